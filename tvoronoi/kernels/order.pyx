"""Insertion order of the incremental engine: random rounds of doubling size, each along an adaptive Hilbert curve."""

import numpy as np

from libc.stdint cimport int32_t, uint64_t
from libc.stdlib cimport malloc, free

from tvoronoi.kernels.interrupt cimport poll_signals
from libc.string cimport memcpy
from cython.parallel cimport prange

cdef enum:
    # rounds stop halving below this expected size: the first sites form one round (CGAL's threshold in 2D)
    FIRST_ROUND = 64
    # most rounds a 64-bit random word can assign (its trailing zeros)
    MAX_ROUNDS = 64
    # items of the largest random sample whose median splits a range
    SAMPLE = 63
    # ranges of at most this many sites are sorted along the curve's axis instead of split
    SMALL = 8
    # ranges of at most this many sites have their extents measured exactly, larger ones sampled
    EXACT_EXTENT = 32
    # sites sampled for the extents of a larger range
    EXTENT_SAMPLE = 16
    # fewer sites are ordered on one thread
    PARALLEL_MIN = 1 << 15

# A range longer than this many times its width along the curve's axis is cut in two, not four.
cdef double ELONGATED = 2.0


cdef struct Item:
    double c[2]         # coordinates x, y
    int32_t i           # input index


cdef inline uint64_t next_random(uint64_t* state) noexcept nogil:
    """splitmix64: a fast, well-mixed 64-bit generator (one state word)."""
    cdef uint64_t z
    state[0] += <uint64_t>0x9E3779B97F4A7C15
    z = state[0]
    z = (z ^ (z >> 30)) * <uint64_t>0xBF58476D1CE4E5B9
    z = (z ^ (z >> 27)) * <uint64_t>0x94D049BB133111EB
    return z ^ (z >> 31)


cdef inline Py_ssize_t below(uint64_t* state, Py_ssize_t bound) noexcept nogil:
    """A random integer in [0, bound), bound < 2**32 (multiply-shift)."""
    return <Py_ssize_t>(((next_random(state) >> 32) * <uint64_t>bound) >> 32)


cdef inline bint precedes(const Item* a, const Item* b, int axis, double s, double t) noexcept nogil:
    """a comes strictly before b: by coordinate axis in direction s (+1 or -1), ties by the
    other coordinate in direction t. Negation is exact, so this is a total order on distinct
    points, read on the input doubles themselves (no constructed key)."""
    cdef double p = s * a.c[axis], q = s * b.c[axis]
    if p != q:
        return p < q
    # degenerate case: equal coordinates along the split axis (a row or column of sites)
    return t * a.c[1 - axis] < t * b.c[1 - axis]


