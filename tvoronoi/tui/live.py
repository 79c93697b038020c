"""A diagram edited in place through dynamic updates, kept in the form the rasterizer draws.

Each edit touches only the cells the dynamic diagram reports as changed:
their sides are rewritten in a segment pool (a side shared by two cells is
drawn by the smaller id), their neighbours read again, their colours checked
against those neighbours (the other cells keep theirs), and the region they
cover is logged so that the canvas draws again only the characters there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from tvoronoi.tui.colours import cell_adjacency, repair_colours
from tvoronoi.tui.scene import ring_next, ring_segments
from tvoronoi.tui.viewport import char_centres

# A ring point within this fraction of the box size of a box side lies on it.
ON_BOX = 1e-9
# Changes the log keeps for the canvas to catch up with; a canvas further
# behind finds every owner again.
LOG_LENGTH = 64
# Up to this many points, nearest() measures every site rather than rebuild an outdated k-d tree.
FEW_POINTS = 8


class SegmentPool:
    """Segments (x0, y0, x1, y1) grouped in slots by id, each slot rewritable in place.

    A slot that outgrows its room moves to the end of the pool; the place
    it leaves is set to NaN (the rasterizer skips NaN segments). The pool is
    compacted when more than half of it is NaN.
    """

    def __init__(self, segments: np.ndarray, offsets: np.ndarray) -> None:
        self._data = np.asarray(segments, np.float64).reshape(-1, 4).copy()
        self._start = np.asarray(offsets[:-1], np.int64).copy()
        self._count = np.diff(offsets).astype(np.int64)
        self._room = self._count.copy()
        self._end = len(self._data)

    @property
    def array(self) -> np.ndarray:
        return self._data[: self._end]

    @property
    def n_used(self) -> int:
        return int(self._count.sum())

    def get(self, i: int) -> np.ndarray:
        if i >= len(self._start):
            return np.empty((0, 4))
        return self._data[self._start[i] : self._start[i] + self._count[i]]

    def _grow_ids(self, n: int) -> None:
        if n <= len(self._start):
            return
        extra = n - len(self._start)
        self._start = np.concatenate([self._start, np.full(extra, self._end, np.int64)])
        self._count = np.concatenate([self._count, np.zeros(extra, np.int64)])
        self._room = np.concatenate([self._room, np.zeros(extra, np.int64)])

    def set(self, i: int, segments: np.ndarray) -> None:
        """Make slot i hold these segments."""
        segments = np.asarray(segments, np.float64).reshape(-1, 4)
        self._grow_ids(i + 1)
        k = len(segments)
        start, room = self._start[i], self._room[i]
        if k <= room:
            self._data[start : start + k] = segments
            self._data[start + k : start + room] = np.nan
            self._count[i] = k
            return
        self._data[start : start + room] = np.nan
        if self._end + k > len(self._data):
            bigger = np.full((max(2 * len(self._data), self._end + k, 64), 4), np.nan)
            bigger[: self._end] = self._data[: self._end]
            self._data = bigger
        self._start[i], self._count[i], self._room[i] = self._end, k, k
        self._data[self._end : self._end + k] = segments
        self._end += k
        if self._end > 2 * self.n_used + 64:
            self._compact()

    def _compact(self) -> None:
        counts = self._count
        offsets = np.zeros(len(counts) + 1, np.int64)
        np.cumsum(counts, out=offsets[1:])
        keep = np.concatenate(
            [np.arange(s, s + c) for s, c in zip(self._start.tolist(), counts.tolist())] + [np.empty(0, np.int64)]
        ).astype(np.int64)
        data = self._data[keep]
        self._data = np.concatenate([data, np.full((max(len(data) // 2, 64), 4), np.nan)])
        self._start, self._room, self._end = offsets[:-1].copy(), counts.copy(), len(data)


@dataclass(frozen=True)
class Change:
    """One update: the cells it changed and the world box around their old and new shapes."""

    version: int
    ids: np.ndarray
    box: tuple[float, float, float, float] | None


class LiveScene:
    """The drawable form of a ``DynamicVoronoi``, updated cell by cell.

    Rows of ``sites`` and ``colours`` are the dynamic diagram's ids (NaN
    rows for removed ids), so the rasterizer's owner of a character is an id.

    Parameters
    ----------
    dynamic : DynamicVoronoi
        Made from the same points as ``diagram`` and with its box.
    diagram : Diagram
        The diagram of the points at the start (its cells, neighbours).
    colours : (n,) int8
        The cell colours of ``diagram``, kept where they stay valid.
    """

    def __init__(self, dynamic, diagram, colours: np.ndarray) -> None:
        self.dynamic = dynamic
        self.bbox = tuple(float(c) for c in diagram.bbox)
        n = diagram.n_sites
        self._sites = np.asarray(diagram.sites, np.float64).copy()
        self._alive = np.ones(n, bool)
        self._colours = np.asarray(colours, np.int8).copy()
        offsets = np.asarray(diagram.cell_offsets, np.int64)
        ring = np.asarray(diagram.cell_vertices, np.int64)
        points = np.asarray(diagram.cell_points, np.float64)
        sizes = np.diff(offsets)
        full = sizes > 0
        nxt = ring_next(offsets, ring.size)
        segs = np.hstack([points[ring], points[ring[nxt]]]) if ring.size else np.empty((0, 4))
        owner = np.repeat(np.arange(n), sizes)
        # each side shared by two cells is kept by the smaller id, as the updates do
        key = np.minimum(ring, ring[nxt]) * max(len(points), 1) + np.maximum(ring, ring[nxt])
        order = np.lexsort((owner, key))
        first = np.ones(order.size, bool)
        first[1:] = key[order][1:] != key[order][:-1]
        keep = np.zeros(order.size, bool)
        keep[order[first]] = True
        kept = np.zeros(n + 1, np.int64)
        np.cumsum(np.bincount(owner[keep], minlength=n), out=kept[1:])
        self._cells = SegmentPool(segs[keep], kept)
        self._has_cell = sizes > 0
        # the box around each cell
        self._boxes = np.full((n, 4), np.nan)
        if ring.size:
            starts = offsets[:-1][full]
            xy = points[ring]
            self._boxes[full, 0] = np.minimum.reduceat(xy[:, 0], starts)
            self._boxes[full, 1] = np.minimum.reduceat(xy[:, 1], starts)
            self._boxes[full, 2] = np.maximum.reduceat(xy[:, 0], starts)
            self._boxes[full, 3] = np.maximum.reduceat(xy[:, 1], starts)
        # neighbours from the half-edges, and Delaunay links to larger ids
        a, b = cell_adjacency(diagram)
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        order = np.argsort(lo, kind="stable")
        lo, hi = lo[order], hi[order]
        link_offsets = np.zeros(n + 1, np.int64)
        np.cumsum(np.bincount(lo, minlength=n), out=link_offsets[1:])
        sites = self._sites
        self._links = SegmentPool(np.hstack([sites[lo], sites[hi]]) if len(lo) else np.empty((0, 4)), link_offsets)
        self.version = 0
        self._log: list[Change] = []
        self._drawn: np.ndarray | None = None
        self._tree: cKDTree | None = None

    # -- what the rasterizer reads --------------------------------------------

    @property
    def sites(self) -> np.ndarray:
        return self._sites

    @property
    def colours(self) -> np.ndarray:
        return self._colours

    @property
    def n_sites(self) -> int:
        """Number of sites alive."""
        return int(self._alive.sum())

    @property
    def edges(self) -> np.ndarray:
        return self._cells.array

    @property
    def edge_mesh(self) -> None:
        """The edges are kept cell by cell, as segments (``edges``)."""
        return None

    @property
    def delaunay(self) -> np.ndarray:
        return self._links.array

    @property
    def vertices(self) -> np.ndarray:
        """Ends of the cell sides strictly inside the box (a Voronoi vertex comes once per side)."""
        ends = self._cells.array.reshape(-1, 2)
        xmin, ymin, xmax, ymax = self.bbox
        inside = (ends[:, 0] > xmin) & (ends[:, 0] < xmax) & (ends[:, 1] > ymin) & (ends[:, 1] < ymax)
        return ends[inside]

    @property
    def n_vertices(self) -> int:
        # about three sides meet at each vertex
        return 2 * self._cells.n_used // 3

    def site_ids(self) -> None:
        return None

    def drawn(self) -> np.ndarray:
        """Ids of the sites that own a cell (alive, not a repeated place, inside the box)."""
        if self._drawn is None:
            self._drawn = np.flatnonzero(self._alive[: len(self._has_cell)] & self._has_cell)
        return self._drawn

    def nearest(self, points: np.ndarray) -> np.ndarray:
        """The id of the cell owner nearest each point (k, 2).

        A few points (the inspector's one) are measured against every site
        while the k-d tree is out of date, rather than rebuilding it after
        every edit; a whole frame's characters build it again.
        """
        ids = self.drawn()
        points = np.asarray(points, np.float64).reshape(-1, 2)
        if self._tree is None and len(points) <= FEW_POINTS and len(ids):
            sites = self._sites[ids]
            d2 = [((sites - p) ** 2).sum(axis=1) for p in points]
            return ids[np.array([int(np.argmin(d)) for d in d2], np.int64)]
        if self._tree is None:
            self._tree = cKDTree(self._sites[ids] if len(ids) else np.zeros((0, 2)))
        _, k = self._tree.query(points)
        return ids[k]

    def site_near(self, x: float, y: float, radius: float) -> int | None:
        """The id of the live site nearest (x, y) within ``radius``, or None."""
        alive = np.flatnonzero(self._alive)
        if not len(alive):
            return None
        d2 = ((self._sites[alive] - (x, y)) ** 2).sum(axis=1)
        k = int(np.argmin(d2))
        return int(alive[k]) if d2[k] <= radius * radius else None

    def alive(self, i: int) -> bool:
        return 0 <= i < len(self._alive) and bool(self._alive[i])

    def points(self) -> np.ndarray:
        """The live sites, by increasing id."""
        return self._sites[self._alive].copy()

    # -- edits ---------------------------------------------------------------

    def insert(self, x: float, y: float) -> int:
        i = int(self.dynamic.insert(x, y))
        self._update([i])
        return i

    def remove(self, i: int) -> None:
        self.dynamic.remove(i)
        self._update([i])

    def move(self, i: int, x: float, y: float) -> None:
        self.dynamic.move(i, x, y)
        self._update([i])

    def _update(self, edited: list[int]) -> None:
        """Bring the changed cells up to date with the dynamic diagram."""
        d = self.dynamic.diagram()
        changed = np.union1d(np.asarray(self.dynamic.changed, np.int64), np.asarray(edited, np.int64))
        self._grow(len(d.sites))
        sites = np.asarray(d.sites, np.float64)
        alive = np.asarray(d.alive, bool)
        # the boxes of the changed cells before
        boxes = [self._cell_box(i) for i in changed.tolist()]
        boxes += [_segments_box(self._links.get(i)) for i in changed.tolist()]
        self._sites[: len(sites)] = sites
        self._alive[: len(alive)] = alive
        near_of = {}
        for i in changed.tolist():
            ring = d.cell_polygon(i) if alive[i] else np.empty((0, 2))
            self._has_cell[i] = len(ring) > 0
            self._boxes[i] = (
                (ring[:, 0].min(), ring[:, 1].min(), ring[:, 0].max(), ring[:, 1].max()) if len(ring) else np.nan
            )
            near = np.asarray(d.neighbours(i), np.int64) if len(ring) else np.empty(0, np.int64)
            near = near_of[i] = near[self._alive[near]]
            # a side shared with a smaller id is that cell's to draw
            sides = ring_segments(ring)
            across = self._across(i, sides, near)
            self._cells.set(i, sides[(across < 0) | (across > i)])
            # the Delaunay links to larger ids
            up = near[near > i]
            self._links.set(i, np.hstack([np.repeat(self._sites[[i]], len(up), axis=0), self._sites[up]]))
            boxes += [self._cell_box(i), _point_box(self._sites[i]), _segments_box(self._links.get(i))]
        # colours: the new cells, and the changed cells that now touch their own colour
        todo = changed[self._alive[changed]]
        repair_colours(self._colours, near_of.__getitem__, todo.tolist())
        self._drawn = None
        self._tree = None
        self.version += 1
        self._log.append(Change(self.version, changed, _union(boxes)))
        del self._log[:-LOG_LENGTH]

    def _grow(self, n: int) -> None:
        have = len(self._alive)
        if n <= have:
            return
        extra = n - have
        self._sites = np.concatenate([self._sites, np.full((extra, 2), np.nan)])
        self._alive = np.concatenate([self._alive, np.zeros(extra, bool)])
        self._colours = np.concatenate([self._colours, np.full(extra, -1, np.int8)])
        self._has_cell = np.concatenate([self._has_cell, np.zeros(extra, bool)])
        self._boxes = np.concatenate([self._boxes, np.full((extra, 4), np.nan)])

    def _cell_box(self, i: int):
        if i >= len(self._boxes) or not np.isfinite(self._boxes[i]).all():
            return None
        return tuple(float(c) for c in self._boxes[i])

    def _across(self, i: int, segs: np.ndarray, candidates: np.ndarray) -> np.ndarray:
        """The cell across each side of cell i: the candidate nearest the side's midpoint, i aside;
        -1 for a side on the box or of no length."""
        across = np.full(len(segs), -1, np.int64)
        others = candidates[candidates != i]
        if not len(segs) or not len(others):
            return across
        xmin, ymin, xmax, ymax = self.bbox
        tol = ON_BOX * max(xmax - xmin, ymax - ymin, 1e-300)
        x0, y0, x1, y1 = segs.T
        on_box = (
            ((np.abs(x0 - xmin) <= tol) & (np.abs(x1 - xmin) <= tol))
            | ((np.abs(x0 - xmax) <= tol) & (np.abs(x1 - xmax) <= tol))
            | ((np.abs(y0 - ymin) <= tol) & (np.abs(y1 - ymin) <= tol))
            | ((np.abs(y0 - ymax) <= tol) & (np.abs(y1 - ymax) <= tol))
        )
        inner = ~on_box & ((x0 != x1) | (y0 != y1))
        if inner.any():
            mid = np.column_stack([(x0 + x1)[inner] / 2, (y0 + y1)[inner] / 2])
            d2 = ((mid[:, None, :] - self._sites[others][None, :, :]) ** 2).sum(axis=2)
            across[inner] = others[np.argmin(d2, axis=1)]
        return across

    # -- what the canvas asks between frames ----------------------------------------

    def changes_since(self, version: int):
        """(ids, world box) of what the updates after ``version`` changed; None if the log no longer
        reaches back that far. The box is None when nothing changed."""
        if version == self.version:
            return np.empty(0, np.int64), None
        changes = [c for c in self._log if c.version > version]
        if not changes or changes[0].version != version + 1:
            return None
        return np.unique(np.concatenate([c.ids for c in changes])), _union([c.box for c in changes])

    def update_owner(self, old: np.ndarray, ids: np.ndarray, view, cols: int, rows: int) -> np.ndarray:
        """The owners of a canvas of ``cols x rows`` characters whose owners before the updates
        that changed ``ids`` were ``old``: each character keeps its old owner unless a changed
        cell is nearer (a character changes hands only between changed cells)."""
        xs, ys = char_centres(view, cols, rows)
        gx, gy = np.meshgrid(xs, ys)
        xmin, ymin, xmax, ymax = self.bbox
        inside = (gx >= xmin) & (gx <= xmax) & (gy >= ymin) & (gy <= ymax)
        old = np.asarray(old, np.int64)
        n = len(self._alive)
        valid = (old >= 0) & (old < n)
        valid[valid] = self._alive[old[valid]] & self._has_cell[old[valid]]
        owner = np.where(valid, old, -1)
        safe = np.where(valid, old, 0)
        best = np.where(valid, (gx - self._sites[safe, 0]) ** 2 + (gy - self._sites[safe, 1]) ** 2, np.inf)
        ids = np.asarray(ids, np.int64)
        ids = ids[(ids >= 0) & (ids < n)]
        ids = ids[self._alive[ids] & self._has_cell[ids]]
        if len(ids):
            d2 = (gx[..., None] - self._sites[ids, 0]) ** 2 + (gy[..., None] - self._sites[ids, 1]) ** 2
            k = np.argmin(d2, axis=2)
            near = np.take_along_axis(d2, k[..., None], axis=2)[..., 0]
            closer = near < best
            owner[closer] = ids[k[closer]]
        owner[~inside] = -1
        return owner

    def to_diagram(self):
        """The full Diagram of the live sites (O(n)), for saving."""
        return self.dynamic.diagram().to_diagram()


def _segments_box(segs: np.ndarray) -> tuple | None:
    if not len(segs):
        return None
    xs, ys = segs[:, [0, 2]], segs[:, [1, 3]]
    return (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))


def _point_box(p) -> tuple | None:
    x, y = float(p[0]), float(p[1])
    if not (np.isfinite(x) and np.isfinite(y)):
        return None
    return (x, y, x, y)


def _union(boxes) -> tuple | None:
    boxes = [b for b in boxes if b is not None]
    if not boxes:
        return None
    arr = np.asarray(boxes, np.float64)
    return (float(arr[:, 0].min()), float(arr[:, 1].min()), float(arr[:, 2].max()), float(arr[:, 3].max()))
