"""A diagram in the form the canvas draws and picks in: its edges, marks, cell colours and nearest sites.

``Drawable`` is what the canvas draws (a ``Scene``, or a ``LiveScene`` edited in place); ``Scene``
holds a whole diagram (or some of its sites, during playback); ``cell_owner`` finds the cell
under every character.
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.spatial import cKDTree

from tvoronoi.tui.colours import cell_colours
from tvoronoi.tui.viewport import ViewLike, char_centres

# From this many sites on, a scene's cell colours and k-d tree are made in two threads, begun
# before its segments are collected and left running while its first frame draws its lines
# (numpy and the k-d tree let go of the GIL): that frame waits for them only to fill its cells.
PARALLEL_SCENE_SITES = 50_000


def ring_next(offsets: np.ndarray, size: int) -> np.ndarray:
    """Rings stored one after the other (ring i: entries ``offsets[i]:offsets[i + 1]`` of an array
    of ``size``): for each entry, the index of the next entry round its ring, so that the sides of
    every ring run from entry k to entry ``ring_next(...)[k]``. The one routine that turns rings
    into sides, for the scene, the live scene and the export."""
    offsets = np.asarray(offsets, np.int64)
    nxt = np.arange(1, size + 1)
    full = np.diff(offsets) > 0
    nxt[offsets[1:][full] - 1] = offsets[:-1][full]
    return nxt


def ring_segments(points: np.ndarray) -> np.ndarray:
    """The sides of one ring of points (k, 2) as (k, 4) segments, the last back to the first."""
    points = np.asarray(points, np.float64).reshape(-1, 2)
    if len(points) < 2:
        return np.empty((0, 4))
    return np.hstack([points, points[ring_next(np.array([0, len(points)]), len(points))]])


def _cell_sides(a: np.ndarray, b: np.ndarray, points: np.ndarray, bbox) -> tuple[np.ndarray, np.ndarray]:
    """The sides a -> b of every cell ring (indices of ``points``), each once.

    Neighbouring cells share point indices and go round counter-clockwise, so a side between two
    cells comes twice, once each way: the one from the smaller index is kept, and a side along the
    box (one cell only) always. Should the rings not pair up so (every side inside the box twice),
    the sides are made unique by sorting instead.
    """
    a = np.asarray(a, np.int64)
    b = np.asarray(b, np.int64)
    if not a.size:
        return a, b
    xmin, ymin, xmax, ymax = bbox
    # per point, a bit for each side of the box it lies on; a side is along the box if its ends share one
    sides = (
        (points[:, 0] == xmin).astype(np.uint8)
        | ((points[:, 0] == xmax).astype(np.uint8) << 1)
        | ((points[:, 1] == ymin).astype(np.uint8) << 2)
        | ((points[:, 1] == ymax).astype(np.uint8) << 3)
    )
    on_box = (sides[a] & sides[b]) != 0
    inner = ~on_box & (a != b)
    first = inner & (a < b)
    if 2 * int(first.sum()) == int(inner.sum()):
        keep = first | (on_box & (a != b))
        return a[keep], b[keep]
    return _unique_pairs(a, b, len(points))


def _unique_pairs(a: np.ndarray, b: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Undirected pairs (a, b), each once, self pairs dropped."""
    a = np.asarray(a, np.int64)
    b = np.asarray(b, np.int64)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = np.sort((lo * max(n, 1) + hi)[lo != hi])
    if key.size:
        key = key[np.r_[True, key[1:] != key[:-1]]]
    return key // max(n, 1), key % max(n, 1)


class Drawable(Protocol):
    """What the canvas draws and picks in: a ``Scene`` (a whole diagram, or some of its sites
    during playback) or a ``LiveScene`` (a diagram edited in place).

    ``version`` grows with every change made in place; ``changes_since(version)`` says which
    sites and what world box changed since then (None: it cannot say, draw everything again),
    and ``update_owner`` finds the owners of the characters those changes touched.
    """

    @property
    def sites(self) -> np.ndarray: ...
    @property
    def edges(self) -> np.ndarray: ...
    @property
    def edge_mesh(self) -> "EdgeMesh | None": ...
    @property
    def delaunay(self) -> np.ndarray: ...
    @property
    def vertices(self) -> np.ndarray: ...
    @property
    def colours(self) -> np.ndarray: ...
    @property
    def bbox(self) -> tuple: ...
    @property
    def n_sites(self) -> int: ...
    @property
    def n_vertices(self) -> int: ...
    @property
    def version(self) -> int: ...

    def nearest(self, points: np.ndarray) -> np.ndarray: ...
    def site_ids(self) -> np.ndarray | None: ...
    def site_near(self, x: float, y: float, radius: float) -> int | None: ...
    def drawn(self) -> np.ndarray: ...
    def changes_since(self, version: int) -> tuple[np.ndarray, tuple | None] | None: ...
    def update_owner(self, old: np.ndarray, ids: np.ndarray, view, cols: int, rows: int) -> np.ndarray: ...


