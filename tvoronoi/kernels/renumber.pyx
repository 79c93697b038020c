"""A triangulation renumbered in a spatial order: sites along a Z-curve of a grid, triangles by their first site.

The incremental engine numbers its sites in insertion order (BRIO: rounds that each sweep the whole
plane) and reuses the slots of destroyed triangles, so the triangles around one site lie far apart in
memory, and so do those of consecutive sites. The dual (dual.pyx) walks around every site in site
order and the clipper reads cells in that order: both are bound by those cache misses. Renumbering
once, in one linear pass, makes consecutive sites neighbours in the plane and stores the triangles
around them together (at 10^6 uniform sites on one thread, the dual itself: 0.37 s -> 0.17-0.26 s).

The order is a heuristic for memory locality only: no geometric decision depends on it, and every
later phase gives the same cells for any numbering (rings start at a canonical point). It is a
function of the coordinates and the given numbering alone, so every thread count gives the same one.
"""

import numpy as np

from cython.parallel cimport prange
from libc.stdint cimport int32_t, uint32_t
from libc.stdlib cimport calloc, free, malloc
from libc.math cimport INFINITY, ldexp
from libc.string cimport memcpy
from tvoronoi.kernels.populate cimport populate, populate_part
from tvoronoi.kernels.prefetch cimport AHEAD_BYTES, prefetch, prefetch_write

cdef enum:
    MAX_GRID_BITS = 11      # at most 2^11 x 2^11 grid cells (a 16 MiB count array); more sites share cells
    PARALLEL_MIN_TRIANGLES = 1 << 16    # fewer triangles are rewritten on one thread
    REWRITE_AHEAD = 32      # triangle_order_into: the places a triangle is written to, asked for this many ahead
    TAKE_AHEAD = 64         # take_sites: the sites read, asked for this many ahead
    CROWDED = 32            # a grid cell with more sites is ordered again, on a grid over its own sites
    MAX_DEPTH = 6           # levels of such grids (each up to 2^11 finer): the work stays linear


cdef inline uint32_t spread(uint32_t v) noexcept nogil:
    # the bits of v (up to 16) moved to the even positions: the Z-curve (Morton) interleave
    v &= 0x0000FFFF
    v = (v | (v << 8)) & 0x00FF00FF
    v = (v | (v << 4)) & 0x0F0F0F0F
    v = (v | (v << 2)) & 0x33333333
    v = (v | (v << 1)) & 0x55555555
    return v


cdef inline int cell_index(double v, double lo, double scale, int top) noexcept nogil:
    # the grid column (or row) of coordinate v: floor((v - lo) * scale), kept in [0, top] (a scale that
    # overflowed to inf, for a span of a few subnormals, gives inf or NaN here: NaN counts as 0)
    cdef double q = (v - lo) * scale
    if not q > 0.0:
        return 0
    if q >= top:
        return top
    return <int> q


cdef inline int32_t first_site(const int32_t* corners, const int32_t* old_to_new, int inf) noexcept nogil:
    # the smallest new number among a triangle's finite corners (every triangle has one; old_to_new
    # NULL: the numbers stay)
    cdef int32_t low = inf, a
    cdef int k
    for k in range(3):
        a = corners[k]
        if a != inf:
            if old_to_new != NULL:
                a = old_to_new[a]
            if a < low:
                low = a
    return low


cdef inline int bits_for(Py_ssize_t count) noexcept nogil:
    # bits per axis of a grid of about one cell per site (4^b >= count), at most MAX_GRID_BITS
    cdef int b = 0
    while b < MAX_GRID_BITS and (<Py_ssize_t> 1 << (2 * b)) < count:
        b += 1
    return b


