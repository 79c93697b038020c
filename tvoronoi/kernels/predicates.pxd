# Exact orientation and in-circle predicates, compiled inline into every kernel that cimports them.
#
#   orient2d(a, b, c)     sign of | ax-cx  ay-cy |     +1: a, b, c turn counter-clockwise
#                                 | bx-cx  by-cy |     -1: clockwise, 0: collinear
#
#   incircle(a, b, c, d)  sign of | ax-dx  ay-dy  (ax-dx)^2 + (ay-dy)^2 |
#                                 | bx-dx  by-dy  (bx-dx)^2 + (by-dy)^2 |
#                                 | cx-dx  cy-dy  (cx-dx)^2 + (cy-dy)^2 |
#                         +1: d strictly inside the circle through a, b, c (taken counter-clockwise),
#                         -1: outside, 0: on it
#
# Both signs are exact for every finite double input whose intermediate values neither overflow nor
# underflow. Each predicate answers in the first of three tiers that can decide:
#
#   1. filter: the determinant in plain doubles with a proven bound on its rounding error (the
#      "errboundA" constants of J. R. Shewchuk, Adaptive Precision Floating-Point Arithmetic and Fast
#      Robust Geometric Predicates, 1997). Settles nearly every call with a handful of flops.
#   2. short exact: the coordinate differences were computed without rounding (the rule for integer and
#      grid coordinates, the usual degenerate input), so the determinant is a polynomial in single
#      doubles: at most 96 expansion components for incircle, 4 for orient2d. For incircle, first
#      in 64- and 128-bit integers when the differences are integers times one power of two, each
#      below 2^30 (tvoronoi_incircle_small: a grid's cocircular squares, a few tens of nanoseconds).
#   3. long exact: some difference was rounded; each difference is carried as a two-double expansion
#      (head + tail) and the determinant is multiplied out in full (up to 1536 components).
#
# Expansion arithmetic: an exact real is held as a sum of doubles ("components") that do not overlap
# bitwise, stored in increasing magnitude; routines that end in _zeroelim drop zero components. The sign of
# an expansion is the sign of its largest nonzero component. All of it relies on IEEE-754 doubles rounded
# to nearest-even, each operation rounded on its own: no x87 excess precision, no fused multiply-add
# (setup.py passes -ffp-contract=off), no fast-math. The C guards below stop a build with fast-math or
# x87 excess precision; FMA contraction cannot be detected from C, hence the compiler flag.
#
# All buffers are fixed-size C arrays on the stack: no allocation, no Python objects, safe without the GIL.

from libc.math cimport fabs
from libc.string cimport memcpy

