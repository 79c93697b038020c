# A hint to start loading the cache line at p (GCC's __builtin_prefetch): for loops whose next reads
# are known a few steps ahead but lie anywhere in memory, and for passes that stream through arrays
# larger than the cache, AHEAD_BYTES ahead of where they read (measured: the hardware's own prefetch
# does not run far enough ahead of a loop that does more than copy; point_bounds on 10^6 rows from
# memory 10.7 ms without, 2.7 ms with; 512 bytes ahead 4.8 ms, 1-8 KiB alike).

cdef enum:
    AHEAD_BYTES = 2048

cdef extern from *:
    """
    #define TV_PREFETCH(p) __builtin_prefetch((const void*)(p))
    #define TV_PREFETCH_WRITE(p) __builtin_prefetch((const void*)(p), 1)
    """
    void prefetch "TV_PREFETCH"(const void* p) noexcept nogil
    void prefetch_write "TV_PREFETCH_WRITE"(const void* p) noexcept nogil  # (a line about to be written)
