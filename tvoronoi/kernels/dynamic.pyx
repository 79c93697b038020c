"""A Delaunay triangulation that changes locally: insert, remove and relabel sites; read one cell."""

import numpy as np

from libc.stdint cimport int8_t, int32_t

from tvoronoi.kernels.predicates cimport orient2d, incircle
from tvoronoi.kernels.mesh cimport (
    Mesh, nxt, prv, is_infinite, strictly_between, locate, insert_site, find_cavity, fill_cavity,
)
from libc.stdlib cimport malloc, free
from tvoronoi.kernels.clipper cimport (
    Box, EdgePart, Points, AT_ORIGIN, AT_POINT, make_box, axis_code, code_in, code_side, clip_edge,
    walk_cell, finish_ring,
)
from tvoronoi.kernels.construct cimport circumcentre
from tvoronoi.kernels.fortune cimport sweep_triangles

cdef enum:
    INF_VERTEX = 0x7FFFFFFE  # the vertex at infinity of a dynamic mesh (site ids stay below it)
    MAX_STAR = 2048         # neighbours of one site handled by remove() and cell()
    MAX_GROUP = 64          # triangles of one cocircular group looked at for its vertex
    MAX_REGION = 256        # sites swept for one local update by Fortune's engine
    MAX_HOLE = 64           # hole size filled by a sweep (larger holes are filled by ears)
    STATUS_DONE = 0
    STATUS_FLAT = 1         # the sites left are collinear: no triangle remains


INFINITE = INF_VERTEX


