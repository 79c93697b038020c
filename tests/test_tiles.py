"""Tiles without Dask: k-d cuts, halos, certification, and cells built tile by tile equal to one build, bit for bit."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tvoronoi
from adversarial import FAMILIES, make
from conftest import DATASETS
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import generate
from tvoronoi.tiles import (
    build_tile,
    certified,
    certify_cells,
    extent_of,
    flower_box,
    group_reaches,
    grown,
    in_region,
    kd_rects,
    tile_of,
    tiled_cells,
)


def assert_same_cells(tiled, full) -> None:
    """Every row has exactly one cell, and (site, ring) pairs equal the whole build's, bit for bit."""
    n = full.n_sites
    assert np.array_equal(tiled.ids, np.arange(n))
    assert np.array_equal(np.diff(tiled.offsets), np.diff(full.cell_offsets))
    whole = full.cell_points[full.cell_vertices]
    assert tiled.ring_xy.shape == whole.shape
    # bit for bit: the same doubles (-0.0 and 0.0 told apart)
    assert np.array_equal(tiled.ring_xy.view(np.int64), whole.view(np.int64))


def test_kd_rects_partition_the_plane_into_balanced_tiles():
    pts = generate("clustered", 20_000, seed=4)
    rects = kd_rects(pts, 7)
    owner = tile_of(pts[:, 0], pts[:, 1], rects)
    # each point in exactly one tile
    hits = sum(
        ((pts[:, 0] >= x0) & (pts[:, 0] < x1) & (pts[:, 1] >= y0) & (pts[:, 1] < y1)).astype(int)
        for x0, y0, x1, y1 in rects
    )
    assert (hits == 1).all() and (owner >= 0).all()
    counts = np.bincount(owner, minlength=7)
    assert counts.min() >= 0.8 * len(pts) / 7 and counts.max() <= 1.2 * len(pts) / 7


def test_kd_rects_refuse_a_bad_tile_count():
    with pytest.raises(TvoronoiError, match="tiles must be a positive integer"):
        kd_rects(np.zeros((3, 2)), 0)


@pytest.mark.parametrize("name", sorted(DATASETS))
@pytest.mark.parametrize("tiles", [2, 5])
def test_small_datasets_tile_to_the_same_cells(name, tiles):
    pts = DATASETS[name]
    assert_same_cells(tiled_cells(pts, tiles=tiles, halo_scale=0.3), tvoronoi.voronoi(pts, threads=1))


@pytest.mark.parametrize("distribution", ["uniform", "gaussian", "clustered"])
def test_distributions_tile_to_the_same_cells(distribution):
    pts = generate(distribution, 30_000, seed=11)
    tiled = tiled_cells(pts, tiles=6)
    assert_same_cells(tiled, tvoronoi.voronoi(pts, threads=1))
    # the pending counts fall to zero, one per round; the reach of the first round's leftovers suffices
    assert len(tiled.pending_after) == tiled.rounds and tiled.pending_after[-1] == 0
    assert tiled.rounds <= 2


def test_sparse_corners_need_more_rounds_and_a_tight_box_fewer():
    pts = generate("gaussian", 20_000, seed=3)
    tiled = tiled_cells(pts, tiles=8)
    assert tiled.rounds > 1 and tiled.pending_after[0] > 0
    assert_same_cells(tiled, tvoronoi.voronoi(pts, threads=1))


@pytest.mark.parametrize("bbox", [(-50.0, -50.0, 50.0, 50.0), (0.2, 0.3, 0.7, 0.6)])
def test_a_user_box_far_or_cutting_tiles_to_the_same_cells(bbox):
    pts = generate("uniform", 5_000, seed=5)
    assert_same_cells(tiled_cells(pts, tiles=4, bbox=bbox), tvoronoi.voronoi(pts, bbox=bbox, threads=1))


