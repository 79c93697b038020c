"""Adversarial families of near-degenerate input, seeded and sized, for hunting engine bugs.

Each generator returns a ``Case``: the points, the user box (None for the default box) and a note.
``FAMILIES`` maps a family name to a generator of that family at its hunt size; ``make(name, seed)``
builds one. Every family is deterministic for a given seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from typing import Callable

import numpy as np

SEED = 20261122


@dataclass(frozen=True)
class Case:
    """One input: points (n, 2) float64 and an optional box (xmin, ymin, xmax, ymax)."""

    points: np.ndarray
    bbox: tuple | None = None
    note: str = ""


def _pts(xy) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(xy, np.float64).reshape(-1, 2))


# ---------------------------------------------------------------------------------------------
# points on one line


def near_collinear(n: int = 100, *, intercept: float = 1.0, slope: float = 2.0, seed: int = SEED) -> Case:
    """n points on y = intercept + slope * x, x uniform in [0, 1), y rounded to a double.

    Rounding y moves each point off the line by up to half an ulp: almost every triple is a
    near-zero orientation, and the sign is decided by the last bit.
    """
    rng = np.random.default_rng(seed)
    x = rng.uniform(0.0, 1.0, n)
    return Case(_pts(np.column_stack([x, intercept + slope * x])), note=f"y = {intercept} + {slope} x, rounded")


def near_collinear_decimal(n: int = 100, *, slope: float = 0.1, seed: int = SEED) -> Case:
    """x on a decimal grid (0.01 steps, themselves rounded), y = slope * x rounded: the line is never exact."""
    rng = np.random.default_rng(seed)
    k = rng.permutation(np.arange(1, 4 * n))[:n]
    x = k * 0.01
    return Case(_pts(np.column_stack([x, 0.3 + slope * x])), note="decimal x, rounded y")


def collinear_exact(n: int = 100, *, slope: int = 2, seed: int = SEED) -> Case:
    """n distinct integer points exactly on y = 1 + slope * x, in random order."""
    rng = np.random.default_rng(seed)
    x = rng.permutation(np.arange(-n // 2, n - n // 2)).astype(float)
    return Case(_pts(np.column_stack([x, 1.0 + slope * x])), note="exactly collinear")


def collinear_dyadic(n: int = 100, *, seed: int = SEED) -> Case:
    """Exactly collinear with dyadic (exact) fractional steps, plus repeats of some of them."""
    rng = np.random.default_rng(seed)
    x = rng.permutation(n) / 64.0
    pts = np.column_stack([x, 0.75 - 3.0 * x])
    return Case(_pts(np.concatenate([pts, pts[: n // 10]])), note="exactly collinear, dyadic, with repeats")


def collinear_plus_one(n: int = 100, *, seed: int = SEED) -> Case:
    """Exactly collinear integer points and one site just off the line (one ulp above the middle one)."""
    base = collinear_exact(n, seed=seed).points
    mid = base[np.argsort(base[:, 0])[n // 2]]
    off = (mid[0], np.nextafter(mid[1], np.inf))
    return Case(_pts(np.concatenate([base, [off]])), note="collinear + one site one ulp off")


# ---------------------------------------------------------------------------------------------
# lattices


def square_grid(side: int = 70, *, noise: float = 1e-17, seed: int = SEED) -> Case:
    """A side x side integer grid plus gaussian noise of this size (1e-17 only moves the zeros)."""
    rng = np.random.default_rng(seed)
    g = np.array([(i, j) for i in range(side) for j in range(side)], float)
    if noise:
        g = g + rng.normal(0.0, noise, g.shape)
    return Case(_pts(g[rng.permutation(len(g))]), note=f"{side}x{side} grid, noise {noise:g}")


def triangular_lattice(side: int = 40, *, noise: float = 0.0, seed: int = SEED) -> Case:
    """A triangular lattice (rows offset by 1/2, height sqrt(3)/2 rounded): near-cocircular hexagons."""
    rng = np.random.default_rng(seed)
    h = math.sqrt(3.0) / 2.0
    g = np.array([(i + 0.5 * (j % 2), j * h) for j in range(side) for i in range(side)], float)
    if noise:
        g = g + rng.normal(0.0, noise, g.shape)
    return Case(_pts(g[rng.permutation(len(g))]), note=f"triangular lattice, noise {noise:g}")


def rotated_grid(side: int = 40, *, degrees: float = 30.0, noise: float = 0.0, seed: int = SEED) -> Case:
    """A square grid rotated by an angle, coordinates rounded: every unit square is near-cocircular."""
    rng = np.random.default_rng(seed)
    t = math.radians(degrees)
    c, s = math.cos(t), math.sin(t)
    g = np.array([(i, j) for i in range(side) for j in range(side)], float)
    g = np.column_stack([c * g[:, 0] - s * g[:, 1], s * g[:, 0] + c * g[:, 1]])
    if noise:
        g = g + rng.normal(0.0, noise, g.shape)
    return Case(_pts(g[rng.permutation(len(g))]), note=f"grid rotated {degrees} deg, noise {noise:g}")


def pythagorean_grid(side: int = 30, *, seed: int = SEED) -> Case:
    """A grid rotated by atan(3/4) with exact integer coordinates: exactly cocircular squares, rotated."""
    rng = np.random.default_rng(seed)
    g = np.array([(4 * i - 3 * j, 3 * i + 4 * j) for i in range(side) for j in range(side)], float)
    return Case(_pts(g[rng.permutation(len(g))]), note="integer grid rotated by atan(3/4)")


def hexagonal_rotated(side: int = 30, *, degrees: float = 17.0, noise: float = 0.0, seed: int = SEED) -> Case:
    """A triangular (hexagonal) lattice rotated by an angle and rounded: sextuples near-cocircular."""
    rng = np.random.default_rng(seed)
    g = np.array([(i + 0.5 * (j % 2), j * math.sqrt(3) / 2) for i in range(side) for j in range(side)], float)
    t = math.radians(degrees)
    g = np.column_stack([math.cos(t) * g[:, 0] - math.sin(t) * g[:, 1], math.sin(t) * g[:, 0] + math.cos(t) * g[:, 1]])
    if noise:
        g = g + rng.normal(0.0, noise, g.shape)
    return Case(_pts(g[rng.permutation(len(g))]), note=f"hexagonal lattice rotated {degrees} deg, noise {noise:g}")


def sheared_lattice(side: int = 30, *, shear: float = 1.0 / 3.0, seed: int = SEED) -> Case:
    """A lattice (i + shear * j, j / 7) in decimal-unfriendly steps: rows of exactly equal y, rounded x."""
    rng = np.random.default_rng(seed)
    g = np.array([(i + shear * j, j / 7.0) for i in range(side) for j in range(side)], float)
    return Case(_pts(g[rng.permutation(len(g))]), note=f"lattice sheared by {shear:.4g}")


# ---------------------------------------------------------------------------------------------
# curves


def spiral(n: int = 1500, *, turns: float = 6.0, seed: int = SEED) -> Case:
    """An Archimedean spiral sampled evenly in angle, rounded: long chains of near-cocircular neighbours."""
    t = np.linspace(0.0, 2.0 * math.pi * turns, n)
    return Case(_pts(np.column_stack([t * np.cos(t), t * np.sin(t)])), note=f"spiral, {turns} turns")


def parabola_decimal(n: int = 1000, *, seed: int = SEED) -> Case:
    """Points on y = x^2 at x given to 3 decimals, plus the same with y rounded to 3 decimals."""
    x = np.round(np.linspace(-1.0, 1.0, n // 2), 3)
    a = np.column_stack([x, x * x])
    b = np.column_stack([x + 0.0005, np.round((x + 0.0005) ** 2, 3)])
    return Case(_pts(np.concatenate([a, b])), note="parabola, decimal abscissae")


def sine_wave(n: int = 2000, *, seed: int = SEED) -> Case:
    """A densely sampled sine wave (step 1e-3): nearly collinear triples along its flat stretches."""
    x = np.arange(n) * 1e-3
    return Case(_pts(np.column_stack([x, np.sin(20.0 * x)])), note="sine wave, step 1e-3")


def sunflower(n: int = 1500, *, seed: int = SEED) -> Case:
    """A sunflower (Vogel's spiral: golden-angle turns, radius sqrt(k)), rounded: near-regular rings of
    neighbours at every radius, each cell close to a hexagon."""
    k = np.arange(n, dtype=np.float64)
    t = k * math.pi * (3.0 - math.sqrt(5.0))
    r = np.sqrt(k)
    return Case(_pts(np.column_stack([r * np.cos(t), r * np.sin(t)])), note="sunflower, golden angle")


def pencil_of_lines(lines: int = 24, per_line: int = 40, *, decimals: int | None = None, seed: int = SEED) -> Case:
    """Sites on rays from one centre at even angles, at unit steps of radius (rounded, or to some
    decimals), with the centre: collinear runs meeting at one point, and near-cocircular rings."""
    t = np.arange(lines) * (2.0 * math.pi / lines)
    r = np.arange(1, per_line + 1, dtype=np.float64)
    x = np.outer(r, np.cos(t)).ravel()
    y = np.outer(r, np.sin(t)).ravel()
    if decimals is not None:
        x, y = np.round(x, decimals), np.round(y, decimals)
    return Case(_pts(np.concatenate([[[0.0, 0.0]], np.column_stack([x, y])])), note=f"{lines} rays from one point")


def rectangle_perimeter(side: int = 300, *, height: int = 170, step: float = 1.0, seed: int = SEED) -> Case:
    """Sites along the four sides of a rectangle at even steps (integers, or tenths rounded): every
    four sites symmetric across both axes are exactly (or nearly) cocircular, far apart across it."""
    xs = np.arange(side + 1) * step
    ys = np.arange(1, height) * step
    w, h = side * step, height * step
    pts = np.concatenate(
        [
            np.column_stack([xs, np.zeros_like(xs)]),
            np.column_stack([xs, np.full_like(xs, h)]),
            np.column_stack([np.zeros_like(ys), ys]),
            np.column_stack([np.full_like(ys, w), ys]),
        ]
    )
    rng = np.random.default_rng(seed)
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"perimeter of a {side} x {height} rectangle, step {step}")


def overlaid_grids(*, a: int = 3, b: int = 5, size: int = 120, seed: int = SEED) -> Case:
    """Two integer grids of steps a and b over one square (their common points once): exactly cocircular
    groups of many sizes where the grids meet, and cells of both sizes side by side."""
    g1 = np.arange(0, size + 1, a)
    g2 = np.arange(0, size + 1, b)
    p1 = np.stack(np.meshgrid(g1, g1), -1).reshape(-1, 2)
    p2 = np.stack(np.meshgrid(g2, g2), -1).reshape(-1, 2)
    pts = np.unique(np.concatenate([p1, p2]), axis=0).astype(np.float64)
    rng = np.random.default_rng(seed)
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"grids of steps {a} and {b}")


def grid_with_holes(
    side: int = 40, *, keep: float = 0.65, degrees: float = 0.0, decimals: int | None = None, seed: int = SEED
) -> Case:
    """A lattice with a random part of its points missing (raster centres with gaps in the data), turned
    and rounded if asked: cocircular unit squares next to empty ones, and cells of many shapes."""
    rng = np.random.default_rng(seed)
    g = np.array([(i, j) for i in range(side) for j in range(side)], float)
    g = g[rng.random(len(g)) < keep]
    if degrees:
        t = math.radians(degrees)
        g = np.column_stack(
            [math.cos(t) * g[:, 0] - math.sin(t) * g[:, 1], math.sin(t) * g[:, 0] + math.cos(t) * g[:, 1]]
        )
    if decimals is not None:
        g = np.round(g, decimals)
    return Case(_pts(g[rng.permutation(len(g))]), note=f"lattice with holes, turned {degrees} deg")


def mirrored_pairs(n: int = 600, *, decimals: int | None = 3, seed: int = SEED) -> Case:
    """Random points (rounded) with their mirror images across the diagonal (coordinates swapped,
    exact) and across the line x = 0.3 (0.6 - x, rounded): many bisectors on one line, Voronoi edges
    along it, and sites on it."""
    rng = np.random.default_rng(seed)
    p = rng.random((n, 2))
    if decimals is not None:
        p = np.round(p, decimals)
    swapped = p[:, ::-1]
    across = np.column_stack([0.6 - p[:, 0], p[:, 1]])
    pts = np.unique(np.concatenate([p, swapped, across]), axis=0)
    return Case(_pts(pts[rng.permutation(len(pts))]), note="points mirrored across y = x and x = 0.3")


def huge_circle_arc(n: int = 800, *, radius: float = 1e6, half_width: float = 50.0, seed: int = SEED) -> Case:
    """Points on a short arc of a huge circle (centre far below), rounded: nearly collinear and nearly
    cocircular at once, their Voronoi vertices far outside the box, the edges between them nearly
    parallel."""
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(-half_width, half_width, n))
    y = np.sqrt(radius * radius - x * x) - radius
    return Case(_pts(np.column_stack([x, y])[rng.permutation(n)]), note=f"arc of a circle of radius {radius:g}")


def refined_cells(levels: int = 4, *, size: int = 8, seed: int = SEED) -> Case:
    """The centres of a quadtree's leaves (adaptive refinement): a square of size x size unit cells,
    random ones split in four, level after level (dyadic, exact): cells of sizes 1 to 2^-levels side by
    side, with cocircular groups of many sizes where they meet."""
    rng = np.random.default_rng(seed)
    leaves = [(float(i), float(j), 1.0) for i in range(size) for j in range(size)]
    for _ in range(levels):
        nxt = []
        for x, y, w in leaves:
            if rng.random() < 0.35:
                h = w / 2.0
                nxt += [(x, y, h), (x + h, y, h), (x, y + h, h), (x + h, y + h, h)]
            else:
                nxt.append((x, y, w))
        leaves = nxt
    pts = np.array([(x + w / 2.0, y + w / 2.0) for x, y, w in leaves])
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"quadtree leaf centres, {levels} levels")


def ellipse_rounded(n: int = 800, *, seed: int = SEED) -> Case:
    """Points on a thin ellipse (axes 1 and 1e-4) and its two foci: sites on both sides very close."""
    rng = np.random.default_rng(seed)
    t = rng.uniform(0.0, 2.0 * math.pi, n)
    pts = np.column_stack([np.cos(t), 1e-4 * np.sin(t)])
    f = math.sqrt(1.0 - 1e-8)
    return Case(_pts(np.concatenate([pts, [(-f, 0.0), (f, 0.0)]])), note="thin ellipse and its foci")


# ---------------------------------------------------------------------------------------------
# real coordinates rounded by their instruments


def gps_degrees(n: int = 2000, *, decimals: int = 6, seed: int = SEED) -> Case:
    """Lon/lat around Paris to 6 decimals (a GPS fix, ~0.1 m): a lattice of 1e-6 on an offset of 48."""
    rng = np.random.default_rng(seed)
    pts = np.column_stack([2.35 + rng.normal(0.0, 1e-3, n), 48.85 + rng.normal(0.0, 1e-3, n)])
    return Case(_pts(np.round(pts, decimals)), note=f"lon/lat, {decimals} decimals")


def utm_millimetres(n: int = 2000, *, seed: int = SEED) -> Case:
    """UTM eastings/northings to the millimetre (500 km, 5400 km): a 1e-3 lattice on offsets of 5e6."""
    rng = np.random.default_rng(seed)
    pts = np.column_stack([500000.0 + rng.uniform(0.0, 50.0, n), 5400000.0 + rng.uniform(0.0, 50.0, n)])
    return Case(_pts(np.round(pts, 3)), note="UTM, millimetres")


def float32_sensor(n: int = 2000, *, seed: int = SEED) -> Case:
    """Readings stored as float32 then widened (a sensor or a GPU): 24-bit lattices near 1e3."""
    rng = np.random.default_rng(seed)
    pts = (1000.0 + rng.normal(0.0, 0.05, (n, 2))).astype(np.float32).astype(np.float64)
    return Case(_pts(pts), note="float32 values near 1000")


def survey_rows(rows: int = 40, per_row: int = 40, *, seed: int = SEED) -> Case:
    """A survey along rows: y to the centimetre per row, x to the centimetre with jitter; repeats kept."""
    rng = np.random.default_rng(seed)
    y = np.repeat(np.round(np.arange(rows) * 2.5 + rng.normal(0.0, 0.004, rows), 2), per_row)
    x = np.round(np.tile(np.arange(per_row) * 2.0, rows) + rng.normal(0.0, 0.01, rows * per_row), 2)
    return Case(_pts(np.column_stack([x, y])), note="survey rows, centimetres")


def raster_scan(rows: int = 50, per_row: int = 90, *, decimals: int = 3, seed: int = SEED) -> Case:
    """A raster scanner's samples near (500 m, 1000 m): rows of equal y at a fixed pitch (a tenth of
    them one unit in the last place off, line jitter below the instrument's resolution), x along each
    row at a fixed pitch with jitter rounded to the resolution, one reading in twenty repeated, the rows
    and readings listed in no order: long runs of equal and nearly equal y for the sweep's order, with
    repeated points inside them."""
    rng = np.random.default_rng(seed)
    y = np.repeat(np.round(1000.0 + np.arange(rows) * 0.25, decimals), per_row)
    off = rng.random(len(y)) < 0.1
    y[off] = np.nextafter(y[off], np.where(rng.random(int(off.sum())) < 0.5, -np.inf, np.inf))
    x = np.round(500.0 + np.tile(np.arange(per_row) * 0.1, rows) + rng.normal(0.0, 0.01, rows * per_row), decimals)
    pts = np.column_stack([x, y])
    pts = np.concatenate([pts, pts[rng.integers(0, len(pts), len(pts) // 20)]])
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"raster scan, {decimals} decimals, ulp line jitter")


def diamond_lattice(side: int = 40, *, seed: int = SEED) -> Case:
    """An integer lattice turned by 45 degrees exactly, (i + j, i - j): every cell a diamond whose circle's
    top is the site above it, so that every circle event ties a site exactly (a site comes first), the
    events of a row at one height; listed in no order."""
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(side), np.arange(side))
    g = np.column_stack([(i + j).ravel(), (i - j).ravel()]).astype(float)
    return Case(_pts(g[rng.permutation(len(g))]), note="lattice turned 45 deg exactly")


def geometric_rows(
    rows: int = 60, per_row: int = 50, *, ratio: float = 1.25, decimals: int = 3, seed: int = SEED
) -> Case:
    """Rows of sites at heights growing geometrically (1, 1.25, 1.56, ... to about 6e5), x uniform over
    the row's own height, rounded: the strips of equal height over the sites' y hold nearly every site in
    the first few, and the circles of the high rows reach across thousands of strips."""
    rng = np.random.default_rng(seed)
    h = np.round(ratio ** np.arange(rows), decimals)
    y = np.repeat(h, per_row)
    x = np.round(rng.random(rows * per_row) * y, decimals)
    return Case(_pts(np.column_stack([x, y])[rng.permutation(rows * per_row)]), note=f"geometric rows x{ratio}")


def rows_on_strip_edges(rows: int = 400, *, decimals: int = 2, seed: int = SEED) -> Case:
    """Two sites a row on rows y = 0, 1, ..., rows - 1, less the last row's second site and the first
    row's: 2 rows - 2 sites, so that Fortune's event queue cuts y into exactly rows - 1 strips of height 1
    and every row lies on a strip's edge; x rounded, with some sites straight above others (circles
    whose tops lie on the rows too)."""
    rng = np.random.default_rng(seed)
    x = np.round(rng.random((rows, 2)) * rows, decimals)
    above = np.flatnonzero(rng.random(rows - 1) < 0.3) + 1
    x[above, 0] = x[above - 1, 0]  # (a site straight above one of the row below)
    y = np.repeat(np.arange(rows, dtype=float), 2).reshape(rows, 2)
    pts = np.column_stack([x.ravel(), y.ravel()])[1:-1]
    return Case(_pts(pts[rng.permutation(len(pts))]), note="rows on the event queue's strip edges")


def ring_around_cloud(on_ring: int = 3000, inside: int = 6000, *, decimals: int = 3, seed: int = SEED) -> Case:
    """Sites on a circle of radius 1000 around a cloud inside it (radius 700), to the mm: a hull of
    thousands of sites (some rounded just inside it), so that infinite triangles lie all through a
    triangulation in either engine's order, and the dual moves the finite ones to the front by runs of
    blocks on two threads (its buffer of triangles that land before their run's start holding hundreds)."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, on_ring)
    ring = 1000 * np.column_stack([np.cos(angle), np.sin(angle)])
    r = 700 * np.sqrt(rng.random(inside))
    t = rng.uniform(0, 2 * np.pi, inside)
    cloud = np.column_stack([r * np.cos(t), r * np.sin(t)])
    pts = np.round(np.vstack([ring, cloud]), decimals)
    return Case(_pts(pts[rng.permutation(len(pts))]), note="a hull of thousands around a cloud")


def median_line_crowded(n: int = 8000, *, share: float = 0.24, seed: int = SEED) -> Case:
    """A quarter of the sites (less one percent) on the line x = 0, half of them at x = -0.0, at y to the
    mm with repeats; the rest uniform in [-1, 1]^2 to the mm: the halves' cut falls on that line (its
    median), every site on it goes right (-0.0 is not below 0.0), and the seam runs along a column of
    thousands of collinear sites, repeated ones among them."""
    rng = np.random.default_rng(seed)
    k = int(share * n)
    line = np.column_stack([np.where(rng.random(k) < 0.5, -0.0, 0.0), np.round(rng.uniform(-1, 1, k), 3)])
    rest = np.round(rng.uniform(-1, 1, (n - k, 2)), 3)
    pts = np.vstack([line, rest])
    return Case(_pts(pts[rng.permutation(n)]), note="the cut's line holding a quarter of the sites")


def gps_tracks(tracks: int = 6, steps: int = 300, *, decimals: int = 6, seed: int = SEED) -> Case:
    """GPS tracks: polylines of straight legs at random headings, a fix every ~1 m (1e-5 degrees) near
    lon -122.4 / lat 37.7, to 6 decimals: long runs of nearly collinear sites closer than the tracks are
    apart, fixes repeated where rounding joins them, legs crossing."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(tracks):
        p = np.array([-122.4, 37.7]) + rng.uniform(-2e-3, 2e-3, 2)
        left = 0
        for _ in range(steps):
            if left == 0:
                heading = rng.uniform(0.0, 2.0 * math.pi)
                left = int(rng.integers(20, 120))
            p = p + 1e-5 * np.array([math.cos(heading), math.sin(heading)]) * rng.uniform(0.8, 1.2)
            out.append(p.copy())
            left -= 1
    return Case(_pts(np.round(np.array(out), decimals)), note=f"GPS tracks, {decimals} decimals")


def contour_lines(levels: int = 12, per_level: int = 150, *, decimals: int = 2, seed: int = SEED) -> Case:
    """Points along the contour lines of a smooth surface (two hills), sampled evenly in angle and
    rounded to centimetres: nested closed curves, near-cocircular runs along each, far closer along a
    line than across."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2.0 * math.pi, per_level, endpoint=False)
    out = []
    for centre, phase in (((0.0, 0.0), 0.0), ((55.0, 10.0), 0.7)):
        for k in range(1, levels + 1):
            r = 3.0 * k * (1.0 + 0.15 * np.sin(3.0 * t + phase + 0.2 * k))
            out.append(np.column_stack([centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)]))
    pts = np.round(np.concatenate(out), decimals)
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"contour lines, {decimals} decimals")