cdef int z_sort(const double* xs, const double* ys, int32_t* ids, Py_ssize_t count, int depth) noexcept nogil:
    """Sort the sites ids[0:count] stably by the Z-curve index of their cell in a grid of about one cell
    per site over their own bounding box, then each crowded cell again, up to MAX_DEPTH levels (a tight
    cluster beside far sites is ordered inside too). Returns -1 if a grid's scratch could not be
    allocated (the sites of that grid keep their order), else 0: ids is a permutation of itself either way."""
    cdef Py_ssize_t k, lo, hi
    cdef int b, top, key, status = 0
    cdef double xlo, xhi, ylo, yhi, sx, sy, x, y
    cdef Py_ssize_t n_cells
    cdef int32_t* keys
    cdef int32_t* start
    cdef int32_t* out
    b = bits_for(count)
    top = (1 << b) - 1
    n_cells = <Py_ssize_t> 1 << (2 * b)
    xlo = xhi = xs[ids[0]]
    ylo = yhi = ys[ids[0]]
    for k in range(1, count):
        x = xs[ids[k]]
        y = ys[ids[k]]
        if x < xlo:
            xlo = x
        elif x > xhi:
            xhi = x
        if y < ylo:
            ylo = y
        elif y > yhi:
            yhi = y
    if not (xhi > xlo or yhi > ylo):
        return 0            # degenerate case: every site at one place (repeated points)
    sx = (top + 1) / (xhi - xlo) if xhi > xlo else 0.0
    sy = (top + 1) / (yhi - ylo) if yhi > ylo else 0.0
    keys = <int32_t*> malloc(count * sizeof(int32_t))
    out = <int32_t*> malloc(count * sizeof(int32_t))
    start = <int32_t*> calloc(n_cells + 1, sizeof(int32_t))
    if keys == NULL or out == NULL or start == NULL:
        free(keys); free(out); free(start)
        return -1
    for k in range(count):
        key = <int> (spread(<uint32_t> cell_index(xs[ids[k]], xlo, sx, top))
                     | (spread(<uint32_t> cell_index(ys[ids[k]], ylo, sy, top)) << 1))
        keys[k] = key
        start[key + 1] += 1
    for k in range(n_cells):
        start[k + 1] += start[k]
    for k in range(count):
        out[start[keys[k]]] = ids[k]
        start[keys[k]] += 1
    memcpy(ids, out, count * sizeof(int32_t))
    free(keys); free(out)   # (only the cells' ends are needed below: the levels under this one hold less)
    # the crowded cells (start[key] is now where cell key ends); the sites at either end of the box
    # fall in different cells, so each is smaller than this one
    if depth + 1 < MAX_DEPTH:
        lo = 0
        for k in range(n_cells):
            hi = start[k]
            if hi - lo > CROWDED and status == 0:
                status = z_sort(xs, ys, ids + lo, hi - lo, depth + 1)
            lo = hi
    free(start)
    return status


def grid_bits(Py_ssize_t n):
    """Bits per axis of the grid n sites are ordered on: about one site a cell, at most MAX_GRID_BITS."""
    return bits_for(n)


def site_order(const double[::1] xs, const double[::1] ys):
    """The sites sorted along a Z-curve (z_sort): (new_to_old, old_to_new), each (n,) int32.

    Sites are sorted (stably, by a counting sort) by the Z-curve index of their cell in a grid of about
    one cell per site over their bounding box, and the sites of a crowded cell again on a grid of their
    own. It reads the coordinates alone, so a build makes it while the triangulation runs.
    """
    cdef Py_ssize_t n = xs.shape[0], k
    new_to_old_arr = np.empty(n, np.int32)
    old_to_new_arr = np.empty(n, np.int32)
    cdef int32_t[::1] new_to_old = new_to_old_arr, old_to_new = old_to_new_arr
    cdef int status = 0
    if n == 0:
        return new_to_old_arr, old_to_new_arr
    with nogil:
        for k in range(n):
            new_to_old[k] = <int32_t> k
        status = z_sort(&xs[0], &ys[0], &new_to_old[0], n, 0)
        for k in range(n):
            old_to_new[new_to_old[k]] = <int32_t> k
    # (status -1: a grid's scratch could not be allocated and its sites kept their order; every order
    # is a correct numbering, this one only less local)
    return new_to_old_arr, old_to_new_arr


