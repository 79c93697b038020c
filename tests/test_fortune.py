"""Fortune's sweepline engine: the same diagram as the incremental engine and the oracle, on every data set."""

import numpy as np
import pytest
import scipy.spatial
from hypothesis import given, settings
from hypothesis import strategies as st

import tvoronoi
from conftest import DATASETS, GENERAL_POSITION
from invariants import validate
from oracle import assert_matches_oracle
from tests import adversarial
from tests.flips import flip_edges
from tvoronoi.engines import sweep_order
from tvoronoi.kernels import fortune, incremental


def assert_same_diagram(a, b):
    """Same cells (vertices to rounding, same count), same vertex count."""
    assert a.n_vertices == b.n_vertices
    assert a.n_edges == b.n_edges
    assert np.array_equal(a.site_of, b.site_of)
    scale = max(a.bbox[2] - a.bbox[0], a.bbox[3] - a.bbox[1])
    for i in range(a.n_sites):
        ra, rb = a.cell_polygon(i), b.cell_polygon(i)
        assert len(ra) == len(rb), f"cell {i}: {len(ra)} vs {len(rb)} vertices"
        if len(ra):
            k = int(np.argmin(np.hypot(*(rb - ra[0]).T)))
            np.testing.assert_allclose(np.roll(rb, -k, axis=0), ra, rtol=0, atol=1e-9 * scale)


def test_fortune_invariants_and_oracle(dataset):
    name, pts = dataset
    d = tvoronoi.voronoi(pts, engine="fortune")
    assert d.engine == "fortune"
    validate(d)
    assert_matches_oracle(d)


def test_engines_agree(dataset):
    name, pts = dataset
    assert_same_diagram(tvoronoi.voronoi(pts, engine="fortune"), tvoronoi.voronoi(pts, engine="incremental"))


@pytest.mark.parametrize("name", GENERAL_POSITION)
def test_fortune_delaunay_matches_qhull(name):
    pts = DATASETS[name]
    ours = {tuple(sorted(t)) for t in tvoronoi.voronoi(pts, engine="fortune").delaunay_triangles().tolist()}
    shifted = pts - pts.min(axis=0) if name == "huge" else pts
    theirs = {tuple(sorted(t)) for t in scipy.spatial.Delaunay(shifted).simplices.tolist()}
    assert ours == theirs


def test_sweep_needs_no_repair_on_general_position():
    """Exact decisions make the sweep itself right; the flips are a safety net for near-ties."""
    pts = DATASETS["uniform"]
    order = sweep_order(pts[:, 0], pts[:, 1])
    out = fortune.sweep(np.ascontiguousarray(pts[order, 0]), np.ascontiguousarray(pts[order, 1]))
    assert out["flips"] == 0
    assert out["steps"] >= len(pts)


def test_first_row_of_equal_y():
    """Several sites on the first sweep position, then the rest above them."""
    pts = np.array([(x, 0.0) for x in range(8)] + [(3.5, 2.0), (1.2, 3.0), (6.1, 1.0)])
    d = tvoronoi.voronoi(pts, engine="fortune")
    validate(d)
    assert_matches_oracle(d)


def test_legalize_restores_delaunay(rng):
    """Spoil a Delaunay triangulation with flips; the exact repair brings it back."""
    pts = DATASETS["uniform"]
    xs, ys = np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1])
    _, tv, opp, _ = incremental.triangulate(xs, ys)
    want = {tuple(sorted(t)) for t in tv.reshape(-1, 3).tolist()}
    assert flip_edges(xs, ys, tv, opp, rng, 40) == 40
    assert {tuple(sorted(t)) for t in tv.reshape(-1, 3).tolist()} != want
    assert fortune.legalize(xs, ys, tv, opp) >= 1
    assert {tuple(sorted(t)) for t in tv.reshape(-1, 3).tolist()} == want


small_ints = st.integers(min_value=-5, max_value=5)


@settings(max_examples=80, deadline=None)
@given(st.lists(st.tuples(small_ints, small_ints), min_size=0, max_size=30))
def test_property_engines_agree_on_degenerate_sets(points):
    """Integer sets: repeats, rows of equal y, collinear runs, cocircular quads."""
    pts = np.array(points, float).reshape(-1, 2)
    f = tvoronoi.voronoi(pts, engine="fortune")
    validate(f)
    assert_same_diagram(f, tvoronoi.voronoi(pts, engine="incremental"))


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.tuples(st.floats(0, 1), st.floats(0, 1)), min_size=3, max_size=60).filter(
        lambda pts: all(v == 0 or v > 1e-40 for p in pts for v in p)
    )
)
def test_property_engines_agree_on_floats(points):
    pts = np.array(points, float)
    f = tvoronoi.voronoi(pts, engine="fortune")
    validate(f)
    assert_same_diagram(f, tvoronoi.voronoi(pts, engine="incremental"))


