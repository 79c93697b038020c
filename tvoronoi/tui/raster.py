"""Draw a Voronoi diagram on a braille grid with numpy: dots, cell fills and styled rows of text.

A character cell holds 2 x 4 braille dots, so a canvas of ``cols x rows``
characters is a boolean dot array of shape ``(rows * 4, cols * 2)``. Dot
coordinates ``(u, v)`` are continuous: dot column ``floor(u)``, dot row
``floor(v)``, with ``v`` growing downwards. Every layer is drawn into its own
dot array and the layers' bit patterns are OR-ed per character, so no dot is
lost where lines meet.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from rich.segment import Segment
from rich.style import Style
from scipy.spatial import cKDTree

from tvoronoi.tui.colours import Palette, cell_colours

DOT_COLS, DOT_ROWS = 2, 4
BRAILLE_BLANK = 0x2800
# DOT_BITS[row, col]: the bit of the dot at (col, row) inside a character
DOT_BITS = np.array([[0x01, 0x08], [0x02, 0x10], [0x04, 0x20], [0x40, 0x80]], np.uint8)
SPACE = 0x20

# The layers, in rising precedence: a character has one foreground colour,
# that of the highest layer with a dot in it.
NO_MARK, DELAUNAY, EDGE, VERTEX, SITE = 0, 1, 2, 3, 4
N_MARKS = 5
# Below this many sites per character a site is drawn as a 2 x 2 block of dots.
SPARSE_SITES_PER_CHAR = 0.05
# Vertex marks are drawn only below this many vertices per character: denser, they
# would recolour most edge characters and hide the edges they mark.
VERTEX_MARKS_PER_CHAR = 0.12
# Fitting the box leaves this fraction of the canvas free around it.
FIT_MARGIN = 0.04


@dataclass(frozen=True)
class View:
    """What the canvas shows: the world point at its centre and the world size of one dot.

    Dots are about square on a terminal whose characters are twice as high
    as wide, so one scale serves both axes. World y grows upwards.
    """

    cx: float = 0.5
    cy: float = 0.5
    scale: float = 0.01

    def to_dots(self, xs, ys, cols: int, rows: int):
        """World coordinates to continuous dot coordinates (u right, v down)."""
        u = (np.asarray(xs) - self.cx) / self.scale + cols * DOT_COLS / 2
        v = rows * DOT_ROWS / 2 - (np.asarray(ys) - self.cy) / self.scale
        return u, v

    def to_world(self, u, v, cols: int, rows: int):
        """Continuous dot coordinates to world coordinates."""
        xs = self.cx + (np.asarray(u) - cols * DOT_COLS / 2) * self.scale
        ys = self.cy - (np.asarray(v) - rows * DOT_ROWS / 2) * self.scale
        return xs, ys

    def char_to_world(self, col: float, row: float, cols: int, rows: int) -> tuple[float, float]:
        """The world point at the centre of character (col, row)."""
        x, y = self.to_world((col + 0.5) * DOT_COLS, (row + 0.5) * DOT_ROWS, cols, rows)
        return float(x), float(y)

    def panned(self, dx_dots: float, dy_dots: float) -> "View":
        """The view moved by a number of dots (right, down on screen)."""
        return View(self.cx + dx_dots * self.scale, self.cy - dy_dots * self.scale, self.scale)

    def zoomed(self, factor: float, about: tuple[float, float] | None = None) -> "View":
        """The view magnified by ``factor``, keeping the world point ``about`` where it is."""
        scale = self.scale / factor
        if about is None:
            return View(self.cx, self.cy, scale)
        ax, ay = about
        keep = 1.0 - 1.0 / factor
        return View(self.cx + (ax - self.cx) * keep, self.cy + (ay - self.cy) * keep, scale)

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


# ---------------------------------------------------------------------------
# dots

def segment_dots(dots: np.ndarray, u0, v0, u1, v1) -> None:
    """Set the dots along many segments at once.

    Each segment is clipped to the dot array, then sampled once per dot
    along its longer axis (a vectorised DDA), so consecutive samples touch
    and a line has no gaps.

    Parameters
    ----------
    dots : (H, W) bool, changed in place
    u0, v0, u1, v1 : (k,) float
        Segment ends in continuous dot coordinates; they may lie outside.
    """
    height, width = dots.shape
    u0, v0, u1, v1 = (np.asarray(c, np.float64).ravel() for c in (u0, v0, u1, v1))
    if u0.size == 0 or width == 0 or height == 0:
        return
    # drop the segments wholly beyond one side
    lo_u, hi_u = np.minimum(u0, u1), np.maximum(u0, u1)
    lo_v, hi_v = np.minimum(v0, v1), np.maximum(v0, v1)
    near = (hi_u >= 0) & (lo_u < width) & (hi_v >= 0) & (lo_v < height)
    if not near.all():
        u0, v0, u1, v1 = u0[near], v0[near], u1[near], v1[near]
        lo_u, hi_u, lo_v, hi_v = lo_u[near], hi_u[near], lo_v[near], hi_v[near]
    # clip the segments that cross a side
    crossing = (lo_u < 0) | (hi_u >= width) | (lo_v < 0) | (hi_v >= height)
    if crossing.any():
        # clip copies: the caller's arrays stay as they were
        u0, v0, u1, v1 = u0.copy(), v0.copy(), u1.copy(), v1.copy()
        keep = np.ones(u0.shape, bool)
        keep[crossing], u0[crossing], v0[crossing], u1[crossing], v1[crossing] = _clip(
            u0[crossing], v0[crossing], u1[crossing], v1[crossing], width, height
        )
        u0, v0, u1, v1 = u0[keep], v0[keep], u1[keep], v1[keep]
    du, dv = u1 - u0, v1 - v0
    # one sample per dot along the longer axis, both ends included; float32 is
    # ample once the ends lie on the canvas
    steps = np.ceil(np.maximum(np.abs(du), np.abs(dv))).astype(np.int32)
    counts = steps + 1
    owner = np.repeat(np.arange(counts.size, dtype=np.int32), counts)
    first = np.cumsum(counts) - counts
    j = (np.arange(owner.size, dtype=np.int32) - first[owner]).astype(np.float32)
    per = np.maximum(steps, 1).astype(np.float32)
    step_u, step_v = (du / per).astype(np.float32), (dv / per).astype(np.float32)
    # the samples are >= 0, so truncation is floor
    cols = (u0.astype(np.float32)[owner] + j * step_u[owner]).astype(np.int32)
    rows = (v0.astype(np.float32)[owner] + j * step_v[owner]).astype(np.int32)
    # the samples are inside [0, W) x [0, H), up to rounding at the far side
    np.clip(cols, 0, width - 1, out=cols)
    np.clip(rows, 0, height - 1, out=rows)
    dots.ravel()[rows.astype(np.int64) * width + cols] = True


def _clip(u0, v0, u1, v1, width: int, height: int):
    """Clip segments to [0, W) x [0, H) (Liang-Barsky, all at once); returns keep, u0, v0, u1, v1."""
    du, dv = u1 - u0, v1 - v0
    t0 = np.zeros_like(u0)
    t1 = np.ones_like(u0)
    keep = np.ones(u0.shape, bool)
    top_u, top_v = np.nextafter(width, 0), np.nextafter(height, 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for p, q in ((-du, u0), (du, top_u - u0), (-dv, v0), (dv, top_v - v0)):
            # this side keeps the points with p * t <= q
            keep &= ~((p == 0) & (q < 0))
            r = q / p
            t0 = np.where(p < 0, np.maximum(t0, r), t0)
            t1 = np.where(p > 0, np.minimum(t1, r), t1)
    keep &= t0 <= t1
    return keep, u0 + t0 * du, v0 + t0 * dv, u0 + t1 * du, v0 + t1 * dv


def point_dots(dots: np.ndarray, u, v, *, block: bool = False) -> None:
    """Set the dot under each point that falls on the array.

    With ``block``, set the 2 x 2 dots around it inside its own character,
    so that a lone site reads as a spot.
    """
    height, width = dots.shape
    col = np.floor(np.asarray(u, np.float64)).astype(np.int64)
    row = np.floor(np.asarray(v, np.float64)).astype(np.int64)
    inside = (col >= 0) & (col < width) & (row >= 0) & (row < height)
    col, row = col[inside], row[inside]
    dots[row, col] = True
    if block:
        # the other column of the character, and the neighbouring row inside it
        other_col = col ^ 1
        other_row = np.where(row % DOT_ROWS == DOT_ROWS - 1, row - 1, row + 1)
        dots[row, other_col] = True
        dots[other_row, col] = True
        dots[other_row, other_col] = True


def pack_braille(dots: np.ndarray) -> np.ndarray:
    """Pack a (rows * 4, cols * 2) dot array into (rows, cols) braille bit patterns."""
    height, width = dots.shape
    rows, cols = height // DOT_ROWS, width // DOT_COLS
    cells = dots[: rows * DOT_ROWS, : cols * DOT_COLS].reshape(rows, DOT_ROWS, cols, DOT_COLS)
    codes = np.zeros((rows, cols), np.uint8)
    for r in range(DOT_ROWS):
        for c in range(DOT_COLS):
            codes |= cells[:, r, :, c].view(np.uint8) * DOT_BITS[r, c]
    return codes


def braille_text(codes: np.ndarray) -> str:
    """One row of bit patterns as text: braille glyphs, a plain space where no dot is set."""
    chars = np.where(codes == 0, SPACE, BRAILLE_BLANK + codes.astype(np.uint32)).astype("<u4")
    return chars.tobytes().decode("utf-32-le")


# ---------------------------------------------------------------------------
# the drawable form of a diagram

def _unique_pairs(a: np.ndarray, b: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Undirected pairs (a, b), each once, self pairs dropped."""
    a = np.asarray(a, np.int64)
    b = np.asarray(b, np.int64)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = np.sort((lo * max(n, 1) + hi)[lo != hi])
    if key.size:
        key = key[np.r_[True, key[1:] != key[:-1]]]
    return key // max(n, 1), key % max(n, 1)