cdef class DynamicMesh:
    """Sites and their Delaunay triangulation (closed by a vertex at infinity).

    Site ids are chosen by the caller; a removed id may be inserted again.
    Every operation touches only the triangles around the sites it changes.
    """

    cdef Mesh m
    cdef double* wx                 # the mesh's coordinates, writable
    cdef double* wy
    cdef dict arrays
    cdef public bint swept_ok       # the last swept update used the sweep's own triangles
    cdef int32_t* vmark             # scratch marks per site, and the epoch that makes them current
    cdef int32_t mark_epoch
    cdef int32_t* nextb             # scratch: the boundary edge leaving each site
    cdef int cap_v, cap_t

    def __init__(self, int capacity):
        self.cap_v = 0
        self.cap_t = 0
        self.arrays = {}
        self.m.n_finite = 0
        self.mark_epoch = 0
        self.m.n_tri = 0
        self.m.n_free = 0
        self.m.last = -1
        self.m.epoch = 0
        self.m.inf = INF_VERTEX
        self.m.n = 0
        self.m.head = NULL
        self.m.next_site = NULL
        self.m.where = NULL
        self.m.trace_cav = NULL
        self.m.trace_new = NULL
        self._grow(max(capacity, 4), 2 * max(capacity, 4))

    def _grow(self, int cap_v, int cap_t):
        """Make room for cap_v sites and cap_t triangles (arrays are copied, pointers renewed)."""
        old = self.arrays
        spec = {"x": (cap_v, np.float64), "y": (cap_v, np.float64), "vedge": (cap_v, np.int32),
                "vmap": (cap_v, np.int32), "dup": (cap_v, np.int32),
                "tv": (3 * cap_t, np.int32), "opp": (3 * cap_t, np.int32), "stamp": (cap_t, np.int32),
                "cavity": (cap_t, np.int32), "bnd_a": (cap_t + 2, np.int32), "bnd_b": (cap_t + 2, np.int32),
                "bnd_twin": (cap_t + 2, np.int32), "free_tri": (cap_t, np.int32),
                "changed": (cap_t + 2, np.int32), "vmark": (cap_v, np.int32), "nextb": (cap_v, np.int32)}
        new = {}
        for name, (size, dtype) in spec.items():
            arr = np.full(size, -1, dtype) if dtype is np.int32 else np.zeros(size, dtype)
            if name in old:
                arr[:len(old[name])] = old[name]
            new[name] = arr
        self.arrays = new
        self.cap_v = cap_v
        self.cap_t = cap_t
        cdef double[::1] x = new["x"], y = new["y"]
        cdef int32_t[::1] vedge = new["vedge"], vmap = new["vmap"], dup = new["dup"], tv = new["tv"]
        cdef int32_t[::1] opp = new["opp"], stamp = new["stamp"], cavity = new["cavity"]
        cdef int32_t[::1] bnd_a = new["bnd_a"], bnd_b = new["bnd_b"], bnd_twin = new["bnd_twin"]
        cdef int32_t[::1] free_tri = new["free_tri"], changed = new["changed"]
        cdef int32_t[::1] vmark = new["vmark"], nextb = new["nextb"]
        self.vmark = &vmark[0]
        self.nextb = &nextb[0]
        self.m.x = &x[0]
        self.m.y = &y[0]
        self.wx = &x[0]
        self.wy = &y[0]
        self.m.vedge = &vedge[0]
        self.m.vmap = &vmap[0]
        self.m.dup = &dup[0]
        self.m.tv = &tv[0]
        self.m.opp = &opp[0]
        self.m.stamp = &stamp[0]
        self.m.cavity = &cavity[0]
        self.m.bnd_a = &bnd_a[0]
        self.m.bnd_b = &bnd_b[0]
        self.m.bnd_twin = &bnd_twin[0]
        self.m.free_tri = &free_tri[0]
        self.m.changed = &changed[0]

    def _reserve(self, int site):
        if site >= self.cap_v:
            self._grow(max(2 * self.cap_v, site + 1), self.cap_t)
        if self.m.n_tri + 4 >= self.cap_t or 2 * self.cap_v + 8 > self.cap_t:
            self._grow(self.cap_v, max(2 * self.cap_t, 2 * self.cap_v + 8))

    def load(self, const double[::1] xs, const double[::1] ys, const int32_t[::1] ids,
             const int32_t[::1] tv, const int32_t[::1] opp, int inf):
        """Start from a batch triangulation: its vertex k is site ids[k], vertex inf is infinity."""
        cdef int n = xs.shape[0], k, e, v, n_he = tv.shape[0]
        top = int(np.max(ids)) + 1 if n else 0
        self._grow(max(self.cap_v, top, 4), max(self.cap_t, n_he // 3 + 8, 2 * top + 8))
        for k in range(n):
            self.wx[ids[k]] = xs[k]
            self.wy[ids[k]] = ys[k]
        self.m.n_finite = 0
        for e in range(n_he):
            v = tv[e]
            self.m.tv[e] = INF_VERTEX if v == inf else ids[v]
            self.m.opp[e] = opp[e]
            if v != inf:
                self.m.vedge[ids[v]] = e
        self.m.n_tri = n_he // 3
        self.m.n_free = 0
        for k in range(self.m.n_tri):
            if not is_infinite(&self.m, k):
                self.m.n_finite += 1
                self.m.last = k

    @property
    def n_finite(self):
        """Finite triangles: 0 once the sites left are collinear (the mesh cannot hold them)."""
        return self.m.n_finite

    def set_site(self, int site, double x, double y):
        """Place a site (not yet in the mesh), e.g. a repeated point that stays outside it."""
        self._reserve(site)
        self.wx[site] = x
        self.wy[site] = y

    def insert(self, int site, double x, double y):
        """Insert a site; returns the site already at (x, y), or -1 once inserted."""
        cdef int t0, before, k, e
        self._reserve(site)
        self.wx[site] = x
        self.wy[site] = y
        self.m.dup[site] = -1
        self.m.n_changed = 0
        with nogil:
            t0 = locate(&self.m, self.m.last, x, y)
            before = self.m.n_tri - self.m.n_free
            insert_site(&self.m, site, t0)
        if self.m.dup[site] >= 0:
            return self.m.dup[site]
        self.m.changed[self.m.n_changed] = site
        self.m.n_changed += 1
        return -1

    def remove(self, int site):
        """Take a site out and fill its hole with the Delaunay triangles of its neighbours."""
        cdef int status
        self._reserve(site)
        with nogil:
            status = remove_site(&self.m, site)
        return status

    # -- the same updates the way of Fortune's engine: sweep the changed region, splice the result --

    def insert_swept(self, int site, double x, double y):
        """Insert a site as Fortune's engine does: find the region whose cells the site takes
        (its conflict region), sweep the region's sites with the ring around them, and splice
        the sweep's triangles around the new site in. Returns as insert(). (Where cocircular
        sites let the sweep's star differ from the region's boundary, the exact cavity fan is
        spliced instead; swept_ok says which happened.)"""
        cdef int status
        self._reserve(site)
        self.wx[site] = x
        self.wy[site] = y
        self.m.dup[site] = -1
        self.m.n_changed = 0
        self.mark_epoch += 1
        with nogil:
            status = insert_by_sweep(&self.m, site, self.vmark, self.mark_epoch, self.nextb)
        if status == -2:
            return self.m.dup[site]
        self.swept_ok = status == 1
        self.m.changed[self.m.n_changed] = site
        self.m.n_changed += 1
        return -1

    def remove_swept(self, int site):
        """Remove a site as Fortune's engine does: sweep the sites around the hole and splice
        the sweep's triangles inside the hole in (ear filling where the hole is open to
        infinity, or the sweep's triangles do not fit it exactly). Returns as remove()."""
        cdef int status
        self._reserve(site)
        with nogil:
            status = remove_by_sweep(&self.m, site)
        self.swept_ok = status == 1
        if status == 1:
            return STATUS_DONE
        return self.remove(site)

    def relabel(self, int old, int new):
        """Give the vertex of site old to site new (a repeated point taking over its place)."""
        cdef int e0, e
        self._reserve(new)
        self.wx[new] = self.m.x[old]
        self.wy[new] = self.m.y[old]
        e0 = self.m.vedge[old]
        e = e0
        while True:
            self.m.tv[e] = new
            e = self.m.opp[prv(e)]
            if e == e0:
                break
        self.m.vedge[new] = e0
        self.m.vedge[old] = -1

    def changed(self):
        """Sites whose cells the last insert or remove changed."""
        return np.asarray(self.arrays["changed"][:self.m.n_changed]).copy()

    def coordinates(self, int site):
        return self.m.x[site], self.m.y[site]

    def export(self):
        """(tv, opp) of the live triangles, compacted (vertex INF_VERTEX kept)."""
        tv = self.arrays["tv"][:3 * self.m.n_tri].reshape(-1, 3)
        live = np.ones(self.m.n_tri, bool)
        live[self.arrays["free_tri"][:self.m.n_free]] = False
        new_index = np.cumsum(live) - 1
        opp = self.arrays["opp"][:3 * self.m.n_tri]
        opp_t = new_index[opp // 3] * 3 + opp % 3
        return (tv[live].ravel().copy(), opp_t.reshape(-1, 3)[live].ravel().astype(np.int32))

    def cell(self, int site, double xmin, double ymin, double xmax, double ymax, int exponent=0):
        """The cell of a site in the mesh, clipped to the box: a (k, 2) ring, counter-clockwise.

        The mesh holds sites in a unit 2^-exponent of the user's; the box and the ring are in the user's."""
        cdef Box box = make_box(xmin, ymin, xmax, ymax, exponent)
        cdef CellBuffers buf
        cdef int k, star = 0, e0 = self.m.vedge[site], e = e0
        if e0 < 0:
            return np.empty((0, 2))
        # the number of triangles around the site sizes the scratch
        while True:
            star += 1
            e = self.m.opp[prv(e)]
            if e == e0:
                break
        if not alloc_cell_buffers(&buf, star):
            free_cell_buffers(&buf)
            raise MemoryError(f"no memory for the cell of a site with {star} neighbours")
        with nogil:
            k = cell_ring(&self.m, site, &box, &buf)
        out = np.empty((max(k, 0), 2))
        for i in range(k):
            out[i, 0] = buf.pts[2 * buf.ring[i]]
            out[i, 1] = buf.pts[2 * buf.ring[i] + 1]
        free_cell_buffers(&buf)
        return out

    def neighbours(self, int site):
        """Sites joined to this one by a Delaunay edge, counter-clockwise."""
        out = []
        cdef int e0 = self.m.vedge[site], e = e0
        if e0 < 0:
            return np.empty(0, np.int32)
        while True:
            if self.m.tv[nxt(e)] != INF_VERTEX:
                out.append(self.m.tv[nxt(e)])
            e = self.m.opp[prv(e)]
            if e == e0:
                break
        return np.asarray(out, np.int32)


# ---------------------------------------------------------------------------------------------------------
# removal: the hole is filled ear by ear, each ear a Delaunay triangle of the hole's vertices

cdef inline bint ear_ok(Mesh* m, int* poly, int* nextp, int a, int b, int c) noexcept nogil:
    """Triangle (poly[a], poly[b], poly[c]) of consecutive hole vertices is Delaunay among them."""
    cdef int va = poly[a], vb = poly[b], vc = poly[c], u = 0, w = 0, q, vq, o
    cdef bint finite = va != m.inf and vb != m.inf and vc != m.inf
    if finite:
        if orient2d(m.x[va], m.y[va], m.x[vb], m.y[vb], m.x[vc], m.y[vc]) <= 0:
            return False
    elif vc == m.inf:
        u = va; w = vb
    elif va == m.inf:
        u = vb; w = vc
    else:
        u = vc; w = va
    q = nextp[c]
    while q != a:
        vq = poly[q]
        if vq != m.inf:
            if finite:
                if incircle(m.x[va], m.y[va], m.x[vb], m.y[vb], m.x[vc], m.y[vc], m.x[vq], m.y[vq]) > 0:
                    return False
            else:
                # an infinite ear is a new hull edge u->w: nothing may lie beyond it
                o = orient2d(m.x[u], m.y[u], m.x[w], m.y[w], m.x[vq], m.y[vq])
                if o > 0 or (o == 0 and strictly_between(m, u, w, m.x[vq], m.y[vq])):
                    return False
        q = nextp[q]
    return True


cdef int new_triangle(Mesh* m, int a, int b, int c, int o_ab, int o_bc, int o_ca) noexcept nogil:
    """A triangle in a free slot, glued to the given outside half-edges (-1: none yet)."""
    cdef int T, k, v
    m.n_free -= 1
    T = m.free_tri[m.n_free]
    m.tv[3 * T] = a
    m.tv[3 * T + 1] = b
    m.tv[3 * T + 2] = c
    m.opp[3 * T] = o_ab
    m.opp[o_ab] = 3 * T
    m.opp[3 * T + 1] = o_bc
    m.opp[o_bc] = 3 * T + 1
    if o_ca >= 0:
        m.opp[3 * T + 2] = o_ca
        m.opp[o_ca] = 3 * T + 2
    for k in range(3):
        v = m.tv[3 * T + k]
        if v != m.inf:
            m.vedge[v] = 3 * T + k
    if not is_infinite(m, T):
        m.n_finite += 1
        m.last = T
    return T


cdef int remove_site(Mesh* m, int v) noexcept nogil:
    cdef int poly[MAX_STAR]
    cdef int out[MAX_STAR]
    cdef int nextp[MAX_STAR]
    cdef int prevp[MAX_STAR]
    cdef int e0 = m.vedge[v], e, ne, k = 0, q, t, a, b, c, j, tries, remaining, T
    cdef bint found
    m.n_changed = 0
    # the star of v: its triangles go, the edges opposite v bound the hole (counter-clockwise)
    e = e0
    while True:
        t = e // 3
        if k == MAX_STAR:
            return -1
        if not is_infinite(m, t):
            m.n_finite -= 1
        ne = nxt(e)
        poly[k] = m.tv[ne]
        out[k] = m.opp[ne]
        m.free_tri[m.n_free] = t
        m.n_free += 1
        k += 1
        e = m.opp[prv(e)]
        if e == e0:
            break
    m.vedge[v] = -1
    for q in range(k):
        nextp[q] = q + 1 if q + 1 < k else 0
        prevp[q] = q - 1 if q > 0 else k - 1
        if poly[q] != m.inf:
            m.changed[m.n_changed] = poly[q]
            m.n_changed += 1
    remaining = k
    j = 0
    while remaining > 3:
        found = False
        tries = 0
        while tries < remaining:
            if ear_ok(m, poly, nextp, prevp[j], j, nextp[j]):
                found = True
                break
            j = nextp[j]
            tries += 1
        if not found:
            return -1
        a = prevp[j]
        c = nextp[j]
        T = new_triangle(m, poly[a], poly[j], poly[c], out[a], out[j], -1)
        out[a] = 3 * T + 2          # the hole's new edge a->c has the ear beyond it
        nextp[a] = c
        prevp[c] = a
        remaining -= 1
        j = a
    a = j
    b = nextp[a]
    c = nextp[b]
    new_triangle(m, poly[a], poly[b], poly[c], out[a], out[b], out[c])
    if m.n_finite == 0:
        return STATUS_FLAT
    if m.last < 0 or is_infinite(m, m.last) or m.tv[3 * m.last] == v or m.tv[3 * m.last + 1] == v \
            or m.tv[3 * m.last + 2] == v:
        # the walks' starting triangle went with the hole: take the finite one beyond a new hull edge
        for q in range(k):
            if out[q] >= 0 and not is_infinite(m, out[q] // 3):
                m.last = out[q] // 3
                break
    return STATUS_DONE


# ---------------------------------------------------------------------------------------------------------
# one cell, read locally

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


cdef bint alloc_cell_buffers(CellBuffers* b, int star) noexcept nogil:
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


cdef void free_cell_buffers(CellBuffers* b) noexcept nogil:
    free(b.ring); free(b.pts); free(b.pt_side); free(b.vcx); free(b.vcy); free(b.c_start); free(b.c_end)
    free(b.c_entry); free(b.c_exit); free(b.c_has); free(b.nbx); free(b.nby); free(b.da); free(b.db)
    free(b.dc)


cdef int cell_ring(Mesh* m, int site, Box* box, CellBuffers* b) noexcept nogil:
    """The cell of site clipped to the box (clipper.pxd, as for batch cells): point ids of b.pts in
    b.ring, counter-clockwise from the lowest point; returns the count."""
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
        if has_o and has_d and b.pts[2 * p] == b.pts[2 * q] and b.pts[2 * p + 1] == b.pts[2 * q + 1]:
            continue                  # a zero-length edge (cocircular sites, or closer than rounding)
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
        return 0
    return finish_ring(b.ring, count, b.pts, box.e)


# ---------------------------------------------------------------------------------------------------------
# local updates by Fortune's sweep

cdef void sort_by_sweep(int* ids, double* xs, double* ys, int n) noexcept nogil:
    """Sort sites by y, then x (insertion sort: a region has a few dozen sites)."""
    cdef int k, j, v
    cdef double x, y
    for k in range(1, n):
        v = ids[k]; x = xs[k]; y = ys[k]
        j = k - 1
        while j >= 0 and (ys[j] > y or (ys[j] == y and xs[j] > x)):
            ids[j + 1] = ids[j]; xs[j + 1] = xs[j]; ys[j + 1] = ys[j]
            j -= 1
        ids[j + 1] = v; xs[j + 1] = x; ys[j + 1] = y


cdef int insert_by_sweep(Mesh* m, int site, int32_t* mark, int32_t epoch, int32_t* nextb) noexcept nogil:
    """1: the sweep's star was spliced; 0: the cavity fan was (cocircular or large region); -2: a repeat."""
    cdef int ids[MAX_REGION]
    cdef double xs[MAX_REGION]
    cdef double ys[MAX_REGION]
    cdef int32_t tvl[6 * MAX_REGION]
    cdef int n = 0, q, a, b, e0, e, nt, k, j, lp = -1, matched = 0, nextb_inf = -1
    cdef bint ok = True
    cdef int t0 = locate(m, m.last, m.x[site], m.y[site])
    if not find_cavity(m, site, t0):
        return -2
    # the region: the new site, the sites whose cells it takes (the cavity's boundary) and their ring
    ids[n] = site
    n += 1
    mark[site] = epoch
    nextb[site] = -1
    for q in range(m.n_bnd):
        a = m.bnd_a[q]
        if a == m.inf:
            nextb_inf = m.bnd_b[q]
            continue
        if mark[a] != epoch:
            if n == MAX_REGION:
                ok = False
                break
            mark[a] = epoch
            ids[n] = a
            n += 1
        nextb[a] = m.bnd_b[q]
        # the ring: every neighbour of a boundary site
        e0 = m.vedge[a]
        e = e0
        while True:
            b = m.tv[nxt(e)]
            if b != m.inf and mark[b] != epoch:
                if n == MAX_REGION:
                    ok = False
                    break
                mark[b] = epoch
                nextb[b] = -1
                ids[n] = b
                n += 1
            e = m.opp[prv(e)]
            if e == e0:
                break
        if not ok:
            break
    if ok:
        for k in range(n):
            xs[k] = m.x[ids[k]]
            ys[k] = m.y[ids[k]]
        sort_by_sweep(ids, xs, ys, n)
        nt = sweep_triangles(xs, ys, n, tvl, 2 * MAX_REGION)
        ok = nt > 0
    if ok:
        for k in range(n):
            if ids[k] == site:
                lp = k
        # the sweep's star of the new site must be the region's boundary, edge for edge
        for q in range(nt):
            for k in range(3):
                if tvl[3 * q + k] != lp:
                    continue
                a = tvl[3 * q + (k + 1) % 3]
                b = tvl[3 * q + (k + 2) % 3]
                a = m.inf if a == n else ids[a]
                b = m.inf if b == n else ids[b]
                if (a == m.inf and nextb_inf == b) or (a != m.inf and mark[a] == epoch and nextb[a] == b):
                    matched += 1
                else:
                    ok = False
        ok = ok and matched == m.n_bnd
    fill_cavity(m, site)
    return 1 if ok else 0


cdef int remove_by_sweep(Mesh* m, int site) noexcept nogil:
    """1 when the hole was filled with the sweep's triangles; 0 when the caller must use ears."""
    cdef int poly[MAX_HOLE]
    cdef int outs[MAX_HOLE]
    cdef int slots[MAX_HOLE]
    cdef int ids[MAX_HOLE]
    cdef int pos_of[MAX_HOLE]
    cdef double xs[MAX_HOLE]
    cdef double ys[MAX_HOLE]
    cdef int32_t tvl[6 * MAX_HOLE]
    cdef int inside[3 * MAX_HOLE]
    cdef int32_t half[MAX_HOLE * MAX_HOLE]
    cdef int e0 = m.vedge[site], e, k = 0, q, j, nt, n_in = 0, pa, pb, pc, T, x, y, h
    e = e0
    while True:
        if k == MAX_HOLE:
            return 0
        poly[k] = m.tv[nxt(e)]
        if poly[k] == m.inf:
            return 0
        outs[k] = m.opp[nxt(e)]
        slots[k] = e // 3
        k += 1
        e = m.opp[prv(e)]
        if e == e0:
            break
    for q in range(k):
        ids[q] = q
        xs[q] = m.x[poly[q]]
        ys[q] = m.y[poly[q]]
    sort_by_sweep(ids, xs, ys, k)
    nt = sweep_triangles(xs, ys, k, tvl, 2 * MAX_HOLE)
    if nt <= 0:
        return 0
    # the sweep's triangles inside the hole meet its vertices in their own cyclic order
    for q in range(nt):
        if tvl[3 * q] == k or tvl[3 * q + 1] == k or tvl[3 * q + 2] == k:
            continue
        pa = ids[tvl[3 * q]]; pb = ids[tvl[3 * q + 1]]; pc = ids[tvl[3 * q + 2]]
        if (pb - pa + k) % k + (pc - pb + k) % k + (pa - pc + k) % k == k:
            if n_in == k - 2:
                return 0
            inside[3 * n_in] = pa; inside[3 * n_in + 1] = pb; inside[3 * n_in + 2] = pc
            n_in += 1
    if n_in != k - 2:
        return 0
    for q in range(k * k):
        half[q] = -1
    for q in range(3 * n_in):
        x = inside[q]
        y = inside[q - q % 3 + (q % 3 + 1) % 3]
        if half[x * k + y] != -1:
            return 0
        half[x * k + y] = -2
    for q in range(k):
        if half[q * k + (q + 1) % k] != -2:
            return 0            # a side of the hole is missing: cocircular sites triangulated another way
    # splice: the star's slots are freed, the sweep's triangles take them
    for q in range(k):
        if not is_infinite(m, slots[q]):
            m.n_finite -= 1
        m.free_tri[m.n_free] = slots[q]
        m.n_free += 1
    m.vedge[site] = -1
    for q in range(n_in):
        m.n_free -= 1
        T = m.free_tri[m.n_free]
        for j in range(3):
            x = inside[3 * q + j]
            y = inside[3 * q + (j + 1) % 3]
            m.tv[3 * T + j] = poly[x]
            m.vedge[poly[x]] = 3 * T + j
            half[x * k + y] = 3 * T + j
        m.n_finite += 1
        m.last = T
    for q in range(3 * n_in):
        x = inside[q]
        y = inside[q - q % 3 + (q % 3 + 1) % 3]
        h = half[x * k + y]
        if y == (x + 1) % k:
            m.opp[h] = outs[x]
            m.opp[outs[x]] = h
        else:
            m.opp[h] = half[y * k + x]
    m.n_changed = 0
    for q in range(k):
        m.changed[m.n_changed] = poly[q]
        m.n_changed += 1
    return 1
