"""The cells' rings gathered for the writers: points in ring order, closed, with their bounding boxes."""

from libc.math cimport NAN
from libc.stdint cimport int32_t, int64_t, uint8_t

from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.prefetch cimport prefetch

cdef enum:
    AHEAD = 8       # rows ahead whose ring points start loading (rows in input order: points anywhere)


def gather_slotted_rings(const int64_t[::1] offsets, const int32_t[::1] vertices, const double[:, ::1] points,
                         Py_ssize_t ra, Py_ssize_t rb, const uint8_t[::1] keep, double[:, ::1] slots,
                         double[:, ::1] mins, double[:, ::1] maxs):
    """The rings of rows ra..rb-1 where keep[row - ra], each in its own run of ``slots``.

    The ring of row r is points[vertices[offsets[r]:offsets[r + 1]]]. The k-th kept ring of L points
    takes L + 2 rows of ``slots``: one left for its header (not written), its points, its first point
    again (closing it); the runs follow one another. mins[k], maxs[k]: the ring's bounding box.
    """
    cdef Py_ssize_t r, j, q, s = 0, k = 0, ahead
    cdef double x, y, x0, y0, x1, y1
    with nogil:
        for r in range(ra, rb):
            if ((r - ra) & POLL_MASK) == 0:
                poll_signals()
            ahead = r + AHEAD
            if ahead < rb and keep[ahead - ra]:
                for j in range(offsets[ahead], offsets[ahead + 1]):
                    prefetch(&points[vertices[j], 0])
            if not keep[r - ra]:
                continue
            s += 1                   # the header's slot
            q = s
            if offsets[r + 1] == offsets[r]:
                slots[s, 0] = slots[s, 1] = NAN     # no point: a NaN box, a NaN closing point
                s += 1
                mins[k, 0] = mins[k, 1] = maxs[k, 0] = maxs[k, 1] = NAN
                k += 1
                continue
            x0 = x1 = points[vertices[offsets[r]], 0]
            y0 = y1 = points[vertices[offsets[r]], 1]
            for j in range(offsets[r], offsets[r + 1]):
                x = points[vertices[j], 0]
                y = points[vertices[j], 1]
                slots[s, 0] = x
                slots[s, 1] = y
                s += 1
                if x < x0:
                    x0 = x
                if x > x1:
                    x1 = x
                if y < y0:
                    y0 = y
                if y > y1:
                    y1 = y
            slots[s, 0] = slots[q, 0]
            slots[s, 1] = slots[q, 1]
            s += 1
            mins[k, 0] = x0
            mins[k, 1] = y0
            maxs[k, 0] = x1
            maxs[k, 1] = y1
            k += 1
