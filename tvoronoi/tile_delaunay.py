"""Delaunay triangles from tiles: one canonical triangulation, and the test that certifies a tile's triangles final.

Which triangulation. Where four or more sites lie on an empty circle, every triangulation of their
polygon is a Delaunay triangulation, and an engine gives one that depends on its insertion order.
Tiles must agree on one without seeing the whole input, so the tiled triangles are *canonical*: each
such polygon is cut into a fan from its lowest-numbered site (``canonical_triangles``). Where no
four sites are cocircular the triangulation is unique and the canonical triangles are the engine's.

Which triangles are final. A task saw every site of a closed rectangle R. A triangle abc of the sites
it saw is a Delaunay triangle of all the sites when no site it did not see lies in the closed disk
through a, b, c (closed: a site on the circle would change the polygon). Every site lies in the
global convex hull H, so only the disk's part inside H matters: where an edge pq of the triangle is
an edge of H, H lies on the triangle's side of the line pq. ``certified_triangles`` decides exactly
whether the closed disk, cut by those lines, lies in R: each side of R is either not crossed by the
disk, or the disk's extreme point in that direction lies strictly beyond one of the hull lines (then
the cut disk's extreme is a vertex of the triangle, inside R). A float filter with a sound error
bound settles nearly every case; the rest are settled in exact rational arithmetic on the sites.

A site's triangles are final when every triangle around it is certified and its edges on the
task's own hull are edges of H: then its star is the star of the whole triangulation. A triangle is
emitted by the task of its lowest-numbered site, in the round in which that site's star is final.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property

import numpy as np

from tvoronoi.engines import scale_exponent
from tvoronoi.hull import boundary_hull, hull_edges
from tvoronoi.tiles import CERTIFY_RELATIVE, CERTIFY_ULPS, Region


@dataclass(frozen=True)
class TileTriangles:
    """What one task emits: triangles (input rows, counter-clockwise, lowest first), the sites whose
    stars were final (``done``), and those left for a later round with the box each needs seen."""

    triangles: np.ndarray
    done: np.ndarray
    pending: np.ndarray
    reaches: np.ndarray = field(default_factory=lambda: np.empty((0, 4)))


def lowest_first(triangles: np.ndarray) -> np.ndarray:
    """Each triangle rotated (orientation kept) to start at its lowest index."""
    tri = np.asarray(triangles).reshape(-1, 3)
    k = np.argmin(tri, axis=1)
    rows = np.arange(len(tri))[:, None]
    return tri[rows, (k[:, None] + np.arange(3)) % 3]


def circumcentres(pts: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(k, 2) correctly rounded circumcentres of triangles of ``pts`` (the kernels' construction)."""
    from tvoronoi.kernels import dual

    e = scale_exponent(pts)
    xs = np.ascontiguousarray(np.ldexp(pts[:, 0], -e))
    ys = np.ascontiguousarray(np.ldexp(pts[:, 1], -e))
    return dual.circumcentres(xs, ys, np.ascontiguousarray(triangles, np.int32), e)


