"""The randomized incremental engine: invariants, the brute-force oracle and Qhull on every data set."""

import re

import numpy as np
import pytest
import scipy.spatial
from hypothesis import given, settings, strategies as st

import tvoronoi
from conftest import DATASETS, GENERAL_POSITION
import exact_checks
from tvoronoi.engines import BOX_SCALED_MAX
from invariants import validate
from oracle import assert_matches_oracle

INSERTIONS = ("brio", "random")


@pytest.mark.parametrize("insertion", INSERTIONS)
def test_invariants_and_oracle(dataset, insertion):
    name, pts = dataset
    d = tvoronoi.voronoi(pts, insertion=insertion)
    validate(d)
    assert_matches_oracle(d)


@pytest.mark.parametrize("name", GENERAL_POSITION)
def test_delaunay_matches_qhull(name):
    pts = DATASETS[name]
    d = tvoronoi.voronoi(pts)
    ours = {tuple(sorted(t)) for t in d.delaunay_triangles().tolist()}
    # Qhull loses precision at offsets of 1e9: give it the same points moved
    # to the origin (the move is exact there, and Delaunay is translation-invariant)
    shifted = pts - pts.min(axis=0) if name == "huge" else pts
    theirs = {tuple(sorted(t)) for t in scipy.spatial.Delaunay(shifted).simplices.tolist()}
    assert ours == theirs


@pytest.mark.parametrize("name", GENERAL_POSITION)
def test_insertion_orders_agree(name):
    pts = DATASETS[name]
    a = tvoronoi.voronoi(pts, insertion="brio", seed=1)
    b = tvoronoi.voronoi(pts, insertion="random", seed=2)
    for i in range(len(pts)):
        ra, rb = a.cell_polygon(i), b.cell_polygon(i)
        assert len(ra) == len(rb)
        # same ring up to the starting vertex
        k = int(np.argmin(np.hypot(*(rb - ra[0]).T)))
        np.testing.assert_allclose(np.roll(rb, -k, axis=0), ra, rtol=0, atol=1e-12)


def test_delaunay_triangles_are_ccw_and_empty_circle():
    pts = DATASETS["uniform"]
    tri = tvoronoi.voronoi(pts).delaunay_triangles()
    a, b, c = pts[tri[:, 0]], pts[tri[:, 1]], pts[tri[:, 2]]
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert np.all(cross > 0)
    hull = scipy.spatial.ConvexHull(pts)
    assert len(tri) == 2 * len(pts) - 2 - len(hull.vertices)


def test_grid_has_no_zero_length_edges():
    d = tvoronoi.voronoi(DATASETS["grid"])
    # a 12 x 9 grid: one Voronoi vertex per unit square, shared by four cells
    assert d.n_vertices == 11 * 8
    assert np.all(np.bincount(d.he_origin[d.he_origin >= 0]) == 4)


def test_cocircular_lattice_points_share_one_vertex():
    d = tvoronoi.voronoi(DATASETS["circle"])
    # the centre's cell is a 20-gon whose vertices lie on no other circle: each
    # is a vertex of exactly 3 cells; the outer sites' edges meet at infinity
    centre = len(DATASETS["circle"]) - 1
    assert len(d.cell_polygon(centre)) == 20


def test_collinear_sites_give_strips():
    pts = DATASETS["collinear"]
    d = tvoronoi.voronoi(pts)
    assert d.n_vertices == 0 and len(d.delaunay_triangles()) == 0
    assert d.n_edges == len(pts) - 1
    # every interior site's cell is bounded by two parallel lines
    inner = np.argsort(pts[:, 0])[1:-1]
    for i in inner:
        assert len(d.half_edge_cycle(i)) == 2


def test_repeated_points_share_the_first_cell():
    pts = np.array([[0, 0], [1, 0], [0, 1], [1, 0], [1, 0], [0, 0]], float)
    d = tvoronoi.voronoi(pts)
    assert d.site_of.tolist() == [0, 1, 2, 1, 1, 0]
    assert d.duplicates() == {0: [5], 1: [3, 4]}
    assert len(d.cell_polygon(3)) == 0 and len(d.cell_polygon(1)) > 0


@pytest.mark.parametrize("n", [0, 1, 2])
def test_tiny_inputs(n):
    pts = np.arange(2 * n, dtype=float).reshape(n, 2) * 3.0
    d = tvoronoi.voronoi(pts)
    assert d.n_sites == n
    validate(d)
    if n == 1:
        assert len(d.cell_polygon(0)) == 4   # the whole box


def test_default_box():
    d = tvoronoi.voronoi([[0, 0], [10, 4]])
    assert d.bbox == (-1.0, -1.0, 11.0, 5.0)
    lone = tvoronoi.voronoi([[5, 5]])
    assert lone.bbox[2] > lone.bbox[0] and lone.bbox[3] > lone.bbox[1]
    zero = tvoronoi.voronoi([[0, 0], [0, 0]])
    assert zero.bbox == (-1.0, -1.0, 1.0, 1.0)


