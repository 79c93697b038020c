# Correctly rounded constructions and the exact tests that go with them, compiled inline where cimported.
#
# Every coordinate tvoronoi writes that is neither an input coordinate nor a box side is made here:
#
#   circumcentre(a, b, c)    the Voronoi vertex of three sites
#   bisector_at_x(a, b, X)   the y where the bisector of sites a and b crosses the vertical line x = X
#   bisector_at_y(a, b, Y)   the x where it crosses the horizontal line y = Y
#
# Sites (and X, Y) are given in a kernel's scaled unit; each result is the double nearest to 2^e times
# the exact value (ties to even), 2^e mapping the scaled unit back to the user's. A vertex computed
# by any engine, any tile or any update is therefore the same double, bit for bit.
#
# Correct rounding is monotone, so a constructed value compares with any double (a box side) exactly
# as the exact value does -- except when the two are equal. The sign tests below settle those ties:
#
#   circumcentre_side(a, b, c, X, axis)   sign of (exact circumcentre coordinate) - X
#   bisector_side(Kx, Ky, a, b)           sign of |K - a|^2 - |K - b|^2 (-1: K nearer to a)
#
# Method: the exact value is a quotient p / q of two expansions (tvoronoi.kernels.predicates). A double
# estimate r of it is refined by comparing p with (r +- half a gap) * q exactly until r is the nearest
# double. The circumcentre first tries plain doubles with a proven error bound and returns at once
# when the bound shows that the rounding is already correct (about 5 vertices in 6 of uniform sites),
# then pairs of doubles or long double the same way (nearly all of the rest). circumcentres_block does
# the first tier for a block of triangles in one loop the compiler vectorizes (the dual's way), and
# calls circumcentre for what it leaves open: the same doubles.

cimport cython
from libc.math cimport fabs, fabsl, frexp, ldexp, nextafter, INFINITY
from libc.string cimport memcpy
from libc.stdint cimport uint64_t

from tvoronoi.kernels.predicates cimport (
    EPSILON, CCW_ERRBOUND_A, two_sum, two_diff, two_diff_tail, two_square, two_product, two_two_diff, expansion_sign,
    fast_expansion_sum_zeroelim,
    scale_expansion_zeroelim, expansion_product, negate_expansion, difference_expansion,
)

cdef extern from *:
    """
    #include <float.h>
    /* the unit roundoff of long double: 2^-64 for x87 extended, 2^-53 where long double is double */
    #define TVORONOI_LDBL_EPS (LDBL_EPSILON / 2.0L)
    #include <stdint.h>
    #include <string.h>
    /* Half the smaller of the two gaps between s and its neighbouring doubles, from s's bits (no libm
       call). 0 where that is not a normal double or the neighbour may not be: s zero, subnormal or
       near the bottom of the normal range, in the top binade, infinite or NaN; a caller then proves
       nothing and takes its slow path. s = 1.f 2^(ex - 1023) has gaps of 2^(ex - 1075), except a
       power of two, whose gap toward zero is half that. */
    static inline double tvoronoi_half_gap(double s) {
        uint64_t b, h;
        double r;
        memcpy(&b, &s, sizeof b);
        uint64_t ex = (b >> 52) & 0x7ff;
        if (ex <= 54 || ex >= 0x7fe) return 0.0;
        h = ((b & 0xfffffffffffffULL) == 0 ? ex - 54 : ex - 53) << 52;
        memcpy(&r, &h, sizeof r);
        return r;
    }
    /* 2^e as a double, for -1022 <= e <= 1023 */
    static inline double tvoronoi_pow2(int e) {
        uint64_t b = (uint64_t)(e + 1023) << 52;
        double r;
        memcpy(&r, &b, sizeof r);
        return r;
    }
    """
    const long double LDBL_EPS "TVORONOI_LDBL_EPS"
    double half_gap "tvoronoi_half_gap"(double s) noexcept nogil
    double pow2 "tvoronoi_pow2"(int e) noexcept nogil

cdef enum:
    # largest expansions met here: a circumcentre's numerator (3 terms of 16) and denominator (3 of 4)
    P_MAX = 48
    Q_MAX = 12
    # a refinement never needs more than a few steps from an estimate within a few ulps; the bound
    # only guarantees that a loop ends
    MAX_REFINE = 64


cdef inline double estimate(int n, const double* e) noexcept nogil:
    # the value of an expansion to about one rounding (components summed from the smallest)
    cdef double s = 0.0
    cdef int i
    for i in range(n):
        s += e[i]
    return s


cdef inline bint is_even(double r) noexcept nogil:
    cdef uint64_t bits
    memcpy(&bits, &r, sizeof(double))
    return (bits & 1) == 0


cdef inline int sign_p_minus_mq(int n_p, const double* p, int n_q, const double* q,
                                double m_hi, double m_lo) noexcept nogil:
    # sign of p - (m_hi + m_lo) * q, exactly
    cdef double t_hi[2 * Q_MAX]
    cdef double t_lo[2 * Q_MAX]
    cdef double mq[4 * Q_MAX]
    cdef double d[P_MAX + 4 * Q_MAX]
    cdef int n_hi = scale_expansion_zeroelim(n_q, q, m_hi, t_hi), n_lo, n_mq
    if m_lo != 0.0:
        n_lo = scale_expansion_zeroelim(n_q, q, m_lo, t_lo)
        n_mq = fast_expansion_sum_zeroelim(n_hi, t_hi, n_lo, t_lo, mq)
    else:
        memcpy(mq, t_hi, n_hi * sizeof(double))
        n_mq = n_hi
    negate_expansion(n_mq, mq)
    return expansion_sign(fast_expansion_sum_zeroelim(n_p, p, n_mq, mq, d), d)


