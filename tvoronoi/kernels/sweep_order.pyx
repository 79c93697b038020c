"""Event order of Fortune's sweep: the sites by y, then x, then input row, exactly.

One sort of 64-bit integers does nearly all of it (engines.sweep_order sorts them with numpy): each
site's key is its y as an unsigned integer of the same order (-0.0 read as +0.0), less the least, shifted
right just enough that the row fits below it, with the row below. sweep_keys makes the keys; after the
sort, sweep_rows reads the rows off and sorts each run of equal shifted keys again, by the exact y, x and
row (a grid's rows of equal y, or y a few units apart when the span of y needs the shift).
"""

from libc.stdint cimport int32_t, uint64_t
from libc.stdlib cimport malloc, free

from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK

cdef extern from *:
    """
    #include <string.h>
    /* a double's bits as an unsigned integer of the same order: every bit of a negative one flipped,
       the sign bit of the others set (-0.0 is read as +0.0: y + 0.0) */
    static inline unsigned long long tv_ordered_bits(double v) {
        unsigned long long b;
        v = v + 0.0;
        memcpy(&b, &v, sizeof b);
        return b ^ ((0ULL - (b >> 63)) | 0x8000000000000000ULL);
    }
    static inline int tv_bit_length(unsigned long long w) { return w ? 64 - __builtin_clzll(w) : 0; }
    """
    uint64_t ordered_bits "tv_ordered_bits"(double v) noexcept nogil
    int bit_length "tv_bit_length"(uint64_t w) noexcept nogil

cdef enum:
    SMALL_RUN = 16      # runs up to this long are sorted by insertion (longer: merged, from runs this long)


cdef struct Tied:
    # a site of a run of equal shifted keys: its exact y and x as ordered integers, and its row
    uint64_t y, x
    int32_t row


cdef inline bint before(const Tied* a, const Tied* b) noexcept nogil:
    # a comes strictly before b: by y, then x, then row
    if a.y != b.y:
        return a.y < b.y
    if a.x != b.x:
        return a.x < b.x
    return a.row < b.row


def sweep_keys(const double[::1] ys, uint64_t[::1] key):
    """The keys of the sweep order's sort in ``key`` (n,): site i's y as an ordered integer, less the
    least, shifted right so that its row fits below (keys a shift apart share a key), then the row.
    Returns the row's bits."""
    cdef Py_ssize_t n = ys.shape[0], i
    cdef uint64_t k, low = <uint64_t> -1, high = 0
    cdef int row_bits = bit_length(<uint64_t> (n - 1)) if n > 1 else 0, shift
    if key.shape[0] != n:
        raise ValueError("key and ys differ in length")
    if n == 0:
        return row_bits
    with nogil:
        for i in range(n):
            k = ordered_bits(ys[i])
            key[i] = k
            if k < low:
                low = k
            if k > high:
                high = k
        shift = bit_length(high - low) - (64 - row_bits)
        if shift < 0:
            shift = 0
        for i in range(n):
            key[i] = (((key[i] - low) >> shift) << row_bits) | <uint64_t> i
    return row_bits


def sweep_rows(const uint64_t[::1] key, int row_bits, const double[::1] xs, const double[::1] ys,
               int32_t[::1] perm):
    """The sweep order in ``perm`` from the sorted keys of sweep_keys: each key's row, each run of equal
    shifted keys sorted again by the exact y, x and row of its sites. Returns the sites in such runs."""
    cdef Py_ssize_t n = key.shape[0], i, j, tied = 0, longest = 0, since_poll = 0
    cdef uint64_t mask = (<uint64_t> 1 << row_bits) - 1 if row_bits < 64 else <uint64_t> -1
    cdef Tied* buf = NULL
    if perm.shape[0] != n or xs.shape[0] != n or ys.shape[0] != n:
        raise ValueError("key, xs, ys and perm differ in length")
    with nogil:
        for i in range(n):
            perm[i] = <int32_t> (key[i] & mask)
        # the runs of equal shifted keys: the longest first, for one scratch buffer
        i = 0
        while i < n:
            j = i + 1
            while j < n and (key[j] >> row_bits) == (key[i] >> row_bits):
                j += 1
            if j - i > 1:
                tied += j - i
                if j - i > longest:
                    longest = j - i
            i = j
    if tied == 0:
        return 0
    buf = <Tied*> malloc(2 * longest * sizeof(Tied))
    if buf == NULL:
        raise MemoryError()
    try:
        with nogil:
            i = 0
            while i < n:
                j = i + 1
                while j < n and (key[j] >> row_bits) == (key[i] >> row_bits):
                    j += 1
                if j - i > 1:
                    sort_run(&perm[i], j - i, xs, ys, buf)
                    # (signals looked at after every POLL_MASK sites sorted or so)
                    since_poll += j - i
                    if since_poll > POLL_MASK:
                        poll_signals()
                        since_poll = 0
                i = j
    finally:
        free(buf)
    return tied


cdef Tied* merge_sort(Tied* a, Tied* b, Py_ssize_t count) noexcept nogil:
    # a[0..count) sorted (b: as much room again); returns where the result lies, a or b
    cdef Py_ssize_t lo, hi, i, j, k, mid, width = SMALL_RUN
    cdef Tied t
    cdef Tied* swap
    lo = 0
    while lo < count:
        hi = lo + SMALL_RUN if lo + SMALL_RUN < count else count
        for i in range(lo + 1, hi):
            t = a[i]
            j = i
            while j > lo and before(&t, &a[j - 1]):
                a[j] = a[j - 1]
                j -= 1
            a[j] = t
        lo = hi
    while width < count:
        lo = 0
        while lo < count:
            mid = lo + width if lo + width < count else count
            hi = lo + 2 * width if lo + 2 * width < count else count
            i = lo
            j = mid
            k = lo
            while i < mid and j < hi:
                if before(&a[j], &a[i]):
                    b[k] = a[j]
                    j += 1
                else:
                    b[k] = a[i]
                    i += 1
                k += 1
            while i < mid:
                b[k] = a[i]
                i += 1
                k += 1
            while j < hi:
                b[k] = a[j]
                j += 1
                k += 1
            lo = hi
        swap = a
        a = b
        b = swap
        width *= 2
    return a


cdef void sort_run(int32_t* rows, Py_ssize_t count, const double[::1] xs, const double[::1] ys,
                   Tied* buf) noexcept nogil:
    # rows[0..count) by y, x and row (buf: room for 2 count); a run already in order (a grid's row in
    # input order) costs one pass
    cdef Py_ssize_t i
    cdef Tied* a = buf
    cdef Tied* b = buf + count
    cdef Tied* c
    cdef bint sorted_ = True
    for i in range(count):
        a[i].row = rows[i]
        a[i].y = ordered_bits(ys[rows[i]])
        a[i].x = ordered_bits(xs[rows[i]])
        if i > 0 and sorted_ and before(&a[i], &a[i - 1]):
            sorted_ = False
    if sorted_:
        return
    c = merge_sort(a, b, count)
    for i in range(count):
        rows[i] = c[i].row
