# Fortune's event queue (fortune.pyx): pending circle events in a binary heap, ordered exactly by the top of
# their circles (circle_events.pxd: a double filter, the rises above the highest site, a double-double filter, then
# exact integers in event_order_exact.pxd), and the exact choice between the next site and the first
# circle event. Inline helpers, compiled into the fortune module.
#
# The heap holds only a window of the events: those whose interval's low end lies in the first strips of y
# (buckets 0 .. bucket_now of n_buckets strips of equal height over the sites' y); the others wait in their
# strip's bucket, a linked list, and are moved to the heap when the window grows to their strip. Most
# events are scheduled far above the sweep line and many are cancelled or rescheduled before it gets there:
# in a bucket that costs a few stores, in a heap of every pending event a sift through its levels, whose
# comparisons no branch predictor foresees. The order is the heap's, exactly: an event outside the window
# has its whole interval above every point of the window's strips, so the first event of the heap is the
# first of all once its interval's high end lies in the window too (queue_next), and a site whose y lies
# in the window comes before every event outside it.
#
# Bucket of a value v: floor((v - bucket_y0) * bucket_scale), clamped to 0 .. n_buckets - 1, a function that
# never decreases as v grows (each rounded operation is monotone). bucket_low places an interval's low end
# (NaN: bucket 0, the window), bucket_high an upper bound (NaN: the last bucket, never in the window before
# the end); bucket_low <= bucket_high everywhere. If lo_e, an event's low end outside the window
# (bucket_low(lo_e) > bucket_now), were <= v with bucket_high(v) <= bucket_now, then bucket_low(lo_e) <=
# bucket_low(v) <= bucket_high(v) <= bucket_now: so every such v lies strictly below every outside event.

from tvoronoi.kernels.sweep_state cimport Sweep, NONE
# the slow paths (near ties: filters, then exact integers) are ordinary functions of fortune.pyx, kept out
# of line so that the common comparison stays a few instructions
from tvoronoi.kernels.fortune cimport ev_less_near, site_first_near, queue_grow

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
    """Event i comes before event j: by the top of its circle (exact), then by the centre's rounded x, then
    by the sites (fortune.ev_less_near)."""
    if s.ev_span[2 * i + 1] < s.ev_span[2 * j]:
        return True
    if s.ev_span[2 * j + 1] < s.ev_span[2 * i]:
        return False
    if s.ev_class[i] == s.ev_class[j] and s.ev_x[i] != s.ev_x[j]:
        return s.ev_x[i] < s.ev_x[j]     # (tops known equal: a lattice's row, compared again and again)
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


cdef inline void heap_take(Sweep* s, int k) noexcept nogil:
    """Take the event at heap slot k out of the heap (it stays an event)."""
    s.n_heap -= 1
    if k < s.n_heap:
        heap_set(s, k, s.heap[s.n_heap])
        heap_fix(s, k)


# ---------------------------------------------------------------------------------------------------------
# the buckets beyond the heap's window

cdef inline int bucket_low(Sweep* s, double v) noexcept nogil:
    """The bucket of an interval's low end v (NaN: 0)."""
    cdef double f = (v - s.bucket_y0) * s.bucket_scale
    cdef int top = s.n_buckets - 1
    if not f > 0.0:
        return 0
    if f >= top:
        return top
    return <int> f


cdef inline int bucket_high(Sweep* s, double v) noexcept nogil:
    """The bucket of an upper bound v (NaN: the last)."""
    cdef double f = (v - s.bucket_y0) * s.bucket_scale
    cdef int top = s.n_buckets - 1
    if not f < top:
        return top
    if not f > 0.0:
        return 0
    return <int> f


cdef inline void bucket_link(Sweep* s, int ev, int b) noexcept nogil:
    cdef int first = s.bucket_head[b]
    s.ev_link[2 * ev] = first
    s.ev_link[2 * ev + 1] = NONE
    if first != NONE:
        s.ev_link[2 * first + 1] = ev
    s.bucket_head[b] = ev
    s.ev_pos[ev] = -2 - b
    s.n_bucketed += 1


cdef inline void bucket_unlink(Sweep* s, int ev) noexcept nogil:
    cdef int after = s.ev_link[2 * ev], before = s.ev_link[2 * ev + 1]
    if before != NONE:
        s.ev_link[2 * before] = after
    else:
        s.bucket_head[-2 - s.ev_pos[ev]] = after
    if after != NONE:
        s.ev_link[2 * after + 1] = before
    s.n_bucketed -= 1


# ---------------------------------------------------------------------------------------------------------
# the queue: heap and buckets

cdef inline void queue_add(Sweep* s, int ev) noexcept nogil:
    """A new event (its interval set): to the heap if its low end lies in the window, else to its bucket."""
    cdef int b = bucket_low(s, s.ev_span[2 * ev])
    if b <= s.bucket_now:
        heap_push(s, ev)
    else:
        bucket_link(s, ev, b)


cdef inline void queue_update(Sweep* s, int ev) noexcept nogil:
    """Event ev, still queued, has a new interval: to its new place."""
    cdef int b = bucket_low(s, s.ev_span[2 * ev]), k = s.ev_pos[ev]
    if k >= 0:
        if b <= s.bucket_now:
            heap_fix(s, k)
        else:
            heap_take(s, k)
            bucket_link(s, ev, b)
    elif b <= s.bucket_now:
        bucket_unlink(s, ev)
        heap_push(s, ev)
    elif b != -2 - k:
        bucket_unlink(s, ev)
        bucket_link(s, ev, b)


cdef inline void heap_remove(Sweep* s, int ev) noexcept nogil:
    """Take event ev out of the queue (heap or bucket) and free its slot."""
    cdef int k = s.ev_pos[ev]
    if k >= 0:
        heap_take(s, k)
    else:
        bucket_unlink(s, ev)
    s.free_events[s.n_free_ev] = ev
    s.n_free_ev += 1


cdef enum:
    SITE_NEXT = -2


cdef inline int queue_next(Sweep* s, int i) noexcept nogil:
    """What comes next: SITE_NEXT (site i, when i < n), the first circle event, or NONE when nothing is
    left. Decided here when the next site lies in the window, or the heap's first event's interval
    does (see the top of this file); else the window grows (queue_grow, out of line)."""
    if i < s.n and bucket_high(s, s.y[i]) <= s.bucket_now:
        if s.n_heap == 0 or site_first(s, i, s.heap[0]):
            return SITE_NEXT
        return s.heap[0]
    if s.n_heap > 0 and bucket_high(s, s.ev_span[2 * s.heap[0] + 1]) <= s.bucket_now:
        return s.heap[0]
    return queue_grow(s, i)


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
