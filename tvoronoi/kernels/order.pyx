"""Insertion order of the incremental engine: random rounds of doubling size, each along a Hilbert curve."""

import numpy as np

from libc.math cimport INFINITY, floor, log2
from libc.stdint cimport int8_t, int32_t, uint8_t, uint16_t, uint32_t, uint64_t
from libc.stdlib cimport malloc, free
from libc.string cimport memcpy

from tvoronoi.kernels.interrupt cimport poll_signals

cdef extern from *:
    """
    /* the trailing zeros of a nonzero word (one instruction where there is one) */
    #if defined(__GNUC__) || defined(__clang__)
    #define tv_trailing_zeros(w) __builtin_ctzll(w)
    #else
    static int tv_trailing_zeros(unsigned long long w) { int r = 0; while (!(w & 1)) { w >>= 1; r++; } return r; }
    #endif
    """
    int trailing_zeros "tv_trailing_zeros"(uint64_t w) noexcept nogil
from tvoronoi.kernels.populate cimport populate

cdef enum:
    # rounds stop halving below this expected size: the first sites form one round (CGAL's threshold in 2D)
    FIRST_ROUND = 64
    # most rounds a 64-bit random word can assign (its trailing zeros)
    MAX_ROUNDS = 64
    # cells of a grid per site it orders (fewer sites share a cell, and fewer cells are ordered again)
    CELLS_PER_SITE = 4
    # most bits of a key: a grid of at most 2^30 cells (more sites share cells, ordered again)
    MAX_KEY_BITS = 30
    # bits of a key sorted by each pass of the radix sort (a count array of 2^11; two passes up to
    # 2^20 sites)
    RADIX_BITS = 11
    # passes for the longest keys (MAX_KEY_BITS)
    RADIX_PASSES = 3
    # a cell with more sites is ordered again, on a grid over its own sites
    CROWDED = 32
    # at most this many sites are sorted by insertion, more by radix
    SMALL_SORT = 48
    # levels of such grids: clusters inside clusters inside ..., deeper than this keep their order in
    # the last level's cells
    MAX_DEPTH = 24


cdef inline uint64_t next_random(uint64_t* state) noexcept nogil:
    """splitmix64: a fast, well-mixed 64-bit generator (one state word)."""
    cdef uint64_t z
    state[0] += <uint64_t>0x9E3779B97F4A7C15
    z = state[0]
    z = (z ^ (z >> 30)) * <uint64_t>0xBF58476D1CE4E5B9
    z = (z ^ (z >> 27)) * <uint64_t>0x94D049BB133111EB
    return z ^ (z >> 31)


# spans below TINY_SPAN (2^-900) are measured times TINY_SCALE (2^600): a grid's scale (cells / span)
# stays finite
cdef double TINY_SPAN = 2.0 ** -900
cdef double TINY_SCALE = 2.0 ** 600


cdef struct Keyed:
    uint32_t key        # the cell's place along the curve
    int32_t i           # input index


# The Hilbert curve, one level (two bits) at a time: in curve state q, the quadrant (2 * x bit + y bit)
# is visited at position DIGIT[q][quadrant] and the next level is in state NEXT[q][quadrant]. State 0
# runs from (0, 0) to (max, 0) through the quadrants bottom-left, top-left, top-right, bottom-right;
# the others are it transposed (1), reflected in the other diagonal (2) and turned half round (3).
# (test_order checks the curve: every cell once, each next to the one before.)
cdef uint32_t DIGIT[4][4]
cdef int NEXT[4][4]
DIGIT[0][:] = [0, 1, 3, 2]
NEXT[0][:] = [1, 0, 2, 0]
DIGIT[1][:] = [0, 3, 1, 2]
NEXT[1][:] = [0, 3, 1, 1]
DIGIT[2][:] = [2, 1, 3, 0]
NEXT[2][:] = [2, 2, 0, 3]
DIGIT[3][:] = [2, 3, 1, 0]
NEXT[3][:] = [3, 1, 3, 2]

