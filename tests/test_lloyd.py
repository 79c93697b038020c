"""Lloyd relaxation: centroids against shapely, the energy going down, clip regions (no site lost), batch --lloyd."""

from __future__ import annotations

import json

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import tvoronoi
from test_clip_region import check_tiles, star, write_region
from tvoronoi import cli
from tvoronoi.generators import coastline
from tvoronoi.relax import INWARD_PULL, cell_centroids, lloyd_targets

L_SHAPE = shapely.Polygon([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)], [[(0.2, 0.2), (0.6, 0.2), (0.4, 0.6)]])


def reference_step(pts, bbox=None, clip=None) -> np.ndarray:
    """One Lloyd step the slow, obvious way: each cell's shapely centroid, one by one."""
    d = tvoronoi.voronoi(pts, bbox=bbox, clip=clip)
    out = pts.copy()
    for i, cell in enumerate(d.to_shapely()):
        if cell is not None:
            out[i] = cell.centroid.coords[0]
    return out


def energy(pts, bbox) -> float:
    """The CVT energy: the sum over cells of the integral of |p - site|^2 (polygon second moments)."""
    d = tvoronoi.voronoi(pts, bbox=bbox)
    total = 0.0
    for i, ring in d.cells():
        if len(ring) < 3:
            continue
        x, y = (ring - pts[i]).T
        x1, y1 = np.roll(x, -1), np.roll(y, -1)
        cross = x * y1 - x1 * y
        total += float(np.sum(cross * (x * x + x * x1 + x1 * x1 + y * y + y * y1 + y1 * y1)) / 12)
    return total


def test_centroids_match_shapely(rng):
    pts = rng.uniform(-3, 5, (500, 2)) + 1e6  # far from the origin: the shoelace runs around each site
    pts[:4] = pts[4:8]
    d = tvoronoi.voronoi(pts)
    centroids, has_cell = cell_centroids(d)
    cells = d.to_shapely()
    assert np.array_equal(has_cell, cells != None)  # noqa: E711
    want = shapely.get_coordinates(shapely.centroid(cells[has_cell]))
    np.testing.assert_allclose(centroids[has_cell], want, rtol=0, atol=1e-9)
    assert np.isnan(centroids[~has_cell]).all()


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_steps_match_the_reference_and_lower_the_energy(rng, engine):
    pts = rng.uniform(0, 1, (300, 2)) ** 2  # crowded in a corner
    box = (0, 0, 1, 1)
    energies, moves = [energy(pts, box)], []
    for _ in range(5):
        moved = tvoronoi.lloyd(pts, 1, bbox=box, engine=engine)
        np.testing.assert_allclose(moved, reference_step(pts, bbox=box), rtol=0, atol=1e-12)
        moves.append(np.abs(moved - pts).sum())
        pts = moved
        energies.append(energy(pts, box))
    assert all(b < a for a, b in zip(energies, energies[1:]))
    assert moves[-1] < moves[0]


def test_iterations_compose(rng):
    pts = rng.uniform(0, 1, (200, 2))
    box = (-0.1, -0.1, 1.1, 1.1)
    three = tvoronoi.lloyd(pts, 3, bbox=box)
    np.testing.assert_array_equal(three, tvoronoi.lloyd(tvoronoi.lloyd(pts, 2, bbox=box), 1, bbox=box))
    # the default box is that of the first step, kept for every step
    np.testing.assert_array_equal(tvoronoi.lloyd(pts, 3), tvoronoi.lloyd(pts, 3, bbox=tvoronoi.voronoi(pts).bbox))
    np.testing.assert_array_equal(tvoronoi.lloyd(pts, 0), pts)


