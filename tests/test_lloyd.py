"""Lloyd relaxation: centroids against shapely, the energy going down, clip regions, the batch --lloyd option."""

from __future__ import annotations

import json

import numpy as np
import pytest
import shapely

import tvoronoi
from tvoronoi import cli
from tvoronoi.relax import cell_centroids

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