@dataclass(eq=False)
class Scene:
    """A diagram in the form the rasterizer draws, prepared once per diagram.

    Attributes
    ----------
    sites : (n, 2) float64
    edges : (e, 4) float64
        Clipped Voronoi edges (the box outline included) as x0, y0, x1, y1, each once.
    delaunay : (t, 4) float64
        Delaunay edges, each once.
    vertices : (m, 2) float64
        Voronoi vertices inside the box.
    colours : (n,) int8
        Palette index of each cell; neighbours differ.
    bbox : (xmin, ymin, xmax, ymax)
    """

    sites: np.ndarray
    edges: np.ndarray
    delaunay: np.ndarray
    vertices: np.ndarray
    colours: np.ndarray
    bbox: tuple
    _tree: cKDTree | None = field(default=None, repr=False)

    @property
    def n_sites(self) -> int:
        return len(self.sites)

    @classmethod
    def from_diagram(cls, diagram) -> "Scene":
        """Collect the segments, marks and cell colours of a diagram."""
        sites = np.asarray(diagram.sites, np.float64)

        # every clipped cell ring, point to next point (wrapping round)
        offsets = np.asarray(diagram.cell_offsets, np.int64)
        ring = np.asarray(diagram.cell_vertices, np.int64)
        nxt = np.arange(1, ring.size + 1)
        sizes = np.diff(offsets)
        full = sizes > 0
        nxt[offsets[1:][full] - 1] = offsets[:-1][full]
        points = np.asarray(diagram.cell_points, np.float64)
        # neighbouring cells share point indices: keep each edge once
        a, b = _unique_pairs(ring, ring[nxt] if ring.size else ring, len(points))
        edges = np.hstack([points[a], points[b]]) if a.size else np.empty((0, 4))

        tri = np.asarray(diagram.delaunay_triangles(), np.int64).reshape(-1, 3)
        ta = tri.ravel()
        tb = tri[:, [1, 2, 0]].ravel()
        a, b = _unique_pairs(ta, tb, len(sites))
        delaunay = np.hstack([sites[a], sites[b]]) if a.size else np.empty((0, 4))

        xmin, ymin, xmax, ymax = diagram.bbox
        vertices = np.asarray(diagram.vertices, np.float64).reshape(-1, 2)
        inside = (
            (vertices[:, 0] >= xmin) & (vertices[:, 0] <= xmax)
            & (vertices[:, 1] >= ymin) & (vertices[:, 1] <= ymax)
        )
        return cls(
            sites=sites,
            edges=edges,
            delaunay=delaunay,
            vertices=vertices[inside],
            colours=cell_colours(diagram),
            bbox=tuple(float(c) for c in diagram.bbox),
        )

    @property
    def tree(self) -> cKDTree:
        """A k-d tree of the sites, built on first use."""
        if self._tree is None:
            self._tree = cKDTree(self.sites if len(self.sites) else np.zeros((0, 2)))
        return self._tree


