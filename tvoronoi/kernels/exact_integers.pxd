# Exact signs of polynomials in doubles of any magnitudes, in arbitrary-precision integers.
#
# Expansion arithmetic (predicates.pxd) is exact only while no product under- or overflows: with
# coordinates of very different magnitudes (1 and 1e-18 in a degree-20 test, or 1 and 1e300 in an
# orientation) the exact value spans more bits than a double's exponent range. Here every double of a
# test is m * 2^e with an integer m; all of them are written as integers times the smallest 2^e among
# them (the tests are homogeneous polynomials, so the common power of two does not change a sign) and
# the polynomials are evaluated on integers of 32-bit limbs. Memory comes from an arena of malloc'd
# blocks that grows as needed; running out of memory is reported, never ignored. Slow: only for the
# rare tests the floating-point paths cannot settle.

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

    /* sign of the orientation of a, b, c (p = ax, ay, bx, by, cx, cy): +1 counter-clockwise, -1 clockwise,
       0 collinear, exactly, whatever the magnitudes; 2 when memory ran out */
    static int tvb_orient(const double *p) {
        tvb_arena A;
        tvb_int q[6], d;
        int i, e0, result;
        e0 = tvb_common_exponent(p, 6);
        tvb_arena_init(&A);
        for (i = 0; i < 6; i++) q[i] = tvb_from_double(&A, p[i], e0);
        d = tvb_sub(&A, tvb_mul(&A, tvb_sub(&A, q[2], q[0]), tvb_sub(&A, q[5], q[1])),
                        tvb_mul(&A, tvb_sub(&A, q[3], q[1]), tvb_sub(&A, q[4], q[0])));
        result = A.failed ? 2 : tvb_sign(d);
        tvb_arena_free(&A);
        return result;
    }
    """
    int tvb_orient(const double* p) nogil
