# Circle events of Fortune's sweep: where an event happens (the top of the circle through three sites) as a
# rounded value with a proven error bound, so that the event order is decided exactly. Four stages, each
# only for what the one before could not separate:
#   1. circle_top_fast / circle_top: the top and an interval [lo, hi] that holds it (two doubles compared);
#   2. the top as base + rise, base the highest site's y, rise with its own bound (relative_sign): near
#      ties much closer than an ulp of the top (sites within 1e-16 of a line) are far apart in the rises;
#   3. circle_top_fine: the same computation in double-double arithmetic with its bound;
#   4. exact integer arithmetic (event_order_exact.pxd).
#
# For sites a, b, c counter-clockwise, relative to an origin o among them (B, C: from o to the other two,
# counter-clockwise):
#     D = Bx Cy - By Cx > 0,   centre - o = (Ux, Uy) = (Cy |B|^2 - By |C|^2,  Bx |C|^2 - Cx |B|^2) / (2 D),
#     radius R = |(Ux, Uy)|,   top T = oy + Uy + R.
# circle_top takes o opposite the longest side (the offsets then come without cancellation) and measures
# the rise from the highest site k, W = centre - k: rise = Wy + R, and when the centre lies below k,
# Wx^2 / (R - Wy), the same number (R^2 - Wy^2 = Wx^2) without the cancellation of Wy + R (a few ulps of a
# 1e17 radius would otherwise move the top of a circle through sites within 1e-18 of a line by more than
# the spread of the sites).
#
# The error bound, u = 2^-53 (each rounded operation has relative error at most u):
#   - differences, squares and products: |bb - |B|^2| <= 4.0001 u |B|^2, each product of three
#     differences within 6.0001 u; so |numx - 2 D Ux| <= 8 u (|t1| + |t2|), the same for numy;
#   - |det - 2 D| <= e_det = 2 CCW_ERRBOUND_A (|p1| + |p2|) (Shewchuk's orient2d bound, same determinant),
#     or 2.001 u |det| when det is recomputed from its exact expansion (orient_rounded);
#   - a quotient q = num * fl(1 / det) of values with errors e_num, e_det, e_det <= det / 2, is within
#     E = (2 u |q| det (1 + 2u) + e_num + |q| e_det) * 2 / det of the exact quotient;
#   - |r - R| <= 2.01 u r + Ex + Ey (the norm is 1-Lipschitz; the rounded sqrt of rounded squares);
#   - W = (o - k) + U: Ewx = Ex + u |ox - kx| (1 + u) + u |wx|, the same for y;
#   - wy >= 0: h = wy + r within Ewy + Er + u h;  wy < 0: s = r - wy within Es = Er + Ewy + u s,
#     Es <= s / 2, h = wx^2 fl(1 / s) within (3 u h s (1 + 4u) + Ewx (2 |wx| + Ewx) + h Es) * 2 / s;
#   - T = ky + h within Eh + u |T|.
# The bound itself is computed with rounding: it is a sum of products and quotients of nonnegative terms
# (about 30 operations), so a factor 1 + 1e-6 covers its own rounding, and 2 u |T| more the rounding of
# T -/+ bound. Underflow: the filter requires every nonzero coordinate difference to be at least
# 2^-250, so that no product of up to three differences underflows; what may still underflow (the squares
# of a tiny centre offset) is absorbed by an absolute slack of 2^-800 (the circle's radius is at least
# 2^-251 then, see the comment at the slack). Anything not finite (overflow of a far-away centre) or a
# determinant known to less than half its size gives the interval (-inf, +inf): the later stages decide.

from libc.math cimport fabs, sqrt, INFINITY

from tvoronoi.kernels.predicates cimport (
    EPSILON, CCW_ERRBOUND_A, two_product, two_diff, two_sum, fast_two_sum,
)

