# The one clipper of Voronoi cells to a box, shared by the batch clip (clip.pyx) and dynamic diagrams
# (dynamic.pyx); inline functions compiled into each kernel that cimports them.
#
# Every decision is exact: which side of a box side a Voronoi vertex lies on (its correctly rounded
# coordinate compared with the side, the exact test on a tie), where a bisector enters and leaves the
# box (the signs of its sites' distances to the four corners), and which box corners a cell walks past
# (the order of points along the box boundary). The points written are Voronoi vertices, crossings of
# bisectors with the box sides (both correctly rounded, tvoronoi.kernels.construct) and the corners.
#
#        K3 ---- side 2 ---- K2        corners K0..K3 counter-clockwise; side k runs from Kk to K(k+1);
#        |                    |        a point on the boundary has a position (side, t), t growing
#      side 3              side 1      counter-clockwise (x on side 0, y on 1, -x on 2, -y on 3);
#        |                    |        a corner Kk is the start of side k
#        K0 ---- side 0 ---- K1
#
# A cell is walked counter-clockwise: each Voronoi edge contributes its part inside the box; where the
# boundary of the cell leaves the box (an exit) and comes back (the next entry), the ring follows the
# box boundary from the one to the other, through the corners between them.

from libc.math cimport fabs, frexp, ldexp, INFINITY
from libc.stdint cimport int32_t

from tvoronoi.kernels.exact_integers cimport tvb_orient
from tvoronoi.kernels.construct cimport (
    P_MAX, Q_MAX, bisector_at, bisector_side, bisector_offset, circumcentre_side, circumcentre_numerator,
    circumcentre_denominator,
)
from tvoronoi.kernels.predicates cimport (
    orient2d, CCW_ERRBOUND_A, two_diff, difference_expansion, expansion_product, expansion_sign, negate_expansion,
    fast_expansion_sum_zeroelim,
)

cdef struct Box:
    double xmin, ymin, xmax, ymax            # the user's unit
    double sxmin, symin, sxmax, symax        # the sites' scaled unit (exact: 2^-e times the above)
    int e
    double kx[4]                             # corners, user unit
    double ky[4]
    double skx[4]                            # corners, scaled unit
    double sky[4]


cdef inline Box make_box(double xmin, double ymin, double xmax, double ymax, int e) noexcept nogil:
    cdef Box b
    cdef double sx0, sx1, sy0, sy1
    b.xmin = xmin; b.ymin = ymin; b.xmax = xmax; b.ymax = ymax; b.e = e
    sx0 = ldexp(xmin, -e); sy0 = ldexp(ymin, -e); sx1 = ldexp(xmax, -e); sy1 = ldexp(ymax, -e)
    b.sxmin = sx0; b.symin = sy0; b.sxmax = sx1; b.symax = sy1
    b.kx[0] = xmin; b.ky[0] = ymin; b.kx[1] = xmax; b.ky[1] = ymin
    b.kx[2] = xmax; b.ky[2] = ymax; b.kx[3] = xmin; b.ky[3] = ymax
    b.skx[0] = sx0; b.sky[0] = sy0; b.skx[1] = sx1; b.sky[1] = sy0
    b.skx[2] = sx1; b.sky[2] = sy1; b.skx[3] = sx0; b.sky[3] = sy1
    return b


# ---------------------------------------------------------------------------------------------------------
# vertices against the box: per axis a code -2 (below the min side), -1 (exactly on it), 0 (strictly
# between), 1 (exactly on the max side), 2 (above it)

cdef inline signed char axis_code(double v, double lo, double hi, double slo, double shi,
                                  double ax, double ay, double bx, double by, double cx, double cy,
                                  bint along_y) noexcept nogil:
    # v is the correctly rounded coordinate of the circumcentre of a, b, c (scaled sites)
    cdef int s
    if v < lo:
        return -2
    if v > hi:
        return 2
    if v == lo:
        s = circumcentre_side(ax, ay, bx, by, cx, cy, slo, along_y)
        return -2 if s < 0 else (-1 if s == 0 else 0)
    if v == hi:
        s = circumcentre_side(ax, ay, bx, by, cx, cy, shi, along_y)
        return 2 if s > 0 else (1 if s == 0 else 0)
    return 0


