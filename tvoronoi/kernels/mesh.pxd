# The triangulation shared by the incremental engine and the dynamic diagrams, with its
# Bowyer-Watson insertion; inline functions compiled into each kernel that cimports them.

from libc.stdint cimport int32_t

from tvoronoi.kernels.predicates cimport orient2d, incircle

# Layout of a triangulation (struct of arrays, like delaunator):
#   triangle t owns half-edges 3t, 3t+1, 3t+2, counter-clockwise;
#   tv[e]  the vertex half-edge e starts from (it ends at tv[nxt(e)]),
#   opp[e] the twin half-edge, in the neighbouring triangle.
# The hull is closed by one vertex at infinity, numbered n (the site count):
# every hull edge u->w (interior on its left) has an "infinite triangle"
# (w, u, inf) on its other side, so that every half-edge has a twin and
# insertion outside the hull is the same cavity operation as inside.
# A triangulation of n sites plus the vertex at infinity has 2n - 2 triangles.


cdef inline int nxt(int e) noexcept nogil:
    return e - 2 if e % 3 == 2 else e + 1


cdef inline int prv(int e) noexcept nogil:
    return e + 2 if e % 3 == 0 else e - 1


cdef struct Mesh:
    const double* x
    const double* y
    int32_t* tv
    int32_t* opp
    int32_t* stamp      # per triangle: 2 * epoch if in the current cavity, 2 * epoch + 1 if tested and not
    int32_t* vmap       # per vertex: the new triangle whose cavity-boundary edge starts there
    int32_t* cavity     # triangles of the current cavity
    int32_t* bnd_a      # cavity boundary edges a->b and the outside twin half-edge
    int32_t* bnd_b
    int32_t* bnd_twin
    int32_t* head       # conflict lists (textbook order): first waiting site per triangle
    int32_t* next_site  #   and the next one in the same list
    int32_t* where      #   and the triangle each waiting site is listed under (-1 once inserted)
    int32_t* dup        # per site: the earlier site at the same place, or -1
    int32_t* trace_cav  # step trace only (else NULL): the last cavity's triangles, as vertex triples
    int trace_n_cav
    int32_t* trace_new  #   and the slots of the triangles that replaced them
    int trace_n_new
    # dynamic diagrams only (else NULL): free triangle slots, one half-edge out of
    # each vertex, and the sites whose cells the last insertion changed
    int32_t* free_tri
    int n_free
    int32_t* vedge
    int32_t* changed
    int n_changed
    int n_finite        # finite triangles (kept up to date only where vedge is kept)
    int n
    int inf
    int vmap_inf        # vmap's entry for the vertex at infinity
    int n_tri
    int last            # a recently created finite triangle: where walks start
    int epoch           # counts insertions: stamps of older cavities never match
    int n_cav           # the last cavity found: its triangles and boundary edges
    int n_bnd


cdef inline bint is_infinite(Mesh* m, int t) noexcept nogil:
    return m.tv[3 * t] == m.inf or m.tv[3 * t + 1] == m.inf or m.tv[3 * t + 2] == m.inf


cdef inline bint strictly_between(Mesh* m, int u, int w, double px, double py) noexcept nogil:
    """p, already known collinear with u and w, lies strictly inside segment uw."""
    cdef double ux = m.x[u], uy = m.y[u], wx = m.x[w], wy = m.y[w]
    if ux != wx:
        return (ux < px < wx) or (wx < px < ux)
    return (uy < py < wy) or (wy < py < uy)


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


