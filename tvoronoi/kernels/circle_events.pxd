# Circle events of Fortune's sweep: where an event happens (the top of the circle through three sites) as a
# rounded value with a proven error bound, so that the event order is decided exactly: by the bound when
# it separates two positions, by exact integer arithmetic (event_order_exact.pxd) when it does not.
#
# For sites a, b, c counter-clockwise, relative to a (B = b - a, C = c - a):
#     D = Bx Cy - By Cx > 0,   centre - a = (Ux, Uy) = (Cy |B|^2 - By |C|^2,  Bx |C|^2 - Cx |B|^2) / (2 D),
#     radius R = |(Ux, Uy)|,   top T = ay + Uy + R.
# Uy + R cancels when the centre lies far below the sites (a huge circle through nearly collinear sites:
# a few ulps of a 1e17 radius would move the top of a circle whose sites lie within 1e-18 of a line by
# more than the spread of the sites); there the top is computed as ay + Ux^2 / (R - Uy), which is the same
# number (R^2 - Uy^2 = Ux^2) without the cancellation.
#
# The error bound, u = 2^-53 (each rounded operation has relative error at most u):
#   - differences, squares and products: |bb - |B|^2| <= 4.0001 u |B|^2, each product of three
#     differences within 6.0001 u; so |numx - 2 D Ux| <= 8 u (|t1| + |t2|), the same for numy;
#   - |det - 2 D| <= e_det = 2 CCW_ERRBOUND_A (|p1| + |p2|) (Shewchuk's orient2d bound, same determinant);
#   - a quotient q = fl(num / det) of values with errors e_num, e_det, det > e_det, is within
#     E = (u |q| det / (1 - u) + e_num + |q| e_det) / (det - e_det) of the exact quotient;
#   - |r - R| <= 2.01 u r + Ex + Ey (the norm is 1-Lipschitz; the rounded sqrt of rounded squares);
#   - uy >= 0: h = uy + r within Ey + Er + u h;  uy < 0: s = r - uy within Es = Er + Ey + u s, s > Es,
#     h = ux^2 / s within (u h s / (1 - u) + Ex (2 |ux| + Ex) + u ux^2 + h Es) / (s - Es);
#   - T = ay + h within Eh + u |T|.
# The bound itself is computed with rounding: it is a sum of products and quotients of nonnegative terms
# (about 30 operations), so a factor 1 + 1e-6 covers its own rounding, and 2 u |T| more the rounding of
# T -/+ bound. Underflow: the filter requires every nonzero coordinate difference to be at least
# 2^-250, so that no product of up to three differences underflows; what may still underflow (the squares
# of a tiny centre offset) is absorbed by an absolute slack of 2^-800 (the circle's radius is at least
# 2^-251 then, see the comment at the slack). Anything not finite (overflow of a far-away centre) or a
# determinant within its own error gives the interval (-inf, +inf): every comparison goes exact.

from libc.math cimport fabs, sqrt, INFINITY

from tvoronoi.kernels.predicates cimport (
    EPSILON, CCW_ERRBOUND_A, two_product, two_two_diff, fast_expansion_sum_zeroelim,
)

cdef extern from *:
    """
    /* 2^-250: smallest nonzero coordinate difference the filter accepts (no underflow in its products) */
    #define TVORONOI_EVENT_TINY_DIFF 5.5271478752604445602472651921923E-76
    /* 2^-800: absolute slack for what may underflow in the filter */
    #define TVORONOI_EVENT_SLACK 1.4996968138956309548176444376647E-241
    /* 2^-500: smallest nonzero coordinate the exact determinant accepts (its products stay normal) */
    #define TVORONOI_EVENT_TINY_COORD 3.0549363634996046820519793932137E-151
    /* 2^-30: a determinant known to less than this relative accuracy is recomputed exactly */
    #define TVORONOI_EVENT_REFINE 9.3132257461547851562500000000000E-10
    """
    const double EVENT_TINY_DIFF "TVORONOI_EVENT_TINY_DIFF"
    const double EVENT_SLACK "TVORONOI_EVENT_SLACK"
    const double EVENT_TINY_COORD "TVORONOI_EVENT_TINY_COORD"
    const double EVENT_REFINE "TVORONOI_EVENT_REFINE"


cdef inline bint usable_difference(double d) noexcept nogil:
    return d == 0.0 or fabs(d) >= EVENT_TINY_DIFF


cdef inline bint usable_coordinate(double v) noexcept nogil:
    return v == 0.0 or fabs(v) >= EVENT_TINY_COORD


