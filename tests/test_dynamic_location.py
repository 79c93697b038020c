"""Point location in dynamic diagrams: the walk starts from the jump grid, not only the last triangle.

The walk itself is exact, so the start changes only its length: these tests check that far-apart
updates walk a few triangles, and that a start taken from a grid cell whose sites are gone, or from
outside the grid, still gives the diagram a fresh build gives.
"""

import numpy as np
import pytest

import tvoronoi
from tests.test_dynamic import ENGINES, assert_equals_fresh_build
from tvoronoi.generators import uniform

BOX = (-0.5, -0.5, 1.5, 1.5)


def far_walk(dv) -> int:
    """Triangles visited to locate a site inserted in the corner opposite the previous insertion."""
    dv.insert(0.01, 0.01)
    dv.insert(0.99, 0.99)
    return dv._mesh.walk_steps


@pytest.mark.parametrize("engine", ENGINES)
def test_far_inserts_walk_a_few_triangles(engine):
    n = 40_000
    dv = tvoronoi.DynamicVoronoi(uniform(n, seed=8), engine=engine, bbox=BOX)
    steps = far_walk(dv)
    # from the last triangle the walk crosses the whole set: about sqrt(2 n) triangles or more
    assert steps < 0.1 * np.sqrt(2 * n), f"{steps} triangles walked"


@pytest.mark.parametrize("engine", ENGINES)
def test_a_grid_cell_emptied_then_filled_again(engine):
    pts = uniform(2_000, seed=9)
    dv = tvoronoi.DynamicVoronoi(pts, engine=engine, bbox=BOX)
    # every site of the lower-left quarter leaves: the grid's starts there are gone
    corner = np.flatnonzero((pts[:, 0] < 0.5) & (pts[:, 1] < 0.5))
    for i in corner:
        dv.remove(int(i))
    rng = np.random.default_rng(4)
    for x, y in rng.random((200, 2)) * 0.5:
        dv.insert(x, y)
    assert_equals_fresh_build(dv, box=BOX)


@pytest.mark.parametrize("engine", ENGINES)
def test_inserts_outside_the_grid(engine):
    dv = tvoronoi.DynamicVoronoi(uniform(2_000, seed=10), engine=engine, bbox=BOX)
    for x, y in [(-0.4, -0.4), (1.4, 0.2), (0.3, 1.45), (1.45, 1.45), (-0.3, 1.2)]:
        dv.insert(x, y)
    assert_equals_fresh_build(dv, box=BOX)