cdef inline bint code_in(signed char c) noexcept nogil:
    return -1 <= c <= 1


cdef inline int code_side(signed char cx, signed char cy) noexcept nogil:
    """The boundary side of a point in the box from its codes (a corner: the side it starts), or -1."""
    if cy == -1:
        return 1 if cx == 1 else 0
    if cx == 1:
        return 2 if cy == 1 else 1
    if cy == 1:
        return 3 if cx == -1 else 2
    if cx == -1:
        return 3
    return -1


cdef inline double boundary_t(int side, double x, double y) noexcept nogil:
    if side == 0:
        return x
    if side == 1:
        return y
    if side == 2:
        return -x
    return -y


# ---------------------------------------------------------------------------------------------------------
# one Voronoi edge: the part inside the box

cdef enum:
    AT_ORIGIN = 0         # a part's start or end is the edge's origin vertex,
    AT_END = 1            # its end vertex,
    AT_POINT = 2          # or a new point on the box boundary

cdef struct EdgePart:
    bint has              # some part of the edge lies in the box
    int start_at          # AT_ORIGIN, AT_END or AT_POINT (then sx, sy)
    int end_at            # likewise (then ex, ey)
    bint entry            # the start comes in from the box boundary
    bint exit             # the end leaves along the box boundary
    double sx, sy, ex, ey
    int s_side, e_side    # boundary side of the start (when entry) and of the end (when exit)


cdef inline void boundary_point(Box* b, double ix, double iy, double jx, double jy, int side,
                                bint at_corner, double* x, double* y) noexcept nogil:
    # where the bisector of i and j meets side `side` (or the corner that starts it), user unit
    if at_corner:
        x[0] = b.kx[side]
        y[0] = b.ky[side]
    elif side == 0:
        x[0] = bisector_at(ix, iy, jx, jy, b.symin, True, b.e); y[0] = b.ymin
    elif side == 1:
        x[0] = b.xmax; y[0] = bisector_at(ix, iy, jx, jy, b.sxmax, False, b.e)
    elif side == 2:
        x[0] = bisector_at(ix, iy, jx, jy, b.symax, True, b.e); y[0] = b.ymax
    else:
        x[0] = b.xmin; y[0] = bisector_at(ix, iy, jx, jy, b.sxmin, False, b.e)
    # the exact crossing is on the side, so its rounding is too; this only guards the bounds
    if x[0] < b.xmin: x[0] = b.xmin
    if x[0] > b.xmax: x[0] = b.xmax
    if y[0] < b.ymin: y[0] = b.ymin
    if y[0] > b.ymax: y[0] = b.ymax


cdef inline bint before_box(signed char cx, signed char cy, int sdx, int sdy) noexcept nogil:
    # a vertex outside the box, on a line that meets it: does it come before the box along (sdx, sdy)?
    return ((cx == -2 and sdx > 0) or (cx == 2 and sdx < 0)
            or (cy == -2 and sdy > 0) or (cy == 2 and sdy < 0))


