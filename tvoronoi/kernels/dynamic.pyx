"""A Delaunay triangulation that changes locally: insert, remove and relabel sites; read one cell."""

import math

import numpy as np

from tvoronoi.errors import EngineError

from libc.stdint cimport int8_t, int32_t, int64_t, uint64_t

from tvoronoi.kernels.predicates cimport orient2d, incircle
from tvoronoi.kernels.mesh cimport Mesh, nxt, prv, is_infinite, strictly_between
from tvoronoi.kernels.location cimport jump_note, jump_start, locate
from tvoronoi.kernels.cavity cimport find_cavity
from tvoronoi.kernels.fill cimport insert_site, fill_cavity
from libc.stdlib cimport malloc, calloc, realloc, free
from libc.string cimport memset
from tvoronoi.kernels.clipper cimport Box, make_box
from tvoronoi.kernels.local_cell cimport (
    CellBuffers, CentreMemo, alloc_cell_buffers, free_cell_buffers, cell_ring, cell_is_bent, memo_clear,
    sure_cells,
)
from tvoronoi.kernels.fortune cimport sweep_triangles
from tvoronoi.kernels.construct cimport circumcentre

cdef enum:
    UNKNOWN = 0             # ring_state of a site: not looked at (or not in the mesh)
    NOT_BENT = 1
    BENT = 2
    QUEUED = 3              # changed since it was looked at; listed in DynamicMesh.queued
    MEMO_RESET = 32         # look_again forgets its memoised circumcentres after this many cells
    INF_VERTEX = 0x7FFFFFFE  # the vertex at infinity of a dynamic mesh (site ids stay below it)
    EAR_LIMIT = 64          # holes of up to this many sides are filled ear by ear (O(k^2) tests);
                            # larger ones by the Delaunay triangles of their sites, spliced in
    SWEEP_WORTH = 8         # a swept insertion's region is worth sweeping up to this many sites
    SWEEP_SLACK = 64        #   per cavity edge, plus this many; beyond, the cavity fan is exact and cheaper
    SMALL_SORT = 32         # up to this many sites are sorted by insertion, more by heap sort
    STATUS_DONE = 0
    STATUS_FLAT = 1         # the sites left are collinear: no triangle remains
    STATUS_NO_MEMORY = 2    # scratch memory could not grow: the mesh is unchanged
    STATUS_NOT_SWEPT = 3    # the sweep's triangles do not tile the hole: fill it by ears instead
    STATUS_STUCK = -1       # no Delaunay ear (impossible with exact predicates): the mesh must be rebuilt


INFINITE = INF_VERTEX
NO_MEMORY = STATUS_NO_MEMORY


