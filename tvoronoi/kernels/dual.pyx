"""The Voronoi diagram as a half-edge structure (DCEL), built as the dual of a Delaunay triangulation."""

import numpy as np

from cython.parallel cimport prange
from libc.stdint cimport int32_t, int64_t, uint64_t
from libc.math cimport fabs, ldexp
from libc.string cimport memcpy, memmove

from tvoronoi.kernels.construct cimport circumcentre, circumcentres_block, CENTRE_BLOCK
from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.predicates cimport incircle
from tvoronoi.kernels.mesh cimport nxt, prv
from tvoronoi.kernels.prefetch cimport AHEAD_BYTES, prefetch
from tvoronoi.kernels.populate cimport populate_part, fill_int32

cdef enum:
    AHEAD = 4       # the walk around site a + AHEAD starts loading while site a is walked
    BLOCK = 1 << 18     # parallel loops run in blocks of this many, signals polled between
    PARALLEL_MIN_SITES = 1 << 15    # fewer sites: one thread (waking the others costs more than it saves)
    # sites walked by one thread in a row, each run taken by the next thread free (neighbouring cells share
    # cache lines, and a twin in another run waits for the look-up after the walks: Fortune's runs in
    # sweep order are strips a few sites tall; at 10^6 uniform sites, runs of 4,096 left 26.5% of its
    # sites loose and 8.9% of the twins, runs of 16,384 6.8% and 2.3%; the incremental engine's 8.6%
    # and 2.9%, then 4.2% and 1.4%)
    WALK_CHUNK = 1 << 14
    TRI_BLOCK = 1 << 12     # triangles given their vertices by one thread in a row
    POLL_BLOCKS = 64        # blocks of triangles between two polls for signals
    MAX_THREADS = 64        # threads the first pass runs on (more are given that many)
    SIDE_MIN = 1 << 12      # room in each thread's side list of the first pass, at least

# Layout of the Voronoi DCEL (struct of arrays, -1 for "at infinity"):
#   he_origin[h]  Voronoi vertex h starts from, -1 if h comes from infinity
#   he_twin[h]    the same edge seen from the neighbouring cell
#   the cycle around a cell, counter-clockwise: its half-edges, consecutive from face_edge (next_in_cell);
#                 an unbounded cell's cycle closes through infinity: the edge
#                 that runs off to infinity is followed by the one coming back
#   he_face[h]    the site whose cell h bounds
# An edge lies on the bisector of he_face[h] and he_face[he_twin[h]].


cdef extern from *:
    """
    /* edge_order's band of magnitudes (see there) and its constants: 2^-53, and Shewchuk's error bound
       of a 2x2 determinant of differences, (3 + 16 eps) eps */
    #define TV_ORDER_BAND_LOW 0x1p-400
    #define TV_ORDER_BAND_HIGH 0x1p400
    #define TV_ORDER_EPS 0x1p-53
    #define TV_ORDER_CCW ((3.0 + 16.0 * 0x1p-53) * 0x1p-53)
    #define TV_ORDER_SLACK (1.0 + 0x1p-40)
    """
    const double ORDER_BAND_LOW "TV_ORDER_BAND_LOW"
    const double ORDER_BAND_HIGH "TV_ORDER_BAND_HIGH"
    const double ORDER_EPS "TV_ORDER_EPS"
    const double ORDER_CCW "TV_ORDER_CCW"
    const double ORDER_SLACK "TV_ORDER_SLACK"


cdef inline int edge_order(double rx, double ry, double lx, double ly, double ax, double ay) noexcept nogil:
    """Whether the Voronoi edge from vertex r to vertex l (correctly rounded circumcentres) runs with site
    a on its left, from the rounded values alone: +1 surely (its Delaunay edge is locally Delaunay and the
    Voronoi edge has a positive length), -1 surely not (the Delaunay edge is illegal), 0 undecided (the
    exact in-circle test decides: a zero-length edge, or one too short for the rounding).

    Site a (exact, the user's unit) and the edge's exact ends c_r, c_l lie on either side of the bisector
    of a and its neighbour b, so T = cross(c_l - c_r, a - c_r) has the sign of the edge's length along
    the bisector, counted positive the way a's cell runs (counter-clockwise): positive for a locally
    Delaunay edge, zero for cocircular sites, negative for an illegal one. T is taken on the rounded ends
    r = c_r + d_r, l = c_l + d_l, each coordinate within eta = 2^-53 m of the exact one (m: the largest
    magnitude, in a band where no product overflows and the rounding of subnormal values, at most
    2^-1075 each, lies far below the eta^2 term; a subnormal difference is exact). Expanding the cross
    product, with |cross(x, y)| <= |x|_1 |y|_1, |d_l - d_r|_1 <= 4 eta and |d_r|_1 <= 2 eta:
        |T(r, l) - T| <= 2 eta |l - r|_1 + 4 eta |a - r|_1 + 24 eta^2,
    and evaluating T(r, l) in doubles adds at most (3 + 16 eps) eps (|u1 v2| + |u2 v1|) (Shewchuk's
    bound for orient2d, the same expression). The sum, raised for its own rounding, bounds the error."""
    cdef double u1 = lx - rx, u2 = ly - ry, v1 = ax - rx, v2 = ay - ry
    cdef double left = u1 * v2, right = u2 * v1, t = left - right
    cdef double m = fabs(rx), eta, bound
    m = fabs(ry) if fabs(ry) > m else m
    m = fabs(lx) if fabs(lx) > m else m
    m = fabs(ly) if fabs(ly) > m else m
    m = fabs(ax) if fabs(ax) > m else m
    m = fabs(ay) if fabs(ay) > m else m
    if not (m >= ORDER_BAND_LOW and m <= ORDER_BAND_HIGH):
        return 0                # (NaN too: a vertex that overflowed)
    eta = m * ORDER_EPS
    bound = (ORDER_CCW * (fabs(left) + fabs(right))
             + 2.0 * eta * (fabs(u1) + fabs(u2)) + 4.0 * eta * (fabs(v1) + fabs(v2)) + 24.0 * eta * eta)
    bound *= ORDER_SLACK         # (the exact magnitudes and differences within a few roundings of these)
    if t > bound:
        return 1
    if t < -bound:
        return -1
    return 0


cdef int find(int32_t* parent, int v) noexcept nogil:
    cdef int root = v, up
    while parent[root] != root:
        root = parent[root]
    while parent[v] != root:     # path compression
        up = parent[v]
        parent[v] = root
        v = up
    return root


