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
# underflow. So the fallback works on integers: every double of the test is m * 2^e with an integer m;
# all of them are written as integers times the smallest 2^e among them (the tests are homogeneous
# polynomials, so the common power of two does not change a sign) and the polynomials are evaluated in
# arbitrary-precision integers (32-bit limbs). Memory comes from an arena of malloc'd blocks that grows
# as needed; running out of memory is reported, never ignored.

cdef extern from *:
    """
    #include <stdint.h>
    #include <stdlib.h>
    #include <string.h>
    #include <math.h>

    /* a signed integer: magnitude in n little-endian 32-bit limbs (no leading zero limb), n == 0 is 0 */
    typedef struct { uint32_t *d; int n; int neg; } tvb_int;

    #define TVB_MAX_BLOCKS 64
    #define TVB_BLOCK_LIMBS 16384
    typedef struct {
        uint32_t *blocks[TVB_MAX_BLOCKS];
        size_t used[TVB_MAX_BLOCKS];
        size_t cap[TVB_MAX_BLOCKS];
        int nb;
        int failed;
    } tvb_arena;

    static void tvb_arena_init(tvb_arena *a) { a->nb = 0; a->failed = 0; }

    static void tvb_arena_free(tvb_arena *a) {
        int i;
        for (i = 0; i < a->nb; i++) free(a->blocks[i]);
        a->nb = 0;
    }

    static uint32_t *tvb_alloc(tvb_arena *a, size_t n) {
        size_t c;
        uint32_t *b;
        if (n == 0) n = 1;
        if (a->nb > 0 && a->cap[a->nb - 1] - a->used[a->nb - 1] >= n) {
            b = a->blocks[a->nb - 1] + a->used[a->nb - 1];
            a->used[a->nb - 1] += n;
            return b;
        }
        if (a->nb == TVB_MAX_BLOCKS) { a->failed = 1; return NULL; }
        c = n > TVB_BLOCK_LIMBS ? n : TVB_BLOCK_LIMBS;
        b = (uint32_t *)malloc(c * sizeof(uint32_t));
        if (b == NULL) { a->failed = 1; return NULL; }
        a->blocks[a->nb] = b;
        a->cap[a->nb] = c;
        a->used[a->nb] = n;
        a->nb++;
        return b;
    }

    static tvb_int tvb_zero(void) { tvb_int z; z.d = NULL; z.n = 0; z.neg = 0; return z; }

    static void tvb_norm(tvb_int *r) {
        while (r->n > 0 && r->d[r->n - 1] == 0) r->n--;
        if (r->n == 0) r->neg = 0;
    }

    static int tvb_sign(tvb_int a) { return a.n == 0 ? 0 : (a.neg ? -1 : 1); }

    static tvb_int tvb_negate(tvb_int a) { if (a.n) a.neg = !a.neg; return a; }

    /* the exponent of the last set bit of a nonzero finite double: v = m * 2^e with m odd */
    static int tvb_low_exponent(double v) {
        int k;
        double f = frexp(fabs(v), &k);
        uint64_t m = (uint64_t)ldexp(f, 53);
        return k - 53 + __builtin_ctzll(m);
    }

    /* v / 2^e0 as an integer; e0 <= tvb_low_exponent(v) */
    static tvb_int tvb_from_double(tvb_arena *A, double v, int e0) {
        tvb_int r;
        int k, shift, word, bit, i;
        uint64_t m, carry;
        double f;
        if (v == 0.0) return tvb_zero();
        f = frexp(fabs(v), &k);
        m = (uint64_t)ldexp(f, 53);
        shift = k - 53 - e0;
        while (shift < 0) { m >>= 1; shift++; }       /* only trailing zero bits (e0 <= low exponent) */
        word = shift / 32;
        bit = shift % 32;
        r.d = tvb_alloc(A, (size_t)word + 3);
        if (r.d == NULL) return tvb_zero();
        for (i = 0; i < word + 3; i++) r.d[i] = 0;
        /* m << bit spread over three limbs, in two halves so that nothing overflows 64 bits */
        carry = (m & 0xffffffffu) << bit;
        r.d[word] = (uint32_t)carry;
        carry = (carry >> 32) + ((m >> 32) << bit);
        r.d[word + 1] = (uint32_t)carry;
        r.d[word + 2] = (uint32_t)(carry >> 32);
        r.n = word + 3;
        r.neg = v < 0.0;
        tvb_norm(&r);
        return r;
    }

    static int tvb_cmp_abs(tvb_int a, tvb_int b) {
        int i;
        if (a.n != b.n) return a.n < b.n ? -1 : 1;
        for (i = a.n - 1; i >= 0; i--)
            if (a.d[i] != b.d[i]) return a.d[i] < b.d[i] ? -1 : 1;
        return 0;
    }

    static tvb_int tvb_add(tvb_arena *A, tvb_int a, tvb_int b) {
        tvb_int r, big, small;
        int i, c;
        uint64_t t, carry = 0;
        int64_t s, borrow = 0;
        if (b.n == 0) return a;
        if (a.n == 0) return b;
        if (a.neg == b.neg) {
            if (a.n < b.n) { big = b; small = a; } else { big = a; small = b; }
            r.d = tvb_alloc(A, (size_t)big.n + 1);
            if (r.d == NULL) return tvb_zero();
            for (i = 0; i < big.n; i++) {
                t = (uint64_t)big.d[i] + (i < small.n ? small.d[i] : 0) + carry;
                r.d[i] = (uint32_t)t;
                carry = t >> 32;
            }
            r.d[big.n] = (uint32_t)carry;
            r.n = big.n + 1;
            r.neg = a.neg;
        } else {
            c = tvb_cmp_abs(a, b);
            if (c == 0) return tvb_zero();
            if (c > 0) { big = a; small = b; } else { big = b; small = a; }
            r.d = tvb_alloc(A, (size_t)big.n);
            if (r.d == NULL) return tvb_zero();
            for (i = 0; i < big.n; i++) {
                s = (int64_t)big.d[i] - (i < small.n ? small.d[i] : 0) - borrow;
                borrow = s < 0;
                r.d[i] = (uint32_t)(s + (borrow << 32));
            }
            r.n = big.n;
            r.neg = big.neg;
        }
        tvb_norm(&r);
        return r;
    }

    static tvb_int tvb_sub(tvb_arena *A, tvb_int a, tvb_int b) { return tvb_add(A, a, tvb_negate(b)); }

    static tvb_int tvb_mul(tvb_arena *A, tvb_int a, tvb_int b) {
        tvb_int r;
        int i, j;
        uint64_t t, carry;
        if (a.n == 0 || b.n == 0) return tvb_zero();
        r.d = tvb_alloc(A, (size_t)a.n + b.n);
        if (r.d == NULL) return tvb_zero();
        memset(r.d, 0, ((size_t)a.n + b.n) * sizeof(uint32_t));
        for (i = 0; i < a.n; i++) {
            carry = 0;
            for (j = 0; j < b.n; j++) {
                t = (uint64_t)a.d[i] * b.d[j] + r.d[i + j] + carry;
                r.d[i + j] = (uint32_t)t;
                carry = t >> 32;
            }
            r.d[i + b.n] = (uint32_t)carry;
        }
        r.n = a.n + b.n;
        r.neg = a.neg != b.neg;
        tvb_norm(&r);
        return r;
    }

    static tvb_int tvb_twice(tvb_arena *A, tvb_int a) { return tvb_add(A, a, a); }

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

    /* the common power of two of n doubles: the smallest exponent of a last set bit */
    static int tvb_common_exponent(const double *v, int n) {
        int i, e, e0 = 1 << 20;
        for (i = 0; i < n; i++) {
            if (v[i] != 0.0) {
                e = tvb_low_exponent(v[i]);
                if (e < e0) e0 = e;
            }
        }
        return e0 == (1 << 20) ? 0 : e0;
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
