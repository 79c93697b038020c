# Filling a cavity: the fan of new triangles joining its boundary to the new site, linked to each other
# and to the outside; and insert_site, the whole Bowyer-Watson step. Inline, compiled where cimported.

from tvoronoi.kernels.mesh cimport Mesh, is_infinite
from tvoronoi.kernels.location cimport locate, list_site
from tvoronoi.kernels.cavity cimport find_cavity


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