cdef extern from *:
    """
    /* 2^-250: smallest nonzero coordinate difference the filter accepts (no underflow in its products) */
    #define TVORONOI_EVENT_TINY_DIFF 5.5271478752604445602472651921923E-76
    /* 2^-800: absolute slack for what may underflow in the filter */
    #define TVORONOI_EVENT_SLACK 1.4996968138956309548176444376647E-241
    /* 2^-500: smallest nonzero coordinate the exact determinant accepts (its products stay normal) */
    #define TVORONOI_EVENT_TINY_COORD 3.0549363634996046820519793932137E-151
    /* 2^-36: a fast bound looser than this, relative to the top and radius, is redone carefully */
    #define TVORONOI_EVENT_LOOSE 1.4551915228366851806640625E-11
    /* 2^-30: a determinant known to less than this relative accuracy is recomputed exactly */
    #define TVORONOI_EVENT_REFINE 9.3132257461547851562500000000000E-10
    """
    const double EVENT_TINY_DIFF "TVORONOI_EVENT_TINY_DIFF"
    const double EVENT_SLACK "TVORONOI_EVENT_SLACK"
    const double EVENT_TINY_COORD "TVORONOI_EVENT_TINY_COORD"
    const double EVENT_REFINE "TVORONOI_EVENT_REFINE"
    const double EVENT_LOOSE "TVORONOI_EVENT_LOOSE"


cdef inline bint usable_difference(double d) noexcept nogil:
    return d == 0.0 or fabs(d) >= EVENT_TINY_DIFF


cdef inline bint usable_coordinate(double v) noexcept nogil:
    return v == 0.0 or fabs(v) >= EVENT_TINY_COORD


cdef inline int grow_expansion_zeroelim(int elen, const double* e, double b, double* h) noexcept nogil:
    """h = e + b for a nonoverlapping expansion e (Shewchuk's Grow-Expansion): nonoverlapping again."""
    cdef double q = b, hh
    cdef int i, hlen = 0
    for i in range(elen):
        q, hh = two_sum(q, e[i])
        if hh != 0.0:
            h[hlen] = hh
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


cdef inline double compressed_head(int elen, double* e) noexcept nogil:
    """The largest component of e after Shewchuk's Compress: within an ulp of the expansion's value."""
    cdef double q, q_new, small
    cdef int i, bottom = elen - 1, top = 0
    q = e[bottom]
    for i in range(elen - 2, -1, -1):
        q_new, small = fast_two_sum(q, e[i])
        if small != 0.0:
            e[bottom] = q_new
            bottom -= 1
            q = small
        else:
            q = q_new
    for i in range(bottom + 1, elen):
        q_new, small = fast_two_sum(e[i], q)
        if small != 0.0:
            e[top] = small
            top += 1
        q = q_new
    return q


cdef inline double orient_rounded(double ax, double ay, double bx, double by, double cx, double cy) noexcept nogil:
    """(b - a) x (c - a) within a relative 2^-52: the head of its exact expansion, compressed.

    The determinant is the sum of three 2x2 minors of the coordinates themselves (bx cy - by cx,
    by ax - bx ay, ay cx - ax cy): twelve exact product halves, grown one by one into a nonoverlapping
    expansion (Grow-Expansion needs nothing more of its input), then compressed; the largest component
    of a compressed expansion is within an ulp of its value (Shewchuk 1997, Theorem 23). Callers make
    sure no product underflows (every nonzero coordinate at least 2^-500).
    """
    cdef double parts[12]
    cdef double e[13]
    cdef double f[13]
    cdef double* cur = e
    cdef double* nxt_buf = f
    cdef double* swap
    cdef int k, n = 0
    parts[0], parts[1] = two_product(bx, cy)
    parts[2], parts[3] = two_product(-by, cx)
    parts[4], parts[5] = two_product(by, ax)
    parts[6], parts[7] = two_product(-bx, ay)
    parts[8], parts[9] = two_product(ay, cx)
    parts[10], parts[11] = two_product(-ax, cy)
    for k in range(12):
        if parts[k] != 0.0:
            n = grow_expansion_zeroelim(n, cur, parts[k], nxt_buf)
            swap = cur
            cur = nxt_buf
            nxt_buf = swap
    if n == 0:
        return 0.0
    return compressed_head(n, cur)


