"""Long kernel runs answer signals: each phase stops inside its loop, with the handler's exception.

A SIGALRM handler stands in for Ctrl-C (KeyboardInterrupt) and for the CLI's SIGTERM handler: the timer
fires while a kernel runs on a million sites, and the exception must come out of the kernel's own poll
(kernels/interrupt.pxd) -- not after the phase has finished, which is what a kernel that never looks at
signals would give. The batch CLI is then checked end to end with a real SIGINT and SIGTERM.
"""

from __future__ import annotations

import os
import pty
import select
import signal
import subprocess
import sys
import time
import traceback

import numpy as np
import pytest

import tvoronoi
from tvoronoi import engines
from tvoronoi.api import default_bbox
from tvoronoi.kernels import clip, fortune, incremental, order, sweep_order

N = 1_000_000
pytestmark = pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs signal.setitimer")


class Alarm(Exception):
    pass


@pytest.fixture(scope="module")
def points():
    return np.random.default_rng(7).random((N, 2))


@pytest.fixture
def alarm():
    """Arm a timer whose handler raises Alarm; yields the arming function."""

    def handler(signum, frame):
        raise Alarm

    previous = signal.signal(signal.SIGALRM, handler)

    def arm(seconds: float):
        signal.setitimer(signal.ITIMER_REAL, seconds)

    yield arm
    signal.setitimer(signal.ITIMER_REAL, 0)
    signal.signal(signal.SIGALRM, previous)


def stopped_in_kernel(arm, run) -> str:
    """Run the call with the timer armed; the handler must run from the kernels' poll (interrupt.pxd).

    Returns the file of the kernel frame that polled. The timer may land in the Python set-up around the
    kernel on a slow machine, so a few delays are tried (from 5 ms: on a fast host a kernel on a million
    sites may finish within 20 ms); a kernel that never polls fails them all.
    """
    seen = []
    for delay in (0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.4):
        arm(delay)
        try:
            run()
        except Alarm as exc:
            files = [frame.filename for frame in traceback.extract_tb(exc.__traceback__)]
            # the last frame is the handler; the one below it is where Python ran it
            if files[-2].endswith("interrupt.pxd"):
                return files[-3]
            seen.append(files[-2])
        else:
            seen.append("finished")
        finally:
            arm(0)
    pytest.fail(f"the signal was never handled inside a kernel: {seen}")


def test_order_answers_signals(points, alarm):
    xs, ys = np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1])
    assert stopped_in_kernel(alarm, lambda: order.brio_order(xs, ys, 0)).endswith("order.pyx")


def test_sweep_order_answers_signals(alarm):
    # a shuffled 1,500 x 1,500 grid: 1,500 runs of equal y, each sorted again by x (sweep_rows alone)
    g = np.arange(1500.0)
    gx, gy = np.meshgrid(g, g)
    pts = np.c_[gx.ravel(), gy.ravel()][np.random.default_rng(7).permutation(g.size**2)]
    xs, ys = np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1])
    key = np.empty(len(xs), np.uint64)
    row_bits = sweep_order.sweep_keys(ys, key)
    key.sort()
    perm = np.empty(len(xs), np.int32)
    run = lambda: sweep_order.sweep_rows(key, row_bits, xs, ys, perm)  # noqa: E731
    assert stopped_in_kernel(alarm, run).endswith("sweep_order.pyx")


def test_incremental_answers_signals(points, alarm):
    s = engines.prepare(points[:, 0], points[:, 1], engine="incremental")
    assert stopped_in_kernel(alarm, lambda: incremental.triangulate(s.xs, s.ys)).endswith("incremental.pyx")


def test_fortune_answers_signals(points, alarm):
    s = engines.prepare(points[:, 0], points[:, 1], engine="fortune")
    assert stopped_in_kernel(alarm, lambda: fortune.sweep(s.xs, s.ys)).endswith("fortune.pyx")


