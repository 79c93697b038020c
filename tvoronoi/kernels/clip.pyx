"""Bounded cells: the Voronoi DCEL clipped to a box, as counter-clockwise rings."""

import numpy as np

from libc.stdint cimport int32_t, int64_t
from tvoronoi.kernels.cliplib cimport Box, make_box, on_box, clip_bisector, snap_inside, angular_ring
from tvoronoi.kernels.distance cimport closer

cdef enum:
    MAX_RING = 4096     # points of one clipped cell before it is sorted


def clip_cells(const double[::1] xs, const double[::1] ys, const double[:, ::1] vertices,
               const int32_t[::1] he_origin, const int32_t[::1] he_twin,
               const int32_t[::1] he_next, const int32_t[::1] he_face,
               const int32_t[::1] face_edge, const signed char[::1] active, box_tuple):
    """Clip every cell to the box (xmin, ymin, xmax, ymax).

    Each edge is clipped once, so neighbouring cells share bit-identical
    points; box corners go to the cell that owns them (the nearest site).

    Parameters
    ----------
    xs, ys : (n,) float64, the sites; vertices : (m, 2) float64
    he_* : (h,) int32, the Voronoi DCEL; face_edge : (n,) int32
    active : (n,) int8, 0 for a site without a cell of its own (a repeat)

    Returns
    -------
    points : (k, 2) float64 -- the m Voronoi vertices, then the new points
        on the box, then the four corners.
    offsets : (n + 1,) int64, ring : (K,) int32 -- cell i is
        points[ring[offsets[i]:offsets[i + 1]]], counter-clockwise, not
        closed; empty when the cell misses the box.
    """
    xmin, ymin, xmax, ymax = [float(side) for side in box_tuple]
    cdef Box box = make_box(xmin, ymin, xmax, ymax)
    cdef int n = xs.shape[0], m = vertices.shape[0], n_he = he_origin.shape[0]
    cdef int cap = m + 2 * n_he + 4
    cdef double[:, ::1] pts = np.empty((cap, 2), np.float64)
    cdef int32_t[::1] seg_start = np.full(n_he, -1, np.int32)
    cdef int32_t[::1] seg_end = np.full(n_he, -1, np.int32)
    cdef int64_t[::1] offsets = np.zeros(n + 1, np.int64)
    cdef int32_t[::1] ring = np.empty(2 * n_he + 4 * n, np.int32)
    cdef signed char[::1] inside = np.zeros(max(m, 1), np.int8)
    cdef int n_pts = m, corner0, h, tw, o, d, a, b, v, i, k, count, j
    cdef int64_t n_ring = 0
    cdef double bx, by, dx, dy, t0, t1, x, y
    cdef bint fast, owned
    cdef int buf[MAX_RING]
    cdef double ang[MAX_RING]
    cdef double px[MAX_RING]
    cdef double py[MAX_RING]
    cdef double corner_x[4]
    cdef double corner_y[4]
    corner_x[:] = [box.xmin, box.xmax, box.xmax, box.xmin]
    corner_y[:] = [box.ymin, box.ymin, box.ymax, box.ymax]

    with nogil:
        for v in range(m):
            # a vertex within rounding of the box counts as inside, put exactly on its edge,
            # so that no sliver of an edge (or a near-copy of the vertex) is left on the boundary
            x = vertices[v, 0]
            y = vertices[v, 1]
            inside[v] = snap_inside(&box, &x, &y)
            pts[v, 0] = x
            pts[v, 1] = y

        # clip each edge once, along the half-edge of smaller index
        for h in range(n_he):
            tw = he_twin[h]
            if tw < h:
                continue
            o = he_origin[h]
            d = he_origin[tw]
            if o >= 0 and d >= 0 and inside[o] and inside[d]:
                seg_start[h] = o
                seg_end[h] = d
                seg_start[tw] = d
                seg_end[tw] = o
                continue
            a = he_face[h]
            b = he_face[tw]
            if not clip_bisector(&box, xs[a], ys[a], xs[b], ys[b],
                                 pts[o, 0] if o >= 0 else 0.0, pts[o, 1] if o >= 0 else 0.0, o >= 0,
                                 pts[d, 0] if d >= 0 else 0.0, pts[d, 1] if d >= 0 else 0.0, d >= 0,
                                 &bx, &by, &dx, &dy, &t0, &t1):
                continue
            # an end inside the box is the vertex itself, shared with its other edges
            if o >= 0 and inside[o]:
                seg_start[h] = o
            else:
                x = bx + t0 * dx; y = by + t0 * dy
                on_box(&box, &x, &y)
                pts[n_pts, 0] = x; pts[n_pts, 1] = y
                seg_start[h] = n_pts
                n_pts += 1
            if d >= 0 and inside[d]:
                seg_end[h] = d
            else:
                x = bx + t1 * dx; y = by + t1 * dy
                on_box(&box, &x, &y)
                pts[n_pts, 0] = x; pts[n_pts, 1] = y
                seg_end[h] = n_pts
                n_pts += 1
            seg_start[tw] = seg_end[h]
            seg_end[tw] = seg_start[h]

        corner0 = n_pts
        for k in range(4):
            pts[corner0 + k, 0] = corner_x[k]
            pts[corner0 + k, 1] = corner_y[k]
        n_pts += 4

        for i in range(n):
            offsets[i] = n_ring
            if not active[i]:
                continue
            h = face_edge[i]
            # an interior cell: its own vertices, already in order
            fast = h >= 0
            if fast:
                while True:
                    o = he_origin[h]
                    if o < 0 or not inside[o]:
                        fast = False
                        break
                    h = he_next[h]
                    if h == face_edge[i]:
                        break
            if fast:
                while True:
                    ring[n_ring] = he_origin[h]
                    n_ring += 1
                    h = he_next[h]
                    if h == face_edge[i]:
                        break
                continue

            # a cell that meets the box edge: the clipped edge points and the
            # corners it owns, in angular order about their centroid
            count = 0
            h = face_edge[i]
            while h >= 0 and count + 2 <= MAX_RING - 4:
                if seg_start[h] >= 0:
                    buf[count] = seg_start[h]
                    buf[count + 1] = seg_end[h]
                    count += 2
                h = he_next[h]
                if h == face_edge[i]:
                    break
            for k in range(4):
                # the corner is the cell's if no neighbour's site is strictly nearer (exact)
                owned = True
                h = face_edge[i]
                while h >= 0:
                    j = he_face[he_twin[h]]
                    if closer(corner_x[k], corner_y[k], xs[i], ys[i], xs[j], ys[j]) > 0:
                        owned = False
                        break
                    h = he_next[h]
                    if h == face_edge[i]:
                        break
                if owned:
                    buf[count] = corner0 + k
                    count += 1
            if count < 3:
                continue
            for k in range(count):
                px[k] = pts[buf[k], 0]
                py[k] = pts[buf[k], 1]
            j = angular_ring(px, py, buf, ang, count)
            if j < 3:
                continue
            for k in range(j):
                ring[n_ring] = buf[k]
                n_ring += 1
        offsets[n] = n_ring

    return (np.asarray(pts)[:n_pts].copy(), np.asarray(offsets),
            np.asarray(ring)[:n_ring].copy())