cdef Py_ssize_t split(const Item* src, Item* dst, Py_ssize_t lo, Py_ssize_t hi, int axis, double s,
                      double t, uint64_t* state) noexcept nogil:
    """Move src[lo:hi] to dst[lo:hi], the items before a pivot near the median first (order
    precedes(axis, s, t)); returns the cut m: dst[lo:m] comes before or ties with dst[m:hi],
    and lo < m < hi when there are two items or more. The pivot is the median of a random
    sample, so the parts are near halves on any input (expected O(log n) levels); the pass
    writes each item to the front or the back without a branch (no mispredictions)."""
    cdef Item sample[SAMPLE]
    cdef Item pivot, tmp
    cdef Py_ssize_t n = hi - lo, i, k, q, r, front, back, lt
    cdef int o = 1 - axis
    cdef double kp, tp, p
    if n <= 1:
        if n == 1:
            dst[lo] = src[lo]
        return lo
    # the pivot: the median of a small random sample (insertion sort)
    r = 3 if n < 256 else (15 if n < 16384 else SAMPLE)
    for q in range(r):
        tmp = src[lo + below(state, n)]
        i = q
        while i > 0 and precedes(&tmp, &sample[i - 1], axis, s, t):
            sample[i] = sample[i - 1]
            i -= 1
        sample[i] = tmp
    pivot = sample[r // 2]
    kp = s * pivot.c[axis]
    tp = t * pivot.c[o]
    # the items strictly before the pivot to the front, the others to the back
    front = lo
    back = hi - 1
    for k in range(lo, hi):
        p = s * src[k].c[axis]
        lt = (p < kp) | ((p == kp) & (t * src[k].c[o] < tp))
        dst[back + (front - back) * lt] = src[k]
        front += lt
        back -= 1 - lt
    if front > lo:
        return front
    # degenerate case: nothing is before the pivot (it is the first item, or ties with it):
    # the items not after the pivot to the front
    back = hi - 1
    for k in range(lo, hi):
        p = s * src[k].c[axis]
        lt = 1 - ((kp < p) | ((kp == p) & (tp < t * src[k].c[o])))
        dst[back + (front - back) * lt] = src[k]
        front += lt
        back -= 1 - lt
    if front < hi:
        return front
    # degenerate case: every item ties with the pivot (repeated points): any cut will do
    return lo + n // 2


cdef void sort_small(Item* a, Py_ssize_t lo, Py_ssize_t hi, int axis, double s, double t) noexcept nogil:
    """Insertion sort of a few items by precedes(axis, s, t): along the curve's axis."""
    cdef Py_ssize_t k, j
    cdef Item tmp
    for k in range(lo + 1, hi):
        tmp = a[k]
        j = k
        while j > lo and precedes(&tmp, &a[j - 1], axis, s, t):
            a[j] = a[j - 1]
            j -= 1
        a[j] = tmp


cdef void extents(const Item* a, Py_ssize_t lo, Py_ssize_t hi, uint64_t* state, double* e) noexcept nogil:
    """The extents of a[lo:hi] along x (e[0]) and y (e[1]): exact for a small range, those of a
    random sample otherwise (they only steer the curve; no exact decision depends on them)."""
    cdef Py_ssize_t n = hi - lo, k, q
    cdef double x0, x1, y0, y1, v
    x0 = x1 = a[lo].c[0]
    y0 = y1 = a[lo].c[1]
    for q in range(n - 1 if n <= EXACT_EXTENT else EXTENT_SAMPLE):
        k = lo + 1 + q if n <= EXACT_EXTENT else lo + below(state, n)
        v = a[k].c[0]
        x0 = v if v < x0 else x0
        x1 = v if v > x1 else x1
        v = a[k].c[1]
        y0 = v if v < y0 else y0
        y1 = v if v > y1 else y1
    e[0] = x1 - x0
    e[1] = y1 - y0


cdef void hilbert_sort(Item* src, Item* dst, Item* out, Py_ssize_t lo, Py_ssize_t hi, int x, double ux,
                       double uy, uint64_t* state) noexcept nogil:
    """Order the items of src[lo:hi] along a Hilbert curve adapted to the points, into
    out[lo:hi] (out is src or dst; each split moves the range from one to the other).

    Each level splits at the median, along axis x (direction ux) then along the other
    axis (direction uy), so that every quadrant holds a quarter of the points however
    they cluster (CGAL's median policy):

        +-----+-----+    quadrants visited 1 2 3 4 (for ux = uy = +1, x the first axis);
        |  2  |  3  |    1 and 4 are entered transposed (and 4 reversed) so that the
        +-----+-----+    curve leaves each quadrant next to where it enters the next
        |  1  |  4  |
        +-----+-----+

    A range much longer along x than across (a row of sites, a thin strip) is cut in two
    halves along x instead, both in the same frame, so the curve runs straight through
    it rather than back and forth across it (as a generalized Hilbert curve does in a
    long rectangle). A few sites are sorted along x.
    """
    cdef int y = 1 - x
    cdef Py_ssize_t m1, m2, m3
    cdef double e[2]
    if hi - lo <= SMALL:
        # a few sites: in order along the curve's axis
        if src != out:
            memcpy(&out[lo], &src[lo], (hi - lo) * sizeof(Item))
        sort_small(out, lo, hi, x, ux, uy)
        return
    extents(src, lo, hi, state, e)
    if e[x] > ELONGATED * e[y]:
        # a long range along the curve: two halves, same frame
        m2 = split(src, dst, lo, hi, x, ux, uy, state)
        hilbert_sort(dst, src, out, lo, m2, x, ux, uy, state)
        hilbert_sort(dst, src, out, m2, hi, x, ux, uy, state)
        return
    # split in halves along x, then each half in quarters along y (the second half reversed)
    m2 = split(src, dst, lo, hi, x, ux, uy, state)
    m1 = split(dst, src, lo, m2, y, uy, ux, state)
    m3 = split(dst, src, m2, hi, y, -uy, ux, state)
    # the quarters, each in its own frame of the curve
    hilbert_sort(src, dst, out, lo, m1, y, uy, ux, state)
    hilbert_sort(src, dst, out, m1, m2, x, ux, uy, state)
    hilbert_sort(src, dst, out, m2, m3, x, ux, uy, state)
    hilbert_sort(src, dst, out, m3, hi, y, -uy, -ux, state)


def brio_order(const double[::1] xs, const double[::1] ys, seed=0, int threads=1):
    """A biased randomized insertion order (Amenta, Choi and Rote), as a permutation.

    Each site joins a random round: the last with probability 1/2, the one
    before with 1/4, and so on (the first round expects 64 to 127 sites, or all of them when fewer than 128).
    Each round is ordered along a Hilbert curve by median splits, so that
    consecutive sites are neighbours at any scale and clustering: every
    split is a cut in a total order of the input doubles (by one coordinate,
    ties by the other), never in rounded keys, so any two distinct sites are
    separated, however close.

    Parameters
    ----------
    xs, ys : (n,) float64
    seed : int
        Seed of the rounds and of the pivots (taken modulo 2**64); the same
        seed gives the same order.
    threads : int
        The rounds are ordered on this many threads (each with its own stream
        of pivots): the same order for any count.

    Returns
    -------
    perm : (n,) int32
        Insert input site perm[k] k-th.

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
    cdef Py_ssize_t n = xs.shape[0], k, start, end, n_rounds = 0
    if ys.shape[0] != n:
        raise ValueError(f"xs and ys differ in length ({n} and {ys.shape[0]})")
    if n >= 2 ** 31:
        raise ValueError(f"{n} sites: an int32 permutation holds fewer than 2**31")
    cdef int32_t[::1] perm = np.empty(n, np.int32)
    cdef int32_t[::1] round_of = np.empty(n, np.int32)
    if n == 0:
        return np.asarray(perm)
    cdef Item* a = <Item*>malloc(n * sizeof(Item))
    cdef Item* b = <Item*>malloc(n * sizeof(Item))
    if a == NULL or b == NULL:
        free(a)
        free(b)
        raise MemoryError(f"no memory to order {n} sites")
    cdef uint64_t state = <uint64_t>(int(seed) & 0xFFFFFFFFFFFFFFFF), word
    cdef Py_ssize_t count[MAX_ROUNDS + 1]
    cdef uint64_t round_state[MAX_ROUNDS + 1]
    cdef int r, k_round, last, axis
    cdef double e[2]
    try:
        with nogil:
            # the rounds: n/2 sites expected in the last, n/4 in the one before, ..., the rest in the first
            while (n >> (n_rounds + 1)) >= FIRST_ROUND and n_rounds + 1 < MAX_ROUNDS:
                n_rounds += 1
            last = <int>n_rounds
            for r in range(last + 2):
                count[r] = 0
            for k in range(n):
                word = next_random(&state)
                r = 0
                while r < last and (word >> r) & 1 == 0:
                    r += 1
                # r trailing zeros: round last - r, so that round last - r has probability 2^-(r + 1)
                round_of[k] = last - r
                count[last - r + 1] += 1
            for r in range(last + 1):
                count[r + 1] += count[r]
            # the sites, round by round (count[r] is where round r starts)
            for k in range(n):
                r = round_of[k]
                a[count[r]].c[0] = xs[k]
                a[count[r]].c[1] = ys[k]
                a[count[r]].i = <int32_t>k
                count[r] += 1
            # each round along the curve, its first axis the longer side of the whole set; each round
            # draws its pivots from a stream of its own (the first goes on with the main one), so that
            # the rounds can be ordered at once, the largest first (round last holds half the sites)
            extents(a, 0, n, &state, e)
            axis = 0 if e[0] >= e[1] else 1
            round_state[0] = state
            for r in range(1, last + 1):
                word = state ^ (<uint64_t>r * <uint64_t>0xD1B54A32D192ED03)
                round_state[r] = next_random(&word)
            poll_signals()
            for k_round in prange(last + 1, num_threads=threads if n >= PARALLEL_MIN else 1,
                                  schedule="dynamic", chunksize=1):
                r = last - k_round
                poll_signals()
                hilbert_sort(a, b, a, count[r - 1] if r > 0 else 0, count[r], axis, 1.0, 1.0,
                             &round_state[r])
            for k in range(n):
                perm[k] = a[k].i
    finally:
        free(a)
        free(b)
    return np.asarray(perm)