cdef inline double orient_rounded(double ax, double ay, double bx, double by, double cx, double cy) noexcept nogil:
    """(b - a) x (c - a) within a relative 2.001 u: the largest component of its exact expansion.

    The determinant is the sum of three 2x2 minors of the coordinates themselves (bx cy - by cx,
    by ax - bx ay, ay cx - ax cy), each two exact products: 12 components, summed without error. The
    components of a nonoverlapping expansion below its largest add up to less than that one's last
    bit. Callers make sure no product underflows (every nonzero coordinate at least 2^-500).
    """
    cdef double p1, p0, q1, q0
    cdef double m1[4]
    cdef double m2[4]
    cdef double m3[4]
    cdef double m12[8]
    cdef double det[12]
    cdef int n12, n
    p1, p0 = two_product(bx, cy)
    q1, q0 = two_product(by, cx)
    two_two_diff(p1, p0, q1, q0, m1)
    p1, p0 = two_product(by, ax)
    q1, q0 = two_product(bx, ay)
    two_two_diff(p1, p0, q1, q0, m2)
    p1, p0 = two_product(ay, cx)
    q1, q0 = two_product(ax, cy)
    two_two_diff(p1, p0, q1, q0, m3)
    n12 = fast_expansion_sum_zeroelim(4, m1, 4, m2, m12)
    n = fast_expansion_sum_zeroelim(n12, m12, 4, m3, det)
    return det[n - 1]


cdef inline void circle_top(double ax, double ay, double bx, double by, double cx, double cy,
                            double* top, double* lo, double* hi,
                            double* centre_x, double* centre_y) noexcept nogil:
    """The top of the circle through a, b, c (counter-clockwise): rounded, and an interval that holds it."""
    cdef double u = EPSILON
    cdef double bdx = bx - ax, bdy = by - ay, cdx = cx - ax, cdy = cy - ay
    cdef double p1 = bdx * cdy, p2 = bdy * cdx
    cdef double det = 2.0 * (p1 - p2)
    cdef double e_det = 2.0 * CCW_ERRBOUND_A * (fabs(p1) + fabs(p2))
    cdef double bb, cc, t1, t2, t3, t4, ux, uy, r, h, t, e_x, e_y, e_r, e_s, e_h, e_t, margin
    cdef double s = 0.0
    # a nearly collinear triple gets its determinant to within 2 ulps (else the bound below is loose)
    if not (e_det < EVENT_REFINE * det) and (
            usable_coordinate(ax) and usable_coordinate(ay) and usable_coordinate(bx)
            and usable_coordinate(by) and usable_coordinate(cx) and usable_coordinate(cy)):
        det = 2.0 * orient_rounded(ax, ay, bx, by, cx, cy)
        e_det = 2.001 * u * fabs(det)
    # the centre, relative to a
    bb = bdx * bdx + bdy * bdy
    cc = cdx * cdx + cdy * cdy
    t1 = cdy * bb; t2 = bdy * cc; t3 = bdx * cc; t4 = cdx * bb
    ux = (t1 - t2) / det
    uy = (t3 - t4) / det
    r = sqrt(ux * ux + uy * uy)
    centre_x[0] = ax + ux
    centre_y[0] = ay + uy
    # the top: uy + r, or without cancellation when the centre lies below a
    if uy >= 0.0:
        h = uy + r
    else:
        s = r - uy
        h = ux * ux / s
    t = ay + h
    top[0] = t
    # its error bound
    margin = det - e_det
    if not (margin > 0.0) or not (usable_difference(bdx) and usable_difference(bdy)
                                  and usable_difference(cdx) and usable_difference(cdy)):
        lo[0] = -INFINITY
        hi[0] = INFINITY
        return
    e_x = (u * fabs(ux) * det * (1.0 + 2.0 * u) + 8.0 * u * (fabs(t1) + fabs(t2)) + fabs(ux) * e_det) / margin
    e_y = (u * fabs(uy) * det * (1.0 + 2.0 * u) + 8.0 * u * (fabs(t3) + fabs(t4)) + fabs(uy) * e_det) / margin
    e_r = 2.01 * u * r + e_x + e_y
    if uy >= 0.0:
        e_h = e_y + e_r + u * h
    else:
        e_s = e_r + e_y + u * s
        if not (s > e_s):
            lo[0] = -INFINITY
            hi[0] = INFINITY
            return
        e_h = ((u * h * s * (1.0 + 2.0 * u) + e_x * (2.0 * fabs(ux) + e_x) + u * ux * ux + h * e_s)
               / (s - e_s))
    # the slack: with every nonzero difference >= 2^-250 the radius is >= 2^-251, so at most the squares
    # of a centre offset below 2^-511 underflow, each by <= 2^-1074, and nothing divides them by less
    # than 2^-251 without the interval being (-inf, inf) already
    e_t = (e_h + u * fabs(t)) * (1.0 + 1e-6) + 2.0 * u * fabs(t) + EVENT_SLACK
    if not (e_t < INFINITY) or not (fabs(t) < INFINITY):
        lo[0] = -INFINITY
        hi[0] = INFINITY
        return
    lo[0] = t - e_t
    hi[0] = t + e_t
