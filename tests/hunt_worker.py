"""Run cases in a child process with a time limit, so that an engine's crash or hang fails one case only.

The child (``python tests/hunt_worker.py``) reads one JSON request a line on stdin, builds the diagram,
runs the checks of ``exact_checks`` and answers one JSON line: ``{"build": "ok" | message, "box": ...,
"delaunay": ..., "cells": ..., "tiling": ...}``, and saves the cells (for comparing engines) when asked.
``Worker`` is the parent's side: it restarts the child after a crash or a timeout and reports
``crash: <signal or sanitizer line>`` or ``timeout after N s`` for that case.

``--kernels DIR`` loads the compiled kernels from DIR (the bounds-checked build) instead of the package's.
"""

from __future__ import annotations

import json
import os
import selectors
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CHECK_NAMES = ("build", "box", "delaunay", "cells", "tiling")


# ---------------------------------------------------------------------------------------------
# the child


def _use_kernels(directory: str) -> None:
    """Make ``tvoronoi.kernels.<x>`` load the extension modules of DIR/tvoronoi/kernels first."""
    import tvoronoi.kernels

    kdir = str(Path(directory, "tvoronoi", "kernels").resolve())
    if not os.path.isdir(kdir):
        raise SystemExit(f"no kernels in {kdir}")
    tvoronoi.kernels.__path__.insert(0, kdir)
    from tvoronoi.kernels import clip, dcel, delaunay, fortune  # noqa: F401

    for mod in (clip, dcel, delaunay, fortune):
        assert mod.__file__.startswith(kdir), f"{mod.__name__} loaded from {mod.__file__}, not {kdir}"


def _serve(kernels: str | None) -> None:
    import faulthandler

    faulthandler.enable()
    proto = os.fdopen(os.dup(1), "w")         # answers go to the real stdout ...
    os.dup2(2, 1)                             # ... and anything printed to stderr
    sys.path.insert(0, str(HERE))
    if kernels:
        _use_kernels(kernels)
    import adversarial
    import exact_checks
    import tvoronoi

    unraisable: list[str] = []

    def hook(u):                               # an error inside a noexcept kernel function
        unraisable.append(f"{type(u.exc_value).__name__}: {u.exc_value} (in {u.object!r})")

    sys.unraisablehook = hook
    proto.write(json.dumps({"ready": True}) + "\n")
    proto.flush()
    for line in sys.stdin:
        req = json.loads(line)
        if "family" in req:
            case = adversarial.make(req["family"], req.get("seed", adversarial.SEED))
            pts, bbox = case.points, case.bbox
        else:
            pts = np.array(req["points"], np.float64).reshape(-1, 2)
            bbox = req.get("bbox")
        out: dict = {}
        unraisable.clear()
        try:
            d = tvoronoi.voronoi(pts, engine=req["engine"], bbox=bbox)
            out["build"] = "ok"
        except Exception as exc:  # noqa: BLE001 -- reported, not hidden
            out["build"] = f"{type(exc).__name__}: {exc}"
            d = None
        if unraisable:
            out["build"] = "error ignored inside a kernel: " + unraisable[0]
        for name in CHECK_NAMES[1:]:
            if d is None:
                out[name] = "not run (no diagram)"
                continue
            try:
                exact_checks.CHECKS[name](d)
                out[name] = "ok"
            except AssertionError as exc:
                out[name] = str(exc) or "assertion failed"
            except Exception as exc:  # noqa: BLE001
                out[name] = f"{type(exc).__name__} in the check: {exc}"
        if d is not None and req.get("save"):
            cells = exact_checks.cells_of(d)
            lengths = np.array([len(r) for r in cells], np.int64)
            np.savez(req["save"], lengths=lengths,
                     points=np.concatenate(cells) if cells else np.empty((0, 2)))
            out["saved"] = req["save"]
        proto.write(json.dumps(out) + "\n")
        proto.flush()


def load_cells(path) -> list[np.ndarray]:
    """The cells a child saved, as a list of (k, 2) rings."""
    with np.load(path) as z:
        ends = np.cumsum(z["lengths"])
        return np.split(z["points"], ends[:-1]) if len(ends) else []


# ---------------------------------------------------------------------------------------------
# the parent


class Worker:
    """A child process that runs cases; restarted after a crash or a timeout."""

    def __init__(self, *, kernels: str | None = None, env: dict | None = None, python: str = sys.executable,
                 start_timeout: float = 120.0):
        self.kernels, self.env, self.python = kernels, env, python
        self.start_timeout = start_timeout
        self.proc: subprocess.Popen | None = None
        self.tmp = tempfile.TemporaryDirectory(prefix="tvoronoi-hunt-")
        self._n = 0

    def _start(self) -> None:
        cmd = [self.python, str(Path(__file__).resolve()), "--serve"]
        if self.kernels:
            cmd += ["--kernels", self.kernels]
        env = dict(os.environ, **(self.env or {}))
        self.stderr = open(Path(self.tmp.name, f"stderr{self._n}.txt"), "w+b")
        self._n += 1
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.stderr,
                                     cwd=str(ROOT), env=env, text=True, bufsize=1)
        ready = self._read(self.start_timeout)
        if ready is None or "ready" not in ready:
            raise RuntimeError(f"the worker did not start: {self._stderr_tail()}")

    def _read(self, timeout: float):
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        try:
            if not sel.select(timeout):
                return "timeout"
        finally:
            sel.close()
        line = self.proc.stdout.readline()
        return json.loads(line) if line else None

    def _stderr_tail(self) -> str:
        self.stderr.flush()
        self.stderr.seek(0)
        text = self.stderr.read().decode(errors="replace")
        lines = [ln for ln in text.splitlines() if ln.strip()]
        # a sanitizer's report: its ERROR line and the first frame in our code say the most
        key = [ln.strip() for ln in lines if "ERROR: AddressSanitizer" in ln or ln.startswith("SUMMARY:")]
        if key:
            return " | ".join(key[:2])
        fatal = [ln.strip() for ln in lines if ln.startswith("Fatal Python error")]
        where = [ln.strip() for ln in lines if ln.strip().startswith("File ")][:1]
        return " | ".join(fatal[:1] + where) or (lines[-1] if lines else "no message")

    def stop(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self.proc = None

    def close(self) -> None:
        self.stop()
        self.tmp.cleanup()

    def cells_path(self, key: str) -> str:
        return str(Path(self.tmp.name, key.replace("/", "_") + ".npz"))

    def run(self, request: dict, *, timeout: float = 60.0) -> dict:
        """Run one request; on a crash or timeout every check reports it and the child is restarted."""
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        t0 = time.monotonic()
        try:
            self.proc.stdin.write(json.dumps(request) + "\n")
            self.proc.stdin.flush()
            answer = self._read(timeout)
        except BrokenPipeError:
            answer = None
        if isinstance(answer, dict):
            answer["seconds"] = round(time.monotonic() - t0, 3)
            return answer
        if answer == "timeout":
            msg = f"timeout after {timeout:g} s"
            self.stop()
        else:
            self.proc.wait()
            code = self.proc.returncode
            sig = f"signal {signal.Signals(-code).name}" if code and code < 0 else f"exit {code}"
            msg = f"crash ({sig}): {self._stderr_tail()}"
            self.proc = None
        return {name: msg for name in CHECK_NAMES} | {"seconds": round(time.monotonic() - t0, 3)}


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--serve"]:
        _serve(args[args.index("--kernels") + 1] if "--kernels" in args else None)
    else:
        raise SystemExit("usage: hunt_worker.py --serve [--kernels DIR]")