cdef inline void clip_edge(Box* b, double ix, double iy, double jx, double jy,
                           bint has_o, signed char ocx, signed char ocy,
                           bint has_d, signed char dcx, signed char dcy, EdgePart* part) noexcept nogil:
    """The part in the box of the Voronoi edge between cells i (on its left) and j, running from its
    origin vertex (or infinity) to its end vertex (or infinity); sites in the scaled unit, vertex codes
    from axis_code."""
    cdef int sig[4]
    cdef int k, a, c, n_pos = 0, n_neg = 0, in_side = -1, out_side = -1
    cdef bint in_corner = False, out_corner = False, chord, o_in, d_in, o_before, d_after
    # the direction of the edge: i's cell on its left, d = rot90(j - i)
    cdef int sdx = (iy > jy) - (iy < jy), sdy = (jx > ix) - (jx < ix)
    part.has = False
    part.entry = False
    part.exit = False
    part.start_at = AT_POINT
    part.end_at = AT_POINT
    o_in = has_o and code_in(ocx) and code_in(ocy)
    d_in = has_d and code_in(dcx) and code_in(dcy)
    if o_in and d_in:
        part.has = True
        part.start_at = AT_ORIGIN
        part.end_at = AT_END
        return

    # where the bisector line crosses the boundary: walking the corners counter-clockwise, it enters
    # the box where i's side (-) gives way to j's (+) and leaves where j's gives way to i's
    for k in range(4):
        sig[k] = bisector_side(b.skx[k], b.sky[k], ix, iy, jx, jy)
        n_pos += sig[k] > 0
        n_neg += sig[k] < 0
    chord = n_pos > 0 and n_neg > 0
    if chord:
        for k in range(4):
            a = sig[k]
            c = sig[(k + 1) % 4]
            if a < 0 and c > 0:
                in_side = k
            elif a > 0 and c < 0:
                out_side = k
            elif a == 0:
                # the line passes through corner k (degenerate case: a site pair's bisector on a corner)
                if sig[(k + 3) % 4] < 0 and c > 0:
                    in_side = k; in_corner = True
                elif sig[(k + 3) % 4] > 0 and c < 0:
                    out_side = k; out_corner = True
        if in_side < 0 or out_side < 0:
            chord = False

    if o_in:
        # the edge starts inside and leaves; no chord: it only touches the box (along a side or at a
        # corner, degenerate cases) and leaves at its origin
        part.has = True
        part.start_at = AT_ORIGIN
        part.exit = True
        if chord:
            boundary_point(b, ix, iy, jx, jy, out_side, out_corner, &part.ex, &part.ey)
            part.e_side = out_side
        else:
            part.end_at = AT_ORIGIN
            part.e_side = code_side(ocx, ocy)
            part.exit = part.e_side >= 0
        return
    if d_in:
        part.has = True
        part.end_at = AT_END
        part.entry = True
        if chord:
            boundary_point(b, ix, iy, jx, jy, in_side, in_corner, &part.sx, &part.sy)
            part.s_side = in_side
        else:
            part.start_at = AT_END
            part.s_side = code_side(dcx, dcy)
            part.entry = part.s_side >= 0
        return
    if not chord:
        return
    # both ends outside: the edge holds the whole chord, or misses the box
    o_before = (not has_o) or before_box(ocx, ocy, sdx, sdy)
    d_after = (not has_d) or not before_box(dcx, dcy, sdx, sdy)
    if not (o_before and d_after):
        return
    part.has = True
    part.entry = True
    part.exit = True
    boundary_point(b, ix, iy, jx, jy, in_side, in_corner, &part.sx, &part.sy)
    boundary_point(b, ix, iy, jx, jy, out_side, out_corner, &part.ex, &part.ey)
    part.s_side = in_side
    part.e_side = out_side


# ---------------------------------------------------------------------------------------------------------
# one cell: the ring

cdef inline bint owns_corner(Box* b, int k, double ix, double iy, const double* nbx, const double* nby,
                             int m) noexcept nogil:
    """Corner k lies in the cell of i (closed), given all of i's Voronoi neighbours."""
    cdef int q
    for q in range(m):
        if bisector_side(b.skx[k], b.sky[k], ix, iy, nbx[q], nby[q]) > 0:
            return False
    return True


cdef inline bint owns_box(Box* b, double ix, double iy, const double* nbx, const double* nby, int m) noexcept nogil:
    """The box lies in the cell of i (closed), given all of i's Voronoi neighbours: its four corners do (the
    cell is convex). One corner is not enough: a cell may hold a corner, or the sides through it, and
    nothing inside the box (it touches the box there)."""
    cdef int k
    for k in range(4):
        if not owns_corner(b, k, ix, iy, nbx, nby, m):
            return False
    return True


cdef struct Points:
    # the points a cell's ring is made of, and how each boundary point was made
    double* xy                 # interleaved x, y, user unit
    signed char* side          # boundary side of the points that start or end on the boundary
    int32_t* da                # a corner (da = -1), the crossing of the bisector of sites da, db with
    int32_t* db                # a box side (dc = -1), or the circumcentre of sites da, db, dc (a vertex
    int32_t* dc                # exactly on a side); written for boundary points only
    const double* sx           # the sites, scaled unit
    const double* sy
    int corner0                # id of corner 0 (corners k at corner0 + k)


