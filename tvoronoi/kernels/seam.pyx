"""Two halves of the sites, triangulated apart, joined along the seam between them (tvoronoi/halves.py).

The sites are cut by a line x = split (or y = split): the left half holds the sites below it, the
right half the others. Each half's Delaunay triangulation is made on its own; then

  1. kept_triangles: a triangle of one half whose closed circumdisk lies strictly on its own side of the
     line holds no site of the other half in or on its circle, so it is a Delaunay triangle of all the
     sites, and so is every triangle on the same circle (all of the circle's sites are in its half, and
     the half triangulated their whole polygon). The test, in doubles, may keep one triangle of such a
     circle and not the next: a triangle on the same circle as a neighbour not kept is then not kept
     either. An infinite triangle is kept when the other half's bounding box lies strictly inside its
     hull edge: that edge is then a hull edge of all the sites.
  2. the seam sites (marked by kept_triangles): the sites of the triangles not kept. Every triangle of the whole triangulation that is
     not kept has its corners among them (near such a corner, a kept triangle would overlap it).
  3. join: the triangulation of the seam sites (made by the caller) is kept where the halves kept
     nothing. Each edge between a kept triangle and one not kept is an edge of it: the kept circle
     through its ends is empty, with no site on its far arc (the neighbour not kept is not on it, so
     no site of its half is; none of the other half is on the circle), so a circle a little past it
     through the same ends holds no site at all. A flood fill from those edges, never across them, finds its
     triangles in the region not kept; they are Delaunay triangles of all the sites (each lies in a
     polygon of cocircular sites, or is one, whose circle is empty of every site).

No decision reads the thread count: the same triangulation on one thread or two.
"""

import numpy as np

from cython.parallel cimport prange
from libc.math cimport fabs
from libc.stdint cimport int32_t

from tvoronoi.kernels.predicates cimport incircle, orient2d
from tvoronoi.kernels.mesh cimport nxt, prv
from tvoronoi.kernels.prefetch cimport AHEAD_BYTES, prefetch

cdef enum:
    OK = 0
    NOT_AN_EDGE = 1     # a kept edge missing from the seam's triangulation (a defect to report)
    WRONG_COUNT = 2     # the joined triangulation does not have 2 n - 2 triangles (a defect to report)

STATUS_OK = OK

# The circumdisk test in doubles, with a bound on its rounding error (see disks_clear), for sites scaled
# below 1 in magnitude (as the engines scale them). Triangles whose sides' product of three
# (|b'|_1 |c'|_1 (|b'|_1 + |c'|_1)) is below TINY, where products of differences could underflow, and
# triangles whose determinant is below FLAT times its magnitude (nearly flat) are left to the seam:
# always safe, as keeping is the only decision that needs proof. Above TINY, an underflowed product is
# off by at most 2^-1074, far below the relative bound. SLACK is 64 units of rounding, about three
# times the bound derived below (the error of u counts twice: in the centre and in the radius).
cdef double EPS = 2.0 ** -53
cdef double SLACK = 64.0 * 2.0 ** -53
cdef double FLAT = 2.0 ** -20
cdef double TINY = 2.0 ** -900


cdef enum:
    DISK_BLOCK = 64     # kept_triangles: triangles whose disks are tested in one vectorized loop
    PARALLEL_MIN_TRIANGLES = 1 << 16    # kept_triangles: fewer are judged on one thread
    MAX_PARTS = 64


