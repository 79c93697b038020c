"""Exact checks of a Diagram: rational Delaunay predicates, valid cells on raw coordinates, engines bit for bit.

Every double is a dyadic rational, so a point set is exactly a set of integers times one common power of
two: ``exact_coordinates`` gives those integers (via ``fractions.Fraction``), and orientation, in-circle
and areas are then evaluated in Python integers, exactly and at any scale (subnormal to 1e300).
Each check raises AssertionError with a message naming the culprit.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import shapely

# The cells' areas must add up to the box's within this relative error (the brief's tolerance: the
# cells are rounded, but shared points are shared bit for bit, so an exact tiling adds up exactly).
AREA_RTOL = 1e-9


# ---------------------------------------------------------------------------------------------
# exact arithmetic


def exact_coordinates(values) -> tuple[list[int], int]:
    """Integers X and a common denominator D (a power of two) with values[k] == X[k] / D exactly."""
    fracs = [Fraction(float(v)) for v in np.asarray(values, np.float64).ravel()]
    den = max((f.denominator for f in fracs), default=1)
    return [f.numerator * (den // f.denominator) for f in fracs], den


class ExactPoints:
    """Points as exact integers on a common dyadic scale (the predicates' signs do not depend on it)."""

    def __init__(self, pts):
        pts = np.asarray(pts, np.float64).reshape(-1, 2)
        ints, self.den = exact_coordinates(pts)
        self.x = ints[0::2]
        self.y = ints[1::2]

    def orient(self, a: int, b: int, c: int) -> int:
        """Twice the signed area of (a, b, c): > 0 counter-clockwise, 0 collinear."""
        x, y = self.x, self.y
        return (x[b] - x[a]) * (y[c] - y[a]) - (y[b] - y[a]) * (x[c] - x[a])

    def incircle(self, a: int, b: int, c: int, d: int) -> int:
        """> 0 when d is strictly inside the circle through a, b, c (counter-clockwise), 0 on it."""
        x, y = self.x, self.y
        adx, ady = x[a] - x[d], y[a] - y[d]
        bdx, bdy = x[b] - x[d], y[b] - y[d]
        cdx, cdy = x[c] - x[d], y[c] - y[d]
        alift = adx * adx + ady * ady
        blift = bdx * bdx + bdy * bdy
        clift = cdx * cdx + cdy * cdy
        return alift * (bdx * cdy - bdy * cdx) + blift * (cdx * ady - cdy * adx) + clift * (adx * bdy - ady * bdx)


def orient_fraction(p, q, r) -> Fraction:
    """The orientation determinant in Fractions (reference for ExactPoints.orient)."""
    (px, py), (qx, qy), (rx, ry) = [(Fraction(float(u)), Fraction(float(v))) for u, v in (p, q, r)]
    return (qx - px) * (ry - py) - (qy - py) * (rx - px)


def incircle_fraction(a, b, c, d) -> Fraction:
    """The in-circle determinant in Fractions (reference for ExactPoints.incircle)."""
    (ax, ay), (bx, by), (cx, cy), (dx, dy) = [(Fraction(float(u)), Fraction(float(v))) for u, v in (a, b, c, d)]
    adx, ady, bdx, bdy, cdx, cdy = ax - dx, ay - dy, bx - dx, by - dy, cx - dx, cy - dy
    return (
        (adx * adx + ady * ady) * (bdx * cdy - bdy * cdx)
        + (bdx * bdx + bdy * bdy) * (cdx * ady - cdy * adx)
        + (cdx * cdx + cdy * cdy) * (adx * bdy - ady * bdx)
    )


def hull_boundary(ex: ExactPoints, idx) -> list[int]:
    """Indices of the points on the convex hull's boundary (collinear ones included), counter-clockwise.

    Andrew's monotone chain on exact integers, keeping points on hull edges. Empty if all are collinear.
    """
    idx = sorted(set(idx), key=lambda i: (ex.x[i], ex.y[i]))
    if len(idx) < 3:
        return []

    def chain(seq):
        out: list[int] = []
        for i in seq:
            while len(out) >= 2 and ex.orient(out[-2], out[-1], i) < 0:
                out.pop()
            out.append(i)
        return out

    lower, upper = chain(idx), chain(reversed(idx))
    if all(ex.orient(idx[0], idx[-1], i) == 0 for i in idx):
        return []
    return lower[:-1] + upper[:-1]


def ring_area2(xs: list[int], ys: list[int]) -> int:
    """Twice the signed area of a ring of exact integer coordinates (shoelace)."""
    k = len(xs)
    return sum(xs[i] * ys[(i + 1) % k] - xs[(i + 1) % k] * ys[i] for i in range(k))


# ---------------------------------------------------------------------------------------------
# the Delaunay triangles


def distinct_rows(d) -> np.ndarray:
    """Input rows that hold their place (the first copy of each repeated point)."""
    return np.flatnonzero(np.asarray(d.site_of) == np.arange(d.n_sites))


def check_delaunay_exact(d) -> None:
    """d.triangles is exactly the Delaunay triangulation of the distinct sites.

    Checks, all in exact arithmetic: each triangle counter-clockwise and not flat; each directed edge used
    once; across each interior edge the opposite vertex not strictly inside the circumcircle (locally
    Delaunay everywhere = Delaunay); unpaired edges exactly the hull's boundary (collinear points split
    it); twice the triangles' areas add up to twice the hull's; the vertices are the distinct sites; and
    the count is 2n - 2 - h (n distinct sites, h of them on the hull), or 0 if all are collinear.
    """
    tri = np.asarray(d.triangles, np.int64).reshape(-1, 3)
    ex = ExactPoints(d.sites)
    rows = distinct_rows(d)
    n = len(rows)
    hull = hull_boundary(ex, rows.tolist())
    if not hull:
        assert len(tri) == 0, f"{len(tri)} triangles on {n} collinear (or fewer than 3) distinct sites"
        return
    h = len(hull)
    assert len(tri) == 2 * n - 2 - h, f"{len(tri)} triangles, want 2n - 2 - h = {2 * n - 2 - h} (n={n}, h={h})"
    used = set(tri.ravel().tolist())
    first = set(rows.tolist())
    assert used <= first, f"triangle vertices {sorted(used - first)[:5]} are not first copies of their place"
    assert used == first, f"distinct sites {sorted(first - used)[:5]} are in no triangle"

    third: dict[tuple[int, int], int] = {}
    area2 = 0
    for t, (a, b, c) in enumerate(tri.tolist()):
        o = ex.orient(a, b, c)
        assert o > 0, f"triangle {t} {a, b, c} is {'flat' if o == 0 else 'clockwise'} (exact orientation)"
        area2 += o
        for e, opp in (((a, b), c), ((b, c), a), ((c, a), b)):
            assert e not in third, f"directed edge {e} in two triangles (triangle {t})"
            third[e] = opp
    for (a, b), c in third.items():
        if a > b and (b, a) in third:
            continue
        dd = third.get((b, a))
        if dd is None:
            continue
        s = ex.incircle(a, b, c, dd)
        assert s <= 0, (
            f"edge {a, b}: site {dd} is strictly inside the circumcircle of {a, b, c} (exact in-circle), not Delaunay"
        )
    boundary = {e for e in third if (e[1], e[0]) not in third}
    want = {(hull[k], hull[(k + 1) % h]) for k in range(h)}
    assert boundary == want, (
        f"the unpaired edges are not the hull's: {sorted(boundary - want)[:3]} extra, "
        f"{sorted(want - boundary)[:3]} missing"
    )
    hull_area2 = ring_area2([ex.x[i] for i in hull], [ex.y[i] for i in hull])
    assert area2 == hull_area2, f"triangles cover {area2}, hull {hull_area2} (twice the area, exact units)"


# ---------------------------------------------------------------------------------------------
# the cells

# Below this magnitude GEOS's products of coordinate differences underflow (a subnormal diagram looks flat
# to it); such diagrams are handed to shapely scaled up by a power of two, which is exact (no rounding).
GEOS_TINY = 2.0**-500


# GEOS decides on doubles (with double-double filters): a diagram whose nonzero coordinates span more
# binary orders than this (unit sites in a box of 1e300) is beyond it, and the validity and coverage of
# its cells are checked exactly here instead.
GEOS_SPAN_BITS = 60


def magnitude_span(d) -> int:
    """Binary orders between the largest and the smallest nonzero coordinate of the cells and the box."""
    v = np.abs(np.concatenate([np.asarray(d.cell_points, np.float64).ravel(), np.asarray(d.bbox, np.float64)]))
    v = v[v > 0]
    return int(np.frexp(v.max())[1] - np.frexp(v.min())[1]) if len(v) else 0


def _segments_meet(ex: ExactPoints, p: int, q: int, r: int, s: int) -> bool:
    """Closed segments pq and rs share a point (exact)."""

    def on(a, b, c):
        return min(ex.x[a], ex.x[b]) <= ex.x[c] <= max(ex.x[a], ex.x[b]) and min(ex.y[a], ex.y[b]) <= ex.y[c] <= max(
            ex.y[a], ex.y[b]
        )

    sg = [(o > 0) - (o < 0) for o in (ex.orient(p, q, r), ex.orient(p, q, s), ex.orient(r, s, p), ex.orient(r, s, q))]
    if sg[0] * sg[1] < 0 and sg[2] * sg[3] < 0:
        return True
    return (
        (sg[0] == 0 and on(p, q, r))
        or (sg[1] == 0 and on(p, q, s))
        or (sg[2] == 0 and on(r, s, p))
        or (sg[3] == 0 and on(r, s, q))
    )


def ring_is_simple_exact(ex: ExactPoints, k: int) -> bool:
    """No two edges of the ring meet but consecutive ones at their common point (exact)."""
    for a in range(k):
        for b in range(a + 2, k):
            if a == 0 and b == k - 1:
                continue
            if _segments_meet(ex, a, (a + 1) % k, b, (b + 1) % k):
                return False
    return True


def covers_exact(ring: np.ndarray, point) -> bool:
    """The closed polygon holds the point (exact crossing count; the boundary counts as inside)."""
    ex = ExactPoints(np.vstack([ring, np.asarray(point, np.float64).reshape(1, 2)]))
    k, t = len(ring), len(ring)
    inside = False
    for a in range(k):
        b = (a + 1) % k
        o = ex.orient(a, b, t)
        if o == 0 and (
            min(ex.x[a], ex.x[b]) <= ex.x[t] <= max(ex.x[a], ex.x[b])
            and min(ex.y[a], ex.y[b]) <= ex.y[t] <= max(ex.y[a], ex.y[b])
        ):
            return True
        if (ex.y[a] > ex.y[t]) != (ex.y[b] > ex.y[t]):
            # the edge crosses the horizontal through t: on t's right when the turn says so
            if (o > 0) == (ex.y[b] > ex.y[a]):
                inside = not inside
    return inside


def within_rounding(ring: np.ndarray, point) -> bool:
    """The point lies within the rounding of the ring's points from its boundary: its exact distance to
    some edge is at most the largest ulp of the ring's coordinates.

    The one exemption from "a site lies in its cell": each point of a ring is the rounding of an exact
    point (half an ulp each way at most), so the rounded boundary lies within an ulp of the exact one,
    and a site closer than that to its exact boundary (a neighbour an ulp or a few away) may fall just
    outside its rounded cell. Doubles cannot hold more."""
    r = np.asarray(ring, np.float64)
    tol = Fraction(float(np.spacing(np.abs(r)).max()))
    px, py = (Fraction(float(v)) for v in np.asarray(point, np.float64))
    xs = [Fraction(float(v)) for v in r[:, 0]]
    ys = [Fraction(float(v)) for v in r[:, 1]]
    for a in range(len(r)):
        b = (a + 1) % len(r)
        dx, dy = xs[b] - xs[a], ys[b] - ys[a]
        wx, wy = px - xs[a], py - ys[a]
        length2 = dx * dx + dy * dy
        t = min(max((wx * dx + wy * dy) / length2, Fraction(0)), Fraction(1)) if length2 else Fraction(0)
        ex, ey = wx - t * dx, wy - t * dy
        if ex * ex + ey * ey <= tol * tol:
            return True
    return False


def geos_exponent(d) -> int:
    """k such that coordinates * 2**k are what shapely sees: 0 (raw) unless every coordinate is tiny."""
    top = max(
        float(np.abs(d.cell_points).max()) if len(d.cell_points) else 0.0,
        float(np.abs(d.sites).max()) if d.n_sites else 0.0,
        *(abs(v) for v in d.bbox),
    )
    if top == 0.0 or top >= GEOS_TINY:
        return 0
    return -int(np.frexp(top)[1])


def for_geos(xy, k: int) -> np.ndarray:
    """Coordinates scaled by 2**k for shapely (exact: a scale up never rounds)."""
    xy = np.asarray(xy, np.float64)
    return xy if k == 0 else np.ldexp(xy, k)


def in_box(pts: np.ndarray, bbox) -> np.ndarray:
    xmin, ymin, xmax, ymax = bbox
    return (pts[:, 0] >= xmin) & (pts[:, 0] <= xmax) & (pts[:, 1] >= ymin) & (pts[:, 1] <= ymax)


def check_box(d) -> None:
    """The box has positive size (the default box included)."""
    xmin, ymin, xmax, ymax = d.bbox
    assert xmin < xmax and ymin < ymax, f"the box {d.bbox} has no area"


def has_ulp_neighbour(d, i: int) -> bool:
    """Another distinct site within one ulp of site i in x and in y.

    The one exemption from "a site in the box has a cell": the bisector of two such sites passes between
    adjacent doubles, so one of the two cells may collapse (the house rule allows what doubles cannot hold).
    """
    s = np.asarray(d.sites, np.float64)
    x, y = s[i]
    near = (np.abs(s[:, 0] - x) <= np.spacing(abs(x))) & (np.abs(s[:, 1] - y) <= np.spacing(abs(y)))
    near &= (s[:, 0] != x) | (s[:, 1] != y)
    return bool(near.any())


def check_cells_valid(d) -> None:
    """Every cell a valid, counter-clockwise polygon on the raw coordinates, holding its site when the site is
    in the box (or within the rounding of its points: within_rounding); a repeated point's later copies have
    no cell; a site in the box has a cell."""
    inside = in_box(np.asarray(d.sites, float), d.bbox) if d.n_sites else np.zeros(0, bool)
    k = geos_exponent(d)
    exact = magnitude_span(d) > GEOS_SPAN_BITS
    first = np.asarray(d.site_of) == np.arange(d.n_sites)
    for i in range(d.n_sites):
        ring = d.cell_polygon(i)
        if not first[i]:
            assert len(ring) == 0, f"repeated point {i} (a copy of {int(d.site_of[i])}) has a cell of its own"
            continue
        if len(ring) == 0:
            assert not inside[i] or has_ulp_neighbour(d, i), (
                f"site {i} {tuple(d.sites[i].tolist())} is in the box but has no cell"
            )
            continue
        assert len(ring) >= 3, f"cell {i} has {len(ring)} points"
        assert np.all(np.isfinite(ring)), f"cell {i} has a non-finite point"
        assert in_box(ring, d.bbox).all(), f"cell {i} has a point outside the box: {ring[~in_box(ring, d.bbox)][0]}"
        ex = ExactPoints(ring)
        a2 = ring_area2(ex.x, ex.y)
        assert a2 > 0, f"cell {i} is {'flat' if a2 == 0 else 'clockwise'} (exact area {a2})"
        # (orientation is the exact test above: shapely's is_ccw under/overflows at extreme scales)
        if exact:
            assert ring_is_simple_exact(ex, len(ring)), f"cell {i} is not simple (exact test)"
            if inside[i]:
                assert covers_exact(ring, d.sites[i]) or within_rounding(ring, d.sites[i]), (
                    f"site {i} {tuple(d.sites[i].tolist())} is outside its cell"
                )
            continue
        poly = shapely.Polygon(for_geos(ring, k))
        assert poly.is_valid, f"cell {i} invalid: {shapely.is_valid_reason(poly)}"
        if inside[i]:
            assert (
                poly.covers(shapely.Point(for_geos(d.sites[i], k)))
                or covers_exact(ring, d.sites[i])
                or within_rounding(ring, d.sites[i])
            ), f"site {i} {tuple(d.sites[i].tolist())} is outside its cell"


def check_points_distinct(d) -> None:
    """No cell passes twice through one point (a zero-length edge: two Voronoi vertices or box crossings
    rounded to the same double, or a point emitted twice). Shapely accepts consecutive repeats; we do not."""
    for i in range(d.n_sites):
        ring = d.cell_polygon(i)
        seen: dict[tuple, int] = {}
        for at, p in enumerate(map(tuple, ring.tolist())):
            assert p not in seen, f"cell {i} repeats the point {p} (at {seen[p]} and {at} of {len(ring)})"
            seen[p] = at


def _num(q: Fraction) -> str:
    """A rational as a short decimal, whatever its size (float() overflows past 1e308)."""
    try:
        return f"{float(q):.10g}"
    except OverflowError:
        e = q.numerator.bit_length() - q.denominator.bit_length()
        return f"~2^{e}"


def check_tiling(d) -> None:
    """The cells tile the box: coverage valid for shapely, exact areas adding up to the box's (rel. 1e-9)."""
    rings = [d.cell_polygon(i) for i in range(d.n_sites)]
    rings = [r for r in rings if len(r)]
    if d.n_sites and not np.asarray(d.site_of == np.arange(d.n_sites)).any():
        raise AssertionError("no site holds a cell")
    if not rings:
        assert d.n_sites == 0, "no cell at all"
        return
    xmin, ymin, xmax, ymax = d.bbox
    (bx0, by0, bx1, by1), den = exact_coordinates([xmin, ymin, xmax, ymax])
    box2 = 2 * (bx1 - bx0) * (by1 - by0)
    total = Fraction(0)
    for r in rings:
        ex = ExactPoints(r)
        total += Fraction(ring_area2(ex.x, ex.y), ex.den * ex.den)
    want = Fraction(box2, den * den)
    err = abs(total - want) / want
    assert err <= AREA_RTOL, f"cells cover {_num(total / 2)}, the box {_num(want / 2)} (relative {float(err):.3g})"
    if magnitude_span(d) > GEOS_SPAN_BITS:
        check_shared_edges(d, rings)
        return
    k = geos_exponent(d)
    polys = shapely.polygons([shapely.linearrings(for_geos(r, k)) for r in rings])
    assert shapely.coverage_is_valid(shapely.GeometryCollection(list(polys))), (
        "shapely: the cells do not form a valid coverage (overlap or slivers)"
    )


def _collinear(a, b, p) -> bool:
    ex = ExactPoints([a, b, p])
    return ex.orient(0, 1, 2) == 0


def check_shared_edges(d, rings) -> None:
    """Exact coverage where GEOS cannot decide: every cell edge off the box boundary is run along, the
    other way, by edges of other cells: one twin edge, or collinear edges whose union covers it (where
    rounding put a neighbour's vertex on the edge, or this edge's ends on a neighbour's edge). With every
    cell simple and counter-clockwise (check_cells_valid) and the exact areas adding up to the box's
    (check_tiling), the cells then cover the box exactly once."""
    xmin, ymin, xmax, ymax = d.bbox
    owner: dict[tuple, int] = {}
    for c, r in enumerate(rings):
        pts = [tuple(p) for p in r.tolist()]
        for a, b in zip(pts, pts[1:] + pts[:1]):
            assert (a, b) not in owner, f"two cells run along the edge {a} -> {b}"
            owner[(a, b)] = c
    edges = list(owner.items())
    for (a, b), c in edges:
        if (a[0] == b[0] and a[0] in (xmin, xmax)) or (a[1] == b[1] and a[1] in (ymin, ymax)) or (b, a) in owner:
            continue
        axis = 0 if a[0] != b[0] else 1
        lo, hi = sorted((a[axis], b[axis]))
        forward = b[axis] > a[axis]
        cover = []
        for (u, v), k in edges:
            if k == c or (v[axis] > u[axis]) == forward or max(u[axis], v[axis]) <= lo or min(u[axis], v[axis]) >= hi:
                continue
            if _collinear(a, b, u) and _collinear(a, b, v):
                cover.append(tuple(sorted((u[axis], v[axis]))))
        reach = lo
        for s0, s1 in sorted(cover):
            if s0 > reach:
                break
            reach = max(reach, s1)
        assert reach >= hi, f"the edge {a} -> {b} of a cell has no neighbour on its other side"


# ---------------------------------------------------------------------------------------------
# engines against each other


def cells_of(d) -> list[np.ndarray]:
    return [d.cell_polygon(i).copy() for i in range(d.n_sites)]


def check_same_cells(a: list[np.ndarray], b: list[np.ndarray], names=("fortune", "incremental")) -> None:
    """Two engines' cells identical bit for bit (same points, same starting point)."""
    assert len(a) == len(b), f"{len(a)} vs {len(b)} cells"
    for i, (ra, rb) in enumerate(zip(a, b)):
        if np.array_equal(ra, rb):
            continue
        how = f"{len(ra)} vs {len(rb)} points"
        if len(ra) == len(rb) and len(ra):
            same_points = {tuple(p) for p in ra.tolist()} == {tuple(p) for p in rb.tolist()}
            if same_points:
                how = "the same points from another start"
            else:
                off = np.abs(np.sort(ra, axis=0) - np.sort(rb, axis=0)).max()
                how = f"points differ by up to {off:.3g}"
        raise AssertionError(f"cell {i}: {names[0]} and {names[1]} differ ({how})")


CHECKS = {
    "box": check_box,
    "delaunay": check_delaunay_exact,
    "cells": check_cells_valid,
    "distinct": check_points_distinct,
    "tiling": check_tiling,
}