cdef inline double round_quotient(int n_p, double* p, int n_q, double* q, int e) noexcept nogil:
    """The double nearest to 2^e * p / q (ties to even); q must not be zero. p and q are scratch:
    they may be negated in place.

    Beyond the double range the result is an infinity; where the exact value lies so far below the
    smallest subnormal that a half gap cannot be formed in the scaled unit, the estimate is returned
    (a value within one subnormal step of the exact one).
    """
    cdef int s_q = expansion_sign(n_q, q), s_p, k, ep, eq, s
    cdef double pa, qa, mp, mq, r, up, down, r_s, half, gap
    if s_q < 0:
        negate_expansion(n_p, p)
        negate_expansion(n_q, q)
    s_p = expansion_sign(n_p, p)
    if s_p == 0:
        return 0.0
    pa = estimate(n_p, p)
    qa = estimate(n_q, q)
    mp = frexp(pa, &ep)
    mq = frexp(qa, &eq)
    r = ldexp(mp / mq, ep - eq + e)
    if r == INFINITY or r == -INFINITY:
        return r
    for k in range(MAX_REFINE):
        r_s = ldexp(r, -e)
        if ldexp(r_s, e) != r:
            return r                        # r's scaled form underflows: nothing finer can be formed
        # is the exact value above the midpoint between r and the next double up?
        up = nextafter(r, INFINITY)
        gap = (r - nextafter(r, -INFINITY)) if up == INFINITY else up - r   # past the largest double: the gap below
        half = ldexp(gap, -e - 1)
        if ldexp(half, e + 1) != gap:
            return r                        # half a gap is not representable in the scaled unit
        s = sign_p_minus_mq(n_p, p, n_q, q, r_s, half)
        if s > 0:
            r = up
            if r == INFINITY:
                return r
            continue
        if s == 0:
            return r if is_even(r) else up
        # below the midpoint between the next double down and r?
        down = nextafter(r, -INFINITY)
        if down == -INFINITY:
            return r
        gap = r - down
        half = ldexp(gap, -e - 1)
        if ldexp(half, e + 1) != gap:
            return r
        s = sign_p_minus_mq(n_p, p, n_q, q, r_s, -half)
        if s < 0:
            r = down
            continue
        if s == 0:
            return r if is_even(r) else down
        return r
    return r


# ---------------------------------------------------------------------------------------------------------
# the circumcentre
#
#   D  = 2 (ax (by - cy) + bx (cy - ay) + cx (ay - by))
#   Ux = (|a|^2 (by - cy) + |b|^2 (cy - ay) + |c|^2 (ay - by)) / D
#   Uy = (|a|^2 (cx - bx) + |b|^2 (ax - cx) + |c|^2 (bx - ax)) / D

cdef inline int lifted_times_diff(double x, double y, double u, double v, double* h) noexcept nogil:
    # (x^2 + y^2) * (u - v) exactly (h: 16 components)
    cdef double sq[4]
    cdef double d[2]
    cdef double work[16]
    cdef double scaled[8]
    cdef double x1, x0, y1, y0, d1, d0
    cdef double xx[2]
    cdef double yy[2]
    cdef int n_sq, n_d
    x1, x0 = two_square(x)
    y1, y0 = two_square(y)
    xx[0] = x0; xx[1] = x1
    yy[0] = y0; yy[1] = y1
    n_sq = fast_expansion_sum_zeroelim(2, xx, 2, yy, sq)
    d1, d0 = two_diff(u, v)
    n_d = difference_expansion(d1, d0, d)
    return expansion_product(n_sq, sq, n_d, d, h, work, scaled)


cdef inline int coord_times_diff(double x, double u, double v, double* h) noexcept nogil:
    # x * (u - v) exactly (h: 4 components)
    cdef double d[2]
    cdef double d1, d0
    d1, d0 = two_diff(u, v)
    cdef int n_d = difference_expansion(d1, d0, d)
    return scale_expansion_zeroelim(n_d, d, x, h)


cdef inline int sum3(int n1, const double* t1, int n2, const double* t2, int n3, const double* t3,
                     double* h) noexcept nogil:
    cdef double s12[P_MAX]
    cdef int n12 = fast_expansion_sum_zeroelim(n1, t1, n2, t2, s12)
    return fast_expansion_sum_zeroelim(n12, s12, n3, t3, h)


cdef inline int circumcentre_denominator(double ax, double ay, double bx, double by, double cx, double cy,
                                         double* h) noexcept nogil:
    # D (h: Q_MAX components)
    cdef double t1[4]
    cdef double t2[4]
    cdef double t3[4]
    cdef int n1 = coord_times_diff(ax, by, cy, t1)
    cdef int n2 = coord_times_diff(bx, cy, ay, t2)
    cdef int n3 = coord_times_diff(cx, ay, by, t3)
    cdef int n = sum3(n1, t1, n2, t2, n3, t3, h), k
    for k in range(n):
        h[k] *= 2.0
    return n


