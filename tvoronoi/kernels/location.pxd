# Point location of the incremental engine: a visibility walk from a recent triangle (BRIO order) or
# conflict lists (the textbook random order); inline, compiled where cimported.

from tvoronoi.kernels.predicates cimport orient2d
from tvoronoi.kernels.mesh cimport Mesh, is_infinite, nxt


cdef inline int locate(Mesh* m, int t, double px, double py) noexcept nogil:
    """Walk from finite triangle t towards p; return a triangle in conflict with p.

    The result contains p (closed), or is the infinite triangle beyond a hull
    edge that p sees strictly: either way p is strictly inside its circle.
    The visibility walk terminates in a Delaunay triangulation.
    """
    cdef int k, e, a, b, came = -1
    cdef bint moved
    while True:
        if is_infinite(m, t):
            return t
        moved = False
        for k in range(3):
            e = 3 * t + k
            if e == came:
                continue
            a = m.tv[e]
            b = m.tv[nxt(e)]
            if orient2d(m.x[a], m.y[a], m.x[b], m.y[b], px, py) < 0:
                came = m.opp[e]
                t = came // 3
                moved = True
                break
        if not moved:
            return t


cdef inline void list_site(Mesh* m, int t, int s) noexcept nogil:
    m.next_site[s] = m.head[t]
    m.head[t] = s
    m.where[s] = t