# two levels a step: for state q and the two bits of x and of y at those levels (xb << 2 | yb), the two
# digits (low four bits) and the state after them (bits 4, 5), in one byte, so that a step is one load
cdef uint8_t TWO_LEVELS[4][16]


cdef void fill_two_levels() noexcept:
    cdef int q, xb, yb, hi, lo, q1
    for q in range(4):
        for xb in range(4):
            for yb in range(4):
                hi = ((xb >> 1) << 1) | (yb >> 1)
                q1 = NEXT[q][hi]
                lo = ((xb & 1) << 1) | (yb & 1)
                TWO_LEVELS[q][(xb << 2) | yb] = <uint8_t> (((DIGIT[q][hi] << 2) | DIGIT[q1][lo])
                                                          | (NEXT[q1][lo] << 4))


# four levels a step, the same way: for state q and the four bits of x and of y (xb << 4 | yb), the
# eight digits (low byte) and the state after them (bits 8, 9): half the dependent loads of two levels
cdef uint16_t FOUR_LEVELS[4][256]


cdef void fill_four_levels() noexcept:
    cdef int q, xb, yb, hi, lo, q1
    for q in range(4):
        for xb in range(16):
            for yb in range(16):
                hi = TWO_LEVELS[q][((xb >> 2) << 2) | (yb >> 2)]
                q1 = hi >> 4
                lo = TWO_LEVELS[q1][((xb & 3) << 2) | (yb & 3)]
                FOUR_LEVELS[q][(xb << 4) | yb] = <uint16_t> ((((hi & 15) << 4) | (lo & 15)) | ((lo >> 4) << 8))


fill_two_levels()
fill_four_levels()


cdef inline uint32_t hilbert_index(uint32_t x, uint32_t y, int bits) noexcept nogil:
    """The place of cell (x, y) of a 2^bits square along the Hilbert curve from (0, 0) to (max, 0)."""
    cdef uint32_t d = 0, quadrant, step
    cdef int level = bits, q = 0
    if level & 1:
        level -= 1
        quadrant = (((x >> level) & 1) << 1) | ((y >> level) & 1)
        d = DIGIT[0][quadrant]
        q = NEXT[0][quadrant]
    if level & 2:
        level -= 2
        step = TWO_LEVELS[q][(((x >> level) & 3) << 2) | ((y >> level) & 3)]
        d = (d << 4) | (step & 15)
        q = step >> 4
    while level > 0:
        level -= 4
        step = FOUR_LEVELS[q][(((x >> level) & 15) << 4) | ((y >> level) & 15)]
        d = (d << 8) | (step & 255)
        q = step >> 8
    return d


cdef inline uint32_t cell_of(double v, double lo, double scale, uint32_t top) noexcept nogil:
    # the grid column (or row) of coordinate v: floor((v - lo) * scale), kept in [0, top] (a scale that
    # overflowed to inf for a span of a few subnormals gives inf or NaN here: NaN counts as 0)
    cdef double q = (v - lo) * scale
    if not q > 0.0:
        return 0
    if q >= top:
        return top
    return <uint32_t> q


