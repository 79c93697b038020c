"""The tiles' certification of a cell as final, one pass over the diagram's rings (see tiles.certified)."""

from libc.math cimport INFINITY, NAN, fabs, hypot, isfinite, nextafter, sqrt
from libc.stdint cimport int32_t, int64_t, uint8_t

from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.prefetch cimport prefetch

cdef enum:
    AHEAD = 8       # rows ahead whose ring points start loading (rows in input order: points anywhere)

# Below this squared distance (or above HUGE) sqrt(dx^2 + dy^2) could lose its relative accuracy to
# underflow (or overflow): hypot is used instead.
cdef double TINY = 2.0 ** -960
cdef double HUGE = 2.0 ** 960


cdef inline double distance(double dx, double dy) noexcept nogil:
    # |(dx, dy)| within a few units of 2^-53 relative: sqrt of the sum of squares, hypot at the extremes
    cdef double d2 = dx * dx + dy * dy
    if TINY < d2 < HUGE:
        return sqrt(d2)
    return hypot(dx, dy)


cdef inline double room(double x, double y, const double* region) noexcept nogil:
    # how far (x, y) lies inside the region from its nearest finite side (inf: no finite side; NaN for a
    # NaN side, which then certifies nothing); a difference that overflows is larger than any finite need
    cdef double r = INFINITY
    if region[0] != region[0] or region[1] != region[1] or region[2] != region[2] or region[3] != region[3]:
        return NAN
    if isfinite(region[0]) and x - region[0] < r:
        r = x - region[0]
    if isfinite(region[1]) and y - region[1] < r:
        r = y - region[1]
    if isfinite(region[2]) and region[2] - x < r:
        r = region[2] - x
    if isfinite(region[3]) and region[3] - y < r:
        r = region[3] - y
    return r


def certify_rings(const int64_t[::1] offsets, const int32_t[::1] vertices, const double[:, ::1] points,
                  const double[:, ::1] sites, const int64_t[::1] rows, region, double relative, double ulps,
                  uint8_t[::1] ok):
    """ok[k] = 1 when no site outside ``region`` can cut the cell of row rows[k], else 0.

    The ring of row r is points[vertices[offsets[r]:offsets[r + 1]]], its site sites[r]; ``region``
    (xmin, ymin, xmax, ymax) is the closed rectangle whose every site the diagram holds (sides may be
    infinite). The test, its margins (``relative``, ``ulps``) and why it is sound: tiles.certified.
    The ulps are those of the largest coordinate of the cell's own ring.
    """
    cdef double box[4]
    box[0], box[1], box[2], box[3] = (float(v) for v in region)
    cdef Py_ssize_t k, j, r, n_rows = rows.shape[0]
    cdef double sx, sy, vx, vy, d, farthest, top, slack, need, least = nextafter(0.0, 1.0)
    cdef bint good, finite
    with nogil:
        for k in range(n_rows):
            if (k & POLL_MASK) == 0:
                poll_signals()
            if k + AHEAD < n_rows:
                r = rows[k + AHEAD]
                for j in range(offsets[r], offsets[r + 1]):
                    prefetch(&points[vertices[j], 0])
                prefetch(&sites[r, 0])
            r = rows[k]
            sx = sites[r, 0]
            sy = sites[r, 1]
            farthest = 0.0
            top = 0.0
            finite = True
            for j in range(offsets[r], offsets[r + 1]):
                vx = points[vertices[j], 0]
                vy = points[vertices[j], 1]
                d = distance(vx - sx, vy - sy)
                if d > farthest:
                    farthest = d
                finite = finite and isfinite(d)
                if fabs(vx) > top:
                    top = fabs(vx)
                if fabs(vy) > top:
                    top = fabs(vy)
            if offsets[r + 1] == offsets[r]:
                ok[k] = 1               # a cell that misses the box stays out
                continue
            if not (finite and isfinite(top)):
                ok[k] = 0               # a non-finite point or distance is never certified
                continue
            slack = 2 * ulps * (nextafter(top, INFINITY) - top) + 4 * least
            # most cells lie far from every side: room(v) >= room(s) - |v - s|; the bound must be finite
            # (an overflowed one would pass against a room that overflowed too)
            need = 2 * (farthest * (1 + relative) + slack)
            if isfinite(need) and room(sx, sy, box) * (1 - relative) - slack >= need:
                ok[k] = 1
                continue
            good = True
            for j in range(offsets[r], offsets[r + 1]):
                vx = points[vertices[j], 0]
                vy = points[vertices[j], 1]
                need = distance(vx - sx, vy - sy) * (1 + relative) + slack
                if not (isfinite(need) and room(vx, vy, box) * (1 - relative) - slack >= need):
                    good = False
                    break
            ok[k] = good
