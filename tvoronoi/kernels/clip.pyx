"""Bounded cells: the Voronoi DCEL clipped to a box, as counter-clockwise rings (the batch driver of clipper.pxd)."""

import numpy as np

from libc.math cimport hypot, fabs
from libc.stdlib cimport calloc, malloc, free
from libc.string cimport memcpy, memmove
from cython.parallel cimport prange
from libc.stdint cimport int32_t, int64_t, uint64_t
from tvoronoi.kernels.construct cimport bisector_at
from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.clipper cimport (
    Box, EdgePart, Points, AT_ORIGIN, AT_POINT, make_box, axis_code, code_in, code_side, clip_edge, walk_cell,
    finish_ring, first_right_turn, turn, convex_ring, bent, TURN_BAND_LOW, TURN_BAND_HIGH,
)
from tvoronoi.kernels.prefetch cimport AHEAD_BYTES, prefetch, prefetch_write
from tvoronoi.kernels.populate cimport populate_part


cdef enum:
    HAS = 1
    ENTRY = 2
    EXIT = 4
    WHOLE = 8       # the whole edge, both ends vertices in the closed box (the interior walk reads only flags)
    PARALLEL_MIN_CELLS = 1 << 15    # fewer cells are clipped on one thread
    GATHER_AHEAD = 16   # rows_of_cells: how many sites ahead a row's offset starts loading


