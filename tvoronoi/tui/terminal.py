"""Leave when the terminal has gone: a closed SSH session or tmux pane.

Textual's input thread reads its terminal until told to stop; once the terminal hangs up, every read
returns at once with nothing and the thread spins (a whole core, for as long as the process lives).
When the app runs under another process (`make run`), the hangup signal may go to that process alone,
so the app would never hear of it. Once a second, the app asks the terminal for its settings: a hung-up
terminal answers with an I/O error, and the app then exits.
"""

from __future__ import annotations

import os
import sys
import termios
from typing import Protocol

# how often the terminal is looked at (seconds)
CHECK_EVERY = 1.0


class Host(Protocol):
    """What the watch needs of the app."""

    @property
    def is_headless(self) -> bool: ...

    def set_interval(self, interval: float, callback) -> object: ...
    def exit(self) -> None: ...


def terminal_fd() -> int | None:
    """The descriptor of the terminal the app reads, or None when its input is not a terminal."""
    stream = sys.__stdin__
    try:
        fd = stream.fileno() if stream is not None else -1
    except (OSError, ValueError):
        return None
    return fd if fd >= 0 and os.isatty(fd) else None


def is_gone(fd: int) -> bool:
    """True when the terminal behind fd has hung up (or the descriptor is no longer a terminal)."""
    try:
        termios.tcgetattr(fd)
    except (termios.error, OSError, ValueError):
        return True
    return False


def watch(app: Host, fd: int | None = None) -> bool:
    """Exit the app once its terminal has gone (checked every CHECK_EVERY seconds). Nothing is watched
    in a headless app (tests) or without a terminal; returns whether a watch was started."""
    fd = terminal_fd() if fd is None else fd
    if app.is_headless or fd is None:
        return False

    def check() -> None:
        if is_gone(fd):
            app.exit()

    app.set_interval(CHECK_EVERY, check)
    return True
