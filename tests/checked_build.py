"""The checked build of the kernels (bounds checks, AddressSanitizer): where it lives, building it, a worker on it.

``make checked`` (a step of ``make test``) builds the kernels into build/checked with Cython's boundscheck
and initializedcheck on and, by default, -fsanitize=address (setup.py, TVORONOI_CHECKED). A bare pytest
run builds it here if it is missing or older than the kernel sources (a few minutes, once).
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys

from hunt_worker import ROOT, Worker, sanitizer_env

CHECKED_DIR = ROOT / "build" / "checked"
KERNELS = ROOT / "tvoronoi" / "kernels"
# A build alone takes under two seconds here, and ASan slows it about twice.
TIMEOUT = 10.0


def built() -> bool:
    """The checked kernels exist and are newer than every kernel source and setup.py."""
    sos = list((CHECKED_DIR / "tvoronoi" / "kernels").glob("*.so"))
    sources = list(KERNELS.glob("*.pyx")) + list(KERNELS.glob("*.pxd")) + [ROOT / "setup.py"]
    return len(sos) >= len(list(KERNELS.glob("*.pyx"))) and min(p.stat().st_mtime for p in sos) >= max(
        p.stat().st_mtime for p in sources
    )


def ensure_built() -> None:
    if built():
        return
    env = dict(os.environ, TVORONOI_CHECKED=os.environ.get("CHECKED_MODE", "asan"))
    subprocess.run(
        [
            sys.executable,
            "setup.py",
            "-q",
            "build_ext",
            "--force",
            "--build-lib",
            str(CHECKED_DIR),
            "--build-temp",
            str(ROOT / "build" / "checked-tmp"),
        ],
        cwd=ROOT,
        env=env,
        check=True,
        capture_output=True,
    )


@contextlib.contextmanager
def checked_worker():
    """A child running the checked kernels (the ASan runtime preloaded when they were built with it)."""
    ensure_built()
    w = Worker(kernels=str(CHECKED_DIR), env=sanitizer_env(str(CHECKED_DIR)))
    try:
        yield w
    finally:
        w.close()


def build_only(worker: Worker, case_request: dict) -> str:
    """The build's result on the checked kernels: "ok", an error, a sanitizer report, a crash or a timeout."""
    return worker.run(dict(case_request, checks=False), timeout=TIMEOUT)["build"]
