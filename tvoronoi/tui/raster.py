"""Draw a Voronoi diagram on a braille grid with numpy: views, scenes, layers, cell fills, styled rows.

Every layer is drawn into its own dot array (see ``dots``) and the layers'
bit patterns are OR-ed per character, so no dot is lost where lines meet.
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from functools import lru_cache
from typing import Protocol

import numpy as np
import numpy.typing as npt
from rich.segment import Segment
from rich.style import Style
from scipy.spatial import cKDTree

from tvoronoi.tui.colours import MAX_COLOURS, Palette, cell_colours
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS, braille_text, pack_braille, point_dots, segment_dots

# The layers, in rising precedence: a character has one foreground colour,
# that of the highest layer with a dot in it. FUTURE (sites not reached yet),
# GROWING, CONFLICT, CIRCLE, BEACH, SWEEP and EVENT belong to algorithm playback,
# CURSOR to editing: the lowest, so that a site or edge under the keyboard cursor
# keeps its colour (the cursor's characters are lit up by their fill instead).
(NO_MARK, CURSOR, FUTURE, DELAUNAY, EDGE, GROWING, WALK, CONFLICT, CIRCLE, BEACH, SWEEP,
 VERTEX, SITE, EVENT) = range(14)
N_MARKS = 14
# Fills: -1 none, 0 .. N_FILLS - 1 the cell colours, TINTED + c the tinted
# colour c, CONFLICT_FILL the inside of a conflict region, HIGHLIGHTED + c the
# colour c under the keyboard cursor.
N_FILLS = MAX_COLOURS
TINTED = N_FILLS
CONFLICT_FILL = 2 * N_FILLS
HIGHLIGHTED = 2 * N_FILLS + 1
# The keyboard cursor's cross reaches this many dots each way (about a character).
CURSOR_ARM = 2
# From this many sites on, a scene's cell colours and k-d tree are made in two threads while
# its segments are collected (numpy and the k-d tree let go of the GIL), so that a large
# diagram's first frame waits for neither.
PARALLEL_SCENE_SITES = 50_000
# Below this many sites per character a site is drawn as a 2 x 2 block of dots.
SPARSE_SITES_PER_CHAR = 0.05
# Vertex marks are drawn only below this many vertices per character: denser, they
# would recolour most edge characters and hide the edges they mark.
VERTEX_MARKS_PER_CHAR = 0.12
# The layer cache keeps the layers of this many recent frames.
LAYER_FRAMES_KEPT = 4
# Fitting the box leaves this fraction of the canvas free around it.
FIT_MARGIN = 0.04


@dataclass(frozen=True)
class View:
    """What the canvas shows: the world point at its centre and the world size of one dot.

    Dots are about square on a terminal whose characters are twice as high
    as wide, so one scale serves both axes. World y grows upwards.

    The centre is kept as an anchor (``ax``, ``ay``) and a whole number of
    characters (``dc`` right, ``dr`` down) the view was panned by since: the
    dots of all views with the same anchor and scale lie on one plane, and a
    panned view's dots are those of the view before, moved by whole
    characters, exactly (see ``dots.segment_dots``), so a layer drawn before
    is shifted rather than drawn again.
    """

    ax: float = 0.5
    ay: float = 0.5
    scale: float = 0.01
    dc: int = 0
    dr: int = 0

    @property
    def cx(self) -> float:
        """World x of the centre."""
        return self.ax + self.dc * DOT_COLS * self.scale if self.dc else self.ax

    @property
    def cy(self) -> float:
        """World y of the centre."""
        return self.ay - self.dr * DOT_ROWS * self.scale if self.dr else self.ay

    @property
    def origin(self) -> tuple[int, int]:
        """The plane's dot at the canvas's top left (see ``plane_dots``)."""
        return self.dc * DOT_COLS, self.dr * DOT_ROWS

    def plane_dots(self, xs, ys, cols: int, rows: int):
        """World coordinates to continuous dot coordinates of the anchor's plane: those of the
        canvas plus ``origin``."""
        u = (np.asarray(xs) - self.ax) / self.scale + cols * DOT_COLS / 2
        v = rows * DOT_ROWS / 2 - (np.asarray(ys) - self.ay) / self.scale
        return u, v

    def to_dots(self, xs, ys, cols: int, rows: int):
        """World coordinates to continuous dot coordinates (u right, v down)."""
        u, v = self.plane_dots(xs, ys, cols, rows)
        ou, ov = self.origin
        return (u - ou, v - ov) if ou or ov else (u, v)

    def to_world(self, u, v, cols: int, rows: int):
        """Continuous dot coordinates to world coordinates."""
        ou, ov = self.origin
        xs = self.ax + (np.asarray(u) + ou - cols * DOT_COLS / 2) * self.scale
        ys = self.ay - (np.asarray(v) + ov - rows * DOT_ROWS / 2) * self.scale
        return xs, ys

    def char_to_world(self, col: float, row: float, cols: int, rows: int) -> tuple[float, float]:
        """The world point at the centre of character (col, row)."""
        x, y = self.to_world((col + 0.5) * DOT_COLS, (row + 0.5) * DOT_ROWS, cols, rows)
        return float(x), float(y)

    def panned(self, dx_dots: float, dy_dots: float) -> "View":
        """The view moved by a number of dots (right, down on screen); by whole characters, it
        keeps its anchor."""
        if dx_dots % DOT_COLS == 0 and dy_dots % DOT_ROWS == 0:
            return View(self.ax, self.ay, self.scale,
                        self.dc + int(dx_dots) // DOT_COLS, self.dr + int(dy_dots) // DOT_ROWS)
        return View(self.cx + dx_dots * self.scale, self.cy - dy_dots * self.scale, self.scale)

    def zoomed(self, factor: float, about: tuple[float, float] | None = None) -> "View":
        """The view magnified by ``factor``, keeping the world point ``about`` where it is."""
        scale = self.scale / factor
        cx, cy = self.cx, self.cy
        if about is None:
            return View(cx, cy, scale)
        ax, ay = about
        keep = 1.0 - 1.0 / factor
        return View(cx + (ax - cx) * keep, cy + (ay - cy) * keep, scale)

    def window(self, c0: int, r0: int, cols: int, rows: int) -> "Window":
        """The part of a ``cols x rows`` canvas from character (c0, r0) on, as a view of its own."""
        return Window(self, cols, rows, c0, r0)

    def char_span(self, box, cols: int, rows: int, margin: int = 1) -> tuple[int, int, int, int] | None:
        """The characters (c0, r0, c1, r1), ends excluded, that a world box touches, grown by
        ``margin`` characters and cut to the canvas; None if it misses the canvas."""
        if not np.isfinite(box).all():
            return None
        x0, y0, x1, y1 = box
        u0, v1 = self.to_dots(x0, y0, cols, rows)
        u1, v0 = self.to_dots(x1, y1, cols, rows)
        c0 = max(int(np.floor(float(u0) / DOT_COLS)) - margin, 0)
        c1 = min(int(np.floor(float(u1) / DOT_COLS)) + 1 + margin, cols)
        r0 = max(int(np.floor(float(v0) / DOT_ROWS)) - margin, 0)
        r1 = min(int(np.floor(float(v1) / DOT_ROWS)) + 1 + margin, rows)
        if c0 >= c1 or r0 >= r1:
            return None
        return c0, r0, c1, r1

    @classmethod
    def fit(cls, bbox, cols: int, rows: int) -> "View":
        """The view that shows the whole box, centred, with a small margin."""
        xmin, ymin, xmax, ymax = (float(b) for b in bbox)
        width_dots = max(cols * DOT_COLS, 1) * (1.0 - 2 * FIT_MARGIN)
        height_dots = max(rows * DOT_ROWS, 1) * (1.0 - 2 * FIT_MARGIN)
        scale = max((xmax - xmin) / width_dots, (ymax - ymin) / height_dots)
        if not scale > 0:
            scale = 1.0 / max(width_dots, 1.0)
        return cls((xmin + xmax) / 2, (ymin + ymax) / 2, scale)


@dataclass(frozen=True)
class Window:
    """The part of a canvas of ``cols x rows`` characters from character (c0, r0) on, used as a view.

    The rasterizer draws the part as a window on the whole view's plane of
    dots (``origin``), which is exact: a mark lands on the same dots whether
    the part or the whole canvas is drawn.
    """

    view: View
    cols: int
    rows: int
    c0: int
    r0: int

    @property
    def scale(self) -> float:
        return self.view.scale

    @property
    def origin(self) -> tuple[int, int]:
        ou, ov = self.view.origin
        return ou + self.c0 * DOT_COLS, ov + self.r0 * DOT_ROWS

    def plane_dots(self, xs, ys, cols: int, rows: int):
        return self.view.plane_dots(xs, ys, self.cols, self.rows)

    def to_dots(self, xs, ys, cols: int, rows: int):
        u, v = self.view.to_dots(xs, ys, self.cols, self.rows)
        return u - self.c0 * DOT_COLS, v - self.r0 * DOT_ROWS

    def to_world(self, u, v, cols: int, rows: int):
        return self.view.to_world(np.asarray(u) + self.c0 * DOT_COLS, np.asarray(v) + self.r0 * DOT_ROWS,
                                  self.cols, self.rows)


# What the rasterizer draws through: a whole canvas's view, or a part of it.
ViewLike = View | Window


# ---------------------------------------------------------------------------
# the drawable form of a diagram

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
    sides = ((points[:, 0] == xmin).astype(np.uint8) | ((points[:, 0] == xmax).astype(np.uint8) << 1)
             | ((points[:, 1] == ymin).astype(np.uint8) << 2) | ((points[:, 1] == ymax).astype(np.uint8) << 3))
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

    def __init__(self, *, sites: np.ndarray, vertices: np.ndarray, colours, bbox: tuple,
                 edges: np.ndarray | None = None, edge_mesh: EdgeMesh | None = None,
                 delaunay_edges: np.ndarray | None = None, triangles: np.ndarray | None = None,
                 tree=None) -> None:
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
            (vertices[:, 0] >= xmin) & (vertices[:, 0] <= xmax)
            & (vertices[:, 1] >= ymin) & (vertices[:, 1] <= ymax)
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


@dataclass(frozen=True)
class Frame:
    """One drawing of a scene: per character, its dots, the layer that colours them, and its fill.

    Attributes
    ----------
    codes : (rows, cols) uint8
        Braille bit patterns (all layers OR-ed).
    mark : (rows, cols) uint8
        The highest layer with a dot in the character (NO_MARK .. EVENT).
    fill : (rows, cols) int16
        Fill of the character (see N_FILLS): usually the palette index of the
        cell that owns the character's centre, -1 outside the box.
    owner : (rows, cols) int64
        The row of ``scene.sites`` nearest the character's centre, -1 outside the box.
    """

    codes: np.ndarray
    mark: np.ndarray
    fill: np.ndarray
    owner: np.ndarray


def char_centres(view: ViewLike, cols: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """World x of each character column's centre (cols,) and y of each row's centre (rows,)."""
    u = (np.arange(cols) + 0.5) * DOT_COLS
    v = (np.arange(rows) + 0.5) * DOT_ROWS
    xs, _ = view.to_world(u, np.zeros_like(u), cols, rows)
    _, ys = view.to_world(np.zeros_like(v), v, cols, rows)
    return xs, ys


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


def fill_of(scene: Drawable, owner: np.ndarray) -> np.ndarray:
    """The palette index of each owner (-1 stays -1)."""
    fill = np.full(owner.shape, -1, np.int16)
    inside = owner >= 0
    fill[inside] = scene.colours[owner[inside]]
    return fill


class Painter:
    """Draws layers of marks into a frame's bit patterns, each layer in its own dot array.

    Layers may come in any order: a character takes the colour of the highest
    layer with a dot in it.
    """

    def __init__(self, view: ViewLike, cols: int, rows: int, cache: "LayerCache | None" = None) -> None:
        self.view, self.cols, self.rows = view, cols, rows
        self.cache = cache
        self.shape = (rows * DOT_ROWS, cols * DOT_COLS)
        self.codes = np.zeros((rows, cols), np.uint8)
        self.mark = np.zeros((rows, cols), np.uint8)
        self.world = self.world_of((0, 0, cols, rows))

    def world_of(self, span) -> tuple[float, float, float, float]:
        """The world box (x0, y0, x1, y1) of the characters span = (c0, r0, c1, r1), a dot wider
        each way: marks beyond it are dropped before any work (NaN coordinates fail its tests too)."""
        c0, r0, c1, r1 = span
        (x0, x1), (y1, y0) = self.view.to_world(np.array([c0 * DOT_COLS - 1.0, c1 * DOT_COLS + 1.0]),
                                                np.array([r0 * DOT_ROWS - 1.0, r1 * DOT_ROWS + 1.0]),
                                                self.cols, self.rows)
        return float(x0), float(y0), float(x1), float(y1)

    def new_dots(self) -> np.ndarray:
        return np.zeros(self.shape, bool)

    def lay(self, layer: int, dots: np.ndarray) -> np.ndarray:
        """Merge a layer's dots into the frame; returns their bit patterns per character."""
        packed = pack_braille(dots)
        self.lay_packed(layer, packed)
        return packed

    def lay_packed(self, layer: int, packed: np.ndarray) -> None:
        """Merge a layer's bit patterns (rows, cols) into the frame."""
        self.codes |= packed
        np.maximum(self.mark, np.where(packed != 0, np.uint8(layer), np.uint8(0)), out=self.mark)

    def to_dots(self, xs, ys):
        """World coordinates to continuous dot coordinates of the view's plane (see ``View``):
        the canvas's top left is the plane's dot ``self.origin``."""
        return self.view.plane_dots(xs, ys, self.cols, self.rows)

    @property
    def origin(self) -> tuple[int, int]:
        return self.view.origin

    def _layer(self, layer: int, key, draw) -> None:
        """Lay a layer: from the cache if drawn before for this view, else shifted from a view
        panned from this one with only the strips it lacks drawn, else drawn whole.
        ``draw(dots, origin, world)`` sets the layer's dots in a window of the plane from dot
        ``origin`` on, given the world box (x0, y0, x1, y1) that window shows."""
        cache = self.cache if key is not None else None
        packed = None if cache is None else cache.get(key, self)
        if packed is None:
            shifted = None if cache is None else cache.shifted(key, self)
            if shifted is None:
                packed = self.draw_part(draw, (0, 0, self.cols, self.rows))
            else:
                packed, missing = shifted
                for c0, r0, c1, r1 in missing:
                    packed[r0:r1, c0:c1] = self.draw_part(draw, (c0, r0, c1, r1))
            if cache is not None:
                cache.put(key, self, packed)
        self.lay_packed(layer, packed)

    def draw_part(self, draw, span) -> np.ndarray:
        """The bit patterns (r1 - r0, c1 - c0) of the characters span = (c0, r0, c1, r1) of a layer."""
        c0, r0, c1, r1 = span
        ou, ov = self.origin
        dots = np.zeros(((r1 - r0) * DOT_ROWS, (c1 - c0) * DOT_COLS), bool)
        world = self.world if span == (0, 0, self.cols, self.rows) else self.world_of(span)
        draw(dots, (ou + c0 * DOT_COLS, ov + r0 * DOT_ROWS), world)
        return pack_braille(dots)

    def segments(self, layer: int, seg: npt.ArrayLike, *, dash: int = 0, key=None) -> None:
        """World segments (k, 4) as x0, y0, x1, y1; ``key`` names them for the layer cache."""
        seg = np.asarray(seg, np.float64).reshape(-1, 4)

        def draw(dots, origin, world) -> None:
            part = _visible_segments(seg, world)
            if len(part):
                u0, v0 = self.to_dots(part[:, 0], part[:, 1])
                u1, v1 = self.to_dots(part[:, 2], part[:, 3])
                segment_dots(dots, u0, v0, u1, v1, dash=dash, origin=origin)

        self._layer(layer, key, draw)

    def mesh(self, layer: int, mesh: "EdgeMesh", *, key=None) -> None:
        """Solid segments given as pairs of points (see ``EdgeMesh``); ``key`` names them for the
        layer cache. The same dots as ``segments`` of ``mesh.segments()``, found with less work:
        each point is mapped to the screen once, each end's dot set once, and a side with both
        ends in one dot (most of them, zoomed out) adds no dot beyond its ends."""
        points, a, b = mesh.points, mesh.a, mesh.b
        box = mesh.box()

        def draw(dots, origin, world) -> None:
            height, width = dots.shape
            ou, ov = origin
            u, v = self.to_dots(points[:, 0], points[:, 1])
            col, row = np.floor(u) - ou, np.floor(v) - ov
            inside = (col >= 0) & (col < width) & (row >= 0) & (row < height)  # False for NaN
            # the dot of each point in the window; beyond it a number no other point has
            dot = (row * width + col).astype(np.int32) if inside.all() else np.where(
                inside, row * width + col, -1.0 - np.arange(len(points))).astype(np.int64)
            # the ends, each point once
            ends = dot[inside] if mesh.ends is None else dot[mesh.ends[inside[mesh.ends]]]
            dots.ravel()[ends] = True
            # a side within one dot has no dot but its ends'
            apart = dot[a] != dot[b]
            x0, y0, x1, y1 = world
            if not (x0 <= box[0] and y0 <= box[1] and box[2] <= x1 and box[3] <= y1):
                # ... and one whose ends lie beyond one side of the window has none here
                xs, ys = points[:, 0], points[:, 1]
                beyond = ((xs < x0).view(np.uint8) | ((xs > x1).view(np.uint8) << 1)
                          | ((ys < y0).view(np.uint8) << 2) | ((ys > y1).view(np.uint8) << 3))
                apart &= (beyond[a] & beyond[b]) == 0
            rest = np.flatnonzero(apart)
            if rest.size:
                ra, rb = a[rest], b[rest]
                segment_dots(dots, u[ra], v[ra], u[rb], v[rb], origin=origin, ends=False)

        self._layer(layer, key, draw)

    def points(self, layer: int, xy: npt.ArrayLike, *, block: bool = False, key=None) -> None:
        """World points (k, 2); ``key`` names them for the layer cache."""
        xy = np.asarray(xy, np.float64).reshape(-1, 2)

        def draw(dots, origin, world) -> None:
            part = _visible_points(xy, world)
            if len(part):
                u, v = self.to_dots(part[:, 0], part[:, 1])
                point_dots(dots, u, v, block=block, origin=origin)

        self._layer(layer, key, draw)

    def cross(self, layer: int, x: float, y: float) -> np.ndarray:
        """A small cross centred on the world point (x, y); the (rows, cols) mask of its characters."""
        dots = self.new_dots()
        u, v = self.to_dots(x, y)
        u, v = float(u), float(v)
        segment_dots(dots, [u - CURSOR_ARM, u], [v, v - CURSOR_ARM - 1], [u + CURSOR_ARM, u],
                     [v, v + CURSOR_ARM + 1], origin=self.origin)
        self.lay(layer, dots)
        return pack_braille(dots) != 0


