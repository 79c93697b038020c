"""The adversarial hunt: every family and fixture, both engines, exact checks, engines agreeing bit for bit.

Each case runs in a child process with a time limit (``hunt_worker``): a crash or a hang of an engine fails
that case's tests and the next case gets a fresh child. Checks (``exact_checks``): ``build`` (no error),
``box`` (positive size), ``delaunay`` (exact), ``cells`` (valid, CCW, holding their sites), ``distinct``
(no point twice in a cell), ``tiling`` (coverage, exact areas), and ``agree`` (the engines bit for bit);
the same output whatever np.empty's arrays held; Fortune on the checked build (``checked_build``).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import adversarial
import exact_checks
from checked_build import build_only, checked_worker
from fixtures_io import FIXTURES, load_fixture
from hunt_worker import CHECK_NAMES, Worker, load_cells, uninit_result

ENGINES = ("fortune", "incremental")
# A case of the hunt takes at most a few seconds; past this it is a hang.
FAMILY_TIMEOUT = 10.0
# A build alone (the poisoned runs) takes under two seconds.
BUILD_TIMEOUT = 5.0
# Hypothesis's cases have at most 12 points.
SMALL_TIMEOUT = 5.0
# CI does not shrink failing examples: a crashing engine would restart the child for every shrink step.
CI_PHASES = tuple(p for p in Phase if p != Phase.shrink) if os.environ.get("CI") else tuple(Phase)


@pytest.fixture(scope="module")
def worker():
    w = Worker()
    yield w
    w.close()


_answers: dict[tuple[str, str], dict] = {}


def request(kind: str, name: str, engine: str) -> dict:
    if kind == "family":
        return {"family": name, "engine": engine}
    case = load_fixture(name)
    return {"points": case.points.tolist(), "bbox": case.bbox, "engine": engine}


def answer(worker: Worker, kind: str, name: str, engine: str) -> dict:
    """The child's answer for a family or fixture with one engine (run once, then remembered)."""
    key = (f"{kind}:{name}", engine)
    if key not in _answers:
        req = request(kind, name, engine) | {"save": worker.cells_path(f"{kind}-{name}-{engine}")}
        _answers[key] = worker.run(req, timeout=FAMILY_TIMEOUT)
    return _answers[key]


def assert_reads_only_written_memory(worker: Worker, kind: str, name: str, engine: str) -> None:
    result = uninit_result(
        worker, request(kind, name, engine), answer(worker, kind, name, engine), timeout=BUILD_TIMEOUT
    )
    assert_ok(result, f"{name}, {engine}")


def assert_ok(result: str, what: str) -> None:
    if result != "ok":
        pytest.fail(f"{what}: {result}", pytrace=False)


def assert_engines_agree(fortune: dict, incremental: dict) -> None:
    for engine, ans in zip(ENGINES, (fortune, incremental)):
        if "saved" not in ans:
            pytest.fail(f"{engine} gave no diagram: {ans['build']}", pytrace=False)
    try:
        exact_checks.check_same_cells(load_cells(fortune["saved"]), load_cells(incremental["saved"]), ENGINES)
    except AssertionError as exc:
        pytest.fail(str(exc), pytrace=False)


# ---------------------------------------------------------------------------------------------
# the families


@pytest.mark.parametrize("check", CHECK_NAMES)
@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("family", list(adversarial.FAMILIES))
def test_family(worker, family, engine, check):
    assert_ok(answer(worker, "family", family, engine)[check], f"{family}, {engine}, {check}")


@pytest.mark.parametrize("family", list(adversarial.FAMILIES))
def test_family_engines_agree(worker, family):
    assert_engines_agree(*(answer(worker, "family", family, e) for e in ENGINES))


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("family", list(adversarial.FAMILIES))
def test_family_reads_only_written_memory(worker, family, engine):
    """The same output whatever the bytes of the kernels' np.empty arrays (an MSan stand-in)."""
    assert_reads_only_written_memory(worker, "family", family, engine)


# ---------------------------------------------------------------------------------------------
# the fixtures: inputs that failed once, one file per bug


def test_fixtures_load():
    assert FIXTURES, "tests/fixtures/ holds no regression input"
    for name in FIXTURES:
        case = load_fixture(name)
        assert case.points.dtype == np.float64 and case.points.ndim == 2 and case.points.shape[1] == 2


@pytest.mark.parametrize("check", CHECK_NAMES)
@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("fixture", sorted(FIXTURES))
def test_fixture(worker, fixture, engine, check):
    assert_ok(answer(worker, "fixture", fixture, engine)[check], f"{fixture}, {engine}, {check}")


@pytest.mark.parametrize("fixture", sorted(FIXTURES))
def test_fixture_engines_agree(worker, fixture):
    assert_engines_agree(*(answer(worker, "fixture", fixture, e) for e in ENGINES))


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("fixture", sorted(FIXTURES))
def test_fixture_reads_only_written_memory(worker, fixture, engine):
    assert_reads_only_written_memory(worker, "fixture", fixture, engine)


# ---------------------------------------------------------------------------------------------
# Fortune against the checked build (bounds checks, ASan; the incremental engine's are in test_checked_build)


