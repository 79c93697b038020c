"""Delaunay triangles from tiles: the canonical triangulation, the exact certification, the global hull."""

from fractions import Fraction

import numpy as np
import pytest
import scipy.spatial
from hypothesis import given, settings
from hypothesis import strategies as st

import tvoronoi
from adversarial import FAMILIES, make
from conftest import DATASETS
from tvoronoi.generators import generate
from tvoronoi.hull import boundary_hull
from tvoronoi.tile_delaunay import (
    Hull,
    canonical_triangles,
    certified_triangles,
    circumcentres,
    disk_inside,
    tile_triangles,
    tiled_triangles,
)
from tvoronoi.tiles import in_region


def canonical(pts, **kw) -> np.ndarray:
    d = tvoronoi.voronoi(pts, threads=1, **kw)
    return canonical_triangles(np.asarray(d.sites), d.triangles, len(d.vertices))[0]


def brute_delaunay(pts: np.ndarray) -> set:
    """Every triple of distinct places whose closed circumcircle holds no other place strictly inside,
    and no other place on it unless the canonical fan of its cocircular polygon takes the triple."""
    places = {}
    for i, p in enumerate(pts.tolist()):
        places.setdefault(tuple(p), i)
    rows = sorted(places.values())
    q = [tuple(Fraction(v) for v in pts[i]) for i in rows]
    out = set()
    k = len(rows)
    for a in range(k):
        for b in range(a + 1, k):
            for c in range(b + 1, k):
                (ax, ay), (bx, by), (cx, cy) = q[a], q[b], q[c]
                turn = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
                if turn == 0:
                    continue
                on, inside = [a, b, c], False
                for d in range(k):
                    if d in (a, b, c):
                        continue
                    dx, dy = q[d]
                    m = [[ax - dx, ay - dy], [bx - dx, by - dy], [cx - dx, cy - dy]]
                    det = sum(
                        m[i][0]
                        * (
                            m[(i + 1) % 3][1] * (m[(i + 2) % 3][0] ** 2 + m[(i + 2) % 3][1] ** 2)
                            - m[(i + 2) % 3][1] * (m[(i + 1) % 3][0] ** 2 + m[(i + 1) % 3][1] ** 2)
                        )
                        for i in range(3)
                    )
                    s = det if turn > 0 else -det
                    if s > 0:
                        inside = True
                        break
                    if s == 0:
                        on.append(d)
                if inside:
                    continue
                # a cocircular polygon: the fan from its lowest site takes the triples holding that site
                # and two neighbours along the circle
                low = min(on)
                if low not in (a, b, c):
                    continue
                ring = sorted(on, key=lambda i: _angle(q, on, i))
                start = ring.index(low)
                ring = ring[start:] + ring[:start]
                fans = {frozenset((ring[0], ring[j], ring[j + 1])) for j in range(1, len(ring) - 1)}
                if frozenset((a, b, c)) in fans:
                    out.add(tuple(sorted(rows[i] for i in (a, b, c))))
    return out


def _angle(q, on, i):
    # order of cocircular points around their centroid (fine for a test on small exact inputs)
    cx = sum(float(q[j][0]) for j in on) / len(on)
    cy = sum(float(q[j][1]) for j in on) / len(on)
    return np.arctan2(float(q[i][1]) - cy, float(q[i][0]) - cx)


def as_set(tri: np.ndarray) -> set:
    return {tuple(sorted(t)) for t in tri.tolist()}


def test_canonical_triangles_of_a_grid_fan_each_square_from_its_lowest_corner():
    side = 6
    pts = np.stack(np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float)), -1).reshape(-1, 2)
    got = canonical(pts)
    # row r, column c is site r * side + c; each square's lowest corner is its bottom-left one, and the
    # fan from it cuts the square along the diagonal from bottom-left to top-right
    want = set()
    for r in range(side - 1):
        for c in range(side - 1):
            i = r * side + c
            want |= {tuple(sorted((i, i + 1, i + side + 1))), tuple(sorted((i, i + side + 1, i + side)))}
    assert as_set(got) == want
    assert all(t[0] == min(t) for t in got.tolist())


@pytest.mark.parametrize("seed", range(6))
def test_canonical_triangles_equal_brute_force_on_rounded_points(seed):
    pts = np.round(np.random.default_rng(seed).random((40, 2)) * 4) / 2  # many cocircular quadruples
    assert as_set(canonical(pts)) == brute_delaunay(pts)


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_both_engines_give_the_same_canonical_triangles(name):
    pts = DATASETS[name]
    inc, fortune = canonical(pts), canonical(pts, engine="fortune")
    assert np.array_equal(inc, fortune)


def test_without_cocircular_sites_the_canonical_triangles_are_the_engines_and_scipys():
    pts = generate("uniform", 3_000, seed=2)
    d = tvoronoi.voronoi(pts)
    assert as_set(canonical(pts)) == as_set(d.triangles) == as_set(scipy.spatial.Delaunay(pts).simplices)


