"""The degenerate families against the checked build of the kernels (bounds checks, AddressSanitizer).

``make checked`` (a step of ``make test``) builds the kernels into build/checked with Cython's
boundscheck and initializedcheck on and, by default, -fsanitize=address (setup.py, TVORONOI_CHECKED).
Bounds checks cover typed memoryviews only; ASan covers the raw pointers into the kernels' arrays (Fortune's
sweep, the mesh) and the fixed-size stack buffers. Each case runs in a child process that loads those
kernels (``hunt_worker --kernels``, the ASan runtime preloaded), so a report fails one case. Only the
build is checked here: the geometry is test_hunt's.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import adversarial
from fixtures_io import FIXTURES, load_fixture
from hunt_worker import ROOT, Worker, sanitizer_env

CHECKED_DIR = ROOT / "build" / "checked"
ENGINES = ("fortune", "incremental")
# A build alone takes under two seconds here, and ASan slows it about twice.
TIMEOUT = 10.0
# The families too large to be worth running slowly twice more (their bugs show in test_hunt).
LARGE = {"grid70_noise1e-17"}
FAMILIES = [f for f in adversarial.FAMILIES if f not in LARGE]


def built() -> bool:
    """The checked kernels exist and are newer than every kernel source."""
    sos = list((CHECKED_DIR / "tvoronoi" / "kernels").glob("*.so"))
    sources = list((ROOT / "tvoronoi" / "kernels").glob("*.p*")) + [ROOT / "setup.py"]
    return len(sos) >= len(list((ROOT / "tvoronoi" / "kernels").glob("*.pyx"))) and \
        min(p.stat().st_mtime for p in sos) >= max(p.stat().st_mtime for p in sources)


@pytest.fixture(scope="module")
def checked():
    if not built():
        # what `make checked` does, for a bare `pytest` run (a few minutes, once)
        env = dict(os.environ, TVORONOI_CHECKED=os.environ.get("CHECKED_MODE", "asan"))
        subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--force", "--build-lib", str(CHECKED_DIR),
                        "--build-temp", str(ROOT / "build" / "checked-tmp")],
                       cwd=ROOT, env=env, check=True, capture_output=True)
    w = Worker(kernels=str(CHECKED_DIR), env=sanitizer_env(str(CHECKED_DIR)))
    yield w
    w.close()


def assert_clean(ans: dict, what: str) -> None:
    if ans["build"] != "ok":
        pytest.fail(f"{what}: {ans['build']}", pytrace=False)


def test_checked_build_is_checked(checked):
    """The child runs the checked kernels, with bounds checks compiled in, and ASan live when linked."""
    c_file = ROOT / "build" / "checked-c" / "tvoronoi" / "kernels" / "clip.c"
    assert "__Pyx_RaiseBufferIndexError" in c_file.read_text(), "clip.c was generated without boundscheck"
    if sanitizer_env(str(CHECKED_DIR)):
        ans = checked.run({"selftest": "asan"}, timeout=TIMEOUT)
        assert "AddressSanitizer: heap-buffer-overflow" in ans["build"], ans


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("family", FAMILIES)
def test_checked_family(checked, family, engine):
    ans = checked.run({"family": family, "engine": engine, "checks": False}, timeout=TIMEOUT)
    assert_clean(ans, f"{family}, {engine}")


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("fixture", sorted(FIXTURES))
def test_checked_fixture(checked, fixture, engine):
    case = load_fixture(fixture)
    ans = checked.run({"points": case.points.tolist(), "bbox": case.bbox, "engine": engine, "checks": False},
                      timeout=TIMEOUT)
    assert_clean(ans, f"{fixture}, {engine}")