def test_user_box_leaving_sites_out():
    pts = DATASETS["uniform"]
    d = tvoronoi.voronoi(pts, bbox=(0.25, 0.25, 0.5, 0.75))
    validate(d, sites_in_box=False)
    assert_matches_oracle(d)


@pytest.mark.parametrize("bad, message", [
    ([[0, 0], [np.nan, 1]], "point 1"),
    ([[0, 0], [1, np.inf]], "finite"),
    ([[0, 0, 0]], "shape"),
    ([["a", "b"]], "numbers"),
])
def test_bad_points_are_named(bad, message):
    with pytest.raises(tvoronoi.TvoronoiError, match=message):
        tvoronoi.voronoi(bad)


@pytest.mark.parametrize("bbox", [(0, 0, 0, 1), (0, 0, 1), (0, 0, np.nan, 1), "abcd"])
def test_bad_boxes(bbox):
    with pytest.raises(tvoronoi.TvoronoiError, match="bbox"):
        tvoronoi.voronoi([[0.5, 0.5]], bbox=bbox)


def test_unknown_engine_and_order():
    with pytest.raises(tvoronoi.TvoronoiError, match="engine"):
        tvoronoi.voronoi([[0, 0]], engine="qhull")
    with pytest.raises(tvoronoi.TvoronoiError, match="insertion"):
        tvoronoi.voronoi([[0, 0]], insertion="sorted")


def test_extreme_scales_are_exact():
    base = np.array([(i, j) for i in range(5) for j in range(5)], float)
    for scale in (2.0 ** -300, 2.0 ** 300):
        d = tvoronoi.voronoi(base * scale)
        assert d.n_vertices == 16      # the grid's cocircular structure survives scaling
        validate(d)


def test_dynamic_range_beyond_exact_arithmetic_is_refused():
    with pytest.raises(tvoronoi.TvoronoiError, match="point 2: .* 2\\^170"):
        tvoronoi.voronoi([[0.0, 0.0], [0.0, 1.0], [1e-60, 0.5]])


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("side", [1.5e300, 2.0 ** 1000, 2.0 ** -701, 1e-250])
def test_a_box_beyond_the_range_rule_is_refused(engine, side):
    """Unit-square sites: box sides past about 1.3e300 (2^997: the exact products split a coordinate by
    multiplying it with 2^27 + 1) or, when nonzero, under 2^-700 are refused with the side and value named."""
    pts = np.random.default_rng(0).random((30, 2))
    with pytest.raises(tvoronoi.TvoronoiError, match=re.escape(f"bbox xmax = {side!r} is beyond the exact range")):
        tvoronoi.voronoi(pts, bbox=(-1.0, -1.0, side, 2.0), engine=engine)
    if side < 1:
        # a dynamic diagram's scale comes from its box too: only a tiny side can be out of range
        with pytest.raises(tvoronoi.TvoronoiError, match="bbox ymin"):
            tvoronoi.DynamicVoronoi(pts, bbox=(-1.0, -side, 2.0, 2.0), engine=engine)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_the_largest_and_smallest_boxes_of_the_range_rule_build(engine):
    pts = np.random.default_rng(0).random((30, 2))
    big = BOX_SCALED_MAX
    d = tvoronoi.voronoi(pts, bbox=(-big, -big, big, big), engine=engine)
    exact_checks.check_cells_valid(d)     # exact at any span (validate's box frame and GEOS are not)
    exact_checks.check_tiling(d)
    small = 2.0 ** -700
    d = tvoronoi.voronoi(np.vstack([pts, [[0.0, 0.0]]]), bbox=(-small, -small, small, small), engine=engine)
    assert len(d.cell_polygon(30)) == 4         # the box around the site at the origin is its cell


small_ints = st.integers(min_value=-6, max_value=6)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(small_ints, small_ints), min_size=0, max_size=30),
       st.sampled_from(INSERTIONS))
def test_property_degenerate_integer_sets(points, insertion):
    """Small integer sets are full of repeats, collinear runs and cocircular quads."""
    pts = np.array(points, float).reshape(-1, 2)
    d = tvoronoi.voronoi(pts, insertion=insertion)
    validate(d)
    assert_matches_oracle(d)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_vertex_on_the_box_edge_leaves_no_spike(engine):
    """The vertex of (0,0), (0,1), (0.4,0.6) is exactly (-0.1, 0.5), on the default box's
    left side, and computes to -0.09999999999999995: the cell must stay simple."""
    pts = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [1, 1], [0.4, 0.6]], float)
    d = tvoronoi.voronoi(pts, engine=engine)
    validate(d)
    assert_matches_oracle(d)