def test_clipped_steps_match_the_reference(rng):
    pts = rng.uniform(-0.5, 2.5, (400, 2))
    pts[:3] = pts[3:6]
    moved = tvoronoi.lloyd(pts, 1, clip=L_SHAPE)
    np.testing.assert_allclose(moved, reference_step(pts, clip=L_SHAPE), rtol=0, atol=1e-12)
    inside = shapely.intersects_xy(L_SHAPE, pts[:, 0], pts[:, 1])
    # sites without a cell stay put: outside the region, and the later copies of a repeated point
    assert np.array_equal(moved[~inside], pts[~inside])
    assert np.array_equal(moved[3:6], pts[3:6])  # rows 0-2 hold the cells of the repeated places
    # each moved site is the centroid of a piece of the region, so it lies in the region's hull
    assert shapely.covers(L_SHAPE.convex_hull, shapely.points(moved[inside])).all()
    more = tvoronoi.lloyd(moved, 4, clip=L_SHAPE)
    steps = [
        np.abs(b - a).sum()
        for a, b in zip(
            [moved, *[tvoronoi.lloyd(moved, k, clip=L_SHAPE) for k in (1, 2, 3)]],
            [tvoronoi.lloyd(moved, k, clip=L_SHAPE) for k in (1, 2, 3, 4)],
        )
    ]
    assert steps[-1] < steps[0]
    assert np.isfinite(more).all()


@pytest.mark.parametrize("iterations, message", [(-1, "0 or more"), (1.5, "whole number")])
def test_bad_iterations(iterations, message):
    with pytest.raises(tvoronoi.TvoronoiError, match=message):
        tvoronoi.lloyd([[0, 0], [1, 1]], iterations)


def test_batch_lloyd(tmp_path, capsys, rng):
    pts = rng.uniform(0, 1, (100, 2))
    src = tmp_path / "pts.csv"
    src.write_text("x,y\n" + "".join(f"{x!r},{y!r}\n" for x, y in pts.tolist()))
    out = tmp_path / "cells.geojson"
    assert cli.main(["batch", str(src), "-o", str(out), "--lloyd", "3", "--bbox", "0,0,1,1"]) == 0
    want = tvoronoi.voronoi(tvoronoi.lloyd(pts, 3, bbox=(0, 0, 1, 1)), bbox=(0, 0, 1, 1)).to_shapely()
    got = [shapely.geometry.shape(f["geometry"]) for f in json.loads(out.read_text())["features"]]
    assert all(g.equals_exact(w, 0) for g, w in zip(got, want))
    assert cli.main(["batch", str(src), "-o", "-", "--lloyd", "-2"]) == 2
    assert "--lloyd -2" in capsys.readouterr().err


# --- clip regions whose cells' centroids can fall outside: a site inside stays inside

# a C (its notch opens to the right) with a slot cut into its back: the notch and the slot take centroids
C_WITH_HOLE = shapely.Polygon(
    [(0, 0), (10, 0), (10, 3), (3, 3), (3, 7), (10, 7), (10, 10), (0, 10)], [[(1, 1), (2, 1), (2, 9), (1, 9)]]
)
BOX_WITH_HOLE = shapely.Polygon([(0, 0), (10, 0), (10, 10), (0, 10)], [[(3, 3), (7, 3), (7, 7), (3, 7)]])
# a ring of land around a lake with an island in it, and an islet off the coast
ISLANDS = shapely.MultiPolygon(
    [
        shapely.Polygon([(0, 0), (10, 0), (10, 10), (0, 10)], [[(2, 2), (8, 2), (8, 8), (2, 8)]]),
        shapely.box(4, 4, 6, 6),
        shapely.box(12, 0, 12.5, 0.5),
    ]
)
REGIONS = {
    "C-with-hole": C_WITH_HOLE,
    "box-with-hole": BOX_WITH_HOLE,
    "star": star(),
    "star-with-hole": star(40, 0.3).difference(shapely.Point(0, 0).buffer(0.2)),
    "islands": ISLANDS,
    "coastline": coastline(400, spikes=30, lakes=3, islands=4),
}


