"""Nearest-site queries: a greedy walk on the Delaunay graph, each step decided by an exact distance comparison."""

from libc.stdint cimport int32_t, int64_t

from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.predicates cimport EPSILON, expansion_sign, fast_expansion_sum_zeroelim, two_product, two_square

# Bound on the rounding error of (qx-ax)^2 + (qy-ay)^2 - (qx-bx)^2 - (qy-by)^2 in doubles, relative to the
# sum of the two squared distances: each distance carries at most (1+eps)^4 - 1 < 4.001 eps, the final
# subtraction eps more; 6 eps leaves room for rounding the bound itself.
cdef double CLOSER_ERRBOUND = 6.0 * EPSILON


cdef inline int pair(double head, double tail, double sign, double* h) noexcept nogil:
    # the exact value sign * (head + tail) as an expansion of one or two components
    if tail == 0.0:
        h[0] = sign * head
        return 1
    h[0] = sign * tail
    h[1] = sign * head
    return 2


cdef int closer_exact(double qx, double qy, double ax, double ay, double bx, double by) noexcept nogil:
    # |q-a|^2 - |q-b|^2 = ax^2 + ay^2 - bx^2 - by^2 - 2 qx ax + 2 qx bx - 2 qy ay + 2 qy by, every term
    # an exact product of two inputs (doubling is exact), summed as expansions
    cdef double terms[8][2]
    cdef int lens[8]
    cdef double sums4[4][4]
    cdef int lens4[4]
    cdef double sums8[2][8]
    cdef int lens8[2]
    cdef double total[16]
    cdef double h, t
    cdef int k, n
    h, t = two_square(ax)
    lens[0] = pair(h, t, 1.0, terms[0])
    h, t = two_square(ay)
    lens[1] = pair(h, t, 1.0, terms[1])
    h, t = two_square(bx)
    lens[2] = pair(h, t, -1.0, terms[2])
    h, t = two_square(by)
    lens[3] = pair(h, t, -1.0, terms[3])
    h, t = two_product(qx, ax)
    lens[4] = pair(2.0 * h, 2.0 * t, -1.0, terms[4])
    h, t = two_product(qx, bx)
    lens[5] = pair(2.0 * h, 2.0 * t, 1.0, terms[5])
    h, t = two_product(qy, ay)
    lens[6] = pair(2.0 * h, 2.0 * t, -1.0, terms[6])
    h, t = two_product(qy, by)
    lens[7] = pair(2.0 * h, 2.0 * t, 1.0, terms[7])
    for k in range(4):
        lens4[k] = fast_expansion_sum_zeroelim(lens[2 * k], terms[2 * k], lens[2 * k + 1], terms[2 * k + 1],
                                               sums4[k])
    for k in range(2):
        lens8[k] = fast_expansion_sum_zeroelim(lens4[2 * k], sums4[2 * k], lens4[2 * k + 1], sums4[2 * k + 1],
                                               sums8[k])
    n = fast_expansion_sum_zeroelim(lens8[0], sums8[0], lens8[1], sums8[1], total)
    return expansion_sign(n, total)


cdef inline int closer(double qx, double qy, double ax, double ay, double bx, double by) noexcept nogil:
    """Sign of |q-a|^2 - |q-b|^2: -1 when a is strictly nearer to q than b, 0 on a tie, +1 when b is nearer.

    Exact for coordinates scaled as the range rule of tvoronoi.api asks (below 1, nonzero ones above
    2^-170): no product under- or overflows.
    """
    cdef double dax = qx - ax, day = qy - ay, dbx = qx - bx, dby = qy - by
    cdef double da = dax * dax + day * day
    cdef double db = dbx * dbx + dby * dby
    cdef double det = da - db
    cdef double bound = CLOSER_ERRBOUND * (da + db)
    if det > bound:
        return 1
    if -det > bound:
        return -1
    return closer_exact(qx, qy, ax, ay, bx, by)


def nearest_sites(const double[:, ::1] sites, const int32_t[::1] face_edge, const int32_t[::1] he_next,
                  const int32_t[::1] he_twin, const int32_t[::1] he_face,
                  const double[::1] qx, const double[::1] qy, const int32_t[::1] start, int32_t first,
                  int32_t[::1] out, int64_t[::1] mark, int32_t[::1] stack) -> int:
    """Write in out[k] the lowest row among the sites nearest to (qx[k], qy[k]).

    ``sites`` are scaled by the diagram's 2^-e and so are the queries. The neighbours of a site are the
    cells across the half-edges of its cell (``face_edge``, ``he_next``, ``he_twin``, ``he_face`` of the
    Diagram); repeated points have no cell and are never visited. A query starts from ``start[k]`` (a row
    the walk may visit: one with a cell edge, or the lone site), or, where it is -1, from the previous
    query's answer (``first`` for the first query). ``mark`` (n, filled with -1) and ``stack`` (n) are scratch. Returns 0.
    """
    cdef Py_ssize_t n_queries = qx.shape[0]
    cdef Py_ssize_t k
    cdef int32_t e, e0
    cdef int32_t cur = first, best, i, j, low, top
    cdef double x, y
    with nogil:
        for k in range(n_queries):
            if (k & POLL_MASK) == 0 and k:
                poll_signals()
            x = qx[k]
            y = qy[k]
            if start[k] >= 0:
                cur = start[k]
            # walk: move to the nearest neighbour while one is strictly nearer than the current site
            # (the Delaunay graph has no local minimum but the nearest sites)
            while True:
                best = cur
                e0 = face_edge[cur]
                e = e0
                while e >= 0:
                    j = he_face[he_twin[e]]
                    if closer(x, y, sites[j, 0], sites[j, 1], sites[best, 0], sites[best, 1]) < 0:
                        best = j
                    e = he_next[e]
                    if e == e0:
                        break
                if best == cur:
                    break
                cur = best
            # ties: the sites as near as cur lie on one empty circle around the query, and consecutive
            # ones on it are Voronoi neighbours, so a search among equally near neighbours finds them all
            low = cur
            mark[cur] = k
            stack[0] = cur
            top = 1
            while top > 0:
                top -= 1
                i = stack[top]
                e0 = face_edge[i]
                e = e0
                while e >= 0:
                    j = he_face[he_twin[e]]
                    if mark[j] != k and closer(x, y, sites[j, 0], sites[j, 1], sites[cur, 0], sites[cur, 1]) == 0:
                        mark[j] = k
                        stack[top] = j
                        top += 1
                        if j < low:
                            low = j
                    e = he_next[e]
                    if e == e0:
                        break
            out[k] = low
    return 0
