"""The degenerate families against the checked build of the kernels (bounds checks, AddressSanitizer).

Bounds checks cover typed memoryviews only; ASan covers the raw pointers into the kernels' arrays (Fortune's
sweep, the incremental engine's mesh) and fixed-size stack buffers; new heap blocks are filled with 0xbe, so a
read of memory never written gives the same bad index every run. Each case runs in a child process that
loads those kernels, so a report fails one case. Only the build is checked: the geometry is test_hunt's.
The incremental engine runs here; Fortune's cases are in test_hunt.py (``test_checked_fortune_*``) until
its sweep stops writing broken triangulations (see the fixtures named ``*_fortune_*``).
"""

from __future__ import annotations

import pytest

import adversarial
from checked_build import CHECKED_DIR, ROOT, TIMEOUT, build_only, checked_worker
from fixtures_io import FIXTURES, load_fixture
from hunt_worker import sanitizer_env


@pytest.fixture(scope="module")
def checked():
    with checked_worker() as w:
        yield w


def test_checked_build_is_checked(checked):
    """The child runs the checked kernels, with bounds checks compiled in, and ASan live when linked."""
    c_file = ROOT / "build" / "checked-c" / "tvoronoi" / "kernels" / "clip.c"
    assert "__Pyx_RaiseBufferIndexError" in c_file.read_text(), "clip.c was generated without boundscheck"
    if sanitizer_env(str(CHECKED_DIR)):
        ans = checked.run({"selftest": "asan"}, timeout=TIMEOUT)
        assert "AddressSanitizer: heap-buffer-overflow" in ans["build"], ans


@pytest.mark.parametrize("family", list(adversarial.FAMILIES))
def test_checked_incremental_family(checked, family):
    assert build_only(checked, {"family": family, "engine": "incremental"}) == "ok"


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("family", list(adversarial.FAMILIES))
def test_checked_family_by_halves(checked, family, engine):
    """The same families cut in two, each half triangulated on a thread of its own, and joined
    (tvoronoi.halves), by either engine."""
    assert build_only(checked, {"family": family, "engine": engine, "split_min": 3}) == "ok"


@pytest.mark.parametrize("fixture", sorted(FIXTURES))
def test_checked_incremental_fixture(checked, fixture):
    case = load_fixture(fixture)
    req = {"points": case.points.tolist(), "bbox": case.bbox, "engine": "incremental"}
    assert build_only(checked, req) == "ok"