def mercator_graticule(step: float = 5.0, *, decimals: int = 2, seed: int = SEED) -> Case:
    """A longitude/latitude graticule in Web Mercator metres (sphere of 6,378,137 m), rounded to
    centimetres: a rectilinear grid whose rows spread apart towards the poles, at magnitudes near 2e7.
    Every column shares its rounded x and every row its rounded y, so each grid cell's four sites are
    exactly cocircular, at every row spacing."""
    rng = np.random.default_rng(seed)
    radius = 6378137.0
    lon0 = rng.uniform(-step, 0.0)
    lons = np.radians(np.arange(lon0 - 180.0, 180.0, step))
    lats = np.radians(np.arange(-80.0 + rng.uniform(0.0, step), 80.0, step))
    x = np.round(radius * lons, decimals)
    y = np.round(radius * np.log(np.tan(math.pi / 4.0 + lats / 2.0)), decimals)
    gx, gy = np.meshgrid(x, y)
    return Case(_pts(np.column_stack([gx.ravel(), gy.ravel()])), note=f"Mercator graticule every {step} degrees")


def tensor_grid(side: int = 45, *, spacing: str = "log", decimals: int = 4, seed: int = SEED) -> Case:
    """The product of two irregular sets of coordinates, rounded: rows and columns spaced by a seeded
    geometric progression ("log", ratios near 1.07 and 1.11) or at sorted random places ("random",
    repeats dropped), so that every cell of the grid is a rectangle of its own shape, its four sites
    exactly cocircular (the rounding keeps rows and columns straight), with neighbouring circumcentres
    nearly equal where the spacing changes slowly."""
    rng = np.random.default_rng(seed)
    if spacing == "log":
        ratios = rng.uniform(1.05, 1.09), rng.uniform(1.09, 1.13)
        axes = [np.round(rng.uniform(0.1, 1.0) * q ** np.arange(side), decimals) for q in ratios]
    else:
        axes = [np.unique(np.round(rng.uniform(0.0, 10.0, side), decimals)) for _ in range(2)]
    gx, gy = np.meshgrid(*axes)
    return Case(_pts(np.column_stack([gx.ravel(), gy.ravel()])), note=f"{spacing} tensor grid, {decimals} decimals")


