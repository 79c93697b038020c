"""The second half of an output made by a forked process, on the second core, and appended when the first half is written.

Serializing a million cells to JSON holds the GIL (orjson, bytes joins), so a thread cannot
share the work; a forked child can: it sees the diagram as it is (copy on write, nothing is
copied), writes its part to an unnamed temporary file, and the parent appends that file to
the output once its own part is written (``sendfile``, within the kernel).
"""

from __future__ import annotations

import errno
import os
import select
import shutil
import signal
import stat
import sys
import tempfile
import threading
from typing import BinaryIO, Callable

from tvoronoi.errors import TvoronoiError
from tvoronoi.fileio import WRITEBACK_BYTES, start_writeback

# outputs of fewer features are written by one process: a fork costs a few milliseconds
MIN_FEATURES = 100_000
WRITE_BUFFER = 1 << 20
# how long the parent waits for the child's report before copying what the child wrote since
POLL_SECONDS = 0.005
# what the child reports on its pipe: "ok COUNT", or the kind of error and its message
_OK, _TVORONOI, _OS = b"ok", b"tvoronoi", b"os"


def can_fork() -> bool:
    """Whether a part of an output can be made by a forked process here: on Linux (fork is cheap),
    from the main thread (the batch command; an application saving from a worker thread, such
    as the terminal UI, has threads of its own that may hold locks when it forks)."""
    return (
        sys.platform.startswith("linux")
        and hasattr(os, "fork")
        and threading.current_thread() is threading.main_thread()
    )


# the signals a batch stops on, held while it forks
_HELD = (signal.SIGINT, signal.SIGTERM)


def _hold_signals():
    """Block Ctrl-C and SIGTERM (pending ones wait); returns the mask to restore, or None where signal
    masks are not available."""
    if not hasattr(signal, "pthread_sigmask"):
        return None
    return signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)


def _release_signals(held) -> None:
    """Restore the mask _hold_signals saved: a signal that came meanwhile has its handler run now
    (pthread_sigmask runs pending handlers before it returns)."""
    if held is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


class ForkedPart:
    """Runs ``write_part(file)`` in a forked child, into a temporary file, while the caller goes on.

    ``write_part`` returns a count (of features written), handed back by :meth:`append_to`.
    Fork before starting any thread of one's own: the child has only the forking thread.
    """

    def __init__(self, stream: BinaryIO, write_part: Callable[[BinaryIO], int]):
        self.pid: int | None = None
        self.part = tempfile.TemporaryFile(dir=_directory_of(stream))
        try:
            read_end, write_end = os.pipe()
        except OSError:
            self.part.close()
            raise
        sys.stdout.flush()
        sys.stderr.flush()
        # Ctrl-C and SIGTERM wait while the process forks: a handler run inside fork's own hooks
        # (logging's, in the parent) has its exception ignored, and the batch would go on as if
        # never signalled. They are delivered once the child is known, below.
        held = _hold_signals()
        try:
            pid = os.fork()
        except OSError:
            _release_signals(held)
            for fd in (read_end, write_end):
                os.close(fd)
            self.part.close()
            raise
        if pid == 0:  # the child: write, report, and leave without running the parent's exit code
            os.close(read_end)
            status, report = 1, _TVORONOI + b" the second half of the output failed"
            try:
                _release_signals(held)
                signal.signal(signal.SIGINT, signal.SIG_DFL)
                with os.fdopen(os.dup(self.part.fileno()), "wb", buffering=WRITE_BUFFER) as file:
                    count = write_part(file)
                status, report = 0, b"%b %d" % (_OK, count)
            except TvoronoiError as e:
                report = _TVORONOI + b" " + str(e).encode()
            except OSError as e:
                report = b"%b %d %b" % (_OS, e.errno or 0, (e.strerror or str(e)).encode())
            except BaseException as e:  # noqa: BLE001 (reported to the parent, which raises)
                report = _TVORONOI + b" " + f"the second half of the output failed: {e!r}".encode()
            finally:
                try:
                    os.write(write_end, report)
                finally:
                    os._exit(status)
        os.close(write_end)
        self.pid, self.reports = pid, read_end
        try:
            _release_signals(held)  # a signal that came meanwhile raises here: stop the child too
        except BaseException:
            self.abandon()
            raise

    def append_to(self, stream: BinaryIO) -> int:
        """Append the child's part to ``stream`` as the child writes it, then the rest once it has
        reported; return its count. Raise its error (what was appended is then incomplete)."""
        appender = _Appender(self.part, stream)
        # while the child works, what it has written so far (its writes reach the file a
        # megabyte at a time): the copy overlaps the wait
        while not select.select([self.reports], [], [], POLL_SECONDS)[0]:
            appender.step()
        report = self._wait()
        kind, _, rest = report.partition(b" ")
        if kind == _OS:
            code, _, message = rest.partition(b" ")
            raise OSError(int(code), message.decode(errors="replace"))
        if kind != _OK:
            raise TvoronoiError(rest.decode(errors="replace"))
        try:
            appender.finish()
        finally:
            self.part.close()
        return int(rest)

    def abandon(self) -> None:
        """Stop the child (the run failed) and drop its part."""
        if self.pid is not None:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            self._wait()
        self.part.close()

    def _wait(self) -> bytes:
        chunks = []
        while chunk := os.read(self.reports, 1 << 16):
            chunks.append(chunk)
        os.close(self.reports)
        assert self.pid is not None
        os.waitpid(self.pid, 0)
        self.pid = None
        return b"".join(chunks)


