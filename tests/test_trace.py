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
    trace = tvoronoi.fortune_steps(pts)
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
        trace = tvoronoi.fortune_steps(pts)
        last = trace.step(len(trace))
        d = tvoronoi.voronoi(pts, engine="fortune")
        assert len({tuple(np.round(v, 9)) for v in last.vertices}) == d.n_vertices
        if name == "duplicates":
            assert any(trace.step(k).kind == "repeat" for k in range(1, len(trace) + 1))


@pytest.fixture(scope="module")
def incremental_run():
    pts = uniform(50, seed=11)
    trace = tvoronoi.incremental_steps(pts)
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
        trace = tvoronoi.incremental_steps(pts)
        for k in range(len(trace) + 1):
            s = trace.step(k)
            assert len(s.inserted) == k
        assert_same_diagram(trace.step(len(trace)).diagram, tvoronoi.voronoi(pts))
