"""The rasterizer: a scene drawn with numpy into a frame of braille dots, marks and cell fills.

Every layer is drawn into its own dot array (see ``dots``) and the layers'
bit patterns are OR-ed per character, so no dot is lost where lines meet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS, pack_braille, point_dots, segment_dots
from tvoronoi.tui.layers import (
    CURSOR,
    DELAUNAY,
    EDGE,
    HIGHLIGHTED,
    N_FILLS,
    SITE,
    VERTEX,
    LayerCache,
)
from tvoronoi.tui.scene import Drawable, EdgeMesh, cell_owner
from tvoronoi.tui.scene import Scene as Scene  # noqa: F401 (building.py imports it from here)
from tvoronoi.tui.viewport import View, ViewLike

# The keyboard cursor's cross reaches this many dots each way (about a character).
CURSOR_ARM = 2
# Below this many sites per character a site is drawn as a 2 x 2 block of dots.
SPARSE_SITES_PER_CHAR = 0.05
# Vertex marks are drawn only below this many vertices per character: denser, they
# would recolour most edge characters and hide the edges they mark.
VERTEX_MARKS_PER_CHAR = 0.12


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
        (x0, x1), (y1, y0) = self.view.to_world(
            np.array([c0 * DOT_COLS - 1.0, c1 * DOT_COLS + 1.0]),
            np.array([r0 * DOT_ROWS - 1.0, r1 * DOT_ROWS + 1.0]),
            self.cols,
            self.rows,
        )
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
            dot = (
                (row * width + col).astype(np.int32)
                if inside.all()
                else np.where(inside, row * width + col, -1.0 - np.arange(len(points))).astype(np.int64)
            )
            # the ends, each point once
            ends = dot[inside] if mesh.ends is None else dot[mesh.ends[inside[mesh.ends]]]
            dots.ravel()[ends] = True
            # a side within one dot has no dot but its ends'
            apart = dot[a] != dot[b]
            x0, y0, x1, y1 = world
            if not (x0 <= box[0] and y0 <= box[1] and box[2] <= x1 and box[3] <= y1):
                # ... and one whose ends lie beyond one side of the window has none here
                xs, ys = points[:, 0], points[:, 1]
                beyond = (
                    (xs < x0).view(np.uint8)
                    | ((xs > x1).view(np.uint8) << 1)
                    | ((ys < y0).view(np.uint8) << 2)
                    | ((ys > y1).view(np.uint8) << 3)
                )
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
        segment_dots(
            dots,
            [u - CURSOR_ARM, u],
            [v, v - CURSOR_ARM - 1],
            [u + CURSOR_ARM, u],
            [v, v + CURSOR_ARM + 1],
            origin=self.origin,
        )
        self.lay(layer, dots)
        return pack_braille(dots) != 0


def _visible_segments(seg: np.ndarray, world) -> np.ndarray:
    """The segments (k, 4) that meet the world box (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = world
    sx0, sy0, sx1, sy1 = seg.T
    keep = (
        (np.maximum(sx0, sx1) >= x0)
        & (np.minimum(sx0, sx1) <= x1)
        & (np.maximum(sy0, sy1) >= y0)
        & (np.minimum(sy0, sy1) <= y1)
    )
    return seg if keep.all() else seg[keep]


def _visible_points(xy: np.ndarray, world) -> np.ndarray:
    x0, y0, x1, y1 = world
    keep = (xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)
    return xy if keep.all() else xy[keep]


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
    for whole, piece in (
        (frame.codes, part.codes),
        (frame.mark, part.mark),
        (frame.fill, part.fill),
        (frame.owner, part.owner),
    ):
        whole[r0:r1, c0:c1] = piece


def per_char(count: int, scene, view: ViewLike) -> float:
    """About how many of ``count`` marks spread over the box share one character."""
    xmin, ymin, xmax, ymax = scene.bbox
    char_w, char_h = view.scale * DOT_COLS, view.scale * DOT_ROWS
    chars = max((xmax - xmin) / char_w * (ymax - ymin) / char_h, 1e-12)
    return count / chars