cdef inline bint circle_top_fast(double ax, double ay, double bx, double by, double cx, double cy,
                                 double* top, double* lo, double* hi,
                                 double* centre_x, double* centre_y) noexcept nogil:
    """The common case of circle_top, with fewer operations and no data-dependent branch: the centre
    relative to a, top = ay + uy + r, and a looser bound (2 (Ex + Ey) + 2.01 u r + u |uy + r| for the
    rise, the terms as in circle_top, Ex + Ey summed in one expression). False when the determinant is
    not known to half its size or a difference is too small: circle_top then does the careful work.
    """
    cdef double u = EPSILON
    cdef double bdx = bx - ax, bdy = by - ay, cdx = cx - ax, cdy = cy - ay
    cdef double p1 = bdx * cdy, p2 = bdy * cdx
    cdef double det = 2.0 * (p1 - p2)
    cdef double e_det = 2.0 * CCW_ERRBOUND_A * (fabs(p1) + fabs(p2))
    cdef double bb = bdx * bdx + bdy * bdy, cc = cdx * cdx + cdy * cdy
    cdef double t1 = cdy * bb, t2 = bdy * cc, t3 = bdx * cc, t4 = cdx * bb
    cdef double inv_det, ux, uy, r, h, t, e_xy, e_t
    if not (e_det <= 0.5 * det) or not (usable_difference(bdx) and usable_difference(bdy)
                                        and usable_difference(cdx) and usable_difference(cdy)):
        return False
    inv_det = 1.0 / det
    ux = (t1 - t2) * inv_det
    uy = (t3 - t4) * inv_det
    r = sqrt(ux * ux + uy * uy)
    h = uy + r
    t = ay + h
    centre_x[0] = ax + ux
    centre_y[0] = ay + uy
    top[0] = t
    # Ex + Ey, then the rise's bound 2 (Ex + Ey) + 2.01 u r + u |h|, then the top's
    e_xy = ((2.0 * u * (1.0 + 2.0 * u)) * (fabs(ux) + fabs(uy)) * det
            + 8.0 * u * (fabs(t1) + fabs(t2) + fabs(t3) + fabs(t4)) + (fabs(ux) + fabs(uy)) * e_det) * (2.0 * inv_det)
    e_t = (2.0 * e_xy + 2.01 * u * r + u * fabs(h) + u * fabs(t)) * (1.0 + 1e-6) + 2.0 * u * fabs(t) + EVENT_SLACK
    if not (e_t < INFINITY) or not (fabs(t) < INFINITY) or e_t > EVENT_LOOSE * (fabs(t) + r):
        return False                # (a loose bound: a thin triangle, which circle_top bounds better)
    lo[0] = t - e_t
    hi[0] = t + e_t
    return True