@pytest.fixture(scope="module")
def checked():
    with checked_worker() as w:
        yield w


@pytest.mark.parametrize("family", list(adversarial.FAMILIES))
def test_checked_fortune_family(checked, family):
    assert_ok(build_only(checked, {"family": family, "engine": "fortune"}), f"{family}, checked build")


@pytest.mark.parametrize("fixture", sorted(FIXTURES))
def test_checked_fortune_fixture(checked, fixture):
    case = load_fixture(fixture)
    req = {"points": case.points.tolist(), "bbox": case.bbox, "engine": "fortune"}
    assert_ok(build_only(checked, req), f"{fixture}, checked build")


# ---------------------------------------------------------------------------------------------
# hypothesis: small near-degenerate sets


def run_engines(worker: Worker, points, bbox=None) -> list[dict]:
    pts = np.asarray(points, np.float64).reshape(-1, 2)
    req: dict = {"points": pts.tolist()} if bbox is None else {"points": pts.tolist(), "bbox": list(bbox)}
    return [
        worker.run({**req, "engine": e, "save": worker.cells_path(f"hyp-{e}")}, timeout=SMALL_TIMEOUT) for e in ENGINES
    ]


decimal = st.integers(-20, 20).map(lambda k: k / 10)  # 0.1 steps, rounded to doubles
HYPOTHESIS = settings(
    max_examples=40, deadline=None, phases=CI_PHASES, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@st.composite
def near_line(draw):
    """Points on y = a + b x with decimal a, b, x; y rounded to a double (often just off the line)."""
    a = draw(decimal)
    b = draw(st.sampled_from([0.1, 0.2, 0.3, 1 / 3, 2.0, 3.0, 0.7, -1.1, 10.0]))
    xs = draw(st.lists(decimal, min_size=3, max_size=12))
    return [(x, a + b * x) for x in xs]


@st.composite
def on_circles(draw):
    """Points on one to three circles (decimal centres and radii) at angles of k * 15 degrees, rounded."""
    pts = []
    for c in range(draw(st.integers(1, 3))):
        cx, cy = draw(decimal), draw(decimal)
        r = draw(st.integers(1, 10)) / 4
        ks = draw(st.lists(st.integers(0, 23), min_size=3 if c == 0 else 1, max_size=6, unique=True))
        pts += [(cx + r * np.cos(k * np.pi / 12), cy + r * np.sin(k * np.pi / 12)) for k in ks]
    return pts[:12]


SMALL_SETS = {
    "coarse_decimals": st.lists(st.tuples(decimal, decimal), min_size=3, max_size=12),
    "near_one_line": near_line(),
    "on_circles": on_circles(),
}


@pytest.mark.parametrize("kind", SMALL_SETS)
@HYPOTHESIS
@given(data=st.data())
def test_hypothesis_checks(worker, kind, data):
    """Every check passes with both engines on small near-degenerate sets."""
    points = data.draw(SMALL_SETS[kind], label="points")
    for engine, ans in zip(ENGINES, run_engines(worker, points)):
        bad = {c: ans[c] for c in CHECK_NAMES if ans[c] != "ok"}
        assert not bad, f"{engine}: {bad}"


@pytest.mark.parametrize("kind", SMALL_SETS)
@HYPOTHESIS
@given(data=st.data())
def test_hypothesis_engines_agree(worker, kind, data):
    """The two engines' cells agree bit for bit on small near-degenerate sets."""
    points = data.draw(SMALL_SETS[kind], label="points")
    fortune, incremental = run_engines(worker, points)
    assert "saved" in fortune and "saved" in incremental, (fortune["build"], incremental["build"])
    exact_checks.check_same_cells(load_cells(fortune["saved"]), load_cells(incremental["saved"]), ENGINES)


@st.composite
def box_on_bisectors(draw):
    """A few sites at small integer points and a box with integer corners: bisectors pass through the
    box's corners and along its sides (a cell may touch the box at a corner or a side and hold nothing
    inside it)."""
    pts = draw(st.lists(st.tuples(st.integers(0, 6), st.integers(0, 6)), min_size=2, max_size=8, unique=True))
    x0, y0 = draw(st.integers(0, 5)), draw(st.integers(0, 5))
    x1, y1 = draw(st.integers(x0 + 1, 6)), draw(st.integers(y0 + 1, 6))
    return [(float(x), float(y)) for x, y in pts], (float(x0), float(y0), float(x1), float(y1))


@HYPOTHESIS
@given(data=st.data())
def test_hypothesis_boxes_on_bisectors(worker, data):
    """Every check passes, and the engines agree, with box corners and sides on the sites' bisectors (a
    cell touching the box only at its lower-left corner, or along the sides through it, once took the
    whole box)."""
    points, bbox = data.draw(box_on_bisectors(), label="points, box")
    answers = run_engines(worker, points, bbox)
    for engine, ans in zip(ENGINES, answers):
        bad = {c: ans[c] for c in CHECK_NAMES if ans[c] != "ok"}
        assert not bad, f"{engine}: {bad}"
    exact_checks.check_same_cells(*(load_cells(a["saved"]) for a in answers), ENGINES)
