# Ctrl-C and SIGTERM during long kernel runs: loops that run without the GIL look at pending signals
# every POLL_EVERY units of work (insertions, events, triangles, cells) and stop with the handler's
# exception (KeyboardInterrupt, or whatever a SIGTERM handler raises). The cost is one GIL round trip
# per POLL_EVERY units: nothing next to the work. In a thread other than the main one Python runs no
# handlers; there the poll stops the kernel only when the thread is in tvoronoi.kernels.STOPPING (the
# other half of an interrupted build by halves).

from cpython.exc cimport PyErr_CheckSignals
from cpython.pythread cimport PyThread_get_thread_ident

cdef enum:
    POLL_MASK = (1 << 14) - 1     # poll when (count & POLL_MASK) == 0


cdef inline int poll_signals() except -1 nogil:
    """Run Python's pending signal handlers; -1 with their exception set if one raised."""
    with gil:
        if PyErr_CheckSignals() < 0:
            return -1
        return stop_requested()


cdef inline int stop_requested() except -1:
    """(With the GIL.) KeyboardInterrupt if this thread was asked to stop (tvoronoi.kernels.STOPPING)."""
    from tvoronoi.kernels import STOPPING
    if STOPPING and PyThread_get_thread_ident() in STOPPING:
        raise KeyboardInterrupt("the build this thread works for was interrupted")
    return 0