cdef inline void circle_top(double ax, double ay, double bx, double by, double cx, double cy,
                            double* top, double* lo, double* hi, double* base, double* rise, double* rise_err,
                            double* centre_x, double* centre_y) noexcept nogil:
    """The top of the circle through a, b, c (counter-clockwise): rounded, and an interval that holds it.

    Also the top as base + rise, base the highest site's y, with |rise - exact rise| <= rise_err: near
    ties between tops (or a top and a site) much closer than an ulp of the top itself are often settled
    by the rises, whose error is a few u of the rise, not of the top (relative_sign below).
    """
    cdef double u = EPSILON
    cdef double abx = bx - ax, aby = by - ay, bcx = cx - bx, bcy = cy - by, cax = ax - cx, cay = ay - cy
    cdef double ab2 = abx * abx + aby * aby, bc2 = bcx * bcx + bcy * bcy, ca2 = cax * cax + cay * cay
    cdef double ox, oy, kx, ky, bdx, bdy, cdx, cdy, bb, cc, dkx, dky, wx, wy, e_wx, e_wy
    cdef double p1, p2, det, e_det, inv_det, t1, t2, t3, t4, ux, uy, r, h, t, e_x, e_y, e_r, e_s, e_h, e_t
    cdef double s = 0.0, inv_s = 0.0
    # the origin: the site opposite the longest side, so that the centre's offsets from it come without
    # cancellation; B and C run from it to the other two, counter-clockwise (the differences are reused)
    if ca2 > bc2 and ca2 >= ab2:
        ox = bx; oy = by; bdx = bcx; bdy = bcy; cdx = -abx; cdy = -aby; bb = bc2; cc = ab2
    elif ab2 > bc2 and ab2 > ca2:
        ox = cx; oy = cy; bdx = cax; bdy = cay; cdx = -bcx; cdy = -bcy; bb = ca2; cc = bc2
    else:
        ox = ax; oy = ay; bdx = abx; bdy = aby; cdx = -cax; cdy = -cay; bb = ab2; cc = ca2
    # the highest site: the rise is measured from it
    kx = ax; ky = ay
    if by > ky:
        kx = bx; ky = by
    if cy > ky:
        kx = cx; ky = cy
    base[0] = ky
    p1 = bdx * cdy; p2 = bdy * cdx
    det = 2.0 * (p1 - p2)
    e_det = 2.0 * CCW_ERRBOUND_A * (fabs(p1) + fabs(p2))
    # a nearly collinear triple gets its determinant to within an ulp (else the bound below is loose)
    if not (e_det < EVENT_REFINE * det) and (
            usable_coordinate(ax) and usable_coordinate(ay) and usable_coordinate(bx)
            and usable_coordinate(by) and usable_coordinate(cx) and usable_coordinate(cy)):
        det = 2.0 * orient_rounded(ax, ay, bx, by, cx, cy)
        e_det = 2.001 * u * fabs(det)
    # the centre, relative to the origin, and relative to the highest site
    inv_det = 1.0 / det
    t1 = cdy * bb; t2 = bdy * cc; t3 = bdx * cc; t4 = cdx * bb
    ux = (t1 - t2) * inv_det
    uy = (t3 - t4) * inv_det
    r = sqrt(ux * ux + uy * uy)
    centre_x[0] = ox + ux
    centre_y[0] = oy + uy
    dkx = ox - kx; dky = oy - ky
    wx = dkx + ux
    wy = dky + uy
    # the rise above the highest site: wy + r, or without cancellation when the centre lies below it
    if wy >= 0.0:
        h = wy + r
    else:
        s = r - wy
        inv_s = 1.0 / s
        h = wx * wx * inv_s
    t = ky + h
    top[0] = t
    rise[0] = h
    # the error bounds; a determinant or a denominator known to less than half its size gives up
    if not (e_det <= 0.5 * det) or not (usable_difference(bdx) and usable_difference(bdy)
                                        and usable_difference(cdx) and usable_difference(cdy)
                                        and usable_difference(dkx) and usable_difference(dky)):
        lo[0] = -INFINITY
        hi[0] = INFINITY
        rise_err[0] = INFINITY
        return
    # (quotients through a rounded inverse: 2 u each; 1 / (det - e_det) <= 2 / det)
    e_x = (2.0 * u * fabs(ux) * det * (1.0 + 2.0 * u) + 8.0 * u * (fabs(t1) + fabs(t2)) + fabs(ux) * e_det) \
        * (2.0 * inv_det)
    e_y = (2.0 * u * fabs(uy) * det * (1.0 + 2.0 * u) + 8.0 * u * (fabs(t3) + fabs(t4)) + fabs(uy) * e_det) \
        * (2.0 * inv_det)
    e_r = 2.01 * u * r + e_x + e_y
    e_wx = e_x + u * fabs(dkx) * (1.0 + u) + u * fabs(wx)
    e_wy = e_y + u * fabs(dky) * (1.0 + u) + u * fabs(wy)
    if wy >= 0.0:
        e_h = e_wy + e_r + u * h
    else:
        e_s = e_r + e_wy + u * s
        if not (e_s <= 0.5 * s):
            lo[0] = -INFINITY
            hi[0] = INFINITY
            rise_err[0] = INFINITY
            return
        # (h = wx^2 * fl(1 / s): three roundings; 1 / (s - e_s) <= 2 / s)
        e_h = (3.0 * u * h * s * (1.0 + 4.0 * u) + e_wx * (2.0 * fabs(wx) + e_wx) + h * e_s) * (2.0 * inv_s)
    # the slack: with every nonzero difference >= 2^-250 the radius is >= 2^-251, so at most the squares
    # of a centre offset below 2^-511 underflow, each by <= 2^-1074, and nothing divides them by less
    # than 2^-251 without the interval being (-inf, inf) already
    e_t = (e_h + u * fabs(t)) * (1.0 + 1e-6) + 2.0 * u * fabs(t) + EVENT_SLACK
    if not (e_t < INFINITY) or not (fabs(t) < INFINITY):
        lo[0] = -INFINITY
        hi[0] = INFINITY
        rise_err[0] = INFINITY
        return
    lo[0] = t - e_t
    hi[0] = t + e_t
    rise_err[0] = e_h * (1.0 + 1e-6) + EVENT_SLACK