cdef extern from *:
    """
    #if defined(__FAST_MATH__)
    #error "tvoronoi predicates: fast-math breaks exact expansion arithmetic; build without it"
    #endif
    #if defined(__FLT_EVAL_METHOD__) && (__FLT_EVAL_METHOD__ != 0)
    #error "tvoronoi predicates: doubles must be evaluated without excess precision (SSE2, not x87)"
    #endif
    /* 2^-53: half a unit in the last place of 1.0, written out exactly */
    #define TVORONOI_EPSILON 1.1102230246251565404236316680908203125e-16
    /* 2^27 + 1: multiplier that splits a double into two 26-bit halves */
    #define TVORONOI_SPLITTER 134217729.0
    #define TVORONOI_CCW_ERRBOUND_A ((3.0 + 16.0 * TVORONOI_EPSILON) * TVORONOI_EPSILON)
    #define TVORONOI_ICC_ERRBOUND_A ((10.0 + 96.0 * TVORONOI_EPSILON) * TVORONOI_EPSILON)
    #include <stdint.h>
    #include <string.h>
    /* The in-circle determinant of exact differences that are all integers times one power of two,
       each below 2^30 in magnitude (grids, integer and dyadic coordinates: the usual cocircular input):
       lifts and minors below 2^61 in 64-bit integers, the three products below 2^122 and their sum
       below 2^124 in 128-bit ones, all exact. Returns the sign, or 2 when the differences do not fit
       (or the compiler has no 128-bit integers): the caller then multiplies expansions. */
    static inline int tvoronoi_incircle_small(const double* v) {
    #if defined(__SIZEOF_INT128__)
        uint64_t bits, mant[6];
        int low[6], neg[6], lo = 1 << 20, hi = -(1 << 20), k, ex;
        int64_t q[6], a_lift, b_lift, c_lift, m_a, m_b, m_c;
        __int128 det;
        for (k = 0; k < 6; k++) {
            memcpy(&bits, &v[k], sizeof bits);
            ex = (int) ((bits >> 52) & 0x7ff);
            mant[k] = bits & 0xfffffffffffffULL;
            neg[k] = (int) (bits >> 63);
            low[k] = 0;
            if (ex == 0x7ff || (ex == 0 && mant[k] != 0)) return 2;     /* inf, NaN, subnormal */
            if (ex == 0) continue;                                       /* a zero */
            mant[k] |= 1ULL << 52;                                       /* |v| = mant 2^(ex - 1075) */
            low[k] = ex - 1075;
            if (low[k] + __builtin_ctzll(mant[k]) < lo) lo = low[k] + __builtin_ctzll(mant[k]);
            if (low[k] + 53 > hi) hi = low[k] + 53;                      /* |v| < 2^hi */
        }
        if (hi < lo) return 0;                                           /* every difference zero */
        if (hi - lo > 30) return 2;
        for (k = 0; k < 6; k++) {
            /* v 2^-lo = mant 2^(low - lo): an integer below 2^30 (the shifted-out bits are zeros) */
            if (mant[k] == 0) q[k] = 0;
            else q[k] = (int64_t) (low[k] >= lo ? mant[k] << (low[k] - lo) : mant[k] >> (lo - low[k]));
            if (neg[k]) q[k] = -q[k];
        }
        a_lift = q[0] * q[0] + q[1] * q[1];
        b_lift = q[2] * q[2] + q[3] * q[3];
        c_lift = q[4] * q[4] + q[5] * q[5];
        m_a = q[2] * q[5] - q[4] * q[3];
        m_b = q[4] * q[1] - q[0] * q[5];
        m_c = q[0] * q[3] - q[2] * q[1];
        det = (__int128) a_lift * m_a + (__int128) b_lift * m_b + (__int128) c_lift * m_c;
        return (det > 0) - (det < 0);
    #else
        (void) v;
        return 2;
    #endif
    }
    """
    const double EPSILON "TVORONOI_EPSILON"
    const double SPLITTER "TVORONOI_SPLITTER"
    const double CCW_ERRBOUND_A "TVORONOI_CCW_ERRBOUND_A"
    const double ICC_ERRBOUND_A "TVORONOI_ICC_ERRBOUND_A"
    int incircle_small "tvoronoi_incircle_small"(const double* v) noexcept nogil


# ---------------------------------------------------------------------------------------------------------
# exact two-double operations: each returns (rounded result, exact roundoff)

cdef inline (double, double) fast_two_sum(double a, double b) noexcept nogil:
    # a + b, valid when |a| >= |b| or a == 0
    cdef double x = a + b
    cdef double b_virtual = x - a
    return x, b - b_virtual


cdef inline (double, double) two_sum(double a, double b) noexcept nogil:
    cdef double x = a + b
    cdef double b_virtual = x - a
    cdef double a_virtual = x - b_virtual
    cdef double b_round = b - b_virtual
    cdef double a_round = a - a_virtual
    return x, a_round + b_round


cdef inline double two_diff_tail(double a, double b, double x) noexcept nogil:
    # roundoff of x = fl(a - b): a - b == x + tail exactly
    cdef double b_virtual = a - x
    cdef double a_virtual = x + b_virtual
    cdef double b_round = b_virtual - b
    cdef double a_round = a - a_virtual
    return a_round + b_round


cdef inline (double, double) two_diff(double a, double b) noexcept nogil:
    cdef double x = a - b
    return x, two_diff_tail(a, b, x)


