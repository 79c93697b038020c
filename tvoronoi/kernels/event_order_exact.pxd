# Exact order of Fortune's events when the floating-point filter cannot decide (near ties only).
#
# A circle event of sites a, b, c (counter-clockwise) happens when the sweep line reaches the top of
# their circle. Relative to a, with B = b - a, C = c - a:
#     D = Bx Cy - By Cx  (> 0),    N = Bx |C|^2 - Cx |B|^2,    Q = |B|^2 |C|^2 |B - C|^2,
#     top  T = ay + (N + sqrt(Q)) / (2 D)         (centre y = ay + N / (2D), radius sqrt(Q) / (2D)).
#
# site Y before the event (Y <= T, sites first at a tie):
#     P = 2 D (Y - ay) - N;   Y <= T  <=>  P <= sqrt(Q)  <=>  P <= 0  or  P^2 <= Q        (degree 6)
#
# two events (sign of T1 - T2), multiplied by 2 D1 D2 > 0:
#     u + sqrt(A) - sqrt(B),   u = 2 D1 D2 (ay1 - ay2) + D2 N1 - D1 N2,  A = D2^2 Q1,  B = D1^2 Q2
#     s = u + sqrt(A) is positive iff u >= 0 or A > u^2; if s <= 0 the sign is -1 (B > 0);
#     else sign(s^2 - B) = sign(w + 2 u sqrt(A)), w = u^2 + A - B, settled by the signs of u and w
#     or, when they differ, by comparing w^2 with 4 u^2 A                                 (degree 20)
#
# Degree 20 does not fit expansion arithmetic: with coordinates of different magnitudes (1 and 1e-18)
# the exact value spans more bits than a double's exponent range, and its smallest components would
# underflow. So the fallback works on the arbitrary-precision integers of exact_integers.pxd.

from tvoronoi.kernels.exact_integers cimport tvb_orient  # the integer arithmetic's C code, first
from tvoronoi.kernels.predicates cimport incircle, two_diff

cdef extern from *:
    """
    /* the terms of a circle event: D, N, Q and ay, from six coordinates already converted */
    typedef struct { tvb_int D, N, Q, ay; } tvb_circle;

    static tvb_circle tvb_circle_terms(tvb_arena *A, const tvb_int *p) {
        /* p: ax, ay, bx, by, cx, cy */
        tvb_circle c;
        tvb_int bx = tvb_sub(A, p[2], p[0]), by = tvb_sub(A, p[3], p[1]);
        tvb_int cx = tvb_sub(A, p[4], p[0]), cy = tvb_sub(A, p[5], p[1]);
        tvb_int dx = tvb_sub(A, p[2], p[4]), dy = tvb_sub(A, p[3], p[5]);
        tvb_int nb = tvb_add(A, tvb_mul(A, bx, bx), tvb_mul(A, by, by));
        tvb_int nc = tvb_add(A, tvb_mul(A, cx, cx), tvb_mul(A, cy, cy));
        tvb_int nd = tvb_add(A, tvb_mul(A, dx, dx), tvb_mul(A, dy, dy));
        c.D = tvb_sub(A, tvb_mul(A, bx, cy), tvb_mul(A, by, cx));
        c.N = tvb_sub(A, tvb_mul(A, bx, nc), tvb_mul(A, cx, nb));
        c.Q = tvb_mul(A, tvb_mul(A, nb, nc), nd);
        c.ay = p[1];
        return c;
    }

    /* 1 when a site at height Y comes before the circle event of (a, b, c) (Y <= top), 0 after it,
       -2 when memory ran out. tri = ax, ay, bx, by, cx, cy, counter-clockwise. */
    static int tvb_site_first(double Y, const double *tri) {
        tvb_arena A;
        double v[7];
        tvb_int p[6], y, P;
        tvb_circle c;
        int i, e0, result;
        for (i = 0; i < 6; i++) v[i] = tri[i];
        v[6] = Y;
        e0 = tvb_common_exponent(v, 7);
        tvb_arena_init(&A);
        for (i = 0; i < 6; i++) p[i] = tvb_from_double(&A, v[i], e0);
        y = tvb_from_double(&A, Y, e0);
        c = tvb_circle_terms(&A, p);
        /* P = 2 D (Y - ay) - N */
        P = tvb_sub(&A, tvb_twice(&A, tvb_mul(&A, c.D, tvb_sub(&A, y, c.ay))), c.N);
        if (tvb_sign(P) <= 0) result = 1;
        else result = tvb_sign(tvb_sub(&A, c.Q, tvb_mul(&A, P, P))) >= 0;
        if (A.failed) result = -2;
        tvb_arena_free(&A);
        return result;
    }

    /* sign of top(t1) - top(t2) for two circle events (each: ax, ay, bx, by, cx, cy,
       counter-clockwise); 2 when memory ran out */
    static int tvb_top_order(const double *t1, const double *t2) {
        tvb_arena A;
        double v[12];
        tvb_int p[12], u, a, b, w, u2;
        tvb_circle c1, c2;
        int i, e0, su, sw, result;
        for (i = 0; i < 6; i++) { v[i] = t1[i]; v[6 + i] = t2[i]; }
        e0 = tvb_common_exponent(v, 12);
        tvb_arena_init(&A);
        for (i = 0; i < 12; i++) p[i] = tvb_from_double(&A, v[i], e0);
        c1 = tvb_circle_terms(&A, p);
        c2 = tvb_circle_terms(&A, p + 6);
        /* u = 2 D1 D2 (ay1 - ay2) + D2 N1 - D1 N2,  A = D2^2 Q1,  B = D1^2 Q2 */
        u = tvb_twice(&A, tvb_mul(&A, tvb_mul(&A, c1.D, c2.D), tvb_sub(&A, c1.ay, c2.ay)));
        u = tvb_add(&A, u, tvb_sub(&A, tvb_mul(&A, c2.D, c1.N), tvb_mul(&A, c1.D, c2.N)));
        a = tvb_mul(&A, tvb_mul(&A, c2.D, c2.D), c1.Q);
        b = tvb_mul(&A, tvb_mul(&A, c1.D, c1.D), c2.Q);
        u2 = tvb_mul(&A, u, u);
        su = tvb_sign(u);
        if (su < 0 && tvb_sign(tvb_sub(&A, a, u2)) <= 0) {
            result = -1;                      /* u + sqrt(A) <= 0 < sqrt(B) */
        } else {
            /* u + sqrt(A) > 0: the sign of (u + sqrt(A))^2 - B = w + 2 u sqrt(A) */
            w = tvb_sub(&A, tvb_add(&A, u2, a), b);
            sw = tvb_sign(w);
            if (su >= 0 && sw >= 0) result = (su > 0 || sw > 0) ? 1 : 0;
            else if (su <= 0 && sw <= 0) result = -1;      /* not both zero: handled above */
            else {
                /* opposite signs: compare w^2 with 4 u^2 A */
                int c = tvb_sign(tvb_sub(&A, tvb_mul(&A, w, w),
                                         tvb_twice(&A, tvb_twice(&A, tvb_mul(&A, u2, a)))));
                result = sw > 0 ? c : -c;
            }
        }
        if (A.failed) result = 2;
        tvb_arena_free(&A);
        return result;
    }
    """
    int tvb_site_first(double Y, const double* tri) nogil
    int tvb_top_order(const double* t1, const double* t2) nogil




