"""Output targets: regular files atomic, devices, pipes and stdout written directly, links kept."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from tvoronoi import cli
from tvoronoi.writers import targets

ROOT = Path(__file__).resolve().parents[1]
CSV = "x,y,name\n0,0,a\n1,0,b\n0,1,c\n1,1,d\n0.5,0.4,e\n"


def batch(*args) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-m", "tvoronoi", "batch", *map(str, args)], capture_output=True, env=env, timeout=120
    )


@pytest.fixture
def points(tmp_path) -> Path:
    path = tmp_path / "p.csv"
    path.write_text(CSV)
    return path


def test_a_named_pipe_is_written_directly_with_or_without_force(tmp_path, points, capsys):
    fifo = tmp_path / "cells.fifo"
    os.mkfifo(fifo)
    for force in ([], ["--force"]):
        received = []
        reader = threading.Thread(target=lambda: received.append(fifo.read_bytes()))  # noqa: B023 (joined below)
        reader.start()
        status = cli.main(["batch", str(points), "-o", str(fifo), "-q", *force])
        reader.join(timeout=60)
        assert status == 0
        assert received and received[0].startswith(b'{"type":"FeatureCollection"')
        assert received[0].count(b'"type":"Feature"') == 5
        assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert {p.name for p in tmp_path.iterdir()} == {"cells.fifo", "p.csv"}  # no temporary file


def test_dev_null_stays_a_device(points, capsys):
    before = os.stat("/dev/null")
    assert cli.main(["batch", str(points), "-o", "/dev/null", "--force", "-q"]) == 0
    after = os.stat("/dev/null")
    assert stat.S_ISCHR(after.st_mode) and after.st_ino == before.st_ino and after.st_rdev == before.st_rdev


def test_kind_of_output():
    assert isinstance(targets.output_file("-"), targets.StdoutFile)
    assert isinstance(targets.output_file("/dev/stdout"), targets.StdoutFile)
    direct = targets.output_file("/dev/null")
    assert isinstance(direct, targets.DirectFile)
    direct.discard()
    assert targets.descriptor_of("/dev/fd/3") == 3 and targets.descriptor_of("/proc/self/fd/1") == 1
    assert targets.descriptor_of("/dev/stdoutx") is None


def test_dev_stdout_redirected_to_a_file_is_written_through_the_descriptor(tmp_path, points):
    """The shell's file behind /dev/stdout is neither replaced nor truncated: the output is appended."""
    out = tmp_path / "out.geojson"
    out.write_bytes(b"HEAD\n")
    with open(out, "ab") as sink:
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        status = subprocess.run(
            [sys.executable, "-m", "tvoronoi", "batch", str(points), "-o", "/dev/stdout"],
            stdout=sink,
            env=env,
            timeout=120,
        ).returncode
    assert status == 0
    data = out.read_bytes()
    assert data.startswith(b'HEAD\n{"type":"FeatureCollection"') and data.endswith(b"]}\n")


def test_a_symbolic_link_keeps_pointing_to_its_replaced_target(tmp_path, points, capsys):
    target = tmp_path / "real.geojson"
    target.write_bytes(b"old")
    link = tmp_path / "link.geojson"
    link.symlink_to(target.name)
    assert cli.main(["batch", str(points), "-o", str(link), "-q"]) == 2  # exists: needs --force
    assert target.read_bytes() == b"old"
    assert cli.main(["batch", str(points), "-o", str(link), "--force", "-q"]) == 0
    assert link.is_symlink() and os.readlink(link) == "real.geojson"
    assert target.read_bytes().count(b'"type":"Feature"') == 5


def test_a_dangling_symbolic_link_is_written_through_without_force(tmp_path, points, capsys):
    """A link whose target is missing is no existing output: the target is created, the link kept
    (through a chain of links too); once the target exists, the link needs --force again."""
    (tmp_path / "tgt").mkdir()
    link = tmp_path / "link.geojson"
    link.symlink_to("tgt/real.geojson")
    chain = tmp_path / "chain.geojson"
    chain.symlink_to("link2.geojson")
    (tmp_path / "link2.geojson").symlink_to("tgt/other.geojson")
    for name, target in ((link, "real.geojson"), (chain, "other.geojson")):
        assert cli.main(["batch", str(points), "-o", str(name), "-q"]) == 0
        assert name.is_symlink() and (tmp_path / "link2.geojson").is_symlink()
        assert (tmp_path / "tgt" / target).read_bytes().count(b'"type":"Feature"') == 5
        assert cli.main(["batch", str(points), "-o", str(name), "-q"]) == 2  # exists now
    assert "exists: add --force" in capsys.readouterr().err
    assert sorted(p.name for p in (tmp_path / "tgt").iterdir()) == ["other.geojson", "real.geojson"]


def test_a_symbolic_link_loop_is_not_replaced(tmp_path, points, capsys):
    (tmp_path / "a.geojson").symlink_to("b.geojson")
    (tmp_path / "b.geojson").symlink_to("a.geojson")
    for force in ([], ["--force"]):
        assert cli.main(["batch", str(points), "-o", str(tmp_path / "a.geojson"), "-q", *force]) != 0
        assert os.readlink(tmp_path / "a.geojson") == "b.geojson" and os.readlink(tmp_path / "b.geojson") == "a.geojson"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.geojson", "b.geojson", "p.csv"]


def test_stdout_dash(points, capsysbinary):
    assert cli.main(["batch", str(points), "-o", "-", "-q"]) == 0
    assert capsysbinary.readouterr().out.count(b'"type":"Feature"') == 5