@dataclass(frozen=True)
class Frame:
    """One drawing of a scene: per character, its dots, the layer that colours them, and its fill.

    Attributes
    ----------
    codes : (rows, cols) uint8
        Braille bit patterns (all layers OR-ed).
    mark : (rows, cols) uint8
        The highest layer with a dot in the character (NO_MARK .. SITE).
    fill : (rows, cols) int16
        Palette index of the cell that owns the character's centre, -1 outside the box.
    """

    codes: np.ndarray
    mark: np.ndarray
    fill: np.ndarray


def cell_fill(scene: Scene, view: View, cols: int, rows: int) -> np.ndarray:
    """The palette index of the cell under each character's centre (-1 outside the box or no sites).

    The nearest site of the centre owns it: that is the Voronoi cell itself,
    found for all characters at once with the k-d tree.
    """
    fill = np.full((rows, cols), -1, np.int16)
    if scene.n_sites == 0 or cols == 0 or rows == 0:
        return fill
    u = (np.arange(cols) + 0.5) * DOT_COLS
    v = (np.arange(rows) + 0.5) * DOT_ROWS
    xs, _ = view.to_world(u, np.zeros_like(u), cols, rows)
    _, ys = view.to_world(np.zeros_like(v), v, cols, rows)
    xmin, ymin, xmax, ymax = scene.bbox
    in_x = (xs >= xmin) & (xs <= xmax)
    in_y = (ys >= ymin) & (ys <= ymax)
    if not (in_x.any() and in_y.any()):
        return fill
    gx, gy = np.meshgrid(xs[in_x], ys[in_y])
    _, nearest = scene.tree.query(np.column_stack([gx.ravel(), gy.ravel()]))
    block = scene.colours[nearest].astype(np.int16).reshape(gx.shape)
    fill[np.ix_(np.flatnonzero(in_y), np.flatnonzero(in_x))] = block
    return fill