cdef inline bint find_cavity(Mesh* m, int i, int t0) noexcept nogil:
    """The conflict region of site i, which contains triangle t0; False for a repeated point.

    # the cavity: every triangle whose circumcircle strictly contains i,
    # found by a search over edges from t0 (the region is connected and
    # star-shaped from i); its boundary is a cycle of k + 2 edges for k
    # triangles (m.cavity, m.bnd_a, m.bnd_b, m.bnd_twin; m.n_cav, m.n_bnd)
    """
    cdef double px = m.x[i], py = m.y[i]
    cdef int32_t conflict, tested
    cdef int n_cav = 1, n_bnd = 0, j = 0, k, e, o, nt, t, a
    # degenerate case: a repeated point; the walk ends on a triangle that has it as a vertex
    if not is_infinite(m, t0):
        for k in range(3):
            a = m.tv[3 * t0 + k]
            if m.x[a] == px and m.y[a] == py:
                m.dup[i] = a
                if m.head != NULL:
                    m.where[i] = -1
                return False
    m.epoch += 1
    conflict = 2 * m.epoch
    tested = conflict + 1
    m.stamp[t0] = conflict
    m.cavity[0] = t0
    while j < n_cav:
        t = m.cavity[j]
        j += 1
        for k in range(3):
            e = 3 * t + k
            o = m.opp[e]
            nt = o // 3
            if m.stamp[nt] == conflict:
                continue
            if m.stamp[nt] != tested:
                if in_conflict(m, nt, px, py):
                    m.stamp[nt] = conflict
                    m.cavity[n_cav] = nt
                    n_cav += 1
                    continue
                m.stamp[nt] = tested
            m.bnd_a[n_bnd] = m.tv[e]
            m.bnd_b[n_bnd] = m.tv[nxt(e)]
            m.bnd_twin[n_bnd] = o
            n_bnd += 1
    m.n_cav = n_cav
    m.n_bnd = n_bnd
    return True


cdef inline void fill_cavity(Mesh* m, int i) noexcept nogil:
    """Replace the cavity just found by the fan of triangles joining its boundary to site i."""
    cdef int n_cav = m.n_cav, n_bnd = m.n_bnd, q, t, s, s_next, a, b, o, T, T2
    cdef int pending = -1

    # take the waiting sites of the doomed triangles (textbook order only)
    if m.head != NULL:
        for q in range(n_cav):
            t = m.cavity[q]
            s = m.head[t]
            while s != -1:
                s_next = m.next_site[s]
                if s != i and m.where[s] != -1:
                    m.next_site[s] = pending
                    pending = s
                s = s_next
            m.head[t] = -1
        m.where[i] = -1

    if m.vedge != NULL:
        for q in range(n_cav):
            if not is_infinite(m, m.cavity[q]):
                m.n_finite -= 1
    if m.trace_cav != NULL:
        for q in range(n_cav):
            t = m.cavity[q]
            m.trace_cav[3 * q] = m.tv[3 * t]
            m.trace_cav[3 * q + 1] = m.tv[3 * t + 1]
            m.trace_cav[3 * q + 2] = m.tv[3 * t + 2]
        m.trace_n_cav = n_cav
        m.trace_n_new = n_bnd

    # fan the boundary to i, reusing the cavity's slots first
    for q in range(n_bnd):
        if q < n_cav:
            T = m.cavity[q]
        elif m.free_tri != NULL and m.n_free > 0:
            m.n_free -= 1
            T = m.free_tri[m.n_free]
        else:
            T = m.n_tri
            m.n_tri += 1
        a = m.bnd_a[q]
        b = m.bnd_b[q]
        o = m.bnd_twin[q]
        m.tv[3 * T] = a
        m.tv[3 * T + 1] = b
        m.tv[3 * T + 2] = i
        m.opp[3 * T] = o
        m.opp[o] = 3 * T
        if a == m.inf:
            m.vmap_inf = T
        else:
            m.vmap[a] = T
        if m.vedge != NULL and a != m.inf:
            if b != m.inf:
                m.n_finite += 1
            m.vedge[a] = 3 * T
            m.changed[m.n_changed] = a
            m.n_changed += 1
        m.bnd_twin[q] = T           # remember the slot for the linking pass
        if m.trace_new != NULL:
            m.trace_new[q] = T
        if a != m.inf and b != m.inf:
            m.last = T
    # link the fan: edge b->i of one new triangle is the twin of i->b of the next
    if m.vedge != NULL:
        m.vedge[i] = 3 * m.bnd_twin[0] + 2
    for q in range(n_bnd):
        T = m.bnd_twin[q]
        T2 = m.vmap_inf if m.bnd_b[q] == m.inf else m.vmap[m.bnd_b[q]]
        m.opp[3 * T + 1] = 3 * T2 + 2
        m.opp[3 * T2 + 2] = 3 * T + 1

    # relist the waiting sites in the new triangles that hold them
    while pending != -1:
        s_next = m.next_site[pending]
        list_site(m, locate(m, m.last, m.x[pending], m.y[pending]), pending)
        pending = s_next




cdef inline void insert_site(Mesh* m, int i, int t0) noexcept nogil:
    """Insert site i, whose conflict region contains triangle t0 (Bowyer-Watson)."""
    if find_cavity(m, i, t0):
        fill_cavity(m, i)