@settings(max_examples=300, deadline=None)
@given(
    rows=st.lists(
        st.tuples(st.sampled_from([-2.0, -0.0, 0.0, 0.5, 1.0, 3.0]), st.sampled_from([-1.0, -0.0, 0.0, 2.0, 7.5])),
        min_size=1,
        max_size=60,
    )
)
def test_sweep_order_is_a_stable_sort_by_y_then_x(rows):
    # rows of equal y (and repeated points, and both zeros) in any order: the sites come by y, then by x,
    # then by input row, as a stable sort of y + i x orders them
    pts = np.array(rows, np.float64)
    want = np.argsort(pts[:, 1] + 1j * pts[:, 0], kind="stable")
    assert np.array_equal(sweep_order(pts[:, 0], pts[:, 1]), want)


@settings(max_examples=300, deadline=None)
@given(
    ulps=st.lists(st.integers(-40, 40), min_size=2, max_size=300),
    far=st.lists(st.sampled_from([5e-324, -5e-324, 1e-300, -1e300, 1e300, -0.0]), max_size=5),
    xs=st.lists(st.sampled_from([-1.0, 0.0, 2.0]), min_size=305, max_size=305),
)
def test_sweep_order_sorts_y_a_few_units_apart_among_far_values(ulps, far, xs):
    # y from 1e-300 to 1e300 beside values a few units apart: the integer keys are shifted to leave room
    # for the row, so nearby y share a key, and each run of equal keys is sorted again exactly
    ys = np.array([1.0 + u * 2.0**-52 for u in ulps] + far)
    x = np.array(xs[: len(ys)])
    want = np.lexsort((np.arange(len(ys)), x, ys))
    got = sweep_order(x, ys)
    assert got.dtype == np.int32
    assert np.array_equal(got, want)


@settings(max_examples=100, deadline=None)
@given(
    cols=st.integers(1, 70),
    rows=st.integers(1, 70),
    spacing=st.sampled_from([1.0, 0.1, 2.0**-30, 3e5]),
    turn=st.sampled_from([0.0, 0.3, np.pi / 2]),
    seed=st.integers(0, 2**32 - 1),
    repeats=st.integers(0, 50),
)
def test_sweep_order_sorts_long_runs_of_equal_y_in_any_order(cols, rows, spacing, turn, seed, repeats):
    # grids (turned or not, in shuffled order, some sites listed twice): runs of equal or nearly equal
    # y far longer than the runs sorted by insertion, merged; against a stable sort by y, x and row
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.arange(cols) * spacing, np.arange(rows) * spacing)
    pts = np.c_[gx.ravel(), gy.ravel()] @ np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    pts = np.round(pts, 9) if spacing >= 0.1 else pts
    pts = np.concatenate([pts, pts[rng.integers(0, len(pts), repeats)]])[rng.permutation(len(pts) + repeats)]
    want = np.lexsort((np.arange(len(pts)), pts[:, 0], pts[:, 1]))
    assert np.array_equal(sweep_order(pts[:, 0], pts[:, 1]), want)


# ---------------------------------------------------------------------------------------------------------
# locating sites from hints (beach_line.locate_hinted): the same arcs as the tree's search


def _sweep_both_ways(pts):
    order = sweep_order(pts[:, 0], pts[:, 1])
    xs, ys = np.ascontiguousarray(pts[order, 0]), np.ascontiguousarray(pts[order, 1])
    return fortune.sweep(xs, ys), fortune.sweep(xs, ys, hints=False)


def _assert_same_sweep(hinted, tree):
    assert hinted["status"] == tree["status"] == fortune.STATUS_OK
    for key in ("steps", "flips", "near_ties", "exact_tests"):
        assert hinted[key] == tree[key], key
    for key in ("tv", "opp", "dup"):
        assert np.array_equal(hinted.get(key), tree.get(key)), key
    assert tree["located"][0] == 0