cdef inline (double, double) split(double a) noexcept nogil:
    # a == hi + lo with hi, lo of at most 26 significant bits each (Veltkamp)
    cdef double c = SPLITTER * a
    cdef double a_big = c - a
    cdef double hi = c - a_big
    return hi, a - hi


cdef inline double product_tail(double x, double a_hi, double a_lo, double b_hi, double b_lo) noexcept nogil:
    # roundoff of x = fl(a * b) from the halves of a and b (Dekker): a * b == x + tail exactly
    cdef double err1 = x - a_hi * b_hi
    cdef double err2 = err1 - a_lo * b_hi
    cdef double err3 = err2 - a_hi * b_lo
    return a_lo * b_lo - err3


cdef inline (double, double) two_product(double a, double b) noexcept nogil:
    cdef double x = a * b
    cdef double a_hi, a_lo, b_hi, b_lo
    a_hi, a_lo = split(a)
    b_hi, b_lo = split(b)
    return x, product_tail(x, a_hi, a_lo, b_hi, b_lo)


cdef inline (double, double) two_square(double a) noexcept nogil:
    cdef double x = a * a
    cdef double a_hi, a_lo
    a_hi, a_lo = split(a)
    cdef double err1 = x - a_hi * a_hi
    cdef double err3 = err1 - (a_hi + a_hi) * a_lo
    return x, a_lo * a_lo - err3


cdef inline void two_two_diff(double a1, double a0, double b1, double b0, double* h) noexcept nogil:
    # (a1 + a0) - (b1 + b0) as the four-component expansion h[0] (smallest) .. h[3]
    cdef double i, j, z, x0, x1, x2, x3
    # subtract b0 from (a1 + a0)
    i, x0 = two_diff(a0, b0)
    j, z = two_sum(a1, i)
    # subtract b1 from (j + z)
    i, x1 = two_diff(z, b1)
    x3, x2 = two_sum(j, i)
    h[0] = x0
    h[1] = x1
    h[2] = x2
    h[3] = x3


# ---------------------------------------------------------------------------------------------------------
# expansions: e[0 .. elen-1], nonoverlapping, increasing magnitude

cdef inline int expansion_sign(int elen, const double* e) noexcept nogil:
    # sign of the largest nonzero component (the last one, once zeros are dropped)
    cdef int i
    for i in range(elen - 1, -1, -1):
        if e[i] > 0.0:
            return 1
        if e[i] < 0.0:
            return -1
    return 0


cdef inline int compress_zeros(int elen, const double* e, double* h) noexcept nogil:
    # copy e to h without its zero components; a zero expansion becomes the single component 0
    cdef int i, hlen = 0
    for i in range(elen):
        if e[i] != 0.0:
            h[hlen] = e[i]
            hlen += 1
    if hlen == 0:
        h[0] = 0.0
        hlen = 1
    return hlen


cdef inline int fast_expansion_sum_zeroelim(int elen, const double* e, int flen, const double* f,
                                            double* h) noexcept nogil:
    # h = e + f; h needs room for elen + flen components
    cdef double q, q_new, hh, e_now, f_now
    cdef int ei = 0, fi = 0, hlen = 0
    # merge the two inputs by magnitude, carrying the running sum in q
    e_now = e[0]
    f_now = f[0]
    if (f_now > e_now) == (f_now > -e_now):
        q = e_now
        ei = 1
    else:
        q = f_now
        fi = 1
    if ei < elen and fi < flen:
        e_now = e[ei]
        f_now = f[fi]
        if (f_now > e_now) == (f_now > -e_now):
            q_new, hh = fast_two_sum(e_now, q)
            ei += 1
        else:
            q_new, hh = fast_two_sum(f_now, q)
            fi += 1
        q = q_new
        if hh != 0.0:
            h[hlen] = hh
            hlen += 1
        while ei < elen and fi < flen:
            e_now = e[ei]
            f_now = f[fi]
            if (f_now > e_now) == (f_now > -e_now):
                q_new, hh = two_sum(q, e_now)
                ei += 1
            else:
                q_new, hh = two_sum(q, f_now)
                fi += 1
            q = q_new
            if hh != 0.0:
                h[hlen] = hh
                hlen += 1
    # one input is used up: run through the rest of the other
    while ei < elen:
        q_new, hh = two_sum(q, e[ei])
        ei += 1
        q = q_new
        if hh != 0.0:
            h[hlen] = hh
            hlen += 1
    while fi < flen:
        q_new, hh = two_sum(q, f[fi])
        fi += 1
        q = q_new
        if hh != 0.0:
            h[hlen] = hh
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


