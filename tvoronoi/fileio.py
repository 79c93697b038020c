"""What the point readers and the output writers share: the name of standard input/output, bulk work."""

import gc
from contextlib import contextmanager

# the file name that means standard input (a point file) or standard output (an output)
STDIO = "-"


@contextmanager
def gc_paused():
    """Pause the cyclic garbage collector around bulk work.

    Reading a million rows or serializing a million cells makes many small
    objects that hold no cycles; collecting them over and over would cost
    more than the work itself.
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
