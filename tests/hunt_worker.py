"""Run cases in a child process with a time limit, so that an engine's crash or hang fails one case only.

The child (``python tests/hunt_worker.py --serve``) reads one JSON request a line on stdin (a family name,
or points and a box; the engine), builds the diagram, runs the checks of ``exact_checks`` and answers one
JSON line: ``{"build": "ok" | message, "box": ..., "delaunay": ..., "cells": ..., "distinct": ...,
"tiling": ..., "digest": ...}``, saving the cells (to compare engines) when asked. A request may also set
``"poison": BYTE`` (``np.empty`` fills new arrays with that byte during the build, see ``poisoned_empty``)
and ``"checks": false`` (build and digest only).

``Worker`` is the parent's side: it restarts the child after a crash or a timeout and reports ``crash
(signal ...): <fatal error or sanitizer line>`` or ``timeout after N s`` as every check's result.
``--kernels DIR`` makes the child load the compiled kernels from DIR (the checked build).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import selectors
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CHECK_NAMES = ("build", "box", "delaunay", "cells", "distinct", "tiling")


# ---------------------------------------------------------------------------------------------
# the child


def _use_kernels(directory: str) -> None:
    """Make ``tvoronoi.kernels.<x>`` load the extension modules of DIR/tvoronoi/kernels first."""
    import tvoronoi.kernels

    kdir = str(Path(directory, "tvoronoi", "kernels").resolve())
    if not os.path.isdir(kdir):
        raise SystemExit(f"no kernels in {kdir}")
    tvoronoi.kernels.__path__.insert(0, kdir)
    from tvoronoi.kernels import clip, dual, fortune, incremental  # noqa: F401

    for mod in (clip, dual, fortune, incremental):
        assert mod.__file__.startswith(kdir), f"{mod.__name__} loaded from {mod.__file__}, not {kdir}"


@contextlib.contextmanager
def poisoned_empty(byte: int | None):
    """While active, ``numpy.empty`` fills every new array with this byte (None: leave it alone).

    The kernels allocate their work arrays with ``np.empty``; an engine whose result changes with the byte
    reads memory it never wrote.
    """
    if byte is None:
        yield
        return
    real = np.empty

    def empty(*args, **kwargs):
        a = real(*args, **kwargs)
        if a.size and a.flags.c_contiguous:
            a.reshape(-1).view(np.uint8)[:] = byte
        return a

    np.empty = empty
    try:
        yield
    finally:
        np.empty = real


def digest(d) -> str:
    """A hash of a diagram's triangles and clipped cells (equal hashes: the same output bit for bit)."""
    h = hashlib.sha1()
    for a in (d.triangles, d.site_of, d.cell_points, d.cell_offsets, d.cell_vertices):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _serve(kernels: str | None) -> None:
    import faulthandler

    faulthandler.enable()
    proto = os.fdopen(os.dup(1), "w")  # answers go to the real stdout ...
    os.dup2(2, 1)  # ... and anything printed to stderr
    sys.path.insert(0, str(HERE))
    if kernels:
        _use_kernels(kernels)
    import adversarial
    import exact_checks
    import tvoronoi
    from tvoronoi import halves

    default_split_min = halves.SPLIT_MIN_SITES
    unraisable: list[str] = []

    def hook(u):  # an error inside a noexcept kernel function
        unraisable.append(f"{type(u.exc_value).__name__}: {u.exc_value} (in {u.object!r})")

    sys.unraisablehook = hook
    proto.write(json.dumps({"ready": True}) + "\n")
    proto.flush()
    for line in sys.stdin:
        req = json.loads(line)
        if req.get("selftest") == "asan":  # overflow a numpy buffer: ASan must stop the child here
            import ctypes

            src, dst = np.zeros(64), np.zeros(128)
            ctypes.memmove(dst.ctypes.data, src.ctypes.data, 8 * 65)
            proto.write(json.dumps({"build": "not caught"}) + "\n")
            proto.flush()
            continue
        if "family" in req:
            case = adversarial.make(req["family"], req.get("seed", adversarial.SEED))
            pts, bbox = case.points, case.bbox
        else:
            pts = np.array(req["points"], np.float64).reshape(-1, 2)
            bbox = req.get("bbox")
        out: dict = {}
        unraisable.clear()
        try:
            # split_min: builds from that many sites go by halves (tvoronoi.halves), on two threads
            halves.SPLIT_MIN_SITES = req.get("split_min", default_split_min)
            threads = 2 if "split_min" in req else None
            with poisoned_empty(req.get("poison")):
                d = tvoronoi.voronoi(pts, engine=req["engine"], bbox=bbox, threads=threads)
            out["build"] = "ok"
        except Exception as exc:  # noqa: BLE001 -- reported, not hidden
            tb = traceback.extract_tb(exc.__traceback__)[-1]
            out["build"] = f"{type(exc).__name__}: {exc} (at {Path(tb.filename).name}:{tb.lineno})"
            d = None
        if unraisable:
            out["build"] = "error ignored inside a kernel: " + unraisable[0]
        if d is not None:
            out["digest"] = digest(d)
        for name in CHECK_NAMES[1:]:
            if d is None or not req.get("checks", True):
                out[name] = "not run" + (" (no diagram)" if d is None else "")
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
            np.savez(req["save"], lengths=lengths, points=np.concatenate(cells) if cells else np.empty((0, 2)))
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

    def __init__(
        self,
        *,
        kernels: str | None = None,
        env: dict | None = None,
        python: str = sys.executable,
        start_timeout: float = 120.0,
    ):
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
        self.proc = subprocess.Popen(
            cmd,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.stderr,
            cwd=str(ROOT),
            env=env,
            text=True,
            bufsize=1,
        )
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