cdef inline int circumcentre_numerator(double ax, double ay, double bx, double by, double cx, double cy,
                                       bint along_y, double* h) noexcept nogil:
    # the numerator of Ux (along_y false) or of Uy (h: P_MAX components)
    cdef double t1[16]
    cdef double t2[16]
    cdef double t3[16]
    cdef int n1, n2, n3
    if not along_y:
        n1 = lifted_times_diff(ax, ay, by, cy, t1)
        n2 = lifted_times_diff(bx, by, cy, ay, t2)
        n3 = lifted_times_diff(cx, cy, ay, by, t3)
    else:
        n1 = lifted_times_diff(ax, ay, cx, bx, t1)
        n2 = lifted_times_diff(bx, by, ax, cx, t2)
        n3 = lifted_times_diff(cx, cy, bx, ax, t3)
    return sum3(n1, t1, n2, t2, n3, t3, h)


cdef inline void circumcentre_exact(double ax, double ay, double bx, double by, double cx, double cy, int e,
                                    double* ux, double* uy) noexcept nogil:
    cdef double num[P_MAX]
    cdef double den[Q_MAX]
    cdef int n_num, n_den
    n_den = circumcentre_denominator(ax, ay, bx, by, cx, cy, den)
    n_num = circumcentre_numerator(ax, ay, bx, by, cx, cy, False, num)
    ux[0] = round_quotient(n_num, num, n_den, den, e)
    n_den = circumcentre_denominator(ax, ay, bx, by, cx, cy, den)
    n_num = circumcentre_numerator(ax, ay, bx, by, cx, cy, True, num)
    uy[0] = round_quotient(n_num, num, n_den, den, e)


cdef inline int lifted_difference(double bax, double bay, double cax, double cay, double* h) noexcept nogil:
    # cay |b - a|^2 - bay |c - a|^2 from exact relative coordinates (h: 16 components): the x
    # numerator; called with (cay, cax, bay, bax) it gives bax |c - a|^2 - cax |b - a|^2, the y one
    cdef double sq_a[2]
    cdef double sq_b[2]
    cdef double bb[4]
    cdef double cc[4]
    cdef double t1[8]
    cdef double t2[8]
    cdef int n_bb, n_cc, n1, n2
    sq_a[1], sq_a[0] = two_square(bax)
    sq_b[1], sq_b[0] = two_square(bay)
    n_bb = fast_expansion_sum_zeroelim(2, sq_a, 2, sq_b, bb)
    sq_a[1], sq_a[0] = two_square(cax)
    sq_b[1], sq_b[0] = two_square(cay)
    n_cc = fast_expansion_sum_zeroelim(2, sq_a, 2, sq_b, cc)
    n1 = scale_expansion_zeroelim(n_bb, bb, cay, t1)
    n2 = scale_expansion_zeroelim(n_cc, cc, -bay, t2)
    return fast_expansion_sum_zeroelim(n1, t1, n2, t2, h)


cdef inline int offset_quotient(double a, int n_num, const double* num, const double* den2, double* p,
                                double* q) noexcept nogil:
    # a + num / den2 as p / q (p: a * den2 + num, up to 24 components; q: a copy of den2, 4)
    cdef double t[8]
    cdef int k, n_t = scale_expansion_zeroelim(4, den2, a, t)
    for k in range(4):
        q[k] = den2[k]
    return fast_expansion_sum_zeroelim(n_t, t, n_num, num, p)


cdef inline bint circumcentre_relative(double ax, double ay, double bx, double by, double cx, double cy,
                                       int e, double* ux, double* uy) noexcept nogil:
    """The exact path in coordinates relative to a, when b - a and c - a are exact doubles (nearby sites,
    the usual case): the centre is a + N / (2 D) with expansions of 4 to 24 components, where the
    general path forms 48 over 12. False (nothing written) when a difference is not exact."""
    cdef double bax, bay, cax, cay, t, l1, l0, r1, r0
    cdef double den2[4]
    cdef double num[16]
    cdef double p[P_MAX]
    cdef double q[Q_MAX]
    cdef int k, n_num, n_p
    bax, t = two_diff(bx, ax)
    if t != 0.0:
        return False
    bay, t = two_diff(by, ay)
    if t != 0.0:
        return False
    cax, t = two_diff(cx, ax)
    if t != 0.0:
        return False
    cay, t = two_diff(cy, ay)
    if t != 0.0:
        return False
    # 2 D = 2 (bax cay - bay cax), exactly (doubling is exact)
    l1, l0 = two_product(bax, cay)
    r1, r0 = two_product(bay, cax)
    two_two_diff(l1, l0, r1, r0, den2)
    for k in range(4):
        den2[k] *= 2.0
    # x: a_x + (cay |b - a|^2 - bay |c - a|^2) / (2 D)
    n_num = lifted_difference(bax, bay, cax, cay, num)
    n_p = offset_quotient(ax, n_num, num, den2, p, q)
    ux[0] = round_quotient(n_p, p, 4, q, e)
    # y: a_y + (bax |c - a|^2 - cax |b - a|^2) / (2 D)
    n_num = lifted_difference(cay, cax, bay, bax, num)
    n_p = offset_quotient(ay, n_num, num, den2, p, q)
    uy[0] = round_quotient(n_p, p, 4, q, e)
    return True


