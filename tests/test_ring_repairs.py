"""The clipper's repairs of rounded rings read the points' values, never their numbers.

Exact Voronoi vertices closer than doubles can separate round to one point, or to points an ulp apart;
which of several equal points a ring holds depends on an engine's numbering. The repairs (dropping a
repeated point or a spike, straightening rings that cross themselves) must come out the same whichever
numbers the rings hold and wherever a ring's walk began.
"""

from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tvoronoi.dynamic import DynamicVoronoi
from tvoronoi.kernels import clip

DYNAMIC_FIXTURE = (
    Path(__file__).resolve().parent / "fixtures" / "dynamic" / "rounded_lattice_cell_keeps_a_point_the_batch_merges.npz"
)

small = st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 1e-300, 3.0])


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(small, small), min_size=1, max_size=40))
def test_value_names_name_each_value_by_its_first_point(pairs):
    """name[p] is the first point equal to p (0.0 and -0.0 equal), found by comparing every pair."""
    pts = np.array(pairs, float)
    names = clip.value_names(pts)
    for p in range(len(pts)):
        first = next(q for q in range(len(pts)) if pts[q, 0] == pts[p, 0] and pts[q, 1] == pts[p, 1])
        assert names[p] == first


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(small, small), min_size=1, max_size=40), st.data())
def test_value_names_of_some_values_name_only_those(pairs, data):
    """With keys, a point is named as without them when its value is a key's, else by itself (the
    straightening names only the values of its bent rings' points)."""
    pts = np.array(pairs, float)
    keys = data.draw(st.lists(st.integers(0, len(pts) - 1), max_size=10))
    every = clip.value_names(pts)
    some = clip.value_names(pts, np.array(keys, np.int32))
    held = {(float(pts[k, 0]) + 0.0, float(pts[k, 1]) + 0.0) for k in keys}
    for p in range(len(pts)):
        value = (float(pts[p, 0]) + 0.0, float(pts[p, 1]) + 0.0)
        assert some[p] == (every[p] if value in held else p)


def test_value_names_at_scale():
    """100,000 points with repeats at random places: the names against a sort."""
    rng = np.random.default_rng(5)
    base = np.round(rng.random((40_000, 2)), 3)
    pts = base[rng.integers(0, len(base), 100_000)]
    names = clip.value_names(pts)
    _, first, inverse = np.unique(pts, axis=0, return_index=True, return_inverse=True)
    assert np.array_equal(names, first[inverse.ravel()])


def test_point_kinds_are_corners_sides_and_inside_by_value():
    box = (0.0, -1.0, 2.0, 3.0)
    pts = np.array([[0, -1], [2, 3], [0, 1], [1, 3], [1, 1], [2.0, 0.5], [-0.0, 3]], float)
    assert clip.point_kinds(pts, box).tolist() == [0, 0, 1, 1, 2, 1, 0]
    # sides that are not integers, and far from 1 (the box read as doubles, not truncated)
    box = (0.5, -1.25, 2.75, 1e15 + 0.125)
    pts = np.array([[0.5, -1.25], [0.0, -1.0], [2.75, 7.0], [1.0, 1e15 + 0.125], [1.0, 1e15]], float)
    assert clip.point_kinds(pts, box).tolist() == [0, 2, 1, 1, 2]


def cyclic(ring: np.ndarray, pts: np.ndarray) -> list:
    """A ring's points as values, from its lowest (the order finish_ring writes)."""
    return [tuple(pts[p]) for p in ring]


def test_drops_come_out_the_same_from_any_start():
    """Points zigzagging along one line: 0 -> 2 -> 1 -> 3. Dropped in the walk's order, the spike at 2
    or the one at 1 goes first, and which point survives depends on where the walk began; from the
    lowest point on, it is the same from every start."""
    pts = np.array([[1.5, -1.0], [0, 0], [2, 0], [1, 0], [3, 0]], float)
    ring = np.arange(5)
    results = {tuple(cyclic(clip.finished_ring(pts, np.roll(ring, k)), pts)) for k in range(5)}
    assert len(results) == 1


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 2)), min_size=3, max_size=12), st.integers(0, 11))
def test_finished_rings_do_not_depend_on_the_start(points, shift):
    """Rings on a small lattice (repeats, spikes, collinear runs): rotating the input changes nothing
    when its lowest point is there once."""
    pts = np.array(points, float)
    lowest = min(range(len(pts)), key=lambda p: (pts[p, 1], pts[p, 0]))
    if sum(1 for p in range(len(pts)) if tuple(pts[p]) == tuple(pts[lowest])) > 1:
        return
    ring = np.arange(len(pts))
    a = cyclic(clip.finished_ring(pts, ring), pts)
    b = cyclic(clip.finished_ring(pts, np.roll(ring, shift % len(pts))), pts)
    assert a == b


