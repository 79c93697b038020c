# Point location of the incremental engine: a visibility walk from a recent triangle (BRIO order) or
# conflict lists (the textbook random order); inline, compiled where cimported.

from tvoronoi.kernels.predicates cimport orient2d
from tvoronoi.kernels.mesh cimport Mesh, is_infinite, nxt, prv
from tvoronoi.kernels.prefetch cimport prefetch

cdef inline int jump_cell(Mesh* m, double px, double py) noexcept nogil:
    # the cell of the jump grid holding p (points outside it: the nearest border cell)
    cdef double fx = (px - m.jump_x0) * m.jump_sx, fy = (py - m.jump_y0) * m.jump_sy
    cdef int i, j, g = m.jump_g
    i = 0 if not fx > 0.0 else (g - 1 if fx >= g else <int> fx)
    j = 0 if not fy > 0.0 else (g - 1 if fy >= g else <int> fy)
    return j * g + i


cdef inline void jump_note(Mesh* m, int site) noexcept nogil:
    # a site just placed in the mesh becomes its grid cell's start
    if m.jump_g > 0:
        m.jump_grid[jump_cell(m, m.x[site], m.y[site])] = site


cdef inline int jump_start(Mesh* m, double px, double py) noexcept nogil:
    """Where a dynamic diagram's walk to p starts (jump and walk): a finite triangle around the site
    last placed in p's cell of a coarse grid over the sites (about four sites a cell), or the last
    triangle when that site has left the mesh. The walk from there is exact; the grid only shortens
    it, to a few triangles where the walk from the last triangle crosses O(sqrt n) of them."""
    cdef int s, e, e0
    if m.jump_g <= 0:
        return m.last
    s = m.jump_grid[jump_cell(m, px, py)]
    if s < 0:
        return m.last
    e0 = m.vedge[s]
    if e0 < 0 or m.tv[e0] != s:
        return m.last               # removed since, or its place taken by a repeat
    e = e0
    while True:
        if not is_infinite(m, e // 3):
            return e // 3
        e = m.opp[prv(e)]
        if e == e0:
            return m.last


cdef inline int locate(Mesh* m, int t, double px, double py) noexcept nogil:
    """Walk from finite triangle t towards p; return a triangle in conflict with p.

    The result contains p (closed), or is the infinite triangle beyond a hull
    edge that p sees strictly: either way p is strictly inside its circle.
    The visibility walk terminates in a Delaunay triangulation.
    """
    cdef int e, a0, a1, a2, came = -1, steps = 0
    cdef double x0, y0, x1, y1, x2, y2
    while True:
        steps += 1
        prefetch(&m.opp[3 * t])
        a0 = m.tv[3 * t]; a1 = m.tv[3 * t + 1]; a2 = m.tv[3 * t + 2]
        if a0 == m.inf or a1 == m.inf or a2 == m.inf:
            m.walk_steps = steps
            return t
        # the corners read once; edge 3t + k runs from corner k to corner k + 1
        x0 = m.x[a0]; y0 = m.y[a0]; x1 = m.x[a1]; y1 = m.y[a1]; x2 = m.x[a2]; y2 = m.y[a2]
        e = 3 * t
        if e != came and orient2d(x0, y0, x1, y1, px, py) < 0:
            came = m.opp[e]
        elif e + 1 != came and orient2d(x1, y1, x2, y2, px, py) < 0:
            came = m.opp[e + 1]
        elif e + 2 != came and orient2d(x2, y2, x0, y0, px, py) < 0:
            came = m.opp[e + 2]
        else:
            m.walk_steps = steps
            return t
        t = <int> (<unsigned> came // 3)


cdef inline void list_site(Mesh* m, int t, int s) noexcept nogil:
    m.next_site[s] = m.head[t]
    m.head[t] = s
    m.where[s] = t
