"""The terminal UI leaves when its terminal hangs up (tvoronoi/tui/terminal.py)."""

import os
import subprocess
import sys
import time

import pytest

from tvoronoi.tui import terminal


def test_a_hung_up_terminal_is_gone():
    """A pseudo-terminal whose other end closes (as a closed SSH session or tmux pane does) answers with
    an I/O error; while open, it does not."""
    master, slave = os.openpty()
    try:
        assert not terminal.is_gone(slave)
        os.close(master)
        assert terminal.is_gone(slave)
    finally:
        os.close(slave)


def test_a_file_is_not_a_terminal(tmp_path):
    with open(tmp_path / "f", "w") as f:
        assert terminal.is_gone(f.fileno())


class FakeApp:
    def __init__(self, headless: bool):
        self.is_headless = headless
        self.callbacks: list = []
        self.exited = 0

    def set_interval(self, interval, callback):
        self.callbacks.append(callback)

    def exit(self):
        self.exited += 1


def test_the_watch_exits_the_app_once_the_terminal_hangs_up():
    master, slave = os.openpty()
    app = FakeApp(headless=False)
    try:
        assert terminal.watch(app, slave)
        (check,) = app.callbacks
        check()
        assert app.exited == 0
        os.close(master)
        check()
        assert app.exited == 1
    finally:
        os.close(slave)


def test_no_watch_in_a_headless_app():
    master, slave = os.openpty()
    try:
        app = FakeApp(headless=True)
        assert not terminal.watch(app, slave)
        assert not app.callbacks
    finally:
        os.close(master)
        os.close(slave)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="pseudo-terminals as on Linux")
def test_the_app_leaves_when_its_terminal_closes_under_another_process():
    """The app started by another process on a pseudo-terminal (as `make run` does); the terminal's other
    end closes, and no hangup signal reaches the app: it exits within a few seconds instead of spinning."""
    master, slave = os.openpty()
    os.set_blocking(master, False)
    env = dict(os.environ, TERM="xterm-256color", COLUMNS="80", LINES="24")
    proc = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import signal; signal.signal(signal.SIGHUP, signal.SIG_IGN); from tvoronoi.tui.app import main; main()",
        ],
        stdin=slave,
        stdout=slave,
        stderr=slave,
        env=env,
        start_new_session=True,
        close_fds=True,
    )
    os.close(slave)
    try:
        deadline = time.monotonic() + 30
        seen = b""
        while time.monotonic() < deadline and b"sites" not in seen:  # drawn: the status line is up
            try:
                seen += os.read(master, 65536)
            except BlockingIOError:
                time.sleep(0.1)
            except OSError:
                break
        os.close(master)
        proc.wait(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
            pytest.fail("the app kept running after its terminal closed")
