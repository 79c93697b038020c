"""Step traces of both engines: every state consistent, the last one equal to the full build."""

from fractions import Fraction

import numpy as np
import pytest

import tvoronoi
from conftest import DATASETS
from test_fortune import assert_same_diagram
from tvoronoi.generators import uniform
from tvoronoi.kernels import incremental
from tvoronoi.trace import visibility_walk


def segment_keys(edges):
    return {tuple(np.round(np.sort(e, axis=0).ravel(), 9)) for e in edges}


@pytest.fixture(scope="module")
def fortune_run():
    pts = uniform(60, seed=7)
    trace = tvoronoi.steps(pts, engine="fortune")
    return pts, trace, [trace.step(k) for k in range(len(trace) + 1)]


def test_fortune_beach_line_is_ordered(fortune_run):
    _, _, steps = fortune_run
    for s in steps:
        bx = s.breakpoints[:, 0]
        assert np.all(np.diff(bx) >= -1e-9), f"step {s.index}: breakpoints out of order"
        assert len(s.beach) == len(s.breakpoints) + 1 or len(s.beach) == 0
        # consecutive arcs belong to different sites
        assert np.all(s.beach[1:] != s.beach[:-1])


def test_fortune_sweep_moves_up_and_edges_only_grow(fortune_run):
    _, _, steps = fortune_run
    for a, b in zip(steps[1:], steps[2:]):
        assert b.sweep_y >= a.sweep_y - 1e-12
        assert segment_keys(a.finished_edges) <= segment_keys(b.finished_edges)
        assert len(b.vertices) >= len(a.vertices)


def test_fortune_pending_circles_are_ahead_and_fit_their_arcs(fortune_run):
    pts, _, steps = fortune_run
    for s in steps:
        for (cx, cy, r), arc in zip(s.circles, s.circle_arcs):
            assert cy + r >= s.sweep_y - 1e-9
            for site in s.beach[arc - 1 : arc + 2]:
                assert abs(np.hypot(*(pts[site] - (cx, cy))) - r) <= 1e-9


def test_fortune_last_step_is_the_full_diagram(fortune_run):
    pts, trace, steps = fortune_run
    last = steps[-1]
    d = tvoronoi.voronoi(pts, engine="fortune")
    assert len(last.circles) == 0
    assert len(last.vertices) == d.n_vertices
    ours = {tuple(np.round(v, 9)) for v in last.vertices}
    assert ours == {tuple(np.round(v, 9)) for v in d.vertices}
    finite = (d.he_origin >= 0) & (d.he_origin[d.he_twin] >= 0)
    assert len(last.finished_edges) == finite.sum() // 2
    # the arcs left at the end go round the convex hull
    assert set(last.beach.tolist()) == set(np.unique(d.he_face[d.he_origin < 0]).tolist())


def test_fortune_step_describes_itself(fortune_run):
    _, _, steps = fortune_run
    kinds = {s.kind for s in steps}
    assert kinds == {"start", "site", "circle"}
    circle = next(s for s in steps if s.kind == "circle")
    assert circle.describe().startswith("circle event at (")
    assert f"vertex {len(circle.vertices) - 1} created" in circle.describe()
    assert steps[0].describe().startswith("before the sweep")


def test_fortune_trace_on_degenerate_sets():
    for name in ("grid", "collinear", "duplicates", "circle"):
        pts = DATASETS[name]
        trace = tvoronoi.steps(pts, engine="fortune")
        last = trace.step(len(trace))
        d = tvoronoi.voronoi(pts, engine="fortune")
        assert len({tuple(np.round(v, 9)) for v in last.vertices}) == d.n_vertices
        if name == "duplicates":
            assert any(trace.step(k).kind == "repeat" for k in range(1, len(trace) + 1))


@pytest.fixture(scope="module")
def incremental_run():
    pts = uniform(50, seed=11)
    trace = tvoronoi.steps(pts, engine="incremental")
    return pts, trace, [trace.step(k) for k in range(len(trace) + 1)]


def test_incremental_last_step_is_the_full_diagram(incremental_run):
    pts, trace, steps = incremental_run
    assert len(trace) == len(pts)
    assert_same_diagram(steps[-1].diagram, tvoronoi.voronoi(pts))