def _visible_segments(seg: np.ndarray, world) -> np.ndarray:
    """The segments (k, 4) that meet the world box (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = world
    sx0, sy0, sx1, sy1 = seg.T
    keep = ((np.maximum(sx0, sx1) >= x0) & (np.minimum(sx0, sx1) <= x1)
            & (np.maximum(sy0, sy1) >= y0) & (np.minimum(sy0, sy1) <= y1))
    return seg if keep.all() else seg[keep]


def _visible_points(xy: np.ndarray, world) -> np.ndarray:
    x0, y0, x1, y1 = world
    keep = (xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)
    return xy if keep.all() else xy[keep]


class LayerCache:
    """The diagram's layers (edges, Delaunay edges, vertices, sites) of the last few frames, as bit
    patterns per character, so that a frame that differs only in another layer (Delaunay shown or
    hidden, vertices, an overlay), or that comes back to a recent view (fit after a zoom), does not
    draw them again.

    An entry holds its scene (so its id cannot be reused while the entry lives) and is found only
    for the same scene, version, view and size. ``rasterize`` calls ``frame_done`` after each
    frame: the entries of the last ``frames`` frames are kept, those of other scenes dropped.
    """

    def __init__(self, frames: int = LAYER_FRAMES_KEPT) -> None:
        self.frames = frames
        self._used: dict = {}
        self._history: list[dict] = []  # the entries of the frames before, oldest first

    def _full_key(self, key, paint: "Painter"):
        scene, rest = key
        return (id(scene), scene.version, paint.view, paint.cols, paint.rows, rest)

    def get(self, key, paint: "Painter") -> np.ndarray | None:
        full = self._full_key(key, paint)
        entry = self._used.get(full)
        for older in reversed(self._history):
            if entry is not None:
                break
            entry = older.get(full)
        if entry is None or entry[0] is not key[0]:
            return None
        self._used[full] = entry
        return entry[1]

    def shifted(self, key, paint: "Painter") -> tuple[np.ndarray, list] | None:
        """The layer of a kept view that this one was panned from (same anchor, scale and size, see
        ``View``), moved by the characters panned, and the spans (c0, r0, c1, r1) of characters
        it lacks; None if there is none. When several are kept, the one lacking fewest."""
        view = paint.view
        if not isinstance(view, View):
            return None
        scene, rest = key
        best = None
        for frame in [self._used] + self._history[::-1]:
            for full, entry in frame.items():
                old = full[2]
                if (entry[0] is not scene or full[1] != scene.version or full[3:] != (paint.cols, paint.rows, rest)
                        or not isinstance(old, View) or (old.ax, old.ay, old.scale) != (view.ax, view.ay, view.scale)):
                    continue
                dc, dr = view.dc - old.dc, view.dr - old.dr
                kept = max(paint.cols - abs(dc), 0) * max(paint.rows - abs(dr), 0)
                if kept and (best is None or kept > best[0]):
                    best = (kept, dc, dr, entry[1])
        if best is None:
            return None
        _, dc, dr, old_packed = best
        cols, rows = paint.cols, paint.rows
        packed = np.zeros_like(old_packed)
        # the character (c, r) of the new view is (c + dc, r + dr) of the old one
        packed[max(-dr, 0):rows - max(dr, 0), max(-dc, 0):cols - max(dc, 0)] = \
            old_packed[max(dr, 0):rows - max(-dr, 0), max(dc, 0):cols - max(-dc, 0)]
        missing = []
        if dr:  # whole rows
            missing.append((0, rows - dr, cols, rows) if dr > 0 else (0, 0, cols, -dr))
        if dc:  # the columns, beside those rows
            r0, r1 = (0, rows - dr) if dr > 0 else (-dr, rows)
            missing.append((cols - dc, r0, cols, r1) if dc > 0 else (0, r0, -dc, r1))
        return packed, missing

    def put(self, key, paint: "Painter", packed: np.ndarray) -> None:
        self._used[self._full_key(key, paint)] = (key[0], packed)

    def frame_done(self) -> None:
        """Keep what this frame used with the last frames' entries; a scene this frame did not
        draw is let go."""
        scenes = {id(entry[0]) for entry in self._used.values()}
        kept = [{k: e for k, e in frame.items() if id(e[0]) in scenes} for frame in self._history]
        self._history = [frame for frame in kept + [self._used] if frame][-self.frames:]
        self._used = {}


def rasterize(
    scene: Drawable,
    view: ViewLike,
    cols: int,
    rows: int,
    *,
    delaunay: bool = False,
    vertices: bool = True,
    overlay=None,
    cursor: tuple[float, float] | None = None,
    owner: np.ndarray | None = None,
    site_blocks: bool = False,
    layers: LayerCache | None = None,
) -> Frame:
    """Draw a scene into a frame of ``cols x rows`` characters.

    ``overlay``, if given, draws more layers (``overlay.draw(painter)``) and
    may change the fills (``overlay.refill(fill, owner, view, cols, rows)``);
    ``cursor`` is a world point marked with a cross; ``owner`` is the
    ``cell_owner`` of this scene and view when the caller already has it;
    ``site_blocks`` draws every site as a block of dots (else only where
    sites are sparse), for a picture without fills. ``layers``, if given, keeps the diagram's
    layers of this frame and gives back those of the last one that are the same.
    """
    paint = Painter(view, cols, rows, layers)
    if delaunay and len(scene.delaunay):
        paint.segments(DELAUNAY, scene.delaunay, key=(scene, "delaunay"))
    mesh = scene.edge_mesh
    if mesh is None:
        paint.segments(EDGE, scene.edges, key=(scene, "edges"))
    else:
        paint.mesh(EDGE, mesh, key=(scene, "edges"))
    if vertices and scene.n_vertices and per_char(scene.n_vertices, scene, view) < VERTEX_MARKS_PER_CHAR:
        paint.points(VERTEX, scene.vertices, key=(scene, "vertices"))
    if scene.n_sites:
        sparse = site_blocks or per_char(scene.n_sites, scene, view) < SPARSE_SITES_PER_CHAR
        paint.points(SITE, scene.sites, block=sparse, key=(scene, ("sites", sparse)))
    if layers is not None:
        layers.frame_done()
    if overlay is not None:
        overlay.draw(paint)
    under_cursor = None if cursor is None else paint.cross(CURSOR, *cursor)
    if owner is None:
        owner = cell_owner(scene, view, cols, rows)
    fill = fill_of(scene, owner)
    if overlay is not None:
        fill = overlay.refill(fill, owner, view, cols, rows)
    if under_cursor is not None:
        # light up the cell colours under the cross (not a block hiding what lies there)
        lit = under_cursor & (fill >= 0) & (fill < N_FILLS)
        fill[lit] += HIGHLIGHTED
    return Frame(paint.codes, paint.mark, fill, owner)


def redraw_part(frame: Frame, scene, view: View, cols: int, rows: int, span, *, owner=None, **options) -> None:
    """Draw again, in place, the characters ``span`` = (c0, r0, c1, r1) of a frame of this scene and view.

    ``owner`` gives the owners of those characters if the caller has them;
    ``options`` are those of ``rasterize``. A segment's dots come from its own
    ends whatever window draws them, so the part matches a whole drawing dot
    for dot, lines crossing its border included.
    """
    c0, r0, c1, r1 = span
    part_view = view.window(c0, r0, cols, rows)
    part = rasterize(scene, part_view, c1 - c0, r1 - r0, owner=owner, **options)
    for whole, piece in ((frame.codes, part.codes), (frame.mark, part.mark),
                         (frame.fill, part.fill), (frame.owner, part.owner)):
        whole[r0:r1, c0:c1] = piece


def per_char(count: int, scene, view: ViewLike) -> float:
    """About how many of ``count`` marks spread over the box share one character."""
    xmin, ymin, xmax, ymax = scene.bbox
    char_w, char_h = view.scale * DOT_COLS, view.scale * DOT_ROWS
    chars = max((xmax - xmin) / char_w * (ymax - ymin) / char_h, 1e-12)
    return count / chars


# ---------------------------------------------------------------------------
# styled text

@lru_cache(maxsize=8)
def style_table(palette: Palette) -> tuple[Style, ...]:
    """Styles indexed by ``mark * len(palette.backgrounds) + fill + 1``."""
    marks = {
        NO_MARK: (None, False),
        FUTURE: (palette.future, False),
        DELAUNAY: (palette.delaunay, False),
        EDGE: (palette.edge, True),
        GROWING: (palette.growing, True),
        WALK: (palette.walk, True),
        CONFLICT: (palette.conflict, True),
        CIRCLE: (palette.circle, False),
        BEACH: (palette.beach, True),
        SWEEP: (palette.sweep, True),
        VERTEX: (palette.vertex, True),
        SITE: (palette.site, True),
        EVENT: (palette.event, True),
        CURSOR: (palette.cursor, True),
    }
    table = []
    for m in range(N_MARKS):
        colour, bold = marks[m]
        for bg in palette.backgrounds:
            table.append(Style(color=colour, bgcolor=bg, bold=bold or None))
    return tuple(table)


def frame_lines(frame: Frame, palette: Palette) -> list[list[Segment]]:
    """The frame as rows of rich segments, one segment per run of equal style."""
    styles = style_table(palette)
    rows, cols = frame.codes.shape
    if rows == 0 or cols == 0:
        return [[] for _ in range(rows)]
    keys = frame.mark.astype(np.int64) * len(palette.backgrounds) + (frame.fill.astype(np.int64) + 1)
    # runs of one style, over the whole frame at once; each row starts a run
    change = np.ones((rows, cols), bool)
    change[:, 1:] = keys[:, 1:] != keys[:, :-1]
    starts = np.flatnonzero(change)
    ends = np.r_[starts[1:], rows * cols]
    text = braille_text(frame.codes.ravel())
    run_styles = [styles[k] for k in keys.ravel()[starts].tolist()]
    make = tuple.__new__  # Segment is a named tuple; this skips its Python-level __new__
    segments = [
        make(Segment, (text[s:e], style, None))
        for s, e, style in zip(starts.tolist(), ends.tolist(), run_styles)
    ]
    per_row = np.bincount(starts // cols, minlength=rows).tolist()
    lines, at = [], 0
    for count in per_row:
        lines.append(segments[at:at + count])
        at += count
    return lines
