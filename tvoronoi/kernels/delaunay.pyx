"""Randomized incremental Delaunay triangulation: Bowyer-Watson cavities decided by exact predicates."""

import numpy as np

from libc.stdint cimport int32_t, int64_t, uint32_t
from libc.math cimport floor

from tvoronoi.kernels.predicates cimport orient2d, incircle

cdef enum:
    # status codes returned to the API layer
    OK = 0
    COLLINEAR = 1       # fewer than three non-collinear sites: no triangle exists
    # bits per coordinate of the Hilbert curve that orders each insertion round
    HILBERT_BITS = 16

STATUS_OK = OK
STATUS_COLLINEAR = COLLINEAR

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
    int32_t* stamp      # per triangle: 2i if in conflict with site i, 2i+1 if tested and not
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
    int n
    int inf
    int n_tri
    int last            # a recently created finite triangle: where walks start


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


cdef int locate(Mesh* m, int t, double px, double py) noexcept nogil:
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


cdef void list_site(Mesh* m, int t, int s) noexcept nogil:
    m.next_site[s] = m.head[t]
    m.head[t] = s
    m.where[s] = t


cdef void insert_site(Mesh* m, int i, int t0) noexcept nogil:
    """Insert site i, whose conflict region contains triangle t0.

    # the cavity: every triangle whose circumcircle strictly contains i,
    # found by a search over edges from t0 (the region is connected and
    # star-shaped from i); its boundary is a cycle of k + 2 edges for k
    # triangles, each of which is joined to i by a new triangle.
    """
    cdef double px = m.x[i], py = m.y[i]
    cdef int32_t conflict = 2 * i, tested = 2 * i + 1
    cdef int n_cav = 1, n_bnd = 0, j = 0, k, e, o, nt, t, q, a, b, T, T2, s, s_next
    cdef int pending = -1
    # degenerate case: a repeated point; the walk ends on a triangle that has it as a vertex
    if not is_infinite(m, t0):
        for k in range(3):
            a = m.tv[3 * t0 + k]
            if m.x[a] == px and m.y[a] == py:
                m.dup[i] = a
                if m.head != NULL:
                    m.where[i] = -1
                return
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
        m.vmap[a] = T
        m.bnd_twin[q] = T           # remember the slot for the linking pass
        if m.trace_new != NULL:
            m.trace_new[q] = T
        if a != m.inf and b != m.inf:
            m.last = T
    # link the fan: edge b->i of one new triangle is the twin of i->b of the next
    for q in range(n_bnd):
        T = m.bnd_twin[q]
        T2 = m.vmap[m.bnd_b[q]]
        m.opp[3 * T + 1] = 3 * T2 + 2
        m.opp[3 * T2 + 2] = 3 * T + 1

    # relist the waiting sites in the new triangles that hold them
    while pending != -1:
        s_next = m.next_site[pending]
        list_site(m, locate(m, m.last, m.x[pending], m.y[pending]), pending)
        pending = s_next


