"""The exact checks themselves catch what they are for, at spans GEOS cannot handle (unit sites, a 1e300 box)."""

import numpy as np
import pytest

import exact_checks as ec
import tvoronoi
from invariants import with_rings


def huge_box_diagram():
    pts = np.random.default_rng(5).random((40, 2))
    d = tvoronoi.voronoi(pts, bbox=(-1e300, -1e300, 1e300, 1e300))
    assert ec.magnitude_span(d) > ec.GEOS_SPAN_BITS
    return d


def test_the_huge_box_diagram_passes():
    d = huge_box_diagram()
    ec.check_cells_valid(d)
    ec.check_tiling(d)


def test_a_moved_shared_vertex_is_caught():
    """One cell's copy of a finite vertex moved by a little: its edges no longer meet the neighbours'."""
    d = huge_box_diagram()
    rings = [d.cell_polygon(i).copy() for i in range(d.n_sites)]
    i = next(i for i, r in enumerate(rings) if len(r) and np.abs(r).max() < 10)
    rings[i][0] = rings[i][0] + 1e-3 * (rings[i][1] - rings[i][0])
    with pytest.raises(AssertionError, match="(no neighbour|cover)"):
        ec.check_tiling(with_rings(d, rings))


def test_a_self_intersecting_cell_is_caught():
    d = huge_box_diagram()
    rings = [d.cell_polygon(i).copy() for i in range(d.n_sites)]
    i = next(i for i, r in enumerate(rings) if len(r) >= 5 and np.abs(r).max() > 1e299)
    r = rings[i]
    r[[1, 2]] = r[[2, 1]]  # a bow tie
    with pytest.raises(AssertionError, match="(not simple|clockwise|flat)"):
        ec.check_cells_valid(with_rings(d, rings))


def test_a_site_outside_its_cell_by_more_than_rounding_is_caught():
    """within_rounding allows a site an ulp of the ring's points outside its cell (a neighbour an ulp
    away), and no more: a cell shifted off its site by 1e-9 is caught, at both spans."""
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert ec.within_rounding(square, (np.nextafter(1.0, 2.0), 0.5))
    assert ec.within_rounding(square, (0.5, -1e-17))
    assert not ec.within_rounding(square, (1.0 + 1e-9, 0.5))
    for d in (huge_box_diagram(), tvoronoi.voronoi(np.random.default_rng(6).random((40, 2)))):
        rings = [d.cell_polygon(i).copy() for i in range(d.n_sites)]
        i = next(i for i, r in enumerate(rings) if len(r) and np.abs(r).max() < 10)
        # the cell moved up until its lowest point is 1e-9 above its site
        rings[i] = rings[i] + np.array([0.0, d.sites[i][1] - rings[i][:, 1].min() + 1e-9])
        with pytest.raises(AssertionError, match="outside its cell"):
            ec.check_cells_valid(with_rings(d, rings))
