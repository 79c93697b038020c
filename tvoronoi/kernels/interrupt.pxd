# Ctrl-C and SIGTERM during long kernel runs: loops that run without the GIL look at pending signals
# every POLL_EVERY units of work (insertions, events, triangles, cells) and stop with the handler's
# exception (KeyboardInterrupt, or whatever a SIGTERM handler raises). The cost is one GIL round trip
# per POLL_EVERY units: nothing next to the work. In a thread other than the main one Python runs no
# handlers, and the poll returns at once.

from cpython.exc cimport PyErr_CheckSignals

cdef enum:
    POLL_MASK = (1 << 14) - 1     # poll when (count & POLL_MASK) == 0


cdef inline int poll_signals() except -1 nogil:
    """Run Python's pending signal handlers; -1 with their exception set if one raised."""
    with gil:
        return PyErr_CheckSignals()