@dataclass(frozen=True, eq=False)
class EdgeMesh:
    """Edges given as pairs of points: side k runs from ``points[a[k]]`` to ``points[b[k]]``.

    Neighbouring cells share their points, so there are fewer points than segment ends: a
    frame maps each point to the screen once and sets each end's dot once.
    ``ends``: the rows of ``points`` that end some side (None: all of them).
    """

    points: np.ndarray
    a: np.ndarray
    b: np.ndarray
    ends: np.ndarray | None = None

    def box(self) -> tuple[float, float, float, float]:
        """The box (xmin, ymin, xmax, ymax) around the points."""
        if not len(self.points):
            return (np.inf, np.inf, -np.inf, -np.inf)
        xs, ys = self.points[:, 0], self.points[:, 1]  # a column at a time: much faster than axis=0
        return float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max())

    def segments(self) -> np.ndarray:
        """The sides as (k, 4) segments x0, y0, x1, y1."""
        if not self.a.size:
            return np.empty((0, 4))
        return np.hstack([self.points[self.a], self.points[self.b]])


class Scene:
    """A diagram in the form the rasterizer draws, prepared once per diagram.

    Attributes
    ----------
    sites : (n, 2) float64
    edges : (e, 4) float64
        Clipped Voronoi edges (the box outline included) as x0, y0, x1, y1, each once; a
        scene made from a diagram keeps them as ``edge_mesh`` (pairs of the cells' points)
        and makes these on first use.
    edge_mesh : EdgeMesh or None
        The same edges as pairs of points, what the rasterizer draws when it is there.
    delaunay : (t, 4) float64
        Delaunay edges, each once, found from ``triangles`` when first shown, which a large
        diagram's start need not wait for.
    vertices : (m, 2) float64
        Voronoi vertices inside the box.
    colours : (n,) int8
        Palette index of each cell; neighbours differ.
    bbox : (xmin, ymin, xmax, ymax)

    A large diagram's colours and k-d tree may still be being made in other threads when its
    scene is first drawn: ``colours`` and ``tree`` wait for them, so a frame's lines and marks
    are drawn meanwhile.
    """

    def __init__(
        self,
        *,
        sites: np.ndarray,
        vertices: np.ndarray,
        colours,
        bbox: tuple,
        edges: np.ndarray | None = None,
        edge_mesh: EdgeMesh | None = None,
        delaunay_edges: np.ndarray | None = None,
        triangles: np.ndarray | None = None,
        tree=None,
    ) -> None:
        self.sites = sites
        self.vertices = vertices
        self.bbox = bbox
        self.edge_mesh = edge_mesh
        self._edges = edges if edges is not None or edge_mesh is not None else np.empty((0, 4))
        self.delaunay_edges = delaunay_edges
        self.triangles = triangles
        # each an array, or the Future of one being made in another thread
        self._colours = colours
        self._tree = tree

    @property
    def edges(self) -> np.ndarray:
        if self._edges is None:
            assert self.edge_mesh is not None
            self._edges = self.edge_mesh.segments()
        return self._edges

    @property
    def colours(self) -> np.ndarray:
        if isinstance(self._colours, Future):
            self._colours = np.asarray(self._colours.result(), np.int8)
        return self._colours

    @property
    def delaunay(self) -> np.ndarray:
        """The Delaunay edges (t, 4), each once, found from the triangles on first use."""
        if self.delaunay_edges is None:
            tri = np.empty((0, 3), np.int64) if self.triangles is None else self.triangles
            a, b = _unique_pairs(tri.ravel(), tri[:, [1, 2, 0]].ravel(), len(self.sites))
            self.delaunay_edges = np.hstack([self.sites[a], self.sites[b]]) if a.size else np.empty((0, 4))
            self.triangles = None
        return self.delaunay_edges

    @property
    def n_sites(self) -> int:
        return len(self.sites)

    @property
    def version(self) -> int:
        """A scene is never changed in place."""
        return 0

    def drawn(self) -> np.ndarray:
        """Rows of ``sites`` that own a cell: all of them."""
        return np.arange(len(self.sites))

    def changes_since(self, version: int) -> None:
        """Never changed in place: nothing to tell."""
        return None

    def update_owner(self, old: np.ndarray, ids: np.ndarray, view, cols: int, rows: int) -> np.ndarray:
        """Never changed in place: the owners stay."""
        return old

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    def nearest(self, points: np.ndarray) -> np.ndarray:
        """The row of ``sites`` nearest each point (k, 2)."""
        _, rows = self.tree.query(points)
        return rows

    def site_ids(self) -> np.ndarray | None:
        """The id of each row of ``sites`` (None: the row number is the id)."""
        return None

    def site_near(self, x: float, y: float, radius: float) -> int | None:
        """The id of the site nearest (x, y) within ``radius``, or None."""
        if self.n_sites == 0:
            return None
        distance, k = self.tree.query([x, y], distance_upper_bound=radius)
        if not np.isfinite(distance):
            return None
        ids = self.site_ids()
        return int(k) if ids is None else int(ids[k])

    @classmethod
    def from_diagram(cls, diagram, colours: np.ndarray | None = None) -> "Scene":
        """Collect the segments, marks and cell colours of a diagram (``colours``: given, not computed).

        A large diagram's colours and k-d tree are made in two other threads, begun before its
        segments are collected and left running when this returns (see ``colours``, ``tree``).
        """
        sites = np.asarray(diagram.sites, np.float64)
        if len(sites) < PARALLEL_SCENE_SITES:
            return cls._collect(diagram, sites, cell_colours(diagram) if colours is None else colours, None)
        pool = ThreadPoolExecutor(max_workers=2, thread_name_prefix="scene")
        try:
            made = colours if colours is not None else pool.submit(cell_colours, diagram)
            tree = pool.submit(_site_tree, sites)
        finally:
            pool.shutdown(wait=False)
        return cls._collect(diagram, sites, made, tree)

    @classmethod
    def _collect(cls, diagram, sites: np.ndarray, colours, tree) -> "Scene":
        """The scene's segments and marks, with the colours and tree given (arrays or futures)."""
        # every clipped cell ring, point to next point (wrapping round)
        offsets = np.asarray(diagram.cell_offsets, np.int64)
        ring = np.asarray(diagram.cell_vertices)
        nxt = ring_next(offsets, ring.size)
        points = np.asarray(diagram.cell_points, np.float64).reshape(-1, 2)
        a, b = _cell_sides(ring, ring[nxt] if ring.size else ring, points, diagram.bbox)
        used = np.zeros(len(points), bool)
        used[a] = used[b] = True
        mesh = EdgeMesh(points, a, b, None if used.all() else np.flatnonzero(used))

        xmin, ymin, xmax, ymax = diagram.bbox
        vertices = np.asarray(diagram.vertices, np.float64).reshape(-1, 2)
        inside = (
            (vertices[:, 0] >= xmin) & (vertices[:, 0] <= xmax) & (vertices[:, 1] >= ymin) & (vertices[:, 1] <= ymax)
        )
        return cls(
            sites=sites,
            edge_mesh=mesh,
            vertices=vertices[inside],
            colours=colours if isinstance(colours, Future) else np.asarray(colours, np.int8),
            bbox=tuple(float(c) for c in diagram.bbox),
            # the diagram's own int32 array, read only: made into edges when first shown
            triangles=np.asarray(diagram.triangles).reshape(-1, 3),
            tree=tree,
        )

    @property
    def tree(self) -> cKDTree:
        """A k-d tree of the sites, built on first use."""
        if self._tree is None:
            self._tree = _site_tree(self.sites)
        elif isinstance(self._tree, Future):
            self._tree = self._tree.result()
        return self._tree