cdef int curve_keys(const double* xs, const double* ys, Keyed* items, Py_ssize_t count) noexcept nogil:
    """Key items[0:count] by their cell along a curve through a grid of about CELLS_PER_SITE cells a site over
    their own bounding box, its cells near square: squares of 2^b x 2^b cells side by side along the
    box's longer side, each along the Hilbert curve from one corner to the next square's. Returns the
    keys' bits, or -1 if every item is at one place (nothing to order)."""
    cdef Py_ssize_t k
    cdef double x0, x1, y0, y1, x, y, w, h, sx, sy, fx, fy
    cdef int total = 0, b_short, b_long, long_x
    cdef uint32_t cx, cy, u, v, top_x, top_y
    x0 = x1 = xs[items[0].i]
    y0 = y1 = ys[items[0].i]
    for k in range(1, count):
        x = xs[items[k].i]
        y = ys[items[k].i]
        x0 = x if x < x0 else x0
        x1 = x if x > x1 else x1
        y0 = y if y < y0 else y0
        y1 = y if y > y1 else y1
    # (halves where a span overflows, as from -1e308 to 1e308: halving is exact but for subnormals, and
    # the cells only steer the order; times 2^600 where a span is so small that a cell's scale would
    # overflow: such sites are all below about 1e-289, so the product is exact and finite)
    fx = 0.5 if not x1 - x0 < INFINITY else (TINY_SCALE if 0 < x1 - x0 < TINY_SPAN else 1.0)
    fy = 0.5 if not y1 - y0 < INFINITY else (TINY_SCALE if 0 < y1 - y0 < TINY_SPAN else 1.0)
    x0 *= fx
    y0 *= fy
    w = x1 * fx - x0
    h = y1 * fy - y0
    if not (w > 0 or h > 0):
        return -1
    # about CELLS_PER_SITE cells a site: 2^total cells, total <= MAX_KEY_BITS
    while total < MAX_KEY_BITS and (<Py_ssize_t> 1 << total) < CELLS_PER_SITE * count:
        total += 1
    # cells near square: the longer side gets the bits of its aspect ratio first (w or h may be 0, or
    # their ratio beyond the double range: then the longer side gets them all)
    long_x = w >= h
    b_short = 0
    if long_x:
        if h > 0 and w / h < 2.0 ** total:
            b_short = (total - <int> floor(log2(w / h))) // 2
    else:
        if w > 0 and h / w < 2.0 ** total:
            b_short = (total - <int> floor(log2(h / w))) // 2
    b_short = 0 if b_short < 0 else b_short
    b_long = total - b_short
    top_x = (1u << (b_long if long_x else b_short)) - 1
    top_y = (1u << (b_short if long_x else b_long)) - 1
    sx = (top_x + 1.0) / w if w > 0 else 0.0
    sy = (top_y + 1.0) / h if h > 0 else 0.0
    for k in range(count):
        cx = cell_of(xs[items[k].i] * fx, x0, sx, top_x)
        cy = cell_of(ys[items[k].i] * fy, y0, sy, top_y)
        u = cx if long_x else cy            # along the longer side
        v = cy if long_x else cx
        items[k].key = ((u >> b_short) << (2 * b_short)) \
            | hilbert_index(u & ((1u << b_short) - 1), v, b_short)
    return total


cdef void radix_sort(Keyed* a, Keyed* tmp, Py_ssize_t count, int bits) noexcept nogil:
    """Sort a[0:count] stably by key (keys below 2^bits), in passes of RADIX_BITS (tmp: scratch)."""
    cdef Py_ssize_t k, c
    cdef Py_ssize_t start[RADIX_PASSES][1 << RADIX_BITS]
    cdef int shift = 0, d, p, passes = (bits + RADIX_BITS - 1) // RADIX_BITS
    cdef uint32_t key
    cdef Keyed* src = a
    cdef Keyed* dst = tmp
    cdef Keyed* swap
    # every pass's counts in one read of the keys (a pass's counts do not depend on the order before it)
    for p in range(passes):
        for d in range(1 << RADIX_BITS):
            start[p][d] = 0
    for k in range(count):
        key = src[k].key
        for p in range(passes):
            start[p][(key >> (p * RADIX_BITS)) & ((1 << RADIX_BITS) - 1)] += 1
    for p in range(passes):
        c = 0
        for d in range(1 << RADIX_BITS):
            c, start[p][d] = c + start[p][d], c
    for p in range(passes):
        shift = p * RADIX_BITS
        for k in range(count):
            d = (src[k].key >> shift) & ((1 << RADIX_BITS) - 1)
            dst[start[p][d]] = src[k]
            start[p][d] += 1
        swap = src
        src = dst
        dst = swap
    if src != a:
        memcpy(a, src, count * sizeof(Keyed))


