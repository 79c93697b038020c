"""The randomized incremental engine: invariants, the brute-force oracle and Qhull on every data set."""

import numpy as np
import pytest
import scipy.spatial
from hypothesis import given, settings
from hypothesis import strategies as st

import tvoronoi
from conftest import DATASETS, GENERAL_POSITION
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
        assert len(d.cell_polygon(0)) == 4  # the whole box


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


def test_extreme_scales_are_exact():
    base = np.array([(i, j) for i in range(5) for j in range(5)], float)
    for scale in (2.0**-300, 2.0**300):
        d = tvoronoi.voronoi(base * scale)
        assert d.n_vertices == 16  # the grid's cocircular structure survives scaling
        validate(d)


small_ints = st.integers(min_value=-6, max_value=6)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(small_ints, small_ints), min_size=0, max_size=30), st.sampled_from(INSERTIONS))
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


@pytest.mark.parametrize("name", ["uniform", "grid", "circle", "duplicates", "collinear_repeats"])
def test_an_insertion_order_gives_the_triangulation_of_the_sites_in_that_order(name):
    """triangulate(xs, ys, order=o) is triangulate(xs[o], ys[o]) with the sites named as given: the same
    triangles and repeats, site for site (the halves' build numbers sites along a curve and inserts them
    in its BRIO order)."""
    from tvoronoi.kernels import incremental

    pts = DATASETS[name]
    xs, ys = np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1])
    o = np.random.default_rng(3).permutation(len(xs)).astype(np.int32)
    s1, tv1, opp1, dup1 = incremental.triangulate(xs, ys, order=o)
    s2, tv2, opp2, dup2 = incremental.triangulate(xs[o], ys[o])
    assert s1 == s2
    n = len(xs)
    name_of = np.append(o, n)  # site k of the second run is site o[k]; n stays the vertex at infinity
    assert np.array_equal(tv1, name_of[tv2]) and np.array_equal(opp1, opp2)
    assert np.array_equal(dup1[o], np.where(dup2 >= 0, name_of[np.maximum(dup2, 0)], -1))


@pytest.mark.parametrize(
    "order, message",
    [([0, 1, 1], "1 at place 2"), ([0, 1, 3], "3 at place 2"), ([0, -1, 2], "-1 at place 1"), ([0, 1], "of 2 sites")],
)
def test_a_wrong_insertion_order_is_refused_by_name(order, message):
    from tvoronoi.kernels import incremental

    xs = np.array([0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match=message):
        incremental.triangulate(xs, xs[::-1].copy(), order=np.array(order, np.int32))