cdef int build(Mesh* m, int32_t* order, int stop_after) noexcept nogil:
    """Triangulate the sites in the given insertion order (modified: the first
    three become a non-degenerate triangle), stopping after stop_after sites
    when it is not negative. Returns a status code."""
    cdef int n = m.n, k = 1, a, b, c, tmp, q, t, s, end
    end = n if stop_after < 0 or stop_after > n else stop_after
    a = order[0]
    # degenerate case: leading repeats of the first site
    while k < n and m.x[order[k]] == m.x[a] and m.y[order[k]] == m.y[a]:
        k += 1
    if k == n:
        return COLLINEAR
    tmp = order[1]
    order[1] = order[k]
    order[k] = tmp
    b = order[1]
    k = 2
    # degenerate case: leading collinear sites; the first that breaks the line starts the mesh
    while k < n and orient2d(m.x[a], m.y[a], m.x[b], m.y[b], m.x[order[k]], m.y[order[k]]) == 0:
        k += 1
    if k == n:
        return COLLINEAR
    tmp = order[2]
    order[2] = order[k]
    order[k] = tmp
    c = order[2]
    if orient2d(m.x[a], m.y[a], m.x[b], m.y[b], m.x[c], m.y[c]) < 0:
        tmp = b
        b = c
        c = tmp

    # the first triangle and the three infinite triangles around it
    m.tv[0] = a; m.tv[1] = b; m.tv[2] = c
    m.tv[3] = b; m.tv[4] = a; m.tv[5] = m.inf
    m.tv[6] = c; m.tv[7] = b; m.tv[8] = m.inf
    m.tv[9] = a; m.tv[10] = c; m.tv[11] = m.inf
    m.opp[0] = 3; m.opp[3] = 0
    m.opp[1] = 6; m.opp[6] = 1
    m.opp[2] = 9; m.opp[9] = 2
    m.opp[4] = 11; m.opp[11] = 4
    m.opp[7] = 5; m.opp[5] = 7
    m.opp[10] = 8; m.opp[8] = 10
    m.n_tri = 4
    m.last = 0

    if m.head != NULL:
        m.where[order[0]] = -1
        m.where[order[1]] = -1
        m.where[order[2]] = -1
        for q in range(3, n):
            s = order[q]
            list_site(m, locate(m, 0, m.x[s], m.y[s]), s)
        for q in range(3, end):
            s = order[q]
            insert_site(m, s, m.where[s])
    else:
        for q in range(3, end):
            s = order[q]
            insert_site(m, s, locate(m, m.last, m.x[s], m.y[s]))
    return OK


def triangulate(const double[::1] xs, const double[::1] ys, bint conflict_lists=False,
                int stop_after=-1):
    """Delaunay triangulation of sites inserted in their given order.

    Give the sites in insertion order: numbering them that way keeps a walk's
    memory accesses local (a large speed-up on big inputs).

    Parameters
    ----------
    xs, ys : (n,) float64
        Site coordinates; repeated points are detected and left out.
    conflict_lists : bool
        Locate each site through conflict lists (the textbook variant, for a
        fully random order) instead of walking from the last new triangle.
    stop_after : int
        For the step trace: stop once this many sites are processed (-1: all).
        The result then also has a dict ``trace``: ``order`` (the insertion
        order used), ``cavity`` (the vertex triples of the triangles the last
        site destroyed) and ``fan`` (the triangles that replaced them).

    Returns
    -------
    status : int
        STATUS_OK, or STATUS_COLLINEAR when no three sites span a triangle.
    tv, opp : (3 * n_tri,) int32
        Triangle vertices (n stands for the vertex at infinity) and twin
        half-edges.
    dup : (n,) int32
        For a repeated point, the site it repeats; -1 otherwise.
    """
    cdef int n = xs.shape[0]
    cdef int32_t[::1] dup = np.full(n, -1, np.int32)
    cdef int32_t[::1] order = np.arange(n, dtype=np.int32)
    if n < 3:
        return STATUS_COLLINEAR, np.empty(0, np.int32), np.empty(0, np.int32), np.asarray(dup)
    cdef int max_tri = 2 * n - 2
    cdef int32_t[::1] tv = np.empty(3 * max_tri, np.int32)
    cdef int32_t[::1] opp = np.empty(3 * max_tri, np.int32)
    cdef int32_t[::1] stamp = np.full(max_tri, -1, np.int32)
    cdef int32_t[::1] vmap = np.empty(n + 1, np.int32)
    cdef int32_t[::1] cavity = np.empty(max_tri, np.int32)
    cdef int32_t[::1] bnd_a = np.empty(max_tri + 2, np.int32)
    cdef int32_t[::1] bnd_b = np.empty(max_tri + 2, np.int32)
    cdef int32_t[::1] bnd_twin = np.empty(max_tri + 2, np.int32)
    cdef int32_t[::1] head, next_site, where
    cdef Mesh m
    m.x = &xs[0]
    m.y = &ys[0]
    m.tv = &tv[0]
    m.opp = &opp[0]
    m.stamp = &stamp[0]
    m.vmap = &vmap[0]
    m.cavity = &cavity[0]
    m.bnd_a = &bnd_a[0]
    m.bnd_b = &bnd_b[0]
    m.bnd_twin = &bnd_twin[0]
    m.head = NULL
    m.next_site = NULL
    m.where = NULL
    if conflict_lists:
        head = np.full(max_tri, -1, np.int32)
        next_site = np.full(n, -1, np.int32)
        where = np.full(n, -1, np.int32)
        m.head = &head[0]
        m.next_site = &next_site[0]
        m.where = &where[0]
    m.dup = &dup[0]
    m.trace_cav = NULL
    m.trace_new = NULL
    m.trace_n_cav = 0
    m.trace_n_new = 0
    cdef int32_t[::1] trace_cav, trace_new
    if stop_after >= 0:
        trace_cav = np.empty(3 * max_tri, np.int32)
        trace_new = np.empty(max_tri + 2, np.int32)
        m.trace_cav = &trace_cav[0]
        m.trace_new = &trace_new[0]
    m.n = n
    m.inf = n
    m.n_tri = 0
    m.last = 0
    cdef int status
    with nogil:
        status = build(&m, &order[0], stop_after)
    if status != STATUS_OK:
        return status, np.empty(0, np.int32), np.empty(0, np.int32), np.asarray(dup)
    result = (status, np.asarray(tv)[:3 * m.n_tri], np.asarray(opp)[:3 * m.n_tri], np.asarray(dup))
    if stop_after >= 0:
        trace = {
            "order": np.asarray(order),
            "cavity": np.asarray(trace_cav)[:3 * m.trace_n_cav].reshape(-1, 3).copy(),
            "fan": np.asarray(trace_new)[:m.trace_n_new].copy(),
        }
        return result + (trace,)
    return result