cdef inline int relative_sign(double base_i, double rise_i, double err_i,
                              double base_j, double rise_j, double err_j) noexcept nogil:
    """Sign of (base_i + rise_i) - (base_j + rise_j) for exact rises within err_i, err_j of these; 0: unsure.

    The bases (site coordinates) are subtracted exactly (two_diff), so only the rises' errors and
    three roundings count. A site is the case rise_j = err_j = 0.
    """
    cdef double d1, d0, dh, s1, tot, err
    d1, d0 = two_diff(base_i, base_j)
    dh = rise_i - rise_j
    s1 = d0 + dh
    tot = d1 + s1
    err = (err_i + err_j + EPSILON * (fabs(dh) + fabs(s1) + fabs(tot))) * (1.0 + 1e-6) + EVENT_SLACK
    if tot > err:
        return 1
    if -tot > err:
        return -1
    return 0


# ---------------------------------------------------------------------------------------------------------
# the second filter, for near ties: the same top in double-double arithmetic (about 106 bits)
#
# Sites within 1e-16 of a line, or the two triangles of a near-cocircular quad (every square of a noisy
# lattice), give circle events whose tops differ from each other and from the next sites by less than a
# double's ulp; exact integer arithmetic for each of those comparisons would cost ~10 us. The same
# computation in double-double arithmetic (pairs hi + lo of doubles, hardware operations only) separates
# them. Its error bound repeats the one above with u replaced by U = 2^-100 per operation: the
# double-double operations below are the accurate ones of Joldes, Muller and Popescu (2017), whose
# relative errors are at most 3 u^2 (sum), 7 u^2 (product) and 15 u^2 + 56 u^3 (quotient), u = 2^-53,
# all below 64 u^2 = U. Except:
#   - the coordinate differences are exact double-doubles (two_diff);
#   - no underflow: every nonzero difference must lie in [2^-200, 2^200] and the centre offsets and the
#     radius above 2^-300, so that each low part stays a normal double; else the filter gives up;
#   - the square root is one Newton step from the double square root of the high part: relative error
#     below e0^2 / 2 + 3 U with e0 < 2^-52, so |r - R| <= 2^-98 r + Ex + Ey;
#   - the bound is computed in doubles from the high parts (about 30 operations, each within 2^-53, and
#     the high parts within 2^-52 of the values): a factor 1 + 2^-40 covers them.

cdef extern from *:
    """
    /* 2^-100, 2^-98, 2^-40, 2^-200, 2^200, 2^-300 as exact double constants */
    #define TVORONOI_DD_EPS 0x1p-100
    #define TVORONOI_DD_SQRT_ERR 0x1p-98
    #define TVORONOI_DD_BOUND_SLACK 0x1p-40
    #define TVORONOI_DD_TINY_DIFF 0x1p-200
    #define TVORONOI_DD_HUGE_DIFF 0x1p200
    #define TVORONOI_DD_TINY 0x1p-300
    """
    const double DD_EPS "TVORONOI_DD_EPS"
    const double DD_SQRT_ERR "TVORONOI_DD_SQRT_ERR"
    const double DD_BOUND_SLACK "TVORONOI_DD_BOUND_SLACK"
    const double DD_TINY_DIFF "TVORONOI_DD_TINY_DIFF"
    const double DD_HUGE_DIFF "TVORONOI_DD_HUGE_DIFF"
    const double DD_TINY "TVORONOI_DD_TINY"