cdef inline int position_parts(Points* P, Box* b, int side, int p, double* num, double* den,
                               int* n_den) noexcept nogil:
    # the exact position of boundary point p along its side (x on sides 0 and 2, y on 1 and 3) as
    # num / den, scaled unit; returns the length of num
    cdef int a = P.da[p], c = P.dc[p], q = P.db[p]
    cdef bint horizontal = side == 0 or side == 2
    cdef double d1, d0
    if a < 0:
        num[0] = ldexp(P.xy[2 * p] if horizontal else P.xy[2 * p + 1], -b.e)
        den[0] = 1.0
        n_den[0] = 1
        return 1
    if c < 0:
        if horizontal:
            d1, d0 = two_diff(P.sx[q], P.sx[a])
        else:
            d1, d0 = two_diff(P.sy[q], P.sy[a])
        n_den[0] = difference_expansion(2.0 * d1, 2.0 * d0, den)
        return bisector_offset(P.sx[a], P.sy[a], P.sx[q], P.sy[q],
                               (b.symin if side == 0 else b.symax) if horizontal
                               else (b.sxmax if side == 1 else b.sxmin), horizontal, num)
    n_den[0] = circumcentre_denominator(P.sx[a], P.sy[a], P.sx[q], P.sy[q], P.sx[c], P.sy[c], den)
    return circumcentre_numerator(P.sx[a], P.sy[a], P.sx[q], P.sy[q], P.sx[c], P.sy[c], not horizontal, num)


cdef inline int compare_along(Points* P, Box* b, int side, int p, int q) noexcept nogil:
    """Sign of (position of p - position of q) along their common side, counter-clockwise, exactly
    (for two boundary points that round to one double)."""
    cdef double num_p[P_MAX]
    cdef double num_q[P_MAX]
    cdef double den_p[Q_MAX]
    cdef double den_q[Q_MAX]
    cdef double left[2 * P_MAX * Q_MAX]
    cdef double right[2 * P_MAX * Q_MAX]
    cdef double work[2 * P_MAX * Q_MAX]
    cdef double scaled[2 * P_MAX]
    cdef double diff[4 * P_MAX * Q_MAX]
    cdef int nd_p, nd_q, n_p, n_q, n_l, n_r, s
    n_p = position_parts(P, b, side, p, num_p, den_p, &nd_p)
    n_q = position_parts(P, b, side, q, num_q, den_q, &nd_q)
    # num_p / den_p - num_q / den_q has the sign of num_p den_q - num_q den_p times those of the dens
    n_l = expansion_product(n_p, num_p, nd_q, den_q, left, work, scaled)
    n_r = expansion_product(n_q, num_q, nd_p, den_p, right, work, scaled)
    negate_expansion(n_r, right)
    s = (expansion_sign(fast_expansion_sum_zeroelim(n_l, left, n_r, right, diff), diff)
         * expansion_sign(nd_p, den_p) * expansion_sign(nd_q, den_q))
    # t grows with x on side 0 and y on side 1, against them on sides 2 and 3
    return s if side < 2 else -s


cdef inline int walk_gap(Box* b, Points* P, int p_exit, int p_entry, int32_t* ring, int n) noexcept nogil:
    # the corners on the box boundary from an exit point counter-clockwise to the next entry point
    cdef int s1 = P.side[p_exit], s2 = P.side[p_entry], count, k
    cdef double t1, t2
    if s1 != s2:
        count = (s2 - s1 + 4) % 4
    else:
        t1 = boundary_t(s1, P.xy[2 * p_exit], P.xy[2 * p_exit + 1])
        t2 = boundary_t(s2, P.xy[2 * p_entry], P.xy[2 * p_entry + 1])
        if t2 == t1:
            # the two points round to one double (degenerate case: an excursion of the cell outside
            # the box, or a wedge inside it, thinner than the rounding): their exact order decides
            count = 4 if compare_along(P, b, s1, p_entry, p_exit) < 0 else 0
        else:
            count = 0 if t2 > t1 else 4
    for k in range(1, count + 1):
        ring[n] = P.corner0 + (s1 + k) % 4
        n += 1
    return n