def voronoi_from_delaunay(const double[::1] xs, const double[::1] ys,
                          const int32_t[::1] tv, const int32_t[::1] opp, int exponent=0, int threads=1,
                          int parallel_min=PARALLEL_MIN_SITES, bint clip_room=False,
                          int walk_chunk=WALK_CHUNK, bint check=False, bint give_triangulation=False,
                          he_room=None):
    """Voronoi DCEL of n distinct sites from their Delaunay triangulation.

    Triangles whose circumcircles coincide (cocircular sites) share one
    Voronoi vertex, and the zero-length edges between them are not emitted.

    The vertices are the finite triangles' circumcentres, numbered in the triangles' order (the
    triangulations come with each site's triangles together, in the sites' order). One walk around
    each site, in the sites' order, then makes the DCEL cell by cell: the half-edges of a cell are
    consecutive, in he_next order, from face_edge (an unbounded cell's first half-edge comes from
    infinity, its last runs off to infinity). The sites come in a spatial order (BRIO or the
    sweep's), so a cell's vertices and half-edges lie near its neighbours' in memory for the phases
    that follow.

    Parameters
    ----------
    xs, ys : (n,) float64, the sites.
    tv, opp : (3 * n_tri,) int32, the triangulation of incremental.triangulate or fortune.sweep
        (vertex n is the vertex at infinity).
    exponent : int, the sites are in a unit 2^-exponent of the user's: vertices are
        returned in the user's unit, each coordinate correctly rounded.
    threads : int, threads for the vertices and the walks (the result is the same for any count),
        when there are at least parallel_min sites.
    walk_chunk : int, sites walked in a row by one thread (tests make it small, so that most twins
        wait for the pass after the walks).
    clip_room : bool, leave room after the vertices for the points clip.clip_cells adds on the box
        (at most two per edge, and four corners), so that it writes them there instead of copying the
        vertices: address space only, as rows never written cost no memory.
    check : bool, also test that every edge is locally Delaunay (a guard for a triangulation whose maker
        did not: Fortune's sweep without its closing repair), at little cost: the walks have both ends
        of each Voronoi edge at hand, and the exact in-circle test runs only where their rounded
        values cannot tell. If some edge is not, the result is only {"illegal": count}: no diagram
        (the caller repairs the triangulation and builds again).
    give_triangulation : bool, the caller gives tv and opp up (not to be read again; each is written
        only if it is an array the dual can write): the finite triangles are moved to the start of tv in
        place and ``triangles`` is a view of it, not a copy; opp holds, as the walks go, the links between
        twins (walk_site: at each Delaunay half-edge, the Voronoi half-edge of its twin), instead of an
        array of their own. A result of only {"illegal": count} leaves both as they were (opp is
        restored from the half-edges).
    he_room : optional (origin, twin, face) int32 arrays, writable and C-contiguous, for the half-edges:
        used when each holds at least tv's length (the returned ones are views of them), else new
        arrays are made (tvoronoi.halves faults theirs in on a thread that waits for the other half).

    Returns
    -------
    dict of arrays: vertices (m, 2) float64; he_origin, he_twin, he_face (h,) int32;
    face_edge (n,) int32 (the first half-edge of each cell, -1 for a site without one); triangles
    (k, 3) int32, the finite Delaunay triangles in the order of tv (with no cocircular sites, vertex k is
    the circumcentre of row k); with clip_room, vertex_room: the
    buffer whose first m rows are the vertices. The next half-edge of a cell is the following one
    while the face stays the same, then the first again (next_in_cell).
    """
    cdef int n = xs.shape[0], inf = n
    cdef int n_he_d = tv.shape[0], n_tri = n_he_d // 3
    cdef int n_blocks = (n_tri + TRI_BLOCK - 1) // TRI_BLOCK
    cdef int32_t[::1] first_e = np.empty(max(n, 1), np.int32)   # where each site's walk starts
    cdef int32_t[::1] h_first = np.zeros(n + 1, np.int32)    # the cell's first half-edge (a count first)
    cdef int32_t[::1] v_block = np.zeros(n_blocks + 1, np.int32)  # the first vertex of each block of triangles
    cdef int32_t[::1] vid = np.empty(max(n_tri, 1), np.int32)  # triangle -> its vertex, -1 if infinite
    cdef int32_t[::1] link_own      # Delaunay half-edge -> the Voronoi half-edge of its twin (walk_site)
    cdef int32_t* link              # (that, or opp itself when it is given up)
    cdef int32_t[::1] he_origin
    cdef int32_t[::1] he_twin
    cdef int32_t[::1] he_face
    if he_room is not None and all(len(a) >= n_he_d for a in he_room):
        he_origin, he_twin, he_face = he_room
    else:
        he_origin = np.empty(n_he_d, np.int32)
        he_twin = np.empty(n_he_d, np.int32)
        he_face = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] face_edge = np.empty(max(n, 1), np.int32)
    cdef int32_t[::1] parent                                  # vertices merged by cocircular sites
    cdef double[:, ::1] centre
    cdef int32_t[:, ::1] tri
    cdef int32_t[::1] edge_of
    cdef int t, e, a, b, c, h = 0, m = 0, n_finite = 0, n_hull, g, k, lo, hi, count, bk

    if n < parallel_min:
        threads = 1
    # (what is given up is written only if the dual can: else the triangles are copied, link is its own)
    cdef bint give_tv = give_triangulation and n_he_d > 0 and writable(tv)
    cdef bint give_opp = give_triangulation and n_he_d > 0 and writable(opp)
    if give_opp:
        link = <int32_t*> &opp[0]
    else:
        link_own = np.empty(max(n_he_d, 1), np.int32)
        link = &link_own[0]

    cdef FirstPass parts[MAX_THREADS]
    cdef int T = min(threads, MAX_THREADS), side_cap
    cdef int32_t[::1] side_buf
    cdef bint overflow
    if T > 1:
        # each thread's run of triangles (whole blocks) and the sites it counts itself (the rest go to its
        # side list): from the least site of its first triangle on, as the triangles come in the order
        # of their least sites
        side_cap = max(SIDE_MIN, n_tri // (4 * T))
        side_buf = np.empty(2 * T * side_cap, np.int32)
        for k in range(T):
            parts[k].t_lo = min(n_blocks * k // T * TRI_BLOCK, n_tri)
            parts[k].t_hi = min(n_blocks * (k + 1) // T * TRI_BLOCK, n_tri)
            parts[k].s_lo = 0 if k == 0 else max(parts[k - 1].s_lo, least_site(&tv[0], parts[k].t_lo, n_tri, inf))
            parts[k].cap_side = side_cap
            parts[k].side_site = &side_buf[2 * k * side_cap]
            parts[k].side_e = parts[k].side_site + side_cap
        for k in range(T):
            parts[k].s_hi = parts[k + 1].s_lo if k + 1 < T else n
    with nogil:
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            fill_int32(&first_e[<int64_t> n * k // T], <int> (<int64_t> n * (k + 1) // T - <int64_t> n * k // T), -1)
            fill_int32(&face_edge[<int64_t> n * k // T], <int> (<int64_t> n * (k + 1) // T - <int64_t> n * k // T),
                       -1)
        # which triangles are finite (counted by blocks of triangles, for their vertices' numbers), and
        # where each site's walk starts: any half-edge out of it, or for a hull site the one whose dual
        # comes from infinity (the twin of a hull edge p->q of an infinite triangle starts at q). On
        # more than one thread, also how many half-edges each walk will emit, so that the walks can run
        # apart: one per Delaunay edge out of the site (counted in h_first)
        # (the triangles last to first, so that each site keeps its first half-edge in triangle order
        # by plain stores, no test of what is there; then the hull's, which take precedence)
        n_hull = 0
        if T == 1:
            for t in range(n_tri - 1, -1, -1):
                if (t & 3) == 0:
                    prefetch(<const char*> &tv[3 * t] - AHEAD_BYTES)     # (the triangles, read last to first)
                a = tv[3 * t]; b = tv[3 * t + 1]; c = tv[3 * t + 2]
                if a == inf or b == inf or c == inf:
                    vid[n_hull] = t         # (vid is free until the vertices are numbered: the hull's triangles)
                    n_hull += 1
                else:
                    v_block[t // TRI_BLOCK + 1] += 1
                    first_e[c] = 3 * t + 2
                    first_e[b] = 3 * t + 1
                    first_e[a] = 3 * t
            for k in range(n_hull):
                hull_starts(&tv[0], &opp[0], vid[k], inf, &first_e[0])
        else:
            # a run of triangles on each thread (the same counts and the same first half-edges: each run
            # keeps the least of its own, the side lists' are merged by the least), its hull triangles
            # listed in vid from the run's start
            for k in prange(T, num_threads=T, schedule="static", chunksize=1):
                first_pass_part(&parts[k], &tv[0], inf, &first_e[0], &h_first[0], &v_block[0], &vid[0])
            overflow = False
            for k in range(T):
                overflow = overflow or parts[k].overflow
            if overflow:
                # (a side list ran out of room: triangles far from the order of their sites) the whole
                # pass again on this thread
                for k in range(n + 1):
                    h_first[k] = 0
                for k in range(n_blocks + 1):
                    v_block[k] = 0
                for k in range(n):
                    first_e[k] = -1
                parts[0].t_lo = 0
                parts[0].t_hi = n_tri
                parts[0].s_lo = 0
                parts[0].s_hi = n
                parts[0].cap_side = 0
                first_pass_part(&parts[0], &tv[0], inf, &first_e[0], &h_first[0], &v_block[0], &vid[0])
                T = 1
            for k in range(T):
                merge_side(&parts[k], &first_e[0], &h_first[0])
            for k in range(T):
                for g in range(parts[k].n_hull):
                    hull_starts(&tv[0], &opp[0], vid[parts[k].t_lo + g], inf, &first_e[0])
        for bk in range(n_blocks):
            v_block[bk + 1] += v_block[bk]
        n_finite = v_block[n_blocks]
        if threads > 1:
            # counts -> offsets: a site's half-edges follow those of the sites before it
            for a in range(n):
                count = h_first[a]
                h_first[a] = h
                h += count
            h_first[n] = h
    # (an edge is dual to a Delaunay edge between two sites, n_he_d bounds twice their number)
    centre_buf = np.empty((n_finite + (n_he_d + 4 if clip_room else 0), 2), np.float64)
    centre = centre_buf
    # the finite triangles: written as the vertices are numbered, unless tv is given up (then moved
    # within it once the walks are done)
    tri = None if give_tv else np.empty((n_finite, 3), np.int32)
    cdef signed char[::1] zero = np.zeros(max(n_he_d, 1), np.int8)   # zero-length: cocircular triangles
    cdef int n_zero = 0, n_marked = 0, n_illegal = 0
    cdef int32_t* tri_rows = &tri[0, 0] if n_finite > 0 and not give_tv else NULL
    cdef double* centres = &centre[0, 0] if n_finite > 0 else NULL
    cdef Walk w
    # (the sites whose cells have a twin to look up after the walks: walks on more than one thread)
    cdef signed char[::1] loose_arr = np.zeros(n if threads > 1 else 1, np.int8)
    cdef signed char* loose = &loose_arr[0]
    w.loose = loose if threads > 1 else NULL
    w.tv = &tv[0]; w.first_e = &first_e[0]; w.inf = inf
    w.link = link; w.vid = &vid[0]
    w.he_origin = &he_origin[0]; w.he_twin = &he_twin[0]; w.he_face = &he_face[0]
    w.xs = &xs[0]; w.ys = &ys[0]; w.centre = centres; w.zero = &zero[0]
    cdef int h0, marked, illegal
    w.check = check
    w.exponent = exponent
    w.up = ldexp(1.0, exponent) if -1022 <= exponent <= 1022 else 0.0
    w.down = ldexp(1.0, -exponent) if -1022 <= exponent <= 1022 else 0.0

    with nogil:
        # the arrays written whole, faulted in by runs of pages (a part on each thread)
        for k in prange(threads, num_threads=threads, schedule="static", chunksize=1):
            populate_part(&vid[0], n_tri * sizeof(int32_t), k, threads)
            populate_part(tri_rows, 3 * n_finite * sizeof(int32_t), k, threads)
            populate_part(centres, 2 * n_finite * sizeof(double), k, threads)
            if not give_opp:
                populate_part(link, n_he_d * sizeof(int32_t), k, threads)
            populate_part(&he_origin[0], n_he_d * sizeof(int32_t), k, threads)
            populate_part(&he_twin[0], n_he_d * sizeof(int32_t), k, threads)
            populate_part(&he_face[0], n_he_d * sizeof(int32_t), k, threads)
        # the vertices: each finite triangle's number (those of the triangles before it), its sites
        # and its circumcentre (construct.circumcentre), by blocks of triangles, on the threads, each
        # taking the next block when it is done: a centre costs more where its coordinates are small
        # (their roundings lie closer together, so that the first tier settles fewer), and the halves
        # of a build lie side by side (sites in [0, 1)^2: the blocks of the left half took 1.3 times
        # as long as the right's)
        lo = 0
        while lo < n_blocks:
            poll_signals()
            hi = lo + POLL_BLOCKS if lo + POLL_BLOCKS < n_blocks else n_blocks
            for bk in prange(lo, hi, num_threads=threads, schedule="dynamic", chunksize=1):
                number_vertices(&tv[0], &opp[0], bk * TRI_BLOCK, min((bk + 1) * TRI_BLOCK, n_tri), v_block[bk],
                                inf, &vid[0], tri_rows, link, &xs[0], &ys[0], exponent, centres)
            lo = hi
        # the walks: one per site, in the sites' order, each making its cell's half-edges,
        # marking its zero-length edges as it goes; on one thread, one after the other
        if threads == 1:
            h = 0
            for a in range(n):
                if (a & POLL_MASK) == 0:
                    poll_signals()
                if a + AHEAD < n and first_e[a + AHEAD] >= 0:
                    prefetch(&tv[first_e[a + AHEAD]])
                    prefetch(&link[first_e[a + AHEAD]])
                h_first[a] = h
                h0 = h
                h = walk_site(&w, a, h, 0, n, &n_marked, &n_illegal)
                if h > h0:
                    face_edge[a] = h0
            h_first[n] = h
        else:
            # in runs of WALK_CHUNK sites, each taken by the next thread free (a core of this machine can
            # run slower than the other for a while), each walk from the offsets counted above; a
            # twin that another run may not have made yet is left as its place in link, looked up once
            # every walk is done, in the cells of the sites marked loose (the arrays are the same for
            # any count)
            lo = 0
            while lo < n:
                poll_signals()
                hi = lo + BLOCK if lo + BLOCK < n else n
                for a in prange(lo, hi, num_threads=threads, schedule="dynamic", chunksize=walk_chunk):
                    if a + AHEAD < n and first_e[a + AHEAD] >= 0:
                        prefetch(&tv[first_e[a + AHEAD]])
                        prefetch(&link[first_e[a + AHEAD]])
                    marked = 0
                    illegal = 0
                    g = a - (a - lo) % walk_chunk
                    walk_site(&w, a, h_first[a], g, min(g + walk_chunk, hi), &marked, &illegal)
                    if h_first[a + 1] > h_first[a]:
                        face_edge[a] = h_first[a]
                    n_marked += marked
                    n_illegal += illegal
                lo = hi
            for a in prange(n, num_threads=threads, schedule="static"):
                if loose[a]:
                    for g in range(h_first[a], h_first[a + 1]):
                        if he_twin[g] < 0:
                            he_twin[g] = link[-1 - he_twin[g]]

        # (the walks marked one half-edge of each zero-length edge; drop_zero_edges marks the other)
        if n_illegal == 0:
            n_zero = 2 * n_marked
    if n_illegal > 0:
        if give_opp:
            edge_of = np.empty(max(h, 1), np.int32)
            restore_opp(&tv[0], link, n_he_d, inf, &he_twin[0], &edge_of[0])
        return {"illegal": n_illegal}      # (not a Delaunay triangulation: no diagram)
    if give_tv:
        finite_to_front_on(<int32_t*> &tv[0] if n_tri > 0 else NULL, n_tri, inf, &v_block[0], n_blocks, threads)
        triangles = np.asarray(tv.base).reshape(-1)[: 3 * n_finite].reshape(n_finite, 3)
    else:
        triangles = np.asarray(tri)
    if n_zero > 0:
        parent = np.empty(max(n_finite, 1), dtype=np.int32)
        with nogil:
            m, h = drop_zero_edges(h, n_finite, n, &he_origin[0], &he_twin[0], &he_face[0], &face_edge[0],
                                   &zero[0], &parent[0], &vid[0], link, &centre[0, 0], threads)
    else:
        m = n_finite

    out = {
        "vertices": centre_buf[:m],
        "he_origin": np.asarray(he_origin)[:h],
        "he_twin": np.asarray(he_twin)[:h],
        "he_face": np.asarray(he_face)[:h],
        "face_edge": np.asarray(face_edge)[:n],
        "triangles": triangles,
    }
    if clip_room:
        out["vertex_room"] = centre_buf
    return out


cdef void number_vertices(const int32_t* tv, const int32_t* opp, int t0, int t1, int m, int inf, int32_t* vid,
                          int32_t* tri, int32_t* link, const double* xs, const double* ys, int e,
                          double* centre) noexcept nogil:
    # the finite triangles t0..t1 - 1 numbered from m on (vid), their sites copied to tri (unless NULL)
    # and their circumcentres computed (by blocks: construct.circumcentres_block); an infinite triangle's
    # vid is -1. And every triangle's twins turned in link for the walks (walk_site): at each half-edge,
    # the twin of the one before it (link may be opp itself: a triangle's three are read, then written)
    cdef double gx[3][CENTRE_BLOCK]
    cdef double gy[3][CENTRE_BLOCK]
    cdef int t = t0, a, b, c, k, m0
    cdef int32_t o0, o1, o2
    while t < t1:
        k = 0
        m0 = m
        while t < t1 and k < CENTRE_BLOCK:
            o0 = opp[3 * t]; o1 = opp[3 * t + 1]; o2 = opp[3 * t + 2]
            link[3 * t] = o2; link[3 * t + 1] = o0; link[3 * t + 2] = o1
            a = tv[3 * t]; b = tv[3 * t + 1]; c = tv[3 * t + 2]
            if a == inf or b == inf or c == inf:
                vid[t] = -1
                t += 1
                continue
            vid[t] = m
            if tri != NULL:
                tri[3 * m] = a; tri[3 * m + 1] = b; tri[3 * m + 2] = c
            gx[0][k] = xs[a]; gy[0][k] = ys[a]
            gx[1][k] = xs[b]; gy[1][k] = ys[b]
            gx[2][k] = xs[c]; gy[2][k] = ys[c]
            m += 1
            k += 1
            t += 1
        circumcentres_block(k, gx[0], gy[0], gx[1], gy[1], gx[2], gy[2], e, &centre[2 * m0], 2)


cdef struct FirstPass:
    # one thread's run of the dual's first pass (voronoi_from_delaunay)
    int t_lo, t_hi          # its triangles
    int s_lo, s_hi          # the sites whose first half-edge and count it writes itself
    int n_hull              # its hull triangles, listed in vid from t_lo on
    int n_side, cap_side    # the other sites it met: side_site[j], met at half-edge side_e[j] (-1: a count
    int32_t* side_site      # only, from a hull triangle)
    int32_t* side_e
    bint overflow           # more than cap_side of them


cdef inline void meet(FirstPass* P, int x, int e, int32_t* first_e, int32_t* h_first) noexcept nogil:
    # site x met at half-edge e out of it (-1: counted only)
    if P.s_lo <= x < P.s_hi:
        if e >= 0:
            first_e[x] = e
        h_first[x] += 1
    elif P.n_side < P.cap_side:
        P.side_site[P.n_side] = x
        P.side_e[P.n_side] = e
        P.n_side += 1
    else:
        P.overflow = True


cdef void first_pass_part(FirstPass* P, const int32_t* tv, int inf, int32_t* first_e, int32_t* h_first,
                          int32_t* v_block, int32_t* vid) noexcept nogil:
    # the first pass over triangles t_lo..t_hi-1, last to first (each site it writes keeps its least
    # half-edge of the run); counts one half-edge a Delaunay edge out of each site
    cdef int t, e, a, b, c
    P.n_hull = 0
    P.n_side = 0
    P.overflow = False
    for t in range(P.t_hi - 1, P.t_lo - 1, -1):
        if (t & 3) == 0:
            prefetch(<const char*> &tv[3 * t] - AHEAD_BYTES)     # (the triangles, read last to first)
        a = tv[3 * t]; b = tv[3 * t + 1]; c = tv[3 * t + 2]
        if a == inf or b == inf or c == inf:
            vid[P.t_lo + P.n_hull] = t
            P.n_hull += 1
            for e in range(3 * t, 3 * t + 3):
                if tv[e] != inf and tv[nxt(e)] != inf:
                    meet(P, tv[e], -1, first_e, h_first)
        else:
            v_block[t // TRI_BLOCK + 1] += 1
            meet(P, c, 3 * t + 2, first_e, h_first)
            meet(P, b, 3 * t + 1, first_e, h_first)
            meet(P, a, 3 * t, first_e, h_first)


cdef void merge_side(FirstPass* P, int32_t* first_e, int32_t* h_first) noexcept nogil:
    # a run's side list into the counts and the first half-edges (the least half-edge wins)
    cdef int j, x, e
    for j in range(P.n_side):
        x = P.side_site[j]
        e = P.side_e[j]
        h_first[x] += 1
        if e >= 0 and (first_e[x] < 0 or e < first_e[x]):
            first_e[x] = e


cdef inline void hull_starts(const int32_t* tv, const int32_t* opp, int t, int inf, int32_t* first_e) noexcept nogil:
    # hull triangle t: each hull site's walk starts at the twin of the hull edge into it
    cdef int e
    for e in range(3 * t, 3 * t + 3):
        if tv[e] != inf and tv[nxt(e)] != inf:
            first_e[tv[nxt(e)]] = opp[e]


cdef int least_site(const int32_t* tv, int t, int n_tri, int inf) noexcept nogil:
    # the least finite site of triangle t (of the first finite one from t on; inf if none)
    cdef int k, v, least = inf
    while t < n_tri:
        for k in range(3):
            v = tv[3 * t + k]
            if v < least:
                least = v
        if least < inf:
            return least
        t += 1
    return inf


cdef finite_to_front_on(int32_t* tv, int n_tri, int inf, const int32_t* v_block, int n_blocks, int threads):
    """finite_to_front on ``threads`` threads, each a run of whole blocks of triangles (TRI_BLOCK; the
    finite ones before block bk: v_block[bk]). A run's finite triangles move to v_block[its first
    block] on, at most as far as it starts: those that land before its start, where the run before
    still reads, wait in a buffer until every run has moved the others, then go in place. One thread
    when that buffer would be large (most triangles infinite, as on a circle of sites)."""
    cdef int T = min(threads, MAX_THREADS, n_blocks), k, b0, lo, dst, t, j
    cdef int waiting[MAX_THREADS]
    cdef int64_t held[MAX_THREADS + 1]
    held[0] = 0
    for k in range(T):
        b0 = n_blocks * k // T
        lo = b0 * TRI_BLOCK
        waiting[k] = min(lo - v_block[b0], v_block[n_blocks * (k + 1) // T] - v_block[b0])
        held[k + 1] = held[k] + waiting[k]
    if T < 2 or held[T] > n_tri // 8:
        with nogil:
            finite_to_front(tv, n_tri, inf)
        return
    buffer_arr = np.empty(max(3 * held[T], 1), np.int32)
    cdef int32_t[::1] buffer = buffer_arr
    cdef int32_t* buf = &buffer[0]
    with nogil:
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            finite_part(tv, n_blocks * k // T * TRI_BLOCK, min(n_blocks * (k + 1) // T * TRI_BLOCK, n_tri), inf,
                        v_block[n_blocks * k // T], waiting[k], &buf[3 * held[k]])
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            if waiting[k] > 0:
                memcpy(&tv[3 * v_block[n_blocks * k // T]], &buf[3 * held[k]], 3 * waiting[k] * sizeof(int32_t))


cdef void finite_part(int32_t* tv, int lo, int hi, int inf, int dst, int waiting, int32_t* held) noexcept nogil:
    # the finite triangles of lo..hi-1 in order: the first ``waiting`` of them copied to held, the others
    # moved to their places from dst + waiting on (at or after lo, at or before where they are), each
    # run of them between infinite ones by one move
    cdef int t = lo, run, m = 0, k
    while t < hi:
        if tv[3 * t] == inf or tv[3 * t + 1] == inf or tv[3 * t + 2] == inf:
            t += 1
            continue
        run = t
        while run < hi and tv[3 * run] != inf and tv[3 * run + 1] != inf and tv[3 * run + 2] != inf:
            run += 1
        if m < waiting:
            k = min(waiting - m, run - t)
            memcpy(&held[3 * m], &tv[3 * t], 3 * k * sizeof(int32_t))
            m += k
            t += k
        if t < run and dst + m != t:
            memmove(&tv[3 * (dst + m)], &tv[3 * t], 3 * (run - t) * sizeof(int32_t))
        m += run - t
        t = run


cdef void finite_to_front(int32_t* tv, int n_tri, int inf) noexcept nogil:
    # the finite triangles of tv moved to its start, in their order: each run of them between infinite
    # ones by one move (the hull's few infinite triangles lie scattered; nothing moves before the first)
    cdef int t = 0, run, m = 0
    while t < n_tri:
        if tv[3 * t] == inf or tv[3 * t + 1] == inf or tv[3 * t + 2] == inf:
            t += 1
            continue
        run = t
        while run < n_tri and tv[3 * run] != inf and tv[3 * run + 1] != inf and tv[3 * run + 2] != inf:
            run += 1
        if m != t:
            memmove(&tv[3 * m], &tv[3 * t], 3 * (run - t) * sizeof(int32_t))
        m += run - t
        t = run


cdef struct Walk:
    # what the walks read (the triangulation, where each starts, the vertices) and write (the DCEL)
    const int32_t* tv
    const int32_t* first_e
    signed char* loose              # 1 at a site whose cell has a twin left to look up (NULL: none can)
    int inf
    int32_t* link
    const int32_t* vid
    int32_t* he_origin
    int32_t* he_twin
    int32_t* he_face
    const double* xs
    const double* ys
    const double* centre
    signed char* zero
    bint check                      # test each edge's order too (edge_order), counting illegal ones
    int exponent                    # the sites are in the unit 2^-exponent of the vertices'
    double up                       # 2^exponent and 2^-exponent, when both are normal doubles
    double down


cdef inline int walk_site(Walk* w, int a, int h, int done_from, int done_to, int* n_marked,
                          int* n_illegal) noexcept nogil:
    """The cell of site a, counter-clockwise from first_e[a]; returns the next free half-edge.

    One half-edge per Delaunay edge a->b with b finite, from h on: its origin is the vertex of the
    triangle on the right of a->b (-1 if that is infinite), its twin the half-edge of b->a. Sites from
    done_from up to a have been walked: the twin made by an earlier one is looked up and linked; one
    of a site before done_from (another thread's) is left as -1 - its place in link, looked up later,
    as is one whose site comes later; one whose site lies outside done_from..done_to - 1 (another
    run's, which will not link it either) marks a loose (w.loose, if not NULL).

    link holds at each Delaunay half-edge s, until a walk writes over it, the twin of prv(s), the edge
    into s's origin before it (number_vertices turns opp so): at an edge e out of a, link[e] is the
    next edge out of a, one load a step (opp[prv(e)] would cost the step prv's arithmetic on its chain
    of loads too). Once the walk has stepped from e to e' = a->b and made e''s half-edge, it writes
    that number at the place e it stepped from: the place of b->a = prv(e) in link, where b's walk
    looks it up (at nxt(b->a), from its own edge b->a). A place of link is thus written by one walk
    only, the walk that reads it to step, after it read it: link may be opp itself (a triangulation
    given up). No walk writes the place of its first edge before it leaves it: the edge it steps to
    the first from is the last it reaches, and the first edge's half-edge is finished then.

    The zero-length edges are marked in zero as the walk goes (n_marked counts them), each from the
    half-edge of the site that comes first (b > a). Equal exact centres round to equal doubles, so
    only an edge whose ends have equal rounded centres can join cocircular triangles; the exact
    in-circle test decides. (Distinct vertices that round to one point, nearly cocircular sites, are
    kept apart: the clipper names rounded points by their values.)

    With w.check, every edge is also tested to be locally Delaunay (a guard over a triangulation whose
    maker did not guarantee it: Fortune's sweep), on the rounded vertices first (edge_order), by the
    exact in-circle test where they cannot tell; n_illegal counts the edges that are not. The cells are
    then not to be used: the caller repairs the triangulation and walks again.
    """
    # (locals, so that the stores below do not make the compiler read the struct again)
    cdef const int32_t* tv = w.tv
    cdef int32_t* link = w.link
    cdef const int32_t* vid = w.vid
    cdef const double* centre = w.centre
    cdef int32_t* he_origin = w.he_origin
    cdef int32_t* he_twin = w.he_twin
    cdef int32_t* he_face = w.he_face
    cdef int e0 = w.first_e[a], e, b, t = -1, o = -1, g, vr = -1, vl, inf = w.inf, h0 = h
    cdef double rx = 0.0, ry = 0.0, lx = 0.0, ly = 0.0, ax = 0.0, ay = 0.0
    cdef bint linked, check = w.check, rounded_ok = False
    cdef bint outside = False
    cdef unsigned run = <unsigned> (done_to - done_from)
    if e0 < 0:
        return h                # a repeated site, or none of the triangles (no cell)
    if check:
        # site a in the vertices' unit, exactly (else every edge of this walk goes to the exact test)
        # (by the powers of two themselves where both are normal doubles: each product is then one
        # rounding of the exact value, as ldexp's result is, without a call per site)
        if -1022 <= w.exponent <= 1022:
            ax = w.xs[a] * w.up
            ay = w.ys[a] * w.up
            rounded_ok = ax * w.down == w.xs[a] and ay * w.down == w.ys[a]
        else:
            ax = ldexp(w.xs[a], w.exponent)
            ay = ldexp(w.ys[a], w.exponent)
            rounded_ok = ldexp(ax, -w.exponent) == w.xs[a] and ldexp(ay, -w.exponent) == w.ys[a]
    e = e0
    while True:
        # e = a->b, o its twin (the edge crossed last), vr the vertex on the right of a->b (triangle t,
        # o's), vl the one on its left (triangle e // 3); for e0, o, t and vr are known at the end
        b = tv[nxt(e)]
        vl = vid[e // 3]
        if vl >= 0:
            lx = centre[2 * vl]; ly = centre[2 * vl + 1]
        if b != inf:
            # the twin, when its site's walk made it (done_from <= b < a): linked both ways, with no
            # branch (an unlinked twin's store lands on h itself, then is overwritten)
            linked = (<unsigned> (b - done_from)) < <unsigned> (a - done_from)
            outside |= (<unsigned> (b - done_from)) >= run
            g = link[nxt(e)]    # (read whether or not b's walk wrote it: selected below)
            g = g if linked else h
            he_twin[g] = h
            he_twin[h] = g if linked else -1 - nxt(e)
            he_face[h] = a
            if e != e0:
                link[o] = h     # (o was read to come here, by this walk alone)
                he_origin[h] = vr
                if vr >= 0 and vl >= 0 and b > a and (check or (lx == rx and ly == ry)):
                    edge_tests(w, a, b, t, e, h, rx, ry, lx, ly, ax, ay, rounded_ok, n_marked, n_illegal)
            h += 1
        t = e // 3
        vr = vl; rx = lx; ry = ly
        o = e
        e = link[e]    # the next edge out (the twin of the edge into a before e), not yet written over
        if e == e0:
            break
    # the first edge's half-edge: its twin o and the triangle t on its right are the last crossed
    if h > h0 and tv[nxt(e0)] != inf:
        link[o] = h0
        he_origin[h0] = vr
        b = tv[nxt(e0)]
        vl = vid[e0 // 3]
        if vr >= 0 and vl >= 0 and b > a:
            edge_tests(w, a, b, t, e0, h0, rx, ry, centre[2 * vl], centre[2 * vl + 1], ax, ay, rounded_ok,
                       n_marked, n_illegal)
    if w.loose != NULL:
        w.loose[a] = outside
    return h


cdef inline void edge_tests(Walk* w, int a, int b, int t, int e, int h, double rx, double ry, double lx, double ly,
                            double ax, double ay, bint rounded_ok, int* n_marked, int* n_illegal) noexcept nogil:
    # a Voronoi edge h (of Delaunay edge e = a->b, b > a, both its vertices finite: r on the right, in
    # triangle t, and l): marked zero-length if its sites are cocircular, and, with w.check, counted as
    # illegal if its Delaunay edge is not locally Delaunay (without it, called only where r == l)
    cdef int sign
    if w.check:
        if not rounded_ok or edge_order(rx, ry, lx, ly, ax, ay) <= 0:
            sign = far_site_inside(a, b, &w.tv[3 * t], &w.tv[3 * (e // 3)], w.xs, w.ys)
            if sign == 0:
                w.zero[h] = 1
                n_marked[0] += 1
            elif sign > 0:
                n_illegal[0] += 1
    elif lx == rx and ly == ry:
        if far_site_inside(a, b, &w.tv[3 * t], &w.tv[3 * (e // 3)], w.xs, w.ys) == 0:
            w.zero[h] = 1
            n_marked[0] += 1


cdef void restore_opp(const int32_t* tv, int32_t* opp, int n_he_d, int inf, const int32_t* he_twin,
                      int32_t* edge_of) noexcept nogil:
    # opp as it was before the dual (every twin linked): the walks left at each half-edge s the twin of
    # the one before it, d = prv(s) (number_vertices), written over where d is between finite sites by
    # the Voronoi half-edge of d's twin, whose twin is d's own; edge_of: scratch, a place per Voronoi
    # half-edge
    cdef int d, t, k
    cdef int32_t v[3]
    for d in range(n_he_d):
        if tv[d] != inf and tv[nxt(d)] != inf:
            edge_of[he_twin[opp[nxt(d)]]] = d
    for t in range(n_he_d // 3):
        v[0] = opp[3 * t]; v[1] = opp[3 * t + 1]; v[2] = opp[3 * t + 2]
        for k in range(3):
            d = 3 * t + k
            opp[d] = edge_of[v[(k + 1) % 3]] if tv[d] != inf and tv[nxt(d)] != inf else v[(k + 1) % 3]


cdef bint writable(const int32_t[::1] a):
    return isinstance(a.base, np.ndarray) and a.base.flags.writeable


cdef inline int far_site_inside(int a, int b, const int32_t* t_right, const int32_t* t_left, const double* xs,
                                const double* ys) noexcept nogil:
    # Delaunay edge a->b between triangle (b, a, c) on its right and (a, b, d) on its left (both
    # counter-clockwise): +1 if d lies strictly inside the circle of (b, a, c) (the edge is illegal),
    # 0 on it (degenerate case: four cocircular sites, one Voronoi vertex), -1 outside (exact)
    cdef int c = third(t_right, a, b), d = third(t_left, a, b)
    return incircle(xs[b], ys[b], xs[a], ys[a], xs[c], ys[c], xs[d], ys[d])


cdef inline int next_in_cell(int g, int h, const int32_t* he_face, const int32_t* face_edge) noexcept nogil:
    # the half-edge after g around its cell: the following one while the face is the same, else the first
    if g + 1 < h and he_face[g + 1] == he_face[g]:
        return g + 1
    return face_edge[he_face[g]]


cdef inline int third(const int32_t* t, int a, int b) noexcept nogil:
    # the site of triangle t that is neither a nor b
    if t[0] != a and t[0] != b:
        return t[0]
    if t[1] != a and t[1] != b:
        return t[1]
    return t[2]


cdef struct DropPart:
    # one thread's run of half-edges [g_lo, g_hi) and of vertices [v_lo, v_hi) in drop_zero_edges
    int g_lo, g_hi, v_lo, v_hi
    int n_zero          # its zero-length half-edges
    int n_listed        # those listed for the merges: the walks marked them (the half-edge of smaller index)
    int first_listed    # the first of them (-1: none)
    int landed[MAX_THREADS]     # the twins this run marked, by the run they lie in
    int k_lo            # the new number of its first kept half-edge
    int q_lo            # where its listed half-edges start in the list
    int n_roots         # its vertices that stay (each group's smallest)
    int r_lo            # the new number of the first of them
    int face_before     # the face of the half-edge before the run (-1 for the first)


cdef inline void mark_range(int lo, int hi, const int32_t* he_twin, signed char* zero, int* listed, int* first,
                            int* landed, const int* bound) noexcept nogil:
    # each half-edge g in lo..hi - 1 that its walk marked (the half-edge of the site that comes first: its
    # twin comes after it) listed, its twin marked and counted in landed by the run it lies in
    cdef int g, tw, j
    for g in range(lo, hi):
        tw = he_twin[g]
        if zero[g] == 1 and tw > g:
            zero[tw] = 1
            j = 0
            while tw >= bound[j]:
                j += 1
            landed[j] += 1
            if listed[0] == 0:
                first[0] = g
            listed[0] += 1


cdef void mark_twins(DropPart* P, const int32_t* he_twin, signed char* zero, const DropPart* parts, int T) noexcept nogil:
    # the twins of the half-edges of P that the walks marked, marked too (mark_range). Words with no
    # mark are skipped whole: `zero`'s pages are read only where a walk wrote to them. (On threads, the
    # twin marked may lie in another run, whose thread reads that mark only to find that its twin comes
    # before it: what it reads there changes nothing)
    cdef int k, lo = P.g_lo, hi = P.g_hi, w_lo = (lo + 7) >> 3, w_hi = hi >> 3, listed = 0, first = -1
    cdef int head_end = min(hi, 8 * w_lo)
    cdef int landed[MAX_THREADS]
    cdef int bound[MAX_THREADS]
    cdef const uint64_t* words = <const uint64_t*> zero
    for k in range(T):
        landed[k] = 0
        bound[k] = parts[k].g_hi
    mark_range(lo, head_end, he_twin, zero, &listed, &first, landed, bound)
    for k in range(w_lo, w_hi):
        if words[k] != 0:
            mark_range(8 * k, 8 * k + 8, he_twin, zero, &listed, &first, landed, bound)
    mark_range(max(head_end, 8 * w_hi), hi, he_twin, zero, &listed, &first, landed, bound)
    P.n_listed = listed
    P.first_listed = first
    for k in range(T):
        P.landed[k] = landed[k]


cdef inline void number_kept(DropPart* P, const signed char* zero, const int32_t* he_twin, int32_t* newh,
                             int32_t* listed) noexcept nogil:
    # each half-edge's new number (the kept ones before it), and the listed half-edges from q_lo on. No
    # branch: where zero-length edges lie follows no pattern the processor could learn (sites numbered
    # along a BRIO curve); a half-edge not listed is written at the next free place, which the next
    # listed one overwrites (those after the run's last one land on the next run's first place: put
    # back once every run is done)
    cdef int g, k = P.k_lo, q = P.q_lo
    for g in range(P.g_lo, P.g_hi):
        newh[g] = k
        k += 1 - zero[g]
        listed[q] = g
        q += zero[g] & (he_twin[g] > g)


cdef inline int count_roots(const DropPart* P, const int32_t* parent) noexcept nogil:
    cdef int v, roots = 0
    for v in range(P.v_lo, P.v_hi):
        roots += parent[v] == v
    return roots


cdef inline void number_groups(DropPart* P, int32_t* parent, int32_t* vmap, double* centre) noexcept nogil:
    # each vertex of P pointed at its group's root (walks up that read only: only a vertex's own place is
    # written, by its own run), the roots numbered from r_lo on and their centres moved down to the start
    # of P's run in place (each to no later place than its own: every place is written after it was read)
    cdef int v, r, i = P.v_lo
    for v in range(P.v_lo, P.v_hi):
        r = v
        while parent[r] != r:
            r = parent[r]
        parent[v] = r
        if r == v:
            vmap[v] = P.r_lo + (i - P.v_lo)
            centre[2 * i] = centre[2 * v]
            centre[2 * i + 1] = centre[2 * v + 1]
            i += 1
    P.n_roots = i - P.v_lo


cdef inline void move_kept(const DropPart* P, int32_t* he_origin, int32_t* he_twin, int32_t* he_face,
                           int32_t* face_edge, const int32_t* parent, const int32_t* vmap,
                           const int32_t* newh) noexcept nogil:
    # the kept half-edges of P moved down to the start of its run in place, with their new numbers (their
    # twins', their origins' groups'), each cell's first where its face begins
    # (a zero-length half-edge is written too, with no branch, at the place of the next kept one, which
    # then overwrites it: every place is written after it was read; those after the run's last kept
    # half-edge land beyond its kept ones, inside the run. Its face's first is the next kept one's
    # number: every cell keeps some edges, those from and to infinity or three at least)
    cdef int g, k, a, o, last_face = P.face_before, shift = P.g_lo - P.k_lo
    for g in range(P.g_lo, P.g_hi):
        k = newh[g]
        o = he_origin[g]
        he_origin[k + shift] = vmap[parent[o]] if o >= 0 else -1
        he_twin[k + shift] = newh[he_twin[g]]
        a = he_face[g]
        he_face[k + shift] = a
        if a != last_face:
            face_edge[a] = k
            last_face = a


cdef (int, int) drop_zero_edges(int h, int m, int n, int32_t* he_origin, int32_t* he_twin, int32_t* he_face,
                                int32_t* face_edge, signed char* zero, int32_t* parent, int32_t* vmap,
                                int32_t* newh, double* centre, int threads) noexcept nogil:
    """Cocircular sites: merge the vertices at both ends of each zero-length half-edge into one (the
    group's smallest number), renumber the vertices in order, and remove those half-edges, keeping
    each cell's in order and the cells contiguous. Returns the new vertex and half-edge counts.

    The walks marked one half-edge of each zero-length edge, that of the site that comes first; the
    other is marked here. On more than one thread, each takes a run of the half-edges and of the
    vertices: they are counted, then each run numbered from the counts of the runs before it and moved
    down to its own start, then the runs moved together in order (the same arrays for any count). The
    merges run on this thread."""
    cdef DropPart parts[MAX_THREADS]
    cdef int T = max(1, min(threads, MAX_THREADS)), k, q, g, u, w, v
    cdef int h_kept = 0, n_listed = 0, n_roots = 0
    for k in range(T):
        parts[k].g_lo = <int> (<int64_t> h * k // T)
        parts[k].g_hi = <int> (<int64_t> h * (k + 1) // T)
        parts[k].v_lo = <int> (<int64_t> m * k // T)
        parts[k].v_hi = <int> (<int64_t> m * (k + 1) // T)
        parts[k].k_lo = 0
        parts[k].q_lo = 0
        parts[k].r_lo = 0
        parts[k].face_before = he_face[parts[k].g_lo - 1] if parts[k].g_lo > 0 else -1
    # the twins of the zero-length half-edges the walks marked, marked too and counted by runs; each
    # vertex its own group
    for k in prange(T, num_threads=T, schedule="static", chunksize=1):
        mark_twins(&parts[k], he_twin, zero, parts, T)
        for v in range(parts[k].v_lo, parts[k].v_hi):
            parent[v] = v
    for k in range(T):
        parts[k].n_zero = parts[k].n_listed
        for q in range(T):
            parts[k].n_zero += parts[q].landed[k]
        parts[k].k_lo = h_kept
        parts[k].q_lo = n_listed
        h_kept += (parts[k].g_hi - parts[k].g_lo) - parts[k].n_zero
        n_listed += parts[k].n_listed
    # each kept half-edge's new number, and the zero-length edges listed, each from its half-edge of
    # smaller index (its twin joins the same two vertices), in vmap (free until the vertices are
    # renumbered; they form a forest: fewer than m)
    for k in prange(T, num_threads=T, schedule="static", chunksize=1):
        number_kept(&parts[k], zero, he_twin, newh, vmap)
    for k in range(1, T):
        if parts[k].n_listed > 0:
            vmap[parts[k].q_lo] = parts[k].first_listed
    # the merges: both ends of each zero-length edge in one group, named by its smallest vertex
    for q in range(n_listed):
        g = vmap[q]
        u = find(parent, he_origin[g])
        w = find(parent, he_origin[next_in_cell(g, h, he_face, face_edge)])
        parent[max(u, w)] = min(u, w)
    # the vertices renumbered in order: a root takes the next number, any other vertex its root's (a
    # merge keeps the smaller root); every cell's first half-edge unknown
    if T > 1:
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            parts[k].n_roots = count_roots(&parts[k], parent)
            fill_int32(&face_edge[<int64_t> n * k // T], <int> (<int64_t> n * (k + 1) // T - <int64_t> n * k // T), -1)
        for k in range(T):
            parts[k].r_lo = n_roots
            n_roots += parts[k].n_roots
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            number_groups(&parts[k], parent, vmap, centre)
        # (every root numbered before any half-edge reads its number)
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            move_kept(&parts[k], he_origin, he_twin, he_face, face_edge, parent, vmap, newh)
    else:
        fill_int32(face_edge, n, -1)
        number_groups(&parts[0], parent, vmap, centre)
        n_roots = parts[0].n_roots
        move_kept(&parts[0], he_origin, he_twin, he_face, face_edge, parent, vmap, newh)
    # each run's vertices and kept half-edges moved to their places, in order (a run's new place is
    # before its own, and after the places of the runs before it)
    for k in range(1, T):
        memmove(&centre[2 * parts[k].r_lo], &centre[2 * parts[k].v_lo], 2 * parts[k].n_roots * sizeof(double))
        u = (parts[k].g_hi - parts[k].g_lo) - parts[k].n_zero
        memmove(&he_origin[parts[k].k_lo], &he_origin[parts[k].g_lo], u * sizeof(int32_t))
        memmove(&he_twin[parts[k].k_lo], &he_twin[parts[k].g_lo], u * sizeof(int32_t))
        memmove(&he_face[parts[k].k_lo], &he_face[parts[k].g_lo], u * sizeof(int32_t))
    return n_roots, h_kept


TRI_BLOCK_SIZE = TRI_BLOCK    # (for tests: the triangles a thread takes at a time)


def circumcentres(const double[::1] xs, const double[::1] ys, const int32_t[:, ::1] tri, int e=0,
                  bint by_blocks=True):
    """Correctly rounded circumcentres (k, 2) of triangles tri (k, 3) of sites xs, ys, times 2^e (by_blocks:
    as the dual computes them, construct.circumcentres_block; else one by one: the same doubles)."""
    cdef Py_ssize_t k, n_tri = tri.shape[0]
    cdef double[:, ::1] out = np.empty((n_tri, 2), np.float64)
    cdef double gx[3][CENTRE_BLOCK]
    cdef double gy[3][CENTRE_BLOCK]
    cdef int a, b, c, j, cnt
    with nogil:
        if not by_blocks:
            for k in range(n_tri):
                a = tri[k, 0]; b = tri[k, 1]; c = tri[k, 2]
                circumcentre(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], e, &out[k, 0], &out[k, 1])
        else:
            k = 0
            while k < n_tri:
                cnt = <int> min(<Py_ssize_t> CENTRE_BLOCK, n_tri - k)
                for j in range(cnt):
                    for a in range(3):
                        b = tri[k + j, a]
                        gx[a][j] = xs[b]
                        gy[a][j] = ys[b]
                circumcentres_block(cnt, gx[0], gy[0], gx[1], gy[1], gx[2], gy[2], e, &out[k, 0], 2)
                k += cnt
    return np.asarray(out)


def voronoi_collinear(const double[::1] xs, const double[::1] ys):
    """Voronoi DCEL of n >= 1 distinct collinear sites: parallel strips.

    Sites must be given in order along their line. Each pair of consecutive
    sites is split by a whole bisector line (both ends at infinity), so the
    diagram has no vertex and every cell is a strip (a half-plane at the ends).

    Returns the same dict as voronoi_from_delaunay (no triangles).
    """
    cdef int n = xs.shape[0], k, n_he = 2 * max(n - 1, 0)
    cdef int32_t[::1] he_origin = np.full(n_he, -1, np.int32)
    cdef int32_t[::1] he_twin = np.empty(n_he, np.int32)
    cdef int32_t[::1] he_face = np.empty(n_he, np.int32)
    cdef int32_t[::1] face_edge = np.full(n, -1, np.int32)
    # half-edge 2k bounds site k (bisector of k, k+1); half-edge 2k+1 bounds site k+1: the cell of site
    # k is half-edges 2k-1 and 2k, consecutive (one of them at either end)
    for k in range(n - 1):
        he_twin[2 * k] = 2 * k + 1
        he_twin[2 * k + 1] = 2 * k
        he_face[2 * k] = k
        he_face[2 * k + 1] = k + 1
    for k in range(n if n > 1 else 0):
        face_edge[k] = 2 * k - 1 if k > 0 else 0
    return {
        "vertices": np.empty((0, 2), np.float64),
        "he_origin": np.asarray(he_origin),
        "he_twin": np.asarray(he_twin),
        "he_face": np.asarray(he_face),
        "face_edge": np.asarray(face_edge),
        "triangles": np.empty((0, 3), np.int32),
    }