def test_incremental_conflict_region(incremental_run):
    pts, _, steps = incremental_run
    for before, s in zip(steps[3:], steps[4:]):
        tris = {tuple(sorted(t)) for t in before.diagram.delaunay_triangles().tolist()}
        p = pts[s.site]
        for t in s.conflict:
            assert tuple(sorted(t)) in tris, f"step {s.index}: conflict triangle not in the mesh"
            a, b, c = pts[t]
            # the new site lies strictly inside the circumcircle of every triangle it destroys
            m = np.array([[*(a - p), (a - p) @ (a - p)], [*(b - p), (b - p) @ (b - p)], [*(c - p), (c - p) @ (c - p)]])
            assert np.linalg.det(m) > 0
        after = {tuple(sorted(t)) for t in s.diagram.delaunay_triangles().tolist()}
        assert not {tuple(sorted(t)) for t in s.conflict} & after
        # the cells it took area from are its Delaunay neighbours now
        nbrs = {v for t in s.diagram.delaunay_triangles() if s.site in t for v in t} - {s.site}
        assert set(s.stolen_from.tolist()) <= nbrs


def _orient(a, b, c) -> int:
    """Exact sign of the turn a -> b -> c, in rationals."""
    (ax, ay), (bx, by), (cx, cy) = ([Fraction(float(v)) for v in p] for p in (a, b, c))
    d = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return (d > 0) - (d < 0)


def check_walk(pts, before, s) -> str:
    """The walk of step s is a chain of adjacent triangles of the mesh before it, from one of the
    previous step's new triangles to one holding the site, or beyond a hull edge the site sees;
    returns how it ended ("inside" or "outside")."""
    # repeated points: one row stands for each place (the mesh and the walk may name different ones)
    _, first, inverse = np.unique(pts, axis=0, return_index=True, return_inverse=True)
    same = np.append(first[inverse.ravel()], -1)  # -1 (infinity) stays -1
    walk = [tuple(int(same[v]) for v in t) for t in s.walk]
    assert walk, f"step {s.index}: no walk"
    mesh = {tuple(sorted(same[t])) for t in before.diagram.delaunay_triangles()}
    for t in walk[:-1]:
        assert -1 not in t, f"step {s.index}: the walk went on past an infinite triangle"
    for t in walk:
        if -1 not in t:
            assert tuple(sorted(t)) in mesh, f"step {s.index}: {t} is not a triangle of the mesh"
    for t, u in zip(walk, walk[1:]):
        assert len(set(t) & set(u)) == 2, f"step {s.index}: {t} and {u} share no edge"
    if s.index > 4 and len(before.new_triangles):
        # it starts where the engine starts: a triangle the previous insertion made
        assert tuple(sorted(walk[0])) in {tuple(sorted(same[t])) for t in before.new_triangles}
    p = pts[s.site]
    last = walk[-1]
    if -1 in last:
        k = last.index(-1)
        a, b = last[(k + 1) % 3], last[(k + 2) % 3]
        # the hull edge b -> a has the mesh on its left; the site lies strictly on its right
        assert _orient(pts[a], pts[b], p) > 0, f"step {s.index}: the site does not see the hull edge"
        return "outside"
    for k in range(3):
        a, b = last[k], last[(k + 1) % 3]
        assert _orient(pts[a], pts[b], p) >= 0, f"step {s.index}: the site is not in {last}"
    if not any((pts[v] == p).all() for v in last):
        # the engine found the same triangle: it is in conflict with the site
        assert tuple(sorted(last)) in {tuple(sorted(same[t])) for t in s.conflict}
    return "inside"


def test_incremental_location_walk_is_a_chain_to_the_site(incremental_run):
    pts, _, steps = incremental_run
    ends = [check_walk(pts, before, s) for before, s in zip(steps[3:], steps[4:])]
    assert {"inside", "outside"} <= set(ends)
    assert max(len(s.walk) for s in steps) >= 3, "no walk crossed a triangle"
    assert all(len(s.walk) == 0 for s in steps[:4])


@pytest.mark.parametrize("name", ["grid", "duplicates", "circle"])
def test_incremental_location_walk_on_degenerate_sets(name):
    pts = DATASETS[name]
    trace = tvoronoi.steps(pts, engine="incremental")
    steps = [trace.step(k) for k in range(len(trace) + 1)]
    for before, s in zip(steps[3:], steps[4:]):
        check_walk(pts, before, s)


