"""A stream written by a second thread, so that the text of the next chunk is made while the last one is written."""

from __future__ import annotations

import queue
import threading
from contextlib import contextmanager
from typing import BinaryIO, Iterator

# chunks waiting to be written (each a few megabytes): enough to ride out a slow write, few
# enough that the text held stays small
QUEUE_CHUNKS = 4
# a chunk smaller than this is gathered with the next rather than handed over on its own
MIN_CHUNK = 1 << 20


class BackgroundWriter:
    """Takes ``write(bytes)`` calls and writes them to ``stream`` in a thread, in order.

    Writing a file or a pipe releases the GIL, so the thread's writes overlap the work of
    the thread that makes the text. An error of the stream (disk full, a pipe whose reader
    left) is raised in the calling thread by the next ``write`` or by ``close``.
    """

    def __init__(self, stream: BinaryIO):
        self.stream = stream
        self.pending: list[bytes] = []
        self.pending_size = 0
        self.error: BaseException | None = None
        self.queue: queue.Queue = queue.Queue(QUEUE_CHUNKS)
        self.thread = threading.Thread(target=self._run, name="tvoronoi-writer", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while True:
            chunk = self.queue.get()
            if chunk is None:
                return
            if self.error is None:
                try:
                    self.stream.write(chunk)
                except BaseException as e:  # handed to the caller's thread
                    self.error = e

    def _check(self) -> None:
        if self.error is not None:
            error, self.error = self.error, None
            raise error

    def write(self, data: bytes) -> None:
        self._check()
        self.pending.append(data)
        self.pending_size += len(data)
        if self.pending_size >= MIN_CHUNK:
            self._hand_over()

    def _hand_over(self) -> None:
        if self.pending:
            chunk = self.pending[0] if len(self.pending) == 1 else b"".join(self.pending)
            self.pending, self.pending_size = [], 0
            self.queue.put(chunk)

    def close(self) -> None:
        """Write what is left and wait for the thread; raise the stream's error if it had one."""
        self._hand_over()
        self.queue.put(None)
        self.thread.join()
        self._check()

    def abandon(self) -> None:
        """Stop without waiting for what is queued (the run failed; the output is discarded)."""
        self.pending = []
        self.error = self.error or RuntimeError("abandoned")
        while True:  # make room for the stop sign: the thread skips what is queued anyway
            try:
                self.queue.get_nowait()
            except queue.Empty:
                break
        self.queue.put(None)


@contextmanager
def background(stream: BinaryIO) -> Iterator[BackgroundWriter]:
    """A :class:`BackgroundWriter` on ``stream``, closed (all written) at the end of the block."""
    writer = BackgroundWriter(stream)
    try:
        yield writer
    except BaseException:
        writer.abandon()
        raise
    writer.close()