cdef inline int scale_expansion_zeroelim(int elen, const double* e, double b, double* h) noexcept nogil:
    # h = e * b; h needs room for 2 * elen components
    cdef double b_hi, b_lo, e_hi, e_lo, q, s, hh, p1, p0
    cdef int i, hlen = 0
    b_hi, b_lo = split(b)
    q = e[0] * b
    e_hi, e_lo = split(e[0])
    hh = product_tail(q, e_hi, e_lo, b_hi, b_lo)
    if hh != 0.0:
        h[hlen] = hh
        hlen += 1
    for i in range(1, elen):
        p1 = e[i] * b
        e_hi, e_lo = split(e[i])
        p0 = product_tail(p1, e_hi, e_lo, b_hi, b_lo)
        s, hh = two_sum(q, p0)
        if hh != 0.0:
            h[hlen] = hh
            hlen += 1
        q, hh = fast_two_sum(p1, s)
        if hh != 0.0:
            h[hlen] = hh
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


cdef inline int expansion_product(int elen, const double* e, int flen, const double* f, double* h,
                                  double* work, double* scaled) noexcept nogil:
    # h = e * f, one scaled copy of e per component of f, summed as they come;
    # h and work need room for 2 * elen * flen components, scaled for 2 * elen
    cdef double* acc = h
    cdef double* other = work
    cdef double* swap
    cdef int j, slen
    cdef int alen = scale_expansion_zeroelim(elen, e, f[0], acc)
    for j in range(1, flen):
        slen = scale_expansion_zeroelim(elen, e, f[j], scaled)
        alen = fast_expansion_sum_zeroelim(alen, acc, slen, scaled, other)
        swap = acc
        acc = other
        other = swap
    if acc != h:
        memcpy(h, acc, alen * sizeof(double))
    return alen


cdef inline int negate_expansion(int elen, double* e) noexcept nogil:
    cdef int i
    for i in range(elen):
        e[i] = -e[i]
    return elen


cdef inline int difference_expansion(double head, double tail, double* h) noexcept nogil:
    # the exact difference head + tail as an expansion of one or two components (h: 2, both written)
    if tail == 0.0:
        h[0] = head
        h[1] = 0.0
        return 1
    h[0] = tail
    h[1] = head
    return 2


# ---------------------------------------------------------------------------------------------------------
# orient2d

cdef inline int orient2d_exact_long(double acx, double acx_t, double acy, double acy_t,
                                    double bcx, double bcx_t, double bcy, double bcy_t) noexcept nogil:
    # some difference was rounded: (acx + acx_t)(bcy + bcy_t) - (acy + acy_t)(bcx + bcx_t), up to 16 components
    cdef double e_acx[2]
    cdef double e_acy[2]
    cdef double e_bcx[2]
    cdef double e_bcy[2]
    cdef double left[8]
    cdef double right[8]
    cdef double work[8]
    cdef double scaled[4]
    cdef double det[16]
    cdef int n_acx = difference_expansion(acx, acx_t, e_acx)
    cdef int n_acy = difference_expansion(acy, acy_t, e_acy)
    cdef int n_bcx = difference_expansion(bcx, bcx_t, e_bcx)
    cdef int n_bcy = difference_expansion(bcy, bcy_t, e_bcy)
    cdef int n_left = expansion_product(n_acx, e_acx, n_bcy, e_bcy, left, work, scaled)
    cdef int n_right = expansion_product(n_acy, e_acy, n_bcx, e_bcx, right, work, scaled)
    negate_expansion(n_right, right)
    return expansion_sign(fast_expansion_sum_zeroelim(n_left, left, n_right, right, det), det)