def clip_cells(const double[::1] xs, const double[::1] ys, const double[:, ::1] vertices,
               const int32_t[::1] he_origin, const int32_t[::1] he_twin,
               const int32_t[::1] he_face,
               const int32_t[::1] face_edge, const signed char[::1] active, box_tuple, int e, int threads=1,
               int parallel_min=PARALLEL_MIN_CELLS, room=None):
    """Clip every cell to the box (xmin, ymin, xmax, ymax), exactly.

    Each edge is clipped once, so neighbouring cells share their points;
    every point is an input-exact corner or a correctly rounded construction.

    Parameters
    ----------
    xs, ys : (n,) float64, the sites in the scaled unit (user = 2^e * scaled)
    vertices : (m, 2) float64, the Voronoi vertices, correctly rounded, user unit
    he_* : (h,) int32, the Voronoi DCEL, laid out cell by cell; face_edge : (n,) int32, each cell's first
        half-edge (its next ones follow while the face stays the same: dual.pyx)
    active : (n,) int8, 0 for a site without a cell of its own (a repeat)
    box_tuple : the box, user unit; e : the scale exponent
    threads : cells are clipped on this many threads (the same result for any count), when there are
        at least parallel_min of them
    room : optional (R, 2) float64 whose first m rows are ``vertices`` (dual's vertex_room): the new
        points are written after them when they fit, instead of into a copy

    Returns
    -------
    points : (k, 2) float64 -- the m Voronoi vertices, then the new points
        on the box, then the four corners.
    offsets : (n + 1,) int64, ring : (K,) int32 -- cell i is
        points[ring[offsets[i]:offsets[i + 1]]], counter-clockwise, not
        closed, starting at its lowest point; empty when the cell misses the box.
    status : int, 0, or 1 if the edges of some cell did not chain (never on a valid DCEL).

    points is a view of room, or of a buffer with room for exactly the crossings counted.
    """
    xmin, ymin, xmax, ymax = [float(side) for side in box_tuple]
    cdef Box box = make_box(xmin, ymin, xmax, ymax, e)
    cdef int n = xs.shape[0], m = vertices.shape[0], n_he = he_origin.shape[0]
    cdef signed char[::1] vcx = np.empty(max(m, 1), np.int8)
    cdef signed char[::1] vcy = np.empty(max(m, 1), np.int8)
    # 1 for a vertex in the closed box (both codes in), 0 outside; from index -1 on, where "at infinity"
    # reads 0
    cdef signed char[::1] v_in_buf = np.empty(m + 1, np.int8)
    cdef signed char* v_in = &v_in_buf[0] + 1
    # arrays written at a few places only (Scratch): ties, the parts of edges not WHOLE
    cdef Scratch scratch = Scratch()
    cdef signed char* tie = <signed char*> scratch.take(max(m, 1), True)
    cdef int32_t* seg_start = <int32_t*> scratch.take(max(n_he, 1) * sizeof(int32_t), False)
    cdef int32_t* seg_end = <int32_t*> scratch.take(max(n_he, 1) * sizeof(int32_t), False)
    cdef int32_t* cross = <int32_t*> scratch.take(max(n_he, 1) * sizeof(int32_t), False)   # whole_edges
    cdef signed char[::1] flags = np.zeros(n_he, np.int8)
    cdef int64_t[::1] offsets = np.zeros(n + 1, np.int64)
    cdef double[:, ::1] pts, room_pts
    cdef signed char* pt_side                                   # read only at exits and entries
    cdef int32_t* pt_a                                          # how a boundary point was made (Points)
    cdef int32_t* pt_b
    cdef int32_t* pt_c
    cdef int n_pts = m, corner0, h, tw, o, d, a, b, c, v, i, k, cnt, status = 0, n_ties = 0, n_bent = 0
    cdef int n_cross = 0, lo, hi
    cdef int64_t n_ring = 0
    cdef EdgePart part
    cdef Points P
    cdef bint has_o, has_d

    cdef int T = threads if n >= parallel_min and threads > 1 else 1
    # per thread: 1 if some vertex lies outside turn()'s band of magnitudes (clipper.pxd)
    cdef int[::1] off_band = np.zeros(T, np.intc)
    cdef int[::1] n_cross_of = np.zeros(T, np.intc)
    with nogil:
        # vertices against the box: rounded comparisons, exact where a coordinate equals a side
        # (each thread a run of them, in a function of its own: its pointers stay in registers across
        # the byte stores, which could alias them for the compiler)
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            n_ties += vertex_codes(<int> (<int64_t> k * m // T), <int> (<int64_t> (k + 1) * m // T),
                                   &vertices[0, 0] if m > 0 else NULL, &box, &vcx[0], &vcy[0], tie, v_in,
                                   &off_band[k])
        v_in_buf[0] = 0
        for h in range(n_he if n_ties > 0 else 0):
            v = he_origin[h]
            if v < 0 or tie[v] != 1:
                continue
            tie[v] = 2
            # the vertex is the circumcentre of the three cells around it
            a = he_face[h]
            b = he_face[he_twin[h]]
            c = he_face[he_twin[prev_in_cell(h, n_he, &he_face[0], &face_edge[0])]]
            vcx[v] = axis_code(vertices[v, 0], box.xmin, box.xmax, box.sxmin, box.sxmax,
                               xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], False)
            vcy[v] = axis_code(vertices[v, 1], box.ymin, box.ymax, box.symin, box.symax,
                               xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], True)
            v_in[v] = code_in(vcx[v]) and code_in(vcy[v])
        # the edges with both ends vertices in the box are whole; the others listed, each thread's
        # from the start of its run of half-edges
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            n_cross_of[k] = whole_edges(<int> (<int64_t> k * n_he // T), <int> (<int64_t> (k + 1) * n_he // T),
                                        n_he, &he_origin[0] if n_he > 0 else NULL,
                                        &he_twin[0] if n_he > 0 else NULL, &he_face[0] if n_he > 0 else NULL,
                                        &face_edge[0] if n > 0 else NULL, v_in, &flags[0] if n_he > 0 else NULL,
                                        cross)
        for k in range(T):
            n_cross += n_cross_of[k]
    cdef bint in_room = False
    if room is not None:
        room_pts = room
        in_room = (room_pts.shape[0] >= m + 2 * n_cross + 4
                   and (m == 0 or &room_pts[0, 0] == &vertices[0, 0]))
    pts_buf = room if in_room else np.empty((m + 2 * n_cross + 4, 2), np.float64)
    pts = pts_buf
    pt_side = <signed char*> scratch.take(m + 2 * n_cross + 4, False)
    pt_a = <int32_t*> scratch.take((m + 2 * n_cross + 4) * sizeof(int32_t), False)
    pt_b = <int32_t*> scratch.take((m + 2 * n_cross + 4) * sizeof(int32_t), False)
    pt_c = <int32_t*> scratch.take((m + 2 * n_cross + 4) * sizeof(int32_t), False)

    with nogil:
        if m > 0 and not in_room:
            memcpy(&pts[0, 0], &vertices[0, 0], 2 * m * sizeof(double))
        for h in range(n_he if n_ties > 0 else 0):
            v = he_origin[h]
            if v < 0 or tie[v] != 2:
                continue
            tie[v] = 1
            pt_a[v] = he_face[h]
            pt_b[v] = he_face[he_twin[h]]
            pt_c[v] = he_face[he_twin[prev_in_cell(h, n_he, &he_face[0], &face_edge[0])]]
        # (codes -1 and 1, on a side, are a tie's alone: vertex_codes gives the others -2, 0 or 2)
        for v in range(m if n_ties > 0 else 0):
            if (vcx[v] == 1 or vcx[v] == -1 or vcy[v] == 1 or vcy[v] == -1) and code_in(vcx[v]) and code_in(vcy[v]):
                pt_side[v] = code_side(vcx[v], vcy[v])

        # clip each edge that is not whole once, along the half-edge of smaller index (as whole_edges
        # listed them, each thread's in increasing order); its twin runs the other way
        for i in range(T * (n_cross > 0)):
            for k in range(n_cross_of[i]):
                h = cross[<int> (<int64_t> i * n_he // T) + k]
                tw = he_twin[h]
                o = he_origin[h]
                d = he_origin[tw]
                has_o = o >= 0
                has_d = d >= 0
                a = he_face[h]
                b = he_face[tw]
                clip_edge(&box, xs[a], ys[a], xs[b], ys[b],
                          has_o, vcx[o] if has_o else 0, vcy[o] if has_o else 0,
                          has_d, vcx[d] if has_d else 0, vcy[d] if has_d else 0, &part)
                if not part.has:
                    continue
                if part.start_at == AT_POINT:
                    pts[n_pts, 0] = part.sx; pts[n_pts, 1] = part.sy
                    pt_side[n_pts] = part.s_side
                    pt_a[n_pts] = a; pt_b[n_pts] = b; pt_c[n_pts] = -1
                    seg_start[h] = n_pts
                    n_pts += 1
                else:
                    seg_start[h] = o if part.start_at == AT_ORIGIN else d
                if part.end_at == AT_POINT:
                    pts[n_pts, 0] = part.ex; pts[n_pts, 1] = part.ey
                    pt_side[n_pts] = part.e_side
                    pt_a[n_pts] = a; pt_b[n_pts] = b; pt_c[n_pts] = -1
                    seg_end[h] = n_pts
                    n_pts += 1
                else:
                    seg_end[h] = o if part.end_at == AT_ORIGIN else d
                flags[h] = HAS | (ENTRY if part.entry else 0) | (EXIT if part.exit else 0)
                seg_start[tw] = seg_end[h]
                seg_end[tw] = seg_start[h]
                flags[tw] = HAS | (ENTRY if part.exit else 0) | (EXIT if part.entry else 0)

        corner0 = n_pts
        for k in range(4):
            pts[corner0 + k, 0] = box.kx[k]
            pts[corner0 + k, 1] = box.ky[k]
            pt_side[corner0 + k] = k
            pt_a[corner0 + k] = -1
        n_pts += 4
        P.xy = &pts[0, 0]
        P.side = pt_side
        P.da = pt_a
        P.db = pt_b
        P.dc = pt_c
        P.sx = &xs[0] if n > 0 else NULL
        P.sy = &ys[0] if n > 0 else NULL
        P.corner0 = corner0

    # each cell: walk its edges counter-clockwise, and the box boundary between exits and entries; the
    # cells are split into one run per thread, each writing into its own part of the buffer (room for
    # the worst case of every cell), the parts then moved together and the buffer cut to size in place
    cdef int64_t cap = 2 * n_he + 4 * n + 4
    ring_buf = np.empty(T * cap, np.int32)
    cdef int32_t[::1] ring = ring_buf
    cdef int64_t[::1] ends = np.zeros(T, np.int64)
    cdef int[::1] bent = np.zeros(T, np.intc)
    cdef int[::1] stat = np.zeros(T, np.intc)
    cdef CellPass S
    cdef int64_t shift
    S.he_origin = &he_origin[0] if n_he > 0 else NULL
    S.he_twin = &he_twin[0] if n_he > 0 else NULL
    S.n_he = n_he
    S.he_face = &he_face[0] if n_he > 0 else NULL
    S.face_edge = &face_edge[0] if n > 0 else NULL
    S.active = &active[0] if n > 0 else NULL
    turned_arr = np.zeros(max(n, 1), np.int8)
    cdef signed char[::1] turned = turned_arr
    S.turned = &turned[0]
    S.flags = &flags[0] if n_he > 0 else NULL
    S.seg_start = seg_start
    S.seg_end = seg_end
    S.box = &box
    S.P = &P
    S.in_band = True
    for k in range(T):
        S.in_band = S.in_band and off_band[k] == 0
    with nogil:
        if T == 1:
            ends[0] = clip_range(&S, 0, n, &ring[0], &offsets[0], 0, &bent[0], &stat[0])
        else:
            for k in prange(T, num_threads=T, schedule="static", chunksize=1):
                ends[k] = clip_range(&S, <int> (<int64_t> k * n // T), <int> (<int64_t> (k + 1) * n // T),
                                     &ring[0], &offsets[0], k * cap, &bent[k], &stat[k])
            n_ring = ends[0]
            for k in range(1, T):
                shift = k * cap - n_ring
                lo = <int> (<int64_t> k * n // T)
                hi = <int> (<int64_t> (k + 1) * n // T)
                memmove(&ring[n_ring], &ring[k * cap], (ends[k] - k * cap) * sizeof(int32_t))
                for i in range(lo, hi):
                    offsets[i] -= shift
                n_ring += ends[k] - k * cap
            ends[0] = n_ring
        n_ring = ends[0]
        offsets[n] = n_ring
        for k in range(T):
            n_bent += bent[k]
            status = max(status, stat[k])
    if status == 2:
        raise MemoryError("no memory for the edges of a cell")

    # no copies: the ring buffer is cut to its rings in place (no view of it is left), and points is a
    # view of a buffer with room for at least the crossings counted
    ring = None
    ring_buf.resize(max(n_ring, 1), refcheck=False)
    rings = ring_buf[:n_ring]
    points = pts_buf[:n_pts]
    offs = np.asarray(offsets)
    if n_bent:
        offs, rings = straighten(points, offs, rings, (xmin, ymin, xmax, ymax), candidates=turned_arr[:n])
    return points, offs, rings, status


cdef int vertex_codes(int lo, int hi, const double* vertices, const Box* box, signed char* vcx, signed char* vcy,
                      signed char* tie, signed char* v_in, int* off_band) noexcept nogil:
    # vertices lo..hi-1 against the box, by their rounded coordinates: codes, and 1 in v_in for those
    # in it; a coordinate equal to a side is a tie (marked 1, codes 0 until the exact test); returns the
    # count of ties. off_band: 1 if some coordinate is nonzero and outside turn()'s band of magnitudes
    cdef int v, n_ties = 0, off = 0
    cdef double x, y
    for v in range(lo, hi):
        if (v & 3) == 0:
            prefetch(<const char*> &vertices[2 * v] + AHEAD_BYTES)
        x = vertices[2 * v]
        y = vertices[2 * v + 1]
        off |= ((fabs(x) >= TURN_BAND_HIGH) | (fabs(y) >= TURN_BAND_HIGH)
                | ((x != 0.0) & (fabs(x) < TURN_BAND_LOW)) | ((y != 0.0) & (fabs(y) < TURN_BAND_LOW)))
        if x == box.xmin or x == box.xmax or y == box.ymin or y == box.ymax:
            tie[v] = 1
            n_ties += 1
            vcx[v] = 0
            vcy[v] = 0
            v_in[v] = 1
        else:
            vcx[v] = -2 if x < box.xmin else (2 if x > box.xmax else 0)
            vcy[v] = -2 if y < box.ymin else (2 if y > box.ymax else 0)
            v_in[v] = vcx[v] == 0 and vcy[v] == 0
    off_band[0] = off
    return n_ties


cdef int whole_edges(int lo, int hi, int n_he, const int32_t* he_origin, const int32_t* he_twin,
                     const int32_t* he_face, const int32_t* face_edge, const signed char* v_in,
                     signed char* flags, int32_t* cross) noexcept nogil:
    # half-edges lo..hi-1 with both ends in the box flagged whole (each on its own: its end is where the
    # next one of its cell starts, and the twin reaches the same verdict; v_in reads 0 at infinity, -1);
    # the other edges, each from its half-edge of smaller index (each makes at most two new points),
    # listed in increasing order from cross[lo] on; returns their count
    cdef int h, k, n_cross = 0
    for h in range(lo, hi):
        if (h & 15) == 0:
            prefetch(<const char*> &he_origin[h] + AHEAD_BYTES)
            prefetch(<const char*> &he_face[h] + AHEAD_BYTES)
            prefetch(<const char*> &he_twin[h] + AHEAD_BYTES)
        k = v_in[he_origin[h]] & v_in[he_origin[next_in_cell(h, n_he, he_face, face_edge)]]
        flags[h] = k * (HAS | WHOLE)
        if k == 0 and he_twin[h] > h:
            cross[lo + n_cross] = h
            n_cross += 1
    return n_cross


cdef class Scratch:
    """C buffers that a pass writes at a few places only, freed with this object. Not numpy's: numpy asks
    the kernel for 2 MiB pages on large arrays, and a few scattered writes would then make all of them
    resident."""
    cdef void* buf[8]
    cdef int count

    cdef void* take(self, size_t nbytes, bint zeroed) except NULL:
        assert self.count < 8, "Scratch holds at most 8 buffers"
        p = calloc(nbytes, 1) if zeroed else malloc(nbytes)
        if p == NULL:
            raise MemoryError()
        self.buf[self.count] = p
        self.count += 1
        return p

    def __dealloc__(self):
        cdef int k
        for k in range(self.count):
            free(self.buf[k])


cdef inline int next_in_cell(int h, int n_he, const int32_t* he_face, const int32_t* face_edge) noexcept nogil:
    # the half-edge after h around its cell: the following one while the face is the same, else the first
    if h + 1 < n_he and he_face[h + 1] == he_face[h]:
        return h + 1
    return face_edge[he_face[h]]


cdef inline int prev_in_cell(int h, int n_he, const int32_t* he_face, const int32_t* face_edge) noexcept nogil:
    # the half-edge before h around its cell (from the first, the cell's last)
    cdef int a = he_face[h]
    if h > face_edge[a]:
        return h - 1
    while h + 1 < n_he and he_face[h + 1] == a:
        h += 1
    return h


cdef struct CellPass:
    # what the walk over a run of cells reads
    const int32_t* he_origin
    const int32_t* he_twin
    int n_he
    const int32_t* he_face
    const int32_t* face_edge
    const signed char* active
    signed char* turned             # per cell: 1 where its finished ring turns right somewhere
    const signed char* flags
    const int32_t* seg_start
    const int32_t* seg_end
    Box* box
    Points* P
    bint in_band                    # every Voronoi vertex lies in turn()'s band (convex_ring)


cdef int64_t clip_range(CellPass* S, int lo, int hi, int32_t* ring, int64_t* offsets, int64_t n_ring,
                        int* n_bent, int* status) except -1 nogil:
    """The rings of cells lo..hi-1, written from ring[n_ring] on (offsets[i] is where cell i starts);
    returns the end. status: 1 if the edges of some cell did not chain, 2 if memory ran out. A signal
    handler's exception (interrupt.pxd, seen on the main thread) stops the run."""
    cdef CellEdges C
    C.cap = 0
    try:
        n_ring = clip_cells_of(S, lo, hi, ring, offsets, n_ring, n_bent, status, &C)
    finally:
        release(&C)
    return n_ring


cdef int64_t clip_cells_of(CellPass* S, int lo, int hi, int32_t* ring, int64_t* offsets, int64_t n_ring,
                           int* n_bent, int* status, CellEdges* C) except -1 nogil:
    cdef int i, h, cnt, k, b
    cdef const double* pts = S.P.xy
    for i in range(lo, hi):
        if ((i - lo) & POLL_MASK) == 0:
            poll_signals()
        offsets[i] = n_ring
        if not S.active[i]:
            continue
        # an interior cell: its vertices, already in order (the half-edges' arrays and the ring, read
        # and written in order, requested AHEAD_BYTES ahead)
        h = S.face_edge[i]
        prefetch(<const char*> &S.he_origin[h] + AHEAD_BYTES)
        prefetch(<const char*> &S.he_face[h] + AHEAD_BYTES)
        prefetch(&S.flags[h + AHEAD_BYTES])
        prefetch_write(<char*> &ring[n_ring] + AHEAD_BYTES)
        cnt = 0
        while h >= 0 and ((S.flags[h] & WHOLE) or (S.flags[h] == HAS and S.seg_start[h] == S.he_origin[h])):
            ring[n_ring + cnt] = S.he_origin[h]
            cnt += 1
            h = next_in_cell(h, S.n_he, S.he_face, S.face_edge)
            if h == S.face_edge[i]:
                break
        if h == S.face_edge[i] and cnt > 0:
            k = convex_ring(&ring[n_ring], cnt, pts, S.in_band)
            if k < 0:
                k = finish_ring(&ring[n_ring], cnt, pts)
                if k > 0 and first_right_turn(&ring[n_ring], k, pts) >= 0:
                    n_bent[0] += 1
                    S.turned[i] = 1
            n_ring += k
            continue
        # a cell that meets the box boundary: its edges' parts, then the walk
        h = S.face_edge[i]
        cnt = 0
        while h >= 0:
            cnt += 1
            h = next_in_cell(h, S.n_he, S.he_face, S.face_edge)
            if h == S.face_edge[i]:
                break
        if not room_for(C, cnt + 1):
            status[0] = 2
            break
        h = S.face_edge[i]
        cnt = 0
        while h >= 0:
            if S.flags[h] & WHOLE:
                C.start[cnt] = S.he_origin[h]
                C.end[cnt] = S.he_origin[S.he_twin[h]]
            else:
                C.start[cnt] = S.seg_start[h]
                C.end[cnt] = S.seg_end[h]
            C.has[cnt] = (S.flags[h] & HAS) != 0
            C.entry[cnt] = (S.flags[h] & ENTRY) != 0
            C.exit_[cnt] = (S.flags[h] & EXIT) != 0
            b = S.he_face[S.he_twin[h]]
            C.nbx[cnt] = S.P.sx[b]
            C.nby[cnt] = S.P.sy[b]
            cnt += 1
            h = next_in_cell(h, S.n_he, S.he_face, S.face_edge)
            if h == S.face_edge[i]:
                break
        k = walk_cell(S.box, cnt, C.start, C.end, C.entry, C.exit_, C.has,
                      S.P, S.P.sx[i], S.P.sy[i], C.nbx, C.nby, &ring[n_ring])
        if k < 0:
            status[0] = max(status[0], 1)
            continue
        k = finish_ring(&ring[n_ring], k, pts)
        if k > 0 and first_right_turn(&ring[n_ring], k, pts) >= 0:
            n_bent[0] += 1
            S.turned[i] = 1
        n_ring += k
    return n_ring


cdef struct CellEdges:
    # the edges of one cell that meets the box boundary, for walk_cell (grown as cells need)
    int cap
    int32_t* start
    int32_t* end
    signed char* entry
    signed char* exit_
    signed char* has
    double* nbx
    double* nby


cdef bint room_for(CellEdges* C, int k) noexcept nogil:
    # make room for k edges; False when memory runs out (C is then released)
    if k <= C.cap:
        return True
    k = max(k, 2 * C.cap, 64)
    release(C)
    C.start = <int32_t*> malloc(k * sizeof(int32_t))
    C.end = <int32_t*> malloc(k * sizeof(int32_t))
    C.entry = <signed char*> malloc(k)
    C.exit_ = <signed char*> malloc(k)
    C.has = <signed char*> malloc(k)
    C.nbx = <double*> malloc(k * sizeof(double))
    C.nby = <double*> malloc(k * sizeof(double))
    C.cap = k
    if (C.start == NULL or C.end == NULL or C.entry == NULL or C.exit_ == NULL or C.has == NULL
            or C.nbx == NULL or C.nby == NULL):
        release(C)
        return False
    return True


cdef void release(CellEdges* C) noexcept nogil:
    if C.cap > 0:
        free(C.start); free(C.end); free(C.entry); free(C.exit_); free(C.has); free(C.nbx); free(C.nby)


def rows_of_cells(const int32_t[::1] owner, const int32_t[::1] perm, const int32_t[::1] dup,
                  const signed char[::1] first, const int32_t[::1] face_edge, const int64_t[::1] offsets,
                  const int32_t[::1] ring, int threads=1):
    """The Diagram's row maps and its cells in input-row order, from the clipper's cells in engine order.

    Site k is input row perm[k]; its cell (first[k]: it has one) is held by row owner[k] (a repeated
    site k shows the cell of the owner of dup[k]); the clipper gave cell k as ring[offsets[k]:offsets[k + 1]].

    Returns (site_of, row_face_edge, cell_offsets, cell_vertices): the row holding each row's cell and
    each row's first half-edge (-1: none), (n,) int32 each; the CSR of the rows' cells, (n + 1,) int64 and
    (K,) int32. Two passes over the sites in engine order (the rings read in order, each row's entries
    written where it lies), on ``threads`` threads: the same arrays for any count (perm and the owners of
    first sites are one-to-one).
    """
    cdef Py_ssize_t n = perm.shape[0], k, r
    cdef int T = threads if n >= PARALLEL_MIN_CELLS and threads > 1 else 1
    cdef int32_t row
    cdef int64_t total = 0, length, lo, hi, dst, j
    site_of_arr = np.empty(n, np.int32)
    face_edge_arr = np.empty(n, np.int32)
    cell_offsets_arr = np.empty(n + 1, np.int64)
    cdef int32_t[::1] site_of = site_of_arr, row_face_edge = face_edge_arr
    cdef int64_t[::1] cell_offsets = cell_offsets_arr
    cell_offsets[0] = 0
    if n == 0:
        return site_of_arr, face_edge_arr, cell_offsets_arr, np.empty(0, np.int32)
    with nogil:
        # (written whole: faulted in by runs of pages, a part on each thread)
        # (site_of first the identity: a row holds its own cell unless its site repeats another or is
        # repeated by an earlier row, the few rows written in the pass below)
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            for r in range(k * n // T, (k + 1) * n // T):
                site_of[r] = <int32_t> r
            populate_part(&row_face_edge[0], n * sizeof(int32_t), <int> k, T)
            populate_part(&cell_offsets[1], n * sizeof(int64_t), <int> k, T)
            for r in range(k * n // T, (k + 1) * n // T):
                cell_offsets[r + 1] = 0
        # each row: the row holding its cell, and for a row holding one its first half-edge and its
        # ring's length, both in its entry of cell_offsets (one store a site: the half-edge plus one in
        # the high 32 bits); then, in row order, the half-edges moved out (-1 where none) and the
        # lengths summed into offsets
        # (the rows written to, asked for GATHER_AHEAD sites ahead; the arrays read in order, AHEAD_BYTES ahead)
        for k in prange(n, num_threads=T, schedule="static"):
            if (k & 7) == 0:
                prefetch(<const char*> &offsets[k] + AHEAD_BYTES)
                if (k & 15) == 0:
                    prefetch(<const char*> &perm[k] + AHEAD_BYTES)
                    prefetch(<const char*> &owner[k] + AHEAD_BYTES)
                    prefetch(<const char*> &dup[k] + AHEAD_BYTES)
                    prefetch(<const char*> &face_edge[k] + AHEAD_BYTES)
            if k + GATHER_AHEAD < n and first[k + GATHER_AHEAD]:
                prefetch_write(&cell_offsets[owner[k + GATHER_AHEAD] + 1])
            r = dup[k] if dup[k] >= 0 else k
            if owner[r] != perm[k]:
                site_of[perm[k]] = owner[r]
            if first[k]:
                cell_offsets[owner[k] + 1] = ((<int64_t> face_edge[k] + 1) << 32) | (offsets[k + 1] - offsets[k])
        for r in range(n):
            length = cell_offsets[r + 1]
            row_face_edge[r] = <int32_t> ((length >> 32) - 1)
            length = length & <int64_t> 0xFFFFFFFF
            total += length
            cell_offsets[r + 1] = total
    vertices_arr = np.empty(total, np.int32)
    cdef int32_t[::1] out = vertices_arr
    cdef int32_t* out_p = &out[0] if total > 0 else NULL
    cdef const int32_t* ring_p = &ring[0] if ring.shape[0] > 0 else NULL
    with nogil:
        for k in prange(T, num_threads=T, schedule="static", chunksize=1):
            populate_part(out_p, total * sizeof(int32_t), <int> k, T)
        # the rings, read in engine order, each written at its row's place (that place's offset is
        # loaded GATHER_AHEAD sites ahead, so that the store seldom waits for it)
        for k in prange(n, num_threads=T, schedule="static"):
            if (k & 7) == 0:
                prefetch(<const char*> &offsets[k] + AHEAD_BYTES)
                if (k & 15) == 0:
                    prefetch(<const char*> &owner[k] + AHEAD_BYTES)
            if k + 2 * GATHER_AHEAD < n and first[k + 2 * GATHER_AHEAD]:
                prefetch(&cell_offsets[owner[k + 2 * GATHER_AHEAD]])
            if k + GATHER_AHEAD < n and first[k + GATHER_AHEAD]:
                prefetch_write(&out_p[cell_offsets[owner[k + GATHER_AHEAD]]])
                prefetch(&ring_p[offsets[k + GATHER_AHEAD]])
            if first[k]:
                lo = offsets[k]
                hi = offsets[k + 1]
                dst = cell_offsets[owner[k]]
                if 4 <= hi - lo <= 8:
                    # (most rings: two moves of four entries, the second ending at the ring's end, with
                    # no loop whose length a predictor would miss)
                    memcpy(&out_p[dst], &ring_p[lo], 16)
                    memcpy(&out_p[dst + (hi - lo) - 4], &ring_p[hi - 4], 16)
                else:
                    for j in range(hi - lo):
                        out_p[dst + j] = ring_p[lo + j]
    return site_of_arr, face_edge_arr, cell_offsets_arr, vertices_arr


def relabel(const int32_t[::1] label, int32_t[::1] ids, int threads=1):
    """ids[k] = label[ids[k]] in place (engine sites to input rows in the Diagram's arrays), with no
    index copy; ids must lie in [0, len(label)). The same result for any thread count."""
    cdef Py_ssize_t k, count = ids.shape[0], n_label = label.shape[0]
    cdef int T = threads if count >= (1 << 18) and threads > 1 else 1
    with nogil:
        for k in prange(count, num_threads=T, schedule="static"):
            if (k & 15) == 0:
                prefetch_write(<char*> &ids[k] + AHEAD_BYTES)
            if 0 <= ids[k] < n_label:
                ids[k] = label[ids[k]]
            else:
                ids[k] = -1
    return np.asarray(ids)


cdef struct Sides:
    double xmin, ymin, xmax, ymax


cdef Sides sides(box_tuple):
    # the box (x0, y0, x1, y1) as doubles
    cdef Sides box
    x0, y0, x1, y1 = box_tuple
    box.xmin = float(x0)
    box.ymin = float(y0)
    box.xmax = float(x1)
    box.ymax = float(y1)
    return box


def straighten(const double[:, ::1] points, offsets, rings, box_tuple, signed char[::1] was_bent=None,
               candidates=None):
    """Make every ring a simple polygon again where rounding made it cross itself (degenerate case: a
    cell thinner than the rounding near a vertex, so that the vertex rounded across the line of its
    neighbours and an edge of the ring crosses another).

    In a ring that is not simple, each vertex at a right turn is merged with the nearer of its two
    ring neighbours, in every ring that has it (so neighbouring cells keep matching edges); merges keep
    the point that is a corner of the box (x0, y0, x1, y1), else one on its boundary, else the lowest
    (y, then x). Points are named by their values (every point equal to a point of a bent ring is that
    point), so the result depends on the values alone, not on an engine's numbering. Repeats until
    every ring is simple: every cell is then a simple counter-clockwise polygon, and such a subdivision
    covers the box exactly once. A cell can vanish (all its vertices merged): a cell thinner than the
    rounding everywhere.

    was_bent: optional (cells,) int8, set to 1 for every ring found bent in some round.
    candidates: optional (cells,) int8, 1 for the rings that may be bent (those with a right turn; the
    others are not looked at in the first round). After a round only the rings it changed, and those
    it found bent, are looked at again: a ring's verdict reads its own points alone.
    Returns the new (offsets, rings).
    """
    cdef Py_ssize_t n_pts = points.shape[0]
    cdef Sides box = sides(box_tuple)
    parent_arr = np.arange(n_pts, dtype=np.int32)
    cdef int32_t[::1] parent = parent_arr
    cdef int32_t[::1] names
    cdef const double* xy = &points[0, 0]
    cdef int32_t[::1] rv
    cdef int64_t[::1] ov
    cdef int n_cells = len(offsets) - 1, i, j, k, cnt, v, u, w, t, changed, guard, n_bent
    cdef int32_t[::1] bent_at
    cdef signed char[::1] look = (np.ones(max(n_cells, 1), np.int8) if candidates is None
                                  else np.array(candidates, np.int8))
    cdef int32_t[::1] before_remap
    cdef int64_t lo, hi
    cdef double du, dw
    for guard in range(n_pts):
        rv = rings
        ov = offsets
        changed = 0
        bent_arr = np.empty(n_cells, np.int32)
        bent_at = bent_arr
        n_bent = 0
        for i in range(n_cells):
            if look[i] and ov[i + 1] > ov[i] and bent(&rv[ov[i]], <int> (ov[i + 1] - ov[i]), xy):
                bent_at[n_bent] = i
                n_bent += 1
        if n_bent == 0:
            break
        if was_bent is not None:
            for k in range(n_bent):
                was_bent[bent_at[k]] = 1
        # every point equal to a point of a bent ring is that point (exact vertices closer than rounding
        # with no edge between them, a crossing on a vertex): whichever of them a ring's walk met
        names = value_names(points, np.concatenate([rings[offsets[i]:offsets[i + 1]] for i in bent_arr[:n_bent].tolist()]))
        for v in range(n_pts):
            if names[v] != v:
                changed += join(&parent[0], xy, &box, v, names[v])
        # merge each right-turn vertex with its nearer ring neighbour
        for j in range(n_bent):
            i = bent_at[j]
            lo = ov[i]
            cnt = <int> (ov[i + 1] - lo)
            for k in range(cnt):
                v = rv[lo + k]
                u = rv[lo + (k + cnt - 1) % cnt]
                w = rv[lo + (k + 1) % cnt]
                if turn(xy, u, v, w) >= 0:
                    continue
                # hypot: no overflow of the squares on boxes up to 2^1000 times the sites
                du = hypot(xy[2 * u] - xy[2 * v], xy[2 * u + 1] - xy[2 * v + 1])
                dw = hypot(xy[2 * w] - xy[2 * v], xy[2 * w + 1] - xy[2 * v + 1])
                t = u if (du < dw or (du == dw and before(xy, &box, u, w))) else w
                changed += join(&parent[0], xy, &box, v, t)
        if changed == 0:
            break
        # every ring through a merged point, again; the next round looks at the rings this one changed
        # and at those it found bent
        for v in range(n_pts):
            parent[v] = find(&parent[0], v)
        before_remap = rings
        rings = parent_arr[rings]
        rv = rings
        for i in range(n_cells):
            look[i] = 0
            for lo in range(ov[i], ov[i + 1]):
                if rv[lo] != before_remap[lo]:
                    look[i] = 1
                    break
        for j in range(n_bent):
            look[bent_at[j]] = 1
        new_rings = np.empty_like(rings)
        new_offsets = np.zeros_like(offsets)
        rv = rings
        ov = offsets
        nv = new_rings
        cdef_fill(ov, rv, new_offsets, nv, xy)
        offsets = new_offsets
        rings = new_rings[:new_offsets[-1]].copy()
    return offsets, rings


cdef inline int kind_of(const double* xy, Sides* box, int p) noexcept nogil:
    # 0 a corner of the box, 1 on a side, 2 inside: the order in which merges keep points
    cdef bint on_x = xy[2 * p] == box.xmin or xy[2 * p] == box.xmax
    cdef bint on_y = xy[2 * p + 1] == box.ymin or xy[2 * p + 1] == box.ymax
    return 0 if (on_x and on_y) else (1 if (on_x or on_y) else 2)


cdef inline int join(int32_t* parent, const double* xy, Sides* box, int p, int q) noexcept nogil:
    # one set of p and q, under the point kept (before); 1 if they were apart
    cdef int rp = find(parent, p), rq = find(parent, q)
    if rp == rq:
        return 0
    if before(xy, box, rp, rq):
        parent[rq] = rp
    else:
        parent[rp] = rq
    return 1


def point_kinds(const double[:, ::1] points, box_tuple):
    """Per point, by its value: 0 a corner of the box (x0, y0, x1, y1), 1 on a side, 2 inside (the
    order in which straighten keeps points; for tests)."""
    cdef Sides box = sides(box_tuple)
    out = np.empty(points.shape[0], np.int8)
    cdef signed char[::1] o = out
    cdef Py_ssize_t p
    for p in range(points.shape[0]):
        o[p] = kind_of(&points[0, 0], &box, <int> p)
    return out


def value_names(const double[:, ::1] points, keys=None):
    """name[p]: the first point with the same value as point p (signed zeros equal), by one pass over
    a hash table: the names depend on the values alone, not on which of equal points a ring holds.
    keys: optional point numbers; then only values held by one of them are named (the table holds
    those alone), every other point is its own name."""
    cdef Py_ssize_t n = points.shape[0], n_keys, size = 16, p, q, slot, k
    cdef const int32_t[::1] kv
    n_keys = n if keys is None else len(keys)
    while size < 2 * n_keys:
        size *= 2
    names_arr = np.empty(n, np.int32)
    table_arr = np.full(size, -1, np.int32)      # a point holding the value (a key), or -1
    first_arr = np.full(size, -1, np.int32)      # the first point in order with it, once seen
    cdef int32_t[::1] name = names_arr
    cdef int32_t[::1] table = table_arr
    cdef int32_t[::1] first = first_arr
    cdef bint all_points = keys is None
    if not all_points:
        kv = np.ascontiguousarray(keys, np.int32)
    with nogil:
        if not all_points:
            for k in range(n_keys):
                slot = value_slot(&points[0, 0], kv[k], &table[0], size)
                if table[slot] < 0:
                    table[slot] = kv[k]
        for p in range(n):
            name[p] = <int32_t> p
            if all_points:
                slot = value_slot(&points[0, 0], <int> p, &table[0], size)
                if table[slot] < 0:
                    table[slot] = <int32_t> p
            else:
                slot = value_slot(&points[0, 0], <int> p, &table[0], size)
                if table[slot] < 0:
                    continue
            if first[slot] < 0:
                first[slot] = <int32_t> p
            name[p] = first[slot]
    return names_arr


cdef inline Py_ssize_t value_slot(const double* xy, int p, const int32_t* table, Py_ssize_t size) noexcept nogil:
    # the slot of p's value: the one holding a point of that value, or the empty one where it would go
    cdef double x = xy[2 * p] + 0.0, y = xy[2 * p + 1] + 0.0      # -0.0 + 0.0 is +0.0: one key for both
    cdef uint64_t bx, by
    cdef Py_ssize_t slot
    cdef int q
    memcpy(&bx, &x, 8)
    memcpy(&by, &y, 8)
    bx = (bx ^ (by * <uint64_t> 0x9E3779B97F4A7C15)) * <uint64_t> 0xC2B2AE3D27D4EB4F
    slot = <Py_ssize_t> ((bx ^ (bx >> 29)) & <uint64_t> (size - 1))
    while table[slot] >= 0:
        q = table[slot]
        if xy[2 * q] == x and xy[2 * q + 1] == y:
            return slot
        slot = (slot + 1) & (size - 1)
    return slot


cdef void cdef_fill(const int64_t[::1] ov, int32_t[::1] rv, int64_t[::1] new_offsets, int32_t[::1] nv,
                    const double* xy):
    cdef int i, k, n_cells = ov.shape[0] - 1
    cdef int64_t out = 0, lo
    for i in range(n_cells):
        new_offsets[i] = out
        lo = ov[i]
        k = <int> (ov[i + 1] - lo)
        for j in range(k):
            nv[out + j] = rv[lo + j]
        out += finish_ring(&nv[out], k, xy)
    new_offsets[n_cells] = out


cdef inline bint before(const double* xy, Sides* box, int p, int q) noexcept nogil:
    # the point kept when p and q merge: a corner, else on the boundary, else the lowest (y, then x)
    cdef int kp = kind_of(xy, box, p), kq = kind_of(xy, box, q)
    if kp != kq:
        return kp < kq
    if xy[2 * p + 1] != xy[2 * q + 1]:
        return xy[2 * p + 1] < xy[2 * q + 1]
    if xy[2 * p] != xy[2 * q]:
        return xy[2 * p] < xy[2 * q]
    return p < q


cdef inline int find(int32_t* parent, int p) noexcept nogil:
    cdef int root = p, up
    while parent[root] != root:
        root = parent[root]
    while parent[p] != root:
        up = parent[p]
        parent[p] = root
        p = up
    return root


def finished_ring(const double[:, ::1] points, ring) -> np.ndarray:
    """finish_ring (clipper.pxd) of a ring of point numbers: the repeats and spikes dropped, from the
    lowest point (for tests)."""
    out = np.array(ring, np.int32)
    cdef int32_t[::1] r = out
    cdef int k = finish_ring(&r[0], <int> len(out), &points[0, 0]) if len(out) else 0
    return out[:k]


def bisector_crossing(double ax, double ay, double bx, double by, double t, bint along_y, int e=0) -> float:
    """Where the bisector of sites a and b crosses the line x = t (returns its y) or, with along_y,
    the line y = t (returns its x): the correctly rounded value, times 2^e (for tests)."""
    return bisector_at(ax, ay, bx, by, t, along_y, e)


def ring_turn(double ax, double ay, double bx, double by, double cx, double cy) -> int:
    """The clipper's orientation of three ring points (+1 left, -1 right, 0 collinear), exact at any
    magnitudes (for tests)."""
    cdef double p[6]
    p[0] = ax; p[1] = ay; p[2] = bx; p[3] = by; p[4] = cx; p[5] = cy
    return turn(p, 0, 1, 2)
