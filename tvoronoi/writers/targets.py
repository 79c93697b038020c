"""Where an output goes: a regular file written atomically, or a device, pipe or stdout written directly.

A regular file (or a symbolic link to one) is written under a temporary name
beside its target and renamed into place, so that a reader sees the old file or
the complete new one. Anything else that can take bytes -- a character device
such as ``/dev/null``, a named pipe, ``/dev/stdout`` or an inherited descriptor
(``/dev/fd/N``) -- is opened and written as it is: renaming a file over it would
destroy it (a device node replaced by a regular file), and a pipe's reader would
never see the data. Such outputs need no ``--force``: writing to them replaces
nothing.
"""

from __future__ import annotations

import errno
import io
import os
import re
import secrets
import stat
import sys
from contextlib import contextmanager
from typing import BinaryIO, Iterator

from tvoronoi.fileio import STDIO, WritebackFile

__all__ = ["STDIO", "TEMP_SUFFIX", "AtomicFile", "DirectFile", "StdoutFile", "open_output", "output_file"]

TEMP_SUFFIX = ".tmp"
NEW_FILE_MODE = 0o666  # before the umask, as open() would create it
WRITE_BUFFER = 1 << 20
# names of an inherited descriptor: written through that descriptor, never opened anew (which
# would truncate or rewind a file the shell opened for appending) and never renamed over
_DESCRIPTOR_NAME = re.compile(r"/(?:dev/(?:fd/(?P<fd>[0-9]+)|(?P<std>stdout|stderr))|proc/self/fd/(?P<pfd>[0-9]+))")
_STD_FDS = {"stdout": 1, "stderr": 2}


class AtomicFile:
    """A binary file written under a temporary name beside its target, renamed into place on commit.

    The temporary file ``.NAME.tvoronoi-XXXXXXXX.tmp`` lives in the target's
    directory, so that ``os.replace`` is a rename within one file system: the
    target either keeps its old content or gets the complete new one.

    Parameters
    ----------
    path : str or os.PathLike
        The target. A symbolic link is followed: the file it points to is
        replaced, or created when it is missing, and the link keeps pointing to it.
    overwrite : bool
        Replace an existing target; if False, ``FileExistsError`` is raised when the
        target (what a link points to) exists, on opening and again just before the rename.

    Raises
    ------
    FileExistsError
        The target exists and ``overwrite`` is False.
    OSError
        The directory is missing or not writable, or the target is a directory.
    """

    direct = False

    def __init__(self, path: str | os.PathLike, *, overwrite: bool = True):
        self.path = os.fspath(path)
        self.target = os.path.realpath(self.path) if os.path.islink(self.path) else self.path
        self.overwrite = overwrite
        self.done = False
        self._check_target()
        directory, name = os.path.split(os.path.abspath(self.target))
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
        while True:
            self.temp = os.path.join(directory, f".{name}.tvoronoi-{secrets.token_hex(4)}{TEMP_SUFFIX}")
            try:
                fd = os.open(self.temp, flags, NEW_FILE_MODE)
            except FileExistsError:  # a name another run holds: draw again
                continue
            break
        # its data goes to disk as it is written, so that commit's fsync waits for little
        self.file: BinaryIO = io.BufferedWriter(WritebackFile(fd), WRITE_BUFFER)

    def _check_target(self) -> None:
        if os.path.isdir(self.target):
            raise IsADirectoryError(errno.EISDIR, "is a directory", self.path)
        # what a link leads to: a link whose target is missing is no existing output (its target
        # is written, the link kept); one in a loop leads to a link, which exists
        if not self.overwrite and os.path.lexists(self.target):
            raise FileExistsError(errno.EEXIST, "file exists", self.path)
        try:
            mode = os.stat(self.target).st_mode
        except OSError:
            return
        if not stat.S_ISREG(mode):
            # it became a device or a pipe since the kind of output was chosen: never rename over it
            raise OSError(errno.EEXIST, f"{_kind(mode)} appeared in its place", self.path)

    def commit(self) -> None:
        """Flush the data to disk and rename the file into place (keeping an old target's mode)."""
        try:
            self.file.flush()
            os.fsync(self.file.fileno())
            self.file.close()
            self._check_target()
            try:
                os.chmod(self.temp, stat.S_IMODE(os.stat(self.target).st_mode))
            except FileNotFoundError:
                pass
            os.replace(self.temp, self.target)
        except BaseException:
            self.discard()
            raise
        self.done = True

    def discard(self) -> None:
        """Close and remove the temporary file; the target is left as it was. No-op after commit."""
        if self.done:
            return
        self.done = True
        try:
            self.file.close()
        except OSError:
            pass
        try:
            os.unlink(self.temp)
        except FileNotFoundError:
            pass