cdef inline int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy,
                               double acx, double acy, double bcx, double bcy) noexcept nogil:
    # the filter could not decide; acx .. bcy are the rounded differences it used
    cdef double acx_t = two_diff_tail(ax, cx, acx)
    cdef double acy_t = two_diff_tail(ay, cy, acy)
    cdef double bcx_t = two_diff_tail(bx, cx, bcx)
    cdef double bcy_t = two_diff_tail(by, cy, bcy)
    cdef double left1, left0, right1, right0
    cdef double det[4]
    if acx_t != 0.0 or acy_t != 0.0 or bcx_t != 0.0 or bcy_t != 0.0:
        return orient2d_exact_long(acx, acx_t, acy, acy_t, bcx, bcx_t, bcy, bcy_t)
    # exact differences: the determinant is two exact products, a four-component expansion
    left1, left0 = two_product(acx, bcy)
    right1, right0 = two_product(acy, bcx)
    two_two_diff(left1, left0, right1, right0, det)
    return expansion_sign(4, det)


cdef inline int orient2d(double ax, double ay, double bx, double by, double cx, double cy) noexcept nogil:
    cdef double acx = ax - cx
    cdef double acy = ay - cy
    cdef double bcx = bx - cx
    cdef double bcy = by - cy
    cdef double det_left = acx * bcy
    cdef double det_right = acy * bcx
    cdef double det = det_left - det_right
    cdef double det_sum = fabs(det_left) + fabs(det_right)
    # filter: trust the rounded determinant when it exceeds its worst-case rounding error. Products of
    # opposite sign or a zero product pass always (then |det| == det_sum): they cannot cancel. One
    # well-predicted branch; the sign itself is computed without branching.
    if fabs(det) >= CCW_ERRBOUND_A * det_sum:
        return (det > 0.0) - (det < 0.0)
    return orient2d_exact(ax, ay, bx, by, cx, cy, acx, acy, bcx, bcy)


# ---------------------------------------------------------------------------------------------------------
# incircle

cdef inline int exact_minor(double a, double b, double c, double d, double* h) noexcept nogil:
    # h = a*b - c*d exactly, zero components dropped (at most 4)
    cdef double p1, p0, q1, q0
    cdef double diff[4]
    p1, p0 = two_product(a, b)
    q1, q0 = two_product(c, d)
    two_two_diff(p1, p0, q1, q0, diff)
    return compress_zeros(4, diff, h)


cdef inline int lifted_term(double x, double y, int mlen, const double* minor, double* h) noexcept nogil:
    # h = (x^2 + y^2) * minor for single doubles x, y and a minor of at most 4 components (h: 32)
    cdef double xx[2]
    cdef double yy[2]
    cdef double lift[4]
    cdef double work[32]
    cdef double scaled[8]
    xx[1], xx[0] = two_square(x)
    yy[1], yy[0] = two_square(y)
    cdef int n_lift = fast_expansion_sum_zeroelim(2, xx, 2, yy, lift)
    # scale the minor by each component of the lift: one pass when the squares were exact
    return expansion_product(mlen, minor, n_lift, lift, h, work, scaled)


cdef inline int incircle_exact_short(double adx, double ady, double bdx, double bdy,
                                     double cdx, double cdy) noexcept nogil:
    # every difference exact: lift_a*(bdx*cdy - cdx*bdy) + lift_b*(cdx*ady - adx*cdy)
    #                          + lift_c*(adx*bdy - bdx*ady), at most 96 components
    cdef double bc[4]
    cdef double ca[4]
    cdef double ab[4]
    cdef double a_term[32]
    cdef double b_term[32]
    cdef double c_term[32]
    cdef double ab_sum[64]
    cdef double det[96]
    cdef int n_bc = exact_minor(bdx, cdy, cdx, bdy, bc)
    cdef int n_ca = exact_minor(cdx, ady, adx, cdy, ca)
    cdef int n_ab = exact_minor(adx, bdy, bdx, ady, ab)
    cdef int n_a = lifted_term(adx, ady, n_bc, bc, a_term)
    cdef int n_b = lifted_term(bdx, bdy, n_ca, ca, b_term)
    cdef int n_c = lifted_term(cdx, cdy, n_ab, ab, c_term)
    cdef int n_ab_sum = fast_expansion_sum_zeroelim(n_a, a_term, n_b, b_term, ab_sum)
    return expansion_sign(fast_expansion_sum_zeroelim(n_ab_sum, ab_sum, n_c, c_term, det), det)