cdef inline int walk_cell(Box* b, int m, const int32_t* start_pt, const int32_t* end_pt,
                          const signed char* entry, const signed char* exit_, const signed char* has,
                          Points* P, double ix, double iy, const double* nbx, const double* nby,
                          int32_t* ring) noexcept nogil:
    """The ring of one cell from its m edges in counter-clockwise order (edge q's part runs from point
    start_pt[q] to end_pt[q] of P; nbx, nby are the neighbours' sites). Writes point ids to ring (room
    for 2 m + 4), returns the count before repeats are dropped, or -1 if the parts do not chain (an
    inconsistent input)."""
    cdef int q, q0 = -1, n = 0, k, step, last_exit = -1, first_entry = -1
    cdef bint any_part = False
    for q in range(m):
        if has[q]:
            # (a part of one point, start and end the same: the edge only touches the box there)
            any_part = any_part or start_pt[q] != end_pt[q]
            if entry[q] and q0 < 0:
                q0 = q
    if not any_part:
        # the box's inside lies wholly inside the cell or wholly outside it (an edge may touch the box: at
        # a vertex on its boundary, say on a corner, where a ring of touching points alone would be one
        # point, or a walk round the box from it to itself)
        if owns_box(b, ix, iy, nbx, nby, m):
            for k in range(4):
                ring[k] = P.corner0 + k
            return 4
        return 0
    if q0 < 0:
        q0 = 0
    for step in range(m):
        q = (q0 + step) % m
        if not has[q]:
            continue
        if entry[q]:
            if last_exit >= 0:
                n = walk_gap(b, P, last_exit, start_pt[q], ring, n)
            elif first_entry < 0:
                first_entry = start_pt[q]
            last_exit = -1
        elif last_exit >= 0:
            return -1
        ring[n] = start_pt[q]
        n += 1
        if exit_[q]:
            ring[n] = end_pt[q]
            n += 1
            last_exit = end_pt[q]
    if last_exit >= 0:
        if first_entry < 0:
            return -1
        n = walk_gap(b, P, last_exit, first_entry, ring, n)
    elif first_entry >= 0:
        return -1
    return n


cdef inline void reverse(int32_t* a, int lo, int hi) noexcept nogil:
    cdef int32_t tmp
    hi -= 1
    while lo < hi:
        tmp = a[lo]; a[lo] = a[hi]; a[hi] = tmp
        lo += 1
        hi -= 1


cdef inline bint same_point(const double* pts, int p, int q) noexcept nogil:
    return pts[2 * p] == pts[2 * q] and pts[2 * p + 1] == pts[2 * q + 1]


cdef inline int sgn(double v) noexcept nogil:
    return (v > 0.0) - (v < 0.0)


# The band of magnitudes (as exponents) where orient2d's expansions neither overflow nor underflow:
# differences stay under 2^451, and a nonzero difference of such doubles is at least 2^-392, so every
# product and its rounding error remain normal doubles.
DEF TURN_TOP = 450
DEF TURN_BOTTOM = -340

cdef extern from *:
    """
    /* 2^(TURN_BOTTOM - 1) and 2^TURN_TOP: the band of turn() as magnitudes */
    #define TVORONOI_TURN_BAND_LOW 0x1p-341
    #define TVORONOI_TURN_BAND_HIGH 0x1p450
    """
    const double TURN_BAND_LOW "TVORONOI_TURN_BAND_LOW"
    const double TURN_BAND_HIGH "TVORONOI_TURN_BAND_HIGH"


