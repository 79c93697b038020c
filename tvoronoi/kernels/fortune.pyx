"""Fortune's sweepline: site and circle events, the beach line in an AVL tree, the result as a triangulation.

Where each phase lives: the sweep's state in sweep_state.pxd, the beach line (AVL tree, locating a site) in
beach_line.pxd, the event queue and its exact order in event_queue.pxd, the top of a circle event and its
filters in circle_events.pxd, the exact integer fallback in event_order_exact.pxd; here the events
themselves, closing the hull, the guard repair and the Python entries.
"""

import numpy as np

from libc.stdint cimport int8_t, int32_t, int64_t
from libc.math cimport sqrt, INFINITY
from libc.stdlib cimport malloc, free

from tvoronoi.kernels.interrupt cimport poll_signals, POLL_MASK
from tvoronoi.kernels.populate cimport populate

from tvoronoi.kernels.predicates cimport orient2d, incircle, incircle_filter
from tvoronoi.kernels.mesh cimport nxt, prv
from tvoronoi.kernels.circle_events cimport (
    circle_top, circle_top_fast, relative_sign, circle_top_fine, fine_order, fine_site,
)
from tvoronoi.kernels.event_order_exact cimport same_top_by_shift, translates, tvb_site_first, tvb_top_order
from tvoronoi.kernels.sweep_state cimport (
    Sweep, NONE, EVENT_SITE, EVENT_CIRCLE, EVENT_REPEAT, FINE_UNKNOWN, FINE_OK, FINE_NONE, FINE_MASK, RISE_KNOWN,
    OK, BROKEN, NO_MEMORY, NO_REPAIR,
)
from tvoronoi.kernels.beach_line cimport (
    new_arc, insert_after, remove_arc, locate_hinted, set_hint, LONG_WALK_STEPS_PER_SITE, LONG_WALK_STEPS_BASE,
)
from tvoronoi.kernels.event_queue cimport (
    event_sites, heap_push, heap_remove, site_first, cancel_event, take_event, queue_add, queue_update, queue_next,
    bucket_high, SITE_NEXT,
)

# The sweep line y = L moves upwards; sites are numbered in event order
# (by y, then x). Each arc of the beach line is a node of an AVL tree (in
# arrays) and of a doubly linked list, left to right. A breakpoint between an
# arc and the next one traces a Voronoi edge; each edge has a record that
# collects the (at most two) Delaunay half-edges on its sides.
#
# The result is written as the sweep goes in the dual form the incremental
# engine also builds: each circle event is a Voronoi vertex, stored as the
# Delaunay triangle of its three sites, and the records link the triangles
# into a half-edge structure (tv, opp, with vertex n at infinity closing the
# hull). dual.voronoi_from_delaunay turns it into the Voronoi DCEL.
#
# Every decision is exact: which arc a site falls on (parabola_order and
# coordinate comparisons), whether three arcs converge (orient2d), and the
# order of events (circle_events.pxd: a rounded top of each circle with a
# proven error bound; near ties by the rise above the highest site, then in
# double-double precision, then in exact integers, event_order_exact.pxd). At an
# exact tie a site comes before a circle event, and circle events with equal
# tops go by their rounded centre x, then by their sites (a strict order): events
# at one height with different centres share no arc and commute, events at one
# centre are cocircular sites, any order of which gives a triangulation of their
# group (the dual merges it). A final pass of exact Lawson flips stays as a
# guard; it finds nothing to flip when the order is exact.
#
# The kernel never trusts its own state blindly: every array has its bound
# checked before a write, and an inconsistent state (which exact decisions
# should make impossible) stops the sweep with a status code that the Python
# layer turns into a TvoronoiError.


STATUS_OK = OK
STATUS_BROKEN = BROKEN
STATUS_NO_MEMORY = NO_MEMORY
STATUS_NO_REPAIR = NO_REPAIR
STATUS_MESSAGES = {
    BROKEN: "Fortune's sweep reached an inconsistent state",
    NO_MEMORY: "Fortune's sweep ran out of memory in its exact arithmetic",
    NO_REPAIR: "Fortune's sweep: the exact repair did not converge",
}


# ---------------------------------------------------------------------------------------------------------
# the event order at near ties (event_queue.pxd settles the rest): the rises above the highest sites, the
# double-double filter, then exact integers

cdef void event_rise(Sweep* s, int ev, double* base, double* rise, double* rise_err) noexcept nogil:
    """The top of event ev as base + rise (within rise_err): computed once, when a near tie needs it."""
    cdef double tri[6]
    cdef double top, lo, hi, centre_x, centre_y
    if not (s.ev_fine_state[ev] & RISE_KNOWN):
        event_sites(s, ev, tri)
        circle_top(tri[0], tri[1], tri[2], tri[3], tri[4], tri[5], &top, &lo, &hi,
                   &s.ev_rise[3 * ev], &s.ev_rise[3 * ev + 1], &s.ev_rise[3 * ev + 2], &centre_x, &centre_y)
        s.ev_fine_state[ev] |= RISE_KNOWN
    base[0] = s.ev_rise[3 * ev]
    rise[0] = s.ev_rise[3 * ev + 1]
    rise_err[0] = s.ev_rise[3 * ev + 2]


cdef bint fine_top(Sweep* s, int ev) noexcept nogil:
    """The double-double top of event ev (computed once, when first needed); False if unavailable."""
    cdef double tri[6]
    if (s.ev_fine_state[ev] & FINE_MASK) == FINE_UNKNOWN:
        s.n_fine_tops += 1
        event_sites(s, ev, tri)
        if circle_top_fine(tri[0], tri[1], tri[2], tri[3], tri[4], tri[5], &s.ev_fine[3 * ev]):
            s.ev_fine_state[ev] |= FINE_OK
        else:
            s.ev_fine_state[ev] |= FINE_NONE
    return (s.ev_fine_state[ev] & FINE_MASK) == FINE_OK