def sanitizer_env(kernels: str) -> dict:
    """The environment a child needs for kernels built with AddressSanitizer (empty if they were not).

    Python itself is not instrumented, so the ASan runtime must be loaded first (LD_PRELOAD); leak
    detection is off (the interpreter keeps memory to the end by design).
    """
    sos = sorted(Path(kernels, "tvoronoi", "kernels").glob("*.so"))
    if not sos:
        return {}
    out = subprocess.run(["ldd", str(sos[0])], capture_output=True, text=True, check=False).stdout
    libs = [ln.split("=>")[1].split("(")[0].strip() for ln in out.splitlines() if "libasan" in ln and "=>" in ln]
    if not libs:
        return {}
    # every new heap block filled with 0xbe (by default only its first 4 KiB): a read of memory never written
    # then gives the same garbage each run (int32 -1094795586, a negative index) instead of whatever was there
    opts = "detect_leaks=0:halt_on_error=1:malloc_fill_byte=190:max_malloc_fill_size=1073741824"
    return {"LD_PRELOAD": libs[0], "ASAN_OPTIONS": opts}


# Bytes that np.empty's arrays are filled with: zeros, all ones (int32 -1, NaN), and 0x01 (int32 16843009:
# an index far out of any array).
POISONS = (0x00, 0xFF, 0x01)


def uninit_result(worker: Worker, request: dict, reference: dict, *, timeout: float) -> str:
    """ "ok" if the build gives the same output (digest or error) whatever np.empty's arrays held."""
    if "digest" not in reference and not reference["build"].startswith(("crash", "timeout")):
        want = reference["build"]  # an error the engine reports: must stay the same
    elif "digest" in reference:
        want = reference["digest"]
    else:
        return f"not run: the engine fails without poison ({reference['build'][:60]})"
    for byte in POISONS:
        ans = worker.run(dict(request, poison=byte, checks=False, save=None), timeout=timeout)
        got = ans.get("digest", ans["build"])
        if got != want:
            what = ans["build"] if "digest" not in ans else "another diagram"
            return f"with np.empty filled with 0x{byte:02x}: {what} (reads memory it did not write)"
    return "ok"


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--serve"]:
        _serve(args[args.index("--kernels") + 1] if "--kernels" in args else None)
    else:
        raise SystemExit("usage: hunt_worker.py --serve [--kernels DIR]")