cdef inline int turn(const double* pts, int a, int b, int c) noexcept nogil:
    """Exact orientation of three output points (+1 left turn, -1 right, 0 collinear) at any magnitudes.

    The points are scaled by one power of two (exact) into the band where orient2d is exact; points whose
    magnitudes span more than that band (a ring on a box 2^1000 times its sites' scale) are settled in
    exact integers (exact_integers.pxd)."""
    cdef double p[6]
    cdef double v, small = INFINITY, large = 0.0
    cdef int i, k, lo = 100000, hi = -100000, s, r
    p[0] = pts[2 * a]; p[1] = pts[2 * a + 1]; p[2] = pts[2 * b]
    p[3] = pts[2 * b + 1]; p[4] = pts[2 * c]; p[5] = pts[2 * c + 1]
    # the usual case, by comparisons alone: every nonzero magnitude inside the band (frexp's exponent k
    # of |v| lies in [TURN_BOTTOM, TURN_TOP] exactly when 2^(TURN_BOTTOM - 1) <= |v| < 2^TURN_TOP)
    for i in range(6):
        v = fabs(p[i])
        if v > large:
            large = v
        if v != 0.0 and v < small:
            small = v
    if large == 0.0:
        return 0                                   # three times the origin
    if small >= TURN_BAND_LOW and large < TURN_BAND_HIGH:
        return orient2d(p[0], p[1], p[2], p[3], p[4], p[5])
    for i in range(6):
        if p[i] != 0.0:
            frexp(p[i], &k)
            lo = min(lo, k)
            hi = max(hi, k)
    if hi < lo:
        return 0                                   # three times the origin
    if TURN_BOTTOM <= lo and hi <= TURN_TOP:
        return orient2d(p[0], p[1], p[2], p[3], p[4], p[5])
    if hi - lo <= TURN_TOP - TURN_BOTTOM:
        s = hi - TURN_TOP if hi > TURN_TOP else lo - TURN_BOTTOM
        return orient2d(ldexp(p[0], -s), ldexp(p[1], -s), ldexp(p[2], -s),
                        ldexp(p[3], -s), ldexp(p[4], -s), ldexp(p[5], -s))
    r = tvb_orient(p)
    if r == 2:                                     # no memory for the integers: the nearest exact band
        s = hi - TURN_TOP
        return orient2d(ldexp(p[0], -s), ldexp(p[1], -s), ldexp(p[2], -s),
                        ldexp(p[3], -s), ldexp(p[4], -s), ldexp(p[5], -s))
    return r


cdef inline bint folds_back(const double* pts, int a, int b, int c) noexcept nogil:
    """a -> b -> c turns back on itself (degenerate case: exact vertices closer than rounding, so a
    convex turn became a spike): c equals a, or the three are collinear and the path reverses.
    The points are in the user's unit; the orientation is taken on them scaled by 2^-e (exact), where
    no product underflows."""
    cdef int rx = sgn(pts[2 * b] - pts[2 * a]) * sgn(pts[2 * c] - pts[2 * b])
    cdef int ry = sgn(pts[2 * b + 1] - pts[2 * a + 1]) * sgn(pts[2 * c + 1] - pts[2 * b + 1])
    # on a line, going back reverses every coordinate that moves (the signs of differences of doubles
    # are exact); a convex turn of a ring mostly reverses at most one, so the exact test is rare
    if not (rx <= 0 and ry <= 0 and (rx < 0 or ry < 0)):
        return False
    return turn(pts, a, b, c) == 0


cdef inline int lowest(const int32_t* ring, int n, const double* pts) noexcept nogil:
    """The position of a ring's lowest point (smallest y, then x; its first place if it repeats)."""
    cdef int k, p, q, start = 0
    for k in range(1, n):
        p = ring[k]
        q = ring[start]
        if pts[2 * p + 1] < pts[2 * q + 1] or (pts[2 * p + 1] == pts[2 * q + 1] and pts[2 * p] < pts[2 * q]):
            start = k
    return start