def relax_and_check(pts: np.ndarray, region, steps: int, engine: str = "incremental") -> np.ndarray:
    """Lloyd steps one by one; after each, the sites inside are those inside at the start, each with a
    non-empty cell of its own, the sites outside have not moved, and the cells tile the region."""
    inside = shapely.intersects_xy(region, pts[:, 0], pts[:, 1])
    first = pts
    for _ in range(steps):
        moved = tvoronoi.lloyd(pts, 1, clip=region, engine=engine)
        d = tvoronoi.voronoi(moved, clip=region, engine=engine)
        assert np.array_equal(d.inside, inside), "a site left the region (or entered it)"
        assert np.array_equal(moved[~inside], first[~inside]), "a site outside the region moved"
        # no site inside moved onto another: each has a cell of its own, of positive area
        assert (d.site_of == np.arange(d.n_sites))[inside].all()
        assert (shapely.area(d.to_shapely()[inside]) > 0).all()
        check_tiles(d, region)
        pts = moved
    np.testing.assert_array_equal(pts, tvoronoi.lloyd(first, steps, clip=region, engine=engine))
    return pts


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("region", list(REGIONS.values()), ids=list(REGIONS))
def test_clipped_lloyd_keeps_every_site_inside(region, seed):
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = region.bounds
    grow = 0.3 * max(xmax - xmin, ymax - ymin)  # many sites outside too: they stay where they are
    n = (20, 300, 1000)[seed]
    pts = rng.uniform([xmin - grow, ymin - grow], [xmax + grow, ymax + grow], (n, 2))
    pts[:3] = pts[3:6]  # repeated points: their later copies get cells of their own from the second step
    pts[-1] = region.representative_point().coords[0]  # one site inside at least
    relax_and_check(pts, region, 6)


def test_clipped_lloyd_keeps_every_site_inside_fortune(rng):
    relax_and_check(rng.uniform(-2, 12, (300, 2)), C_WITH_HOLE, 6, engine="fortune")