cdef void disks_clear(const double* xs, const double* ys, const int32_t* tv, Py_ssize_t t0, int count, int inf,
                      double split, int axis, bint below, double* clear) noexcept nogil:
    """For triangles t0 .. t0 + count - 1 (count <= DISK_BLOCK), clear[j] = 1.0 only if the closed
    circumdisk of triangle t0 + j lies strictly below the line (below) or strictly above it; 0.0 also
    when the doubles cannot tell (the triangle is then left to the seam). In a loop without branches
    that the compiler runs on pairs of triangles. A triangle with a corner at infinity reads site 0
    there; its entry is not to be used.

    With b' = b - a, c' = c - a, the centre is a + u, u = (c'y B - b'y C, b'x C - c'x B) / d, where
    B = |b'|^2, C = |c'|^2, d = 2 (b'x c'y - b'y c'x), and the radius is |u| <= |u|_1. With D = |b'|_1 |c'|_1
    (which bounds |b'x c'y| + |b'y c'x|, and |b'|^2 by |b'|_1^2) and one rounding unit e: d is off by at
    most 6 e D + e |d|, each numerator by 7 e D (|b'|_1 + |c'|_1) + e |N|, so once |d| > FLAT D the
    computed u is off in the 1-norm by at most 14 e D (|b'|_1 + |c'|_1) / |d| + |u|_1 (6 e D / |d| + 3 e);
    the centre's coordinate adds e of itself, the final sum 2 e of its terms. SLACK times each term
    covers all of it about three times over.

    The line is x = split; for y = split (axis 1) the coordinates are read swapped, which mirrors the
    triangle: d and both numerators are negated, u's components swap, and the bound is the same. The
    test above the line is the one below it on negated coordinates along the axis."""
    cdef double pax[DISK_BLOCK]
    cdef double pay[DISK_BLOCK]
    cdef double pbx[DISK_BLOCK]
    cdef double pby[DISK_BLOCK]
    cdef double pcx[DISK_BLOCK]
    cdef double pcy[DISK_BLOCK]
    cdef double bx_, by_, cx_, cy_, nb, nc, big, d, wb, wc, ux, uy, r, err, centre, verdict
    cdef double slack = SLACK, flat = FLAT, tiny = TINY, sign = 1.0 if below else -1.0
    cdef const double* along = xs if axis == 0 else ys        # the coordinate across the line, read as x
    cdef const double* other = ys if axis == 0 else xs
    cdef int j, a, b, c
    for j in range(count):
        if (j & 3) == 0:
            prefetch(<const char*> &tv[3 * (t0 + j)] + AHEAD_BYTES)   # (the triangles, read in order)
        a = tv[3 * (t0 + j)]; b = tv[3 * (t0 + j) + 1]; c = tv[3 * (t0 + j) + 2]
        a = a if a != inf else 0
        b = b if b != inf else 0
        c = c if c != inf else 0
        pax[j] = along[a]; pay[j] = other[a]; pbx[j] = along[b]; pby[j] = other[b]
        pcx[j] = along[c]; pcy[j] = other[c]
    for j in range(count):
        bx_ = pbx[j] - pax[j]; by_ = pby[j] - pay[j]; cx_ = pcx[j] - pax[j]; cy_ = pcy[j] - pay[j]
        nb = fabs(bx_) + fabs(by_)
        nc = fabs(cx_) + fabs(cy_)
        big = nb * nc
        d = 2.0 * (bx_ * cy_ - by_ * cx_)
        wb = bx_ * bx_ + by_ * by_
        wc = cx_ * cx_ + cy_ * cy_
        ux = (cy_ * wb - by_ * wc) / d
        uy = (bx_ * wc - cx_ * wb) / d
        r = fabs(ux) + fabs(uy)
        centre = pax[j] + ux
        err = slack * (big * (nb + nc) / fabs(d) + r * big / fabs(d) + r + fabs(pax[j]) + fabs(split))
        # the verdict, then the cases the bound does not cover (tiny, nearly flat): not clear
        verdict = 1.0 if (sign * centre + r) + err < sign * split else 0.0
        verdict = verdict if fabs(d) > flat * big else 0.0
        clear[j] = verdict if big * (nb + nc) > tiny else 0.0