cdef inline int long_minor(int n_p, const double* p, int n_q, const double* q,
                           int n_r, const double* r, int n_s, const double* s, double* h) noexcept nogil:
    # h = p*q - r*s for expansions of at most two components each (h: 16)
    cdef double left[8]
    cdef double right[8]
    cdef double work[8]
    cdef double scaled[4]
    cdef int n_left = expansion_product(n_p, p, n_q, q, left, work, scaled)
    cdef int n_right = expansion_product(n_r, r, n_s, s, right, work, scaled)
    negate_expansion(n_right, right)
    return fast_expansion_sum_zeroelim(n_left, left, n_right, right, h)


cdef inline int long_lifted_term(int n_x, const double* x, int n_y, const double* y,
                                 int mlen, const double* minor, double* h, double* work) noexcept nogil:
    # h = (x^2 + y^2) * minor for expansions x, y of at most two components (h, work: 512)
    cdef double xx[8]
    cdef double yy[8]
    cdef double lift[16]
    cdef double small_work[8]
    cdef double scaled[32]
    cdef int n_xx = expansion_product(n_x, x, n_x, x, xx, small_work, scaled)
    cdef int n_yy = expansion_product(n_y, y, n_y, y, yy, small_work, scaled)
    cdef int n_lift = fast_expansion_sum_zeroelim(n_xx, xx, n_yy, yy, lift)
    return expansion_product(mlen, minor, n_lift, lift, h, work, scaled)


cdef inline int incircle_exact_long(double adx, double adx_t, double ady, double ady_t,
                                    double bdx, double bdx_t, double bdy, double bdy_t,
                                    double cdx, double cdx_t, double cdy, double cdy_t) noexcept nogil:
    # some difference was rounded: the same determinant with two-component differences, up to 1536 components
    cdef double e_adx[2]
    cdef double e_ady[2]
    cdef double e_bdx[2]
    cdef double e_bdy[2]
    cdef double e_cdx[2]
    cdef double e_cdy[2]
    cdef double minor[16]
    cdef double work[512]
    cdef double term[512]
    cdef double other_term[512]
    cdef double partial[1024]
    cdef double det[1536]
    cdef int n_adx = difference_expansion(adx, adx_t, e_adx)
    cdef int n_ady = difference_expansion(ady, ady_t, e_ady)
    cdef int n_bdx = difference_expansion(bdx, bdx_t, e_bdx)
    cdef int n_bdy = difference_expansion(bdy, bdy_t, e_bdy)
    cdef int n_cdx = difference_expansion(cdx, cdx_t, e_cdx)
    cdef int n_cdy = difference_expansion(cdy, cdy_t, e_cdy)
    cdef int n_minor, n_term, n_other, n_partial
    # lift_a * (bdx*cdy - cdx*bdy)
    n_minor = long_minor(n_bdx, e_bdx, n_cdy, e_cdy, n_cdx, e_cdx, n_bdy, e_bdy, minor)
    n_term = long_lifted_term(n_adx, e_adx, n_ady, e_ady, n_minor, minor, term, work)
    # + lift_b * (cdx*ady - adx*cdy)
    n_minor = long_minor(n_cdx, e_cdx, n_ady, e_ady, n_adx, e_adx, n_cdy, e_cdy, minor)
    n_other = long_lifted_term(n_bdx, e_bdx, n_bdy, e_bdy, n_minor, minor, other_term, work)
    n_partial = fast_expansion_sum_zeroelim(n_term, term, n_other, other_term, partial)
    # + lift_c * (adx*bdy - bdx*ady)
    n_minor = long_minor(n_adx, e_adx, n_bdy, e_bdy, n_bdx, e_bdx, n_ady, e_ady, minor)
    n_term = long_lifted_term(n_cdx, e_cdx, n_cdy, e_cdy, n_minor, minor, term, work)
    return expansion_sign(fast_expansion_sum_zeroelim(n_partial, partial, n_term, term, det), det)


