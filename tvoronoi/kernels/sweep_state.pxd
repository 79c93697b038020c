# The state of Fortune's sweep (fortune.pyx): one struct of arrays, shared by the beach line, the event
# queue and the events; the enums of event kinds, double-double filter states and status codes.

from libc.stdint cimport int8_t, int32_t, int64_t


cdef enum:
    NONE = -1
    EVENT_SITE = 0
    EVENT_CIRCLE = 1
    EVENT_REPEAT = 2      # a site at the same place as an earlier one

cdef enum:
    FINE_UNKNOWN = 0
    FINE_OK = 1
    FINE_NONE = 2         # the double-double filter cannot bound this event's top
    FINE_MASK = 3
    RISE_KNOWN = 4        # flag: ev_rise holds this event's base, rise and rise error

cdef enum:
    OK = 0
    BROKEN = 1            # an inconsistent state: a capacity exceeded, an arc without neighbours, ...
    NO_MEMORY = 2         # the exact fallback could not allocate
    NO_REPAIR = 3         # the exact repair did not converge within its bound


cdef struct Sweep:
    const double* x
    const double* y
    int n
    # arcs: site, list neighbours, tree links, pending event, record of the breakpoint to the right
    int32_t* arc_site
    int32_t* arc_prev
    int32_t* arc_next
    int32_t* left
    int32_t* right
    int32_t* parent
    int8_t* height
    int32_t* arc_event
    int32_t* arc_edge
    int root
    int n_arcs
    int first_arc
    int32_t* free_arcs     # slots of removed arcs, reused so the live beach line stays in cache
    int n_free
    # where to start locating a site: for each of n_hint strips of x, an arc made or kept there lately,
    # and its site (the arc's slot may since have been freed, or reused for another site elsewhere)
    int32_t* hint
    int32_t* hint_site
    int n_hint
    double hint_x0
    double hint_scale
    long n_walks
    long n_descents
    # the tree is kept only once a site needs it: with hints, the arcs are a list alone (tree_on False)
    # while walks settle within long_budget steps in all (beach_line.locate_hinted)
    bint tree_on
    long long_budget
    long n_long_walks
    # circle events: position (top of the circle, rounded, and an interval that surely holds it),
    # centre, arc; a binary heap of their ids
    double* ev_y
    double* ev_span         # lo, hi of each event (2 per event, side by side for the heap's comparisons)
    double* ev_x
    double* ev_cy
    double* ev_fine         # the top in double-double and its bound (hi, lo, err: 3 per event), for near ties
    int8_t* ev_fine_state   # FINE_UNKNOWN, FINE_OK, FINE_NONE, | RISE_KNOWN
    double* ev_rise         # base, rise, rise error (3 per event), where RISE_KNOWN
    int32_t* ev_arc
    int32_t* ev_sites       # the three sites of each event's circle (3 per event), as they were scheduled
    int64_t* ev_class       # events proven to have equal tops share a class (numbers never reused)
    int64_t n_classes
    int32_t* heap
    int32_t* ev_pos        # where each pending event sits: its heap slot (>= 0), or -2 - its bucket
    int n_heap
    # the events beyond the heap's window (event_queue.pxd): in n_buckets strips of y by the low end of
    # their interval, each a doubly linked list; buckets 0 .. bucket_now are in the heap
    int32_t* bucket_head
    int32_t* ev_link        # next, prev of each event in its bucket (2 per event)
    int n_buckets
    int bucket_now
    int n_bucketed
    double bucket_y0
    double bucket_scale
    int n_events
    int32_t* free_events
    int n_free_ev
    # edge records: the Delaunay half-edges found so far; for the step trace only (NULL otherwise: a
    # finished sweep never reads them), the sites on each side and where the edge began
    int32_t* rec_a
    int32_t* rec_b
    int32_t* rec_e0
    int32_t* rec_e1
    double* rec_x
    double* rec_y
    int n_recs
    # the triangulation
    int32_t* tv
    int32_t* opp
    int n_tri
    int32_t* dup
    # the first row of sites (equal y), before any other site
    bint row_mode
    int row_last
    # the last event, for the step trace
    int last_kind
    int last_site
    int last_tri
    double sweep_y
    # capacities of the arrays, what went wrong, and how often the exact fallback ran
    int cap_arcs
    int cap_ev
    int cap_rec
    int cap_tri
    int status
    long n_exact_site
    long n_exact_circle
    long n_fine_tops
    long n_near
    long n_fine_tests