cdef Py_ssize_t judge_part(const double* xs, const double* ys, const int32_t* tv, Py_ssize_t lo, Py_ssize_t hi,
                           int inf, double split, int axis, bint below, const double* qx, const double* qy,
                           signed char* keep, int32_t* judged) noexcept nogil:
    # triangles lo..hi-1 (lo a multiple of DISK_BLOCK) judged into keep; those not kept listed in
    # judged[0..], in order; returns their count
    cdef Py_ssize_t t, count = 0
    cdef int a, b, c, u, w
    cdef double clear[DISK_BLOCK]
    for t in range(lo, hi):
        if t % DISK_BLOCK == 0:
            disks_clear(xs, ys, tv, t, <int> min(DISK_BLOCK, hi - t), inf, split, axis, below, clear)
        a = tv[3 * t]; b = tv[3 * t + 1]; c = tv[3 * t + 2]
        if a != inf and b != inf and c != inf:
            keep[t] = clear[t % DISK_BLOCK] != 0.0
        else:
            # an infinite triangle (u, w, inf): its region is the open half-plane left of u->w
            if a == inf:
                u = b; w = c
            elif b == inf:
                u = c; w = a
            else:
                u = a; w = b
            keep[t] = (orient2d(xs[u], ys[u], xs[w], ys[w], qx[0], qy[0]) < 0
                       and orient2d(xs[u], ys[u], xs[w], ys[w], qx[1], qy[1]) < 0
                       and orient2d(xs[u], ys[u], xs[w], ys[w], qx[2], qy[2]) < 0
                       and orient2d(xs[u], ys[u], xs[w], ys[w], qx[3], qy[3]) < 0)
        if not keep[t]:
            judged[count] = <int32_t> t
            count += 1
    return count


def kept_triangles(const double[::1] xs, const double[::1] ys, const int32_t[::1] tv, const int32_t[::1] opp,
                   int first, int inf, double split, int axis, bint below, double ox0, double oy0, double ox1,
                   double oy1, signed char[::1] keep, signed char[::1] seam, int threads=1):
    """Which triangles of one half are triangles of the whole triangulation (1) or left to the seam (0).

    Parameters
    ----------
    xs, ys : (n,) float64, the sites; tv, opp : (3 k,) int32, the half's triangles (vertex inf at
        infinity) and twins, its triangle t being triangle first + t of the whole (the twins count so).
    split, axis : the line: x = split (axis 0) or y = split (axis 1).
    below : the half lies below the line (its sites' coordinate < split), else on or above it.
    ox0, oy0, ox1, oy1 : the bounding box of the other half's sites.
    keep : (k,) int8, written.
    seam : (n,) int8, set to 1 at the sites of the triangles not kept (the seam sites; the halves' sites
        are apart, so both halves can mark at once).
    threads : the triangles are judged in a run of whole blocks on each (the same result for any count).
    """
    cdef Py_ssize_t n_tri = tv.shape[0] // 3, t, nt, head = 0, tail = 0, j
    cdef int a, b, c, u, w, k, o, d, part
    cdef double qx[4]
    cdef double qy[4]
    if keep.shape[0] != n_tri or opp.shape[0] != tv.shape[0] or seam.shape[0] < inf:
        raise ValueError("kept_triangles: keep must hold one entry a triangle, opp one a half-edge, seam one a site")
    if n_tri == 0:
        return
    cdef int32_t[::1] queue = np.empty(n_tri, np.int32)
    cdef Py_ssize_t n_blocks = (n_tri + DISK_BLOCK - 1) // DISK_BLOCK
    cdef int T = max(1, min(threads, MAX_PARTS)) if n_tri >= PARALLEL_MIN_TRIANGLES else 1
    cdef Py_ssize_t starts[MAX_PARTS + 1]
    cdef Py_ssize_t counts[MAX_PARTS]
    qx[0] = ox0; qy[0] = oy0; qx[1] = ox1; qy[1] = oy0; qx[2] = ox1; qy[2] = oy1; qx[3] = ox0; qy[3] = oy1
    for part in range(T + 1):
        starts[part] = min(n_blocks * part // T * DISK_BLOCK, n_tri)
    with nogil:
        # each part's triangles judged, those not kept listed from its start in queue; then, in order,
        # their sites marked and the finite ones queued for the pass below
        for part in prange(T, num_threads=T, schedule="static", chunksize=1):
            counts[part] = judge_part(&xs[0], &ys[0], &tv[0], starts[part], starts[part + 1], inf, split, axis,
                                      below, qx, qy, &keep[0], &queue[starts[part]])
        for part in range(T):
            for j in range(counts[part]):
                t = queue[starts[part] + j]
                a = tv[3 * t]; b = tv[3 * t + 1]; c = tv[3 * t + 2]
                if a != inf and b != inf and c != inf:
                    seam[a] = 1; seam[b] = 1; seam[c] = 1
                    queue[tail] = <int32_t> t       # (tail <= starts[part] + j: the list moves down)
                    tail += 1
                else:
                    if a != inf:
                        seam[a] = 1
                    if b != inf:
                        seam[b] = 1
                    if c != inf:
                        seam[c] = 1

        # degenerate case: cocircular sites. The doubles' verdict differs from one triangle of a circle to
        # the next (the bound reads the circle from the triangle's first corner), so a kept triangle whose
        # neighbour not kept is on the same circle (exact in-circle 0) is not kept either, until none is:
        # the edges between kept triangles and the rest then have no site on the kept circle's far arc
        # (the queue starts with the finite triangles not kept, listed above)
        while head < tail:
            t = queue[head]
            head += 1
            for k in range(3):
                nt = opp[3 * t + k] // 3 - first
                if not keep[nt]:
                    continue
                a = tv[3 * nt]; b = tv[3 * nt + 1]; c = tv[3 * nt + 2]
                if a == inf or b == inf or c == inf:
                    continue
                d = tv[3 * t + (k + 2) % 3]             # the corner of t across the shared edge
                if incircle(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], xs[d], ys[d]) == 0:
                    keep[nt] = 0
                    seam[a] = 1; seam[b] = 1; seam[c] = 1
                    queue[tail] = <int32_t> nt
                    tail += 1


