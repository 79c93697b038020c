"""One pass over the input points: whether they are finite, their bounding box, and their smallest nonzero
magnitude (what the range rule, the scale, the default box and the halves' cut read, without a temporary)."""

from libc.math cimport INFINITY, fabs


def point_bounds(const double[:, ::1] pts):
    """(n_bad, xmin, ymin, xmax, ymax, smallest) of an (n, 2) array: n_bad counts the values that are NaN
    or infinite (the other figures then mean nothing); smallest is the least nonzero |coordinate| (inf
    when all are zero). Of equal extremes, a bound is the first row's value (a zero keeps its sign).
    An empty array gives (0, inf, inf, -inf, -inf, inf)."""
    cdef Py_ssize_t n = pts.shape[0], k
    cdef double x, y, ax, ay
    cdef double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY, small_x = INFINITY, small_y = INFINITY
    cdef long bad = 0
    if pts.shape[1] != 2:
        raise ValueError("point_bounds: the points must have two columns")
    with nogil:
        # (no branch that depends on the data: min and max as selects, a zero's magnitude moved to inf,
        # and x - x, which is 0 exactly when x is finite; the columns' smallest apart, two short chains)
        for k in range(n):
            x = pts[k, 0]
            y = pts[k, 1]
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
    return bad, x0, y0, x1, y1, min(small_x, small_y)