cdef void insertion_sort(Keyed* a, Py_ssize_t count) noexcept nogil:
    """Sort a[0:count] stably by key (a few items)."""
    cdef Py_ssize_t k, j
    cdef Keyed tmp
    for k in range(1, count):
        tmp = a[k]
        j = k
        while j > 0 and a[j - 1].key > tmp.key:
            a[j] = a[j - 1]
            j -= 1
        a[j] = tmp


cdef void curve_sort(const double* xs, const double* ys, Keyed* a, Keyed* tmp, Py_ssize_t count,
                     int depth) noexcept nogil:
    """Order a[0:count] along the curve of curve_keys, then the sites of each crowded cell again along a
    curve over their own box (a cluster far smaller than the whole is ordered inside too), up to
    MAX_DEPTH levels; the sites of a cell with a few of them keep their order."""
    cdef Py_ssize_t lo, hi
    cdef int bits
    if count <= 1:
        return
    bits = curve_keys(xs, ys, a, count)
    if bits <= 0:
        return
    if count <= SMALL_SORT:
        insertion_sort(a, count)
    else:
        radix_sort(a, tmp, count, bits)
    if depth + 1 >= MAX_DEPTH:
        return
    lo = 0
    while lo < count:
        hi = lo + 1
        while hi < count and a[hi].key == a[lo].key:
            hi += 1
        if hi - lo > CROWDED:
            curve_sort(xs, ys, a + lo, tmp + lo, hi - lo, depth + 1)
        lo = hi


def hilbert_indices(const uint32_t[::1] x, const uint32_t[::1] y, int bits):
    """The places of cells (x, y) of a 2^bits square along the curve the order follows (exposed for
    tests): from (0, 0) to (2^bits - 1, 0), each cell next to the one before."""
    if not 0 <= bits <= 16:
        raise ValueError(f"hilbert_indices: bits must lie in [0, 16], got {bits}")
    cdef Py_ssize_t k, n = x.shape[0]
    if y.shape[0] != n:
        raise ValueError("hilbert_indices: x and y differ in length")
    out_arr = np.empty(n, np.uint32)
    cdef uint32_t[::1] out = out_arr
    with nogil:
        for k in range(n):
            out[k] = hilbert_index(x[k], y[k], bits)
    return out_arr


