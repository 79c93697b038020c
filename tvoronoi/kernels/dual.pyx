"""The Voronoi diagram as a half-edge structure (DCEL), built as the dual of a Delaunay triangulation."""

import numpy as np

from cython.parallel cimport prange
from libc.stdint cimport int32_t, uint64_t

from tvoronoi.kernels.construct cimport circumcentre
from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.predicates cimport incircle
from tvoronoi.kernels.mesh cimport nxt, prv
from tvoronoi.kernels.prefetch cimport prefetch

cdef extern from *:
    """
    /* set bit g of a bit array that several threads set bits of */
    static inline void tvoronoi_set_bit(unsigned char* bits, int g) {
        __atomic_fetch_or(&bits[g >> 3], (unsigned char) (1u << (g & 7)), __ATOMIC_RELAXED);
    }
    """
    void set_bit "tvoronoi_set_bit"(unsigned char* bits, int g) noexcept nogil


cdef enum:
    AHEAD = 4       # the walk around site a + AHEAD starts loading while site a is walked
    BLOCK = 1 << 18     # parallel loops run in blocks of this many, signals polled between
    PARALLEL_MIN_SITES = 1 << 15    # fewer sites: one thread (waking the others costs more than it saves)
    WALK_CHUNK = 1 << 12    # sites walked by one thread in a row (neighbouring cells share cache lines)

