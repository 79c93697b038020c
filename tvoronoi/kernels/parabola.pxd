# Exact comparison of two parabolic arcs of Fortune's beach line, compiled inline where cimported.
#
# The sweep line is y = py, through the new site p. A site s below it (sy <= py) has the
# parabola of points equidistant from s and the line; its height above x = px is
#     c_s = py + |s - p|^2 / (2 (sy - py)),
# the centre of the circle through s tangent to the line at p. The beach line is the upper
# envelope of the parabolas, so s is above p rather than t exactly when c_s > c_t, i.e. when
#     parabola_order(s, t, p) = sign( |s - p|^2 (ty - py) - |t - p|^2 (sy - py) )  > 0
# (multiplying by 2 (sy - py)(ty - py) >= 0). A site on the line itself (sy == py) has a
# vertical, degenerate parabola, which the same sign handles: it is never above p unless the
# other one is degenerate too, which gives 0.
#
# The sign is exact: a floating-point filter with a generous bound on its rounding error, then
# expansion arithmetic (tvoronoi.kernels.predicates) when the filter cannot decide.

from libc.math cimport fabs

from tvoronoi.kernels.predicates cimport (
    EPSILON, two_diff, two_product, expansion_sign, scale_expansion_zeroelim,
    fast_expansion_sum_zeroelim, expansion_product, negate_expansion, difference_expansion,
)

# The computed determinant is within (7 + O(eps)) eps of the permanent; 16 eps leaves room.
cdef extern from *:
    """
    #define TVORONOI_PARABOLA_ERRBOUND (16.0 * 1.1102230246251565404236316680908203125e-16)
    """
    const double PARABOLA_ERRBOUND "TVORONOI_PARABOLA_ERRBOUND"


cdef inline int parabola_lift(double dx, double dy, double* h) noexcept nogil:
    # dx^2 + dy^2 exactly (4 components at most)
    cdef double x2[2]
    cdef double y2[2]
    x2[1], x2[0] = two_product(dx, dx)
    y2[1], y2[0] = two_product(dy, dy)
    return fast_expansion_sum_zeroelim(2, x2, 2, y2, h)


cdef inline int parabola_order_exact(double ax, double ay, double bx, double by,
                                     double px, double py) noexcept nogil:
    cdef double adx, adx_t, ady, ady_t, bdx, bdx_t, bdy, bdy_t
    cdef double la[64]
    cdef double lb[64]
    cdef double t1[256]
    cdef double t2[256]
    cdef double det[512]
    cdef double work[256]
    cdef double scaled[64]
    cdef double ex[2]
    cdef double ey[2]
    cdef double sq1[16]
    cdef double sq2[16]
    cdef double e_a[2]
    cdef double e_b[2]
    cdef int nla, nlb, n1, n2, nd, nx, ny
    adx, adx_t = two_diff(ax, px)
    ady, ady_t = two_diff(ay, py)
    bdx, bdx_t = two_diff(bx, px)
    bdy, bdy_t = two_diff(by, py)
    if adx_t == 0.0 and ady_t == 0.0 and bdx_t == 0.0 and bdy_t == 0.0:
        # the differences are exact: products of single doubles
        nla = parabola_lift(adx, ady, la)
        nlb = parabola_lift(bdx, bdy, lb)
        n1 = scale_expansion_zeroelim(nla, la, bdy, t1)
        n2 = scale_expansion_zeroelim(nlb, lb, ady, t2)
    else:
        # some difference was rounded: carry each as head + tail
        nx = difference_expansion(adx, adx_t, ex)
        ny = difference_expansion(ady, ady_t, ey)
        n1 = expansion_product(nx, ex, nx, ex, sq1, work, scaled)
        n2 = expansion_product(ny, ey, ny, ey, sq2, work, scaled)
        nla = fast_expansion_sum_zeroelim(n1, sq1, n2, sq2, la)
        nx = difference_expansion(bdx, bdx_t, ex)
        ny = difference_expansion(bdy, bdy_t, ey)
        n1 = expansion_product(nx, ex, nx, ex, sq1, work, scaled)
        n2 = expansion_product(ny, ey, ny, ey, sq2, work, scaled)
        nlb = fast_expansion_sum_zeroelim(n1, sq1, n2, sq2, lb)
        n1 = difference_expansion(bdy, bdy_t, e_b)
        n1 = expansion_product(nla, la, n1, e_b, t1, work, scaled)
        n2 = difference_expansion(ady, ady_t, e_a)
        n2 = expansion_product(nlb, lb, n2, e_a, t2, work, scaled)
    negate_expansion(n2, t2)
    nd = fast_expansion_sum_zeroelim(n1, t1, n2, t2, det)
    return expansion_sign(nd, det)


cdef inline int parabola_order(double ax, double ay, double bx, double by,
                               double px, double py) noexcept nogil:
    """Sign of |a - p|^2 (by - py) - |b - p|^2 (ay - py): +1 when a's arc is above p rather than b's."""
    cdef double adx = ax - px, ady = ay - py, bdx = bx - px, bdy = by - py
    cdef double la = adx * adx + ady * ady
    cdef double lb = bdx * bdx + bdy * bdy
    cdef double t1 = la * bdy, t2 = lb * ady
    cdef double det = t1 - t2
    cdef double bound = PARABOLA_ERRBOUND * (fabs(t1) + fabs(t2))
    if det > bound:
        return 1
    if -det > bound:
        return -1
    return parabola_order_exact(ax, ay, bx, by, px, py)