cdef inline int finish_ring(int32_t* ring, int n, const double* pts) noexcept nogil:
    """Make a ring of rounded points a valid polygon and give it its canonical start.

    Repeated consecutive points (by value) are dropped, and so is the tip of a spike -- a point where
    the ring folds back on itself: exact vertices closer than doubles can separate round onto one line
    (the collapse the output documents). The ring then starts at its lowest point (smallest y, then x),
    so that every engine writes the same ring. Returns the count (0 if fewer than three points remain).

    The drops are made from the lowest point on, not from wherever the ring's walk began: where they
    could come out two ways (points zigzagging along one line), the choice reads the values alone.
    """
    cdef int k, j = 0, start = lowest(ring, n, pts), p, q, guard
    if start > 0:
        reverse(ring, 0, start)
        reverse(ring, start, n)
        reverse(ring, 0, n)
    start = 0
    for k in range(n):
        p = ring[k]
        if j > 0 and same_point(pts, ring[j - 1], p):
            continue
        while j > 1 and folds_back(pts, ring[j - 2], ring[j - 1], p):
            j -= 1
            if same_point(pts, ring[j - 1], p):
                break
        if j > 0 and same_point(pts, ring[j - 1], p):
            continue
        ring[j] = p
        j += 1
    # the same across the ring's closing point
    for guard in range(n):
        if j > 1 and same_point(pts, ring[j - 1], ring[0]):
            j -= 1
        elif j > 2 and folds_back(pts, ring[j - 2], ring[j - 1], ring[0]):
            j -= 1
        elif j > 2 and folds_back(pts, ring[j - 1], ring[0], ring[1]):
            for k in range(j - 1):
                ring[k] = ring[k + 1]
            j -= 1
        else:
            break
    if j < 3:
        return 0
    start = lowest(ring, j, pts)
    # rotate left by start (three reversals)
    reverse(ring, 0, start)
    reverse(ring, start, j)
    reverse(ring, 0, j)
    return j


cdef enum:
    CONVEX_FAST_MAX = 64      # rings up to this many points try convex_ring first (a stack buffer)

cdef extern from *:
    """
    #ifdef __SSE2__
    #include <emmintrin.h>
    #endif
    /* Of points 1..n of lx, ly (3 <= n <= 64), the place of the lowest: smallest y, then smallest x,
       the first of equals. Usually one point has the smallest y: it is found by comparisons on pairs
       of points, without branches (where it lies in a ring is random to a branch predictor); a tie in
       y is settled point by point. */
    static inline int tvoronoi_lowest_point(const double* lx, const double* ly, int n) {
        int k, start = 1;
    #ifdef __SSE2__
        __m128d low = _mm_set1_pd(ly[1]);
        unsigned long long at = 0;
        for (k = 1; k < n; k += 2)
            low = _mm_min_pd(low, _mm_loadu_pd(ly + k));
        if (k == n)
            low = _mm_min_pd(low, _mm_set1_pd(ly[n]));
        low = _mm_min_pd(low, _mm_shuffle_pd(low, low, 1));
        for (k = 1; k < n; k += 2)
            at |= (unsigned long long) _mm_movemask_pd(_mm_cmpeq_pd(_mm_loadu_pd(ly + k), low)) << (k - 1);
        if (k == n)
            at |= (unsigned long long) (ly[n] == _mm_cvtsd_f64(low)) << (n - 1);
        if (at != 0 && (at & (at - 1)) == 0)
            return __builtin_ctzll(at) + 1;
    #endif
        for (k = 2; k <= n; k++)
            if (ly[k] < ly[start] || (ly[k] == ly[start] && lx[k] < lx[start]))
                start = k;
        return start;
    }
    """
    int lowest_point "tvoronoi_lowest_point"(const double* lx, const double* ly, int n) noexcept nogil