def rasterize(
    scene: Scene,
    view: View,
    cols: int,
    rows: int,
    *,
    delaunay: bool = False,
    vertices: bool = True,
) -> Frame:
    """Draw a scene into a frame of ``cols x rows`` characters."""
    shape = (rows * DOT_ROWS, cols * DOT_COLS)
    codes = np.zeros((rows, cols), np.uint8)
    mark = np.zeros((rows, cols), np.uint8)

    def lay(layer: int, dots: np.ndarray) -> None:
        packed = pack_braille(dots)
        codes[:] |= packed
        mark[packed != 0] = layer  # layers come in rising precedence

    if delaunay and len(scene.delaunay):
        dots = np.zeros(shape, bool)
        d = scene.delaunay
        u0, v0 = view.to_dots(d[:, 0], d[:, 1], cols, rows)
        u1, v1 = view.to_dots(d[:, 2], d[:, 3], cols, rows)
        segment_dots(dots, u0, v0, u1, v1)
        lay(DELAUNAY, dots)
    if len(scene.edges):
        dots = np.zeros(shape, bool)
        e = scene.edges
        u0, v0 = view.to_dots(e[:, 0], e[:, 1], cols, rows)
        u1, v1 = view.to_dots(e[:, 2], e[:, 3], cols, rows)
        segment_dots(dots, u0, v0, u1, v1)
        lay(EDGE, dots)
    if vertices and len(scene.vertices) and _per_char(len(scene.vertices), scene, view) < VERTEX_MARKS_PER_CHAR:
        dots = np.zeros(shape, bool)
        u, v = view.to_dots(scene.vertices[:, 0], scene.vertices[:, 1], cols, rows)
        point_dots(dots, u, v)
        lay(VERTEX, dots)
    if scene.n_sites:
        dots = np.zeros(shape, bool)
        u, v = view.to_dots(scene.sites[:, 0], scene.sites[:, 1], cols, rows)
        sparse = _per_char(scene.n_sites, scene, view) < SPARSE_SITES_PER_CHAR
        point_dots(dots, u, v, block=sparse)
        lay(SITE, dots)
    return Frame(codes, mark, cell_fill(scene, view, cols, rows))


def _per_char(count: int, scene: Scene, view: View) -> float:
    """About how many of ``count`` marks spread over the box share one character."""
    xmin, ymin, xmax, ymax = scene.bbox
    char_w, char_h = view.scale * DOT_COLS, view.scale * DOT_ROWS
    chars = max((xmax - xmin) / char_w * (ymax - ymin) / char_h, 1e-12)
    return count / chars


# ---------------------------------------------------------------------------
# styled text

@lru_cache(maxsize=8)
def style_table(palette: Palette) -> tuple[Style, ...]:
    """Styles indexed by ``mark * (len(fills) + 1) + fill + 1``."""
    marks = {
        NO_MARK: (None, False),
        DELAUNAY: (palette.delaunay, False),
        EDGE: (palette.edge, True),
        VERTEX: (palette.vertex, True),
        SITE: (palette.site, True),
    }
    table = []
    for m in range(N_MARKS):
        colour, bold = marks[m]
        for bg in (None, *palette.fills):
            table.append(Style(color=colour, bgcolor=bg, bold=bold or None))
    return tuple(table)


def frame_lines(frame: Frame, palette: Palette) -> list[list[Segment]]:
    """The frame as rows of rich segments, one segment per run of equal style."""
    styles = style_table(palette)
    rows, cols = frame.codes.shape
    if rows == 0 or cols == 0:
        return [[] for _ in range(rows)]
    keys = frame.mark.astype(np.int64) * (len(palette.fills) + 1) + (frame.fill.astype(np.int64) + 1)
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
