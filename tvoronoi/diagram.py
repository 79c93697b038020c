"""The Diagram: sites, Voronoi vertices, the half-edge structure, clipped cells and the Delaunay dual."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True, eq=False)
class Diagram:
    """A Voronoi diagram of n input points, bounded by a box.

    Cell i is always input point i. Points that repeat an earlier point share
    its cell: their own cell is empty and ``site_of`` names the first copy.

    Attributes
    ----------
    sites : (n, 2) float64
        The input points, in input order.
    site_of : (n,) int32
        The first input row with the same coordinates (itself if unique).
    vertices : (m, 2) float64
        Voronoi vertices (unclipped), one per distinct circumcircle.
    he_origin, he_twin, he_face : (h,) int32
        The half-edge structure (DCEL). ``he_origin`` is -1 for a half-edge
        coming from infinity. Half-edge h lies on the bisector of
        ``he_face[h]`` and ``he_face[he_twin[h]]``. The half-edges of a
        cell are consecutive, counter-clockwise from ``face_edge`` (through
        infinity for an unbounded cell): ``he_next`` and ``he_prev``,
        derived on first use, follow that order.
    face_edge : (n,) int32
        The first half-edge of each cell, -1 where the cell has none (a lone
        site, a repeated point).
    triangles : (k, 3) int32
        Delaunay triangles (input rows, counter-clockwise).
    bbox : (xmin, ymin, xmax, ymax)
        The box the cells are clipped to.
    cell_points : (p, 2) float64
        Points of the clipped cells (vertices inside the box, points on the
        box, corners); neighbouring cells share identical points.
    cell_offsets : (n + 1,) int64, cell_vertices : (K,) int32
        Clipped cells in CSR form: cell i is
        ``cell_points[cell_vertices[cell_offsets[i]:cell_offsets[i + 1]]]``.
    engine : str
        The engine that built the diagram.
    crs : optional
        The coordinates' CRS when the input carried one (a GeoSeries or GeoDataFrame with a ``crs``), as
        it gave it; None otherwise. :meth:`to_geopandas` uses it unless given another.
    """

    sites: np.ndarray
    site_of: np.ndarray
    vertices: np.ndarray
    he_origin: np.ndarray
    he_twin: np.ndarray
    he_face: np.ndarray
    face_edge: np.ndarray
    triangles: np.ndarray
    bbox: tuple
    cell_points: np.ndarray
    cell_offsets: np.ndarray
    cell_vertices: np.ndarray
    engine: str = "incremental"
    crs: object = None

    @cached_property
    def he_next(self) -> np.ndarray:
        """(h,) int32: the next half-edge counter-clockwise around the same cell."""
        f = self.he_face
        nxt = np.arange(1, len(f) + 1, dtype=np.int32)
        last = np.ones(len(f), bool)  # the last half-edge of its cell
        last[:-1] = f[1:] != f[:-1]
        nxt[last] = self.face_edge[f[last]]
        return nxt

    @cached_property
    def he_prev(self) -> np.ndarray:
        """(h,) int32: the previous half-edge around the same cell."""
        prev = np.empty(len(self.he_next), np.int32)
        prev[self.he_next] = np.arange(len(self.he_next), dtype=np.int32)
        return prev

    @property
    def n_sites(self) -> int:
        """Number of input points (repeated points included)."""
        return len(self.sites)

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_edges(self) -> int:
        """Number of Voronoi edges (each is two half-edges)."""
        return len(self.he_origin) // 2

    def cell_polygon(self, i: int) -> np.ndarray:
        """Cell i clipped to the box, as a (k, 2) ring.

        Counter-clockwise, first vertex not repeated; empty (shape (0, 2)) for
        a repeated point and for a cell that misses the box.

        >>> import tvoronoi
        >>> d = tvoronoi.voronoi([[0, 0], [2, 0]], bbox=(-1, -1, 3, 1))
        >>> d.cell_polygon(0).tolist()
        [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        """
        i = int(i)
        if not -self.n_sites <= i < self.n_sites:
            raise IndexError(f"site {i} out of range for a diagram of {self.n_sites} sites")
        i %= self.n_sites
        lo, hi = self.cell_offsets[i], self.cell_offsets[i + 1]
        return self.cell_points[self.cell_vertices[lo:hi]]

    def cells(self):
        """Iterate over (i, ring) for every cell, rings as in cell_polygon."""
        for i in range(self.n_sites):
            yield i, self.cell_polygon(i)

    def delaunay_triangles(self) -> np.ndarray:
        """The Delaunay triangles as a (k, 3) int32 array of input rows, counter-clockwise.

        Where four or more sites are cocircular, one of the valid
        triangulations is given.
        """
        return self.triangles.copy()

    def duplicates(self) -> dict[int, list[int]]:
        """Map each repeated site's first row to the later rows at the same place."""
        rows = np.flatnonzero(self.site_of != np.arange(self.n_sites))
        groups: dict[int, list[int]] = {}
        for r in rows.tolist():
            groups.setdefault(int(self.site_of[r]), []).append(r)
        return groups

    def half_edge_cycle(self, i: int) -> np.ndarray:
        """Half-edges of cell i in counter-clockwise order (empty if it has none)."""
        start = int(self.face_edge[i])
        if start < 0:
            return np.empty(0, np.int32)
        out = [start]
        h = int(self.he_next[start])
        while h != start:
            out.append(h)
            h = int(self.he_next[h])
        return np.asarray(out, np.int32)

    def to_shapely(self) -> np.ndarray:
        """The cells as shapely Polygons, one per input row, built in one call.

        Returns
        -------
        ndarray of shape (n,), dtype object
            Polygon i has the counter-clockwise exterior ring of
            ``cell_polygon(i)``, closed; it is None for a row without a cell
            (a repeated point, a cell that misses the box).

        >>> import tvoronoi
        >>> d = tvoronoi.voronoi([[0, 0], [2, 0]], bbox=(-1, -1, 3, 1))
        >>> [p.area for p in d.to_shapely()]
        [4.0, 4.0]
        """
        from tvoronoi.shapes import cell_polygons

        return cell_polygons(self)

    def to_geopandas(self, properties=None, crs=None):
        """The cells as a geopandas GeoDataFrame with one row per input point.

        Parameters
        ----------
        properties : mapping or DataFrame, optional
            Columns to carry, one value per input point, taken by position.
        crs : optional
            The coordinates' CRS, in any form geopandas accepts ("EPSG:4326"); by default the
            input's (``self.crs``).

        Returns
        -------
        geopandas.GeoDataFrame
            Columns ``site`` (the input row), the properties, ``geometry``
            (the cells as in :meth:`to_shapely`; missing where a row has no
            cell).

        Raises
        ------
        TvoronoiError
            geopandas is not installed (``pip install geopandas``), or the
            properties do not fit.
        """
        from tvoronoi.shapes import cells_frame

        return cells_frame(self, properties, self.crs if crs is None else crs)

    @cached_property
    def _locator(self):
        from tvoronoi.locate import SiteLocator

        return SiteLocator(self)

    def locate(self, xs, ys) -> np.ndarray:
        """The input row of the site nearest to each query point (x, y).

        Walks the Delaunay graph from a nearby site, each step decided by an
        exact comparison of squared distances. Queries may lie anywhere,
        inside the box or not, within the range rule of the sites (2^170
        around their scale).

        Parameters
        ----------
        xs, ys : array_like
            Query coordinates, of one shape (or broadcastable).

        Returns
        -------
        ndarray of int32, of the queries' shape
            For each query, the lowest input row among the sites nearest to
            it: a tie between equidistant sites goes to the lower row, and a
            repeated point to the row that holds its cell (``site_of``).
            Rows without a cell edge (repeated points, the removed sites of
            a dynamic diagram) are never answers.

        Raises
        ------
        TvoronoiError
            Non-finite or out-of-range queries (naming the first), or a
            diagram without sites.

        >>> import tvoronoi
        >>> d = tvoronoi.voronoi([[0, 0], [2, 0], [0, 2], [2, 2]])
        >>> d.locate([0.2, 1.9, 1.0, 50.0], [0.1, 2.5, 1.0, -3.0]).tolist()
        [0, 3, 0, 1]
        """
        return self._locator.locate(xs, ys)
