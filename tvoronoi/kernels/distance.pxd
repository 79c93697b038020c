# Exact comparison of distances, compiled inline where cimported.
#
#   closer(cx, cy, ax, ay, bx, by) = sign( |c - a|^2 - |c - b|^2 )
#       -1: c is strictly nearer to a, +1: strictly nearer to b, 0: on their bisector
#
# A floating-point filter, then expansion arithmetic (tvoronoi.kernels.predicates)
# when the filter cannot decide: exact for all finite inputs that neither
# overflow nor underflow.

from libc.math cimport fabs

from tvoronoi.kernels.predicates cimport (
    two_diff, two_product, expansion_sign, fast_expansion_sum_zeroelim,
    expansion_product, negate_expansion, difference_expansion,
)

cdef extern from *:
    """
    /* |computed - exact| <= (4 + O(eps)) eps (|c-a|^2 + |c-b|^2); 8 eps leaves room */
    #define TVORONOI_CLOSER_ERRBOUND (8.0 * 1.1102230246251565404236316680908203125e-16)
    """
    const double CLOSER_ERRBOUND "TVORONOI_CLOSER_ERRBOUND"


cdef inline int square_sum(double x, double x_t, double y, double y_t, double* h) noexcept nogil:
    # (x + x_t)^2 + (y + y_t)^2 exactly (h: 32 components)
    cdef double ex[2]
    cdef double ey[2]
    cdef double sx[16]
    cdef double sy[16]
    cdef double work[16]
    cdef double scaled[8]
    cdef int nx = difference_expansion(x, x_t, ex), ny = difference_expansion(y, y_t, ey)
    nx = expansion_product(nx, ex, nx, ex, sx, work, scaled)
    ny = expansion_product(ny, ey, ny, ey, sy, work, scaled)
    return fast_expansion_sum_zeroelim(nx, sx, ny, sy, h)


cdef inline int closer_exact(double cx, double cy, double ax, double ay, double bx, double by) noexcept nogil:
    cdef double ux, ux_t, uy, uy_t, wx, wx_t, wy, wy_t
    cdef double la[32]
    cdef double lb[32]
    cdef double det[64]
    cdef int na, nb
    ux, ux_t = two_diff(cx, ax)
    uy, uy_t = two_diff(cy, ay)
    wx, wx_t = two_diff(cx, bx)
    wy, wy_t = two_diff(cy, by)
    na = square_sum(ux, ux_t, uy, uy_t, la)
    nb = square_sum(wx, wx_t, wy, wy_t, lb)
    negate_expansion(nb, lb)
    return expansion_sign(fast_expansion_sum_zeroelim(na, la, nb, lb, det), det)


cdef inline int closer(double cx, double cy, double ax, double ay, double bx, double by) noexcept nogil:
    """Sign of |c - a|^2 - |c - b|^2: -1 when c is nearer to a, +1 nearer to b, 0 on the bisector."""
    cdef double ux = cx - ax, uy = cy - ay, wx = cx - bx, wy = cy - by
    cdef double la = ux * ux + uy * uy, lb = wx * wx + wy * wy
    cdef double det = la - lb, bound = CLOSER_ERRBOUND * (la + lb)
    if det > bound:
        return 1
    if -det > bound:
        return -1
    return closer_exact(cx, cy, ax, ay, bx, by)
