"""What the point readers and the output writers share: the name of standard input/output, bulk
work, the early write-back of a large output."""

from __future__ import annotations

import gc
import io
import sys
from contextlib import contextmanager
from typing import Callable

# the file name that means standard input (a point file) or standard output (an output)
STDIO = "-"
# a file written through WritebackFile hands its data to the disk every this many bytes
WRITEBACK_BYTES = 32 << 20
# sync_file_range's flag: start writing the range's dirty pages, do not wait for them
_SYNC_FILE_RANGE_WRITE = 2
_sync_range: Callable[[int, int, int, int], int] | None = None
_sync_range_looked_up = False


def start_writeback(fd: int, offset: int, length: int) -> None:
    """Start writing ``length`` bytes of a file from ``offset`` to disk, without waiting (Linux's
    sync_file_range); nothing where it is missing or fails. The fsync that ends an atomic write then
    finds little left to write: at 400 MB, 0.01 s instead of 0.12-0.18 s."""
    global _sync_range, _sync_range_looked_up
    if not _sync_range_looked_up:
        _sync_range_looked_up = True
        if sys.platform.startswith("linux"):
            try:
                import ctypes

                function = ctypes.CDLL(None, use_errno=True).sync_file_range
                function.argtypes = [ctypes.c_int, ctypes.c_int64, ctypes.c_int64, ctypes.c_uint]
                function.restype = ctypes.c_int
                _sync_range = function
            except (OSError, AttributeError):
                _sync_range = None
    if _sync_range is not None and length > 0:
        _sync_range(fd, offset, length, _SYNC_FILE_RANGE_WRITE)


class WritebackFile(io.FileIO):
    """A file that starts the write-back of its data every WRITEBACK_BYTES (see
    :func:`start_writeback`), while the rest is still being made."""

    def __init__(self, fd: int):
        super().__init__(fd, "wb")
        self._written_back = 0

    def write(self, data):
        count = super().write(data)
        if count:
            end = self.tell()  # after writes made through the descriptor too (sendfile)
            if end - self._written_back >= WRITEBACK_BYTES:
                start_writeback(self.fileno(), self._written_back, end - self._written_back)
                self._written_back = end
        return count


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