cdef inline bint translates(const double* t1, const double* t2) noexcept nogil:
    """True when the sites of t2 are those of t1, in the same cyclic order, moved along x by one amount
    that a double holds exactly: congruent circles side by side, so their tops are equal. Exact
    comparisons only, no in-circle test: the common tie of a lattice's row parallel to the sweep line,
    settled before any filter. Each list is counter-clockwise: ax, ay, bx, by, cx, cy."""
    cdef int r, w, k
    cdef double dx, tail, px
    for r in range(3):
        if t2[1] != t1[2 * r + 1]:
            continue
        dx, tail = two_diff(t2[0], t1[2 * r])
        if tail != 0.0:
            continue
        for w in range(1, 3):
            k = (w + r) % 3
            if t2[2 * w + 1] != t1[2 * k + 1]:
                break
            px, tail = two_diff(t2[2 * w], dx)
            if tail != 0.0 or px != t1[2 * k]:
                break
        else:
            return True
    return False


cdef inline bint same_top_by_shift(const double* t1, const double* t2) noexcept nogil:
    """True when the circle of one event is the other's moved along x by an exact amount (zero
    included): each site of t2, moved back by it, is a site of t1 or lies on t1's circle (exact
    in-circle test). The two tops are then equal. The degenerate case of a lattice's row parallel to
    the sweep line (congruent circles side by side, several triples of one cocircular square), where
    every comparison of two events in the queue is a tie: a sufficient test, exact, far cheaper than
    the integer fallback. Each list is counter-clockwise: ax, ay, bx, by, cx, cy."""
    cdef int u, v, w, k
    cdef double dx, tail, px
    cdef bint on
    for u in range(3):
        for v in range(3):
            if t1[2 * u + 1] != t2[2 * v + 1]:
                continue
            # the shift that takes site u of t1 to site v of t2, if a double holds it exactly
            dx, tail = two_diff(t2[2 * v], t1[2 * u])
            if tail != 0.0:
                continue
            on = True
            for w in range(3):
                px, tail = two_diff(t2[2 * w], dx)
                if tail != 0.0:
                    on = False
                    break
                for k in range(3):
                    if px == t1[2 * k] and t2[2 * w + 1] == t1[2 * k + 1]:
                        break
                else:
                    if incircle(t1[0], t1[1], t1[2], t1[3], t1[4], t1[5], px, t2[2 * w + 1]) != 0:
                        on = False
                        break
            if on:
                return True
    return False