# Layout of the Voronoi DCEL (struct of arrays, -1 for "at infinity"):
#   he_origin[h]  Voronoi vertex h starts from, -1 if h comes from infinity
#   he_twin[h]    the same edge seen from the neighbouring cell
#   the cycle around a cell, counter-clockwise: its half-edges, consecutive from face_edge (next_in_cell);
#                 an unbounded cell's cycle closes through infinity: the edge
#                 that runs off to infinity is followed by the one coming back
#   he_face[h]    the site whose cell h bounds
# An edge lies on the bisector of he_face[h] and he_face[he_twin[h]].


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
                          int walk_chunk=WALK_CHUNK):
    """Voronoi DCEL of n distinct sites from their Delaunay triangulation.

    Triangles whose circumcircles coincide (cocircular sites) share one
    Voronoi vertex, and the zero-length edges between them are not emitted.

    One walk around each site, in the sites' order, makes the DCEL cell by cell: the half-edges of a
    cell are consecutive, in he_next order, from face_edge (an unbounded cell's first half-edge comes
    from infinity, its last runs off to infinity), and vertices are numbered as the walk first meets
    them. The sites come in a spatial order (BRIO or the sweep's), so a cell's vertices and
    half-edges lie near its neighbours' in memory for the phases that follow.

    Parameters
    ----------
    xs, ys : (n,) float64, the sites.
    tv, opp : (3 * n_tri,) int32, the triangulation of incremental.triangulate or fortune.sweep
        (vertex n is the vertex at infinity).
    exponent : int, the sites are in a unit 2^-exponent of the user's: vertices are
        returned in the user's unit, each coordinate correctly rounded.
    threads : int, threads for the walks (each computing the vertices it numbers and testing its cell
        for zero-length edges; the result is the same for any count), when there are at least
        parallel_min sites.
    walk_chunk : int, sites walked in a row by one thread (tests make it small, so that most lookups
        wait for the pass after the walks).
    clip_room : bool, leave room after the vertices for the points clip.clip_cells adds on the box
        (at most two per edge, and four corners), so that it writes them there instead of copying the
        vertices: address space only, as rows never written cost no memory.

    Returns
    -------
    dict of arrays: vertices (m, 2) float64; he_origin, he_twin, he_face (h,) int32;
    face_edge (n,) int32 (the first half-edge of each cell, -1 for a site without one); triangles
    (k, 3) int32, the finite Delaunay triangles; with clip_room, vertex_room: the buffer whose first m
    rows are the vertices. The next half-edge of a cell is the following one
    while the face stays the same, then the first again (next_in_cell).
    """
    cdef int n = xs.shape[0], inf = n
    cdef int n_he_d = tv.shape[0], n_tri = n_he_d // 3
    cdef int32_t[::1] first_e = np.full(n, -1, np.int32)     # where each site's walk starts
    cdef int32_t[::1] h_first = np.zeros(n + 1, np.int32)    # the cell's first half-edge (a count first)
    cdef int32_t[::1] v_first = np.zeros(n + 1, np.int32)    # the number of its first vertex (a count first)
    cdef int32_t[::1] vid = np.empty(max(n_tri, 1), np.int32)  # finite triangle -> its vertex
    cdef int32_t[::1] vor = np.empty(n_he_d, np.int32)        # Delaunay half-edge -> Voronoi half-edge
    cdef int32_t[::1] he_origin = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] he_twin = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] he_face = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] face_edge = np.full(n, -1, np.int32)
    cdef int32_t[::1] parent                                  # vertices merged by cocircular sites
    cdef double[:, ::1] centre
    cdef int32_t[:, ::1] tri
    cdef int t, e, a, b, c, h = 0, m = 0, n_finite = 0, n_hull, g, k, lo, hi, count

    if n < parallel_min:
        threads = 1

    with nogil:
        # which triangles are finite, and where each site's walk starts: any half-edge out of it, or for
        # a hull site the one whose dual comes from infinity (the twin of a hull edge p->q of an
        # infinite triangle starts at q). On more than one thread, also what each walk will emit, so
        # that the walks can run apart: one half-edge per Delaunay edge out of the site (counted in
        # h_first), and the vertices of the finite triangles whose smallest site it is (v_first)
        # (the finite triangles last to first, so that each site keeps its first half-edge in triangle
        # order by plain stores, no test of what is there; then the hull's, which take precedence)
        n_hull = 0
        for t in range(n_tri - 1, -1, -1):
            a = tv[3 * t]; b = tv[3 * t + 1]; c = tv[3 * t + 2]
            if a == inf or b == inf or c == inf:
                vid[n_hull] = t         # (vid is free until the walks: the hull's triangles, listed)
                n_hull += 1
                if threads > 1:
                    for e in range(3 * t, 3 * t + 3):
                        if tv[e] != inf and tv[nxt(e)] != inf:
                            h_first[tv[e]] += 1
            else:
                n_finite += 1
                first_e[c] = 3 * t + 2
                first_e[b] = 3 * t + 1
                first_e[a] = 3 * t
                if threads > 1:
                    h_first[a] += 1; h_first[b] += 1; h_first[c] += 1
                    v_first[smallest(a, b, c)] += 1
        for k in range(n_hull):
            t = vid[k]
            for e in range(3 * t, 3 * t + 3):
                if tv[e] != inf and tv[nxt(e)] != inf:
                    first_e[tv[nxt(e)]] = opp[e]
        if threads > 1:
            # counts -> offsets: a site's half-edges and vertices follow those of the sites before it
            for a in range(n):
                count = h_first[a]
                h_first[a] = h
                h += count
                count = v_first[a]
                v_first[a] = m
                m += count
            h_first[n] = h
    # (an edge is dual to a Delaunay edge between two sites, n_he_d bounds twice their number)
    centre_buf = np.empty((n_finite + (n_he_d + 4 if clip_room else 0), 2), np.float64)
    centre = centre_buf
    tri = np.empty((n_finite, 3), np.int32)
    cdef signed char[::1] zero = np.zeros(max(n_he_d, 1), np.int8)   # zero-length: cocircular triangles
    # the edges a walk could not test (their ends another thread's walk numbers), a bit each: a few
    # at the ends of the runs, scattered, so not in `zero`, whose pages are seldom written
    cdef unsigned char[::1] open_bits = np.zeros(8 * ((n_he_d + 63) // 64 + 1), np.uint8)
    cdef int n_zero = 0, n_marked = 0
    cdef int32_t* tri_rows = &tri[0, 0] if n_finite > 0 else NULL
    cdef Walk w
    w.tv = &tv[0]; w.opp = &opp[0]; w.first_e = &first_e[0]; w.inf = inf
    w.vor = &vor[0]; w.vid = &vid[0]; w.tri = tri_rows
    w.he_origin = &he_origin[0]; w.he_twin = &he_twin[0]; w.he_face = &he_face[0]
    w.xs = &xs[0]; w.ys = &ys[0]; w.e = exponent; w.centre = &centre[0, 0] if n_finite > 0 else NULL
    cdef int h0

    with nogil:
        # the walks: one per site, in the sites' order, each making its cell's half-edges and numbering
        # (and computing) the vertices it meets first, then testing its cell for zero-length edges
        # (zero_after_walk); on one thread, one after the other
        if threads == 1:
            h = 0
            m = 0
            for a in range(n):
                if (a & POLL_MASK) == 0:
                    poll_signals()
                if a + AHEAD < n and first_e[a + AHEAD] >= 0:
                    prefetch(&tv[first_e[a + AHEAD]])
                    prefetch(&opp[first_e[a + AHEAD]])
                h_first[a] = h
                h0 = h
                h, m = walk_site(&w, a, h, m, 0)
                if h > h0:
                    face_edge[a] = h0
                n_marked += zero_after_walk(&w, a, h0, h, 0, &zero[0], &open_bits[0])
            h_first[n] = h
        else:
            # in runs of WALK_CHUNK sites on the threads, each walk from the offsets counted above; an
            # origin or twin that another run may not have made yet is left as its Delaunay triangle or
            # half-edge and looked up once every walk is done (the arrays are the same for any count)
            lo = 0
            while lo < n:
                poll_signals()
                hi = lo + BLOCK if lo + BLOCK < n else n
                for a in prange(lo, hi, num_threads=threads, schedule="static", chunksize=walk_chunk):
                    if a + AHEAD < n and first_e[a + AHEAD] >= 0:
                        prefetch(&tv[first_e[a + AHEAD]])
                        prefetch(&opp[first_e[a + AHEAD]])
                    walk_site(&w, a, h_first[a], v_first[a], a - (a - lo) % walk_chunk)
                    if h_first[a + 1] > h_first[a]:
                        face_edge[a] = h_first[a]
                    n_marked += zero_after_walk(&w, a, h_first[a], h_first[a + 1], a - (a - lo) % walk_chunk,
                                                &zero[0], &open_bits[0])
                lo = hi
            lo = 0
            while lo < h:
                poll_signals()
                hi = lo + BLOCK if lo + BLOCK < h else h
                for g in prange(lo, hi, num_threads=threads, schedule="static"):
                    if he_origin[g] < -1:
                        he_origin[g] = vid[-2 - he_origin[g]]
                    if he_twin[g] < 0:
                        he_twin[g] = vor[-1 - he_twin[g]]
                lo = hi

        # the edges the walks marked: those left open decided now that every origin is known, and the
        # twins of the zero-length ones marked (a twin comes after its edge)
        # (no finite triangle: no vertex, so nothing marked or open)
        if n_finite > 0 and (n_marked > 0 or threads > 1):
            n_zero = settle_zero(h, threads > 1, n_marked > 0, &he_origin[0], &he_twin[0], &he_face[0],
                                 &face_edge[0], &centre[0, 0], &tri[0, 0], &xs[0], &ys[0], &zero[0], &open_bits[0])
    if n_zero > 0:
        parent = np.arange(max(m, 1), dtype=np.int32)
        with nogil:
            m, h = drop_zero_edges(h, m, n, &he_origin[0], &he_twin[0], &he_face[0], &face_edge[0],
                                   &zero[0], &parent[0], &vid[0], &vor[0], &centre[0, 0])

    out = {
        "vertices": centre_buf[:m],
        "he_origin": np.asarray(he_origin)[:h],
        "he_twin": np.asarray(he_twin)[:h],
        "he_face": np.asarray(he_face)[:h],
        "face_edge": np.asarray(face_edge),
        "triangles": np.asarray(tri),
    }
    if clip_room:
        out["vertex_room"] = centre_buf
    return out


cdef inline int smallest(int a, int b, int c) noexcept nogil:
    if b < a:
        a = b
    return c if c < a else a


cdef struct Walk:
    # what the walks read (the triangulation, where each starts) and write (the Voronoi arrays)
    const int32_t* tv
    const int32_t* opp
    const int32_t* first_e
    int inf
    int32_t* vor
    int32_t* vid
    int32_t* tri
    int32_t* he_origin
    int32_t* he_twin
    int32_t* he_face
    const double* xs
    const double* ys
    int e
    double* centre


cdef inline (int, int) walk_site(Walk* w, int a, int h, int m, int done_from) noexcept nogil:
    """The cell of site a, counter-clockwise from first_e[a]; returns the next free half-edge and vertex.

    One half-edge per Delaunay edge a->b with b finite, from h on: its origin is the vertex of the
    triangle on the right of a->b (-1 if that is infinite), its twin the half-edge of b->a. The finite
    triangles whose smallest site is a are numbered from m on, as met. Sites from done_from up to a
    have been walked: a vertex or twin of an earlier site is looked up; one of a site before done_from
    (another thread's) is left as -2 - triangle or -1 - Delaunay half-edge, looked up later. The
    triangle on the right of a->b is the one the walk left at the step before. A vertex is computed
    (construct.circumcentre) where it is numbered, while its sites are at hand.
    """
    # (locals, so that the stores below do not make the compiler read the struct again)
    cdef const int32_t* tv = w.tv
    cdef const int32_t* opp = w.opp
    cdef int32_t* vor = w.vor
    cdef int32_t* vid = w.vid
    cdef int32_t* tri = w.tri
    cdef int32_t* he_origin = w.he_origin
    cdef int32_t* he_twin = w.he_twin
    cdef int32_t* he_face = w.he_face
    cdef int e0 = w.first_e[a], e, b, t, r0, r1, r2, x0, x1, x2, base, low, o, g, tl, k, inf = w.inf
    if e0 < 0:
        return h, m             # a repeated site, or none of the triangles (no cell)
    t = opp[e0] // 3
    r0 = tv[3 * t]; r1 = tv[3 * t + 1]; r2 = tv[3 * t + 2]
    e = e0
    while True:
        tl = e // 3
        base = 3 * tl
        x0 = tv[base]; x1 = tv[base + 1]; x2 = tv[base + 2]
        k = e - base
        b = x1 if k == 0 else (x2 if k == 1 else x0)      # the head of e
        if b != inf:
            vor[e] = h
            if r0 == inf or r1 == inf or r2 == inf:
                he_origin[h] = -1
            else:
                low = smallest(r0, r1, r2)
                if low == a:
                    vid[t] = m
                    tri[3 * m] = r0; tri[3 * m + 1] = r1; tri[3 * m + 2] = r2
                    circumcentre(w.xs[r0], w.ys[r0], w.xs[r1], w.ys[r1], w.xs[r2], w.ys[r2], w.e,
                                 &w.centre[2 * m], &w.centre[2 * m + 1])
                    he_origin[h] = m
                    m += 1
                elif low >= done_from:
                    he_origin[h] = vid[t]
                else:
                    he_origin[h] = -2 - t
            o = opp[e]
            if done_from <= b < a:
                g = vor[o]
                he_twin[h] = g
                he_twin[g] = h
            else:
                he_twin[h] = -1 - o
            he_face[h] = a
            h += 1
        t = tl
        r0 = x0; r1 = x1; r2 = x2
        e = opp[base + (2 if k == 0 else k - 1)]     # the twin of the edge into a: the next edge out
        if e == e0:
            break
    return h, m


cdef inline int zero_after_walk(Walk* w, int a, int h0, int h1, int done_from, signed char* zero,
                                      unsigned char* open_bits) noexcept nogil:
    """zero_length for the half-edges h0..h1 - 1 of site a's cell, right after its walk, while they are
    at hand (done_from: as in walk_site; the vertices of the sites from done_from to a are computed by
    then). Equal exact centres round to equal doubles, so only an edge whose ends have equal rounded
    centres can join cocircular triangles; the exact in-circle test decides. An edge is tested from
    its half-edge of smaller index, the one whose twin's site comes later. Marks a zero-length edge 1
    in zero, and one whose ends an earlier run numbers (on another thread) in open_bits, for
    settle_zero. Returns the count marked in zero. (Distinct vertices that round to one point, nearly
    cocircular sites, are kept apart: the clipper names rounded points by their values.)"""
    cdef int g, vr, vl, b, count = 0
    for g in range(h0, h1):
        if w.he_twin[g] >= 0:
            continue                # the twin came first: tested from there
        b = w.tv[-1 - w.he_twin[g]]      # the twin's Delaunay half-edge b->a
        if b < a:
            continue                # the twin's site came first (in an earlier run): tested there
        vr = w.he_origin[g]
        vl = w.he_origin[g + 1 if g + 1 < h1 else h0]
        if vr == -1 or vl == -1:
            continue                # an end at infinity
        if vr < -1 or vl < -1:
            set_bit(open_bits, g)   # numbered by an earlier run: decided once it is known
            continue
        if w.centre[2 * vr] != w.centre[2 * vl] or w.centre[2 * vr + 1] != w.centre[2 * vl + 1]:
            continue
        if cocircular(a, b, &w.tri[3 * vr], &w.tri[3 * vl], w.xs, w.ys):
            zero[g] = 1
            count += 1
    return count


cdef int settle_zero(int h, bint any_open, bint any_zero, const int32_t* he_origin, const int32_t* he_twin,
                     const int32_t* he_face, const int32_t* face_edge, const double* centre, const int32_t* tri,
                     const double* xs, const double* ys, signed char* zero,
                     const unsigned char* open_bits) noexcept nogil:
    # after the walks, with every origin and twin known: the edges left open tested (any_open: the
    # walks ran on more than one thread), and both half-edges of every zero-length edge marked 1
    # (any_zero: a walk marked one; an open edge found zero has both marked already); returns the
    # count of half-edges marked, 0 when none is. Words with no flag set are skipped whole: `zero`'s
    # pages are read only when a walk wrote to them.
    cdef int g, k, count = 0
    cdef const uint64_t* words = <const uint64_t*> open_bits
    if any_open:
        for k in range((h + 63) // 64):
            if words[k] == 0:
                continue
            for g in range(64 * k, min(64 * k + 64, h)):
                if open_bits[g >> 3] & (1 << (g & 7)):
                    count += zero_length(g, h, he_origin, he_twin, he_face, face_edge, centre, tri, xs, ys, zero)
    if not any_zero:
        return count
    words = <const uint64_t*> zero
    for k in range(h // 8):
        if words[k] == 0:
            continue
        for g in range(8 * k, 8 * k + 8):
            count += mark_twin(g, he_twin, zero)
    for g in range(h - h % 8, h):
        count += mark_twin(g, he_twin, zero)
    return count


cdef inline int mark_twin(int g, const int32_t* he_twin, signed char* zero) noexcept nogil:
    if zero[g] == 1 and he_twin[g] > g:
        zero[he_twin[g]] = 1
        return 2
    return 0


cdef inline bint cocircular(int a, int b, const int32_t* t_right, const int32_t* t_left, const double* xs,
                            const double* ys) noexcept nogil:
    # the triangles on both sides of Delaunay edge a-b share their circumcircle (exactly)
    cdef int c = third(t_right, a, b), d = third(t_left, a, b)
    # degenerate case: four cocircular sites
    return incircle(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], xs[d], ys[d]) == 0


cdef inline int next_in_cell(int g, int h, const int32_t* he_face, const int32_t* face_edge) noexcept nogil:
    # the half-edge after g around its cell: the following one while the face is the same, else the first
    if g + 1 < h and he_face[g + 1] == he_face[g]:
        return g + 1
    return face_edge[he_face[g]]


cdef inline int zero_length(int g, int h, const int32_t* he_origin, const int32_t* he_twin,
                            const int32_t* he_face, const int32_t* face_edge, const double* centre,
                            const int32_t* tri, const double* xs, const double* ys,
                            signed char* zero) noexcept nogil:
    # is half-edge g (and its twin) of length zero, between cocircular triangles? Marks both; returns
    # the count marked. Each edge is
    # tested once, from its half-edge of smaller index.
    cdef int vr = he_origin[g], vl = he_origin[next_in_cell(g, h, he_face, face_edge)]
    if vr < 0 or vl < 0 or he_twin[g] < g:
        return 0
    if centre[2 * vr] != centre[2 * vl] or centre[2 * vr + 1] != centre[2 * vl + 1]:
        return 0
    if not cocircular(he_face[g], he_face[he_twin[g]], &tri[3 * vr], &tri[3 * vl], xs, ys):
        return 0
    zero[g] = 1
    zero[he_twin[g]] = 1
    return 2


cdef inline int third(const int32_t* t, int a, int b) noexcept nogil:
    # the site of triangle t that is neither a nor b
    if t[0] != a and t[0] != b:
        return t[0]
    if t[1] != a and t[1] != b:
        return t[1]
    return t[2]


cdef (int, int) drop_zero_edges(int h, int m, int n, int32_t* he_origin, int32_t* he_twin, int32_t* he_face,
                                int32_t* face_edge, const signed char* zero, int32_t* parent, int32_t* vmap,
                                int32_t* newh, double* centre) noexcept nogil:
    """Cocircular sites: merge the vertices at both ends of each zero-length half-edge into one (the
    group's smallest number), renumber the vertices in order, and remove those half-edges, keeping
    each cell's in order and the cells contiguous. Returns the new vertex and half-edge counts."""
    cdef int g, k, u, w, r, a, last_face = -1, h_kept
    # the merges (each zero-length edge from its half-edge of smaller index: its twin joins the same two
    # vertices), and each kept half-edge's new number (how many before it are kept)
    k = 0
    for g in range(h):
        newh[g] = k
        if zero[g]:
            if he_twin[g] < g:
                continue
            u = find(parent, he_origin[g])
            w = find(parent, he_origin[next_in_cell(g, h, he_face, face_edge)])
            if u < w:
                parent[w] = u
            elif w < u:
                parent[u] = w
        else:
            k += 1
    h_kept = k
    # the vertices renumbered in order: a root takes the next number, any other vertex its root's (a
    # merge keeps the smaller root, so that root is numbered already)
    k = 0
    for g in range(m):
        r = find(parent, g)
        if r == g:
            vmap[g] = k
            centre[2 * k] = centre[2 * g]
            centre[2 * k + 1] = centre[2 * g + 1]
            k += 1
        else:
            vmap[g] = vmap[r]
    m = k
    # the kept half-edges moved down in place (to no later place than their own), and each cell's first
    # where its face begins: the cells stay contiguous and in order (every cell keeps some edges: those
    # from and to infinity, or three at least)
    for g in range(n):
        face_edge[g] = -1
    for g in range(h):
        if zero[g]:
            continue
        k = newh[g]
        he_origin[k] = vmap[he_origin[g]] if he_origin[g] >= 0 else -1
        he_twin[k] = newh[he_twin[g]]
        a = he_face[g]
        he_face[k] = a
        if a != last_face:
            face_edge[a] = k
            last_face = a
    return m, h_kept


def circumcentres(const double[::1] xs, const double[::1] ys, const int32_t[:, ::1] tri, int e=0):
    """Correctly rounded circumcentres (k, 2) of triangles tri (k, 3) of sites xs, ys, times 2^e."""
    cdef Py_ssize_t k, n_tri = tri.shape[0]
    cdef double[:, ::1] out = np.empty((n_tri, 2), np.float64)
    cdef int a, b, c
    with nogil:
        for k in range(n_tri):
            a = tri[k, 0]; b = tri[k, 1]; c = tri[k, 2]
            circumcentre(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], e, &out[k, 0], &out[k, 1])
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