@pytest.mark.parametrize("family", sorted(adversarial.FAMILIES))
def test_hinted_location_is_the_trees_on_every_hard_family(family):
    """Every adversarial family (lattices in several orientations, cocircular rings, near-collinear rows,
    rounded curves, repeats): the sweep with hints makes the same triangles, twins and counts, bit for
    bit, as the sweep that searches the tree for every site."""
    hinted, tree = _sweep_both_ways(adversarial.make(family, adversarial.SEED).points)
    _assert_same_sweep(hinted, tree)


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(3, 400),
    span=st.sampled_from([3, 8, 40, 1000]),
    turn=st.sampled_from([0.0, 0.3, 1.0]),
    seed=st.integers(0, 2**16),
)
def test_hinted_location_is_the_trees_on_small_integer_sets(n, span, turn, seed):
    """Small integer coordinates (many sites on one row, on one breakpoint, cocircular), turned and
    rounded: ties at breakpoints are left to the tree, so the sweep is the same either way."""
    rng = np.random.default_rng(seed)
    pts = rng.integers(0, span, size=(n, 2)).astype(np.float64)
    c, s = np.cos(turn), np.sin(turn)
    pts = np.round(pts @ np.array([[c, -s], [s, c]]), 3)
    hinted, tree = _sweep_both_ways(pts)
    if tree["status"] == fortune.STATUS_OK and "tv" in tree:
        _assert_same_sweep(hinted, tree)


@pytest.mark.parametrize("hints", [True, False])
@pytest.mark.parametrize("row, k", [(8, 3), (64, 0), (64, 31), (64, 62), (257, 128)])
def test_a_site_on_a_breakpoint_goes_to_the_arc_right_of_it(hints, row, k):
    """A row of sites at y = 0 (vertical breakpoints at their midpoints), then one site right above the
    midpoint of sites k and k + 1: it splits the arc of site k + 1, the arc whose span [left breakpoint,
    right breakpoint) holds it, whether a walk from a hint or the tree finds it (the tree's answer at a
    breakpoint used to depend on its shape)."""
    xs = np.r_[np.arange(float(row)), k + 0.5]
    ys = np.r_[np.zeros(row), 2.0]
    beach = fortune.sweep(xs, ys, stop_after=row + 1, hints=hints)["beach"].tolist()
    assert beach == [*range(k + 2), row, *range(k + 1, row)]


@pytest.mark.parametrize("hints", [True, False])
def test_a_site_at_the_top_of_a_circle_goes_to_the_arc_right_of_the_breakpoint(hints):
    """Sites (-3, -4) and (4, -3) on the circle of radius 5 about the origin, then (0, 5), its top: at
    that sweep line the breakpoint between the first site's arc and the second's is the origin, right
    below the new site, which splits the arc right of it (the second site's)."""
    xs, ys = np.array([-3.0, 4.0, 0.0]), np.array([-4.0, -3.0, 5.0])
    assert fortune.sweep(xs, ys, stop_after=3, hints=hints)["beach"].tolist() == [0, 1, 2, 1, 0]


@pytest.mark.parametrize("dist", ["uniform", "gaussian", "clustered"])
def test_hints_locate_nearly_every_site(dist):
    """The hints work: on 50,000 sites of each distribution, at least 97% are located by a short walk,
    the rest by longer walks within their budget, so that the tree is never built; and the result is
    the tree's."""
    from tvoronoi.generators import generate

    hinted, tree = _sweep_both_ways(generate(dist, 50_000, seed=5))
    _assert_same_sweep(hinted, tree)
    walks, descents = hinted["located"]
    assert walks + descents + hinted["long_walks"] == 50_000 - 1  # (the first site starts the beach line)
    assert walks >= 0.97 * 50_000
    assert descents == 0 and not hinted["tree_built"]
    assert tree["long_walks"] == 0 and tree["tree_built"]


def test_hints_outlast_outliers_and_give_way_to_the_tree():
    """The strips span the middle 99.8% of the sites' x: a dense cluster with a few far outliers is
    still located by walks. Two clusters far apart leave each one strip or two, where walks seldom
    settle: once the longer walks have spent their budget the tree is built from the beach line, the
    hints are given up after a trial, and the tree locates the rest. The same sweep as the tree's
    either way."""
    rng = np.random.default_rng(8)
    outliers = np.r_[0.5 + 1e-3 * rng.random((20_000, 2)), rng.random((20, 2)) * 1000]
    hinted, tree = _sweep_both_ways(outliers)
    _assert_same_sweep(hinted, tree)
    assert hinted["located"][0] >= 0.9 * len(outliers)
    far = np.r_[1e-3 * rng.random((10_000, 2)), 1000 + 1e-3 * rng.random((10_000, 2))]
    hinted, tree = _sweep_both_ways(far)
    _assert_same_sweep(hinted, tree)
    walks, descents = hinted["located"]
    assert hinted["tree_built"]
    assert walks + descents + hinted["long_walks"] == len(far) - 1
    assert descents > 0.8 * len(far)


