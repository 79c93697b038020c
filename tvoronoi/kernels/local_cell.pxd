"""One cell of a changing mesh, read locally: its ring clipped to the box (the one clipper, as for batch
cells), and whether rounding bent it (the rings the batch build straightens).

Used by dynamic.pyx: DynamicMesh.cell reads a cell; DynamicMesh.cells_near keeps count of the bent rings.
"""

from libc.math cimport fabs
from libc.stdint cimport int32_t, uint64_t
from libc.stdlib cimport malloc, calloc, free
from tvoronoi.kernels.predicates cimport incircle, orient2d
from tvoronoi.kernels.mesh cimport Mesh, nxt, prv, is_infinite
from tvoronoi.kernels.clipper cimport (
    Box, EdgePart, Points, AT_ORIGIN, AT_POINT, axis_code, code_in, code_side, clip_edge, walk_cell,
    finish_ring, bent, convex_ring, TURN_BAND_LOW, TURN_BAND_HIGH,
)
from tvoronoi.kernels.construct cimport circumcentre



cdef struct CellBuffers:
    # scratch of one cell with `star` triangles around its site (malloc'd: no cap on the star)
    int32_t* ring          # point ids of the ring, 2 star + 4
    double* pts            # interleaved x, y: star vertices, 2 star crossings, 4 corners
    signed char* pt_side
    int32_t* da            # how each boundary point was made (clipper.Points)
    int32_t* db
    int32_t* dc
    signed char* vcx       # per triangle: the vertex's codes against the box
    signed char* vcy
    int32_t* c_start       # per edge: its part in the box
    int32_t* c_end
    signed char* c_entry
    signed char* c_exit
    signed char* c_has
    double* nbx            # per edge: the neighbour's site
    double* nby


cdef inline bint alloc_cell_buffers(CellBuffers* b, int star) noexcept nogil:
    b.ring = <int32_t*> malloc((2 * star + 8) * sizeof(int32_t))
    b.pts = <double*> malloc(2 * (3 * star + 8) * sizeof(double))
    b.pt_side = <signed char*> malloc(3 * star + 8)
    b.da = <int32_t*> malloc((3 * star + 8) * sizeof(int32_t))
    b.db = <int32_t*> malloc((3 * star + 8) * sizeof(int32_t))
    b.dc = <int32_t*> malloc((3 * star + 8) * sizeof(int32_t))
    b.vcx = <signed char*> malloc(star + 1)
    b.vcy = <signed char*> malloc(star + 1)
    b.c_start = <int32_t*> malloc((star + 1) * sizeof(int32_t))
    b.c_end = <int32_t*> malloc((star + 1) * sizeof(int32_t))
    b.c_entry = <signed char*> malloc(star + 1)
    b.c_exit = <signed char*> malloc(star + 1)
    b.c_has = <signed char*> malloc(star + 1)
    b.nbx = <double*> malloc((star + 1) * sizeof(double))
    b.nby = <double*> malloc((star + 1) * sizeof(double))
    return (b.ring != NULL and b.pts != NULL and b.pt_side != NULL and b.vcx != NULL and b.vcy != NULL
            and b.da != NULL and b.db != NULL and b.dc != NULL
            and b.c_start != NULL and b.c_end != NULL and b.c_entry != NULL and b.c_exit != NULL
            and b.c_has != NULL and b.nbx != NULL and b.nby != NULL)


cdef inline void free_cell_buffers(CellBuffers* b) noexcept nogil:
    free(b.ring); free(b.pts); free(b.pt_side); free(b.vcx); free(b.vcy); free(b.c_start); free(b.c_end)
    free(b.c_entry); free(b.c_exit); free(b.c_has); free(b.nbx); free(b.nby); free(b.da); free(b.db)
    free(b.dc)


cdef enum:
    MEMO_SLOTS = 256        # circumcentres remembered while the cells around a site are read (cells_near)