cdef inline (double, double) dd_add(double ah, double al, double bh, double bl) noexcept nogil:
    # (ah + al) + (bh + bl), relative error <= 3 u^2 (AccurateDWPlusDW)
    cdef double sh, sl, th, tl
    sh, sl = two_sum(ah, bh)
    th, tl = two_sum(al, bl)
    sl = sl + th
    sh, sl = fast_two_sum(sh, sl)
    sl = sl + tl
    return fast_two_sum(sh, sl)


cdef inline (double, double) dd_mul(double ah, double al, double bh, double bl) noexcept nogil:
    # (ah + al) (bh + bl), relative error <= 7 u^2 (DWTimesDW1, no fused multiply-add)
    cdef double ch, cl
    ch, cl = two_product(ah, bh)
    cl = cl + (ah * bl + al * bh)
    return fast_two_sum(ch, cl)


cdef inline (double, double) dd_div(double ah, double al, double bh, double bl) noexcept nogil:
    # (ah + al) / (bh + bl), relative error <= 15 u^2 + 56 u^3 (DWDivDW2)
    cdef double th = ah / bh, rh, rl, ph, pl, d
    rh, rl = two_product(bh, th)
    rl = rl + bl * th
    rh, rl = fast_two_sum(rh, rl)
    ph, pl = dd_add(ah, al, -rh, -rl)
    d = ph / bh
    return fast_two_sum(th, d)


cdef inline bint dd_difference(double a, double b, double* h, double* l) noexcept nogil:
    """a - b as an exact double-double; False when it is nonzero and outside [2^-200, 2^200]."""
    h[0], l[0] = two_diff(a, b)
    cdef double m = fabs(h[0])
    return m == 0.0 or (DD_TINY_DIFF <= m <= DD_HUGE_DIFF)