cdef inline bint rounds_alike(double a, double q, double w, int e, double* out) noexcept nogil:
    # a + Q for an exact Q with |Q - q| < w, where w also holds the slack for the rounding of q -+ w
    # (see circumcentre): when a + (q - w) and a + (q + w) round to the same double, so does a + Q, which
    # lies between them (rounding is monotone); then 2^e times it
    cdef double lo = a + (q - w)
    if lo != a + (q + w):
        return False
    return scaled_back(lo, e, out)


cdef inline bint scaled_back(double s, int e, double* out) noexcept nogil:
    # 2^e * s, if exact: no overflow, no subnormal result
    cdef double r
    if -1022 <= e <= 1023:
        r = s * pow2(e)             # exact, unless it overflows or turns subnormal (refused below)
    else:
        r = ldexp(s, e)
    if fabs(r) == INFINITY or (r != 0.0 and fabs(r) < 2.2250738585072014e-308) or (r == 0.0 and s != 0.0):
        return False
    out[0] = r
    return True


cdef inline bint settled_long(double a, long double u, long double err, int e, double* out) noexcept nogil:
    # a + u with |u - exact| <= err, u and err in long double (x87 extended where the platform has it):
    # is the rounding of a + exact to a double known? (then 2^e * it)
    cdef long double xl = <long double> a + u
    cdef double s = <double> xl
    # half the smaller gap beside s, from its bits (0 where s is not safely normal: nothing is proved)
    cdef long double hg = half_gap(s)
    # the sum's own rounding, then the interval against the midpoints narrowed to the nearer one
    # (each side formed exactly)
    err = (err + LDBL_EPS * fabsl(xl)) * (1.0 + 4.0 * LDBL_EPS)
    if not (xl + err < s + hg and xl - err > s - hg):
        return False
    return scaled_back(s, e, out)


cdef inline bint circumcentre_long(double ax, double ay, double bx, double by, double cx, double cy, int e,
                                   bint need_x, bint need_y, double* ux, double* uy) noexcept nogil:
    # the fast path again in long double, for the few vertices whose rounding the doubles left open
    # (need_x, need_y: the coordinates still open); the same error analysis with the long double unit
    # roundoff
    cdef long double bax = <long double> bx - ax, bay = <long double> by - ay
    cdef long double cax = <long double> cx - ax, cay = <long double> cy - ay
    cdef long double l = bax * cay, r = bay * cax
    cdef long double det = l - r, det_sum = fabsl(l) + fabsl(r)
    cdef long double err_det = (3.0 + 16.0 * LDBL_EPS) * LDBL_EPS * det_sum
    cdef long double adet = fabsl(det), bb, cc, tx1, tx2, ty1, ty2, nx, ny, inv, ig, qx, qy, wx, wy
    if not (adet > 8.0 * err_det):
        return False
    bb = bax * bax + bay * bay
    cc = cax * cax + cay * cay
    tx1 = cay * bb
    tx2 = bay * cc
    ty1 = bax * cc
    ty2 = cax * bb
    nx = tx1 - tx2
    ny = ty1 - ty2
    # q and its bound w as in circumcentre's doubles (one division), less the slack rounds_alike needs:
    # settled_long allows for the rounding of a + q itself
    inv = 0.5 / det
    qx = nx * inv
    qy = ny * inv
    ig = 2.00002 * inv * inv * (1.0 + 4.0 * err_det * fabsl(inv))
    wx = (fabsl(nx) * err_det + adet * 8.0 * LDBL_EPS * (fabsl(tx1) + fabsl(tx2))) * ig + 4.0 * LDBL_EPS * fabsl(qx)
    wy = (fabsl(ny) * err_det + adet * 8.0 * LDBL_EPS * (fabsl(ty1) + fabsl(ty2))) * ig + 4.0 * LDBL_EPS * fabsl(qy)
    return ((not need_x or settled_long(ax, qx, wx, e, ux))
            and (not need_y or settled_long(ay, qy, wy, e, uy)))


cdef inline bint in_pair_range(double v) noexcept nogil:
    # 0, or a size whose products of three stay normal doubles (so every product's roundoff is exact) and
    # whose splits cannot overflow
    cdef double m = fabs(v)
    return m == 0.0 or (1e-60 <= m <= 1e60)


cdef struct Estimate:
    # circumcentre's first tier: the centre relative to a in plain doubles (q) and the bound on its
    # error (w), with the values the second tier carries on
    double bax, bay, cax, cay, l, r, det, det_sum, err_det, bb, cc, tx1, tx2, ty1, ty2, nx, ny, inv, qx, qy, wx, wy


cdef struct PairTerms:
    # what circumcentre_pairs adds to an Estimate: the roundoffs of D (t) and of N's coordinates
    double t, nl_x, nl_y
    double tails    # the roundoffs of the four differences, in magnitude, summed: 0 when all are exact


