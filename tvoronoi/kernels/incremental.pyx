"""The randomized incremental engine: Delaunay triangulation by Bowyer-Watson insertion, every decision exact.

One insertion = locate (location.pxd), find the cavity (cavity.pxd), fill it (fill.pxd); the mesh layout is
mesh.pxd, and dual.pyx turns the triangles into the Voronoi DCEL.
"""

import numpy as np

from libc.stdint cimport int32_t

from tvoronoi.kernels.predicates cimport orient2d
from tvoronoi.kernels.mesh cimport Mesh
from tvoronoi.kernels.location cimport locate, list_site
from tvoronoi.kernels.fill cimport insert_site
from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.populate cimport populate, fill_int32

cdef enum:
    # status codes returned to the API layer
    OK = 0
    COLLINEAR = 1       # fewer than three non-collinear sites: no triangle exists

STATUS_OK = OK
STATUS_COLLINEAR = COLLINEAR

cdef int build(Mesh* m, int32_t* order, int stop_after) except -1 nogil:
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
            if (q & POLL_MASK) == 0:
                poll_signals()
            s = order[q]
            insert_site(m, s, m.where[s])
    else:
        for q in range(3, end):
            if (q & POLL_MASK) == 0:
                poll_signals()
            s = order[q]
            insert_site(m, s, locate(m, m.last, m.x[s], m.y[s]))
    return OK


def permutation_copy(const int32_t[::1] order, int n):
    """A copy of order, checked to be a permutation of 0 .. n - 1 (ValueError naming the first value
    that is out of range or repeated)."""
    if order.shape[0] != n:
        raise ValueError(f"an insertion order of {order.shape[0]} sites for {n} sites")
    copy = np.empty(n, np.int32)
    seen = np.zeros(n, np.int8)
    cdef int32_t[::1] out = copy
    cdef signed char[::1] met = seen
    cdef int k, v, bad = -1
    with nogil:
        for k in range(n):
            v = order[k]
            if v < 0 or v >= n or met[v]:
                bad = k
                break
            met[v] = 1
            out[k] = v
    if bad >= 0:
        raise ValueError(f"insertion order: {order[bad]} at place {bad} is out of range or repeated")
    return copy


def triangulate(const double[::1] xs, const double[::1] ys, bint conflict_lists=False,
                int stop_after=-1, const int32_t[::1] order=None):
    """Delaunay triangulation of sites inserted in their given order.

    Give the sites in insertion order, or numbered along a space-filling
    curve with ``order``: either way a walk's memory accesses stay local (a
    large speed-up on big inputs).

    Parameters
    ----------
    xs, ys : (n,) float64
        Site coordinates; repeated points are detected and left out.
    conflict_lists : bool
        Locate each site through conflict lists (the textbook variant, for a
        fully random order) instead of walking from the last new triangle.
    stop_after : int
        For the step trace: stop once this many sites are processed (-1: all).
    order : (n,) int32, optional
        Insert site order[k] k-th (a permutation of 0 .. n - 1, as
        order.brio_order(..., along_curve=True) gives for sites numbered along
        its curve); by default site k k-th.
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
    cdef int32_t[::1] dup = np.empty(n, np.int32)
    if n > 0:
        with nogil:
            fill_int32(&dup[0], n, -1)
    # (a copy: build reorders its first sites)
    cdef int32_t[::1] ins = np.arange(n, dtype=np.int32) if order is None else permutation_copy(order, n)
    if n < 3:
        return STATUS_COLLINEAR, np.empty(0, np.int32), np.empty(0, np.int32), np.asarray(dup)
    cdef int max_tri = 2 * n - 2
    cdef int32_t[::1] tv = np.empty(3 * max_tri, np.int32)
    cdef int32_t[::1] opp = np.empty(3 * max_tri, np.int32)
    cdef int32_t[::1] vmap = np.empty(n + 1, np.int32)
    cdef int32_t[::1] cavity = np.empty(max_tri, np.int32)
    cdef int32_t[::1] cav_from = np.empty(max_tri, np.int32)
    cdef int32_t[::1] bnd_a = np.empty(max_tri + 2, np.int32)
    cdef int32_t[::1] bnd_b = np.empty(max_tri + 2, np.int32)
    cdef int32_t[::1] bnd_twin = np.empty(max_tri + 2, np.int32)
    cdef int32_t[::1] head, next_site, where
    cdef Mesh m
    m.x = &xs[0]
    m.y = &ys[0]
    m.tv = &tv[0]
    m.opp = &opp[0]
    m.vmap = &vmap[0]
    m.cavity = &cavity[0]
    m.cav_from = &cav_from[0]
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
    m.free_tri = NULL
    m.n_free = 0
    m.vedge = NULL
    m.changed = NULL
    m.n_changed = 0
    m.n = n
    m.inf = n
    m.n_tri = 0
    m.last = 0
    cdef int status
    with nogil:
        # the mesh grows to 2 n - 2 triangles less the hull's: its arrays are written (nearly) whole,
        # faulted in by runs of pages
        populate(&tv[0], 3 * max_tri * sizeof(int32_t))
        populate(&opp[0], 3 * max_tri * sizeof(int32_t))
        status = build(&m, &ins[0], stop_after)
    if status != STATUS_OK:
        return status, np.empty(0, np.int32), np.empty(0, np.int32), np.asarray(dup)
    result = (status, np.asarray(tv)[:3 * m.n_tri], np.asarray(opp)[:3 * m.n_tri], np.asarray(dup))
    if stop_after >= 0:
        trace = {
            "order": np.asarray(ins),
            "cavity": np.asarray(trace_cav)[:3 * m.trace_n_cav].reshape(-1, 3).copy(),
            "fan": np.asarray(trace_new)[:m.trace_n_new].copy(),
        }
        return result + (trace,)
    return result