def test_dual_and_clip_answer_signals(points, alarm):
    t = engines.run(points[:, 0], points[:, 1], engine="incremental")
    assert stopped_in_kernel(alarm, t.voronoi).endswith("dual.pyx")
    out = t.voronoi()
    s = t.sites
    first = (out["dup"] < 0).astype(np.int8)
    box = default_bbox(points)
    assert stopped_in_kernel(
        alarm,
        lambda: clip.clip_cells(
            s.xs,
            s.ys,
            out["vertices"],
            out["he_origin"],
            out["he_twin"],
            out["he_face"],
            out["face_edge"],
            first,
            box,
            s.exponent,
        ),
    ).endswith("clip.pyx")


def test_a_build_after_an_interrupted_one_is_whole(points, alarm):
    """Nothing a stopped kernel left behind changes the next build."""
    sub = points[:20_000]
    want = tvoronoi.voronoi(sub)
    s = engines.prepare(points[:, 0], points[:, 1], engine="incremental")
    stopped_in_kernel(alarm, lambda: incremental.triangulate(s.xs, s.ys))
    got = tvoronoi.voronoi(sub)
    assert np.array_equal(got.cell_points, want.cell_points)
    assert np.array_equal(got.cell_offsets, want.cell_offsets)


def _wait_for(fd: int, text: bytes, proc: subprocess.Popen, limit: float) -> bytes:
    """Read the terminal's output until ``text`` shows (the bytes read so far), the child ends or time is up."""
    seen = b""
    deadline = time.monotonic() + limit
    while text not in seen and proc.poll() is None and time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.05)
        if ready:
            try:
                seen += os.read(fd, 65536)
            except OSError:  # the child closed the terminal
                break
    return seen


def _drain(fd: int, proc: subprocess.Popen, limit: float) -> bytes:
    """Keep reading the terminal (so that the child never blocks on it) until the child ends."""
    seen = b""
    deadline = time.monotonic() + limit
    while proc.poll() is None and time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.05)
        if ready:
            try:
                seen += os.read(fd, 65536)
            except OSError:
                break
    return seen


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_batch_stops_on_signal_and_leaves_no_file(tmp_path, sig, code):
    """`tvoronoi batch` on 2,000,000 points, signalled while its engine runs: it ends at once, writes nothing.

    Its standard error is a terminal, so that the batch shows its phases; the signal goes out once the
    build phase is on the screen (a fixed delay raced the whole run on a fast host, where the batch could
    be done before the signal came).
    """
    src = tmp_path / "points.npy"
    np.save(src, np.random.default_rng(3).random((2_000_000, 2)))
    out = tmp_path / "cells.geojson"
    master, slave = pty.openpty()
    # a child of a background job inherits SIGINT ignored, and Python then leaves it ignored: give the
    # child the default disposition, as a terminal would
    # (a terminal that draws: under TERM=dumb the progress display is drawn only once it stops)
    proc = subprocess.Popen(
        [sys.executable, "-m", "tvoronoi", "batch", str(src), "-o", str(out)],
        stdout=subprocess.PIPE,
        stderr=slave,
        env=dict(os.environ, TERM="xterm-256color"),
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    os.close(slave)
    try:
        shown = _wait_for(master, b"build", proc, 60)
        assert b"build" in shown, f"the build phase never showed: {shown[-2000:]!r}"
        assert proc.poll() is None, "the batch ended before it was signalled"
        proc.send_signal(sig)
        shown += _drain(master, proc, 60)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:  # a kernel that ignores signals would not end: fail, don't hang
            proc.kill()
            proc.wait()
            pytest.fail("the batch did not stop on the signal")
        proc.stdout.close()
    finally:
        os.close(master)
    err = shown.decode(errors="replace")
    assert proc.returncode == code, err
    assert not out.exists()
    assert not [p for p in os.listdir(tmp_path) if p not in ("points.npy",)], os.listdir(tmp_path)
    assert "Traceback" not in err, err