# scratch memory of one update (a hole, a swept region), kept by the mesh and grown on demand
cdef struct Scratch:
    int32_t* ints
    Py_ssize_t n_ints
    double* reals
    Py_ssize_t n_reals
    int64_t* keys
    Py_ssize_t n_keys
    Py_ssize_t limit        # tests only: requests above this many entries fail (-1: no limit)


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
    # which cells rounding bent (the rings the batch build straightens), kept for cells_near: per site
    # UNKNOWN, NOT_BENT, BENT or QUEUED (changed since, listed in `queued`); the count of BENT; whether
    # every cell must be looked at again (a new mesh, a new box); the box they were clipped to
    cdef signed char* ring_state
    cdef int32_t* queued
    cdef int n_queued, n_bent
    cdef bint recheck_all
    cdef tuple state_box
    cdef CellBuffers look_buf       # look_again's buffers, kept: room for stars of look_room triangles
    cdef int look_room
    cdef int cap_v, cap_t
    cdef object jump_cells          # the jump grid's array (location.jump_start), made by load
    cdef Scratch scratch            # scratch of one update, grown to the largest hole or region met

    def __cinit__(self):
        self.look_room = 0
        self.scratch.ints = NULL
        self.scratch.n_ints = 0
        self.scratch.reals = NULL
        self.scratch.n_reals = 0
        self.scratch.keys = NULL
        self.scratch.n_keys = 0
        self.scratch.limit = -1

    def __dealloc__(self):
        if self.look_room > 0:
            free_cell_buffers(&self.look_buf)
        free(self.scratch.ints)
        free(self.scratch.reals)
        free(self.scratch.keys)

    def __init__(self, int capacity):
        self.cap_v = 0
        self.cap_t = 0
        self.arrays = {}
        self.m.n_finite = 0
        self.mark_epoch = 0
        self.n_queued = 0
        self.n_bent = 0
        self.recheck_all = True
        self.m.n_tri = 0
        self.m.n_free = 0
        self.m.last = -1
        self.m.jump_g = 0
        self.m.jump_grid = NULL
        self.m.walk_steps = 0
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
                "tv": (3 * cap_t, np.int32), "opp": (3 * cap_t, np.int32), "cavity": (cap_t, np.int32),
                "cav_from": (cap_t, np.int32), "bnd_a": (cap_t + 2, np.int32), "bnd_b": (cap_t + 2, np.int32),
                "bnd_twin": (cap_t + 2, np.int32), "free_tri": (cap_t, np.int32),
                "changed": (cap_t + 2, np.int32), "vmark": (cap_v, np.int32), "nextb": (cap_v, np.int32),
                "ring_state": (cap_v, np.int8), "queued": (cap_v, np.int32)}
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
        cdef int32_t[::1] opp = new["opp"], cavity = new["cavity"], cav_from = new["cav_from"]
        cdef int32_t[::1] bnd_a = new["bnd_a"], bnd_b = new["bnd_b"], bnd_twin = new["bnd_twin"]
        cdef int32_t[::1] free_tri = new["free_tri"], changed = new["changed"]
        cdef int32_t[::1] vmark = new["vmark"], nextb = new["nextb"]
        self.vmark = &vmark[0]
        self.nextb = &nextb[0]
        cdef signed char[::1] ring_state = new["ring_state"]
        cdef int32_t[::1] queued = new["queued"]
        self.ring_state = &ring_state[0]
        self.queued = &queued[0]
        self.m.x = &x[0]
        self.m.y = &y[0]
        self.wx = &x[0]
        self.wy = &y[0]
        self.m.vedge = &vedge[0]
        self.m.vmap = &vmap[0]
        self.m.dup = &dup[0]
        self.m.tv = &tv[0]
        self.m.opp = &opp[0]
        self.m.cavity = &cavity[0]
        self.m.cav_from = &cav_from[0]
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
        cap_v, cap_t = max(self.cap_v, top, 4), max(self.cap_t, n_he // 3 + 8, 2 * top + 8)
        if cap_v > self.cap_v or cap_t > self.cap_t or self.m.n_tri > 0:
            # (a new mesh with room enough keeps its fresh arrays: a second set of them, made and
            # copied for nothing, cost a second at a million sites, mostly in fresh pages)
            self._grow(cap_v, cap_t)
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
        self._grid(xs, ys, ids)
        self.recheck_all = True          # every cell is new
        self.n_queued = 0

    def _grid(self, const double[::1] xs, const double[::1] ys, const int32_t[::1] ids):
        """The jump grid over the loaded sites: about four sites a cell, each cell holding one of them."""
        cdef int n = xs.shape[0], k, g
        cdef int32_t[::1] cells
        if n == 0:
            return
        x0, x1, y0, y1 = float(np.min(xs)), float(np.max(xs)), float(np.min(ys)), float(np.max(ys))
        g = max(1, min(4096, int((n / 4) ** 0.5)))
        self.jump_cells = np.full(g * g, -1, np.int32)
        cells = self.jump_cells
        self.m.jump_grid = &cells[0]
        self.m.jump_g = g
        self.m.jump_x0 = x0
        self.m.jump_y0 = y0
        self.m.jump_sx = g / (x1 - x0) if x1 > x0 and math.isfinite(g / (x1 - x0)) else 0.0
        self.m.jump_sy = g / (y1 - y0) if y1 > y0 and math.isfinite(g / (y1 - y0)) else 0.0
        for k in range(n):
            jump_note(&self.m, ids[k])

    @property
    def walk_steps(self):
        """Triangles the last point location visited (for tests)."""
        return self.m.walk_steps

    @property
    def n_finite(self):
        """Finite triangles: 0 once the sites left are collinear (the mesh cannot hold them)."""
        return self.m.n_finite

    def set_site(self, int site, double x, double y):
        """Place a site (not yet in the mesh), e.g. a repeated point that stays outside it."""
        self._reserve(site)
        self.forget(site)
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
            t0 = locate(&self.m, jump_start(&self.m, x, y), x, y)
            before = self.m.n_tri - self.m.n_free
            insert_site(&self.m, site, t0)
        if self.m.dup[site] >= 0:
            return self.m.dup[site]
        jump_note(&self.m, site)
        self.m.changed[self.m.n_changed] = site
        self.m.n_changed += 1
        self.unsettle()
        return -1

    def remove(self, int site):
        """Take a site out and fill its hole with the Delaunay triangles of its neighbours:
        ear by ear, or for a large hole (a site with many neighbours) the Delaunay triangles
        of the neighbours spliced in. Returns STATUS_DONE, STATUS_FLAT (the sites left are
        collinear), STATUS_NO_MEMORY (nothing changed) or STATUS_STUCK (rebuild the mesh)."""
        cdef int status = STATUS_NOT_SWEPT
        self._reserve(site)
        with nogil:
            if star_size(&self.m, site) > EAR_LIMIT:
                status = remove_by_sweep(&self.m, site, &self.scratch)
            if status == STATUS_NOT_SWEPT or status == STATUS_NO_MEMORY:
                status = remove_site(&self.m, site, &self.scratch)
        self.unsettle()
        return status

    # -- the same updates the way of Fortune's engine: sweep the changed region, splice the result --

    def insert_swept(self, int site, double x, double y):
        """Insert a site as Fortune's engine does: find the region whose cells the site takes
        (its conflict region), sweep the region's sites with the ring around them, and splice
        the sweep's triangles around the new site in. Returns as insert(). (Where cocircular
        sites let the sweep's star differ from the region's boundary, or the region is far
        larger than the cavity, e.g. next to a site with thousands of neighbours, the exact
        cavity fan is spliced instead; swept_ok says which happened.)"""
        cdef int status
        self._reserve(site)
        self.wx[site] = x
        self.wy[site] = y
        self.m.dup[site] = -1
        self.m.n_changed = 0
        self.mark_epoch += 1
        with nogil:
            status = insert_by_sweep(&self.m, site, self.vmark, self.mark_epoch, self.nextb, &self.scratch)
        if status == -2:
            return self.m.dup[site]
        jump_note(&self.m, site)
        self.swept_ok = status == 1
        self.m.changed[self.m.n_changed] = site
        self.m.n_changed += 1
        self.unsettle()
        return -1

    def remove_swept(self, int site):
        """Remove a site as Fortune's engine does: sweep the sites around the hole and splice
        the sweep's triangles inside the hole in (ear filling where the sweep's triangles do
        not fit it exactly, or its sites are collinear). Returns as remove()."""
        cdef int status
        cdef bint swept = True
        self._reserve(site)
        with nogil:
            status = remove_by_sweep(&self.m, site, &self.scratch)
            if status == STATUS_NOT_SWEPT or status == STATUS_NO_MEMORY:
                swept = False
                status = remove_site(&self.m, site, &self.scratch)
        self.swept_ok = swept
        self.unsettle()
        return status

    def relabel(self, int old, int new):
        """Give the vertex of site old to site new (a repeated point taking over its place)."""
        cdef int e0, e
        self._reserve(new)
        self.forget(old)
        self.forget(new)
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

    def _limit_scratch(self, Py_ssize_t entries):
        """Tests only: make scratch requests above this many entries fail as if memory ran out
        (-1: no limit)."""
        self.scratch.limit = entries

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
        if k < 0:
            free_cell_buffers(&buf)
            raise EngineError(f"the clipper found a cell whose edges do not chain (site {site}): please report "
                              "the updates that led here")
        out = np.empty((k, 2))
        for i in range(k):
            out[i, 0] = buf.pts[2 * buf.ring[i]]
            out[i, 1] = buf.pts[2 * buf.ring[i] + 1]
        free_cell_buffers(&buf)
        return out

    cdef void forget(self, int site) noexcept:
        # the cell of site may have changed: no longer known bent or not, queued to be looked at again
        if site < 0 or site >= self.cap_v:
            return
        if self.ring_state[site] == BENT:
            self.n_bent -= 1
        if self.ring_state[site] != QUEUED and not self.recheck_all:
            self.queued[self.n_queued] = site
            self.n_queued += 1
            self.ring_state[site] = QUEUED
        elif self.recheck_all:
            self.ring_state[site] = UNKNOWN

    cdef void unsettle(self) noexcept:
        # the cells the last update changed
        cdef int k
        for k in range(self.m.n_changed):
            if self.m.changed[k] != INF_VERTEX:
                self.forget(self.m.changed[k])

    cdef int look_again(self, Box* box) except -1:
        """Bring ring_state and n_bent up to date: the queued cells, or every cell after a new mesh or
        box (sure_cells settles most at once, by triangles). A cell is looked at once after each change
        that touches it (cell_is_bent: memoised circumcentres, one convexity test in the usual case)."""
        cdef CentreMemo memo
        cdef int k, s, looked = 0
        cdef bint all_of_them = self.recheck_all, out_of_memory = False
        cdef signed char* sure = NULL
        if not all_of_them and self.n_queued == 0:
            return 0
        memo_clear(&memo)
        if all_of_them:
            sure = <signed char*> calloc(max(self.cap_v, 1), 1)
            if sure == NULL:
                raise MemoryError("no memory to look at every cell")
        with nogil:
            if all_of_them:
                self.n_bent = 0
                for s in range(self.cap_v):
                    self.ring_state[s] = UNKNOWN
                if sure_cells(&self.m, box, sure) < 0:
                    memset(sure, 0, self.cap_v)
                for s in range(self.cap_v):
                    if self.m.vedge[s] < 0:
                        continue
                    if sure[s]:
                        self.ring_state[s] = NOT_BENT
                        continue
                    if not self.look_at(s, box, &memo):
                        out_of_memory = True
                        break
                    looked += 1
                    if looked % MEMO_RESET == 0:
                        memo_clear(&memo)
            else:
                for k in range(self.n_queued):
                    s = self.queued[k]
                    if self.ring_state[s] != QUEUED:
                        continue
                    self.ring_state[s] = UNKNOWN
                    if self.m.vedge[s] >= 0 and not self.look_at(s, box, &memo):
                        out_of_memory = True
                        break
        free(sure)
        if out_of_memory:
            self.recheck_all = True          # what was not looked at is looked at next time
            raise MemoryError("no memory for the cell of a site")
        self.n_queued = 0
        self.recheck_all = False
        return 0

    cdef bint look_at(self, int s, Box* box, CentreMemo* memo) noexcept nogil:
        # ring_state of site s (in the mesh) from its cell; False when no buffers could be had for it
        cdef int star = 0, e0 = self.m.vedge[s], e = e0
        while True:
            star += 1
            e = self.m.opp[prv(e)]
            if e == e0:
                break
        if star > self.look_room:
            if self.look_room > 0:
                free_cell_buffers(&self.look_buf)
            self.look_room = 0
            if not alloc_cell_buffers(&self.look_buf, max(star, 16)):
                free_cell_buffers(&self.look_buf)
                return False
            self.look_room = max(star, 16)
        if cell_is_bent(&self.m, s, box, memo, &self.look_buf):
            self.ring_state[s] = BENT
            self.n_bent += 1
        else:
            self.ring_state[s] = NOT_BENT
        return True

    def bent_sites(self, double xmin, double ymin, double xmax, double ymax, int exponent, bint by_triangles):
        """The sites whose cells rounding bent, looked at afresh: every cell by triangles (as after a new
        mesh), or each on its own (as after updates). For tests: the two must agree."""
        cdef Box box = make_box(xmin, ymin, xmax, ymax, exponent)
        cdef int s
        self.state_box = (xmin, ymin, xmax, ymax, exponent)
        if by_triangles:
            self.recheck_all = True
        else:
            self.recheck_all = False
            self.n_queued = 0
            self.n_bent = 0
            for s in range(self.cap_v):
                self.ring_state[s] = UNKNOWN
                if self.m.vedge[s] >= 0:
                    self.forget(s)
        self.look_again(&box)
        states = np.asarray(self.arrays["ring_state"][:self.cap_v])
        assert int((states == BENT).sum()) == self.n_bent
        return np.flatnonzero(states == BENT).astype(np.int32)

    def sites_at_point(self, int site, double x, double y, int exponent):
        """The sites of the cells that have (x, y) as a vertex: of the triangles whose circumcentre,
        correctly rounded (times 2^exponent), is that point, found from the triangles around `site` and
        then their neighbours that round to it too. (Delaunay triangles whose centres round to one point
        share one empty circle, nearly: they triangulate the polygon of its sites, each next to another.)
        Nearly cocircular sites can share such a point across many Delaunay steps."""
        cdef int e0 = self.m.vedge[site], e, t, k, u
        cdef double cx, cy
        found, todo, seen = set(), [], set()
        if e0 < 0:
            return found
        e = e0
        while True:
            todo.append(e // 3)
            e = self.m.opp[prv(e)]
            if e == e0:
                break
        while todo:
            t = todo.pop()
            if t in seen or is_infinite(&self.m, t):
                continue
            seen.add(t)
            circumcentre(self.m.x[self.m.tv[3 * t]], self.m.y[self.m.tv[3 * t]],
                         self.m.x[self.m.tv[3 * t + 1]], self.m.y[self.m.tv[3 * t + 1]],
                         self.m.x[self.m.tv[3 * t + 2]], self.m.y[self.m.tv[3 * t + 2]], exponent, &cx, &cy)
            if cx != x or cy != y:
                continue
            for k in range(3):
                found.add(self.m.tv[3 * t + k])
                u = self.m.opp[3 * t + k]
                if u >= 0:
                    todo.append(u // 3)
        return found

    def shares_a_bent_vertex(self, int site, int exponent):
        """Whether a cell known bent (ring_state, as cells_near last brought it up to date) has a vertex
        of this site's cell: its merges would rename that point here, however many steps away."""
        cdef int e0 = self.m.vedge[site], e, t, a, b, c
        cdef double cx, cy
        if e0 < 0 or self.n_bent == 0:
            return False
        e = e0
        while True:
            t = e // 3
            if not is_infinite(&self.m, t):
                a = self.m.tv[3 * t]; b = self.m.tv[3 * t + 1]; c = self.m.tv[3 * t + 2]
                circumcentre(self.m.x[a], self.m.y[a], self.m.x[b], self.m.y[b], self.m.x[c], self.m.y[c],
                             exponent, &cx, &cy)
                for s in self.sites_at_point(site, cx, cy, exponent):
                    if self.ring_state[s] == BENT:
                        return True
            e = self.m.opp[prv(e)]
            if e == e0:
                break
        return False

    def cells_near(self, int site, double xmin, double ymin, double xmax, double ymax, int exponent,
                   int radius):
        """The cell of a site, as cell() reads it, and whether the batch build's straightening could
        change it: when a cell of a site within `radius` Delaunay steps (the site's own included) is
        bent (clipper.bent), also the cells of all those sites, for the caller to straighten. Which
        cells are bent is kept up to date as updates change them (look_again), so without a bent cell
        in the mesh this costs one cell and the cells the last updates changed.

        Returns (ring, None), or (ring, (ids, steps, offsets, xy)): the sites breadth first from this
        one (int32), their steps from it (int32), and their rings as rows of xy from offsets[k] to
        offsets[k + 1] (int64). A site whose cell misses the box has an empty ring."""
        cdef Box box = make_box(xmin, ymin, xmax, ymax, exponent)
        cdef CellBuffers buf
        cdef int32_t* ids = NULL
        cdef int32_t* steps = NULL
        cdef int32_t* grown
        cdef int n_ids = 0, cap = 0, head = 0, e0, e, j, k, i, any_bent = 0
        cdef int32_t epoch
        if self.m.vedge[site] < 0:
            return np.empty((0, 2)), None
        if self.state_box != (xmin, ymin, xmax, ymax, exponent):
            self.recheck_all = True
            self.state_box = (xmin, ymin, xmax, ymax, exponent)
        self.look_again(&box)
        ring = self.cell(site, xmin, ymin, xmax, ymax, exponent)
        if self.n_bent == 0:
            return ring, None
        # breadth first from the site, to `radius` steps, looking for a bent cell
        self.mark_epoch += 1
        epoch = self.mark_epoch
        cap = 64
        ids = <int32_t*> malloc(cap * sizeof(int32_t))
        steps = <int32_t*> malloc(cap * sizeof(int32_t))
        if ids == NULL or steps == NULL:
            free(ids); free(steps)
            raise MemoryError("no memory for the cells around a site")
        try:
            ids[0] = site
            steps[0] = 0
            n_ids = 1
            self.vmark[site] = epoch
            while head < n_ids:
                i = ids[head]
                if self.ring_state[i] == BENT:
                    any_bent = 1
                e0 = self.m.vedge[i]
                e = e0
                while steps[head] < radius:
                    j = self.m.tv[nxt(e)]
                    if j != self.m.inf and self.vmark[j] != epoch:
                        if n_ids == cap:
                            cap *= 2
                            grown = <int32_t*> realloc(ids, cap * sizeof(int32_t))
                            if grown == NULL:
                                raise MemoryError("no memory for the cells around a site")
                            ids = grown
                            grown = <int32_t*> realloc(steps, cap * sizeof(int32_t))
                            if grown == NULL:
                                raise MemoryError("no memory for the cells around a site")
                            steps = grown
                        self.vmark[j] = epoch
                        ids[n_ids] = j
                        steps[n_ids] = steps[head] + 1
                        n_ids += 1
                    e = self.m.opp[prv(e)]
                    if e == e0:
                        break
                head += 1
            if not any_bent:
                return ring, None
            offsets = np.zeros(n_ids + 1, np.int64)
            chunks = []
            for i in range(n_ids):
                xy = self.cell(ids[i], xmin, ymin, xmax, ymax, exponent)
                chunks.append(xy)
                offsets[i + 1] = offsets[i] + len(xy)
            out_ids = np.array(<int32_t[:n_ids]> ids, np.int32)
            out_steps = np.array(<int32_t[:n_ids]> steps, np.int32)
            return ring, (out_ids, out_steps, offsets, np.concatenate(chunks))
        finally:
            free(ids)
            free(steps)

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
# scratch memory of one update: grown to the largest hole or region met, kept by the mesh

cdef bint reserve(Scratch* s, Py_ssize_t n_ints, Py_ssize_t n_reals, Py_ssize_t n_keys) noexcept nogil:
    """Room for n_ints int32, n_reals doubles and n_keys int64 (contents are not kept);
    False when memory runs out (the buffers there are left as they were)."""
    cdef void* p
    if s.limit >= 0 and (n_ints > s.limit or n_reals > s.limit or n_keys > s.limit):
        return False
    if n_ints > s.n_ints:
        n_ints = max(n_ints, 2 * s.n_ints)
        p = malloc(n_ints * sizeof(int32_t))
        if p == NULL:
            return False
        free(s.ints)
        s.ints = <int32_t*>p
        s.n_ints = n_ints
    if n_reals > s.n_reals:
        n_reals = max(n_reals, 2 * s.n_reals)
        p = malloc(n_reals * sizeof(double))
        if p == NULL:
            return False
        free(s.reals)
        s.reals = <double*>p
        s.n_reals = n_reals
    if n_keys > s.n_keys:
        n_keys = max(n_keys, 2 * s.n_keys)
        p = malloc(n_keys * sizeof(int64_t))
        if p == NULL:
            return False
        free(s.keys)
        s.keys = <int64_t*>p
        s.n_keys = n_keys
    return True


# ---------------------------------------------------------------------------------------------------------
# removal: the hole is filled ear by ear, each ear a Delaunay triangle of the hole's vertices;
# a large hole by the Delaunay triangles of its vertices, spliced in (see remove_by_sweep)

cdef int star_size(Mesh* m, int v) noexcept nogil:
    """Triangles around site v (its neighbours, the vertex at infinity included)."""
    cdef int e0 = m.vedge[v], e = e0, k = 0
    while True:
        k += 1
        e = m.opp[prv(e)]
        if e == e0:
            return k


cdef void collect_hole(Mesh* m, int v, int32_t* poly, int32_t* outs, int32_t* slots) noexcept nogil:
    """The hole that v leaves, counter-clockwise: its vertices poly (the ends of v's edges), the
    half-edges outs outside each side poly[q] -> poly[q + 1], and the star's triangles slots."""
    cdef int e0 = m.vedge[v], e = e0, k = 0
    while True:
        poly[k] = m.tv[nxt(e)]
        outs[k] = m.opp[nxt(e)]
        slots[k] = e // 3
        k += 1
        e = m.opp[prv(e)]
        if e == e0:
            return


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


cdef void repair_last(Mesh* m, int v, const int32_t* outs, int k) noexcept nogil:
    """If the walks' starting triangle went with the hole of v, take the finite one beyond a side."""
    cdef int q
    if m.last < 0 or is_infinite(m, m.last) or m.tv[3 * m.last] == v or m.tv[3 * m.last + 1] == v \
            or m.tv[3 * m.last + 2] == v:
        for q in range(k):
            if outs[q] >= 0 and not is_infinite(m, outs[q] // 3):
                m.last = outs[q] // 3
                break


cdef int remove_site(Mesh* m, int v, Scratch* sc) noexcept nogil:
    """Remove site v and fill its hole ear by ear. Returns STATUS_DONE, STATUS_FLAT,
    STATUS_NO_MEMORY (before any change) or STATUS_STUCK."""
    cdef int k = star_size(m, v), q, t, a, b, c, j, tries, remaining, T
    cdef int32_t* poly
    cdef int32_t* out
    cdef int32_t* nextp
    cdef int32_t* prevp
    cdef int32_t* slots
    cdef bint found
    if not reserve(sc, 5 * k, 0, 0):
        return STATUS_NO_MEMORY
    poly = sc.ints
    out = poly + k
    nextp = out + k
    prevp = nextp + k
    slots = prevp + k
    # the star of v: its triangles go, the edges opposite v bound the hole (counter-clockwise)
    collect_hole(m, v, poly, out, slots)
    m.n_changed = 0
    for q in range(k):
        t = slots[q]
        if not is_infinite(m, t):
            m.n_finite -= 1
        m.free_tri[m.n_free] = t
        m.n_free += 1
    m.vedge[v] = -1
    for q in range(k):
        nextp[q] = q + 1 if q + 1 < k else 0
        prevp[q] = q - 1 if q > 0 else k - 1
        if poly[q] != m.inf:
            m.changed[m.n_changed] = poly[q]
            m.n_changed += 1
    # cut ears until a triangle is left
    remaining = k
    j = 0
    while remaining > 3:
        found = False
        tries = 0
        while tries < remaining:
            if ear_ok(m, <int*>poly, <int*>nextp, prevp[j], j, nextp[j]):
                found = True
                break
            j = nextp[j]
            tries += 1
        if not found:
            return STATUS_STUCK
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
    repair_last(m, v, out, k)
    return STATUS_DONE


cdef inline Py_ssize_t slot_of(const int64_t* keys, Py_ssize_t mask, int64_t key) noexcept nogil:
    """The slot of a hash table (linear probing, -1 for empty) that holds key, or where it goes."""
    cdef uint64_t h = <uint64_t>key * <uint64_t>0x9E3779B97F4A7C15
    cdef Py_ssize_t i = <Py_ssize_t>((h ^ (h >> 29)) & <uint64_t>mask)
    while keys[i] != -1 and keys[i] != key:
        i = (i + 1) & mask
    return i


cdef int splice_hole(Mesh* m, int v, int k, const int32_t* poly, const int32_t* outs,
                     const int32_t* slots, const int32_t* tvl, int nt, const int32_t* pos, int n_local,
                     int32_t* inside, int64_t* keys, int32_t* half, Py_ssize_t mask) noexcept nogil:
    """Fill the hole of v (k sides, from collect_hole) with those of the nt triangles tvl that
    lie inside it, when they tile it exactly; returns STATUS_DONE, STATUS_FLAT, or
    STATUS_NOT_SWEPT with the mesh unchanged.

    tvl is a Delaunay triangulation of the hole's sites: local vertex j is the hole's vertex
    pos[j], local vertex n_local the vertex at infinity (pos[n_local]: its place in the hole,
    or -1 when the hole is closed). Scratch: inside (3k), and a hash table keys, half of
    mask + 1 slots (at least twice 3k) from half-edges x -> y (hole positions) to half-edges.
    """
    cdef int q, j, x, y, z, n_in = 0, T, pa, pb, pc
    cdef int64_t key
    cdef Py_ssize_t h
    # the triangles inside the hole meet its vertices in its own cyclic order
    for q in range(nt):
        pa = pos[tvl[3 * q]]
        pb = pos[tvl[3 * q + 1]]
        pc = pos[tvl[3 * q + 2]]
        if pa < 0 or pb < 0 or pc < 0:
            continue                # an infinite triangle of the sites, the hole being closed
        if (pb - pa + k) % k + (pc - pb + k) % k + (pa - pc + k) % k == k:
            if n_in == k - 2:
                return STATUS_NOT_SWEPT
            inside[3 * n_in] = pa
            inside[3 * n_in + 1] = pb
            inside[3 * n_in + 2] = pc
            n_in += 1
    if n_in != k - 2:
        return STATUS_NOT_SWEPT
    # every half-edge once, every side of the hole among them, every other one with its twin
    for h in range(mask + 1):
        keys[h] = -1
    for q in range(3 * n_in):
        x = inside[q]
        y = inside[q - q % 3 + (q % 3 + 1) % 3]
        key = <int64_t>x * k + y
        h = slot_of(keys, mask, key)
        if keys[h] == key:
            return STATUS_NOT_SWEPT
        keys[h] = key
        half[h] = q
    for q in range(k):
        key = <int64_t>q * k + (q + 1) % k
        if keys[slot_of(keys, mask, key)] != key:
            return STATUS_NOT_SWEPT     # a side is missing: cocircular sites triangulated another way
    for q in range(3 * n_in):
        x = inside[q]
        y = inside[q - q % 3 + (q % 3 + 1) % 3]
        if y != (x + 1) % k:
            key = <int64_t>y * k + x
            if keys[slot_of(keys, mask, key)] != key:
                return STATUS_NOT_SWEPT
    # splice: the star's slots are freed, the new triangles take them
    m.n_changed = 0
    for q in range(k):
        if not is_infinite(m, slots[q]):
            m.n_finite -= 1
        m.free_tri[m.n_free] = slots[q]
        m.n_free += 1
        if poly[q] != m.inf:
            m.changed[m.n_changed] = poly[q]
            m.n_changed += 1
    m.vedge[v] = -1
    for q in range(n_in):
        m.n_free -= 1
        T = m.free_tri[m.n_free]
        for j in range(3):
            x = inside[3 * q + j]
            y = inside[3 * q + (j + 1) % 3]
            z = poly[x]
            m.tv[3 * T + j] = z
            if z != m.inf:
                m.vedge[z] = 3 * T + j
            half[slot_of(keys, mask, <int64_t>x * k + y)] = 3 * T + j
        if not is_infinite(m, T):
            m.n_finite += 1
            m.last = T
    for q in range(3 * n_in):
        x = inside[q]
        y = inside[q - q % 3 + (q % 3 + 1) % 3]
        h = half[slot_of(keys, mask, <int64_t>x * k + y)]
        if y == (x + 1) % k:
            m.opp[h] = outs[x]
            m.opp[outs[x]] = h
        else:
            m.opp[h] = half[slot_of(keys, mask, <int64_t>y * k + x)]
    if m.n_finite == 0:
        return STATUS_FLAT
    repair_last(m, v, outs, k)
    return STATUS_DONE


# ---------------------------------------------------------------------------------------------------------
# local updates by Fortune's sweep

cdef inline bint sweeps_first(const double* xs, const double* ys, int a, int b) noexcept nogil:
    """Site a comes before site b in the sweep: by y, then x."""
    return ys[a] < ys[b] or (ys[a] == ys[b] and xs[a] < xs[b])


cdef inline void swap_sites(int32_t* ids, double* xs, double* ys, int a, int b) noexcept nogil:
    cdef int32_t i = ids[a]
    cdef double t = xs[a]
    ids[a] = ids[b]; ids[b] = i
    xs[a] = xs[b]; xs[b] = t
    t = ys[a]; ys[a] = ys[b]; ys[b] = t


cdef void sift_down(int32_t* ids, double* xs, double* ys, int root, int end) noexcept nogil:
    """Restore the max-heap (in sweep order) below root, in sites [0, end)."""
    cdef int child
    while True:
        child = 2 * root + 1
        if child >= end:
            return
        if child + 1 < end and sweeps_first(xs, ys, child, child + 1):
            child += 1
        if not sweeps_first(xs, ys, root, child):
            return
        swap_sites(ids, xs, ys, root, child)
        root = child


cdef void sort_by_sweep(int32_t* ids, double* xs, double* ys, int n) noexcept nogil:
    """Sort sites by y, then x, carrying ids along (insertion sort for a few dozen sites,
    heap sort for more: no scratch memory either way)."""
    cdef int k, j
    cdef int32_t v
    cdef double x, y
    if n > SMALL_SORT:
        for k in range(n // 2 - 1, -1, -1):
            sift_down(ids, xs, ys, k, n)
        for k in range(n - 1, 0, -1):
            swap_sites(ids, xs, ys, 0, k)
            sift_down(ids, xs, ys, 0, k)
        return
    for k in range(1, n):
        v = ids[k]; x = xs[k]; y = ys[k]
        j = k - 1
        while j >= 0 and (ys[j] > y or (ys[j] == y and xs[j] > x)):
            ids[j + 1] = ids[j]; xs[j + 1] = xs[j]; ys[j + 1] = ys[j]
            j -= 1
        ids[j + 1] = v; xs[j + 1] = x; ys[j + 1] = y


cdef int insert_by_sweep(Mesh* m, int site, int32_t* mark, int32_t epoch, int32_t* nextb,
                         Scratch* sc) noexcept nogil:
    """1: the sweep's star was spliced; 0: the cavity fan was (cocircular sites, a region far
    larger than the cavity, or no memory to sweep it: the fan needs none); -2: a repeat."""
    cdef int32_t* ids
    cdef int32_t* tvl
    cdef double* xs
    cdef double* ys
    cdef int n = 0, q, a, b, e0, e, nt, k, j, lp = -1, matched = 0, nextb_inf = -1, bound = 1
    cdef bint ok = True
    cdef int t0 = locate(m, jump_start(m, m.x[site], m.y[site]), m.x[site], m.y[site])
    if not find_cavity(m, site, t0):
        return -2
    # the region's size, at most: the new site, each boundary site and its neighbours
    for q in range(m.n_bnd):
        if m.bnd_a[q] != m.inf:
            bound += 1 + star_size(m, m.bnd_a[q])
    if bound > SWEEP_WORTH * m.n_bnd + SWEEP_SLACK or not reserve(sc, bound + 3 * (2 * bound + 2), 2 * bound, 0):
        fill_cavity(m, site)
        return 0
    ids = sc.ints
    tvl = ids + bound
    xs = sc.reals
    ys = xs + bound
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
                mark[b] = epoch
                nextb[b] = -1
                ids[n] = b
                n += 1
            e = m.opp[prv(e)]
            if e == e0:
                break
    for k in range(n):
        xs[k] = m.x[ids[k]]
        ys[k] = m.y[ids[k]]
    sort_by_sweep(ids, xs, ys, n)
    nt = sweep_triangles(xs, ys, n, tvl, 2 * bound + 2)
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


cdef int remove_by_sweep(Mesh* m, int site, Scratch* sc) noexcept nogil:
    """Remove a site, filling its hole with the triangles of a sweep over the hole's sites.
    Returns STATUS_DONE or STATUS_FLAT; STATUS_NOT_SWEPT when the sweep's triangles do not
    tile the hole (cocircular sites triangulated another way, collinear sites) and
    STATUS_NO_MEMORY, both with the mesh unchanged: the caller fills the hole by ears."""
    cdef int k = star_size(m, site), q, nf = 0, nt, p_inf = -1
    cdef Py_ssize_t size = 1
    cdef int32_t* poly
    cdef int32_t* outs
    cdef int32_t* slots
    cdef int32_t* ids
    cdef int32_t* tvl
    cdef int32_t* inside
    cdef int32_t* half
    cdef double* xs
    cdef double* ys
    # the hash table of the splice: a power of two, at least twice the half-edges
    while size < 6 * k:
        size *= 2
    if not reserve(sc, 5 * k + 1 + 3 * (2 * k + 2) + 3 * k + size, 2 * k, size):
        return STATUS_NO_MEMORY
    poly = sc.ints
    outs = poly + k
    slots = outs + k
    ids = slots + k                 # hole position of each site swept, then the vertex at infinity
    tvl = ids + k + 1
    inside = tvl + 3 * (2 * k + 2)
    half = inside + 3 * k
    xs = sc.reals
    ys = xs + k
    collect_hole(m, site, poly, outs, slots)
    # the hole's sites, in sweep order
    for q in range(k):
        if poly[q] == m.inf:
            p_inf = q
            continue
        ids[nf] = q
        xs[nf] = m.x[poly[q]]
        ys[nf] = m.y[poly[q]]
        nf += 1
    sort_by_sweep(ids, xs, ys, nf)
    ids[nf] = p_inf
    nt = sweep_triangles(xs, ys, nf, tvl, 2 * k + 2)
    if nt <= 0:
        return STATUS_NOT_SWEPT
    return splice_hole(m, site, k, poly, outs, slots, tvl, nt, ids, nf, inside, sc.keys, half, size - 1)
