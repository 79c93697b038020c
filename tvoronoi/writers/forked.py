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


# the signals a batch stops on, deferred while it forks
_HELD = (signal.SIGINT, signal.SIGTERM)


def _hold_signals() -> tuple[dict, list]:
    """Defer Ctrl-C and SIGTERM: until _release_signals their handlers are replaced by one that only
    notes them. (Blocking them would not do: a signal sent to the process reaches whichever thread
    does not block it, such as the kernels' OpenMP threads, and Python runs the handler on the main
    thread all the same.) Returns the handlers to restore and the list of signals noted."""
    noted: list[int] = []

    def note(signum, frame) -> None:
        noted.append(signum)

    saved = {}
    for s in _HELD:
        try:
            saved[s] = signal.signal(s, note)
        except (ValueError, OSError):  # not the main thread, or not settable here
            pass
    return saved, noted


def _restore_signals(held: tuple[dict, list]) -> list[int]:
    """Put the handlers back; returns the signals noted meanwhile that their handlers would act on."""
    saved, noted = held
    for s, handler in saved.items():
        signal.signal(s, handler)
    return [s for s in dict.fromkeys(noted) if saved.get(s) not in (signal.SIG_IGN, None)]


def _deliver(signals: list[int], held: tuple[dict, list]) -> None:
    """Run the restored handler of each signal noted (it raises, as it would have), or for the default
    disposition send the signal again."""
    saved, _ = held
    for s in signals:
        handler = saved[s]
        if callable(handler):
            handler(s, None)
        else:
            signal.raise_signal(s)


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
            _deliver(_restore_signals(held), held)
            for fd in (read_end, write_end):
                os.close(fd)
            self.part.close()
            raise
        if pid == 0:  # the child: write, report, and leave without running the parent's exit code
            os.close(read_end)
            status, report = 1, _TVORONOI + b" the second half of the output failed"
            try:
                _restore_signals(held)  # (what came before the fork is the parent's to act on)
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
        came = _restore_signals(held)
        if came:  # a signal came meanwhile: stop the child, then act on it as its handler would have
            self.abandon()
            _deliver(came, held)

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