cdef inline int edge_from(const int32_t* tv, const int32_t* opp, const int32_t* vedge, int a, int b,
                          int most) noexcept nogil:
    """The half-edge a->b of a triangulation (a finite), found around a from vedge[a] in at most ``most``
    steps (a site has fewer neighbours than there are sites; a broken triangulation cannot loop here);
    -1 if none."""
    cdef int e0 = vedge[a], e = e0, steps = 0
    if e0 < 0:
        return -1
    while steps < most:
        if tv[nxt(e)] == b:
            return e
        e = opp[prv(e)]             # the next half-edge out of a
        if e == e0:
            return -1
        steps += 1
    return -1


def join(int32_t[::1] tv, int32_t[::1] opp, signed char[::1] keep, const int32_t[::1] holes, int gap_lo,
         int gap_hi, int n, const int32_t[::1] tv_m, const int32_t[::1] opp_m, const int32_t[::1] sites_m,
         int expected):
    """Join two halves in place: the triangles of both lie in tv, opp, in one numbering (vertex n at
    infinity), the left half's below gap_lo and the right half's from gap_hi on; keep marks those kept
    (kept_triangles) and holes lists, increasing, the slots of the others and of the gap between.
    The seam's triangles (tv_m, opp_m, its site k being site sites_m[k]) that the fill reaches take the
    holes in order; triangles from slot ``expected`` on (2 n - 2 for n distinct sites) then move down into
    any holes still free below it (repeated sites leave some). The work is that of the seam alone.

    Returns STATUS_OK, or a defect (NOT_AN_EDGE, WRONG_COUNT); tv[:3 expected], opp[:3 expected] then
    hold the triangulation. keep is overwritten (which slots are taken).
    """
    cdef int cap = keep.shape[0], n_m = sites_m.shape[0], n_tri_m = tv_m.shape[0] // 3, n_holes = holes.shape[0]
    cdef int t, k, e, o, a, b, h, F, q, head = 0, tail = 0, count = cap - n_holes, status = OK
    cdef int32_t[::1] slot_m = np.full(max(n_tri_m, 1), -1, np.int32)
    cdef int32_t[::1] local = np.full(n + 1, -1, np.int32)        # site -> seam site
    cdef int32_t[::1] vedge = np.full(n_m + 1, -1, np.int32)
    cdef int32_t[::1] across = np.full(max(3 * n_tri_m, 1), -1, np.int32)   # seam half-edge -> kept twin
    cdef int32_t[::1] queue = np.empty(max(n_tri_m, 1), np.int32)
    if tv.shape[0] != 3 * cap or opp.shape[0] != 3 * cap or not 0 <= gap_lo <= gap_hi <= cap:
        raise ValueError("join: tv, opp and keep disagree")
    with nogil:
        for k in range(n_m):
            local[sites_m[k]] = k
        local[n] = n_m
        for e in range(3 * n_tri_m):
            if tv_m[e] != n_m:
                vedge[tv_m[e]] = e

        # each edge between a triangle not kept and a kept one: its reverse in the seam's triangulation is
        # where the fill starts, and the fill does not cross it
        for q in range(n_holes):
            t = holes[q]
            if gap_lo <= t < gap_hi:
                continue
            for k in range(3):
                e = opp[3 * t + k]              # the kept side, a->b
                if not keep[e // 3]:
                    continue
                a = local[tv[e]]
                b = local[tv[3 * (e // 3) + (e % 3 + 1) % 3]]
                if a < 0 or b < 0:
                    status = NOT_AN_EDGE
                    break
                if b != n_m:
                    h = edge_from(&tv_m[0], &opp_m[0], &vedge[0], b, a, n_m + 1)
                else:
                    h = edge_from(&tv_m[0], &opp_m[0], &vedge[0], a, b, n_m + 1)
                    h = opp_m[h] if h >= 0 else -1
                if h < 0 or across[h] >= 0:
                    status = NOT_AN_EDGE
                    break
                across[h] = e
                if slot_m[h // 3] < 0:
                    slot_m[h // 3] = 0
                    queue[tail] = h // 3
                    tail += 1
            if status != OK:
                break

        # no kept triangle at all: the seam's triangulation is the whole of it
        if status == OK and count == 0:
            for t in range(n_tri_m):
                slot_m[t] = 0
                queue[tail] = t
                tail += 1

        # the fill: the seam's triangles reached from those edges, never across them
        while status == OK and head < tail:
            t = queue[head]
            head += 1
            for k in range(3):
                if across[3 * t + k] >= 0:
                    continue
                o = opp_m[3 * t + k] // 3
                if slot_m[o] < 0:
                    slot_m[o] = 0
                    queue[tail] = o
                    tail += 1
        if status == OK and (count + tail != expected or tail > n_holes):
            status = WRONG_COUNT
        if status == OK:
            # the reached triangles into the holes, linked to each other and to the kept ones
            for k in range(tail):
                slot_m[queue[k]] = holes[k]
                keep[holes[k]] = 1
            for k in range(tail):
                t = queue[k]
                F = holes[k]
                for e in range(3):
                    a = tv_m[3 * t + e]
                    tv[3 * F + e] = n if a == n_m else sites_m[a]
                    h = across[3 * t + e]
                    if h >= 0:
                        opp[3 * F + e] = h
                        opp[h] = 3 * F + e
                    else:
                        o = opp_m[3 * t + e]
                        opp[3 * F + e] = 3 * slot_m[o // 3] + o % 3
            # repeated sites: the holes still free below expected take the triangles from there on
            k = tail
            t = cap - 1
            while k < n_holes and holes[k] < expected:
                while not keep[t]:
                    t -= 1
                F = holes[k]
                for e in range(3):
                    tv[3 * F + e] = tv[3 * t + e]
                    o = opp[3 * t + e]
                    opp[3 * F + e] = o
                    opp[o] = 3 * F + e
                keep[F] = 1
                keep[t] = 0
                k += 1
                t -= 1
    return status
