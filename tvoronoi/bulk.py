"""Helpers for building or writing millions of small Python objects at once."""

import gc
from contextlib import contextmanager


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