cdef inline void pair_terms(double ax, double ay, double bx, double by, double cx, double cy, const Estimate* f,
                            PairTerms* p) noexcept nogil:
    """circumcentre_pairs' roundoffs (meaningful where the differences are exact and in_pair_range).
    Straight-line code, so that a loop over many triangles vectorizes."""
    cdef double x, sq1, sq2, lo_b, lo_c, lo1, lo2, lo3, lo4
    p.tails = (fabs(two_diff_tail(bx, ax, f.bax)) + fabs(two_diff_tail(by, ay, f.bay))
               + fabs(two_diff_tail(cx, ax, f.cax)) + fabs(two_diff_tail(cy, ay, f.cay)))
    p.t = two_diff_tail(f.l, f.r, f.det) + (two_product(f.bax, f.cay)[1] - two_product(f.bay, f.cax)[1])
    x, sq1 = two_square(f.bax)
    x, sq2 = two_square(f.bay)
    lo_b = two_sum(f.bax * f.bax, f.bay * f.bay)[1] + (sq1 + sq2)
    x, sq1 = two_square(f.cax)
    x, sq2 = two_square(f.cay)
    lo_c = two_sum(f.cax * f.cax, f.cay * f.cay)[1] + (sq1 + sq2)
    lo1 = two_product(f.cay, f.bb)[1] + f.cay * lo_b
    lo2 = two_product(f.bay, f.cc)[1] + f.bay * lo_c
    p.nl_x = two_diff_tail(f.tx1, f.tx2, f.nx) + (lo1 - lo2)
    lo3 = two_product(f.bax, f.cc)[1] + f.bax * lo_c
    lo4 = two_product(f.cax, f.bb)[1] + f.cax * lo_b
    p.nl_y = two_diff_tail(f.ty1, f.ty2, f.ny) + (lo3 - lo4)


cdef inline bint pairs_apply(const Estimate* f, const PairTerms* p) noexcept nogil:
    # the differences are exact and in_pair_range
    return (p.tails == 0.0 and in_pair_range(f.bax) and in_pair_range(f.bay) and in_pair_range(f.cax)
            and in_pair_range(f.cay))


cdef inline int circumcentre_pairs(double ax, double ay, double bx, double by, double cx, double cy,
                                    const Estimate* f, int e, bint need_x, bint need_y,
                                    double* ux, double* uy) noexcept nogil:
    """circumcentre's doubles carried on as pairs (a double and its roundoff), for the coordinates they
    left open (need_x, need_y), when the differences bax .. cay are exact and in_pair_range: N and D are
    then known within a few eps^2 of their size, and a centre nearly always settles. Returns 1: settled;
    0: some coordinate is still open (what settled is written); -1: not tried (a difference not exact,
    or out of range).

    With u = eps (2^-53) and every roundoff below exact (Dekker's products, two-sums; no underflow in
    range):
      D = det + t, t = (l - r - det) + (roundoff(l) - roundoff(r)): within 3.01 u^2 P, P = det_sum;
      |t| <= 2.01 u P
      |b - a|^2 = bb + lo_b, bb = fl(fl(bax^2) + fl(bay^2)), lo_b its three roundoffs summed: within
      3.01 u^2 bb, |lo_b| <= 2.01 u bb (the same for cc)
      cay |b - a|^2 = tx1 + lo1, lo1 = roundoff(cay bb) + fl(cay lo_b): within 8.1 u^2 |tx1|,
      |lo1| <= 3.03 u |tx1| (each term of N likewise)
      N_x = nx + nl, nl = (tx1 - tx2 - nx) + (lo1 - lo2): within 15.2 u^2 M, M = |tx1| + |tx2|,
      |nl| <= 4.1 u M
    (pair_terms) and pair_settled finishes each coordinate."""
    cdef PairTerms p
    cdef bint done_x = not need_x, done_y = not need_y
    pair_terms(ax, ay, bx, by, cx, cy, f, &p)
    if not pairs_apply(f, &p):
        return -1
    if need_x:
        done_x = pair_settled(ax, f.nx, p.nl_x, fabs(f.tx1) + fabs(f.tx2), f.det, p.t, f.det_sum, f.inv, f.qx,
                              e, ux)
    if need_y:
        done_y = pair_settled(ay, f.ny, p.nl_y, fabs(f.ty1) + fabs(f.ty2), f.det, p.t, f.det_sum, f.inv, f.qy,
                              e, uy)
    return 1 if done_x and done_y else 0