def penrose_vertices(reach: int = 7, *, decimals: int = 6, seed: int = SEED) -> Case:
    """Vertices of a Penrose rhombus tiling, from de Bruijn's pentagrid (five families of parallel lines
    at multiples of 72 degrees, seeded offsets summing to 0), rounded: a quasi-periodic set whose exact
    vertices make rings of ten cocircular sites and many cocircular quadruples, all of them broken or
    kept by the rounding according to the digits."""
    rng = np.random.default_rng(seed)
    angle = 2.0 * np.pi * np.arange(5) / 5.0
    e = np.column_stack([np.cos(angle), np.sin(angle)])
    gamma = rng.uniform(0.0, 1.0, 5)
    gamma += (0.5 - gamma.sum()) / 5.0  # (sum 0.5: a generic, non-singular pentagrid)
    found = []
    ks = np.arange(-reach, reach + 1)
    for r in range(5):
        for t in range(r + 1, 5):
            # where line k_r of family r meets line k_t of family t: x . e_j + gamma_j = k_j for j = r, t
            kr, kt = (a.ravel() for a in np.meshgrid(ks, ks))
            m = np.array([e[r], e[t]])
            x = np.linalg.solve(m, np.array([kr - gamma[r], kt - gamma[t]])).T
            k = np.ceil(x @ e.T + gamma)  # the pentagrid cell each family puts the meeting in
            # the rhombus of the meeting: its four corners, k_r and k_t each one below or at the lines
            for dr, dt in ((0, 0), (1, 0), (1, 1), (0, 1)):
                kk = k.copy()
                kk[:, r] = kr + dr
                kk[:, t] = kt + dt
                found.append(kk @ e)
    pts = np.unique(np.round(np.concatenate(found), decimals), axis=0)
    keep = np.hypot(pts[:, 0], pts[:, 1]) < 2.0 * reach  # (the patch, 2.5 reach wide, is ragged at its edge)
    return Case(_pts(pts[keep]), note=f"Penrose tiling vertices, {decimals} decimals")


