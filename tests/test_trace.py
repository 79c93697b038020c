"""Step traces of both engines: every state consistent, the last one equal to the full build."""

import numpy as np
import pytest

import tvoronoi
from conftest import DATASETS
from test_fortune import assert_same_diagram
from tvoronoi.generators import uniform


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
            for site in s.beach[arc - 1:arc + 2]:
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
            m = np.array([[*(a - p), (a - p) @ (a - p)], [*(b - p), (b - p) @ (b - p)],
                          [*(c - p), (c - p) @ (c - p)]])
            assert np.linalg.det(m) > 0
        after = {tuple(sorted(t)) for t in s.diagram.delaunay_triangles().tolist()}
        assert not {tuple(sorted(t)) for t in s.conflict} & after
        # the cells it took area from are its Delaunay neighbours now
        nbrs = {v for t in s.diagram.delaunay_triangles() if s.site in t for v in t} - {s.site}
        assert set(s.stolen_from.tolist()) <= nbrs


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
    sweep = {tuple(int(tvoronoi.steps(pts, engine="fortune", seed=s).step(k).site) for k in range(1, 10))
             for s in range(3)}
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
    assert [trace.step(k).describe() for k in range(len(trace) + 1)] == \
        [same.step(k).describe() for k in range(len(same) + 1)]
