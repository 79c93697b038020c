"""The invariant checker judges the rings a Diagram holds, not a rounded copy of them.

Its frame (coordinates brought to about the unit square, so that areas of tiny or huge diagrams stay
representable) once translated and divided by the box's width. That rounds each point, and on the cells
of sites along a rectangle's sides at tenths (strips thinner than an ulp of the translated coordinates)
it made valid rings cross themselves: a false alarm at 1,000 sites, and the same rounding could as well
hide a ring that does cross itself. The frame is now a power of two, exact.
"""

import numpy as np
import pytest
import shapely

import adversarial
import invariants
import tvoronoi


def perimeter_diagram(seed: int, engine: str):
    case = adversarial.rectangle_perimeter(300, height=200, step=0.1, seed=seed)
    return tvoronoi.voronoi(case.points, engine=engine)


@pytest.mark.parametrize("engine", ["fortune", "incremental"])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_thin_perimeter_cells_are_judged_as_held(seed, engine):
    """Every ring is valid as the Diagram holds it, valid in the frame, and the whole check passes."""
    d = perimeter_diagram(seed, engine)
    frame = invariants.box_frame(d)
    thin = 0
    for i in range(d.n_sites):
        ring = d.cell_polygon(i)
        assert shapely.Polygon(ring).is_valid, f"cell {i} invalid as held"
        assert shapely.Polygon(frame(ring)).is_valid, f"cell {i} invalid in the frame"
        lo, hi = ring.min(axis=0), ring.max(axis=0)
        thin += min(hi - lo) < 0.2
    assert thin > 100  # the strips that fooled the old frame are there
    invariants.validate(d)


@pytest.mark.parametrize(
    "scale, bbox",
    [(1.0, None), (1e-300, None), (1e300, None), (3e-320, None), (1.0, (-1e300, -1e300, 1e300, 1e300))],
)
def test_the_frame_moves_no_point_off_its_value(scale, bbox):
    """The framed points are the points times one power of two, exactly, at any scale (subnormal sites,
    a 1e300 box), so the frame's verdicts are the raw points' verdicts."""
    pts = np.random.default_rng(7).random((60, 2)) * scale
    d = tvoronoi.voronoi(pts) if bbox is None else tvoronoi.voronoi(pts, bbox=bbox)
    raw = np.asarray(d.cell_points, float)
    framed = invariants.box_frame(d)(raw)
    shift = np.frexp(np.abs(raw).max())[1] - np.frexp(np.abs(framed).max())[1]
    assert np.array_equal(np.ldexp(framed, shift), raw)
    assert 0.25 <= np.abs(invariants.box_frame(d)(np.asarray(d.bbox, float))).max() <= 1.0 or shift == 0


@pytest.mark.parametrize("scale", [1.0, 1e-300, 1e300, 3e-320])
def test_cells_pass_at_any_scale(scale):
    """The cells' check (validity, orientation, coverage, areas) holds from subnormal sites to 1e300."""
    pts = np.random.default_rng(7).random((60, 2)) * scale
    invariants.check_cells(tvoronoi.voronoi(pts))


def test_a_ring_crossing_itself_by_an_ulp_is_caught():
    """A cell whose last point an ulp beyond the opposite side (a bow tie an ulp wide) fails the check."""
    d = perimeter_diagram(1, "incremental")
    rings = [np.array(d.cell_polygon(i)) for i in range(d.n_sites)]
    k = next(i for i, r in enumerate(rings) if len(r) == 4)
    r = rings[k]
    # the ring's first point, moved across its opposite edge's line: swap two neighbours
    rings[k] = r[[0, 2, 1, 3]]
    with pytest.raises(AssertionError, match=f"cell {k} invalid"):
        invariants.check_cells(invariants.with_rings(d, rings))
