"""One pass over the input points: whether they are finite, their bounding box, and their smallest nonzero
magnitude (what the range rule, the scale, the default box and the halves' cut read, without a temporary)."""

from cython.parallel cimport prange
from libc.math cimport INFINITY, fabs

from tvoronoi.kernels.prefetch cimport AHEAD_BYTES, prefetch

cdef enum:
    PARALLEL_MIN_POINTS = 1 << 16   # fewer points: one thread (waking another costs more than it saves)
    MAX_PARTS = 64


cdef struct Part:
    long bad
    double x0, y0, x1, y1, small


cdef void part_bounds(const double* pts, Py_ssize_t lo, Py_ssize_t hi, Part* out) noexcept nogil:
    # rows lo..hi-1 (no branch that depends on the data: min and max as selects, a zero's magnitude moved
    # to inf, and x - x, which is 0 exactly when x is finite; the columns' smallest apart, two short chains;
    # the rows AHEAD_BYTES on requested once a cache line)
    cdef Py_ssize_t k
    cdef double x, y, ax, ay
    cdef double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY, small_x = INFINITY, small_y = INFINITY
    cdef long bad = 0
    for k in range(lo, hi):
        if (k & 3) == 0:
            prefetch(<const char*> &pts[2 * k] + AHEAD_BYTES)
        x = pts[2 * k]
        y = pts[2 * k + 1]
        bad += (not (x - x == 0.0)) + (not (y - y == 0.0))
        x0 = x if x < x0 else x0
        y0 = y if y < y0 else y0
        x1 = x if x > x1 else x1
        y1 = y if y > y1 else y1
        ax = fabs(x)
        ay = fabs(y)
        ax = ax if ax != 0.0 else INFINITY
        ay = ay if ay != 0.0 else INFINITY
        small_x = ax if ax < small_x else small_x
        small_y = ay if ay < small_y else small_y
    out.bad = bad
    out.x0 = x0
    out.y0 = y0
    out.x1 = x1
    out.y1 = y1
    out.small = small_x if small_x < small_y else small_y


def point_bounds(const double[:, ::1] pts, int threads=1):
    """(n_bad, xmin, ymin, xmax, ymax, smallest) of an (n, 2) array: n_bad counts the values that are NaN
    or infinite (the other figures then mean nothing); smallest is the least nonzero |coordinate| (inf
    when all are zero). Of equal extremes, a bound is the first row's value (a zero keeps its sign).
    An empty array gives (0, inf, inf, -inf, -inf, inf). threads: a run of rows on each (the same
    figures for any count: the runs are merged in row order, the earlier one's bound kept on a tie)."""
    cdef Py_ssize_t n = pts.shape[0], k
    cdef Part parts[MAX_PARTS]
    cdef Part r
    if pts.shape[1] != 2:
        raise ValueError("point_bounds: the points must have two columns")
    cdef int T = min(max(threads, 1), MAX_PARTS) if n >= PARALLEL_MIN_POINTS else 1
    cdef const double* p = &pts[0, 0] if n > 0 else NULL
    with nogil:
        if T == 1:
            part_bounds(p, 0, n, &parts[0])
        else:
            for k in prange(T, num_threads=T, schedule="static", chunksize=1):
                part_bounds(p, k * n // T, (k + 1) * n // T, &parts[k])
        r = parts[0]
        for k in range(1, T):
            r.bad += parts[k].bad
            r.x0 = parts[k].x0 if parts[k].x0 < r.x0 else r.x0
            r.y0 = parts[k].y0 if parts[k].y0 < r.y0 else r.y0
            r.x1 = parts[k].x1 if parts[k].x1 > r.x1 else r.x1
            r.y1 = parts[k].y1 if parts[k].y1 > r.y1 else r.y1
            r.small = parts[k].small if parts[k].small < r.small else r.small
    return r.bad, r.x0, r.y0, r.x1, r.y1, r.small