cdef inline int incircle_exact(double ax, double ay, double bx, double by, double cx, double cy,
                               double dx, double dy, double adx, double ady, double bdx, double bdy,
                               double cdx, double cdy) noexcept nogil:
    # the filter could not decide; adx .. cdy are the rounded differences it used
    cdef double adx_t = two_diff_tail(ax, dx, adx)
    cdef double ady_t = two_diff_tail(ay, dy, ady)
    cdef double bdx_t = two_diff_tail(bx, dx, bdx)
    cdef double bdy_t = two_diff_tail(by, dy, bdy)
    cdef double cdx_t = two_diff_tail(cx, dx, cdx)
    cdef double cdy_t = two_diff_tail(cy, dy, cdy)
    if (adx_t != 0.0 or ady_t != 0.0 or bdx_t != 0.0 or bdy_t != 0.0
            or cdx_t != 0.0 or cdy_t != 0.0):
        return incircle_exact_long(adx, adx_t, ady, ady_t, bdx, bdx_t, bdy, bdy_t,
                                   cdx, cdx_t, cdy, cdy_t)
    cdef double d[6]
    d[0] = adx; d[1] = ady; d[2] = bdx; d[3] = bdy; d[4] = cdx; d[5] = cdy
    cdef int small = incircle_small(d)
    if small != 2:
        return small
    return incircle_exact_short(adx, ady, bdx, bdy, cdx, cdy)


cdef inline int incircle_filter(double ax, double ay, double bx, double by, double cx, double cy,
                                double dx, double dy) noexcept nogil:
    """incircle's first tier alone: its sign when the rounded determinant settles it, else 2. Small
    enough to be compiled into a hot loop that calls incircle only when this gives 2."""
    cdef double adx = ax - dx
    cdef double ady = ay - dy
    cdef double bdx = bx - dx
    cdef double bdy = by - dy
    cdef double cdx = cx - dx
    cdef double cdy = cy - dy
    cdef double bdxcdy = bdx * cdy
    cdef double cdxbdy = cdx * bdy
    cdef double a_lift = adx * adx + ady * ady
    cdef double cdxady = cdx * ady
    cdef double adxcdy = adx * cdy
    cdef double b_lift = bdx * bdx + bdy * bdy
    cdef double adxbdy = adx * bdy
    cdef double bdxady = bdx * ady
    cdef double c_lift = cdx * cdx + cdy * cdy
    cdef double det = (a_lift * (bdxcdy - cdxbdy)
                       + b_lift * (cdxady - adxcdy)
                       + c_lift * (adxbdy - bdxady))
    cdef double permanent = ((fabs(bdxcdy) + fabs(cdxbdy)) * a_lift
                             + (fabs(cdxady) + fabs(adxcdy)) * b_lift
                             + (fabs(adxbdy) + fabs(bdxady)) * c_lift)
    cdef double err_bound = ICC_ERRBOUND_A * permanent
    # trust the rounded determinant when it exceeds its worst-case rounding error
    if fabs(det) > err_bound:
        return (det > 0.0) - (det < 0.0)
    return 2


cdef inline int incircle(double ax, double ay, double bx, double by, double cx, double cy,
                         double dx, double dy) noexcept nogil:
    cdef int sign = incircle_filter(ax, ay, bx, by, cx, cy, dx, dy)
    if sign != 2:
        return sign
    return incircle_exact(ax, ay, bx, by, cx, cy, dx, dy, ax - dx, ay - dy, bx - dx, by - dy, cx - dx, cy - dy)