def brio_order(const double[::1] xs, const double[::1] ys, seed=0, bint along_curve=False):
    """A biased randomized insertion order (Amenta, Choi and Rote), as a permutation.

    Each site joins a random round: the last with probability 1/2, the one
    before with 1/4, and so on (the first round expects 64 to 127 sites, or all of them when fewer than 128).
    The first round is in random order; every other is ordered along one
    Hilbert curve, so that consecutive sites are neighbours at any scale and
    clustering: the curve runs through a grid of about CELLS_PER_SITE cells a
    site over the sites' bounding box (cells near square, however long the
    box), and the sites of a crowded cell are ordered again on a grid over
    their own box (a cluster a billionth of the box's size is ordered inside
    as finely as the box). Keys are sorted by radix, in a few linear passes.

    Parameters
    ----------
    xs, ys : (n,) float64
    seed : int
        Seed of the rounds (taken modulo 2**64); the same seed gives the same
        order.
    along_curve : bool
        Also return the curve's order of all the sites, and give the insertion
        order in places along it: for sites numbered along the curve (where
        neighbours in the plane are neighbours in memory, as the Voronoi phases
        want them) and inserted in this order (incremental.triangulate's
        ``order``), with no renumbering after the triangulation.

    Returns
    -------
    perm : (n,) int32
        Insert input site perm[k] k-th.
    (with along_curve) (order, curve) : (n,) int32 each
        curve[j] is the j-th input site along the curve; insert site curve[order[k]]
        k-th (the same sites in the same order as perm: perm == curve[order]).

    Raises
    ------
    MemoryError
        When the scratch arrays cannot be allocated.

    Examples
    --------
    >>> import numpy as np
    >>> sorted(brio_order(np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0, 0.0]), 0).tolist())
    [0, 1, 2]
    """
    cdef Py_ssize_t n = xs.shape[0], k, n_rounds = 0
    if ys.shape[0] != n:
        raise ValueError(f"xs and ys differ in length ({n} and {ys.shape[0]})")
    if n >= 2 ** 31:
        raise ValueError(f"{n} sites: an int32 permutation holds fewer than 2**31")
    perm_arr = np.empty(n, np.int32)
    cdef int32_t[::1] perm = perm_arr
    curve_arr = np.empty(n if along_curve else 0, np.int32)
    cdef int32_t[::1] curve = curve_arr
    cdef int8_t[::1] round_of = np.empty(n, np.int8)
    if n == 0:
        return (perm_arr, curve_arr) if along_curve else perm_arr
    cdef Keyed* a = <Keyed*>malloc(n * sizeof(Keyed))
    cdef Keyed* b = <Keyed*>malloc(n * sizeof(Keyed))
    if a == NULL or b == NULL:
        free(a)
        free(b)
        raise MemoryError(f"no memory to order {n} sites")
    cdef uint64_t state = <uint64_t>(int(seed) & 0xFFFFFFFFFFFFFFFF), word
    cdef Py_ssize_t count[MAX_ROUNDS + 1]
    cdef int r, last
    cdef Py_ssize_t j
    cdef int32_t tmp
    try:
        with nogil:
            # the arrays written whole, faulted in by runs of pages
            populate(&perm[0], n * sizeof(int32_t))
            if along_curve:
                populate(&curve[0], n * sizeof(int32_t))
            populate(&round_of[0], n * sizeof(int8_t))
            populate(a, n * sizeof(Keyed))
            populate(b, n * sizeof(Keyed))
            # the rounds: n/2 sites expected in the last, n/4 in the one before, ..., the rest in the first
            while (n >> (n_rounds + 1)) >= FIRST_ROUND and n_rounds + 1 < MAX_ROUNDS:
                n_rounds += 1
            last = <int>n_rounds
            for r in range(last + 2):
                count[r] = 0
            for k in range(n):
                word = next_random(&state)
                # r trailing zeros (at most last; no branch for the random count): round last - r, so
                # that round last - r has probability 2^-(r + 1)
                r = trailing_zeros(word | (<uint64_t> 1 << last))
                round_of[k] = <int8_t> (last - r)
                count[last - r + 1] += 1
                a[k].i = <int32_t> k
            for r in range(last + 1):
                count[r + 1] += count[r]
            poll_signals()
            # every site along one curve (its grid over all the sites, crowded cells again over their
            # own), then each round takes its sites in that order: each round is ordered along the curve
            curve_sort(&xs[0], &ys[0], a, b, n, 0)
            poll_signals()
            for k in range(n):
                r = round_of[a[k].i]
                if along_curve:
                    perm[count[r]] = <int32_t> k
                    curve[k] = a[k].i
                else:
                    perm[count[r]] = a[k].i
                count[r] += 1
            # the first round (64 to 127 sites expected, or all of them when there are fewer than 128) in
            # random order, the textbook randomized incremental order: too few sites for their order to
            # cost, and the seed orders even a small set (count[0] is now where the first round ends)
            for k in range(count[0] - 1, 0, -1):
                j = <Py_ssize_t> (((next_random(&state) >> 32) * <uint64_t> (k + 1)) >> 32)
                tmp = perm[k]
                perm[k] = perm[j]
                perm[j] = tmp
    finally:
        free(a)
        free(b)
    return (perm_arr, curve_arr) if along_curve else perm_arr