def bent_patch():
    """Rings of cells around a place where rounding bent some (from a recorded dynamic session): each
    ring's points are its own rows of xy."""
    with np.load(DYNAMIC_FIXTURE) as z:
        dv = DynamicVoronoi(z["start"])
        for kind, index, xy in zip(z["kind"].tolist(), z["index"].tolist(), z["xy"]):
            (dv.insert(*xy) if kind == 0 else dv.move(index, *xy) if kind == 1 else dv.remove(index))
    view = dv.diagram()
    for i in np.flatnonzero(view.alive).tolist():
        if i in dv._primary:
            continue
        _, patch = dv._mesh.cells_near(i, *dv.bbox, dv._e, 2)
        if patch is not None:
            return patch[2], patch[3], dv.bbox
    raise AssertionError("the session bends no ring")


def straightened(points, offsets, rings, box):
    new_offsets, new_rings = clip.straighten(points, offsets, rings, box)
    return [points[new_rings[a:b]] for a, b in zip(new_offsets[:-1], new_offsets[1:])]


def test_straightening_reads_values_not_numbers():
    """The same rings, their points numbered three ways: each ring holding its own copies; one shared
    table; the shared table shuffled, with some points given twice. The straightened cells are the
    same values, and some ring did change."""
    offsets, xy, box = bent_patch()
    own = straightened(xy, offsets, np.arange(len(xy), dtype=np.int32), box)
    values, inverse = np.unique(xy, axis=0, return_inverse=True)
    inverse = inverse.ravel().astype(np.int32)
    shared = straightened(values, offsets, inverse, box)
    rng = np.random.default_rng(3)
    for _ in range(5):
        order = rng.permutation(len(values))
        extra = rng.integers(0, len(values), len(values) // 3)
        table = np.concatenate([values[order], values[extra]])
        where = np.empty(len(values), np.int32)
        where[order] = np.arange(len(values))
        rings = where[inverse]
        again = rng.random(len(rings)) < 0.5  # half the uses go to the second copy, where there is one
        second = {int(v): len(values) + k for k, v in enumerate(extra)}
        rings = np.array([second.get(int(inverse[k]), r) if again[k] else r for k, r in enumerate(rings)], np.int32)
        shuffled = straightened(table, offsets, rings, box)
        assert all(np.array_equal(a, b) for a, b in zip(own, shuffled))
    assert all(np.array_equal(a, b) for a, b in zip(own, shared))
    assert any(len(a) != b - c for a, b, c in zip(own, offsets[1:], offsets[:-1]))


def test_straightening_looks_only_at_rings_that_may_be_bent():
    """Told which rings may be bent (those that turn right), straighten gives the rings it gives
    looking at all of them; told none, it changes nothing."""
    offsets, xy, box = bent_patch()
    rings = np.arange(len(xy), dtype=np.int32)
    every = straightened(xy, offsets, rings, box)
    turns_right = np.array(
        [
            any(
                clip.ring_turn(*xy[a + (k - 1) % (b - a)], *xy[a + k], *xy[a + (k + 1) % (b - a)]) < 0
                for k in range(b - a)
            )
            for a, b in zip(offsets[:-1], offsets[1:])
        ],
        np.int8,
    )
    assert 0 < turns_right.sum() < len(turns_right)
    new_offsets, new_rings = clip.straighten(xy, offsets, rings, box, candidates=turns_right)
    some = [xy[new_rings[a:b]] for a, b in zip(new_offsets[:-1], new_offsets[1:])]
    assert all(np.array_equal(a, b) for a, b in zip(every, some))
    new_offsets, new_rings = clip.straighten(xy, offsets, rings, box, candidates=np.zeros(len(turns_right), np.int8))
    assert np.array_equal(new_offsets, offsets) and np.array_equal(new_rings, rings)
