# Pages of an array about to be written whole, faulted in by one call (Linux's MADV_POPULATE_WRITE) instead of
# one fault at each first store: the kernel maps a run of pages in one pass, which costs about 0.6 of the
# faults it replaces on the machines measured. Elsewhere, or on a kernel without it, nothing happens: the
# stores fault the pages in as before. Only for arrays written whole; a part never written would be made
# resident for nothing.

cdef extern from *:
    """
    #include <stdint.h>
    #include <stddef.h>
    #if defined(__linux__) && !defined(__SANITIZE_ADDRESS__)
    #include <sys/mman.h>
    #ifndef MADV_POPULATE_WRITE
    #define MADV_POPULATE_WRITE 23
    #endif
    /* below this, an array's own faults cost about what the call does */
    #define TV_POPULATE_MIN ((size_t) 256 << 10)
    static inline void tv_populate(void* p, size_t len) {
        uintptr_t a = ((uintptr_t) p + 4095) & ~(uintptr_t) 4095;
        uintptr_t b = ((uintptr_t) p + len) & ~(uintptr_t) 4095;
        if (len >= TV_POPULATE_MIN && b > a) madvise((void*) a, (size_t) (b - a), MADV_POPULATE_WRITE);
    }
    #else
    static inline void tv_populate(void* p, size_t len) { (void) p; (void) len; }
    #endif
    /* part k of parts (k = 0 .. parts - 1) of the len bytes at p: for each thread to fault in its own */
    static inline void tv_populate_part(void* p, size_t len, int k, int parts) {
        size_t lo = len / (size_t) parts * (size_t) k, hi = k + 1 == parts ? len : len / (size_t) parts * (size_t) (k + 1);
        if (p != NULL) tv_populate((char*) p + lo, hi - lo);
    }
    """
    void populate "tv_populate"(void* p, size_t len) noexcept nogil
    void populate_part "tv_populate_part"(void* p, size_t len, int k, int parts) noexcept nogil

from libc.stdint cimport int32_t


cdef inline void fill_int32(int32_t* p, Py_ssize_t count, int32_t value) noexcept nogil:
    # p[0:count] = value, its pages faulted in first (np.full's fill faults them one at a time)
    cdef Py_ssize_t k
    populate(p, count * sizeof(int32_t))
    for k in range(count):
        p[k] = value