def lloyd_relaxed(
    n: int = 1500, *, iterations: int = 10, samples: int = 30, decimals: int = 4, seed: int = SEED
) -> Case:
    """Sites after Lloyd's relaxation in the unit square (each moved to the centroid of its cell, the
    centroids estimated from ``samples`` random points a site, assigned by a k-d tree), rounded: a centroidal
    tessellation, nearly hexagonal inside, its sites nearly evenly spaced, so that many Voronoi vertices
    of neighbouring triples lie within the rounding of one another. Made apart from the code under test."""
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(seed)
    sites = rng.uniform(0.0, 1.0, (n, 2))
    for _ in range(iterations):
        drawn = rng.uniform(0.0, 1.0, (samples * n, 2))
        owner = cKDTree(sites).query(drawn)[1]
        counts = np.bincount(owner, minlength=n)
        sums = np.column_stack([np.bincount(owner, drawn[:, k], minlength=n) for k in range(2)])
        moved = counts > 0
        sites[moved] = sums[moved] / counts[moved, None]
    return Case(_pts(np.round(sites, decimals)), note=f"Lloyd-relaxed, {decimals} decimals")


def street_network(streets: int = 14, *, spacing_m: float = 8.0, decimals: int = 7, seed: int = SEED) -> Case:
    """A street network as a map stores it: two families of straight streets (a grid turned by a seeded
    angle, blocks of about 80 m) and two avenues across, with a node every few metres along each and a
    node at every crossing, in degrees near lon 13.4 / lat 52.5 rounded to 7 decimals (an integer of
    1e-7 degrees): long runs of nodes that are collinear before the rounding, a crossing's node repeated
    by each street through it, streets far closer along than across."""
    rng = np.random.default_rng(seed)
    metre = np.array([1.0 / (111320.0 * math.cos(math.radians(52.5))), 1.0 / 110540.0])  # degrees a metre
    theta = rng.uniform(0.0, math.pi / 2.0)
    u = np.array([math.cos(theta), math.sin(theta)])
    v = np.array([-u[1], u[0]])
    half = 40.0 * streets
    lines = [(k * 80.0 * v, u) for k in range(-streets // 2, streets // 2 + 1)]
    lines += [(k * 80.0 * u, v) for k in range(-streets // 2, streets // 2 + 1)]
    for _ in range(2):
        a = rng.uniform(0.0, math.pi)
        lines.append((rng.uniform(-half / 3, half / 3, 2), np.array([math.cos(a), math.sin(a)])))
    out = []
    for k, (p, d) in enumerate(lines):
        t = np.arange(-half, half, spacing_m * rng.uniform(0.8, 1.2))
        out.append(p + t[:, None] * d)
        for q, e in lines[k + 1 :]:
            det = d[0] * e[1] - d[1] * e[0]
            if abs(det) > 1e-9:  # the crossing, a node of both streets
                s_ = ((q[0] - p[0]) * e[1] - (q[1] - p[1]) * e[0]) / det
                if abs(s_) < half:
                    out.append(np.repeat((p + s_ * d)[None, :], 2, axis=0))  # (listed by both streets)
    metres = np.concatenate(out)
    degrees = np.array([13.4, 52.5]) + metres * metre
    pts = np.round(degrees, decimals)
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"street network, {decimals} decimals")


def time_series(n: int = 1000, *, series: int = 3, decimals: int = 2, seed: int = SEED) -> Case:
    """A scatter of time series: x a Unix time in seconds near 1.7e9 (steps of 1 to 60 s, some repeated
    stamps), y each series' random walk rounded to a few decimals, the series sampled at the same
    stamps: columns of sites on one x, a scale of 1 across the columns against 0.01 up them, and the
    large offset leaving x some 22 bits below its unit."""
    rng = np.random.default_rng(seed)
    steps = rng.integers(0, 61, n)  # (0: a repeated stamp)
    t = 1.7e9 + np.cumsum(steps).astype(np.float64)
    walks = np.cumsum(rng.normal(0.0, 0.3, (series, n)), axis=1) + rng.uniform(-5.0, 5.0, (series, 1))
    pts = np.column_stack([np.tile(t, series), np.round(walks.ravel(), decimals)])
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"time series, {decimals} decimals")


def building_footprints(blocks: int = 80, *, decimals: int = 2, turned: bool = True, seed: int = SEED) -> Case:
    """The corners of building footprints in projected metres (UTM near 389,000 / 5,819,000), rounded as
    a survey stores them: blocks of rectangles along streets of a few orientations, terraces of houses
    sharing their side walls (a shared corner listed by both houses), a courtyard cut into some. Every
    rectangle's four corners are cocircular before the rounding (exactly, for those not turned), and
    neighbouring houses' corners lie on common lines and circles."""
    rng = np.random.default_rng(seed)
    angles = [0.0] if not turned else list(rng.uniform(0.0, math.pi / 2.0, 3))
    out = []
    for _ in range(blocks):
        a = angles[rng.integers(len(angles))]
        u = np.array([math.cos(a), math.sin(a)])
        v = np.array([-u[1], u[0]])
        origin = rng.uniform(0.0, 1500.0, 2)
        x = 0.0
        depth = float(rng.integers(8, 16))
        for _ in range(int(rng.integers(1, 9))):  # a terrace: houses wall to wall
            width = float(rng.integers(5, 13)) + (0.5 if rng.random() < 0.3 else 0.0)
            corners = [(x, 0.0), (x + width, 0.0), (x + width, depth), (x, depth)]
            if rng.random() < 0.15:  # a courtyard: an inner rectangle
                corners += [
                    (x + 2.0, 2.0),
                    (x + width - 2.0, 2.0),
                    (x + width - 2.0, depth - 2.0),
                    (x + 2.0, depth - 2.0),
                ]
            out += [origin + cx * u + cy * v for cx, cy in corners]
            x += width
    pts = np.round(np.array([389000.0, 5819000.0]) + np.array(out), decimals)
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"building footprints, {decimals} decimals")


# ---------------------------------------------------------------------------------------------
# rounded random points


def rounded_uniform(n: int = 2000, *, decimals: int = 2, seed: int = SEED) -> Case:
    """Uniform points in the unit square rounded to a few decimals: repeats, rows, cocircular quads."""
    rng = np.random.default_rng(seed)
    return Case(_pts(np.round(rng.uniform(0.0, 1.0, (n, 2)), decimals)), note=f"uniform, {decimals} decimals")


def rounded_gaussian(n: int = 2000, *, decimals: int = 1, seed: int = SEED) -> Case:
    """Gaussian points rounded to a few decimals: dense repeats in the middle, a ragged hull."""
    rng = np.random.default_rng(seed)
    return Case(_pts(np.round(rng.normal(0.0, 1.0, (n, 2)), decimals)), note=f"gaussian, {decimals} decimals")


def decimal_pythagorean(n: int = 2000, *, decimals: int = 3, seed: int = SEED) -> Case:
    """Groups of five sites at decimal centres plus (3, 4), (-4, 3), (5, 0), (0, -5), (-3, -4) in the last
    decimal, rounded: cocircular in decimals, not quite in binary, so the Voronoi vertices of a group
    lie within an ulp of each other (some round to one point, some to neighbouring doubles)."""
    rng = np.random.default_rng(seed)
    q = 10.0**-decimals
    offsets = np.array([[3, 4], [-4, 3], [5, 0], [0, -5], [-3, -4]], float) * q
    centres = np.round(rng.uniform(0.0, 1.0, (n // 5, 2)), decimals)
    return Case(
        _pts(np.round((centres[:, None, :] + offsets[None]).reshape(-1, 2), decimals)),
        note=f"decimal circles of 5, {decimals} decimals",
    )


def decimal_circles(circles: int = 150, *, decimals: int = 3, seed: int = SEED) -> Case:
    """Integer points of the circles of radius 5, 13, 25 and 65 in units of the last decimal, around
    decimal centres (most of each circle's points kept): up to 12 sites on a decimal circle."""
    rng = np.random.default_rng(seed)
    q = 10.0**-decimals
    circles_at = [lattice_circle_points(r * r) for r in (5, 13, 25, 65)]
    centres = np.round(rng.uniform(0.0, 200 * q, (circles, 2)), decimals)
    parts = []
    for c in centres:
        ring = circles_at[rng.integers(0, len(circles_at))]
        parts.append(np.round(c + ring[rng.random(len(ring)) < 0.6] * q, decimals))
    return Case(_pts(np.concatenate(parts)), note=f"{circles} decimal circles, {decimals} decimals")


def sobol_net(m: int = 11, *, unit: float = 1.0, seed: int = SEED) -> Case:
    """The first 2^m points of the two-dimensional Sobol sequence (unscrambled) on the integer grid
    0 .. 2^m - 1, each axis XOR-shifted by a seeded integer (a digital shift: still a (0, m, 2)-net,
    one point in every dyadic box of area 2^m), times ``unit``: a permutation of a grid, so full of
    exactly cocircular quadruples and of collinear runs in dyadic directions; unit 0.001 rounds them."""
    from scipy.stats import qmc

    rng = np.random.default_rng(seed)
    grid = np.rint(qmc.Sobol(2, scramble=False).random_base2(m) * (1 << m)).astype(np.int64)
    grid ^= rng.integers(0, 1 << m, 2)
    return Case(_pts(grid * unit), note=f"Sobol (0, {m}, 2)-net, unit {unit}")


def halton_rounded(n: int = 3000, *, decimals: int = 3, seed: int = SEED) -> Case:
    """Halton points in bases 2 and 3 (unscrambled, from a seeded start) scaled to 100 and rounded: a
    low-discrepancy set whose thirds round in every coordinate, nearly regular everywhere."""
    from scipy.stats import qmc

    rng = np.random.default_rng(seed)
    h = qmc.Halton(2, scramble=False)
    h.fast_forward(int(rng.integers(0, 10_000)))
    return Case(_pts(np.round(100.0 * h.random(n), decimals)), note=f"Halton points, {decimals} decimals")


# ---------------------------------------------------------------------------------------------
# circles


def circle_rounded(
    n: int = 500, *, radius: float = 1.0, centre=(0.0, 0.0), with_centre: bool = False, seed: int = SEED
) -> Case:
    """n points on a circle at random angles, rounded to doubles: every quadruple near-cocircular."""
    rng = np.random.default_rng(seed)
    t = rng.uniform(0.0, 2.0 * math.pi, n)
    pts = np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])
    if with_centre:
        pts = np.concatenate([[centre], pts])
    return Case(_pts(pts), note=f"{n} on a circle, rounded" + (", and its centre" if with_centre else ""))


def circle_regular(n: int = 3000, *, with_centre: bool = True, seed: int = SEED) -> Case:
    """A regular n-gon on the unit circle (rounded) and its centre: the centre's cell has n edges."""
    t = 2.0 * math.pi * np.arange(n) / n
    pts = np.column_stack([np.cos(t), np.sin(t)])
    if with_centre:
        pts = np.concatenate([[(0.0, 0.0)], pts])
    return Case(_pts(pts), note=f"centre inside {n} sites on a circle")


def lattice_circle_points(r2: int) -> np.ndarray:
    """All integer points (x, y) with x^2 + y^2 == r2, exactly."""
    r = math.isqrt(r2)
    out = []
    for x in range(-r, r + 1):
        y2 = r2 - x * x
        y = math.isqrt(y2)
        if y * y == y2:
            out.append((x, y))
            if y:
                out.append((x, -y))
    return np.array(sorted(out), float)


def circle_lattice(r: int = 5525, *, with_centre: bool = True, seed: int = SEED) -> Case:
    """Integer points exactly on x^2 + y^2 = r^2 (180 of them for r = 5525), and the centre."""
    rng = np.random.default_rng(seed)
    pts = lattice_circle_points(r * r)
    pts = pts[rng.permutation(len(pts))]
    if with_centre:
        pts = np.concatenate([pts, [(0.0, 0.0)]])
    return Case(_pts(pts), note=f"{len(pts)} lattice points exactly on a circle of radius {r}")


def concentric_exact(*, seed: int = SEED) -> Case:
    """Lattice points exactly on concentric circles of radius 5, 25, 65, 325, 1105 (with the centre)."""
    rng = np.random.default_rng(seed)
    pts = np.concatenate([lattice_circle_points(r * r) for r in (5, 25, 65, 325, 1105)] + [[(0.0, 0.0)]])
    return Case(_pts(pts[rng.permutation(len(pts))]), note="concentric exact circles")


def concentric_rounded(rings: int = 10, per_ring: int = 60, *, seed: int = SEED) -> Case:
    """Regular polygons on concentric circles, all with the same angles (rounded): radial alignments."""
    t = 2.0 * math.pi * np.arange(per_ring) / per_ring
    pts = [np.column_stack([r * np.cos(t), r * np.sin(t)]) for r in range(1, rings + 1)]
    return Case(_pts(np.concatenate(pts + [[(0.0, 0.0)]])), note=f"{rings} concentric {per_ring}-gons")


# ---------------------------------------------------------------------------------------------
# scale: offsets, tiny and subnormal coordinates


def offset(n: int = 300, *, at: float = 1e9, spread: float = 1.0, seed: int = SEED) -> Case:
    """Uniform points of a small spread far from the origin: few bits of resolution left."""
    rng = np.random.default_rng(seed)
    return Case(_pts(at + spread * rng.uniform(0.0, 1.0, (n, 2))), note=f"offset {at:g}, spread {spread:g}")


def offset_grid(side: int = 12, *, at: float = 1e15, step: float = 0.125, seed: int = SEED) -> Case:
    """A grid of ulp-sized steps at a large offset (at 1e15 one ulp is 0.125): exact grid, huge offset."""
    rng = np.random.default_rng(seed)
    g = np.array([(at + i * step, at + j * step) for i in range(side) for j in range(side)], float)
    return Case(_pts(g[rng.permutation(len(g))]), note=f"{side}x{side} grid of step {step} at {at:g}")


def scaled(n: int = 300, *, factor: float = 1e-310, seed: int = SEED) -> Case:
    """Uniform points in the unit square times a factor (1e-310: subnormal, a few digits of precision)."""
    rng = np.random.default_rng(seed)
    return Case(_pts(rng.uniform(0.0, 1.0, (n, 2)) * factor), note=f"uniform * {factor:g}")


def cluster_in_box(n: int = 200, *, width: float = 1e-9, box: float = 1e6, seed: int = SEED) -> Case:
    """A cluster of this width in the middle of a large user box: cells reach far out to the box."""
    rng = np.random.default_rng(seed)
    pts = box / 2 + width * rng.uniform(0.0, 1.0, (n, 2))
    return Case(_pts(pts), bbox=(0.0, 0.0, box, box), note=f"{width:g} cluster in a {box:g} box")


def cluster_with_far_sites(n: int = 200, *, width: float = 1e-9, box: float = 1e6, seed: int = SEED) -> Case:
    """The same cluster with four sites at the corners of the large box (default box)."""
    c = cluster_in_box(n, width=width, box=box, seed=seed).points
    corners = [(0.0, 0.0), (box, 0.0), (box, box), (0.0, box)]
    return Case(_pts(np.concatenate([c, corners])), note=f"{width:g} cluster and far corner sites")


def two_sites_ulps_apart(*, at: float = 1e12, ulps: int = 2, seed: int = SEED) -> Case:
    """Two sites at (at, at), a few ulps apart in x: the bisector sits between two doubles or on one."""
    x1 = at
    for _ in range(ulps):
        x1 = float(np.nextafter(x1, np.inf))
    return Case(_pts([(at, at), (x1, at)]), note=f"two sites {ulps} ulps apart at {at:g}")


def subnormal_sites(*, seed: int = SEED) -> Case:
    """A few sites on the smallest subnormals: the default box's margin rounds to zero."""
    t = 5e-324
    return Case(_pts([(t, t), (2 * t, t), (4 * t, 3 * t), (2 * t, 5 * t)]), note="sites at multiples of 5e-324")


def subnormal_row(*, seed: int = SEED) -> Case:
    """Sites on one horizontal row of subnormals: the box's height comes from the margin alone."""
    t = 5e-324
    return Case(_pts([(t, t), (2 * t, t), (3 * t, t)]), note="a row of subnormal sites")


# ---------------------------------------------------------------------------------------------
# repeats and tiny counts


def heavy_duplicates(distinct: int = 50, copies: int = 20, *, seed: int = SEED) -> Case:
    """A few distinct points, each repeated many times, shuffled."""
    rng = np.random.default_rng(seed)
    base = np.round(rng.uniform(0.0, 1.0, (distinct, 2)), 3)
    pts = np.repeat(base, copies, axis=0)
    return Case(_pts(pts[rng.permutation(len(pts))]), note=f"{distinct} points x {copies} copies")


def duplicates_of_three(copies: int = 30, *, collinear: bool = False, seed: int = SEED) -> Case:
    """Three places (a triangle, or three collinear places), each repeated many times."""
    rng = np.random.default_rng(seed)
    base = [(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)] if collinear else [(0.0, 0.0), (1.0, 0.0), (0.3, 0.9)]
    pts = np.repeat(np.array(base), copies, axis=0)
    return Case(_pts(pts[rng.permutation(len(pts))]), note="three places repeated")


def few_sites(kind: str, *, seed: int = SEED) -> Case:
    """0 to 3 sites: empty, one, two, two equal, three collinear, three in a triangle."""
    sets = {
        "zero": [],
        "one": [(0.25, 0.5)],
        "two": [(0.0, 0.0), (1.0, 0.5)],
        "two_equal": [(0.3, 0.3), (0.3, 0.3)],
        "three_collinear": [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0)],
        "three": [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)],
    }
    return Case(_pts(sets[kind]), note=f"{kind} site(s)")