cdef struct CentreMemo:
    int32_t tri[MEMO_SLOTS]
    double cx[MEMO_SLOTS]
    double cy[MEMO_SLOTS]
    int used


cdef inline void memo_clear(CentreMemo* memo) noexcept nogil:
    cdef int k
    for k in range(MEMO_SLOTS):
        memo.tri[k] = -1
    memo.used = 0


cdef inline void memo_centre(Mesh* m, int t, int e, CentreMemo* memo, double* x, double* y) noexcept nogil:
    """The correctly rounded circumcentre of finite triangle t (the same double whichever corner it is
    read from), computed once per cells_near while the memo has room."""
    cdef int a = m.tv[3 * t], b = m.tv[3 * t + 1], c = m.tv[3 * t + 2], slot, probes
    slot = <int> ((<uint64_t> t * 2654435761u) % MEMO_SLOTS)
    for probes in range(MEMO_SLOTS // 2):
        if memo.tri[slot] == t:
            x[0] = memo.cx[slot]
            y[0] = memo.cy[slot]
            return
        if memo.tri[slot] < 0:
            break
        slot = (slot + 1) % MEMO_SLOTS
    circumcentre(m.x[a], m.y[a], m.x[b], m.y[b], m.x[c], m.y[c], e, x, y)
    if memo.tri[slot] < 0 and memo.used < MEMO_SLOTS // 2:
        memo.tri[slot] = t
        memo.cx[slot] = x[0]
        memo.cy[slot] = y[0]
        memo.used += 1


cdef inline int interior_ring(Mesh* m, int site, Box* box, CentreMemo* memo, double* pts, int32_t* ring) noexcept nogil:
    """The cell of site when every vertex is finite and strictly inside the box: its circumcentres in
    order, as cell_ring would read them before finish_ring (pts and ring as there). -1 when the cell
    has a hull gap or a vertex not strictly inside the box: cell_ring clips it."""
    cdef int e0 = m.vedge[site], e = e0, k = 0
    cdef double x, y
    while True:
        if is_infinite(m, e // 3):
            return -1
        memo_centre(m, e // 3, box.e, memo, &x, &y)
        if not (box.xmin < x < box.xmax and box.ymin < y < box.ymax):
            return -1
        pts[2 * k] = x
        pts[2 * k + 1] = y
        ring[k] = k
        k += 1
        e = m.opp[prv(e)]
        if e == e0:
            break
    return k


cdef inline bint cocircular_edge(Mesh* m, int site, int before, int j, int after) noexcept nogil:
    # the edge between site and neighbour j, from the centre of (site, before, j) to that of
    # (site, j, after), has length zero: the four sites lie on one circle (exactly)
    return incircle(m.x[site], m.y[site], m.x[before], m.y[before], m.x[j], m.y[j], m.x[after], m.y[after]) == 0


cdef inline int cell_ring(Mesh* m, int site, Box* box, CellBuffers* b) noexcept nogil:
    """The cell of site clipped to the box (clipper.pxd, as for batch cells): point ids of b.pts in
    b.ring, counter-clockwise from the lowest point; returns the count, or -1 if its edges do not chain
    (an inconsistent mesh: the batch build raises there too)."""
    cdef int e0 = m.vedge[site], e, k = 0, q, p, nxq, j, a, c, n_pts, corner0, n_edges = 0, count
    cdef double sx = m.x[site], sy = m.y[site]
    cdef EdgePart part
    cdef Points P
    cdef bint has_o, has_d
    # the triangles around the site, counter-clockwise: triangle q is (site, nb q, nb q+1), and its
    # circumcentre is the cell's vertex q (the same double in every cell that has it)
    e = e0
    while True:
        p = e // 3
        if is_infinite(m, p):
            b.vcx[k] = 3                                     # no vertex: a hull gap
        else:
            a = m.tv[nxt(e)]
            c = m.tv[prv(e)]
            circumcentre(sx, sy, m.x[a], m.y[a], m.x[c], m.y[c], box.e, &b.pts[2 * k], &b.pts[2 * k + 1])
            b.vcx[k] = axis_code(b.pts[2 * k], box.xmin, box.xmax, box.sxmin, box.sxmax,
                                 sx, sy, m.x[a], m.y[a], m.x[c], m.y[c], False)
            b.vcy[k] = axis_code(b.pts[2 * k + 1], box.ymin, box.ymax, box.symin, box.symax,
                                 sx, sy, m.x[a], m.y[a], m.x[c], m.y[c], True)
            if code_in(b.vcx[k]) and code_in(b.vcy[k]):
                b.pt_side[k] = code_side(b.vcx[k], b.vcy[k])
            b.da[k] = site; b.db[k] = a; b.dc[k] = c
        b.c_start[k] = m.tv[nxt(e)]                          # the neighbour of edge k, for now
        k += 1
        e = m.opp[prv(e)]
        if e == e0:
            break
    n_pts = k
    # the edges, counter-clockwise: the edge with neighbour nb q runs from vertex q - 1 to vertex q
    for q in range(k):
        j = b.c_start[q]
        if j == m.inf:
            continue
        p = q - 1 if q > 0 else k - 1
        has_o = b.vcx[p] != 3
        has_d = b.vcx[q] != 3
        if (has_o and has_d and b.pts[2 * p] == b.pts[2 * q] and b.pts[2 * p + 1] == b.pts[2 * q + 1]
                and cocircular_edge(m, site, b.db[p], j, b.dc[q])):
            continue                  # a zero-length edge, which the batch dual drops too (dual.pyx)
        # (an edge whose distinct ends round to one point stays, as in the batch cells: it may be where
        # the cell enters or leaves the box)
        b.nbx[n_edges] = m.x[j]
        b.nby[n_edges] = m.y[j]
        clip_edge(box, sx, sy, m.x[j], m.y[j], has_o, b.vcx[p] if has_o else 0, b.vcy[p] if has_o else 0,
                  has_d, b.vcx[q] if has_d else 0, b.vcy[q] if has_d else 0, &part)
        b.c_has[n_edges] = part.has
        b.c_entry[n_edges] = part.entry
        b.c_exit[n_edges] = part.exit
        if part.has:
            if part.start_at == AT_POINT:
                b.pts[2 * n_pts] = part.sx; b.pts[2 * n_pts + 1] = part.sy
                b.pt_side[n_pts] = part.s_side
                b.da[n_pts] = site; b.db[n_pts] = j; b.dc[n_pts] = -1
                b.ring[n_edges] = n_pts            # parked here until the edges are all known
                n_pts += 1
            else:
                b.ring[n_edges] = p if part.start_at == AT_ORIGIN else q
            if part.end_at == AT_POINT:
                b.pts[2 * n_pts] = part.ex; b.pts[2 * n_pts + 1] = part.ey
                b.pt_side[n_pts] = part.e_side
                b.da[n_pts] = site; b.db[n_pts] = j; b.dc[n_pts] = -1
                b.c_end[n_edges] = n_pts
                n_pts += 1
            else:
                b.c_end[n_edges] = p if part.end_at == AT_ORIGIN else q
        n_edges += 1
    for q in range(n_edges):
        b.c_start[q] = b.ring[q]
    corner0 = n_pts
    for c in range(4):
        b.pts[2 * (corner0 + c)] = box.kx[c]
        b.pts[2 * (corner0 + c) + 1] = box.ky[c]
        b.pt_side[corner0 + c] = c
        b.da[corner0 + c] = -1
    P.xy = b.pts
    P.side = b.pt_side
    P.da = b.da
    P.db = b.db
    P.dc = b.dc
    P.sx = m.x
    P.sy = m.y
    P.corner0 = corner0
    count = walk_cell(box, n_edges, b.c_start, b.c_end, b.c_entry, b.c_exit, b.c_has, &P, sx, sy, b.nbx,
                      b.nby, b.ring)
    if count <= 0:
        return count            # -1: the edges did not chain (never on a valid mesh)
    return finish_ring(b.ring, count, b.pts)


cdef inline bint cell_is_bent(Mesh* m, int site, Box* box, CentreMemo* memo, CellBuffers* b) noexcept nogil:
    """The site's cell, clipped and finished, crosses itself (clipper.bent). A cell strictly inside the
    box is read from memoised circumcentres, and one whose every turn is strictly left is not bent
    (the usual case); the others are clipped as cell_ring reads them."""
    cdef int k = interior_ring(m, site, box, memo, b.pts, b.ring)
    if k > 0 and convex_ring(b.ring, k, b.pts, False) == k:
        return False
    if k > 0:
        k = finish_ring(b.ring, k, b.pts)
    else:
        k = cell_ring(m, site, box, b)
    return k > 0 and bent(b.ring, k, b.pts)


cdef inline bint in_band(double v) noexcept nogil:
    # zero, or a magnitude where orient2d of ring points is exact (clipper.turn's band)
    v = fabs(v)
    return v == 0.0 or (TURN_BAND_LOW <= v < TURN_BAND_HIGH)


cdef inline int sure_cells(Mesh* m, Box* box, signed char* sure) noexcept nogil:
    """Every cell of the mesh at once, by triangles: sure[s] = 1 where site s's cell lies strictly inside
    the box with every turn strictly left (then it is not bent: cell_is_bent's usual case), 0 where
    cell_is_bent must decide. Each circumcentre is computed once and each turn read from a triangle and
    its two neighbours around the site; in the triangles' order, so neighbours are near in memory.
    sure has a byte per site (ids up to the mesh's capacity), zeroed by the caller. Returns -1 when
    memory runs out (sure is left all 0), else 0."""
    cdef int n = m.n_tri, t, c, e, s, p, q, k
    cdef double* cx = <double*> malloc(max(n, 1) * sizeof(double))
    cdef double* cy = <double*> malloc(max(n, 1) * sizeof(double))
    cdef signed char* ok = <signed char*> calloc(max(n, 1), 1)    # 1: finite, strictly inside, in band
    cdef signed char* live = <signed char*> malloc(max(n, 1))
    if cx == NULL or cy == NULL or ok == NULL or live == NULL:
        free(cx); free(cy); free(ok); free(live)
        return -1
    for t in range(n):
        live[t] = 1
    for k in range(m.n_free):
        live[m.free_tri[k]] = 0
    for t in range(n):
        if not live[t] or is_infinite(m, t):
            continue
        circumcentre(m.x[m.tv[3 * t]], m.y[m.tv[3 * t]], m.x[m.tv[3 * t + 1]], m.y[m.tv[3 * t + 1]],
                     m.x[m.tv[3 * t + 2]], m.y[m.tv[3 * t + 2]], box.e, &cx[t], &cy[t])
        ok[t] = (box.xmin < cx[t] < box.xmax and box.ymin < cy[t] < box.ymax
                 and in_band(cx[t]) and in_band(cy[t]))
    # a site is sure until one of its turns is not: first every live site with a triangle, then the
    # doubtful ones struck out
    for t in range(n):
        if not live[t]:
            continue
        for c in range(3):
            s = m.tv[3 * t + c]
            if s != m.inf:
                sure[s] = 1
    for t in range(n):
        if not live[t]:
            continue
        for c in range(3):
            e = 3 * t + c
            s = m.tv[e]
            if s == m.inf:
                continue
            p = m.opp[e] // 3                 # the triangle before t around s
            q = m.opp[prv(e)] // 3            # the triangle after it
            if not (ok[t] and ok[p] and ok[q]) or orient2d(cx[p], cy[p], cx[t], cy[t], cx[q], cy[q]) <= 0:
                sure[s] = 0
    free(cx); free(cy); free(ok); free(live)
    return 0