def canonical_triangles(
    pts: np.ndarray,
    triangles: np.ndarray,
    n_vertices: int | None = None,
    centres: np.ndarray | None = None,
    sort: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """The canonical Delaunay triangulation: each polygon of cocircular sites a fan from its lowest index.

    Parameters
    ----------
    pts : (n, 2) the sites; triangles : (k, 3) a Delaunay triangulation of them, counter-clockwise
    n_vertices : the number of distinct Voronoi vertices, when known (``len(diagram.vertices)``): equal
        to k, no two triangles share a circle and the triangles are returned as they are
    centres : (k, 2) their correctly rounded circumcentres, when known
    sort : sort the triangles by rows (a task that only filters them skips it)

    Returns
    -------
    (triangles, centres)
        Lowest index first in each triangle, sorted by rows; the centres in the same order.
    """
    tri = np.asarray(triangles, np.int64).reshape(-1, 3)
    if centres is None:
        centres = circumcentres(pts, tri)
    if n_vertices is None or n_vertices < len(tri):
        tri, centres = _fan_cocircular(pts, tri, centres)
    tri = lowest_first(tri)
    if not sort:
        return tri, centres
    order = np.lexsort((tri[:, 2], tri[:, 1], tri[:, 0]))
    return tri[order], centres[order]


def _fan_cocircular(pts: np.ndarray, tri: np.ndarray, centres: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Re-triangulate every polygon of cocircular sites as a fan from its lowest index.

    Triangles of one empty circle have the same exact centre, hence the same rounded one; triangles
    with equal rounded centres are grouped, and the exact in-circle test confirms each member's circle.
    """
    from tvoronoi.kernels.predicates import incircle_sign

    if len(tri) < 2:
        return tri, centres
    order = np.lexsort((centres[:, 1], centres[:, 0]))
    same = np.zeros(len(tri), bool)
    same[1:] = (centres[order[1:], 0] == centres[order[:-1], 0]) & (centres[order[1:], 1] == centres[order[:-1], 1])
    if not same.any():
        return tri, centres
    starts = np.flatnonzero(~same)
    stops = np.append(starts[1:], len(tri))
    drop = np.zeros(len(tri), bool)
    new_tri, new_centres = [], []
    xy = np.ldexp(pts, -scale_exponent(pts)).tolist()  # the predicates want coordinates near 1
    for a, b in zip(starts.tolist(), stops.tolist()):
        if b - a < 2:
            continue
        members = order[a:b].tolist()
        while members:
            # the triangles on the first member's circle (two empty circles with one centre are one circle)
            ref = tri[members[0]].tolist()
            (ax, ay), (bx, by), (cx, cy) = (xy[i] for i in ref)
            group: list[int] = []
            rest: list[int] = []
            for k in members:
                on = all(incircle_sign(ax, ay, bx, by, cx, cy, *xy[i]) == 0 for i in tri[k].tolist())
                (group if on else rest).append(k)
            members = rest
            if len(group) < 2:
                continue
            ring = _boundary_cycle(tri[group])
            start = ring.index(min(ring))
            ring = ring[start:] + ring[:start]
            drop[group] = True
            for j in range(1, len(ring) - 1):
                new_tri.append((ring[0], ring[j], ring[j + 1]))
                new_centres.append(centres[group[0]])
    if not new_tri:
        return tri, centres
    return (
        np.concatenate([tri[~drop], np.array(new_tri, np.int64)]),
        np.concatenate([centres[~drop], np.array(new_centres, np.float64)]),
    )


def _boundary_cycle(group: np.ndarray) -> list[int]:
    """The counter-clockwise boundary of a triangulated convex polygon: its edges used once, chained."""
    edges = {(int(t[j]), int(t[(j + 1) % 3])) for t in group for j in range(3)}
    nxt = {p: q for p, q in edges if (q, p) not in edges}
    start = min(nxt)
    ring = [start]
    while nxt[ring[-1]] != start:
        ring.append(nxt[ring[-1]])
    return ring


# ---------------------------------------------------------------------------------------------
# certification


def certified_triangles(
    pts: np.ndarray, tri: np.ndarray, centres: np.ndarray, on_hull: np.ndarray, region: Region
) -> np.ndarray:
    """(k,) bool: which triangles no site outside the closed ``region`` can make non-Delaunay.

    ``tri`` (k, 3) counter-clockwise rows of ``pts``, ``centres`` their correctly rounded circumcentres,
    ``on_hull`` (k, 3) bool: edge j (``tri[:, j]`` to ``tri[:, j + 1]``) is an edge of the global hull.
    The decision is exact (see the module's docstring): a float filter, then rationals where it cannot tell.

    Why the filter is sound: the centre is correctly rounded, so the float distances err by at most an
    ulp of the centre plus a few roundings relative to their size; the margins ``CERTIFY_ULPS`` ulps and
    ``CERTIFY_RELATIVE`` are those of ``tiles.certified``, and a case within them goes to the exact test.
    """
    k = len(tri)
    if k == 0:
        return np.ones(0, bool)
    ox, oy = centres[:, 0], centres[:, 1]
    a = pts[tri[:, 0]]
    passed = np.ones(k, bool)
    failed = np.zeros(k, bool)
    with np.errstate(over="ignore", invalid="ignore"):
        r = np.hypot(ox - a[:, 0], oy - a[:, 1])
        top = np.maximum(np.abs(ox), np.abs(oy))
        slack = 2 * CERTIFY_ULPS * np.spacing(top) + 4 * float(np.spacing(0.0))
        finite = np.isfinite(r) & np.isfinite(slack)
        low = r * (1 - CERTIFY_RELATIVE) - slack
        high = r * (1 + CERTIFY_RELATIVE) + slack
        for j, sigma, beta in _sides(region):
            o = ox if j == 0 else oy
            room = sigma * (beta - o)  # how far the side is from the centre
            err = np.abs(room) * CERTIFY_RELATIVE + slack
            passed &= finite & (room - err >= high)
            failed |= finite & (room + err < low)
    unsure = ~passed & ~(failed & ~on_hull.any(axis=1))
    ok = passed.copy()
    for t in np.flatnonzero(unsure).tolist():
        corners = pts[tri[t]].tolist()
        hull = [(corners[j], corners[(j + 1) % 3]) for j in range(3) if on_hull[t, j]]
        ok[t] = disk_inside(corners, hull, region)
    return ok


def _sides(region: Region):
    """(axis, sigma, bound) of each finite side: the side is ``sigma * coordinate <= sigma * bound``."""
    x0, y0, x1, y1 = region
    for j, sigma, beta in ((0, -1, x0), (1, -1, y0), (0, 1, x1), (1, 1, y1)):
        if math.isfinite(beta):
            yield j, sigma, float(beta)


def disk_inside(corners, hull, region: Region) -> bool:
    """Exactly: whether the closed disk through the three ``corners`` (counter-clockwise), cut by the
    lines of its ``hull`` edges ((p, q) pairs: the sites lie on their left), lies in the closed ``region``."""
    (ax, ay), (bx, by), (cx, cy) = ((Fraction(x), Fraction(y)) for x, y in corners)
    ux, uy, wx, wy = bx - ax, by - ay, cx - ax, cy - ay
    d = 2 * (ux * wy - uy * wx)
    u2, w2 = ux * ux + uy * uy, wx * wx + wy * wy
    ox = ax + (wy * u2 - uy * w2) / d
    oy = ay + (ux * w2 - wx * u2) / d
    r2 = (ox - ax) ** 2 + (oy - ay) ** 2
    lines = [((Fraction(p[0]), Fraction(p[1])), (Fraction(q[0]), Fraction(q[1]))) for p, q in hull]
    for j, sigma, beta in _sides(region):
        room = sigma * (Fraction(beta) - (ox if j == 0 else oy))
        if room >= 0 and room * room >= r2:
            continue
        # the disk crosses the side: fine if its extreme point L = O + sigma r e_j is strictly beyond a hull line
        beyond = False
        for (px, py), (qx, qy) in lines:
            # orient(p, q, L) = A + B r
            a_ = (qx - px) * (oy - py) - (qy - py) * (ox - px)
            b_ = sigma * ((qx - px) if j == 1 else -(qy - py))
            if _sign_plus_root(a_, b_, r2) < 0:
                beyond = True
                break
        if not beyond:
            return False
    return True


def _sign_plus_root(a: Fraction, b: Fraction, r2: Fraction) -> int:
    """The sign of a + b sqrt(r2), r2 > 0, exactly."""
    sa = (a > 0) - (a < 0)
    sb = (b > 0) - (b < 0)
    if sb == 0:
        return sa
    if sa == 0 or sa == sb:
        return sb
    d = a * a - b * b * r2
    return sa if d > 0 else (sb if d < 0 else 0)


# ---------------------------------------------------------------------------------------------
# one task's triangles


@dataclass(frozen=True)
class Hull:
    """The global convex hull's boundary sites, counter-clockwise (input rows and places)."""

    ids: np.ndarray
    xy: np.ndarray

    @classmethod
    def of(cls, pts: np.ndarray, ids: np.ndarray) -> Hull:
        """The hull of sites ``pts`` numbered ``ids``: the hull of partitions' hulls is the whole one."""
        order = boundary_hull(pts, ids)
        place = dict(zip(np.asarray(ids).tolist(), map(tuple, np.asarray(pts).tolist())))
        return cls(order, np.array([place[i] for i in order.tolist()], np.float64).reshape(-1, 2))

    @cached_property
    def edges(self) -> set:
        """The directed edges (p, q) as pairs of input rows (the sites on their left); none when every
        site lies on one line (then there is no triangle either)."""
        if self.collinear:
            return set()
        return {(int(p), int(q)) for p, q in hull_edges(self.ids).tolist()}

    @cached_property
    def collinear(self) -> bool:
        """Whether the sites span no area (fewer than three places, or all on one line)."""
        if len(self.ids) < 3:
            return True
        from tvoronoi.kernels.predicates import orient2d_many

        xy = np.ldexp(self.xy, -scale_exponent(self.xy))
        a = np.ascontiguousarray(np.broadcast_to(xy[0], xy.shape))
        b = np.ascontiguousarray(np.broadcast_to(xy[1], xy.shape))
        return not orient2d_many(a, b, np.ascontiguousarray(xy)).any()

    @cached_property
    def edge_boxes(self) -> np.ndarray:
        """(h, 4) each edge's bounding box."""
        if self.collinear:
            return np.empty((0, 4))
        a, b = self.xy, np.roll(self.xy, -1, axis=0)
        return np.column_stack([np.minimum(a, b), np.maximum(a, b)])


def tile_triangles(
    pts: np.ndarray,
    ids: np.ndarray,
    want: np.ndarray,
    region: Region,
    diagram,
    *,
    hull: Hull,
    extent: Region,
    everything: bool = False,
) -> TileTriangles:
    """The final Delaunay triangles a task emits, from the diagram it built of the sites it saw.

    Parameters
    ----------
    pts, ids, want, region, everything : as ``tiles.build_tile`` (``ids`` ascending)
    diagram : the Diagram of ``pts``
    hull : the global convex hull
    extent : the sites' bounding box (what a pending site's reach is cut to)
    """
    m = len(pts)
    duplicate = diagram.site_of != np.arange(m)
    tri = np.asarray(diagram.triangles, np.int64).reshape(-1, 3)
    empty = np.empty(0, np.int64)
    if len(tri) == 0:
        # no triangle among the sites seen (all on a line): final only when they are all the sites
        wanted = ids[want]
        if everything:
            return TileTriangles(np.empty((0, 3), np.int64), wanted, empty)
        live = want & ~duplicate
        reach = np.tile(np.array(region, np.float64), (int(live.sum()), 1))
        reach = _cut_to(reach, extent)
        return TileTriangles(np.empty((0, 3), np.int64), ids[want & duplicate], ids[live], reach)
    tri, centres = canonical_triangles(pts, tri, len(diagram.vertices), sort=False)
    open_site = np.zeros(m, bool)
    if everything:
        ok = np.ones(len(tri), bool)
    else:
        # the task's own hull: an edge that is not one of the global hull leaves its sites open
        local = hull_edges(boundary_hull(pts, np.arange(m)))
        global_ = np.array([(int(ids[p]), int(ids[q])) in hull.edges for p, q in local.tolist()], bool)
        open_site[local[~global_].ravel()] = True
        keys = tri * m + np.roll(tri, -1, axis=1)  # edge j: tri[:, j] -> tri[:, j + 1]
        on_hull = np.isin(keys, local[global_, 0] * m + local[global_, 1])
        ok = certified_triangles(pts, tri, centres, on_hull, within(region, extent))
    bad = open_site.copy()
    bad[tri[~ok].ravel()] = True
    done = want & ~bad
    emit = done[tri[:, 0]]  # the lowest site is first
    pending = want & bad & ~duplicate
    return TileTriangles(ids[tri[emit]], ids[done], ids[pending], _reaches(pts, tri, centres, pending, hull, extent))


def within(region: Region, extent: Region) -> Region:
    """The region with each side at or beyond the sites' extent made infinite: no site lies past it, so
    a disk may cross it (a triangle near the hull has a wide disk, mostly outside every site)."""
    x0, y0, x1, y1 = region
    ex0, ey0, ex1, ey1 = extent
    return (
        -math.inf if x0 <= ex0 else x0,
        -math.inf if y0 <= ey0 else y0,
        math.inf if x1 >= ex1 else x1,
        math.inf if y1 >= ey1 else y1,
    )


def _reaches(pts, tri, centres, pending: np.ndarray, hull: Hull, extent: Region) -> np.ndarray:
    """(p, 4) the box each pending site needs seen: itself, its triangles' disks within the extent, and the
    global hull edges these meet (a long hull edge's far end decides the triangles under it)."""
    rows = np.flatnonzero(pending)
    if len(rows) == 0:
        return np.empty((0, 4))
    lo = pts.copy()
    hi = pts.copy()
    near = pending[tri].any(axis=1)
    t, c = tri[near], centres[near]
    with np.errstate(over="ignore", invalid="ignore"):
        r = np.hypot(c[:, 0] - pts[t[:, 0], 0], c[:, 1] - pts[t[:, 0], 1])
        box = np.column_stack([c[:, 0] - r, c[:, 1] - r, c[:, 0] + r, c[:, 1] + r])
    box = _cut_to(np.where(np.isfinite(box), box, np.array([-np.inf, -np.inf, np.inf, np.inf])), extent)
    for j in range(3):
        np.minimum.at(lo, t[:, j], box[:, :2])
        np.maximum.at(hi, t[:, j], box[:, 2:])
    out = np.column_stack([lo[rows], hi[rows]])
    edges = hull.edge_boxes
    if len(edges):
        for k in range(len(out)):
            meet = ~(
                (edges[:, 2] < out[k, 0])
                | (edges[:, 0] > out[k, 2])
                | (edges[:, 3] < out[k, 1])
                | (edges[:, 1] > out[k, 3])
            )
            if meet.any():
                out[k, :2] = np.minimum(out[k, :2], edges[meet, :2].min(axis=0))
                out[k, 2:] = np.maximum(out[k, 2:], edges[meet, 2:].max(axis=0))
    return out


def _cut_to(boxes: np.ndarray, extent: Region) -> np.ndarray:
    ex = np.array(extent, np.float64)
    out = boxes.copy()
    out[:, :2] = np.clip(out[:, :2], ex[:2], ex[2:])
    out[:, 2:] = np.clip(out[:, 2:], ex[:2], ex[2:])
    return out


# ---------------------------------------------------------------------------------------------
# every round in this process


@dataclass
class TiledTriangles:
    """Every Delaunay triangle of a tiled build (lowest row first, sorted), and the rounds it took."""

    triangles: np.ndarray
    rounds: int
    pending_after: list[int] = field(default_factory=list)


def tiled_triangles(
    points, *, tiles: int, bbox=None, engine: str = "incremental", seed: int = 0, halo_scale: float = 1.0
) -> TiledTriangles:
    """The canonical Delaunay triangles of ``points``, built tile by tile in this process.

    The reference of the distributed build (``tvoronoi.distributed.voronoi(..., delaunay=True)``): the
    same plan, the same rounds; equal to ``canonical_triangles`` of one process's triangles.
    """
    from tvoronoi.api import as_bbox, as_points, default_bbox, voronoi
    from tvoronoi.errors import TvoronoiError
    from tvoronoi.tiles import (
        MAX_ROUNDS,
        SAMPLE_PER_TILE,
        Plan,
        extent_of,
        group_reaches,
        in_region,
        plan_tiles,
        tile_of,
    )

    pts = as_points(points)
    n = len(pts)
    if n == 0:
        return TiledTriangles(np.empty((0, 3), np.int64), 0)
    box = default_bbox(pts) if bbox is None else as_bbox(bbox)
    rng = np.random.default_rng(seed)
    take = min(n, SAMPLE_PER_TILE * tiles)
    sample = pts[np.sort(rng.choice(n, take, replace=False))] if take < n else pts
    extent = extent_of(pts)
    plan = plan_tiles(sample, tiles, extent, box, n)
    plan = Plan(plan.rects, plan.halos * halo_scale, plan.extent, plan.box)
    ids = np.arange(n, dtype=np.int64)
    hull = Hull.of(pts, ids)
    owner = tile_of(pts[:, 0], pts[:, 1], plan.rects)
    todo = np.ones(n, bool)
    found: list[np.ndarray] = []
    pending_after: list[int] = []
    units: list[tuple[int, np.ndarray | None, Region | None]] = [(t, None, None) for t in range(plan.n_tiles)]
    round_ = 0
    while units:
        round_ += 1
        if round_ > MAX_ROUNDS:
            raise TvoronoiError("the tiles' regions stopped growing before every triangle was certified")
        next_units: list[tuple[int, np.ndarray | None, Region | None]] = []
        for t, group, reach in units:
            region = plan.region(t, round_, reach)
            rows = np.flatnonzero(in_region(pts[:, 0], pts[:, 1], region))
            want = ((owner[rows] == t) if group is None else np.isin(ids[rows], group)) & todo[rows]
            if not want.any():
                continue
            d = voronoi(pts[rows], bbox=box, engine=engine, threads=1)
            got = tile_triangles(
                pts[rows], ids[rows], want, region, d, hull=hull, extent=extent, everything=plan.sees_everything(region)
            )
            todo[got.done] = False
            found.append(got.triangles)
            next_units += [(t, g, b) for g, b in group_reaches(got.pending, got.reaches, plan.margin(t, round_))]
        units = next_units
        pending_after.append(int(todo.sum()))
    tri = np.concatenate(found) if found else np.empty((0, 3), np.int64)
    order = np.lexsort((tri[:, 2], tri[:, 1], tri[:, 0]))
    return TiledTriangles(tri[order], round_, pending_after)