# the event queue (event_queue.pxd): the events far above the sweep line wait in buckets by strips of y,
# the heap holding a window of them; the same sweep as with every event in the heap


def _sweep_with_and_without_buckets(pts, **kw):
    order = sweep_order(pts[:, 0], pts[:, 1])
    xs, ys = np.ascontiguousarray(pts[order, 0]), np.ascontiguousarray(pts[order, 1])
    return fortune.sweep(xs, ys, **kw), fortune.sweep(xs, ys, buckets=False, **kw)


def _assert_same_events(bucketed, heap):
    assert bucketed["status"] == heap["status"] == fortune.STATUS_OK
    for key in ("steps", "flips"):
        assert bucketed[key] == heap[key], key
    for key in ("tv", "opp", "dup"):
        assert np.array_equal(bucketed.get(key), heap.get(key)), key
    assert heap["queue"][0] == 1


@pytest.mark.parametrize("family", sorted(adversarial.FAMILIES))
def test_bucketed_queue_is_the_heaps_on_every_hard_family(family):
    """Every adversarial family, two seeds: the same triangles, twins and steps, bit for bit, with the
    far events in buckets as with all of them in the heap. Lattices and cocircular rings give events
    with equal tops by the hundred, whose order the sweep fixes by their centres and sites (a strict
    order, whatever holds the events)."""
    for seed in (adversarial.SEED, 2):
        bucketed, heap = _sweep_with_and_without_buckets(adversarial.make(family, seed).points)
        _assert_same_events(bucketed, heap)


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(64, 600),
    span=st.sampled_from([3, 8, 40, 1000]),
    turn=st.sampled_from([0.0, 0.3, 1.0]),
    seed=st.integers(0, 2**16),
)
def test_bucketed_queue_is_the_heaps_on_small_integer_sets(n, span, turn, seed):
    """Small integer coordinates, turned and rounded: rows of equal y, many cocircular quadruples, equal
    tops in every bucket."""
    rng = np.random.default_rng(seed)
    pts = rng.integers(0, span, (n, 2)).astype(float)
    c, s = np.cos(turn), np.sin(turn)
    pts = np.round(pts @ np.array([[c, s], [-s, c]]), 3)
    _assert_same_events(*_sweep_with_and_without_buckets(pts))


@pytest.mark.parametrize("dist", ["uniform", "gaussian", "clustered"])
def test_buckets_hold_the_events_far_above_the_sweep_line(dist):
    """The buckets are used: halfway through a sweep of 20,000 sites most pending events wait in
    buckets, the heap holds a few, and the pending events are those of the sweep without buckets."""
    from tvoronoi.generators import generate

    pts = generate(dist, 20_000, seed=3)
    whole, _ = _sweep_with_and_without_buckets(pts)
    half = whole["steps"] // 2
    bucketed, heap = _sweep_with_and_without_buckets(pts, stop_after=half)
    n_buckets, now, waiting, in_heap = bucketed["queue"]
    assert n_buckets == 20_000 // 2 and 0 < now < n_buckets - 1
    assert waiting > 4 * in_heap > 0, bucketed["queue"]
    assert heap["queue"][2] == 0
    for key in ("beach", "beach_edges", "triangles"):
        assert np.array_equal(bucketed[key], heap[key]), key
    a, b = bucketed["events"], heap["events"]
    assert len(a) == waiting + in_heap == len(b)
    assert np.array_equal(a[np.lexsort(a.T[::-1])], b[np.lexsort(b.T[::-1])])


def test_buckets_give_way_to_the_heap_where_strips_cannot_measure_y():
    """One bucket (every event in the heap) for fewer than 64 sites, sites on one row, or a span of y
    whose strips would not be finite; a far outlier leaves nearly every site in the first strip: the
    heap then holds nearly every event, and the sweep is the same."""
    rng = np.random.default_rng(4)
    few = rng.random((63, 2))
    row = np.c_[rng.random(500), np.zeros(500)]
    tiny = rng.random((300, 2)) * 1e-310
    for pts in (few, row, tiny):
        bucketed, heap = _sweep_with_and_without_buckets(pts)
        assert bucketed["queue"][0] == 1
        _assert_same_events(bucketed, heap)
    outlier = np.r_[rng.random((5000, 2)), [[0.5, 1e12]]]
    _assert_same_events(*_sweep_with_and_without_buckets(outlier))
