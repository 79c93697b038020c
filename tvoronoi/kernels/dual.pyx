"""The Voronoi diagram as a half-edge structure (DCEL), built as the dual of a Delaunay triangulation."""

import numpy as np

from libc.stdint cimport int32_t

from tvoronoi.kernels.construct cimport circumcentre
from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.predicates cimport incircle
from tvoronoi.kernels.mesh cimport nxt, prv

# Layout of the Voronoi DCEL (struct of arrays, -1 for "at infinity"):
#   he_origin[h]  Voronoi vertex h starts from, -1 if h comes from infinity
#   he_twin[h]    the same edge seen from the neighbouring cell
#   he_next[h], he_prev[h]  the cycle around the cell, counter-clockwise;
#                 an unbounded cell's cycle closes through infinity: the edge
#                 that runs off to infinity is followed by the one coming back
#   he_face[h]    the site whose cell h bounds
# An edge lies on the bisector of he_face[h] and he_face[he_twin[h]].


cdef int find(int32_t* parent, int t) noexcept nogil:
    cdef int root = t, up
    while parent[root] != root:
        root = parent[root]
    while parent[t] != root:     # path compression
        up = parent[t]
        parent[t] = root
        t = up
    return root


def voronoi_from_delaunay(const double[::1] xs, const double[::1] ys,
                          const int32_t[::1] tv, const int32_t[::1] opp, int exponent=0):
    """Voronoi DCEL of n distinct sites from their Delaunay triangulation.

    Triangles whose circumcircles coincide (cocircular sites) share one
    Voronoi vertex, and the zero-length edges between them are not emitted.

    Parameters
    ----------
    xs, ys : (n,) float64, the sites.
    tv, opp : (3 * n_tri,) int32, the triangulation of incremental.triangulate or fortune.sweep
        (vertex n is the vertex at infinity).
    exponent : int, the sites are in a unit 2^-exponent of the user's: vertices are
        returned in the user's unit, each coordinate correctly rounded.

    Returns
    -------
    dict of arrays: vertices (m, 2) float64; he_origin, he_twin, he_next,
    he_prev, he_face (h,) int32; face_edge (n,) int32 (one half-edge of each
    cell); triangles (k, 3) int32, the finite Delaunay triangles.
    """
    cdef int n = xs.shape[0], inf = n
    cdef int n_he_d = tv.shape[0], n_tri = n_he_d // 3
    cdef int32_t[::1] parent = np.empty(n_tri, np.int32)
    cdef int32_t[::1] tri_vertex = np.full(n_tri, -1, np.int32)
    cdef int32_t[::1] group_tri = np.full(n_tri, -1, np.int32)
    cdef int32_t[::1] vor = np.full(n_he_d, -1, np.int32)      # Delaunay half-edge -> Voronoi half-edge
    cdef int32_t[::1] he_origin = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] he_twin = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] he_next = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] he_prev = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] he_face = np.empty(n_he_d, np.int32)
    cdef int32_t[::1] dual_of = np.empty(n_he_d, np.int32)     # Voronoi half-edge -> Delaunay half-edge
    cdef int32_t[::1] face_edge = np.full(n, -1, np.int32)
    cdef int32_t[::1] finite = np.empty(n_tri, np.int32)
    cdef double[:, ::1] vertices
    cdef int t, t2, e, o, a, b, c, d, r, m = 0, h = 0, n_finite = 0, f, g, merges = 0
    cdef double vx, vy

    with nogil:
        # merge the triangles of each cocircular group into one Voronoi vertex
        for t in range(n_tri):
            parent[t] = t
            if tv[3 * t] != inf and tv[3 * t + 1] != inf and tv[3 * t + 2] != inf:
                finite[n_finite] = t
                n_finite += 1
        for f in range(n_finite):
            if (f & POLL_MASK) == 0:
                poll_signals()
            t = finite[f]
            for e in range(3 * t, 3 * t + 3):
                o = opp[e]
                t2 = o // 3
                if t2 < t:
                    continue
                d = tv[prv(o)]
                if d == inf:
                    continue
                a = tv[3 * t]; b = tv[3 * t + 1]; c = tv[3 * t + 2]
                # degenerate case: four cocircular sites, a zero-length Voronoi edge
                if incircle(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], xs[d], ys[d]) == 0:
                    r = find(&parent[0], t)
                    g = find(&parent[0], t2)
                    if r != g:
                        parent[g] = r
                        merges += 1
        # each group's vertex: the circumcentre of one of its triangles (all give the same exact
        # point, hence the same correctly rounded one); with no cocircular sites, one per triangle
        if merges == 0:
            m = n_finite
        for f in range(n_finite if merges > 0 else 0):
            t = finite[f]
            r = find(&parent[0], t)
            if tri_vertex[r] == -1:
                tri_vertex[r] = m
                m += 1
                group_tri[r] = t
    vertices = np.empty((m, 2), np.float64)
    with nogil:
        for f in range(n_finite):
            if (f & POLL_MASK) == 0:
                poll_signals()
            t = finite[f]
            if merges == 0:
                r = t
                tri_vertex[t] = f
            else:
                r = find(&parent[0], t)
                tri_vertex[t] = tri_vertex[r]
                if group_tri[r] != t:
                    continue
            a = tv[3 * t]; b = tv[3 * t + 1]; c = tv[3 * t + 2]
            circumcentre(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], exponent, &vx, &vy)
            vertices[tri_vertex[r], 0] = vx
            vertices[tri_vertex[r], 1] = vy

        # one Voronoi half-edge per Delaunay half-edge between two sites,
        # unless both sides share a vertex (a zero-length edge)
        for e in range(n_he_d):
            a = tv[e]
            b = tv[nxt(e)]
            if a == inf or b == inf:
                continue
            if tri_vertex[e // 3] != -1 and tri_vertex[e // 3] == tri_vertex[opp[e] // 3]:
                continue
            vor[e] = h
            dual_of[h] = e
            # the cell of a is on the left of a->b's dual: it runs from the
            # triangle right of a->b to the triangle left of it
            he_origin[h] = tri_vertex[opp[e] // 3]
            he_face[h] = a
            face_edge[a] = h
            h += 1
        for g in range(h):
            e = dual_of[g]
            he_twin[g] = vor[opp[e]]
            # the next edge counter-clockwise around site tv[e]
            e = opp[prv(e)]
            while vor[e] == -1:
                e = opp[prv(e)]
            he_next[g] = vor[e]
            he_prev[vor[e]] = g

    tri = np.asarray(tv).reshape(-1, 3)[np.asarray(finite)[:n_finite]]
    return {
        "vertices": np.asarray(vertices),
        "he_origin": np.asarray(he_origin)[:h].copy(),
        "he_twin": np.asarray(he_twin)[:h].copy(),
        "he_next": np.asarray(he_next)[:h].copy(),
        "he_prev": np.asarray(he_prev)[:h].copy(),
        "he_face": np.asarray(he_face)[:h].copy(),
        "face_edge": np.asarray(face_edge),
        "triangles": np.ascontiguousarray(tri, dtype=np.int32),
    }


def circumcentres(const double[::1] xs, const double[::1] ys, const int32_t[:, ::1] tri, int e=0):
    """Correctly rounded circumcentres (k, 2) of triangles tri (k, 3) of sites xs, ys, times 2^e."""
    cdef Py_ssize_t k, n_tri = tri.shape[0]
    cdef double[:, ::1] out = np.empty((n_tri, 2), np.float64)
    cdef int a, b, c
    with nogil:
        for k in range(n_tri):
            a = tri[k, 0]; b = tri[k, 1]; c = tri[k, 2]
            circumcentre(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], e, &out[k, 0], &out[k, 1])
    return np.asarray(out)


def voronoi_collinear(const double[::1] xs, const double[::1] ys):
    """Voronoi DCEL of n >= 1 distinct collinear sites: parallel strips.

    Sites must be given in order along their line. Each pair of consecutive
    sites is split by a whole bisector line (both ends at infinity), so the
    diagram has no vertex and every cell is a strip (a half-plane at the ends).

    Returns the same dict as voronoi_from_delaunay (no triangles).
    """
    cdef int n = xs.shape[0], k, n_he = 2 * max(n - 1, 0)
    cdef int32_t[::1] he_origin = np.full(n_he, -1, np.int32)
    cdef int32_t[::1] he_twin = np.empty(n_he, np.int32)
    cdef int32_t[::1] he_next = np.empty(n_he, np.int32)
    cdef int32_t[::1] he_prev = np.empty(n_he, np.int32)
    cdef int32_t[::1] he_face = np.empty(n_he, np.int32)
    cdef int32_t[::1] face_edge = np.full(n, -1, np.int32)
    # half-edge 2k bounds site k (bisector of k, k+1); half-edge 2k+1 bounds site k+1
    for k in range(n - 1):
        he_twin[2 * k] = 2 * k + 1
        he_twin[2 * k + 1] = 2 * k
        he_face[2 * k] = k
        he_face[2 * k + 1] = k + 1
        face_edge[k] = 2 * k
        face_edge[k + 1] = 2 * k + 1
    for k in range(n):
        # a middle strip: its two bounding lines follow each other through infinity
        if 0 < k < n - 1:
            he_next[2 * k] = 2 * k - 1
            he_prev[2 * k] = 2 * k - 1
            he_next[2 * k - 1] = 2 * k
            he_prev[2 * k - 1] = 2 * k
        elif n > 1 and k == 0:
            he_next[0] = 0
            he_prev[0] = 0
        elif n > 1:
            he_next[2 * k - 1] = 2 * k - 1
            he_prev[2 * k - 1] = 2 * k - 1
    return {
        "vertices": np.empty((0, 2), np.float64),
        "he_origin": np.asarray(he_origin),
        "he_twin": np.asarray(he_twin),
        "he_next": np.asarray(he_next),
        "he_prev": np.asarray(he_prev),
        "he_face": np.asarray(he_face),
        "face_edge": np.asarray(face_edge),
        "triangles": np.empty((0, 3), np.int32),
    }
