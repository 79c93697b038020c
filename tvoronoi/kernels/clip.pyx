"""Bounded cells: the Voronoi DCEL clipped to a box, as counter-clockwise rings."""

import numpy as np

from libc.stdint cimport int32_t, int64_t
from libc.math cimport atan2, fabs, hypot, INFINITY

from tvoronoi.kernels.distance cimport closer

# A clipped point closer than this fraction of the box size to a box corner
# becomes that corner, so that the corner is not emitted twice by rounding.
cdef double CORNER_SNAP = 1e-12

cdef enum:
    MAX_RING = 4096     # points of one clipped cell before it is sorted


cdef struct Box:
    double xmin, ymin, xmax, ymax, snap


cdef inline bint clip_param(double p, double q, double* t0, double* t1) noexcept nogil:
    """One Liang-Barsky boundary: keep t where p * t <= q. False if nothing is left."""
    cdef double r
    if p == 0.0:
        return q >= 0.0
    r = q / p
    if p < 0.0:
        if r > t1[0]:
            return False
        if r > t0[0]:
            t0[0] = r
    else:
        if r < t0[0]:
            return False
        if r < t1[0]:
            t1[0] = r
    return True


cdef inline void on_box(Box* box, double* x, double* y) noexcept nogil:
    """Put a point exactly on or in the box: clamp, then snap each coordinate within rounding of a side onto it."""
    if x[0] < box.xmin: x[0] = box.xmin
    if x[0] > box.xmax: x[0] = box.xmax
    if y[0] < box.ymin: y[0] = box.ymin
    if y[0] > box.ymax: y[0] = box.ymax
    if fabs(x[0] - box.xmin) <= box.snap: x[0] = box.xmin
    if fabs(x[0] - box.xmax) <= box.snap: x[0] = box.xmax
    if fabs(y[0] - box.ymin) <= box.snap: y[0] = box.ymin
    if fabs(y[0] - box.ymax) <= box.snap: y[0] = box.ymax


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
    cdef Box box
    box.xmin, box.ymin, box.xmax, box.ymax = [float(side) for side in box_tuple]
    box.snap = CORNER_SNAP * max(box.xmax - box.xmin, box.ymax - box.ymin)
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
    cdef double bx, by, dx, dy, norm, t0, t1, lo, hi, x, y, cxm, cym, key
    cdef bint fast, owned
    cdef int buf[MAX_RING]
    cdef double ang[MAX_RING]
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
            inside[v] = (box.xmin - box.snap <= x <= box.xmax + box.snap
                         and box.ymin - box.snap <= y <= box.ymax + box.snap)
            if inside[v]:
                on_box(&box, &x, &y)
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
            # the edge as a stretch of the bisector M + t D, M the sites' midpoint
            # and D along the bisector, counter-clockwise about site a: points
            # computed from M keep their precision even when a far-off vertex
            # (of nearly collinear sites) ends the edge
            bx = 0.5 * (xs[a] + xs[b]); by = 0.5 * (ys[a] + ys[b])
            # (a unit direction: t is then a length, and nothing is squared that could underflow
            # for sites that are very close)
            dx = -(ys[b] - ys[a])
            dy = xs[b] - xs[a]
            norm = hypot(dx, dy)
            dx /= norm
            dy /= norm
            lo = -INFINITY
            hi = INFINITY
            if o >= 0:
                lo = (pts[o, 0] - bx) * dx + (pts[o, 1] - by) * dy
            if d >= 0:
                hi = (pts[d, 0] - bx) * dx + (pts[d, 1] - by) * dy
            t0 = lo
            t1 = hi
            if not (clip_param(-dx, bx - box.xmin, &t0, &t1)
                    and clip_param(dx, box.xmax - bx, &t0, &t1)
                    and clip_param(-dy, by - box.ymin, &t0, &t1)
                    and clip_param(dy, box.ymax - by, &t0, &t1)):
                continue
            if t1 - t0 <= box.snap:
                continue          # the edge only touches the box (up to rounding)
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
            cxm = 0.0
            cym = 0.0
            for k in range(count):
                cxm += pts[buf[k], 0]
                cym += pts[buf[k], 1]
            cxm /= count
            cym /= count
            for k in range(count):
                ang[k] = atan2(pts[buf[k], 1] - cym, pts[buf[k], 0] - cxm)
            # insertion sort: a cell has a handful of points
            for k in range(1, count):
                key = ang[k]
                v = buf[k]
                j = k - 1
                while j >= 0 and ang[j] > key:
                    ang[j + 1] = ang[j]
                    buf[j + 1] = buf[j]
                    j -= 1
                ang[j + 1] = key
                buf[j + 1] = v
            # drop repeated points (shared edge ends, corners met by an edge)
            j = 0
            for k in range(count):
                if j > 0 and pts[buf[k], 0] == pts[buf[j - 1], 0] and pts[buf[k], 1] == pts[buf[j - 1], 1]:
                    continue
                buf[j] = buf[k]
                j += 1
            while j > 1 and pts[buf[j - 1], 0] == pts[buf[0], 0] and pts[buf[j - 1], 1] == pts[buf[0], 1]:
                j -= 1
            if j < 3:
                continue
            for k in range(j):
                ring[n_ring] = buf[k]
                n_ring += 1
        offsets[n] = n_ring

    return (np.asarray(pts)[:n_pts].copy(), np.asarray(offsets),
            np.asarray(ring)[:n_ring].copy())