def _directory_of(stream) -> str | None:
    """The directory of a regular file being written (its part goes beside it, on the same disk);
    None (the temporary directory) for anything else."""
    try:
        fd = stream.fileno()
        if stat.S_ISREG(os.fstat(fd).st_mode):
            return os.path.dirname(os.readlink(f"/proc/self/fd/{fd}"))
    except (OSError, AttributeError, ValueError):
        pass
    return None


def _copy(part: BinaryIO, stream: BinaryIO) -> None:
    """Append the whole of ``part`` to ``stream``: in the kernel when both are descriptors."""
    copier = _Appender(part, stream)
    copier.step()
    copier.finish()


class _Appender:
    """Appends a growing file (a part a child is still writing) to a stream, as it grows:
    ``step`` copies what is there so far, ``finish`` the rest (once it has stopped growing)."""

    def __init__(self, part: BinaryIO, stream: BinaryIO):
        self.part, self.stream, self.copied = part, stream, 0
        try:
            self.fd: int | None = stream.fileno()
        except (OSError, AttributeError, ValueError):
            self.fd = None
        self.start: int | None = None
        if self.fd is not None:
            stream.flush()
            try:
                self.start = os.lseek(self.fd, 0, os.SEEK_CUR)
            except OSError:  # a pipe: nothing to write back
                self.start = None

    def step(self) -> None:
        """Copy what the part holds beyond what was copied, in the kernel (nothing when the stream
        is not a descriptor sendfile writes to: then all of it at the end)."""
        if self.fd is None:
            return
        size = os.fstat(self.part.fileno()).st_size
        while self.copied < size:
            try:
                # a run at a time, each handed to the disk while the next is copied
                sent = os.sendfile(self.fd, self.part.fileno(), self.copied, min(size - self.copied, WRITEBACK_BYTES))
            except OSError as e:
                if self.copied or e.errno not in (errno.EINVAL, errno.ENOSYS):
                    raise
                self.fd = None  # a descriptor sendfile does not write to
                return
            if sent == 0:
                raise OSError(f"the output took no more bytes after {self.copied} of {size}")
            if self.start is not None:
                start_writeback(self.fd, self.start + self.copied, sent)
            self.copied += sent

    def finish(self) -> None:
        """Copy the rest of the part (complete now)."""
        if self.fd is None:
            self.part.seek(self.copied)
            shutil.copyfileobj(self.part, self.stream, WRITE_BUFFER)
            return
        self.step()
        if self.fd is None:  # sendfile refused the descriptor at its first run
            self.finish()