cdef inline int convex_ring(int32_t* ring, int n, const double* pts, bint in_band) noexcept nogil:
    """The usual case of finish_ring and first_right_turn together, on one read of the ring's points:
    when every turn is strictly to the left (then no point repeats and none folds back) and the
    magnitudes lie in turn()'s band, rotate the ring to its canonical start and return n. Otherwise
    return -1, changing nothing: the caller runs finish_ring and first_right_turn. in_band: the caller
    knows every point of the ring lies in the band (clip.pyx checks the Voronoi vertices once)."""
    # the points, with the last one before the first and the first after the last: turn k (at point
    # k + 1) reads places k, k + 1, k + 2
    cdef double lx[CONVEX_FAST_MAX + 2]
    cdef double ly[CONVEX_FAST_MAX + 2]
    cdef double v, small = INFINITY, large = 0.0, acx, acy, bcx, bcy, det_left, det_right, unsure = 0.0
    cdef int32_t twice[2 * CONVEX_FAST_MAX]
    cdef int k, start = 1
    if n < 3 or n > CONVEX_FAST_MAX:
        return -1
    for k in range(n):
        twice[k] = ring[k]
        twice[n + k] = ring[k]
        lx[k + 1] = pts[2 * ring[k]]
        ly[k + 1] = pts[2 * ring[k] + 1]
    lx[0] = lx[n]
    ly[0] = ly[n]
    lx[n + 1] = lx[1]
    ly[n + 1] = ly[1]
    if not in_band:
        for k in range(1, n + 1):
            v = fabs(lx[k])
            if v > large:
                large = v
            if v != 0.0 and v < small:
                small = v
            v = fabs(ly[k])
            if v > large:
                large = v
            if v != 0.0 and v < small:
                small = v
        if not (small >= TURN_BAND_LOW and large < TURN_BAND_HIGH):
            return -1
    # orient2d's filter on every turn in one loop without branches (the compiler runs it on pairs of
    # turns): a turn is surely to the left when its rounded determinant exceeds the filter's error
    # bound; any other turn sends the ring to orient2d, turn by turn
    for k in range(n):
        acx = lx[k] - lx[k + 2]
        acy = ly[k] - ly[k + 2]
        bcx = lx[k + 1] - lx[k + 2]
        bcy = ly[k + 1] - ly[k + 2]
        det_left = acx * bcy
        det_right = acy * bcx
        unsure = unsure if det_left - det_right > CCW_ERRBOUND_A * (fabs(det_left) + fabs(det_right)) else 1.0
    if unsure != 0.0:
        for k in range(n):
            if orient2d(lx[k], ly[k], lx[k + 1], ly[k + 1], lx[k + 2], ly[k + 2]) <= 0:
                return -1
    # the canonical start: the lowest point (smallest y, then x)
    start = lowest_point(lx, ly, n)
    # the ring rotated to start there, from a copy of it twice over (one loop of n, whatever the start)
    for k in range(n):
        ring[k] = twice[start - 1 + k]
    return n


cdef inline int first_right_turn(const int32_t* ring, int n, const double* pts) noexcept nogil:
    """The position in a finished ring of its first right turn (a vertex that rounding moved across the
    line of its neighbours: the cell around it is thinner than the rounding there), or -1: every turn
    is to the left and the ring is convex."""
    cdef int k
    for k in range(n):
        if turn(pts, ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]) < 0:
            return k
    return -1


cdef inline bint ring_is_simple(const int32_t* ring, int k, const double* xy) noexcept nogil:
    # no two edges that do not follow each other meet (exact; rings are small, pairs are checked)
    cdef int a, b
    for a in range(k):
        for b in range(a + 2, k):
            if a == 0 and b == k - 1:
                continue
            if segments_meet(xy, ring[a], ring[(a + 1) % k], ring[b], ring[(b + 1) % k]):
                return False
    return True


cdef inline bint on_segment(const double* xy, int p, int q, int r) noexcept nogil:
    # r, collinear with p and q, lies within their bounding box
    return (min(xy[2 * p], xy[2 * q]) <= xy[2 * r] <= max(xy[2 * p], xy[2 * q])
            and min(xy[2 * p + 1], xy[2 * q + 1]) <= xy[2 * r + 1] <= max(xy[2 * p + 1], xy[2 * q + 1]))


cdef inline bint segments_meet(const double* xy, int p, int q, int r, int s) noexcept nogil:
    cdef int o1 = turn(xy, p, q, r), o2 = turn(xy, p, q, s)
    cdef int o3 = turn(xy, r, s, p), o4 = turn(xy, r, s, q)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return True
    return ((o1 == 0 and on_segment(xy, p, q, r)) or (o2 == 0 and on_segment(xy, p, q, s))
            or (o3 == 0 and on_segment(xy, r, s, p)) or (o4 == 0 and on_segment(xy, r, s, q)))


cdef inline bint bent(const int32_t* ring, int n, const double* pts) noexcept nogil:
    """A finished ring that rounding made cross itself (a right turn, and two edges meet): the rings
    the clipper straightens."""
    return first_right_turn(ring, n, pts) >= 0 and not ring_is_simple(ring, n, pts)