def test_a_1e9_cluster_and_repeated_points_tile_to_the_same_cells():
    rng = np.random.default_rng(8)
    cluster = 1.0 + 1e-9 * rng.random((4_000, 2))
    pts = np.concatenate([cluster, cluster[rng.integers(0, 4_000, 500)], generate("uniform", 1_000, seed=8)])
    assert_same_cells(tiled_cells(pts, tiles=5), tvoronoi.voronoi(pts, threads=1))


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_adversarial_families_tile_to_the_same_cells(family):
    case = make(family, 1)
    pts = case.points[:3000]
    full = tvoronoi.voronoi(pts, bbox=case.bbox, threads=1)
    assert_same_cells(tiled_cells(pts, tiles=4, bbox=case.bbox, halo_scale=0.5), full)


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(1, 300),
    tiles=st.integers(1, 9),
    decimals=st.integers(0, 3),
    halo=st.sampled_from([0.05, 0.3, 1.0]),
    seed=st.integers(0, 2**32 - 1),
)
def test_hunt_rounded_points_tile_to_the_same_cells(n, tiles, decimals, halo, seed):
    # rounded coordinates: repeats, collinear runs and cocircular quadruples at tile edges
    pts = np.round(np.random.default_rng(seed).random((n, 2)) * 10, decimals)
    assert_same_cells(tiled_cells(pts, tiles=tiles, halo_scale=halo, seed=seed), tvoronoi.voronoi(pts, threads=1))


def test_certification_refuses_a_cell_a_hidden_site_cuts():
    # the local diagram of three sites; a fourth, outside the region, cuts the middle cell
    seen = np.array([[0.0, 0.0], [-1.0, 0.0], [1.0, 0.0]])
    hidden = np.array([[0.0, 0.9]])
    box = (-2.0, -2.0, 2.0, 2.0)
    region = (-1.5, -1.5, 1.5, 0.5)  # y <= 0.5: the hidden site is outside
    assert not in_region(hidden[:, 0], hidden[:, 1], region).any()
    cells = build_tile(seen, np.arange(3), np.array([True, False, False]), region, box)
    assert cells.ids.size == 0 and cells.pending.tolist() == [0]
    # once the region holds it, the cell is certified and is the cell of all four sites
    everything = np.concatenate([seen, hidden])
    cells = build_tile(
        everything, np.arange(4), np.array([True, False, False, False]), grown(extent_of(everything), 10.0), box
    )
    assert cells.ids.tolist() == [0]
    assert np.array_equal(cells.ring_xy, tvoronoi.voronoi(everything, bbox=box).cell_polygon(0))


def test_certification_is_exact_at_the_margin():
    # a ring point at distance r from the site: a side exactly r away is not enough room (rounding margin),
    # a side safely farther is
    site = np.array([[0.0, 0.0]])
    ring = np.array([[1.0, 0.0]])
    offsets = np.array([0, 1])
    assert not certified(ring, offsets, site, (-10.0, -10.0, 2.0, 10.0))[0]
    assert certified(ring, offsets, site, (-10.0, -10.0, 2.0 + 1e-9, 10.0))[0]
    assert certified(ring, offsets, site, (-math.inf, -math.inf, math.inf, math.inf))[0]
    # a non-finite distance is never certified
    assert not certified(np.array([[1e308, 0.0]]), offsets, np.array([[-1e308, 0.0]]), (-math.inf, -1, math.inf, 1))[0]
    # an empty ring (a cell that misses the box) stays out whatever the hidden sites
    assert certified(np.empty((0, 2)), np.array([0, 0]), site, (0.0, 0.0, 0.0, 0.0))[0]


def _exact_room_holds(ring: np.ndarray, site, region, top: float) -> bool:
    """Exactly, in rationals: every ring point v, moved by up to two ulps of ``top`` in each coordinate
    (its rounding, with room to spare), is farther inside the region than from the site."""
    from fractions import Fraction

    u = 2 * Fraction(float(np.spacing(top)))
    sx, sy = Fraction(float(site[0])), Fraction(float(site[1]))
    for vx, vy in ring.tolist():
        vx, vy = Fraction(vx), Fraction(vy)
        rooms = [
            vx - Fraction(region[0]) if math.isfinite(region[0]) else None,
            vy - Fraction(region[1]) if math.isfinite(region[1]) else None,
            Fraction(region[2]) - vx if math.isfinite(region[2]) else None,
            Fraction(region[3]) - vy if math.isfinite(region[3]) else None,
        ]
        if all(v is None for v in rooms):
            continue
        room = min(v for v in rooms if v is not None)
        room -= u  # the exact point may lie u nearer a side
        reach = (abs(vx - sx) + u) ** 2 + (abs(vy - sy) + u) ** 2  # and u farther from the site in each coordinate
        if room < 0 or room * room < reach:
            return False
    return True


