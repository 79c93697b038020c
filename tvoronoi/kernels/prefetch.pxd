# A hint to start loading the cache line at p (GCC's __builtin_prefetch): for loops whose next reads
# are known a few steps ahead but lie anywhere in memory.

cdef extern from *:
    """
    #define TV_PREFETCH(p) __builtin_prefetch((const void*)(p))
    """
    void prefetch "TV_PREFETCH"(const void* p) noexcept nogil