cdef int top_order_exact(Sweep* s, int i, int j) noexcept nogil:
    """Sign of top(i) - top(j), exactly (the intervals of the two events overlap)."""
    cdef double ti[6]
    cdef double tj[6]
    cdef int c
    cdef double base_i, rise_i, err_i, base_j, rise_j, err_j
    # near tie: the rises above the sites, the double-double filter, then exact integers
    s.n_near += 1
    if s.ev_y[i] == s.ev_y[j]:
        # first the degenerate case of a lattice: congruent circles side by side (one rounded top)
        event_sites(s, i, ti)
        event_sites(s, j, tj)
        if translates(ti, tj):
            return 0
    event_rise(s, i, &base_i, &rise_i, &err_i)
    event_rise(s, j, &base_j, &rise_j, &err_j)
    c = relative_sign(base_i, rise_i, err_i, base_j, rise_j, err_j)
    if c != 0:
        return c
    # a tie the rises leave is most often an exact one: one circle (two triples of a cocircular group),
    # or congruent circles side by side (a lattice), which the double-double filter could not separate
    # either; an exact test that costs less than the two fine tops it spares
    event_sites(s, i, ti)
    event_sites(s, j, tj)
    if same_top_by_shift(ti, tj):
        return 0
    s.n_fine_tests += 1
    if fine_top(s, i) and fine_top(s, j):
        c = fine_order(&s.ev_fine[3 * i], &s.ev_fine[3 * j])
        if c != 0:
            return c
    s.n_exact_circle += 1
    c = tvb_top_order(ti, tj)
    if c == 2:
        s.status = NO_MEMORY
        return 0
    return c


cdef inline bint sites_less(const int32_t* p, const int32_t* q) noexcept nogil:
    # the triples (a, b, c) of two events, by b, then a, then c
    if p[1] != q[1]:
        return p[1] < q[1]
    if p[0] != q[0]:
        return p[0] < q[0]
    return p[2] < q[2]


cdef bint ev_less_near(Sweep* s, int i, int j) noexcept nogil:
    """ev_less when the two events' intervals overlap: the exact sign, then the centre's rounded x, then
    the sites."""
    cdef int c = 0
    if s.ev_class[i] != s.ev_class[j]:
        c = top_order_exact(s, i, j)
        if c != 0:
            return c < 0
        # equal tops: remembered, so that the next comparison of the two (a heap compares the events of
        # a lattice's row with each other again and again) costs nothing. Equality is transitive: both
        # take the older class, so a row's events gather into its first event's class
        if s.ev_class[i] < s.ev_class[j]:
            s.ev_class[j] = s.ev_class[i]
        else:
            s.ev_class[i] = s.ev_class[j]
    # equal tops: different centres share no arc (the events commute), one centre is a cocircular group
    # (any order of its events triangulates it); the centres' rounded x, then the sites make the order
    # strict, so that the sweep is the same whatever structure holds the events (event_queue.pxd): two
    # pending events never have the same three sites (a beach line never holds a..b..a..b)
    if s.ev_x[i] != s.ev_x[j]:
        return s.ev_x[i] < s.ev_x[j]
    return sites_less(&s.ev_sites[3 * i], &s.ev_sites[3 * j])


cdef bint site_first_near(Sweep* s, int i, int ev) noexcept nogil:
    """site_first when y_i lies in the event's interval."""
    cdef double yi = s.y[i]
    cdef double tri[6]
    cdef double base, rise, err
    cdef int r
    # near tie: the rise above the event's site, the double-double filter, then exact integers
    s.n_near += 1
    event_rise(s, ev, &base, &rise, &err)
    r = relative_sign(base, rise, err, yi, 0.0, 0.0)
    if r != 0:
        return r > 0
    s.n_fine_tests += 1
    if fine_top(s, ev):
        r = fine_site(&s.ev_fine[3 * ev], yi)
        if r != 0:
            return r > 0
    event_sites(s, ev, tri)
    s.n_exact_site += 1
    r = tvb_site_first(yi, tri)
    if r < 0:
        s.status = NO_MEMORY
        return True
    return r == 1


# ---------------------------------------------------------------------------------------------------------
# the event queue's window (event_queue.pxd), grown where queue_next cannot decide

cdef inline void pull_bucket(Sweep* s) noexcept nogil:
    """The window grows by one strip: its bucket's events go to the heap, in the order they came to the
    bucket (the list's last first). Events at one height often come in order along the line (a row of a
    lattice, scheduled left to right): pushed in that order, each stays where it lands after a comparison
    or two; pushed the other way, each would rise through the heap past events it ties with."""
    cdef int ev, before
    s.bucket_now += 1
    ev = s.bucket_head[s.bucket_now]
    s.bucket_head[s.bucket_now] = NONE
    if ev == NONE:
        return
    while s.ev_link[2 * ev] != NONE:
        ev = s.ev_link[2 * ev]
    while ev != NONE:
        before = s.ev_link[2 * ev + 1]
        s.n_bucketed -= 1
        heap_push(s, ev)
        ev = before


cdef int queue_grow(Sweep* s, int i) noexcept nogil:
    """queue_next, once neither the next site nor the heap's first event lies in the window: its strips'
    buckets go to the heap one by one until one of them does, or every event is in the heap."""
    while True:
        if s.bucket_now >= s.n_buckets - 1:     # (every event is in the heap)
            if i < s.n and (s.n_heap == 0 or site_first(s, i, s.heap[0])):
                return SITE_NEXT
            return s.heap[0] if s.n_heap > 0 else NONE
        pull_bucket(s)
        if i < s.n and bucket_high(s, s.y[i]) <= s.bucket_now:
            if s.n_heap == 0 or site_first(s, i, s.heap[0]):
                return SITE_NEXT
            return s.heap[0]
        if s.n_heap > 0 and bucket_high(s, s.ev_span[2 * s.heap[0] + 1]) <= s.bucket_now:
            return s.heap[0]


# ---------------------------------------------------------------------------------------------------------
# circle events: scheduling one