@settings(max_examples=300, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    scale=st.sampled_from([1e-300, 1e-160, 1e-8, 1.0, 1e8, 1e150, 1e300]),
    k=st.integers(1, 8),
)
def test_hunt_certification_agrees_with_exact_rationals(seed, scale, k):
    # rings of k points near a site, regions whose sides pass near the ring: whatever the test certifies
    # holds exactly, at every scale (tiny distances whose squares underflow, huge ones that overflow)
    rng = np.random.default_rng(seed)
    site = rng.normal(size=2) * scale
    ring = site + rng.normal(size=(k, 2)) * scale
    r = float(np.max(np.hypot(ring[:, 0] - site[0], ring[:, 1] - site[1])))
    x0, y0, x1, y1 = (
        float(v)
        for v in (ring.min(axis=0) - r * rng.uniform(0.9, 1.1, 2)).tolist()
        + (ring.max(axis=0) + r * rng.uniform(0.9, 1.1, 2)).tolist()
    )
    sides = [x0, y0, x1, y1]
    # sides at the edge of the test: as near the ring as its distances, in doubles
    dist = np.hypot(ring[:, 0] - site[0], ring[:, 1] - site[1])
    edge = [np.min(ring[:, 0] - dist), np.min(ring[:, 1] - dist), np.max(ring[:, 0] + dist), np.max(ring[:, 1] + dist)]
    for i in range(4):
        chance = rng.random()
        if chance < 0.2:
            sides[i] = -math.inf if i < 2 else math.inf
        elif chance < 0.6:
            sides[i] = float(edge[i]) * (1 + (1 if i < 2 else -1) * float(rng.choice([0, 1e-15, 1e-13, 1e-11]))) - (
                1 if i < 2 else -1
            ) * float(rng.choice([0, 1, 4, 64])) * float(np.spacing(np.max(np.abs(ring))))
    region = tuple(sides)
    ok = certified(ring, np.array([0, k]), site[None], region)[0]
    if ok and np.all(np.isfinite(ring)):
        top = float(np.max(np.abs(ring)))
        assert _exact_room_holds(ring, site, region, top)
    # a region whose side runs through a ring point never certifies it
    through = (float(ring[0, 0]), -math.inf, math.inf, math.inf)
    assert not certified(ring, np.array([0, k]), site[None], through)[0] or np.all(ring[:, 0] == site[0])


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), k=st.integers(3, 40))
def test_hunt_certified_cells_are_final(seed, k):
    # random local subsets of random sites: every cell the test certifies equals the whole diagram's cell
    rng = np.random.default_rng(seed)
    pts = np.round(rng.random((k + 20, 2)), int(rng.integers(1, 6)))
    box = (-0.5, -0.5, 1.5, 1.5)
    cx, cy, half = rng.random(), rng.random(), 0.1 + 0.5 * rng.random()
    region = (cx - half, cy - half, cx + half, cy + half)
    seen = np.flatnonzero(in_region(pts[:, 0], pts[:, 1], region))
    if len(seen) == 0:
        return
    cells = build_tile(pts[seen], seen.astype(np.int64), np.ones(len(seen), bool), region, box)
    full = tvoronoi.voronoi(pts, bbox=box, threads=1)
    for i, ring in cells.rings():
        assert np.array_equal(ring, full.cell_polygon(i))
    if len(cells.pending) == 0:
        return
    # the reach of each group of pending cells, grown by a margin, is enough: a second build certifies them
    groups = group_reaches(cells.pending, cells.reaches, 1e-6)
    assert sorted(np.concatenate([g for g, _ in groups]).tolist()) == sorted(cells.pending.tolist())
    for group, reach in groups:
        region = grown(reach, 1e-6)
        seen = np.flatnonzero(in_region(pts[:, 0], pts[:, 1], region))
        again = build_tile(pts[seen], seen.astype(np.int64), np.isin(seen, group), region, box)
        assert len(again.pending) == 0 and sorted(again.ids.tolist()) == sorted(group.tolist())
        for i, ring in again.rings():
            assert np.array_equal(ring, full.cell_polygon(i))