def _site_tree(sites: np.ndarray) -> cKDTree:
    """A k-d tree of sites (k, 2) for nearest-site queries.

    Split at the middle of each box's longer side rather than at the median: it builds in
    about two thirds of the time, and a frame asks it only one query per character.
    """
    return cKDTree(sites if len(sites) else np.zeros((0, 2)), balanced_tree=False, compact_nodes=False)


def cell_owner(scene: Drawable, view: ViewLike, cols: int, rows: int) -> np.ndarray:
    """The row of ``scene.sites`` whose cell holds each character's centre (-1 outside the box).

    The nearest site of the centre owns it: that is the Voronoi cell itself,
    found for all characters at once with the k-d tree.
    """
    owner = np.full((rows, cols), -1, np.int64)
    if scene.n_sites == 0 or cols == 0 or rows == 0:
        return owner
    xs, ys = char_centres(view, cols, rows)
    xmin, ymin, xmax, ymax = scene.bbox
    in_x = (xs >= xmin) & (xs <= xmax)
    in_y = (ys >= ymin) & (ys <= ymax)
    if not (in_x.any() and in_y.any()):
        return owner
    gx, gy = np.meshgrid(xs[in_x], ys[in_y])
    nearest = scene.nearest(np.column_stack([gx.ravel(), gy.ravel()]))
    owner[np.ix_(np.flatnonzero(in_y), np.flatnonzero(in_x))] = nearest.reshape(gx.shape)
    return owner
