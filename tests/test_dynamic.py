"""Dynamic updates: after any sequence of inserts, removes and moves, the diagram equals a fresh build."""

import numpy as np
import pytest
from hypothesis import settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, precondition, rule

import tvoronoi
from tvoronoi.generators import uniform

ENGINES = ("incremental", "fortune")
BOX = (-10.0, -10.0, 20.0, 20.0)


def cells_by_place(cells):
    """{(x, y): ring} for the sites that own a cell."""
    return {k: v for k, v in cells.items() if len(v)}


def assert_equals_fresh_build(dv, box=BOX):
    """Each place holds one cell, under one of the ids there, equal to a fresh build's cell."""
    view = dv.diagram()
    ids = np.flatnonzero(view.alive)
    if len(ids) == 0:
        return
    fresh = tvoronoi.voronoi(view.sites[ids], bbox=box)
    places = {}
    for row, i in enumerate(ids):
        places.setdefault(tuple(view.sites[i]), []).append((row, i))
    for place, members in places.items():
        rings = [view.cell_polygon(i) for _, i in members]
        owners = [i for (_, i), r in zip(members, rings) if len(r)]
        want = fresh.cell_polygon(fresh.site_of[members[0][0]])
        if len(want) == 0:
            assert not owners, f"place {place}: a cell where a fresh build has none"
            continue
        assert len(owners) == 1, f"place {place}: cells under ids {owners} of {[i for _, i in members]}"
        ring = rings[[i for _, i in members].index(owners[0])]
        # one clipper, one correctly rounded construction: the same ring, bit for bit
        assert np.array_equal(ring, want), f"site {owners[0]} at {place}: {ring} vs a fresh build's {want}"
    # the full export agrees with the view
    full = view.to_diagram()
    assert full.n_vertices == fresh.n_vertices
    for members in places.values():
        for _, i in members:
            assert len(full.cell_polygon(i)) == len(view.cell_polygon(i))


coords = st.integers(min_value=0, max_value=8).map(float)


class DynamicMachine(RuleBasedStateMachine):
    """Random edits on a small integer grid: repeats, collinear runs and cocircular quads abound."""

    engine = "incremental"

    @initialize(points=st.lists(st.tuples(coords, coords), min_size=0, max_size=8))
    def start(self, points):
        self.dv = tvoronoi.DynamicVoronoi(np.array(points, float).reshape(-1, 2), engine=self.engine, bbox=BOX)

    def live(self):
        return np.flatnonzero(self.dv.diagram().alive).tolist()

    @rule(x=coords, y=coords)
    def insert(self, x, y):
        i = self.dv.insert(x, y)
        assert i in self.dv.changed

    @precondition(lambda self: len(self.live()) > 0)
    @rule(data=st.data())
    def remove(self, data):
        i = data.draw(st.sampled_from(self.live()))
        self.dv.remove(i)
        assert len(self.dv.diagram().cell_polygon(i)) == 0

    @precondition(lambda self: len(self.live()) > 0)
    @rule(data=st.data(), x=coords, y=coords)
    def move(self, data, x, y):
        i = data.draw(st.sampled_from(self.live()))
        self.dv.move(i, x, y)
        assert tuple(self.dv.diagram().sites[i]) == (x, y)

    @invariant()
    def equals_fresh_build(self):
        assert_equals_fresh_build(self.dv)


class FortuneMachine(DynamicMachine):
    engine = "fortune"


TestDynamicIncremental = DynamicMachine.TestCase
TestDynamicIncremental.settings = settings(max_examples=60, stateful_step_count=25, deadline=None)
TestDynamicFortune = FortuneMachine.TestCase
TestDynamicFortune.settings = settings(max_examples=60, stateful_step_count=25, deadline=None)


@pytest.mark.parametrize("engine", ENGINES)
def test_long_random_sequence(engine, rng):
    pts = uniform(300, seed=5)
    dv = tvoronoi.DynamicVoronoi(pts, engine=engine, bbox=(-0.1, -0.1, 1.1, 1.1))
    for _ in range(600):
        live = np.flatnonzero(dv.diagram().alive)
        r = rng.random()
        if r < 0.4:
            dv.insert(*rng.random(2))
        elif r < 0.7:
            dv.remove(int(rng.choice(live)))
        else:
            i = int(rng.choice(live))
            dv.move(i, *(dv.diagram().sites[i] + rng.normal(0, 0.01, 2)))
    assert_equals_fresh_build(dv, box=(-0.1, -0.1, 1.1, 1.1))