cdef inline void pair_interval(double a, double ns, double nl, double m, double s, double t, double p,
                               double inv, double q1, double* lo, double* hi) noexcept nogil:
    """a + N / (2 D), N = ns + nl within 15.2 u^2 m, D = s + t within 3.01 u^2 p (|t| <= 2.01 u p, and
    |s| > 24 u p: circumcentre's guard), q1 = fl(ns inv), inv = fl(0.5 / s): rounds_alike's interval
    for it, [lo, hi] (it settles where they are equal).

    2 s q1 = r1 + r1e exactly, and ns - r1 = h exactly (r1 is within three roundings of ns), so
    N - 2 D q1 = rp + E, rp = ((h - r1e) + nl) - 2 t q1 as computed (four roundings of terms below
    4.1 u (|ns| + m + p |q1|)), |E| <= u^2 (17 |ns| + 42 m + 26 p |q1|); then with q2 = fl(rp inv),
    |N / (2 D) - q1 - q2| <= u |q2| (5 p |inv| + 2.1) + 1.11 u^2 (17 |ns| + 42 m + 26 p |q1|) |inv|
    (1 / (2 D) = inv (1 + rho), |rho| <= 2.2 u p / |s| < 0.1), which w2 bounds with room; a + q1 = s0 + s1
    exactly, and s1 + q2 rounds to sm."""
    cdef double r1, r1e, h, rp, q2, w2, s0, s1, sm, w, u = EPSILON
    r1, r1e = two_product(2.0 * s, q1)
    h = ns - r1
    rp = ((h - r1e) + nl) - 2.0 * t * q1
    q2 = rp * inv
    w2 = 64.0 * u * u * (fabs(ns) + m + p * fabs(q1)) * fabs(inv) + 8.0 * u * (1.0 + p * fabs(inv)) * fabs(q2)
    s0, s1 = two_sum(a, q1)
    sm = s1 + q2
    # rounds_alike's slack: the bound, the rounding of sm, and w's own (w (1 - u) >= w2 + 2 u |sm|)
    w = 1.0001 * w2 + 3.0 * u * fabs(sm) + 1e-300
    lo[0] = s0 + (sm - w)
    hi[0] = s0 + (sm + w)


cdef inline bint pair_settled(double a, double ns, double nl, double m, double s, double t, double p, double inv,
                              double q1, int e, double* out) noexcept nogil:
    # pair_interval's rounding if it settles (then 2^e times it; rounds_alike)
    cdef double lo, hi
    pair_interval(a, ns, nl, m, s, t, p, inv, q1, &lo, &hi)
    return lo == hi and scaled_back(lo, e, out)


cdef inline bint usable(double det, double err_det, double det_sum) noexcept nogil:
    # an Estimate's bound holds: the determinant is well clear of its error, and nothing underflows
    return fabs(det) > 8.0 * err_det and det_sum > 1e-280


@cython.cdivision(True)     # det == 0 gives inf, never an exception (and the estimate is not usable)
cdef inline void estimate_centre(double ax, double ay, double bx, double by, double cx, double cy,
                                 Estimate* f) noexcept nogil:
    """The plain-double estimate of the circumcentre of a, b, c relative to a, and its error bound (only
    meaningful where usable(f.det, f.err_det, f.det_sum)). Straight-line code, so that a loop over many
    triangles vectorizes."""
    cdef double err_det, adet, ig
    f.bax = bx - ax
    f.bay = by - ay
    f.cax = cx - ax
    f.cay = cy - ay
    f.l = f.bax * f.cay
    f.r = f.bay * f.cax
    f.det = f.l - f.r
    f.det_sum = fabs(f.l) + fabs(f.r)
    err_det = CCW_ERRBOUND_A * f.det_sum
    f.err_det = err_det
    adet = fabs(f.det)
    f.bb = f.bax * f.bax + f.bay * f.bay
    f.cc = f.cax * f.cax + f.cay * f.cay
    f.tx1 = f.cay * f.bb
    f.tx2 = f.bay * f.cc
    f.ty1 = f.bax * f.cc
    f.ty2 = f.cax * f.bb
    f.nx = f.tx1 - f.tx2
    f.ny = f.ty1 - f.ty2
    # q = n / (2 det) by one division: q = n * inv, two roundings, |q - n / (2 det)| <= 3 eps |q|
    f.inv = 0.5 / f.det
    f.qx = f.nx * f.inv
    f.qy = f.ny * f.inv
    # |n - N| <= 8 eps (|terms|) (seven roundings on each term); |det - D| <= err_det; then
    # |n / (2 det) - N / (2 D)| <= A / (2 |det| (|det| - err_det)), A = |n| err_det + |det| err_n, and with
    # r = err_det / |det| < 1/8: 1 / (2 |det| (|det| - err_det)) = 2 inv^2 / (1 - r) <= 2 inv^2 (1 + 4 err_det |inv|)
    # (the factor 1 + 1e-5 covers the rounding of the bound itself)
    ig = 2.00002 * f.inv * f.inv * (1.0 + 4.0 * err_det * fabs(f.inv))
    # w: the bound, plus what rounds_alike needs for the rounding of q -+ w: w (1 - eps) >= bound + eps |q|
    # (6 eps |q| for the division's 3 and this 2, with room; 1e-300 for roundings below the normal range)
    f.wx = (fabs(f.nx) * err_det + adet * 8.0 * EPSILON * (fabs(f.tx1) + fabs(f.tx2))) * ig + 6.0 * EPSILON * fabs(f.qx) + 1e-300
    f.wy = (fabs(f.ny) * err_det + adet * 8.0 * EPSILON * (fabs(f.ty1) + fabs(f.ty2))) * ig + 6.0 * EPSILON * fabs(f.qy) + 1e-300