class DirectFile:
    """A character device or a named pipe, opened and written as it is (commit flushes).

    Opening a named pipe waits for its reader, as a shell redirection does.
    A failed run cannot take back what was written.
    """

    direct = True

    def __init__(self, path: str | os.PathLike):
        self.path = os.fspath(path)
        fd = os.open(self.path, os.O_WRONLY | getattr(os, "O_BINARY", 0))
        self.file: BinaryIO = os.fdopen(fd, "wb", buffering=WRITE_BUFFER)

    def commit(self) -> None:
        self.file.flush()
        self.file.close()

    def discard(self) -> None:
        try:
            self.file.close()
        except OSError:  # the unflushed rest cannot go anywhere (a reader that left)
            pass


class StdoutFile:
    """Standard output, or another inherited descriptor, written directly (commit flushes)."""

    direct = True

    def __init__(self, fd: int = 1, path: str = STDIO):
        self.path = path
        if fd == 1:
            self.file: BinaryIO = sys.stdout.buffer
            sys.stdout.flush()
        else:
            self.file = os.fdopen(os.dup(fd), "wb", buffering=WRITE_BUFFER)
        self.fd = fd

    def commit(self) -> None:
        self.file.flush()
        if self.fd != 1:
            self.file.close()

    def discard(self) -> None:
        if self.fd != 1:
            try:
                self.file.close()
            except OSError:
                pass


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISFIFO, "a named pipe"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISDIR, "a directory"),
    ):
        if test(mode):
            return name
    return "not a regular file"


def descriptor_of(path: str) -> int | None:
    """The inherited descriptor a name like ``/dev/stdout`` or ``/dev/fd/3`` stands for, else None."""
    match = _DESCRIPTOR_NAME.fullmatch(path)
    if match is None:
        return None
    if match["std"]:
        return _STD_FDS[match["std"]]
    return int(match["fd"] or match["pfd"])


def is_direct(out) -> bool:
    """Whether ``out`` is written directly: ``"-"``, a descriptor name, a character device or a pipe."""
    if isinstance(out, str) and (out == STDIO or descriptor_of(out) is not None):
        return True
    try:
        mode = os.stat(out).st_mode
    except (OSError, TypeError, ValueError):
        return False
    return stat.S_ISCHR(mode) or stat.S_ISFIFO(mode)


def output_file(out, *, overwrite: bool = True) -> AtomicFile | DirectFile | StdoutFile:
    """The output for ``out``: a :class:`StdoutFile` for ``"-"`` and descriptor names, a
    :class:`DirectFile` for a character device or a named pipe (through symbolic links),
    an :class:`AtomicFile` for anything else.

    Write to ``.file``, then call ``.commit()`` on success or ``.discard()`` on failure.

    Raises
    ------
    FileExistsError
        ``overwrite`` is False and a regular file (or a link to one) is at ``out``.
    OSError
        The output cannot be created or opened; a block device or a socket (never written).
    """
    if isinstance(out, str):
        if out == STDIO:
            return StdoutFile()
        fd = descriptor_of(out)
        if fd is not None:
            return StdoutFile(fd, out)
    try:
        mode = os.stat(out).st_mode
    except (FileNotFoundError, NotADirectoryError):
        mode = None
    if mode is not None and (stat.S_ISCHR(mode) or stat.S_ISFIFO(mode)):
        return DirectFile(out)
    if mode is not None and not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise OSError(
            errno.EINVAL, f"is {_kind(mode)}; tvoronoi writes files, character devices and pipes", os.fspath(out)
        )
    return AtomicFile(out, overwrite=overwrite)


@contextmanager
def open_output(out, *, overwrite: bool = True) -> Iterator[BinaryIO]:
    """A binary stream for ``out``: a path, ``"-"`` (stdout) or an open binary file.

    A regular file is written through an :class:`AtomicFile`: it is renamed
    into place when the block ends normally and removed when the block raises,
    so a failure never leaves half a file and never touches an existing one.
    Devices, pipes and standard output are written directly and flushed at the
    end; an open file is used as it is.

    Raises
    ------
    FileExistsError
        If ``overwrite`` is False and a regular file is at the path.
    OSError
        If the output cannot be created or written.
    """
    if hasattr(out, "write"):
        yield out
        return
    target = output_file(out, overwrite=overwrite)
    try:
        yield target.file
    except BaseException:
        target.discard()
        raise
    target.commit()
