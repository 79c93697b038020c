# Clipping Voronoi edges and cells to a box, shared by the batch clip and the dynamic diagrams;
# inline functions compiled into each kernel that cimports them.

from libc.math cimport atan2, fabs, hypot, INFINITY

cdef struct Box:
    double xmin, ymin, xmax, ymax, snap


cdef inline Box make_box(double xmin, double ymin, double xmax, double ymax) noexcept nogil:
    # a point within this fraction of the box size of a side is put on it: a corner or
    # a vertex on the boundary is then not emitted twice (or as a sliver) by rounding
    cdef Box box
    box.xmin = xmin
    box.ymin = ymin
    box.xmax = xmax
    box.ymax = ymax
    box.snap = 1e-12 * (xmax - xmin if xmax - xmin > ymax - ymin else ymax - ymin)
    return box


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



cdef inline bint clip_bisector(Box* box, double ax, double ay, double bx, double by,
                               double lo_x, double lo_y, bint has_lo, double hi_x, double hi_y, bint has_hi,
                               double* mx, double* my, double* dx, double* dy,
                               double* t0, double* t1) noexcept nogil:
    """The part inside the box of the Voronoi edge of sites a and b.

    The edge runs along the bisector M + t D (M the sites' midpoint, D a unit
    vector counter-clockwise about a), from the vertex (lo_x, lo_y), or from
    infinity when has_lo is false, to (hi_x, hi_y) or infinity. Points computed
    from M keep their precision even when a far-off vertex (of nearly
    collinear sites) ends the edge; with a unit D nothing is squared that could
    underflow for very close sites; and the same edge seen from b gives
    bit-identical points. False when the edge misses or only touches the box.
    """
    cdef double norm
    mx[0] = 0.5 * (ax + bx)
    my[0] = 0.5 * (ay + by)
    dx[0] = -(by - ay)
    dy[0] = bx - ax
    norm = hypot(dx[0], dy[0])
    dx[0] /= norm
    dy[0] /= norm
    t0[0] = (lo_x - mx[0]) * dx[0] + (lo_y - my[0]) * dy[0] if has_lo else -INFINITY
    t1[0] = (hi_x - mx[0]) * dx[0] + (hi_y - my[0]) * dy[0] if has_hi else INFINITY
    if not (clip_param(-dx[0], mx[0] - box.xmin, t0, t1)
            and clip_param(dx[0], box.xmax - mx[0], t0, t1)
            and clip_param(-dy[0], my[0] - box.ymin, t0, t1)
            and clip_param(dy[0], box.ymax - my[0], t0, t1)):
        return False
    return t1[0] - t0[0] > box.snap


cdef inline bint snap_inside(Box* box, double* x, double* y) noexcept nogil:
    """A vertex within rounding of the box counts as inside and is put exactly on its edge,
    so that no sliver of an edge (or a near-copy of the vertex) is left on the boundary."""
    if (box.xmin - box.snap <= x[0] <= box.xmax + box.snap
            and box.ymin - box.snap <= y[0] <= box.ymax + box.snap):
        on_box(box, x, y)
        return True
    return False


cdef inline int angular_ring(double* px, double* py, int* ids, double* ang, int count) noexcept nogil:
    """Order points of a convex ring counter-clockwise about their centroid, dropping repeats.

    px, py, ids are permuted together; returns the number of points kept.
    """
    cdef double cxm = 0.0, cym = 0.0, key, kx, ky
    cdef int k, j, kid
    for k in range(count):
        cxm += px[k]
        cym += py[k]
    cxm /= count
    cym /= count
    for k in range(count):
        ang[k] = atan2(py[k] - cym, px[k] - cxm)
    # insertion sort: a cell has a handful of points
    for k in range(1, count):
        key = ang[k]; kx = px[k]; ky = py[k]; kid = ids[k]
        j = k - 1
        while j >= 0 and ang[j] > key:
            ang[j + 1] = ang[j]; px[j + 1] = px[j]; py[j + 1] = py[j]; ids[j + 1] = ids[j]
            j -= 1
        ang[j + 1] = key; px[j + 1] = kx; py[j + 1] = ky; ids[j + 1] = kid
    j = 0
    for k in range(count):
        if j > 0 and px[k] == px[j - 1] and py[k] == py[j - 1]:
            continue
        px[j] = px[k]; py[j] = py[k]; ids[j] = ids[k]
        j += 1
    while j > 1 and px[j - 1] == px[0] and py[j - 1] == py[0]:
        j -= 1
    return j