cdef void check_circle(Sweep* s, int arc, int old) noexcept nogil:
    """Schedule the circle event of arc if its two breakpoints converge. old: the arc's former event,
    taken from it (take_event) but still in the heap, or NONE: the new event takes its slot and moves
    from its place in the heap, or it leaves the heap if there is no new event."""
    cdef int l = s.arc_prev[arc], r = s.arc_next[arc], a, b, c, ev
    if l == NONE or r == NONE:
        if old != NONE:
            heap_remove(s, old)
        return
    a = s.arc_site[l]
    b = s.arc_site[arc]
    c = s.arc_site[r]
    if a == c or orient2d(s.x[a], s.y[a], s.x[b], s.y[b], s.x[c], s.y[c]) <= 0:
        if old != NONE:
            heap_remove(s, old)
        return
    if old != NONE:
        ev = old
    elif s.n_free_ev > 0:
        s.n_free_ev -= 1
        ev = s.free_events[s.n_free_ev]
    elif s.n_events < s.cap_ev:
        ev = s.n_events
        s.n_events += 1
    else:
        s.status = BROKEN
        return
    # the event is where the sweep line touches the circle's top: rounded, with an interval that holds it
    if circle_top_fast(s.x[a], s.y[a], s.x[b], s.y[b], s.x[c], s.y[c], &s.ev_y[ev],
                       &s.ev_span[2 * ev], &s.ev_span[2 * ev + 1], &s.ev_x[ev], &s.ev_cy[ev]):
        s.ev_fine_state[ev] = FINE_UNKNOWN
    else:
        # a thin triangle (or tiny differences): the careful computation, its rise kept for near ties
        circle_top(s.x[a], s.y[a], s.x[b], s.y[b], s.x[c], s.y[c], &s.ev_y[ev],
                   &s.ev_span[2 * ev], &s.ev_span[2 * ev + 1],
                   &s.ev_rise[3 * ev], &s.ev_rise[3 * ev + 1], &s.ev_rise[3 * ev + 2], &s.ev_x[ev], &s.ev_cy[ev])
        s.ev_fine_state[ev] = FINE_UNKNOWN | RISE_KNOWN
    s.ev_arc[ev] = arc
    s.ev_sites[3 * ev] = a
    s.ev_sites[3 * ev + 1] = b
    s.ev_sites[3 * ev + 2] = c
    s.ev_class[ev] = s.n_classes
    s.n_classes += 1
    s.arc_event[arc] = ev
    if old != NONE:
        queue_update(s, ev)
    else:
        queue_add(s, ev)


# ---------------------------------------------------------------------------------------------------------
# edge records and triangles

cdef int new_record(Sweep* s, int a, int b, double x, double y) noexcept nogil:
    cdef int r = s.n_recs
    s.n_recs += 1
    s.rec_e0[r] = NONE
    s.rec_e1[r] = NONE
    if s.rec_a != NULL:         # a step trace's state: what the records show
        s.rec_a[r] = a
        s.rec_b[r] = b
        s.rec_x[r] = x
        s.rec_y[r] = y
    return r


cdef inline void attach(Sweep* s, int r, int e) noexcept nogil:
    """Half-edge e of a new triangle lies on the edge of record r: pair it with the other side.

    Each twin link is written once, both ways, between half-edges with the same two ends; anything
    else is an inconsistent state (BROKEN), so the finished links need no second look.
    """
    cdef int o = s.rec_e0[r]
    if o == NONE:
        s.rec_e0[r] = e
    elif s.rec_e1[r] != NONE or s.tv[o] != s.tv[nxt(e)] or s.tv[nxt(o)] != s.tv[e]:
        s.status = BROKEN           # a third triangle on one edge, or a twin with other ends
    else:
        s.rec_e1[r] = e
        s.opp[e] = o
        s.opp[o] = e


cdef void site_event(Sweep* s, int i) noexcept nogil:
    cdef double px = s.x[i], py = s.y[i]
    cdef int b, p, b2, r, site_b, old
    cdef double dy
    s.sweep_y = py
    s.last_site = i
    s.last_kind = EVENT_SITE
    if s.first_arc == NONE:
        b = new_arc(s, i)
        s.root = b
        s.first_arc = b
        s.row_mode = True
        s.row_last = b
        return
    if s.row_mode and py == s.y[s.arc_site[s.row_last]]:
        # degenerate case: the first row of sites (equal y); their breakpoints are
        # vertical lines coming up from infinity, in order of x
        b = s.row_last
        if s.n_free + (s.cap_arcs - s.n_arcs) < 1 or s.n_recs >= s.cap_rec:
            s.status = BROKEN
            return
        p = new_arc(s, i)
        insert_after(s, b, p)
        s.arc_edge[b] = new_record(s, s.arc_site[b], i, 0.5 * (s.x[s.arc_site[b]] + px), -INFINITY)
        s.row_last = p
        return
    s.row_mode = False
    if s.n_free + (s.cap_arcs - s.n_arcs) < 2 or s.n_recs >= s.cap_rec:
        s.status = BROKEN           # more arcs or edges than n sites can make
        return
    # find the arc above the site and split it in two around a new arc
    b = locate_hinted(s, px, py)
    site_b = s.arc_site[b]
    old = take_event(s, b)          # b's event goes: rescheduled for b's left part, or removed
    # split b into b, p, b2; the new edge starts on b's parabola right above p
    dy = s.y[site_b] - py
    r = new_record(s, site_b, i, px,
                   py + ((s.x[site_b] - px) * (s.x[site_b] - px) + dy * dy) / (2.0 * dy) if dy != 0.0 else py)
    p = new_arc(s, i)
    b2 = new_arc(s, site_b)
    insert_after(s, b, p)
    insert_after(s, p, b2)
    s.arc_edge[b2] = s.arc_edge[b]
    s.arc_edge[b] = r
    s.arc_edge[p] = r
    set_hint(s, px, p)
    check_circle(s, b, old)
    check_circle(s, b2, NONE)