cdef inline void circumcentre(double ax, double ay, double bx, double by, double cx, double cy, int e,
                              double* ux, double* uy) noexcept nogil:
    """The circumcentre of a, b, c (not collinear), each coordinate correctly rounded, times 2^e."""
    cdef Estimate f
    cdef bint done_x, done_y
    cdef int pairs
    estimate_centre(ax, ay, bx, by, cx, cy, &f)
    # fast path: relative coordinates in doubles, with a bound on their error
    if usable(f.det, f.err_det, f.det_sum):
        done_x = rounds_alike(ax, f.qx, f.wx, e, ux)
        done_y = rounds_alike(ay, f.qy, f.wy, e, uy)
        if done_x and done_y:
            return
        # the coordinates the doubles left open (rarely both): as pairs of doubles where the differences
        # are exact (nearly always; what the pairs leave open is within a few eps^2 of a tie, beyond long
        # double too), else in long double
        pairs = circumcentre_pairs(ax, ay, bx, by, cx, cy, &f, e, not done_x, not done_y, ux, uy)
        if pairs == 1:
            return
        if pairs == -1 and circumcentre_long(ax, ay, bx, by, cx, cy, e, not done_x, not done_y, ux, uy):
            return
    if circumcentre_relative(ax, ay, bx, by, cx, cy, e, ux, uy):
        return
    circumcentre_exact(ax, ay, bx, by, cx, cy, e, ux, uy)


cdef enum:
    CENTRE_BLOCK = 64     # triangles a block of circumcentres gathers (circumcentres_block)


cdef inline void circumcentres_block(int k, const double* ax, const double* ay, const double* bx,
                                     const double* by, const double* cx, const double* cy, int e,
                                     double* out, int out_stride) noexcept nogil:
    """circumcentre of k <= CENTRE_BLOCK triangles given by their corners' coordinates, the centre of
    triangle j written at out[j * out_stride] (x) and the next double (y): the same doubles. The first
    tier of all k runs in one loop that the compiler vectorizes, then the pairs of those it leaves open
    in another; circumcentre takes the few left. (Each tier's result, where it settles, is the correctly
    rounded centre: which tier settles a coordinate does not change it.)"""
    cdef Estimate f
    cdef PairTerms pt
    cdef double lo_x[CENTRE_BLOCK]
    cdef double hi_x[CENTRE_BLOCK]
    cdef double lo_y[CENTRE_BLOCK]
    cdef double hi_y[CENTRE_BLOCK]
    cdef double det[CENTRE_BLOCK]
    cdef double err_det[CENTRE_BLOCK]
    cdef double det_sum[CENTRE_BLOCK]
    cdef double g[6][CENTRE_BLOCK]      # the open triangles' corners, gathered
    cdef double tails[CENTRE_BLOCK]
    cdef int at[CENTRE_BLOCK]
    cdef int j, q, n_open = 0
    # (doubles only, no branch: the compiler vectorizes this loop; the tests follow in the next)
    for j in range(k):
        estimate_centre(ax[j], ay[j], bx[j], by[j], cx[j], cy[j], &f)
        det[j] = f.det
        err_det[j] = f.err_det
        det_sum[j] = f.det_sum
        # rounds_alike's interval, on both coordinates
        lo_x[j] = ax[j] + (f.qx - f.wx)
        hi_x[j] = ax[j] + (f.qx + f.wx)
        lo_y[j] = ay[j] + (f.qy - f.wy)
        hi_y[j] = ay[j] + (f.qy + f.wy)
    for j in range(k):
        if not (usable(det[j], err_det[j], det_sum[j]) and lo_x[j] == hi_x[j] and lo_y[j] == hi_y[j]
                and scaled_back(lo_x[j], e, &out[j * out_stride])
                and scaled_back(lo_y[j], e, &out[j * out_stride + 1])):
            at[n_open] = j
            g[0][n_open] = ax[j]; g[1][n_open] = ay[j]; g[2][n_open] = bx[j]
            g[3][n_open] = by[j]; g[4][n_open] = cx[j]; g[5][n_open] = cy[j]
            n_open += 1
    # the second tier (circumcentre_pairs), both coordinates, in one vectorized loop
    for q in range(n_open):
        estimate_centre(g[0][q], g[1][q], g[2][q], g[3][q], g[4][q], g[5][q], &f)
        pair_terms(g[0][q], g[1][q], g[2][q], g[3][q], g[4][q], g[5][q], &f, &pt)
        tails[q] = pt.tails
        pair_interval(g[0][q], f.nx, pt.nl_x, fabs(f.tx1) + fabs(f.tx2), f.det, pt.t, f.det_sum, f.inv, f.qx,
                      &lo_x[q], &hi_x[q])
        pair_interval(g[1][q], f.ny, pt.nl_y, fabs(f.ty1) + fabs(f.ty2), f.det, pt.t, f.det_sum, f.inv, f.qy,
                      &lo_y[q], &hi_y[q])
    for q in range(n_open):
        j = at[q]
        if not (usable(det[j], err_det[j], det_sum[j]) and tails[q] == 0.0
                and in_pair_range(bx[j] - ax[j]) and in_pair_range(by[j] - ay[j])
                and in_pair_range(cx[j] - ax[j]) and in_pair_range(cy[j] - ay[j])
                and lo_x[q] == hi_x[q] and lo_y[q] == hi_y[q]
                and scaled_back(lo_x[q], e, &out[j * out_stride])
                and scaled_back(lo_y[q], e, &out[j * out_stride + 1])):
            circumcentre(ax[j], ay[j], bx[j], by[j], cx[j], cy[j], e, &out[j * out_stride],
                         &out[j * out_stride + 1])