cdef inline bint circle_top_fine(double ax, double ay, double bx, double by, double cx, double cy,
                                 double* fine) noexcept nogil:
    """The top of the circle through a, b, c (counter-clockwise) in double-double precision:
    fine[0] + fine[1] within fine[2] of the exact top.

    False when this filter cannot bound it (differences out of its range, a nearly collinear triple).
    """
    cdef double u = DD_EPS
    cdef double bdx, bdxl, bdy, bdyl, cdx, cdxl, cdy, cdyl
    cdef double p1, p1l, p2, p2l, det, detl, e_det, margin, bb, bbl, cc, ccl, q, ql
    cdef double t1, t1l, t2, t2l, t3, t3l, t4, t4l, ux, uxl, uy, uyl, x, xl, r0, r, rl
    cdef double h, hl, t, tl, sv = 0.0, svl = 0.0, e_x, e_y, e_r, e_s, e_h
    if not (dd_difference(bx, ax, &bdx, &bdxl) and dd_difference(by, ay, &bdy, &bdyl)
            and dd_difference(cx, ax, &cdx, &cdxl) and dd_difference(cy, ay, &cdy, &cdyl)):
        return False
    p1, p1l = dd_mul(bdx, bdxl, cdy, cdyl)
    p2, p2l = dd_mul(bdy, bdyl, cdx, cdxl)
    det, detl = dd_add(p1, p1l, -p2, -p2l)
    det = 2.0 * det
    detl = 2.0 * detl
    # (each product rounded once, the difference once: 4 U of the permanent covers both)
    e_det = 8.0 * u * (fabs(p1) + fabs(p2)) * (1.0 + DD_BOUND_SLACK)
    margin = det - e_det
    if not (margin > det / 2):
        return False
    # the centre, relative to a, and the radius (one Newton step from the double square root)
    bb, bbl = dd_mul(bdx, bdxl, bdx, bdxl)
    q, ql = dd_mul(bdy, bdyl, bdy, bdyl)
    bb, bbl = dd_add(bb, bbl, q, ql)
    cc, ccl = dd_mul(cdx, cdxl, cdx, cdxl)
    q, ql = dd_mul(cdy, cdyl, cdy, cdyl)
    cc, ccl = dd_add(cc, ccl, q, ql)
    t1, t1l = dd_mul(cdy, cdyl, bb, bbl)
    t2, t2l = dd_mul(bdy, bdyl, cc, ccl)
    t3, t3l = dd_mul(bdx, bdxl, cc, ccl)
    t4, t4l = dd_mul(cdx, cdxl, bb, bbl)
    q, ql = dd_add(t1, t1l, -t2, -t2l)
    ux, uxl = dd_div(q, ql, det, detl)
    q, ql = dd_add(t3, t3l, -t4, -t4l)
    uy, uyl = dd_div(q, ql, det, detl)
    if (ux != 0.0 and fabs(ux) < DD_TINY) or (uy != 0.0 and fabs(uy) < DD_TINY):
        return False
    x, xl = dd_mul(ux, uxl, ux, uxl)
    q, ql = dd_mul(uy, uyl, uy, uyl)
    x, xl = dd_add(x, xl, q, ql)
    r0 = sqrt(x)
    if not (r0 > DD_TINY and r0 < INFINITY):
        return False
    q, ql = dd_div(x, xl, r0, 0.0)
    r, rl = dd_add(r0, 0.0, q, ql)
    r = 0.5 * r
    rl = 0.5 * rl
    # the top, without cancellation when the centre lies below a
    if uy >= 0:
        h, hl = dd_add(uy, uyl, r, rl)
    else:
        sv, svl = dd_add(r, rl, -uy, -uyl)
        q, ql = dd_mul(ux, uxl, ux, uxl)
        h, hl = dd_div(q, ql, sv, svl)
    t, tl = dd_add(ay, 0.0, h, hl)
    # its error bound (in doubles, from the high parts; see the notes above)
    e_x = (u * fabs(ux) * det * (1 + 2 * u) + 8 * u * (fabs(t1) + fabs(t2)) + fabs(ux) * e_det) / margin
    e_y = (u * fabs(uy) * det * (1 + 2 * u) + 8 * u * (fabs(t3) + fabs(t4)) + fabs(uy) * e_det) / margin
    e_r = DD_SQRT_ERR * r + e_x + e_y
    if uy >= 0:
        e_h = e_y + e_r + u * h
    else:
        e_s = e_r + e_y + u * sv
        if not (sv > e_s * (1.0 + DD_BOUND_SLACK)):
            return False
        e_h = (u * h * sv * (1 + 2 * u) + e_x * (2 * fabs(ux) + e_x) + u * ux * ux + h * e_s) / (sv - e_s)
    fine[0] = t
    fine[1] = tl
    fine[2] = ((e_h + u * fabs(t)) * (1 + DD_BOUND_SLACK) + 2 * u * fabs(t)) * (1 + DD_BOUND_SLACK)
    return True


cdef inline int fine_sign(double dh, double dl, double slack) noexcept nogil:
    """Sign of an exact value within slack of the double-double dh + dl, itself the rounded difference of
    two double-doubles (relative error 3 u^2); 0 when the slack hides it."""
    slack = slack * (1 + DD_BOUND_SLACK) + DD_EPS * 4 * fabs(dh)
    if dh > slack:
        return 1
    if -dh > slack:
        return -1
    return 0


cdef inline int fine_order(const double* f, const double* g) noexcept nogil:
    """Sign of top f - top g for two fine tops (hi, lo, err); 0 when their bounds overlap."""
    cdef double dh, dl
    dh, dl = dd_add(f[0], f[1], -g[0], -g[1])
    return fine_sign(dh, dl, f[2] + g[2])


cdef inline int fine_site(const double* f, double y) noexcept nogil:
    """Sign of top f - y; 0 when the bound hides it."""
    cdef double dh, dl
    dh, dl = dd_add(f[0], f[1], -y, 0.0)
    return fine_sign(dh, dl, f[2])