@pytest.mark.parametrize("engine", ENGINES)
def test_down_to_nothing_and_back(engine):
    dv = tvoronoi.DynamicVoronoi(uniform(20, seed=3), engine=engine, bbox=(-1, -1, 2, 2))
    for i in range(20):
        dv.remove(i)
        assert_equals_fresh_build(dv, box=(-1, -1, 2, 2))
    assert len(dv) == 0
    for x, y in [(0.5, 0.5), (0.2, 0.2), (0.8, 0.8), (0.2, 0.8), (0.5, 0.5)]:
        dv.insert(x, y)
        assert_equals_fresh_build(dv, box=(-1, -1, 2, 2))


@pytest.mark.parametrize("engine", ENGINES)
def test_special_places(engine):
    """On an existing site, on a bisector, outside the hull, collinear with the hull."""
    dv = tvoronoi.DynamicVoronoi([[0, 0], [2, 0], [0, 2], [2, 2]], engine=engine, bbox=BOX)
    a = dv.insert(0, 0)  # on a site: shares its cell
    assert len(dv.diagram().cell_polygon(a)) == 0 and dv.changed.tolist() == [a]
    dv.insert(1, 0)  # on a hull edge and a bisector
    dv.insert(1, 1)  # the common vertex of four cells
    dv.insert(5, 5)  # outside the hull
    dv.insert(3, 0)  # collinear with a hull edge
    assert_equals_fresh_build(dv)
    dv.remove(0)  # the repeat at (0, 0) takes over
    assert len(dv.diagram().cell_polygon(a)) > 0
    assert_equals_fresh_build(dv)


def test_errors_change_nothing():
    dv = tvoronoi.DynamicVoronoi([[0, 0], [1, 0], [0, 1]])
    before = dv.diagram().cell_polygon(0).copy()
    with pytest.raises(tvoronoi.TvoronoiError, match="no site 9"):
        dv.remove(9)
    dv.remove(2)
    with pytest.raises(tvoronoi.TvoronoiError, match="site 2 was removed"):
        dv.move(2, 0.5, 0.5)
    with pytest.raises(tvoronoi.TvoronoiError, match="finite"):
        dv.insert(float("nan"), 0)
    with pytest.raises(tvoronoi.TvoronoiError, match="finite"):
        dv.move(0, 0, float("inf"))
    assert len(dv) == 2
    assert tuple(dv.diagram().sites[0]) == (0.0, 0.0)
    assert len(before) > 0


def test_changed_lists_the_cells_that_moved(rng):
    pts = uniform(200, seed=9)
    dv = tvoronoi.DynamicVoronoi(pts, bbox=(-0.1, -0.1, 1.1, 1.1))
    before = {i: dv.diagram().cell_polygon(i) for i in range(200)}
    dv.insert(0.5, 0.5)
    changed = set(dv.changed.tolist())
    for i in range(200):
        after = dv.diagram().cell_polygon(i)
        same = len(after) == len(before[i]) and np.allclose(after, before[i])
        assert same or i in changed, f"cell {i} changed but is not listed"
    assert 200 in changed and len(changed) < 20


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_a_new_site_out_of_range_is_measured_against_the_diagram(engine):
    """The range rule for an insert or a move names the diagram's scale, not the new site itself, and
    nothing changes."""
    dv = tvoronoi.DynamicVoronoi(uniform(50, seed=3), engine=engine)
    before = [dv.diagram().cell_polygon(i).tolist() for i in range(50)]
    for update in (lambda: dv.insert(5e-324, 5e-324), lambda: dv.move(0, 1e-300, 0.5)):
        with pytest.raises(tvoronoi.TvoronoiError) as caught:
            update()
        message = str(caught.value)
        assert message.startswith("the new site: coordinate ")
        assert "smaller than the scale of the diagram (about " in message
        assert "around the scale of the diagram" in message and "(the same point)" not in message
    assert [dv.diagram().cell_polygon(i).tolist() for i in range(50)] == before