def test_certify_cells_agrees_with_the_test_of_gathered_rings():
    # a tile's diagram with halo sites not wanted; certified where the diagram holds the rings, the
    # verdict is the test of the wanted rings gathered, the kept cells are the whole diagram's and the
    # reaches those of the failed rings
    pts = generate("gaussian", 6_000, seed=21)
    rects = kd_rects(pts, 4)
    region = grown(rects[1], 0.05)
    seen = np.flatnonzero(in_region(pts[:, 0], pts[:, 1], region))
    want = tile_of(pts[seen, 0], pts[seen, 1], rects) == 1
    box = (-6.0, -6.0, 6.0, 6.0)
    d = tvoronoi.voronoi(pts[seen], bbox=box, threads=1)
    verdict = certify_cells(d, pts[seen], want, region)
    rows = np.flatnonzero(want)
    rings = [d.cell_polygon(i) for i in rows]
    offsets = np.concatenate([[0], np.cumsum([len(r) for r in rings])])
    ok = certified(np.concatenate(rings), offsets, pts[seen][rows], region)
    assert 0 < len(verdict.failed) < len(rows)
    assert np.array_equal(verdict.kept, rows[ok]) and np.array_equal(verdict.failed, rows[~ok])
    for i, reach in zip(verdict.failed, verdict.reaches):
        ring = d.cell_polygon(i)
        assert tuple(reach) == flower_box(ring, np.repeat(pts[seen][i][None], len(ring), axis=0))
    full = tvoronoi.voronoi(pts, bbox=box, threads=1)
    for i in verdict.kept:
        assert np.array_equal(d.cell_polygon(i), full.cell_polygon(seen[i]))
    # a region holding every site certifies every wanted cell without a test
    assert np.array_equal(certify_cells(d, pts[seen], want, region, everything=True).kept, rows)


def test_group_reaches_keeps_far_cells_apart_and_joins_overlapping_ones():
    pending = np.array([7, 3, 9])
    reaches = np.array([[0.0, 0.0, 1.0, 1.0], [0.9, 0.9, 2.0, 2.0], [10.0, 10.0, 11.0, 11.0]])
    groups = group_reaches(pending, reaches, 0.05)
    assert sorted((g.tolist(), box) for g, box in groups) == [
        ([3, 7], (0.0, 0.0, 2.0, 2.0)),
        ([9], (10.0, 10.0, 11.0, 11.0)),
    ]
    # a margin that bridges the gap joins all three
    assert [g.tolist() for g, _ in group_reaches(pending, reaches, 5.0)] == [[3, 7, 9]]


def test_certification_refuses_a_bound_that_overflows():
    # near the top of the doubles, room(s) and twice the farthest distance both overflow: inf >= inf must
    # not certify. Here an exact check finds a ring point nearer a side (5e307) than its site (1.5e308)
    ring = np.array([[-5e307, 0.0], [1e308, 1.0]])
    site = np.array([[1e308, 0.0]])
    assert not certified(ring, np.array([0, 2]), site, (-1e308, -math.inf, math.inf, math.inf))[0]
    # end to end: a site the region does not hold cuts the cell, which must stay pending
    pts = np.array([[1e308, 0.0], [-9e307, 0.0], [-1.01e308, 1e308]])
    box = (-1.7e308, -1.5e308, 1.7e308, 1.5e308)
    cells = build_tile(
        pts[[0, 1]], np.array([0, 1]), np.array([True, False]), (-1e308, -math.inf, math.inf, math.inf), box
    )
    assert cells.ids.size == 0 and cells.pending.tolist() == [0]
    full = tvoronoi.voronoi(pts, bbox=box)
    assert len(full.cell_polygon(0)) == 5
    # a side that is not a number certifies nothing
    assert not certified(np.array([[0.1, 0.0]]), np.array([0, 1]), np.array([[0.0, 0.0]]), (-5.0, math.nan, 5.0, 5.0))[
        0
    ]


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), k=st.integers(1, 6))
def test_hunt_certification_near_the_largest_doubles(seed, k):
    # sites and ring points near +-1.7e308, sides near -+1e308: distances and rooms overflow; whatever the
    # test certifies holds exactly
    rng = np.random.default_rng(seed)
    # the site near one end of the doubles, its finite sides (one or two) near the other, so that its
    # room overflows; ring points up to the whole range away, so that twice the farthest overflows too
    site = rng.choice([-1.0, 1.0], 2) * rng.uniform(0.5, 1.7, 2) * 1e308
    ring = rng.uniform(-1.0, 1.0, (k, 2)) * 1.7e308
    near = -np.sign(site) * rng.uniform(0.2, 1.7, 2) * 1e308
    sides = [-math.inf, -math.inf, math.inf, math.inf]
    for axis in range(2):
        if rng.random() < 0.7:
            sides[axis if near[axis] < 0 else axis + 2] = float(near[axis])
    region = tuple(sides)
    if certified(ring, np.array([0, k]), site[None], region)[0]:
        assert _exact_room_holds(ring, site, region, float(np.max(np.abs(ring))))