# ---------------------------------------------------------------------------------------------
# user boxes


def _unit_sites(n: int = 300, seed: int = SEED) -> np.ndarray:
    return np.random.default_rng(seed).uniform(0.0, 1.0, (n, 2))


def box_excludes_most(n: int = 300, *, seed: int = SEED) -> Case:
    """A user box around a small part of the sites: most cells miss it."""
    return Case(_pts(_unit_sites(n, seed)), bbox=(0.40, 0.45, 0.47, 0.50), note="a box holding a few sites")


def box_far_away(n: int = 300, *, seed: int = SEED) -> Case:
    """A user box far from every site: only the cells that reach out to it are there."""
    return Case(_pts(_unit_sites(n, seed)), bbox=(40.0, -30.0, 41.5, -29.0), note="a box far from the sites")


def box_one_ulp_thin(n: int = 300, *, seed: int = SEED) -> Case:
    """A box one ulp high across the sites."""
    y0 = 0.5
    return Case(
        _pts(_unit_sites(n, seed)), bbox=(0.0, y0, 1.0, float(np.nextafter(y0, 1.0))), note="a box one ulp thin"
    )


def box_huge(n: int = 300, *, seed: int = SEED) -> Case:
    """Unit-square sites in a box of +-1e300 (the range rule allows up to about 1.3e300 here)."""
    return Case(_pts(_unit_sites(n, seed)), bbox=(-1e300, -1e300, 1e300, 1e300), note="a box of +-1e300")