def hundredths(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Multiples of 0.01 from lo to hi (no coordinate 1e-255 next to 1, which the clip refuses)."""
    return st.integers(round(lo * 100), round(hi * 100)).map(lambda i: i / 100)


@st.composite
def concave_regions(draw) -> shapely.Geometry:
    """A star-shaped polygon of random radii (concave where they dip), perhaps with a hole near its
    centre (a notch where it reaches the outline), a notch cut from its side, an island off its coast."""
    k = draw(st.integers(3, 14))
    radii = np.array(draw(st.lists(hundredths(0.15, 1.0), min_size=k, max_size=k)))
    t = np.arange(k) * 2 * np.pi / k
    region = shapely.Polygon(np.c_[radii * np.cos(t), radii * np.sin(t)])
    if draw(st.booleans()):
        x, y = draw(hundredths(-0.2, 0.2)), draw(hundredths(-0.2, 0.2))
        region = region.difference(shapely.Point(x, y).buffer(draw(hundredths(0.02, 0.3)), quad_segs=4))
    if draw(st.booleans()):
        y0 = draw(hundredths(-0.6, 0.5))
        region = region.difference(shapely.box(draw(hundredths(-0.5, 0.8)), y0, 2, y0 + draw(hundredths(0.05, 0.5))))
    if draw(st.booleans()):
        x0, y0 = draw(hundredths(1.05, 1.5)), draw(hundredths(-1, 1))
        region = region.union(shapely.box(x0, y0, x0 + draw(hundredths(0.01, 0.3)), y0 + draw(hundredths(0.01, 0.3))))
    return region


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(concave_regions(), st.integers(2, 120), st.integers(0, 2**32 - 1))
def test_clipped_lloyd_on_random_regions(region, n, seed):
    assume(region.area > 1e-3)  # the hole or the notch took (nearly) all of it
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = region.bounds
    pts = rng.uniform([xmin - 0.2, ymin - 0.2], [xmax + 0.2, ymax + 0.2], (n, 2))
    pts[0] = region.representative_point().coords[0]  # one site inside at least
    relax_and_check(pts, region, 4)


def test_audit_box_with_hole_keeps_the_hole_empty():
    """The audit's case: 2,000 sites in a box with a hole; 5 steps left one in the hole."""
    pts = np.random.default_rng(5).uniform(0, 10, (2000, 2))
    moved = tvoronoi.lloyd(pts, 5, clip=BOX_WITH_HOLE)
    hole = shapely.box(3, 3, 7, 7)
    inside = shapely.intersects_xy(BOX_WITH_HOLE, pts[:, 0], pts[:, 1])
    assert not shapely.contains_xy(hole, moved[inside, 0], moved[inside, 1]).any()
    assert np.array_equal(shapely.intersects_xy(BOX_WITH_HOLE, moved[:, 0], moved[:, 1]), inside)


def test_centroid_outside_goes_to_the_nearest_point_just_inside():
    # one site: its cell is the whole region, two boxes whose centroid (2.62, 0.5) lies in the gap,
    # nearer the right box: the site goes to that box's nearest point (3, 0.5), pulled just inside
    region = shapely.MultiPolygon([shapely.box(0, 0, 2, 1), shapely.box(3, 0, 5.2, 1)])
    d = tvoronoi.voronoi([[0.5, 0.5]], clip=region)
    centroid = cell_centroids(d)[0][0]
    assert 2 < centroid[0] < 3
    target = lloyd_targets(d)[0][0]
    assert shapely.contains_xy(shapely.box(3, 0, 5.2, 1), *target)
    assert 0 < target[0] - 3 <= INWARD_PULL * 2.2 and target[1] == 0.5
    assert tvoronoi.lloyd([[0.5, 0.5]], 1, clip=region).tolist() == [target.tolist()]


def test_centroid_off_an_acute_corner_is_pulled_toward_the_inner_point():
    """The centroid lies beyond the tip of a 20-degree wedge, 45 degrees off its axis: moving away from
    the centroid would leave the wedge, so the tip is pulled toward the wedge's point on surface."""
    t = float(np.tan(np.radians(10)))
    wedge = shapely.Polygon([(0, 0), (1, -t), (1, t)])  # its tip at the origin, pointing to -x
    want = np.array([-0.3, -0.3])
    # an annulus around the wedge, placed so that the region's centroid is `want`
    ring = shapely.Point(0, 0).buffer(4, quad_segs=64).difference(shapely.Point(0, 0).buffer(3, quad_segs=64))
    shift = want - wedge.area * (np.array(wedge.centroid.coords[0]) - want) / ring.area
    region = shapely.union_all([wedge, shapely.affinity.translate(ring, *shift)])
    d = tvoronoi.voronoi([[0.5, 0.0]], clip=region)
    np.testing.assert_allclose(cell_centroids(d)[0][0], want, atol=1e-12)
    target = lloyd_targets(d)[0][0]
    assert shapely.contains_xy(wedge, *target)
    assert 0 < np.hypot(*target) <= INWARD_PULL
    away = INWARD_PULL * (-want) / np.hypot(*want)  # the first candidate: outside the wedge
    assert not shapely.contains_xy(wedge, *away)


def test_batch_lloyd_keeps_every_site_in_a_c_shape(tmp_path, capsys):
    """The audit's CLI case: sites in a C with a hole were lost one by one until --lloyd 10 failed with
    "none of the 200 points lies inside the clip region"."""
    pts = np.random.default_rng(39).uniform(-15, 25, (200, 2))
    inside = shapely.intersects_xy(C_WITH_HOLE, pts[:, 0], pts[:, 1])
    assert inside.sum() == 3
    src = tmp_path / "pts.csv"
    src.write_text("x,y\n" + "".join(f"{x!r},{y!r}\n" for x, y in pts.tolist()))
    region = write_region(tmp_path / "c.geojson", [C_WITH_HOLE])
    out = tmp_path / "cells.geojson"
    assert cli.main(["batch", str(src), "-o", str(out), "--clip", region, "--lloyd", "10"]) == 0
    assert "197 sites lie outside the --clip region" in capsys.readouterr().err
    got = [f["geometry"] for f in json.loads(out.read_text())["features"]]
    assert [g is not None for g in got] == inside.tolist()
    cells = [shapely.geometry.shape(g) for g in got if g is not None]
    assert shapely.coverage_is_valid(np.array(cells))
    assert shapely.union_all(cells).symmetric_difference(C_WITH_HOLE).area <= 1e-12 * C_WITH_HOLE.area