cdef void circle_event(Sweep* s, int ev) noexcept nogil:
    cdef int arc = s.ev_arc[ev], l = s.arc_prev[arc], r = s.arc_next[arc]
    cdef int a, b, c, t, rec, old_l, old_r
    if (l == NONE or r == NONE or s.arc_edge[l] == NONE or s.arc_edge[arc] == NONE
            or s.n_tri >= s.cap_tri or s.n_recs >= s.cap_rec):
        s.status = BROKEN           # an event of an arc at the end of the beach line, or too many
        return
    a = s.arc_site[l]
    b = s.arc_site[arc]
    c = s.arc_site[r]
    s.sweep_y = s.ev_y[ev]
    # the Voronoi vertex: triangle (a, b, c), counter-clockwise
    t = s.n_tri
    s.n_tri += 1
    s.tv[3 * t] = a
    s.tv[3 * t + 1] = b
    s.tv[3 * t + 2] = c
    s.opp[3 * t] = NONE
    s.opp[3 * t + 1] = NONE
    s.opp[3 * t + 2] = NONE
    attach(s, s.arc_edge[l], 3 * t)          # edge a-b ends here
    attach(s, s.arc_edge[arc], 3 * t + 1)    # edge b-c ends here
    rec = new_record(s, a, c, s.ev_x[ev], s.ev_cy[ev])
    attach(s, rec, 3 * t + 2)                # edge a-c begins here
    s.last_kind = EVENT_CIRCLE
    s.last_site = b
    s.last_tri = t
    cancel_event(s, arc)            # the event itself leaves the heap
    old_l = take_event(s, l)        # the neighbours' events: rescheduled in place, or removed
    old_r = take_event(s, r)
    remove_arc(s, arc)
    set_hint(s, s.ev_x[ev], l)
    s.arc_edge[l] = rec
    check_circle(s, l, old_l)
    check_circle(s, r, old_r)


cdef int step(Sweep* s, int* next_site) noexcept nogil:
    """Process the next event; 0 when there is none left."""
    cdef int i, ev
    i = next_site[0]
    if s.status != OK:
        return 0
    ev = queue_next(s, i)
    if ev == SITE_NEXT:
        # sites come before circle events at the same position
        next_site[0] = i + 1
        if i > 0 and s.x[i] == s.x[i - 1] and s.y[i] == s.y[i - 1]:
            # degenerate case: a repeated point, sorted next to its first copy
            s.dup[i] = s.dup[i - 1] if s.dup[i - 1] != NONE else i - 1
            s.last_kind = EVENT_REPEAT
            s.last_site = i
            return 1
        site_event(s, i)
        return 1
    if ev == NONE:
        return 0
    circle_event(s, ev)
    return 1


# ---------------------------------------------------------------------------------------------------------
# closing the hull, and the exact repair

cdef int close_hull(Sweep* s, int32_t* vmap) noexcept nogil:
    """An infinite triangle beyond each edge that has a triangle on one side only; OK or BROKEN.

    vmap (n + 1 entries) is scratch. Every twin link is written once, both
    ways, and checked (here and in attach), so the repair and the Python layer
    never follow a link that was not written.
    """
    cdef int r, e, u, w, t, k, first = s.n_tri
    for k in range(s.n + 1):
        vmap[k] = NONE
    # an infinite triangle (w, u, inf) beyond each finite half-edge u->w without a twin
    for r in range(s.n_recs):
        e = s.rec_e0[r]
        if e == NONE or s.rec_e1[r] != NONE:
            continue
        u = s.tv[e]
        w = s.tv[nxt(e)]
        if s.n_tri >= s.cap_tri or vmap[w] != NONE:
            return BROKEN           # more hull edges than sites, or two hull edges leaving w
        t = s.n_tri
        s.n_tri += 1
        s.tv[3 * t] = w
        s.tv[3 * t + 1] = u
        s.tv[3 * t + 2] = s.n
        s.opp[3 * t] = e
        s.opp[e] = 3 * t
        s.opp[3 * t + 1] = NONE
        s.opp[3 * t + 2] = NONE
        vmap[w] = t
    # link the infinite triangles around the hull: (w, u, inf) has edge u->inf, the twin of inf->u in
    # the infinite triangle that starts at u
    for t in range(first, s.n_tri):
        u = s.tv[3 * t + 1]
        if vmap[u] == NONE or s.opp[3 * vmap[u] + 2] != NONE:
            return BROKEN           # the hull is not one closed cycle
        s.opp[3 * t + 1] = 3 * vmap[u] + 2
        s.opp[3 * vmap[u] + 2] = 3 * t + 1
    # every link was written once, both ways, between matching ends: what is left is a half-edge
    # without a twin
    for e in range(3 * s.n_tri):
        if s.opp[e] == NONE:
            return BROKEN
    return OK


cdef bint is_infinite(Sweep* s, int t) noexcept nogil:
    return s.tv[3 * t] == s.n or s.tv[3 * t + 1] == s.n or s.tv[3 * t + 2] == s.n


cdef int repair(Sweep* s, int32_t* stack, int8_t* queued, int max_flips) noexcept nogil:
    """Lawson flips until every edge is locally Delaunay (exact incircle).

    Every edge is tested once, in order; one that is not locally Delaunay is flipped at once, and the
    edges around each flip are tested again (a stack) before the scan goes on. An edge the scan has
    passed can only stop being locally Delaunay by a flip next to it, which puts it on the stack, so
    every edge is locally Delaunay at the end. (On the sweep's own output nothing is flipped, and
    stack and queued, which must be zero, are never written.)

    Returns the flip count, or -1 when more than max_flips were needed (an
    input that was not a triangulation; each flip is exact, so on a valid
    triangulation the flips end).
    """
    cdef int n_he = 3 * s.n_tri, top = 0, e, e0, flips = 0
    for e0 in range(n_he):
        if s.opp[e0] < e0 or not flip_if_illegal(s, e0, stack, queued, &top, &flips, max_flips):
            continue
        if flips > max_flips:
            return -1
        while top > 0:
            top -= 1
            e = stack[top]
            queued[e] = 0
            flip_if_illegal(s, e, stack, queued, &top, &flips, max_flips)
            if flips > max_flips:
                return -1
    return flips


