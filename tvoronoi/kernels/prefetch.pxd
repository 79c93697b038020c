# A hint to start loading the cache line at p (GCC's __builtin_prefetch): for loops whose next reads
# are known a few steps ahead but lie anywhere in memory.

cdef extern from *:
    """
    #define TV_PREFETCH(p) __builtin_prefetch((const void*)(p))
    #define TV_PREFETCH_WRITE(p) __builtin_prefetch((const void*)(p), 1)
    """
    void prefetch "TV_PREFETCH"(const void* p) noexcept nogil
    void prefetch_write "TV_PREFETCH_WRITE"(const void* p) noexcept nogil  # (a line about to be written)