cdef inline int circumcentre_side(double ax, double ay, double bx, double by, double cx, double cy,
                                  double t, bint along_y) noexcept nogil:
    """Sign of (exact circumcentre x, or y when along_y) - t, all in the scaled unit."""
    cdef double num[P_MAX]
    cdef double den[Q_MAX]
    cdef double td[2 * Q_MAX]
    cdef double diff[P_MAX + 2 * Q_MAX]
    cdef int n_den = circumcentre_denominator(ax, ay, bx, by, cx, cy, den)
    cdef int n_num = circumcentre_numerator(ax, ay, bx, by, cx, cy, along_y, num)
    cdef int s_den = expansion_sign(n_den, den)
    cdef int n_td = scale_expansion_zeroelim(n_den, den, t, td)
    negate_expansion(n_td, td)
    return s_den * expansion_sign(fast_expansion_sum_zeroelim(n_num, num, n_td, td, diff), diff)


# ---------------------------------------------------------------------------------------------------------
# the bisector of a and b: points p with 2 p . (b - a) = |b|^2 - |a|^2

cdef inline int bisector_offset(double ax, double ay, double bx, double by, double t, bint along_y,
                                double* h) noexcept nogil:
    # |b|^2 - |a|^2 - 2 t (b - a)_x  (along_y false: the line x = t), or with (b - a)_y (h: 16)
    cdef double sq[8]
    cdef double lin[4]
    cdef double a2[4]
    cdef double b2[4]
    cdef double p[2]
    cdef double q[2]
    cdef double h1, h0
    cdef int n_a, n_b, n_sq, n_lin, k
    h1, h0 = two_square(bx); p[0] = h0; p[1] = h1
    h1, h0 = two_square(by); q[0] = h0; q[1] = h1
    n_b = fast_expansion_sum_zeroelim(2, p, 2, q, b2)
    h1, h0 = two_square(ax); p[0] = -h0; p[1] = -h1
    h1, h0 = two_square(ay); q[0] = -h0; q[1] = -h1
    n_a = fast_expansion_sum_zeroelim(2, p, 2, q, a2)
    n_sq = fast_expansion_sum_zeroelim(n_b, b2, n_a, a2, sq)
    if along_y:
        n_lin = coord_times_diff(t, by, ay, lin)
    else:
        n_lin = coord_times_diff(t, bx, ax, lin)
    for k in range(n_lin):
        lin[k] *= -2.0
    return fast_expansion_sum_zeroelim(n_sq, sq, n_lin, lin, h)


cdef inline double bisector_at(double ax, double ay, double bx, double by, double t, bint along_y,
                               int e) noexcept nogil:
    """Where the bisector of a and b crosses the line x = t (along_y false: returns its y) or y = t
    (returns its x), correctly rounded, times 2^e. The bisector must not be parallel to that line."""
    cdef double num[16]
    cdef double den[2]
    cdef double d1, d0
    cdef int n_num = bisector_offset(ax, ay, bx, by, t, along_y, num), n_den
    if along_y:
        d1, d0 = two_diff(bx, ax)
    else:
        d1, d0 = two_diff(by, ay)
    n_den = difference_expansion(2.0 * d1, 2.0 * d0, den)
    return round_quotient(n_num, num, n_den, den, e)


cdef inline int bisector_side(double kx, double ky, double ax, double ay, double bx, double by) noexcept nogil:
    """Sign of |K - a|^2 - |K - b|^2 = 2 K.(b - a) + |a|^2 - |b|^2: -1 when K is nearer to a, +1 nearer
    to b, 0 on their bisector. Linear in K, so K may be as large as a box side can be."""
    cdef double dx = bx - ax, dy = by - ay
    cdef double tx = kx * dx, ty = ky * dy
    cdef double aa = ax * ax + ay * ay, bb = bx * bx + by * by
    cdef double det = 2.0 * (tx + ty) + (aa - bb)
    cdef double bound = 10.0 * EPSILON * (2.0 * (fabs(tx) + fabs(ty)) + aa + bb)
    cdef double lin[8]
    cdef double px[4]
    cdef double py[4]
    cdef double sq[16]
    cdef double total[24]
    cdef int n_x, n_y, n_lin, n_sq, k
    if det > bound:
        return 1
    if -det > bound:
        return -1
    # exact: 2 K.(b - a) - (|b|^2 - |a|^2 - 0) via the bisector offset at 0
    n_x = coord_times_diff(kx, bx, ax, px)
    n_y = coord_times_diff(ky, by, ay, py)
    n_lin = fast_expansion_sum_zeroelim(n_x, px, n_y, py, lin)
    for k in range(n_lin):
        lin[k] *= 2.0
    n_sq = bisector_offset(ax, ay, bx, by, 0.0, False, sq)      # |b|^2 - |a|^2
    negate_expansion(n_sq, sq)
    return expansion_sign(fast_expansion_sum_zeroelim(n_lin, lin, n_sq, sq, total), total)