def test_boundary_hull_keeps_collinear_sites_and_the_lowest_of_repeats():
    # a square with points along its sides, repeats and inner points
    pts = np.array(
        [[0, 0], [2, 0], [2, 2], [0, 2], [1, 0], [2, 1], [1, 1], [0, 1], [1, 2], [0.5, 0.5], [1, 0], [0, 0]], float
    )
    assert boundary_hull(pts, np.arange(len(pts))).tolist() == [0, 4, 1, 5, 2, 8, 3, 7]
    # every hull vertex of scipy's hull is there, in counter-clockwise order, on larger random input
    pts = generate("gaussian", 20_000, seed=4)
    got = boundary_hull(pts, np.arange(len(pts)))
    assert set(got.tolist()) == set(scipy.spatial.ConvexHull(pts).vertices.tolist())
    ring = pts[got]
    assert 0.5 * np.sum(ring[:, 0] * np.roll(ring[:, 1], -1) - np.roll(ring[:, 0], -1) * ring[:, 1]) > 0
    # the hull of parts' hulls is the hull of all
    parts = np.array_split(np.arange(len(pts)), 5)
    hulls = np.concatenate([boundary_hull(pts[p], p) for p in parts])
    assert boundary_hull(pts[hulls], hulls).tolist() == got.tolist()


def test_the_hull_of_collinear_sites_has_no_edge():
    line = np.array([[0.0, 0.0], [2.0, 2.0], [1.0, 1.0], [3.0, 3.0]])
    assert Hull.of(line, np.arange(4)).edges == set() and Hull.of(line, np.arange(4)).collinear
    square = Hull.of(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.0]]), np.arange(5))
    assert square.edges == {(0, 4), (4, 1), (1, 2), (2, 3), (3, 0)} and not square.collinear


def test_disk_inside_is_exact_at_tangency():
    corners = [(-1.0, 0.0), (1.0, 0.0), (0.0, 1.0)]  # the unit circle about the origin
    assert disk_inside(corners, [], (-1.0, -1.0, 1.0, 1.0))  # tangent to every side: inside
    assert not disk_inside(corners, [], (-1.0, -1.0, 1.0, 0.9999999999999999))
    # cut by the hull line through (-1, 0) and (1, 0) (the sites above it), the lower half no longer counts
    assert disk_inside(corners, [((-1.0, 0.0), (1.0, 0.0))], (-1.0, -0.5, 1.0, 1.0))
    assert not disk_inside(corners, [((-1.0, 0.0), (1.0, 0.0))], (-0.5, -0.5, 1.0, 1.0))
    # the float filter sends the tangent case to the exact test and agrees with it
    pts = np.array(corners)
    tri = np.array([[0, 1, 2]])
    centres = circumcentres(pts, tri)
    no_hull = np.zeros((1, 3), bool)
    assert certified_triangles(pts, tri, centres, no_hull, (-1.0, -1.0, 1.0, 1.0))[0]
    assert not certified_triangles(pts, tri, centres, no_hull, (-1.0, -1.0, 1.0, 0.9999999999999999))[0]


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), k=st.integers(3, 40))
def test_hunt_emitted_triangles_are_final(seed, k):
    # a random region of random rounded sites: every triangle a task emits is a triangle of the whole
    # canonical triangulation, and a site it calls done has all its triangles there
    rng = np.random.default_rng(seed)
    pts = np.round(rng.random((k + 20, 2)), int(rng.integers(1, 4)))
    cx, cy, half = rng.random(), rng.random(), 0.1 + 0.5 * rng.random()
    region = (cx - half, cy - half, cx + half, cy + half)
    seen = np.flatnonzero(in_region(pts[:, 0], pts[:, 1], region))
    if len(seen) < 3:
        return
    ids = seen.astype(np.int64)
    whole = as_set(canonical(pts))
    d = tvoronoi.voronoi(pts[seen], threads=1)
    extent = (*pts.min(axis=0).tolist(), *pts.max(axis=0).tolist())
    got = tile_triangles(
        pts[seen], ids, np.ones(len(seen), bool), region, d, hull=Hull.of(pts, np.arange(len(pts))), extent=extent
    )
    assert as_set(got.triangles) <= whole
    for i in got.done.tolist():
        assert {t for t in whole if min(t) == i} <= as_set(got.triangles)


@pytest.mark.parametrize("name", sorted(DATASETS))
@pytest.mark.parametrize("tiles", [2, 5])
def test_small_datasets_tile_to_the_canonical_triangles(name, tiles):
    pts = DATASETS[name]
    assert np.array_equal(tiled_triangles(pts, tiles=tiles, halo_scale=0.3).triangles, canonical(pts))


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_adversarial_families_tile_to_the_canonical_triangles(family):
    case = make(family, 1)
    pts = case.points[:3000]
    got = tiled_triangles(pts, tiles=4, bbox=case.bbox, halo_scale=0.5)
    assert np.array_equal(got.triangles, canonical(pts, bbox=case.bbox))


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(1, 300),
    tiles=st.integers(1, 9),
    decimals=st.integers(0, 3),
    halo=st.sampled_from([0.05, 0.3, 1.0]),
    seed=st.integers(0, 2**32 - 1),
)
def test_hunt_rounded_points_tile_to_the_canonical_triangles(n, tiles, decimals, halo, seed):
    pts = np.round(np.random.default_rng(seed).random((n, 2)) * 10, decimals)
    got = tiled_triangles(pts, tiles=tiles, halo_scale=halo, seed=seed)
    assert np.array_equal(got.triangles, canonical(pts))
    assert got.pending_after[-1] == 0