def triangle_order(const int32_t[::1] tv, const int32_t[::1] opp, const int32_t[::1] old_to_new, int threads=1):
    """The triangulation tv, opp in the sites' new numbers (old_to_new, vertex n the vertex at infinity),
    its triangles counting-sorted by their smallest new site (stably): (tv2, opp2), new triangle T an old
    one with its corners in the same rotation. The same arrays for any thread count."""
    tv2_arr = np.empty(tv.shape[0], np.int32)
    opp2_arr = np.empty(tv.shape[0], np.int32)
    triangle_order_into(tv, opp, old_to_new, tv2_arr, opp2_arr, 0, 0, old_to_new.shape[0], threads)
    return tv2_arr, opp2_arr


def triangle_order_into(const int32_t[::1] tv, const int32_t[::1] opp, const int32_t[::1] old_to_new,
                        int32_t[::1] tv2, int32_t[::1] opp2, int site_base, int tri_base, int inf_out,
                        int threads=1, int n_sites=-1):
    """triangle_order, written into tv2, opp2 (each as long as tv) as part of a larger triangulation
    (tvoronoi.halves): sites numbered from site_base on and the vertex at infinity inf_out, triangles from
    tri_base on (the twins count from there: tv2 and opp2 are the slice of the larger arrays that starts
    at half-edge 3 tri_base). old_to_new None: the sites are numbered in a spatial order already (n_sites
    of them) and keep their numbers; only the triangles are sorted."""
    cdef Py_ssize_t n = old_to_new.shape[0] if old_to_new is not None else n_sites
    cdef Py_ssize_t n_he = tv.shape[0], n_tri = n_he // 3, k, t
    cdef int inf = <int> n, a, T, o, ahead
    if n < 0:
        raise ValueError("triangle_order_into: no old_to_new and no n_sites")
    if tv2.shape[0] != n_he or opp2.shape[0] != n_he or opp.shape[0] != n_he:
        raise ValueError("triangle_order_into: tv, opp, tv2 and opp2 differ in length")
    cdef const int32_t* renumbered = &old_to_new[0] if old_to_new is not None and n > 0 else NULL
    cdef int32_t[::1] keys = np.empty(max(n_tri, 1), np.int32)      # each triangle's smallest new site
    cdef int32_t[::1] start = np.zeros(n + 1, np.int32)
    cdef int32_t[::1] tri_new = np.empty(max(n_tri, 1), np.int32)
    cdef int T_threads = threads if n_tri >= PARALLEL_MIN_TRIANGLES and threads > 1 else 1
    if n_tri == 0:
        return
    with nogil:
        # the arrays written whole, faulted in by runs of pages (the output a part on each thread)
        populate(&keys[0], n_tri * sizeof(int32_t))
        populate(&tri_new[0], n_tri * sizeof(int32_t))
        for k in prange(T_threads, num_threads=T_threads, schedule="static", chunksize=1):
            populate_part(&tv2[0], n_he * sizeof(int32_t), <int> k, T_threads)
            populate_part(&opp2[0], n_he * sizeof(int32_t), <int> k, T_threads)
        # a counting sort by the smallest new site (every triangle has a finite one)
        # (the triangles and keys, read in order, requested AHEAD_BYTES ahead)
        for t in prange(n_tri, num_threads=T_threads, schedule="static"):
            if (t & 3) == 0:
                prefetch(<const char*> &tv[3 * t] + AHEAD_BYTES)
            keys[t] = first_site(&tv[3 * t], renumbered, inf)
        for t in range(n_tri):
            if (t & 15) == 0:
                prefetch(<const char*> &keys[t] + AHEAD_BYTES)
            start[keys[t] + 1] += 1
        for k in range(n):
            start[k + 1] += start[k]
        for t in range(n_tri):
            if (t & 15) == 0:
                prefetch(<const char*> &keys[t] + AHEAD_BYTES)
            tri_new[t] = start[keys[t]]
            start[keys[t]] += 1

        # the triangles rewritten in their new places, sites and twins renumbered (the new places, and
        # the new numbers of the twins' triangles, lie anywhere: asked for REWRITE_AHEAD triangles ahead,
        # which took the pass from 14.8 to 7.7 ms for 1,000,000 triangles)
        for t in prange(n_tri, num_threads=T_threads, schedule="static"):
            if t + REWRITE_AHEAD < n_tri:
                ahead = tri_new[t + REWRITE_AHEAD]
                prefetch_write(&tv2[3 * ahead])
                prefetch_write(&opp2[3 * ahead])
                prefetch(&tri_new[opp[3 * (t + REWRITE_AHEAD)] // 3])
                prefetch(&tri_new[opp[3 * (t + REWRITE_AHEAD) + 1] // 3])
                prefetch(&tri_new[opp[3 * (t + REWRITE_AHEAD) + 2] // 3])
            T = tri_new[t]
            for k in range(3):
                a = tv[3 * t + k]
                if a == inf:
                    a = inf_out
                else:
                    a = site_base + (renumbered[a] if renumbered != NULL else a)
                tv2[3 * T + k] = a
                o = opp[3 * t + k]
                opp2[3 * T + k] = 3 * (tri_base + tri_new[o // 3]) + o % 3


def spatial_order(const double[::1] xs, const double[::1] ys, const int32_t[::1] tv, const int32_t[::1] opp,
                  int threads=1):
    """Sites and triangles renumbered so that neighbours in the plane are neighbours in memory:
    site_order, then triangle_order.

    Parameters
    ----------
    xs, ys : (n,) float64, the sites.
    tv, opp : (3 * n_tri,) int32, a triangulation of them (vertex n is the vertex at infinity) and its
        twin half-edges, as incremental.triangulate or fortune.sweep return them.
    threads : int, threads for the triangles' keys and rewrite (the result is the same for any count).

    Returns
    -------
    new_to_old : (n,) int32, new site k is old site new_to_old[k].
    old_to_new : (n,) int32, its inverse.
    tv2, opp2 : (3 * n_tri,) int32, the same triangulation in the new numbers: new triangle T is an old
        one with its corners in the same rotation, sites and half-edges renumbered.
    """
    new_to_old, old_to_new = site_order(xs, ys)
    tv2, opp2 = triangle_order(tv, opp, old_to_new, threads)
    return new_to_old, old_to_new, tv2, opp2


cdef inline double scaled(double v, int exponent, double factor) noexcept nogil:
    # v * 2^-exponent, correctly rounded (as numpy's ldexp): by the power of two itself where it is a
    # normal double, so that the product is one rounding of the exact result
    return v * factor if -1022 <= exponent <= 1022 else ldexp(v, -exponent)


def take_sites(const double[:] xs, const double[:] ys, const int32_t[::1] idx, int exponent=0):
    """(xs[idx], ys[idx]) * 2^-exponent as new contiguous arrays, in one pass, without numpy's widening of
    the int32 indices (xs, ys may be strided: the columns of an (n, 2) array); each value is rounded as
    numpy's ldexp rounds it (exact unless the result is subnormal). Raises IndexError if an index is
    out of range."""
    cdef Py_ssize_t n = xs.shape[0], m = idx.shape[0], k
    cdef int32_t i
    cdef bint bad = False
    cdef double factor = ldexp(1.0, -exponent)
    if ys.shape[0] != n:
        raise ValueError("take_sites: xs and ys differ in length")
    out_x_arr = np.empty(m, np.float64)
    out_y_arr = np.empty(m, np.float64)
    cdef double[::1] out_x = out_x_arr, out_y = out_y_arr
    with nogil:
        if m > 0:
            populate(&out_x[0], m * sizeof(double))
            populate(&out_y[0], m * sizeof(double))
        for k in range(m):
            i = idx[k]
            if i < 0 or i >= n:
                bad = True
                break
            if (k & 3) == 0 and k + TAKE_AHEAD < m:
                prefetch(&xs[idx[k + TAKE_AHEAD]])
                prefetch(&ys[idx[k + TAKE_AHEAD]])
            if exponent == 0:
                out_x[k] = xs[i]
                out_y[k] = ys[i]
            else:
                out_x[k] = scaled(xs[i], exponent, factor)
                out_y[k] = scaled(ys[i], exponent, factor)
    if bad:
        raise IndexError(f"take_sites: index {idx[k]} out of range for {n} sites")
    return out_x_arr, out_y_arr


cdef enum:
    MAX_SPLIT_PARTS = 64    # split_sites: runs of rows, one a thread
    PARALLEL_MIN_ROWS = 1 << 16     # split_sites: fewer rows are split on one thread


cdef struct SplitPart:
    # split_sites: a run of rows [lo, hi), how many lie below the split, and each side's box
    Py_ssize_t lo, hi, n_below, at_left, at_right
    double box[8]           # left xmin, ymin, xmax, ymax, then right's


cdef void split_count(SplitPart* P, const double[:] xs, const double[:] ys, int axis, double split,
                      int32_t* rows) noexcept nogil:
    # a run of rows: those below the split counted, and each side's box; with rows (not NULL), the run's
    # rows written too, those below from P.lo up and the others from P.hi - 1 down (then the right ones
    # are in reverse). No branch on the side (the sides of rows in input order are as good as random):
    # the row by a select, each box's bounds by min and max over every site, the other side's moved to
    # +-inf by adding up[side] or down[side] (-0.0 leaves any coordinate as it is, a signed zero too)
    cdef Py_ssize_t k, lo = P.lo, hi = P.hi - 1, n_below = 0
    cdef double x, y, lx, ly, rx, ry
    cdef double lx0 = INFINITY, ly0 = INFINITY, lx1 = -INFINITY, ly1 = -INFINITY
    cdef double rx0 = INFINITY, ry0 = INFINITY, rx1 = -INFINITY, ry1 = -INFINITY
    cdef double up[2]
    cdef double down[2]
    cdef bint below
    up[0] = INFINITY; up[1] = -0.0          # [not below, below]
    down[0] = -INFINITY; down[1] = -0.0
    for k in range(P.lo, P.hi):
        if (k & 3) == 0:
            prefetch(<const char*> &xs[k] + AHEAD_BYTES)
            prefetch(<const char*> &ys[k] + AHEAD_BYTES)
        x = xs[k]
        y = ys[k]
        below = (x if axis == 0 else y) < split
        if rows != NULL:
            rows[lo if below else hi] = <int32_t> k
            lo += below
            hi -= 1 - below
        n_below += below
        lx = x + up[below]
        ly = y + up[below]
        rx = x + up[1 - below]
        ry = y + up[1 - below]
        lx0 = lx if lx < lx0 else lx0
        ly0 = ly if ly < ly0 else ly0
        rx0 = rx if rx < rx0 else rx0
        ry0 = ry if ry < ry0 else ry0
        lx = x + down[below]
        ly = y + down[below]
        rx = x + down[1 - below]
        ry = y + down[1 - below]
        lx1 = lx if lx > lx1 else lx1
        ly1 = ly if ly > ly1 else ly1
        rx1 = rx if rx > rx1 else rx1
        ry1 = ry if ry > ry1 else ry1
    P.n_below = n_below
    P.box[0] = lx0; P.box[1] = ly0; P.box[2] = lx1; P.box[3] = ly1
    P.box[4] = rx0; P.box[5] = ry0; P.box[6] = rx1; P.box[7] = ry1


cdef void split_place(const SplitPart* P, const double[:] xs, const double[:] ys, int axis, double split,
                      int32_t* rows, Py_ssize_t n_left) noexcept nogil:
    # a counted run's rows written at its places: those below from P.at_left, the others from n_left +
    # P.at_right; the place by arithmetic on the side, not a select (which the compiler may make a branch,
    # as good as random here)
    cdef Py_ssize_t k, at_l = P.at_left, at_r = n_left + P.at_right
    cdef Py_ssize_t below
    for k in range(P.lo, P.hi):
        if (k & 3) == 0:
            prefetch(<const char*> &xs[k] + AHEAD_BYTES)
            prefetch(<const char*> &ys[k] + AHEAD_BYTES)
        below = (xs[k] if axis == 0 else ys[k]) < split
        rows[at_r + ((at_l - at_r) & -below)] = <int32_t> k
        at_l += below
        at_r += 1 - below


cdef void gather_sites(const double[:] xs, const double[:] ys, const int32_t* rows, Py_ssize_t lo, Py_ssize_t hi,
                       int exponent, double* out_x, double* out_y) noexcept nogil:
    # out[k] = (xs, ys)[rows[k]] * 2^-exponent for k in lo..hi - 1 (take_sites' pass, rows in range), its
    # places faulted in first
    cdef Py_ssize_t k
    cdef int32_t i
    cdef double factor = ldexp(1.0, -exponent)
    if hi <= lo:
        return
    populate(&out_x[lo], (hi - lo) * sizeof(double))
    populate(&out_y[lo], (hi - lo) * sizeof(double))
    for k in range(lo, hi):
        i = rows[k]
        if (k & 3) == 0 and k + TAKE_AHEAD < hi:
            prefetch(&xs[rows[k + TAKE_AHEAD]])
            prefetch(&ys[rows[k + TAKE_AHEAD]])
        if exponent == 0:
            out_x[k] = xs[i]
            out_y[k] = ys[i]
        else:
            out_x[k] = scaled(xs[i], exponent, factor)
            out_y[k] = scaled(ys[i], exponent, factor)


def split_sites(const double[:] xs, const double[:] ys, int axis, double split, int exponent=0,
                Py_ssize_t least=0, int threads=1):
    """The rows whose coordinate ``axis`` (0: x, 1: y) is below ``split``, then the others, each part with
    its sites: the rows in row order and their coordinates scaled by 2^-exponent (as take_sites scales
    them). On one thread the rows in one pass (those below from the front, the others from the back,
    then turned round); on more, a run of rows on each thread counted, then written at their places;
    then the sites gathered (on more threads, a part of each side on each): the same arrays for any
    count.

    Returns (left, right, box_left, box_right), left and right each (rows int32, xs, ys float64), the
    rows views of one array; each box (xmin, ymin, xmax, ymax) of its part's sites, unscaled ((inf, inf,
    -inf, -inf) for an empty part), each bound the first site's among equal extremes, bit for bit. None
    when a part has fewer than ``least`` rows. xs, ys may be strided (the columns of an (n, 2) array).
    """
    cdef Py_ssize_t n = xs.shape[0], n_left = 0, k, i, lo, hi
    cdef int T = max(1, min(threads, MAX_SPLIT_PARTS))
    cdef SplitPart parts[MAX_SPLIT_PARTS]
    cdef double box[8]
    cdef int32_t tmp
    if ys.shape[0] != n:
        raise ValueError("split_sites: xs and ys differ in length")
    if n < PARALLEL_MIN_ROWS:
        T = 1
    for k in range(T):
        parts[k].lo = n * k // T
        parts[k].hi = n * (k + 1) // T
    rows_arr = np.empty(n, np.int32)
    cdef int32_t[::1] rows = rows_arr
    cdef int32_t* rows_p = &rows[0] if n > 0 else NULL
    with nogil:
        if T == 1:
            split_count(&parts[0], xs, ys, axis, split, rows_p)
            n_left = parts[0].n_below
            lo = n_left
            hi = n - 1
            while lo < hi:
                tmp = rows_p[lo]
                rows_p[lo] = rows_p[hi]
                rows_p[hi] = tmp
                lo += 1
                hi -= 1
        else:
            for k in prange(T, num_threads=T, schedule="static", chunksize=1):
                split_count(&parts[k], xs, ys, axis, split, NULL)
            for k in range(T):
                parts[k].at_left = n_left
                parts[k].at_right = parts[k].lo - n_left
                n_left += parts[k].n_below
    # the runs' boxes in row order: a later run's bound only where it is strictly beyond (ties keep the
    # first site's value, as one pass does)
    for i in range(8):
        box[i] = parts[0].box[i]
    for k in range(1, T):
        for i in range(8):
            if (i & 3) < 2:
                box[i] = parts[k].box[i] if parts[k].box[i] < box[i] else box[i]
            else:
                box[i] = parts[k].box[i] if parts[k].box[i] > box[i] else box[i]
    if min(n_left, n - n_left) < least:
        return None
    xl_arr = np.empty(n_left, np.float64)
    yl_arr = np.empty(n_left, np.float64)
    xr_arr = np.empty(n - n_left, np.float64)
    yr_arr = np.empty(n - n_left, np.float64)
    cdef double[::1] xl = xl_arr, yl = yl_arr, xr = xr_arr, yr = yr_arr
    # (an empty side: its arrays are never written, any address stands for them)
    cdef double* p_xl = &xl[0] if n_left > 0 else NULL
    cdef double* p_yl = &yl[0] if n_left > 0 else NULL
    cdef double* p_xr = &xr[0] if n > n_left else NULL
    cdef double* p_yr = &yr[0] if n > n_left else NULL
    cdef Py_ssize_t n_right = n - n_left
    with nogil:
        if T == 1:
            gather_sites(xs, ys, rows_p, 0, n_left, exponent, p_xl, p_yl)
            gather_sites(xs, ys, rows_p + n_left, 0, n_right, exponent, p_xr, p_yr)
        else:
            for k in prange(T, num_threads=T, schedule="static", chunksize=1):
                split_place(&parts[k], xs, ys, axis, split, rows_p, n_left)
            for k in prange(T, num_threads=T, schedule="static", chunksize=1):
                gather_sites(xs, ys, rows_p, n_left * k // T, n_left * (k + 1) // T, exponent, p_xl, p_yl)
                gather_sites(xs, ys, rows_p + n_left, n_right * k // T, n_right * (k + 1) // T, exponent,
                             p_xr, p_yr)
    return ((rows_arr[:n_left], xl_arr, yl_arr), (rows_arr[n_left:], xr_arr, yr_arr),
            (box[0], box[1], box[2], box[3]), (box[4], box[5], box[6], box[7]))


def sites_into(const double[::1] xs, const double[::1] ys, const int32_t[::1] rows, const int32_t[::1] perm,
               const int32_t[::1] new_to_old, double[::1] out_x, double[::1] out_y, int32_t[::1] out_rows):
    """A half's sites in their new order, written into its part of the joined arrays (tvoronoi.halves):
    out_x[k] = xs[j], out_y[k] = ys[j] and out_rows[k] = rows[perm[j]], j = new_to_old[k] (perm None:
    rows[j]). Raises IndexError if an index is out of range."""
    cdef Py_ssize_t n = xs.shape[0], m = new_to_old.shape[0], n_rows = rows.shape[0], k
    cdef int32_t j, r
    cdef bint bad = False
    cdef const int32_t* through = &perm[0] if perm is not None and n > 0 else NULL
    if (ys.shape[0] != n or (perm is not None and perm.shape[0] != n) or out_x.shape[0] != m
            or out_y.shape[0] != m or out_rows.shape[0] != m):
        raise ValueError("sites_into: the arrays differ in length")
    with nogil:
        if m > 0:
            populate(&out_x[0], m * sizeof(double))
            populate(&out_y[0], m * sizeof(double))
            populate(&out_rows[0], m * sizeof(int32_t))
        for k in range(m):
            j = new_to_old[k]
            if j < 0 or j >= n:
                bad = True
                break
            r = through[j] if through != NULL else j
            if r < 0 or r >= n_rows:
                bad = True
                break
            out_x[k] = xs[j]
            out_y[k] = ys[j]
            out_rows[k] = rows[r]
    if bad:
        raise IndexError("sites_into: an index is out of range")