cdef inline bint flip_if_illegal(Sweep* s, int e, int32_t* stack, int8_t* queued, int* top, int* flips,
                                 int max_flips) noexcept nogil:
    """Flip the edge of half-edge e if it is not locally Delaunay (both triangles finite, and the far
    site strictly inside the circle of e's triangle), pushing the four edges around it that are not on
    the stack already; True if it did. Past max_flips, counts the flip without making it."""
    cdef int o = s.opp[e], e1, e2, o1, o2, a, b, c, d, A, B, k, sign
    cdef int quad[4]
    if is_infinite(s, e // 3) or is_infinite(s, o // 3):
        return False
    e1 = nxt(e); e2 = prv(e); o1 = nxt(o); o2 = prv(o)
    a = s.tv[e]; b = s.tv[e1]; c = s.tv[e2]; d = s.tv[o2]
    sign = incircle_filter(s.x[a], s.y[a], s.x[b], s.y[b], s.x[c], s.y[c], s.x[d], s.y[d])
    if sign == 2:
        sign = incircle(s.x[a], s.y[a], s.x[b], s.y[b], s.x[c], s.y[c], s.x[d], s.y[d])
    if sign <= 0:
        return False
    flips[0] += 1
    if flips[0] > max_flips:
        return True
    # flip a-b to c-d: (a, b, c) + (b, a, d) become (d, b, c) + (c, a, d)
    A = s.opp[e2]
    B = s.opp[o2]
    s.tv[e] = d
    s.tv[o] = c
    s.opp[e] = B; s.opp[B] = e
    s.opp[o] = A; s.opp[A] = o
    s.opp[e2] = o2; s.opp[o2] = e2
    quad[0] = e; quad[1] = e1; quad[2] = o; quad[3] = o1
    for k in range(4):
        if not queued[quad[k]] and not queued[s.opp[quad[k]]]:
            stack[top[0]] = quad[k]
            top[0] += 1
            queued[quad[k]] = 1
    return True


cdef void start_state(Sweep* s, const double* x, const double* y, int n, int cap_arcs, int cap_ev, int cap_rec,
                      int cap_tri) noexcept nogil:
    """The counters and scalars of a sweep that has not begun, for both entries (sweep, sweep_triangles),
    which set every array; no hints (n_hint 0: every site located down the tree) until the caller
    gives some."""
    s.x = x; s.y = y; s.n = n
    s.root = NONE; s.n_arcs = 0; s.first_arc = NONE; s.n_free = 0
    s.n_hint = 0; s.hint = NULL; s.hint_site = NULL; s.hint_x0 = 0.0; s.hint_scale = 0.0
    s.n_walks = 0; s.n_descents = 0; s.tree_on = True; s.long_budget = 0; s.n_long_walks = 0
    s.n_classes = 0; s.n_heap = 0; s.n_events = 0; s.n_free_ev = 0
    # one bucket, always in the window (every event in the heap), until the caller sets buckets
    s.bucket_head = NULL; s.ev_link = NULL; s.n_buckets = 1; s.bucket_now = 0; s.n_bucketed = 0
    s.bucket_y0 = 0.0; s.bucket_scale = 0.0
    s.n_recs = 0; s.n_tri = 0
    s.row_mode = False; s.row_last = NONE
    s.last_kind = NONE; s.last_site = NONE; s.last_tri = NONE; s.sweep_y = -INFINITY
    s.cap_arcs = cap_arcs; s.cap_ev = cap_ev; s.cap_rec = cap_rec; s.cap_tri = cap_tri
    s.status = OK; s.n_exact_site = 0; s.n_exact_circle = 0; s.n_fine_tops = 0; s.n_fine_tests = 0; s.n_near = 0


cdef enum:
    BUCKET_MIN_SITES = 64       # fewer sites: every event in the heap (one bucket)
    SITES_PER_BUCKET = 2        # the strips' height: about this many sites each, over uniform y


cdef object set_buckets(Sweep* s, int32_t[::1] ev_link):
    """Buckets for the events beyond the heap's window (event_queue.pxd): strips of equal height from the
    first site's y to the last's, about SITES_PER_BUCKET sites a strip. Returns the array of bucket
    heads, for the caller to keep; None (one bucket, every event in the heap) for few sites or a span
    of y the strips cannot measure."""
    cdef int n = s.n, nb
    cdef double span, scale
    if n < BUCKET_MIN_SITES:
        return None
    span = s.y[n - 1] - s.y[0]
    nb = n // SITES_PER_BUCKET
    scale = nb / span if span > 0.0 else 0.0
    if not (0.0 < scale < INFINITY):
        return None
    heads_arr = np.full(nb, NONE, np.int32)
    cdef int32_t[::1] heads = heads_arr
    s.bucket_head = &heads[0]
    s.ev_link = &ev_link[0]
    s.n_buckets = nb
    s.bucket_now = 0
    s.bucket_y0 = s.y[0]
    s.bucket_scale = scale
    return heads_arr


def sweep(const double[::1] xs, const double[::1] ys, long stop_after=-1, bint hints=True, bint guard=True,
          bint buckets=True):
    """Fortune's sweep over sites sorted by (y, x).

    Parameters
    ----------
    xs, ys : (n,) float64
        Site coordinates in event order (sorted by y, then x).
    stop_after : int
        Stop after this many events (site, repeat and circle events count
        one each) and return the sweep's state; -1 runs to the end.
    hints : bool
        Locate each site by a walk along the beach line from an arc met
        lately near its x (beach_line.locate_hinted); False: always down the
        tree. The same arcs either way (tests compare them).
    buckets : bool
        Keep the events far above the sweep line in buckets by strips of y,
        the heap holding only a window of them (event_queue.pxd); False: every
        event in the heap. The same order of events either way.
    guard : bool
        Close with the exact repair, a guard that finds nothing to flip (``flips`` counts what it
        flipped). False leaves the guard to the caller: the dual checks every edge as it walks
        (dual.voronoi_from_delaunay's ``check``), for a fraction of the repair's cost.

    Returns
    -------
    dict: ``status`` (STATUS_OK, or the code of an inconsistent state, with
    STATUS_MESSAGES), ``tv``, ``opp`` (3 * n_tri,) int32 -- the triangulation
    (vertex n at infinity; only when the sweep finished without trouble and
    some triangle exists), ``dup`` (n,) int32, ``steps`` (events processed),
    ``flips`` (exact repairs), ``near_ties`` (comparisons the double filter
    left to the rises, those left to the double-double filter, events whose fine top
    was computed), ``exact_tests`` (site and circle comparisons left to exact
    integers), ``located`` (sites located by a walk from a hint, by the
    tree), ``queue`` (buckets, the last bucket in the heap's window, events waiting in
    buckets, events in the heap, when the sweep stopped), and with ``stop_after`` the state: ``beach`` (arc sites left to
    right), ``beach_edges`` (record of each breakpoint), ``events`` (pending
    circle events: arc index in ``beach``, centre x, centre y, top y),
    ``records`` (sites a, b; half-edges e0, e1; start x, y), ``triangles``
    so far, ``sweep_y``, ``last`` (kind, site, triangle).
    """
    cdef int n = xs.shape[0]
    cdef int cap_arcs = 2 * n + 2, cap_ev = 2 * n + 2, cap_rec = 3 * n + 4, cap_tri = 3 * n + 4
    # (the records' sites and starts only for a trace's state: a whole sweep would write 24 bytes an
    # edge that nothing reads)
    cdef int cap_shown = cap_rec if stop_after >= 0 else 1
    arrays = {
        "arc_site": np.empty(cap_arcs, np.int32), "arc_prev": np.empty(cap_arcs, np.int32),
        "arc_next": np.empty(cap_arcs, np.int32), "left": np.empty(cap_arcs, np.int32),
        "right": np.empty(cap_arcs, np.int32), "parent": np.empty(cap_arcs, np.int32),
        "height": np.empty(cap_arcs, np.int8), "arc_event": np.empty(cap_arcs, np.int32),
        "arc_edge": np.empty(cap_arcs, np.int32),
        "ev_y": np.empty(cap_ev, np.float64), "ev_x": np.empty(cap_ev, np.float64),
        "ev_span": np.empty(2 * cap_ev, np.float64), "ev_rise": np.empty(3 * cap_ev, np.float64),
        "ev_fine_state": np.empty(cap_ev, np.int8),
        "ev_cy": np.empty(cap_ev, np.float64), "ev_arc": np.empty(cap_ev, np.int32),
        "ev_sites": np.empty(3 * cap_ev, np.int32),
        "ev_class": np.empty(cap_ev, np.int64),
        "ev_pos": np.empty(cap_ev, np.int32), "heap": np.empty(cap_ev, np.int32),
        "ev_link": np.empty(2 * cap_ev, np.int32),
        "free_events": np.empty(cap_ev, np.int32), "free_arcs": np.empty(cap_arcs, np.int32),
        "rec_a": np.empty(cap_shown, np.int32), "rec_b": np.empty(cap_shown, np.int32),
        "rec_e0": np.empty(cap_rec, np.int32), "rec_e1": np.empty(cap_rec, np.int32),
        "rec_x": np.empty(cap_shown, np.float64), "rec_y": np.empty(cap_shown, np.float64),
        "tv": np.empty(3 * cap_tri, np.int32), "opp": np.empty(3 * cap_tri, np.int32),
        "dup": np.full(n, -1, np.int32),
    }
    cdef int32_t[::1] arc_site = arrays["arc_site"], arc_prev = arrays["arc_prev"], arc_next = arrays["arc_next"]
    cdef int32_t[::1] left = arrays["left"], right = arrays["right"], parent = arrays["parent"]
    cdef int8_t[::1] height = arrays["height"]
    cdef int32_t[::1] ev_pos = arrays["ev_pos"], free_events = arrays["free_events"]
    cdef int32_t[::1] free_arcs = arrays["free_arcs"]
    cdef int32_t[::1] arc_event = arrays["arc_event"], arc_edge = arrays["arc_edge"]
    cdef double[::1] ev_y = arrays["ev_y"], ev_x = arrays["ev_x"], ev_cy = arrays["ev_cy"]
    cdef double[::1] ev_span = arrays["ev_span"], ev_rise = arrays["ev_rise"]
    cdef int8_t[::1] ev_fine_state = arrays["ev_fine_state"]
    cdef int32_t[::1] ev_arc = arrays["ev_arc"], heap = arrays["heap"], ev_sites = arrays["ev_sites"]
    cdef int64_t[::1] ev_class = arrays["ev_class"]
    cdef int32_t[::1] rec_a = arrays["rec_a"], rec_b = arrays["rec_b"]
    cdef int32_t[::1] rec_e0 = arrays["rec_e0"], rec_e1 = arrays["rec_e1"]
    cdef double[::1] rec_x = arrays["rec_x"], rec_y = arrays["rec_y"]
    cdef int32_t[::1] tv = arrays["tv"], opp = arrays["opp"], dup = arrays["dup"]
    cdef Sweep s
    start_state(&s, &xs[0] if n else NULL, &ys[0] if n else NULL, n, cap_arcs, cap_ev, cap_rec, cap_tri)
    s.arc_site = &arc_site[0]; s.arc_prev = &arc_prev[0]; s.arc_next = &arc_next[0]
    s.left = &left[0]; s.right = &right[0]; s.parent = &parent[0]; s.height = &height[0]
    s.arc_event = &arc_event[0]; s.arc_edge = &arc_edge[0]
    s.ev_y = &ev_y[0]; s.ev_x = &ev_x[0]; s.ev_cy = &ev_cy[0]; s.ev_arc = &ev_arc[0]; s.ev_sites = &ev_sites[0]
    s.ev_class = &ev_class[0]
    s.ev_span = &ev_span[0]
    s.ev_rise = &ev_rise[0]
    s.ev_fine_state = &ev_fine_state[0]
    s.ev_fine = <double*>malloc(3 * cap_ev * sizeof(double))
    if s.ev_fine == NULL:
        raise MemoryError("Fortune's sweep: event buffers")
    s.ev_pos = &ev_pos[0]; s.heap = &heap[0]
    s.free_events = &free_events[0]
    bucket_heads = set_buckets(&s, arrays["ev_link"]) if buckets else None    # (kept until the sweep's end)
    s.free_arcs = &free_arcs[0]
    s.rec_e0 = &rec_e0[0]; s.rec_e1 = &rec_e1[0]
    s.rec_a = s.rec_b = NULL
    s.rec_x = s.rec_y = NULL
    if stop_after >= 0:
        s.rec_a = &rec_a[0]; s.rec_b = &rec_b[0]
        s.rec_x = &rec_x[0]; s.rec_y = &rec_y[0]
    s.tv = &tv[0]; s.opp = &opp[0]
    s.dup = &dup[0] if n else NULL
    # the hints: about sqrt(n) strips of equal width (a strip then holds an arc or two of the beach line
    # over uniform sites; a new site finds a live arc in its strip or one beside it more than 99% of
    # the time, on clustered sites too), across the middle 99.8% of the sites' x in a sample of them:
    # a few far outliers go to the end strips instead of squeezing every other site into one
    cdef int n_hint = 1
    while n_hint < sqrt(n) and n_hint < (1 << 22):
        n_hint *= 2
    hint_arr = np.full(2 * n_hint, NONE, np.int32)
    cdef int32_t[::1] hint = hint_arr
    cdef double x_lo = 0.0, x_hi = 0.0
    if hints and n:
        x_lo, x_hi = (float(v) for v in np.quantile(np.asarray(xs)[:: max(1, n // 4096)], [0.001, 0.999]))
        s.n_hint = n_hint
        s.hint = &hint[0]
        s.hint_site = &hint[n_hint]
        s.hint_x0 = x_lo
        s.hint_scale = n_hint / (x_hi - x_lo) if x_hi > x_lo else 0.0
        s.tree_on = False
        s.long_budget = LONG_WALK_STEPS_PER_SITE * <long> n + LONG_WALK_STEPS_BASE
    cdef int next_site = 0, flips = 0
    cdef long steps = 0
    # the sweep: one event at a time (every step processes a site or removes an arc, so it ends)
    try:
        with nogil:
            # the arrays a whole sweep writes (nearly) whole, faulted in by runs of pages: the triangles
            # (at most 2 n) and the records (one an edge)
            if stop_after < 0 and n > 0:
                populate(s.tv, 3 * min(cap_tri, 2 * n) * sizeof(int32_t))
                populate(s.opp, 3 * min(cap_tri, 2 * n) * sizeof(int32_t))
                populate(s.rec_e0, cap_rec * sizeof(int32_t))
                populate(s.rec_e1, cap_rec * sizeof(int32_t))
            while stop_after < 0 or steps < stop_after:
                if not step(&s, &next_site):
                    break
                steps += 1
                if (steps & POLL_MASK) == 0:
                    poll_signals()
    finally:
        free(s.ev_fine)
        s.ev_fine = NULL
    out = {"status": s.status, "dup": arrays["dup"], "steps": steps, "flips": 0, "sweep_y": s.sweep_y,
           "last": (s.last_kind, s.last_site, s.last_tri),
           "near_ties": (s.n_near, s.n_fine_tests, s.n_fine_tops), "exact_tests": (s.n_exact_site, s.n_exact_circle), "located": (s.n_walks, s.n_descents),
           "long_walks": s.n_long_walks, "tree_built": s.tree_on,
           "queue": (s.n_buckets, s.bucket_now, s.n_bucketed, s.n_heap)}
    if s.status != OK:
        return out
    cdef bint finished = next_site == n and s.n_heap == 0 and s.n_bucketed == 0
    if not finished or stop_after >= 0:
        out.update(_state(&s, arrays))
    if not finished:
        return out
    cdef int32_t[::1] vmap
    cdef int32_t[::1] stack
    cdef int8_t[::1] queued
    if s.n_tri > 0:
        # close the hull with triangles at infinity, then the exact repair (a guard: no flips expected)
        vmap = np.empty(n + 1, np.int32)
        with nogil:
            s.status = close_hull(&s, &vmap[0])
        if s.status != OK:
            out["status"] = s.status
            return out
        if guard:
            stack = np.empty(3 * s.n_tri, np.int32)
            queued = np.zeros(3 * s.n_tri, np.int8)
            with nogil:
                flips = repair(&s, &stack[0], &queued[0], max_repair_flips(s.n_tri))
            if flips < 0:
                out["status"] = NO_REPAIR
                return out
        out["tv"] = arrays["tv"][:3 * s.n_tri]
        out["opp"] = arrays["opp"][:3 * s.n_tri]
    out["flips"] = flips
    return out


cdef inline int max_repair_flips(int n_tri) noexcept nogil:
    """A bound on the flips of the guard repair: none are expected; a wrong sweep is reported, not looped on."""
    return 3 * n_tri + 1024


cdef dict _state(Sweep* s, dict arrays):
    """The beach line, pending events and records, as arrays for the step trace."""
    cdef int a = s.first_arc, k = 0, ev
    beach, edges, index = [], [], {}
    while a != NONE:
        index[a] = k
        beach.append(s.arc_site[a])
        edges.append(s.arc_edge[a])
        a = s.arc_next[a]
        k += 1
    events = []
    for k in range(s.n_heap):
        ev = s.heap[k]
        events.append((index[s.ev_arc[ev]], s.ev_x[ev], s.ev_cy[ev], s.ev_y[ev]))
    for k in range(s.bucket_now + 1, s.n_buckets):
        ev = s.bucket_head[k]
        while ev != NONE:
            events.append((index[s.ev_arc[ev]], s.ev_x[ev], s.ev_cy[ev], s.ev_y[ev]))
            ev = s.ev_link[2 * ev]
    events.sort(key=lambda row: (row[3], row[1]))
    r = s.n_recs if s.rec_a != NULL else 0
    return {
        "beach": np.asarray(beach, np.int32),
        "beach_edges": np.asarray(edges[:len(edges) - 1], np.int32) if edges else np.empty(0, np.int32),
        "events": np.asarray(events, np.float64).reshape(-1, 4),
        "records": {
            "a": arrays["rec_a"][:r].copy(), "b": arrays["rec_b"][:r].copy(),
            "e0": arrays["rec_e0"][:r].copy(), "e1": arrays["rec_e1"][:r].copy(),
            "x": arrays["rec_x"][:r].copy(), "y": arrays["rec_y"][:r].copy(),
        },
        "triangles": arrays["tv"][:3 * s.n_tri].reshape(-1, 3).copy(),
    }


def legalize(const double[::1] xs, const double[::1] ys, int32_t[::1] tv, int32_t[::1] opp, bint bounded=False):
    """Flip the edges of a triangulation (tv, opp; vertex n at infinity) until it is Delaunay.

    The exact repair that closes every sweep (and the one engines.Triangulation.voronoi runs where the
    dual's check found an illegal edge). Modifies tv and opp in place; returns the number of flips, or
    -1 when ``bounded`` and more were needed than a sweep's guard allows (then tv, opp were no
    triangulation).
    """
    cdef Sweep s
    cdef int n_he = tv.shape[0]
    cdef int32_t[::1] stack = np.empty(max(n_he, 1), np.int32)
    cdef int8_t[::1] queued = np.zeros(max(n_he, 1), np.int8)
    cdef int flips
    s.x = &xs[0]
    s.y = &ys[0]
    s.n = xs.shape[0]
    s.tv = &tv[0]
    s.opp = &opp[0]
    s.n_tri = n_he // 3
    with nogil:
        flips = repair(&s, &stack[0], &queued[0], max_repair_flips(s.n_tri) if bounded else 2_000_000_000)
    return flips


cdef int sweep_triangles(const double* x, const double* y, int n, int32_t* tv_out, int cap) noexcept nogil:
    """Fortune's sweep over a few sites (sorted by y, then x), for local updates.

    Writes the Delaunay triangles, vertex n at infinity, into tv_out (room for
    cap triangles) and returns their number; -1 when no triangle exists (the
    sites are collinear), cap is too small, memory ran out or the sweep met an
    inconsistent state. No Python objects: scratch
    memory comes from malloc.
    """
    cdef int cap_arcs = 2 * n + 2, cap_ev = 2 * n + 2, cap_rec = 3 * n + 4, cap_tri = 3 * n + 4
    cdef int n_i32 = 11 * cap_arcs + 7 * cap_ev + 2 * cap_rec + 6 * cap_tri + n + (n + 1) + 3 * cap_tri
    cdef int n_f64 = 9 * cap_ev
    cdef int32_t* ib = <int32_t*>malloc(n_i32 * sizeof(int32_t))
    cdef double* fb = <double*>malloc(n_f64 * sizeof(double))
    cdef int8_t* bb = <int8_t*>malloc((cap_arcs + 3 * cap_tri + cap_ev) * sizeof(int8_t))
    cdef double* fine = <double*>malloc(3 * cap_ev * sizeof(double))
    cdef int64_t* classes = <int64_t*>malloc(cap_ev * sizeof(int64_t))
    cdef int32_t* p = ib
    cdef double* q = fb
    cdef Sweep s
    cdef int next_site = 0, k, result = -1
    if ib == NULL or fb == NULL or bb == NULL or fine == NULL or classes == NULL:
        free(ib); free(fb); free(bb); free(fine); free(classes)
        return -1
    start_state(&s, x, y, n, cap_arcs, cap_ev, cap_rec, cap_tri)
    s.arc_site = p; p += cap_arcs
    s.arc_prev = p; p += cap_arcs
    s.arc_next = p; p += cap_arcs
    s.left = p; p += cap_arcs
    s.right = p; p += cap_arcs
    s.parent = p; p += cap_arcs
    s.arc_event = p; p += cap_arcs
    s.arc_edge = p; p += cap_arcs
    s.free_arcs = p; p += 3 * cap_arcs
    s.ev_arc = p; p += cap_ev
    s.ev_sites = p; p += 3 * cap_ev
    s.ev_class = classes
    s.ev_pos = p; p += cap_ev
    s.heap = p; p += cap_ev
    s.free_events = p; p += cap_ev
    s.rec_a = s.rec_b = NULL      # (no trace: the records' sites and starts are not kept)
    s.rec_e0 = p; p += cap_rec
    s.rec_e1 = p; p += cap_rec
    s.tv = p; p += 3 * cap_tri
    s.opp = p; p += 3 * cap_tri
    s.dup = p; p += n
    cdef int32_t* vmap = p
    p += n + 1
    cdef int32_t* stack = p
    s.height = bb
    cdef int8_t* queued = bb + cap_arcs
    s.ev_fine_state = bb + cap_arcs + 3 * cap_tri
    s.ev_fine = fine
    s.ev_y = q; q += cap_ev
    s.ev_x = q; q += cap_ev
    s.ev_cy = q; q += cap_ev
    s.ev_span = q; q += 2 * cap_ev
    s.ev_rise = q; q += 3 * cap_ev
    s.rec_x = s.rec_y = NULL
    for k in range(n):
        s.dup[k] = NONE
    while step(&s, &next_site):
        pass
    if s.n_tri > 0 and s.status == OK:
        s.status = close_hull(&s, vmap)
    if s.n_tri > 0 and s.status == OK:
        for k in range(3 * s.n_tri):
            queued[k] = 0
        if repair(&s, stack, queued, max_repair_flips(s.n_tri)) >= 0 and s.n_tri <= cap:
            for k in range(3 * s.n_tri):
                tv_out[k] = s.tv[k]
            result = s.n_tri
    free(ib)
    free(fb)
    free(bb)
    free(fine)
    free(classes)
    return result


def circle_event_top(double ax, double ay, double bx, double by, double cx, double cy):
    """The circle event of sites a, b, c (counter-clockwise), for tests.

    Returns (top, lo, hi, base, rise, rise_err, centre x, centre y): ``top``
    is rounded; the exact top lies in [lo, hi] and within rise_err of
    base + rise.
    """
    cdef double top, lo, hi, base, rise, rise_err, centre_x, centre_y
    circle_top(ax, ay, bx, by, cx, cy, &top, &lo, &hi, &base, &rise, &rise_err, &centre_x, &centre_y)
    return top, lo, hi, base, rise, rise_err, centre_x, centre_y


def circle_event_top_fine(double ax, double ay, double bx, double by, double cx, double cy):
    """The double-double filter's top of the circle through a, b, c, for tests: None when it gives up,
    else (head, tail, err): the exact top lies within err of head + tail."""
    cdef double fine[3]
    if not circle_top_fine(ax, ay, bx, by, cx, cy, fine):
        return None
    return fine[0], fine[1], fine[2]


def site_before_event(double y, double ax, double ay, double bx, double by, double cx, double cy):
    """Exact: a site at height y comes before the circle event of a, b, c (y <= top), for tests."""
    cdef double tri[6]
    tri[0] = ax; tri[1] = ay; tri[2] = bx; tri[3] = by; tri[4] = cx; tri[5] = cy
    cdef int r = tvb_site_first(y, tri)
    if r < 0:
        raise MemoryError("exact event order")
    return r == 1


def event_top_order(t1, t2):
    """Exact sign of top(t1) - top(t2) for two counter-clockwise triples (ax, ay, bx, by, cx, cy), for tests."""
    cdef double a[6]
    cdef double b[6]
    cdef int k, r
    for k in range(6):
        a[k] = t1[k]
        b[k] = t2[k]
    r = tvb_top_order(a, b)
    if r == 2:
        raise MemoryError("exact event order")
    return r
