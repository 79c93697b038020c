# Fortune's event queue (fortune.pyx): pending circle events in a binary heap, ordered exactly by the top of
# their circles (circle_events.pxd: a double filter, the rises above the highest site, a double-double filter, then
# exact integers in event_order_exact.pxd), and the exact choice between the next site and the first
# circle event. Inline helpers, compiled into the fortune module.

from tvoronoi.kernels.sweep_state cimport Sweep, NONE
# the slow paths (near ties: filters, then exact integers) are ordinary functions of fortune.pyx, kept out
# of line so that the common comparison stays a few instructions
from tvoronoi.kernels.fortune cimport ev_less_near, site_first_near

# ---------------------------------------------------------------------------------------------------------
# the exact order of events

cdef inline void event_sites(Sweep* s, int ev, double* tri) noexcept nogil:
    """The coordinates of the three sites of event ev (the arc and its two neighbours when it was
    scheduled, counter-clockwise: an event taken from its arc keeps its order until it is rescheduled)."""
    cdef int a = s.ev_sites[3 * ev], b = s.ev_sites[3 * ev + 1], c = s.ev_sites[3 * ev + 2]
    tri[0] = s.x[a]; tri[1] = s.y[a]
    tri[2] = s.x[b]; tri[3] = s.y[b]
    tri[4] = s.x[c]; tri[5] = s.y[c]


cdef inline bint ev_less(Sweep* s, int i, int j) noexcept nogil:
    """Event i comes before event j: by the top of its circle (exact), then by the centre's rounded x."""
    if s.ev_span[2 * i + 1] < s.ev_span[2 * j]:
        return True
    if s.ev_span[2 * j + 1] < s.ev_span[2 * i]:
        return False
    return ev_less_near(s, i, j)


cdef inline bint site_first(Sweep* s, int i, int ev) noexcept nogil:
    """Site i comes before circle event ev: y_i <= top(ev), exactly (a site first at a tie)."""
    if s.y[i] <= s.ev_span[2 * ev]:
        return True
    if s.y[i] > s.ev_span[2 * ev + 1]:
        return False
    return site_first_near(s, i, ev)


cdef inline void heap_set(Sweep* s, int k, int ev) noexcept nogil:
    s.heap[k] = ev
    s.ev_pos[ev] = k


cdef inline void sift_up(Sweep* s, int k) noexcept nogil:
    cdef int ev = s.heap[k], up
    while k > 0:
        up = (k - 1) // 2
        if not ev_less(s, ev, s.heap[up]):
            break
        heap_set(s, k, s.heap[up])
        k = up
    heap_set(s, k, ev)


cdef inline void sift_down(Sweep* s, int k) noexcept nogil:
    cdef int ev = s.heap[k], c
    while True:
        c = 2 * k + 1
        if c >= s.n_heap:
            break
        if c + 1 < s.n_heap and ev_less(s, s.heap[c + 1], s.heap[c]):
            c += 1
        if not ev_less(s, s.heap[c], ev):
            break
        heap_set(s, k, s.heap[c])
        k = c
    heap_set(s, k, ev)


cdef inline void heap_push(Sweep* s, int ev) noexcept nogil:
    s.heap[s.n_heap] = ev
    s.ev_pos[ev] = s.n_heap
    s.n_heap += 1
    sift_up(s, s.n_heap - 1)


cdef inline void heap_fix(Sweep* s, int k) noexcept nogil:
    """The event at heap slot k has a new position in the order: up or down to its place."""
    if k > 0 and ev_less(s, s.heap[k], s.heap[(k - 1) // 2]):
        sift_up(s, k)
    else:
        sift_down(s, k)


cdef inline void heap_remove(Sweep* s, int ev) noexcept nogil:
    """Take event ev out of the heap and free its slot."""
    cdef int k = s.ev_pos[ev]
    s.n_heap -= 1
    if k < s.n_heap:
        heap_set(s, k, s.heap[s.n_heap])
        heap_fix(s, k)
    s.free_events[s.n_free_ev] = ev
    s.n_free_ev += 1


cdef inline void cancel_event(Sweep* s, int arc) noexcept nogil:
    if s.arc_event[arc] != NONE:
        heap_remove(s, s.arc_event[arc])
        s.arc_event[arc] = NONE


cdef inline int take_event(Sweep* s, int arc) noexcept nogil:
    """The arc's pending event (NONE if none), taken from the arc but left in the heap for check_circle
    to reschedule in place or remove: one heap operation where a removal and a push were two."""
    cdef int ev = s.arc_event[arc]
    s.arc_event[arc] = NONE
    return ev