def test_visibility_walk_matches_a_brute_force_containment():
    # on a fixed mesh, the walk from any start ends in the triangle that holds the point
    pts = uniform(40, seed=3)
    d = tvoronoi.voronoi(pts)
    tri = d.delaunay_triangles()
    res = incremental.triangulate(np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1]))
    tv, opp = res[1], res[2]
    finite = [t for t in range(len(tv) // 3) if (tv[3 * t : 3 * t + 3] < len(pts)).all()]
    assert len(finite) == len(tri)
    rng = np.random.default_rng(5)
    for q in rng.uniform(0.2, 0.8, size=(20, 2)):
        walk = visibility_walk(pts[:, 0].copy(), pts[:, 1].copy(), tv, opp, finite[0], *q)
        signs = [{_orient(pts[t[k]], pts[t[(k + 1) % 3]], q) for k in range(3)} for t in tri]
        holding = {tuple(sorted(t)) for t, sg in zip(tri.tolist(), signs) if not {-1, 1} <= sg}
        assert tuple(sorted(walk[-1].tolist())) in holding


def test_incremental_steps_grow_one_site_at_a_time(incremental_run):
    _, _, steps = incremental_run
    for s in steps:
        assert len(s.inserted) == s.index
        cells = sum(len(s.diagram.cell_polygon(i)) > 0 for i in range(s.diagram.n_sites))
        assert cells == s.index
    assert "inserted at" in steps[10].describe()


def test_incremental_trace_on_degenerate_sets():
    for name in ("grid", "collinear", "duplicates", "circle", "two", "one"):
        pts = DATASETS[name]
        trace = tvoronoi.steps(pts, engine="incremental")
        for k in range(len(trace) + 1):
            s = trace.step(k)
            assert len(s.inserted) == k
        assert_same_diagram(trace.step(len(trace)).diagram, tvoronoi.voronoi(pts))


# -- the one entry: steps(points, engine=..., bbox=..., seed=...) -------------------------------------


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_steps_takes_the_same_arguments_for_both_engines(engine):
    pts = uniform(20, seed=3)
    box = (-1.0, -2.0, 3.0, 4.0)
    trace = tvoronoi.steps(pts, engine=engine, bbox=box, seed=5)
    assert trace.engine == engine
    assert trace.bbox == box
    np.testing.assert_array_equal(trace.points, pts)
    default = tvoronoi.steps(pts, engine=engine)
    assert default.bbox == tvoronoi.voronoi(pts).bbox
    last = trace.step(len(trace))
    assert last.index == len(trace)
    assert last.describe() == tvoronoi.steps(pts, engine=engine, bbox=box, seed=5).step(len(trace)).describe()


def test_steps_defaults_to_the_incremental_engine_as_voronoi_does():
    pts = uniform(10, seed=4)
    trace = tvoronoi.steps(pts)
    assert trace.engine == "incremental" and len(trace) == len(pts)


def test_steps_clips_the_incremental_diagrams_to_the_box_given():
    pts = uniform(30, seed=8)
    box = (0.25, 0.25, 0.75, 0.75)
    trace = tvoronoi.steps(pts, engine="incremental", bbox=box)
    d = trace.step(len(trace)).diagram
    assert d.bbox == box
    assert_same_diagram(d, tvoronoi.voronoi(pts, bbox=box))


def test_the_seed_orders_the_insertions_and_leaves_the_sweep_alone():
    pts = uniform(40, seed=9)
    first = [tvoronoi.steps(pts, engine="incremental", seed=s).step(1).site for s in range(6)]
    assert len(set(first)) > 1, "the insertion order does not depend on the seed"
    # the sweep takes the sites by y whatever the seed
    sweep = {
        tuple(int(tvoronoi.steps(pts, engine="fortune", seed=s).step(k).site) for k in range(1, 10)) for s in range(3)
    }
    assert len(sweep) == 1


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_steps_checks_the_box_for_both_engines(engine):
    with pytest.raises(tvoronoi.TvoronoiError, match="the box is empty"):
        tvoronoi.steps([[0, 0], [1, 1]], engine=engine, bbox=(1, 0, 0, 1))
    with pytest.raises(tvoronoi.TvoronoiError, match="bbox xmax = 1e-250 is beyond the exact range"):
        tvoronoi.steps([[0.5, 0.5], [0.25, 0.75]], engine=engine, bbox=(0, 0, 1e-250, 1))


def test_steps_refuses_an_unknown_engine():
    with pytest.raises(tvoronoi.TvoronoiError, match="unknown engine 'qhull': choose one of incremental, fortune"):
        tvoronoi.steps([[0, 0]], engine="qhull")


@pytest.mark.parametrize("name, engine", [("fortune_steps", "fortune"), ("incremental_steps", "incremental")])
def test_the_engine_named_entries_are_steps(name, engine):
    pts = uniform(15, seed=2)
    trace = getattr(tvoronoi, name)(pts, bbox=(-1, -1, 2, 2))
    assert trace.engine == engine and trace.bbox == (-1.0, -1.0, 2.0, 2.0)
    same = tvoronoi.steps(pts, engine=engine, bbox=(-1, -1, 2, 2))
    assert [trace.step(k).describe() for k in range(len(trace) + 1)] == [
        same.step(k).describe() for k in range(len(same) + 1)
    ]