def box_through_sites(n: int = 300, *, seed: int = SEED) -> Case:
    """A box whose sides pass exactly through sites and Voronoi vertices of a grid."""
    g = np.array([(i, j) for i in range(12) for j in range(12)], float)
    return Case(_pts(g), bbox=(2.0, 2.5, 9.5, 9.0), note="box sides through grid sites and vertices")


def box_on_lattice_edges(side: int = 24, *, step: float = 0.5, seed: int = SEED) -> Case:
    """Sites at the centres of a lattice's squares, a few left out, and a box whose sides lie on the
    lattice lines: the Voronoi edges run along the box's sides and meet at its corners, so cells outside
    touch the box at a corner or along a side and hold nothing inside it."""
    rng = np.random.default_rng(seed)
    ij = np.array([(i, j) for i in range(side) for j in range(side)])
    lo = rng.integers(1, side // 4, 2)
    hi = rng.integers(3 * side // 4, side, 2)
    keep = rng.random(len(ij)) < 0.9
    # at each corner of the box, the two squares beside it across the box's sides go: the bisector of the
    # two diagonal squares' centres passes through the corner
    for cx, cy in ((lo[0], lo[1]), (hi[0], lo[1]), (lo[0], hi[1]), (hi[0], hi[1])):
        for i, j in ((cx - 1, cy), (cx, cy - 1)) if (cx == lo[0]) == (cy == lo[1]) else ((cx - 1, cy - 1), (cx, cy)):
            keep &= ~((ij[:, 0] == i) & (ij[:, 1] == j))
    g = (ij[keep] + 0.5) * step
    box = (lo[0] * step, lo[1] * step, hi[0] * step, hi[1] * step)
    return Case(_pts(g[rng.permutation(len(g))]), bbox=box, note="box sides on cell edges, corners on bisectors")


def box_corner_on_vertex(side: int = 20, *, pythagorean: bool = False, seed: int = SEED) -> Case:
    """A small box inside one cell with a corner exactly on a Voronoi vertex: the cell's edges only touch
    the box there (at a lattice's 4-cell vertex, or at the centre of 3-4-5 circles of sites), and every
    cell around the vertex touches the box at that corner alone."""
    rng = np.random.default_rng(seed)
    g = np.array([(i, j) for i in range(side) for j in range(side)], float)
    if pythagorean:
        # sites at (3, 4), (-4, 3), (0, -5), ... from centres on a lattice of step 20: each centre a vertex
        rim = np.array([(3, 4), (-4, 3), (-5, 0), (0, -5), (4, -3), (-3, -4)], float)
        centres = g[::7] * 20.0
        pts = (
            centres[:, None, :] + rim[rng.permuted(np.tile(np.arange(6), (len(centres), 1)), axis=1)[:, :3]]
        ).reshape(-1, 2)
        v = centres[rng.integers(len(centres))]
        reach = 0.5
    else:
        pts = g
        v = g[rng.integers(len(g))] + 0.5
        reach = 0.5 * float(rng.choice([1.0, 0.5, 2.0**-20]))
    qx, qy = rng.choice([-1.0, 1.0], 2) * reach
    box = (min(v[0], v[0] + qx), min(v[1], v[1] + qy), max(v[0], v[0] + qx), max(v[1], v[1] + qy))
    return Case(_pts(np.unique(pts, axis=0)), bbox=box, note="a small box in one cell, a corner on a vertex")


def ulp_pairs(n: int = 1200, *, decimals: int | None = 3, seed: int = SEED) -> Case:
    """Points, each with a partner one ulp away in x, in y or in both: the bisector of a pair passes within
    half an ulp of both sites (one cell may vanish, or miss its site by the rounding of its points)."""
    rng = np.random.default_rng(seed)
    base = rng.uniform(0.0, 1.0, (n // 2, 2)) + 0.25
    if decimals is not None:
        base = np.round(base, decimals)
    steps = rng.integers(-1, 2, (len(base), 2))
    steps[(steps == 0).all(axis=1), 1] = 1
    partner = np.where(steps > 0, np.nextafter(base, np.inf), np.where(steps < 0, np.nextafter(base, -np.inf), base))
    return Case(_pts(np.concatenate([base, partner])), note="pairs one ulp apart")


# ---------------------------------------------------------------------------------------------
# the registry: family name -> generator at its hunt size


FAMILIES: dict[str, Callable[..., Case]] = {
    # one line
    "near_collinear_slope2": partial(near_collinear, 100, intercept=1.0, slope=2.0),
    "near_collinear_slope_third": partial(near_collinear, 100, intercept=0.1, slope=1.0 / 3.0),
    "near_collinear_slope_pi": partial(near_collinear, 100, intercept=-0.7, slope=math.pi),
    "near_collinear_flat": partial(near_collinear, 100, intercept=0.3, slope=1e-3),
    "near_collinear_steep": partial(near_collinear, 100, intercept=0.3, slope=1e3),
    "near_collinear_decimal": partial(near_collinear_decimal, 100, slope=0.1),
    "collinear_exact": partial(collinear_exact, 100, slope=2),
    "collinear_dyadic_repeats": partial(collinear_dyadic, 100),
    "collinear_plus_one_ulp": partial(collinear_plus_one, 100),
    # lattices
    "grid70_noise1e-17": partial(square_grid, 70, noise=1e-17),
    "grid10_noise1e-17": partial(square_grid, 10, noise=1e-17),
    "grid30_noise1e-12": partial(square_grid, 30, noise=1e-12),
    "grid30_noise1e-6": partial(square_grid, 30, noise=1e-6),
    "triangular40": partial(triangular_lattice, 40),
    "triangular30_noise1e-15": partial(triangular_lattice, 30, noise=1e-15),
    "rotated_grid_30deg": partial(rotated_grid, 30, degrees=30.0),
    "rotated_grid_45deg": partial(rotated_grid, 30, degrees=45.0),
    "rotated_grid_1deg_noise1e-9": partial(rotated_grid, 30, degrees=1.0, noise=1e-9),
    "pythagorean_grid": partial(pythagorean_grid, 30),
    "rotated_grid_7deg": partial(rotated_grid, 30, degrees=7.0),
    "rotated_grid_60deg_noise1e-13": partial(rotated_grid, 30, degrees=60.0, noise=1e-13),
    "rotated_grid_89_9deg": partial(rotated_grid, 30, degrees=89.9),
    "hexagonal_17deg": partial(hexagonal_rotated, 30, degrees=17.0),
    "hexagonal_90deg_noise1e-16": partial(hexagonal_rotated, 30, degrees=90.0, noise=1e-16),
    "sheared_lattice_third": partial(sheared_lattice, 30),
    # curves
    "spiral": spiral,
    "parabola_decimal": parabola_decimal,
    "sine_wave": sine_wave,
    "ellipse_thin_with_foci": ellipse_rounded,
    "sunflower": sunflower,
    "pencil_of_lines": pencil_of_lines,
    "pencil_of_lines_3dec": partial(pencil_of_lines, 36, 30, decimals=3),
    "rectangle_perimeter": rectangle_perimeter,
    "rectangle_perimeter_tenths": partial(rectangle_perimeter, 200, height=90, step=0.1),
    "overlaid_grids_3_5": overlaid_grids,
    "overlaid_grids_4_6_tenths": lambda seed=SEED: Case(
        overlaid_grids(a=4, b=6, size=96, seed=seed).points * 0.1, note="grids of steps 0.4 and 0.6 (rounded)"
    ),
    "grid_with_holes": grid_with_holes,
    "grid_with_holes_23deg_2dec": partial(grid_with_holes, 40, degrees=23.0, decimals=2),
    "grid_with_holes_tenths": lambda seed=SEED: Case(
        grid_with_holes(40, seed=seed).points * 0.1, note="lattice with holes, step 0.1 (rounded)"
    ),
    "mirrored_pairs_3dec": mirrored_pairs,
    "mirrored_pairs_raw": partial(mirrored_pairs, 500, decimals=None),
    "huge_circle_arc": huge_circle_arc,
    "huge_circle_arc_1e9": partial(huge_circle_arc, 600, radius=1e9, half_width=500.0),
    "refined_cells": refined_cells,
    "refined_cells_offset": lambda seed=SEED: Case(
        refined_cells(5, size=6, seed=seed).points + 1000.3, note="quadtree leaf centres at 1000.3 (rounded)"
    ),
    # instruments
    "gps_6dec": gps_degrees,
    "gps_4dec": partial(gps_degrees, decimals=4),
    "gps_tracks_6dec": gps_tracks,
    "gps_tracks_5dec": partial(gps_tracks, 8, 250, decimals=5),
    "contour_lines_cm": contour_lines,
    "contour_lines_dm": partial(contour_lines, 10, 200, decimals=1),
    "utm_mm": utm_millimetres,
    "float32_sensor": float32_sensor,
    "survey_rows_cm": survey_rows,
    "mercator_graticule_cm": mercator_graticule,
    "mercator_graticule_m": partial(mercator_graticule, 4.0, decimals=0),
    # products and tilings
    "tensor_grid_log_4dec": tensor_grid,
    "tensor_grid_random_3dec": partial(tensor_grid, 60, spacing="random", decimals=3),
    "penrose_6dec": penrose_vertices,
    "penrose_2dec": partial(penrose_vertices, 9, decimals=2),
    # relaxed sites, networks and series
    "lloyd_relaxed_4dec": lloyd_relaxed,
    "lloyd_relaxed_2dec": partial(lloyd_relaxed, 800, iterations=12, decimals=2),
    "street_network_7dec": street_network,
    "street_network_5dec": partial(street_network, 10, spacing_m=3.0, decimals=5),
    "time_series_epoch_2dec": time_series,
    "time_series_epoch_1dec": partial(time_series, 1500, series=4, decimals=1),
    "buildings_turned_2dec": building_footprints,
    "buildings_axis_1dec": partial(building_footprints, 100, decimals=1, turned=False),
    "raster_scan_3dec": raster_scan,
    "raster_scan_1dec": partial(raster_scan, 80, 120, decimals=1),
    # sites tied with circle tops; heights spread over many magnitudes (the event queue's strips)
    "diamond_lattice": diamond_lattice,
    "geometric_rows_3dec": geometric_rows,
    "rows_on_strip_edges": rows_on_strip_edges,
    "ring_around_cloud_mm": ring_around_cloud,
    "median_line_crowded": median_line_crowded,
    # rounded random
    "uniform_1dec": partial(rounded_uniform, 500, decimals=1),
    "uniform_2dec": partial(rounded_uniform, 2000, decimals=2),
    "uniform_3dec": partial(rounded_uniform, 2000, decimals=3),
    "gaussian_1dec": partial(rounded_gaussian, 2000, decimals=1),
    "gaussian_2dec": partial(rounded_gaussian, 2000, decimals=2),
    "decimal_pythagorean_3dec": partial(decimal_pythagorean, 1000, decimals=3),
    "decimal_pythagorean_2dec_offset": lambda seed=SEED: Case(
        decimal_pythagorean(600, decimals=2, seed=seed).points + 1000.0, note="decimal circles of 5 at 1000"
    ),
    "decimal_circles_3dec": partial(decimal_circles, 60, decimals=3),
    "sobol_net": sobol_net,
    "sobol_net_mm": partial(sobol_net, 11, unit=0.001),
    "halton_3dec": halton_rounded,
    "halton_1dec": partial(halton_rounded, 2000, decimals=1),
    # circles
    "circle_rounded": partial(circle_rounded, 500),
    "circle_rounded_offset": partial(circle_rounded, 300, radius=1e-3, centre=(1e4, -1e4)),
    "circle_lattice_5525": partial(circle_lattice, 5525),
    "concentric_exact": concentric_exact,
    "concentric_rounded": partial(concentric_rounded, 10, 60),
    "circle_centre_3000": partial(circle_regular, 3000),
    "circle_centre_5000": partial(circle_regular, 5000),
    # scale
    "offset_1e6": partial(offset, 300, at=1e6, spread=1.0),
    "offset_1e9": partial(offset, 300, at=1e9, spread=1.0),
    "offset_1e12": partial(offset, 300, at=1e12, spread=1.0),
    "offset_1e15": partial(offset, 300, at=1e15, spread=10.0),
    "offset_grid_1e15": partial(offset_grid, 12, at=1e15, step=0.125),
    "tiny_1e-300": partial(scaled, 300, factor=1e-300),
    "subnormal_1e-310": partial(scaled, 300, factor=1e-310),
    "cluster_1e-9_in_1e6_box": partial(cluster_in_box, 200),
    "cluster_1e-9_far_corners": partial(cluster_with_far_sites, 200),
    "two_sites_1e12_2ulps": partial(two_sites_ulps_apart, at=1e12, ulps=2),
    "two_sites_1e12_1ulp": partial(two_sites_ulps_apart, at=1e12, ulps=1),
    "subnormal_default_box": subnormal_sites,
    "subnormal_row_default_box": subnormal_row,
    # repeats and tiny counts
    "heavy_duplicates": partial(heavy_duplicates, 50, 20),
    "duplicates_of_triangle": partial(duplicates_of_three, 30),
    "duplicates_of_collinear": partial(duplicates_of_three, 30, collinear=True),
    **{
        f"sites_{kind}": partial(few_sites, kind)
        for kind in ("zero", "one", "two", "two_equal", "three_collinear", "three")
    },
    # user boxes
    "box_excludes_most": box_excludes_most,
    "box_far_away": box_far_away,
    "box_one_ulp_thin": box_one_ulp_thin,
    "box_huge_1e300": box_huge,
    "box_through_grid": box_through_sites,
    "box_on_lattice_edges": box_on_lattice_edges,
    "box_on_lattice_edges_tenths": partial(box_on_lattice_edges, 30, step=0.1),
    "box_corner_on_vertex": box_corner_on_vertex,
    "box_on_perimeter_sites_tenths": lambda seed=SEED: Case(
        rectangle_perimeter(60, height=40, step=0.1, seed=seed).points,
        bbox=(0.0, 0.0, 6.0, 4.0),
        note="sites along the box's own sides, at tenths",
    ),
    "box_on_mirror_axis": lambda seed=SEED: Case(
        mirrored_pairs(200, seed=seed).points, bbox=(0.0, 0.0, 0.3, 1.0), note="box side on the mirror line"
    ),
    "box_through_refined_cells": lambda seed=SEED: Case(
        refined_cells(4, size=6, seed=seed).points, bbox=(0.5, 0.5, 5.0, 5.0), note="box sides on leaf edges"
    ),
    "box_corner_on_vertex_pythagorean": partial(box_corner_on_vertex, 20, pythagorean=True),
    # neighbours an ulp apart
    "ulp_pairs_3dec": ulp_pairs,
    "ulp_pairs_raw": partial(ulp_pairs, 1200, decimals=None),
}


def make(name: str, seed: int = SEED) -> Case:
    """The case of a family at its hunt size."""
    return FAMILIES[name](seed=seed)