def test_a_reader_leaving_early_ends_the_run_quietly(tmp_path):
    rng = np.random.default_rng(5)
    big = tmp_path / "big.csv"
    np.savetxt(big, rng.random((60_000, 2)), delimiter=",", header="x,y", comments="")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "tvoronoi", "batch", str(big), "-o", "-"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
    )
    proc.stdout.read(100)
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 1
    assert err == b""


def test_dev_null_may_take_both_outputs(points, capsys):
    assert cli.main(["batch", str(points), "-o", "/dev/null", "--delaunay", "/dev/null", "-q"]) == 0


def test_a_regular_file_is_handed_to_the_disk_as_it_is_written(tmp_path, monkeypatch):
    """The write-back is started for consecutive runs of the file, its own writes and those
    appended through the descriptor (a forked part's sendfile) alike; the content is the same."""
    from tvoronoi import fileio
    from tvoronoi.writers import forked

    calls: list[tuple[int, int]] = []
    monkeypatch.setattr(fileio, "WRITEBACK_BYTES", 1000)
    monkeypatch.setattr(forked, "WRITEBACK_BYTES", 1000)
    monkeypatch.setattr(fileio, "_sync_range_looked_up", True)
    monkeypatch.setattr(fileio, "_sync_range", lambda fd, offset, length, flags: calls.append((offset, length)) or 0)
    rng = np.random.default_rng(2)
    pieces = [rng.bytes(int(k)) for k in rng.integers(1, 3000, 40)]
    part = tmp_path / "part"
    part.write_bytes(b"".join(pieces[20:]))
    out = targets.output_file(str(tmp_path / "out.bin"))
    for piece in pieces[:20]:
        out.file.write(piece)
    with open(part, "rb") as source:
        forked._copy(source, out.file)
    out.commit()
    assert (tmp_path / "out.bin").read_bytes() == b"".join(pieces)
    assert calls and calls[0][0] == 0
    assert all(a + n == b for (a, n), (b, _) in zip(calls, calls[1:]))  # consecutive runs
    total = sum(map(len, pieces))
    assert total - 2 * 1000 <= calls[-1][0] + calls[-1][1] <= total


def test_start_writeback_on_this_system(tmp_path):
    """The real call (sync_file_range on Linux, nothing elsewhere) leaves the data as written."""
    from tvoronoi.fileio import start_writeback

    path = tmp_path / "f"
    with open(path, "wb") as f:
        f.write(b"x" * 10_000)
        f.flush()
        start_writeback(f.fileno(), 0, 10_000)
        start_writeback(-1, 0, 10)  # a bad descriptor: ignored
    assert path.read_bytes() == b"x" * 10_000


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the forked part is made on Linux")
@pytest.mark.parametrize("kind", ["file", "stream"])
def test_the_forked_part_is_appended_while_it_is_written(tmp_path, monkeypatch, kind):
    """The parent copies what the child has written so far while the child still writes (the
    child here pauses between runs); a stream that is not a descriptor gets it all at the end."""
    import io
    import time

    from tvoronoi.writers import forked

    rng = np.random.default_rng(8)
    runs = [rng.bytes(int(k)) for k in rng.integers(1, 300_000, 6)]

    def write_part(file) -> int:
        for run in runs:
            file.write(run)
            file.flush()
            time.sleep(0.03)
        return len(runs)

    out = targets.output_file(str(tmp_path / "out.bin")) if kind == "file" else None
    stream = out.file if out is not None else io.BytesIO()
    stream.write(b"head|")
    steps: list[int] = []
    step = forked._Appender.step

    def counted(self) -> None:
        step(self)
        steps.append(self.copied)

    monkeypatch.setattr(forked._Appender, "step", counted)
    part = forked.ForkedPart(stream, write_part)
    assert part.append_to(stream) == len(runs)
    expected = b"head|" + b"".join(runs)
    if out is not None:
        out.commit()
        assert (tmp_path / "out.bin").read_bytes() == expected
        # runs were copied before the child had written them all
        assert any(0 < copied < len(expected) - 5 for copied in steps)
    else:
        assert stream.getvalue() == expected
        assert not any(steps)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the forked part is made on Linux")
def test_a_signal_while_forking_stops_the_parent_and_the_child(monkeypatch):
    """SIGTERM arriving while the process forks (here: sent just before fork, to whichever thread takes
    it) is noted, then raises in the parent once the child is known (it was lost in fork's own hooks
    before), and the child is stopped."""
    import io
    import signal as signals
    import time

    from tvoronoi.writers import forked

    def terminate(signum, frame):
        raise SystemExit(128 + signum)

    real_fork, children = os.fork, []

    def fork():
        os.kill(os.getpid(), signals.SIGTERM)  # pending: the mask holds it
        pid = real_fork()
        if pid:
            children.append(pid)
        return pid

    def write_part(file) -> int:
        time.sleep(30)  # the child would take long: the parent must not wait for it
        return 0

    previous = signals.signal(signals.SIGTERM, terminate)
    monkeypatch.setattr(os, "fork", fork)
    try:
        started = time.monotonic()
        with pytest.raises(SystemExit) as stop:
            forked.ForkedPart(io.BytesIO(), write_part)
        assert stop.value.code == 128 + signals.SIGTERM
        assert signals.getsignal(signals.SIGTERM) is terminate  # the handler is back
    finally:
        signals.signal(signals.SIGTERM, previous)
    assert len(children) == 1
    with pytest.raises(ChildProcessError):  # reaped by abandon(): not left running or a zombie
        os.waitpid(children[0], os.WNOHANG)
    assert time.monotonic() - started < 20