cdef inline uint32_t hilbert_key(uint32_t x, uint32_t y, int bits) noexcept nogil:
    """Index of cell (x, y) along a Hilbert curve over a 2^bits grid."""
    cdef uint32_t side = (<uint32_t>1) << bits, s = side >> 1, rx, ry, d = 0, t
    while s > 0:
        rx = 1 if (x & s) else 0
        ry = 1 if (y & s) else 0
        d += s * s * ((3 * rx) ^ ry)
        # turn the quadrant so that the curve's pattern repeats inside it
        if ry == 0:
            if rx == 1:
                x = side - 1 - x
                y = side - 1 - y
            t = x
            x = y
            y = t
        s >>= 1
    return d


def brio_keys(const double[::1] xs, const double[::1] ys, const int64_t[::1] rank):
    """Sort keys of a biased randomized insertion order.

    A site of random rank r goes to round floor(log2(r + 1)) (rounds double in
    size); within a round, sites follow a Hilbert curve over their bounding box.

    Parameters
    ----------
    xs, ys : (n,) float64
    rank : (n,) int64, a random permutation of 0..n-1

    Returns
    -------
    keys : (n,) int64, to be argsorted.
    """
    cdef Py_ssize_t n = xs.shape[0], i
    cdef int64_t[::1] keys = np.empty(n, np.int64)
    if n == 0:
        return np.asarray(keys)
    cdef double xmin = xs[0], xmax = xs[0], ymin = ys[0], ymax = ys[0], scale, side
    cdef uint32_t cells = ((<uint32_t>1) << HILBERT_BITS) - 1, hx, hy
    cdef int64_t r, rnd
    with nogil:
        for i in range(n):
            xmin = min(xmin, xs[i]); xmax = max(xmax, xs[i])
            ymin = min(ymin, ys[i]); ymax = max(ymax, ys[i])
        side = max(xmax - xmin, ymax - ymin)
        scale = cells / side if side > 0 else 0.0
        for i in range(n):
            hx = <uint32_t>floor((xs[i] - xmin) * scale)
            hy = <uint32_t>floor((ys[i] - ymin) * scale)
            if hx > cells:
                hx = cells
            if hy > cells:
                hy = cells
            r = rank[i] + 1
            rnd = 0
            while r > 1:
                r >>= 1
                rnd += 1
            keys[i] = (rnd << 32) | <int64_t>hilbert_key(hx, hy, HILBERT_BITS)
    return np.asarray(keys)
