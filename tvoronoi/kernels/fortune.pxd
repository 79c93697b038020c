# Fortune's sweep, for other kernels: a C entry over a few sites (local updates of dynamic diagrams).

from libc.stdint cimport int32_t

cdef int sweep_triangles(const double* x, const double* y, int n, int32_t* tv_out, int cap) noexcept nogil

# the event order at near ties, out of line (called from event_queue.pxd's inline comparisons)
from tvoronoi.kernels.sweep_state cimport Sweep
cdef bint ev_less_near(Sweep* s, int i, int j) noexcept nogil
cdef bint site_first_near(Sweep* s, int i, int ev) noexcept nogil

# the event queue's window grown until it decides what comes next (event_queue.queue_next), out of line
cdef int queue_grow(Sweep* s, int i) noexcept nogil
