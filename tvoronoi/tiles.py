"""Tiles of a diagram: k-d cuts of the plane, halos, and the test that certifies a tile's cell final.

A diagram too large for one process is built tile by tile. The plane is cut into tiles of about equal
counts (quantile cuts of a sample, k-d style); the task of a tile runs the exact engine on the sites
within a margin (the halo) around its tile and keeps the cells of its own sites. A kept cell is
*certified* when, for every point v of its clipped ring, the disk centred at v through the cell's site
lies inside the region whose sites the task saw: a site that the task did not see would then be
farther from every point of the ring than the cell's own site, and cannot cut the cell (a half-plane
that removes part of a convex cell removes one of its vertices). The other cells go to another round
with the halo doubled, until every cell is certified.

The Voronoi vertices are correctly rounded, box crossings are exact and rings start at a canonical
point, so a certified cell is the cell of the whole diagram, bit for bit. Nothing here needs Dask:
``tiled_cells`` runs the rounds in this process (tests, and the reference of ``tvoronoi.distributed``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tvoronoi.errors import TvoronoiError

# The first halo of a tile, in typical site spacings (sqrt(area / count) of the tile): wide enough that
# nearly every cell of uniform data is certified in the first round, narrow enough that a tile's task
# sees few sites besides its own (a halo of 4 spacings around a tile of 10^6 sites adds about 1.6%).
HALO_SPACINGS = 4.0
# Sites per tile taken into the sample from which the cuts are chosen.
SAMPLE_PER_TILE = 1000
# The certification's safety margins (see ``certified``): a relative slack far above the few roundings
# of the test itself (each at most 2^-53), and ulps for the rounding of a ring's point.
CERTIFY_RELATIVE = 2.0**-40
CERTIFY_ULPS = 2.0
# Rounds after which a tile sees everything: its region doubles each round, so this bounds nothing
# in practice; it guards against a region that stops growing (a halo of 0).
MAX_ROUNDS = 64

Region = tuple[float, float, float, float]


def kd_rects(sample: np.ndarray, n_tiles: int) -> np.ndarray:
    """Cut the plane into ``n_tiles`` rectangles holding about equal shares of ``sample``.

    Each cut halves the remaining tiles along the sample's longer side at the matching quantile (k-d
    style, so clustered data stays balanced). Tiles are half-open, ``[xmin, xmax) x [ymin, ymax)``,
    and the outer sides are infinite, so every point of the plane lies in exactly one tile.

    Returns
    -------
    (n_tiles, 4) float64
        xmin, ymin, xmax, ymax of each tile.

    >>> kd_rects(np.array([[0.0, 0], [1, 0], [2, 0], [3, 0]]), 2).tolist()
    [[-inf, -inf, 2.0, inf], [2.0, -inf, inf, inf]]
    """
    if isinstance(n_tiles, bool) or not isinstance(n_tiles, (int, np.integer)) or n_tiles < 1:
        raise TvoronoiError(f"tiles must be a positive integer, got {n_tiles!r}")
    sample = np.asarray(sample, np.float64).reshape(-1, 2)
    rects: list[list[float]] = []

    def split(rect: list[float], pts: np.ndarray, k: int) -> None:
        if k == 1:
            rects.append(rect)
            return
        k_low = k // 2
        spread = np.ptp(pts, axis=0) if len(pts) else np.zeros(2)
        axis = 0 if spread[0] >= spread[1] else 1
        if len(pts):
            ordered = np.sort(pts[:, axis])
            cut = float(ordered[min(len(ordered) - 1, (len(ordered) * k_low) // k)])
        else:  # no sample left: cut the rectangle's finite middle
            lo, hi = rect[axis], rect[axis + 2]
            cut = 0.0 if not (math.isfinite(lo) and math.isfinite(hi)) else (lo + hi) / 2
        low, high = rect.copy(), rect.copy()
        low[axis + 2] = cut
        high[axis] = cut
        below = pts[:, axis] < cut
        split(low, pts[below], k_low)
        split(high, pts[~below], k - k_low)

    split([-math.inf, -math.inf, math.inf, math.inf], sample, int(n_tiles))
    return np.asarray(rects, np.float64)


def tile_of(xs: np.ndarray, ys: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """(n,) int32: the tile whose half-open rectangle holds each point."""
    out = np.full(len(xs), -1, np.int32)
    for t, (x0, y0, x1, y1) in enumerate(rects):
        out[(xs >= x0) & (xs < x1) & (ys >= y0) & (ys < y1)] = t
    return out


def grown(rect, by: float) -> Region:
    """A rectangle grown by ``by`` on every side (infinite sides stay infinite)."""
    x0, y0, x1, y1 = (float(v) for v in rect)
    return (x0 - by, y0 - by, x1 + by, y1 + by)


def in_region(xs: np.ndarray, ys: np.ndarray, region: Region) -> np.ndarray:
    """(n,) bool: the points of the closed rectangle ``region``: the sites a task with that region sees."""
    x0, y0, x1, y1 = region
    return (xs >= x0) & (xs <= x1) & (ys >= y0) & (ys <= y1)


def covers(region: Region, extent: Region) -> bool:
    """Whether the closed ``region`` holds the closed ``extent`` (then a task sees every site)."""
    return region[0] <= extent[0] and region[1] <= extent[1] and region[2] >= extent[2] and region[3] >= extent[3]


def first_halos(rects: np.ndarray, counts: np.ndarray, extent: Region) -> np.ndarray:
    """(T,) the first halo of each tile: ``HALO_SPACINGS`` typical site spacings of the tile.

    ``counts`` are the tiles' site counts (estimated from the sample); ``extent`` the sites' bounding
    box. A tile's area is that of its rectangle within the extent.
    """
    ex0, ey0, ex1, ey1 = extent
    width, height = ex1 - ex0, ey1 - ey0
    side = max(width, height)
    total = max(1, int(np.sum(counts)))
    halos = np.empty(len(rects))
    for t, (x0, y0, x1, y1) in enumerate(rects):
        w = max(0.0, min(x1, ex1) - max(x0, ex0))
        h = max(0.0, min(y1, ey1) - max(y0, ey0))
        share = max(1, int(counts[t]))
        if w > 0 and h > 0:
            spacing = math.sqrt(w * h / share)
        elif side > 0:  # sites on a line: spacing along it
            spacing = side / total
        else:  # every site at one place
            spacing = max(1.0, abs(ex0), abs(ey0))
        halos[t] = HALO_SPACINGS * spacing
    # a halo that rounds to nothing at the sites' magnitude would never grow a region
    scale = max(abs(ex0), abs(ey0), abs(ex1), abs(ey1))
    return np.maximum(halos, 4 * np.spacing(scale) if scale > 0 else 1e-300)


def certified(ring_xy: np.ndarray, offsets: np.ndarray, sites: np.ndarray, region: Region) -> np.ndarray:
    """(c,) bool: which cells no site outside ``region`` can cut.

    Cell k has the ring ``ring_xy[offsets[k]:offsets[k + 1]]`` and the site ``sites[k]``; ``region``
    is the closed rectangle whose every site the diagram was built from (sides may be infinite). An
    empty ring is certified: more sites only shrink a cell, so one that misses the box stays out.

    Why the test is sound. Let v* be a point of the exact local cell and v its double (a corner is
    exact; a Voronoi vertex or a box crossing is the double nearest v*, so |v - v*| <= ulp/2 in each
    coordinate). A site t outside the region lies strictly beyond one side, say x < x0, so
    |v* - t| > v*.x - x0. If v*.x - x0 >= |v* - s| for every side and every v*, no unseen site is
    nearer to a point of the ring than s, so none cuts the (convex) cell. The test bounds both sides
    with the doubles it has: v*.x - x0 >= (v.x - x0) - ulp(v.x)/2 from below, and
    |v* - s| <= |v - s| + ulp(v.x)/2 + ulp(v.y)/2 from above. The floating-point evaluation of
    (v.x - x0), of |v - s| (two differences and a hypot) and of the comparison errs by a few units
    of 2^-53 relative; the relative slack ``CERTIFY_RELATIVE`` (2^-40) covers them, and
    ``CERTIFY_ULPS`` ulps of the largest coordinate among the ring points, for each coordinate (an ulp
    only grows with the magnitude; plus the least subnormal, for results below the normal range) cover
    the ring's rounding. Any non-finite value fails the test: never certified.

    Most cells are settled without the test at each point: the room to the nearest side changes by at
    most |v - s| between s and v, so room(s) >= 2 max |v* - s| implies the test at every v*; the site's
    room and the farthest distance carry the same margins as above. The test runs in one compiled pass
    over the rings (``kernels.certify``); its distances are sqrt(dx^2 + dy^2), hypot where the squares
    could underflow or overflow, within a few units of 2^-53.
    """
    offsets = np.ascontiguousarray(offsets, np.int64)
    n_cells = len(offsets) - 1
    return _certify(
        offsets, np.arange(len(ring_xy), dtype=np.int32), ring_xy, sites, np.arange(n_cells, dtype=np.int64), region
    )


def _certify(
    offsets: np.ndarray, vertices: np.ndarray, points: np.ndarray, sites: np.ndarray, rows: np.ndarray, region: Region
) -> np.ndarray:
    """(len(rows),) bool: ``certified`` for the cells of ``rows`` of rings given as CSR offsets into vertex
    numbers of ``points``; ``sites`` indexed by row."""
    from tvoronoi.kernels.certify import certify_rings

    ok = np.zeros(len(rows), np.uint8)
    certify_rings(
        np.ascontiguousarray(offsets, np.int64),
        np.ascontiguousarray(vertices, np.int32),
        np.ascontiguousarray(points, np.float64).reshape(-1, 2),
        np.ascontiguousarray(sites, np.float64).reshape(-1, 2),
        np.ascontiguousarray(rows, np.int64),
        (float(region[0]), float(region[1]), float(region[2]), float(region[3])),
        CERTIFY_RELATIVE,
        CERTIFY_ULPS,
        ok,
    )
    return ok.view(bool)


def flower_box(ring_xy: np.ndarray, sites: np.ndarray) -> Region:
    """The bounding box of the disks centred at each ring point through its cell's site (the cells' "flowers").

    ``sites`` (K, 2) repeats each cell's site for each point of its ring (a site lies on its disks). A
    later build that sees every
    site of this box (grown by a margin for rounding) certifies the cells: with more sites a cell can
    only shrink, and a disk centred at a point w of a smaller cell through the site lies in the union of
    the disks at the larger cell's vertices (a half-plane {q : |q - p| <= |q - s|} that holds w holds a
    vertex of the larger convex cell).
    """
    with np.errstate(over="ignore", invalid="ignore"):
        r = np.hypot(ring_xy[:, 0] - sites[:, 0], ring_xy[:, 1] - sites[:, 1])
        lo = (ring_xy - r[:, None]).min(axis=0)
        hi = (ring_xy + r[:, None]).max(axis=0)
    return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


@dataclass(frozen=True)
class TileCells:
    """The cells one task certified: site ids, their rings in CSR form, and the ids left for a later round.

    ``ids`` (c,) int64 ascending, ``offsets`` (c + 1,) int64, ``ring_xy`` (K, 2) float64 (cell k is
    ``ring_xy[offsets[k]:offsets[k + 1]]``, as ``Diagram.cell_polygon``); ``pending`` (p,) int64.
    ``reaches`` (p, 4): for each pending cell, the box of what it needs seen (``flower_box``).
    """

    ids: np.ndarray
    offsets: np.ndarray
    ring_xy: np.ndarray
    pending: np.ndarray
    reaches: np.ndarray = field(default_factory=lambda: np.empty((0, 4)))

    def rings(self):
        """Iterate over (id, ring) pairs."""
        for k, i in enumerate(self.ids.tolist()):
            yield i, self.ring_xy[self.offsets[k] : self.offsets[k + 1]]


def build_tile(
    pts: np.ndarray,
    ids: np.ndarray,
    want: np.ndarray,
    region: Region,
    box,
    *,
    everything: bool = False,
    engine: str = "incremental",
    threads: int = 1,
    diagram=None,
) -> TileCells:
    """Build the diagram of the sites a task saw and certify the cells it must emit.

    Parameters
    ----------
    pts : (m, 2) float64
        Every site of ``region`` (closed), in ascending ``ids`` order, so that a repeated point's cell
        goes to its first row as in the whole diagram.
    ids : (m,) int64
        The sites' rows in the whole input, ascending.
    want : (m,) bool
        The sites whose cells this task emits (its tile's own sites still without a cell).
    region : (xmin, ymin, xmax, ymax)
        The closed rectangle whose every site is in ``pts``.
    box : the whole diagram's box
    everything : bool
        ``pts`` holds every site of the input: every cell is final.
    diagram : Diagram, optional
        The diagram of ``pts`` in ``box``, when already built (for the tile's Delaunay triangles too).
    """
    from tvoronoi.api import voronoi

    if not want.any():
        empty = np.empty(0, np.int64)
        return TileCells(empty, np.zeros(1, np.int64), np.empty((0, 2)), empty)
    d = voronoi(pts, bbox=box, engine=engine, threads=threads) if diagram is None else diagram
    verdict = certify_cells(d, pts, want, region, everything=everything)
    kept = verdict.kept
    # the kept cells' rings (a mask over the CSR points: cheaper than an index when most are kept)
    all_lengths = np.diff(d.cell_offsets)
    offsets = np.zeros(len(kept) + 1, np.int64)
    np.cumsum(all_lengths[kept], out=offsets[1:])
    if len(kept) == len(pts):
        vertices = d.cell_vertices
    else:
        mask = np.zeros(len(pts), bool)
        mask[kept] = True
        vertices = d.cell_vertices[np.repeat(mask, all_lengths)]
    return TileCells(
        ids[kept].astype(np.int64),
        offsets,
        np.take(d.cell_points, vertices, axis=0),
        ids[verdict.failed].astype(np.int64),
        verdict.reaches,
    )


@dataclass(frozen=True)
class Verdict:
    """Which wanted cells of a tile's diagram are certified: ``kept`` and ``failed`` are rows of the
    diagram (ascending); ``reaches`` (f, 4) the box each failed cell needs seen (``flower_box``)."""

    kept: np.ndarray
    failed: np.ndarray
    reaches: np.ndarray


def certify_cells(diagram, pts: np.ndarray, want: np.ndarray, region: Region, *, everything: bool = False) -> Verdict:
    """Certify the cells of the ``want`` rows of a tile's diagram (as ``build_tile``, without gathering
    their rings: a writer takes the kept cells from the diagram a row group at a time).

    The test reads the rings where the diagram holds them, in one compiled pass (``certified``).
    """
    rows = np.flatnonzero(want)
    if everything or len(rows) == 0:
        return Verdict(rows, np.empty(0, np.int64), np.empty((0, 4)))
    offsets = diagram.cell_offsets
    ok = _certify(offsets, diagram.cell_vertices, diagram.cell_points, pts, rows, region)
    failed = rows[~ok]
    reaches = np.empty((len(failed), 4))
    for j, i in enumerate(failed.tolist()):
        ring = diagram.cell_points[diagram.cell_vertices[offsets[i] : offsets[i + 1]]]
        reaches[j] = flower_box(ring, np.repeat(pts[i][None], len(ring), axis=0))
    return Verdict(rows[ok], failed, reaches)


def group_reaches(pending: np.ndarray, reaches: np.ndarray, margin: float) -> list[tuple[np.ndarray, Region]]:
    """Gather pending cells whose reaches, grown by ``margin``, overlap: [(ids, box)], one build each.

    Cells at opposite ends of a tile are rebuilt apart, each with the few sites around it, instead of
    in one box spanning the tile.
    """
    boxes = [list(grown(r, margin)) for r in reaches]
    members = [[k] for k in range(len(boxes))]
    merged = True
    while merged:
        merged = False
        for a in range(len(boxes)):
            if not members[a]:
                continue
            for b in range(a + 1, len(boxes)):
                if members[b] and _overlap(boxes[a], boxes[b]):
                    boxes[a] = [
                        min(boxes[a][0], boxes[b][0]),
                        min(boxes[a][1], boxes[b][1]),
                        max(boxes[a][2], boxes[b][2]),
                        max(boxes[a][3], boxes[b][3]),
                    ]
                    members[a] += members[b]
                    members[b] = []
                    merged = True
    out = []
    for ks in members:
        if ks:
            r = reaches[ks]
            box = (float(r[:, 0].min()), float(r[:, 1].min()), float(r[:, 2].max()), float(r[:, 3].max()))
            out.append((np.sort(pending[ks]), box))
    return out


def _overlap(a, b) -> bool:
    return not (a[2] < b[0] or b[2] < a[0] or a[3] < b[1] or b[3] < a[1])


@dataclass(frozen=True)
class Plan:
    """How the sites are tiled: the tiles' rectangles, their first halos, the sites' extent and the box."""

    rects: np.ndarray
    halos: np.ndarray
    extent: Region
    box: Region

    @property
    def n_tiles(self) -> int:
        return len(self.rects)

    def region(self, t: int, round_: int = 1, reach: Region | None = None) -> Region:
        """The closed rectangle tile t's task sees in round ``round_`` (1, 2, ...).

        The first round sees the tile grown by its halo; a later one the ``reach`` of a group of cells
        still pending (``group_reaches``: what they need seen) grown by the halo doubled once per round
        (a margin far above the certification's rounding slack, so every round makes progress).
        """
        if reach is None:
            return grown(self.rects[t], float(self.halos[t]))
        return grown(reach, self.margin(t, round_ - 1))

    def margin(self, t: int, round_: int) -> float:
        """How far beyond its reach a group of cells left after round ``round_`` is seen next."""
        return float(self.halos[t]) * 2.0**round_

    def sees_everything(self, region: Region) -> bool:
        return covers(region, self.extent)


def plan_tiles(sample: np.ndarray, n_tiles: int, extent: Region, box: Region, n_sites: int) -> Plan:
    """Cut the plane from a sample of the ``n_sites`` sites, and give each tile its first halo."""
    rects = kd_rects(sample, n_tiles)
    in_sample = np.bincount(tile_of(sample[:, 0], sample[:, 1], rects), minlength=len(rects))
    counts = in_sample * (n_sites / max(1, len(sample)))
    return Plan(rects, first_halos(rects, counts, extent), extent, box)


def extent_of(pts: np.ndarray) -> Region:
    """The sites' bounding box (closed; a point for one site)."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def default_tiles(n: int, workers: int = 1) -> int:
    """Tiles for n sites on ``workers`` workers: a few per worker, each of at least 100,000 sites when n allows."""
    by_size = max(1, n // 1_000_000)
    return max(1, min(max(by_size, 4 * workers), max(1, n // 100_000)))


@dataclass
class TiledCells:
    """Every cell of a tiled build, in site order, and how many rounds each tile needed."""

    ids: np.ndarray
    offsets: np.ndarray
    ring_xy: np.ndarray
    rounds: int
    pending_after: list[int] = field(default_factory=list)

    def ring(self, k: int) -> np.ndarray:
        return self.ring_xy[self.offsets[k] : self.offsets[k + 1]]


def concat_cells(parts: list[TileCells]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Join tiles' cells and put them in site order: (ids, offsets, ring_xy)."""
    ids = np.concatenate([p.ids for p in parts]) if parts else np.empty(0, np.int64)
    lengths = np.concatenate([np.diff(p.offsets) for p in parts]) if parts else np.empty(0, np.int64)
    ring_xy = np.concatenate([p.ring_xy for p in parts]) if parts else np.empty((0, 2))
    starts = np.zeros(len(lengths), np.int64)
    np.cumsum(lengths[:-1], out=starts[1:])
    order = np.argsort(ids, kind="stable")
    lengths = lengths[order]
    offsets = np.zeros(len(ids) + 1, np.int64)
    np.cumsum(lengths, out=offsets[1:])
    gather = np.repeat(starts[order] - offsets[:-1], lengths) + np.arange(offsets[-1])
    return ids[order], offsets, ring_xy[gather]


def tiled_cells(
    points, *, tiles: int, bbox=None, engine: str = "incremental", seed: int = 0, halo_scale: float = 1.0
) -> TiledCells:
    """Every clipped cell of ``voronoi(points, bbox=bbox)``, built tile by tile in this process.

    The reference of the distributed build, and a way to test the tiling with plain calls.
    ``halo_scale`` multiplies the first halos (a small value forces more rounds).

    Returns
    -------
    TiledCells
        Cells in site order (``ids`` is 0..n-1), the rounds run, and the cells still pending after
        each round.
    """
    from tvoronoi.api import as_bbox, as_points, default_bbox

    pts = as_points(points)
    n = len(pts)
    if n == 0:
        return TiledCells(np.empty(0, np.int64), np.zeros(1, np.int64), np.empty((0, 2)), 0)
    box = default_bbox(pts) if bbox is None else as_bbox(bbox)
    rng = np.random.default_rng(seed)
    take = min(n, SAMPLE_PER_TILE * tiles)
    sample = pts[np.sort(rng.choice(n, take, replace=False))] if take < n else pts
    plan = plan_tiles(sample, tiles, extent_of(pts), box, n)
    plan = Plan(plan.rects, plan.halos * halo_scale, plan.extent, plan.box)
    ids = np.arange(n, dtype=np.int64)
    owner = tile_of(pts[:, 0], pts[:, 1], plan.rects)
    todo = np.ones(n, bool)
    parts: list[TileCells] = []
    pending_after: list[int] = []
    # a unit of work: a tile, and in later rounds a group of its pending cells with the box they need
    units: list[tuple[int, np.ndarray | None, Region | None]] = [(t, None, None) for t in range(plan.n_tiles)]
    round_ = 0
    while units:
        round_ += 1
        if round_ > MAX_ROUNDS:
            raise TvoronoiError("the tiles' regions stopped growing before every cell was certified")
        next_units: list[tuple[int, np.ndarray | None, Region | None]] = []
        for t, group, reach in units:
            region = plan.region(t, round_, reach)
            rows = np.flatnonzero(in_region(pts[:, 0], pts[:, 1], region))
            want = (owner[rows] == t) if group is None else np.isin(ids[rows], group)
            cells = build_tile(
                pts[rows],
                ids[rows],
                want & todo[rows],
                region,
                box,
                everything=plan.sees_everything(region),
                engine=engine,
            )
            todo[cells.ids] = False
            parts.append(cells)
            next_units += [(t, g, b) for g, b in group_reaches(cells.pending, cells.reaches, plan.margin(t, round_))]
        units = next_units
        pending_after.append(int(todo.sum()))
    out_ids, offsets, ring_xy = concat_cells(parts)
    return TiledCells(out_ids, offsets, ring_xy, round_, pending_after)
