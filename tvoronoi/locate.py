"""Nearest-site queries on a Diagram: scaled sites, start sites from a coarse grid, the kernel's walk."""

from __future__ import annotations

import math

import numpy as np

from tvoronoi.api import check_range
from tvoronoi.engines import scale_exponent
from tvoronoi.errors import TvoronoiError

# Sites per cell of the grid that picks each query's starting site (a heuristic: the answer never depends on it,
# only the length of the walk does).
SITES_PER_BUCKET = 2.0


class SiteLocator:
    """What nearest-site queries on one diagram share: scaled sites, the half-edges, the start grid."""

    def __init__(self, diagram):
        sites = np.asarray(diagram.sites, np.float64)
        self.n_sites = len(sites)
        self.e = scale_exponent(sites)
        self.scaled = np.ascontiguousarray(np.ldexp(sites, -self.e))
        # the Voronoi neighbour graph (the Delaunay graph): the kernel reads it off the half-edges
        self.face_edge = np.ascontiguousarray(diagram.face_edge, np.int32)
        self.he_next = np.ascontiguousarray(diagram.he_next, np.int32)
        self.he_twin = np.ascontiguousarray(diagram.he_twin, np.int32)
        self.he_face = np.ascontiguousarray(diagram.he_face, np.int32)
        distinct = _graph_nodes(diagram)
        self.first = int(distinct[0]) if len(distinct) else -1
        # a grid over the sites' bounding box, each cell holding one of its sites, or -1 until filled below
        side = max(1, math.ceil(math.sqrt(len(distinct) / SITES_PER_BUCKET)))
        self.side = side
        self.lo = sites.min(axis=0) if len(sites) else np.zeros(2)
        extent = (sites.max(axis=0) - self.lo) if len(sites) else np.ones(2)
        with np.errstate(divide="ignore"):
            self.per_unit = np.where(extent > 0, side / extent, 0.0)
        self.bucket_site = np.full(side * side, -1, np.int32)
        self.bucket_site[self._buckets(sites[distinct])[::-1]] = distinct[::-1]
        # an empty cell takes a site of the nearest full cell in its row (or, in an empty row, in its column):
        # every walk then starts nearby
        grid = self.bucket_site.reshape(side, side)
        grid = _fill_along(_fill_along(grid, axis=1), axis=0)
        self.bucket_site = np.ascontiguousarray(grid.ravel())

    def _buckets(self, xy: np.ndarray) -> np.ndarray:
        with np.errstate(over="ignore", invalid="ignore"):
            cell = np.clip((xy - self.lo) * self.per_unit, 0, self.side - 1)
        cell = np.nan_to_num(cell, nan=0.0).astype(np.int64)
        return cell[:, 1] * self.side + cell[:, 0]

    def locate(self, xs, ys) -> np.ndarray:
        """See Diagram.locate."""
        from tvoronoi.kernels.nearest import nearest_sites

        try:
            qx = np.asarray(xs, np.float64)
            qy = np.asarray(ys, np.float64)
        except (TypeError, ValueError) as exc:
            raise TvoronoiError(f"query coordinates must be numbers: {exc}") from None
        try:
            qx, qy = np.broadcast_arrays(qx, qy)
        except ValueError:
            raise TvoronoiError(f"xs and ys must have the same shape, got {qx.shape} and {qy.shape}") from None
        shape = qx.shape
        q = np.stack([qx.ravel(), qy.ravel()], axis=1)
        bad = ~np.isfinite(q).all(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise TvoronoiError(f"query point {k} is ({q[k, 0]!r}, {q[k, 1]!r}): coordinates must be finite")
        if self.first < 0:
            raise TvoronoiError("the diagram has no sites: there is no nearest site to locate")
        check_range(q, self.e, what="query point", scale_of="the diagram")
        scaled = np.ldexp(q, -self.e)
        buckets = self._buckets(q)
        # queries in grid order: consecutive walks touch nearby sites (a few times faster on large inputs)
        order = np.argsort(buckets, kind="stable")
        start = self.bucket_site[buckets[order]]
        found = np.empty(len(q), np.int32)
        mark = np.full(self.n_sites, -1, np.int64)
        stack = np.empty(self.n_sites, np.int32)
        nearest_sites(
            self.scaled,
            self.face_edge,
            self.he_next,
            self.he_twin,
            self.he_face,
            np.ascontiguousarray(scaled[order, 0]),
            np.ascontiguousarray(scaled[order, 1]),
            start,
            self.first,
            found,
            mark,
            stack,
        )
        out = np.empty(len(q), np.int32)
        out[order] = found
        return out.reshape(shape)


def _graph_nodes(diagram) -> np.ndarray:
    """The rows a walk may visit: those with a cell edge; else (a lone site) the row with a cell; else the
    first copies. Repeated points, and the rows of removed sites in a dynamic diagram, are never answers."""
    for rows in (
        np.flatnonzero(np.asarray(diagram.face_edge) >= 0),
        np.flatnonzero(np.diff(np.asarray(diagram.cell_offsets)) > 0),
        np.flatnonzero(np.asarray(diagram.site_of) == np.arange(diagram.n_sites)),
    ):
        if len(rows):
            return rows
    return np.empty(0, np.intp)


def _fill_along(grid: np.ndarray, axis: int) -> np.ndarray:
    """Replace each -1 with the nearest entry that is not -1 along the axis (the earlier one on a tie)."""
    n = grid.shape[axis]
    index = np.arange(n).reshape((1, n) if axis == 1 else (n, 1))
    full = grid >= 0
    before = np.maximum.accumulate(np.where(full, index, -1), axis=axis)
    after = np.flip(np.minimum.accumulate(np.flip(np.where(full, index, n), axis=axis), axis=axis), axis=axis)
    use_after = (before < 0) | ((after < n) & (after - index < index - before))
    pick = np.where(use_after, after, before)
    pick = np.where((pick < 0) | (pick >= n), index, pick)  # nothing full along this line: leave it
    return np.take_along_axis(grid, pick, axis=axis)
