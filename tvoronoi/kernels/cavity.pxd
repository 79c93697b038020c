# The conflict region (cavity) of a new site: every triangle whose circumcircle strictly holds it,
# decided by the exact in-circle test; inline, compiled where cimported.

from libc.stdint cimport int32_t

from tvoronoi.kernels.predicates cimport orient2d, incircle
from tvoronoi.kernels.mesh cimport Mesh, is_infinite, nxt, strictly_between
from tvoronoi.kernels.prefetch cimport prefetch


cdef inline bint in_conflict(Mesh* m, int t, double px, double py) noexcept nogil:
    """Site p lies strictly inside the circumcircle of t (its cavity takes t).

    For an infinite triangle (u, w, inf) the 'circle' is the open half-plane
    left of u->w (outside the hull), plus the open segment uw itself.
    """
    cdef int a = m.tv[3 * t], b = m.tv[3 * t + 1], c = m.tv[3 * t + 2]
    cdef int u, w, o
    if a == m.inf:
        u = b
        w = c
    elif b == m.inf:
        u = c
        w = a
    elif c == m.inf:
        u = a
        w = b
    else:
        return incircle(m.x[a], m.y[a], m.x[b], m.y[b], m.x[c], m.y[c], px, py) > 0
    o = orient2d(m.x[u], m.y[u], m.x[w], m.y[w], px, py)
    if o > 0:
        return True
    # degenerate case: p on the line of a hull edge
    return o == 0 and strictly_between(m, u, w, px, py)


cdef inline int cross_edge(Mesh* m, int e, double px, double py, int n_cav, int n_bnd) noexcept nogil:
    # the triangle across half-edge e of a cavity triangle joins the cavity (returns 1), or e is a
    # boundary edge (0); written as both, at places n_cav and n_bnd (the compiler keeps this out of
    # line: its three calls inlined, or one call in a loop, measured slower)
    cdef int o = m.opp[e]
    cdef int nt = <int> (<unsigned> o // 3)     # (o >= 0: the unsigned division is shorter)
    prefetch(&m.opp[3 * nt])
    m.cavity[n_cav] = nt
    m.cav_from[n_cav] = o
    m.bnd_a[n_bnd] = m.tv[e]
    m.bnd_b[n_bnd] = m.tv[nxt(e)]
    m.bnd_twin[n_bnd] = o
    return in_conflict(m, nt, px, py)


cdef inline bint find_cavity(Mesh* m, int i, int t0) noexcept nogil:
    """The conflict region of site i, which contains triangle t0; False for a repeated point.

    # the cavity: every triangle whose circumcircle strictly contains i,
    # found by a search over edges from t0 (the region is connected and
    # star-shaped from i); its boundary is a cycle of k + 2 edges for k
    # triangles (m.cavity, m.bnd_a, m.bnd_b, m.bnd_twin; m.n_cav, m.n_bnd)
    """
    cdef double px = m.x[i], py = m.y[i]
    cdef int n_cav = 1, n_bnd = 0, j, k, t, a, came, inside
    # degenerate case: a repeated point; the walk ends on a triangle that has it as a vertex
    if not is_infinite(m, t0):
        for k in range(3):
            a = m.tv[3 * t0 + k]
            if m.x[a] == px and m.y[a] == py:
                m.dup[i] = a
                if m.head != NULL:
                    m.where[i] = -1
                return False
    # The cavity's triangles form a tree across their shared edges: every vertex of a cavity triangle
    # stays a vertex of the triangulation, so it lies on the cavity's boundary and no cavity triangle is
    # reached twice. The search skips only the edge back to the triangle it came from; a triangle
    # outside that touches the cavity along two edges is tested twice, with the same exact answer.
    # Which edges cross into the cavity is random to a branch predictor, so each edge is written both
    # as the next cavity triangle and as the next boundary edge, and the verdict advances one of the
    # two counts (the write past the end is overwritten or never read; the arrays have room for it:
    # a cavity never holds every triangle). The first triangle's three edges, then two of each next
    # one's (those other than the edge it was reached by, in the order 0, 1, 2).
    m.cavity[0] = t0
    for k in range(3):
        inside = cross_edge(m, 3 * t0 + k, px, py, n_cav, n_bnd)
        n_cav += inside
        n_bnd += 1 - inside
    j = 1
    while j < n_cav:
        t = m.cavity[j]
        came = m.cav_from[j] - 3 * t
        j += 1
        inside = cross_edge(m, 3 * t + (came == 0), px, py, n_cav, n_bnd)
        n_cav += inside
        n_bnd += 1 - inside
        inside = cross_edge(m, 3 * t + 2 - (came == 2), px, py, n_cav, n_bnd)
        n_cav += inside
        n_bnd += 1 - inside
    m.n_cav = n_cav
    m.n_bnd = n_bnd
    return True
