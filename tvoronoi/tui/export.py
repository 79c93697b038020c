"""Export the view: the cells, edges and sites the canvas shows now, as an SVG (vector) or a PNG.

The picture is the canvas's own: the same world window, the cells in their fill colours, the Voronoi
edges, the Delaunay edges when they are shown, the sites. The PNG is rasterised here with numpy
(each pixel takes the colour of the cell of the nearest site, as the canvas's fills do) and written
with zlib and struct: no imaging library.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import escape

import numpy as np

import tvoronoi
from tvoronoi.errors import TvoronoiError
from tvoronoi.tui.colours import Palette
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
from tvoronoi.tui.scene import ring_next
from tvoronoi.tui.viewport import View

# Pixels per braille dot of the canvas: a 120 x 40 canvas (240 x 160 dots) exports at 960 x 640.
PX_PER_DOT = 4
# The page behind the box, for a dark and a light theme.
BACKGROUND = {True: "#121212", False: "#ffffff"}
# Sites are drawn as discs of this radius, edges with this width (pixels).
SITE_RADIUS_PX = 2.0
EDGE_WIDTH_PX = 1.0
FORMATS = (".svg", ".png")


@dataclass(frozen=True)
class ViewPicture:
    """What an export draws: the visible cells (rings in world coordinates, each with its colour),
    the sites shown, the Delaunay edges (empty when hidden) and the window of the canvas.

    ``window`` is (x0, y0, x1, y1) in world units; ``width`` and ``height`` the picture's size in
    pixels; ``view`` maps world points to the canvas's dots.
    """

    rings: list[np.ndarray]
    colours: list[str]
    sites: np.ndarray
    delaunay: np.ndarray
    window: tuple[float, float, float, float]
    view: View
    cols: int
    rows: int
    palette: Palette
    background: str
    # for the PNG: the sites whose cells fill the pixels, and the colour of each of their cells
    owners: np.ndarray
    owner_colours: list[str]
    bbox: tuple[float, float, float, float]

    @property
    def width(self) -> int:
        return self.cols * DOT_COLS * PX_PER_DOT

    @property
    def height(self) -> int:
        return self.rows * DOT_ROWS * PX_PER_DOT

    def to_px(self, xy: np.ndarray) -> np.ndarray:
        """World points (k, 2) to pixel coordinates (x right, y down)."""
        xy = np.asarray(xy, np.float64).reshape(-1, 2)
        u, v = self.view.to_dots(xy[:, 0], xy[:, 1], self.cols, self.rows)
        return np.column_stack([u, v]) * PX_PER_DOT


def view_window(view: View, cols: int, rows: int) -> tuple[float, float, float, float]:
    """The world box (x0, y0, x1, y1) a canvas of ``cols x rows`` characters shows."""
    (x0, x1), (y1, y0) = view.to_world(np.array([0.0, cols * DOT_COLS]), np.array([0.0, rows * DOT_ROWS]), cols, rows)
    return float(x0), float(y0), float(x1), float(y1)


def visible_cells(offsets: np.ndarray, xy: np.ndarray, window) -> np.ndarray:
    """Which convex rings meet the window: ``xy`` the ring points one cell after the other
    (counter-clockwise), ``offsets`` (n + 1,) where each cell's run starts.

    Separating axes: a convex ring misses an axis-aligned box exactly when their boxes do not
    overlap or one of the ring's sides has the whole box strictly on its outer side.
    """
    offsets = np.asarray(offsets, np.int64)
    n = len(offsets) - 1
    sizes = np.diff(offsets)
    full = sizes > 0
    seen = np.zeros(n, bool)
    if not full.any():
        return seen
    x0, y0, x1, y1 = window
    starts = offsets[:-1][full]
    xs, ys = xy[:, 0], xy[:, 1]
    overlap = (
        (np.minimum.reduceat(xs, starts) <= x1)
        & (np.maximum.reduceat(xs, starts) >= x0)
        & (np.minimum.reduceat(ys, starts) <= y1)
        & (np.maximum.reduceat(ys, starts) >= y0)
    )
    # each side: from a ring point to the next one of its ring (wrapping round)
    nxt = ring_next(offsets, len(xy))
    ax, ay, bx, by = xs, ys, xs[nxt], ys[nxt]
    outside = np.ones(len(xy), bool)
    for cx, cy in ((x0, y0), (x1, y0), (x1, y1), (x0, y1)):
        outside &= (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) < 0
    separated = np.logical_or.reduceat(outside, starts)
    seen[full] = overlap & ~separated
    return seen


def picture(
    scene, view: View, cols: int, rows: int, palette: Palette, *, dark: bool, delaunay: bool, diagram=None
) -> ViewPicture:
    """The picture of what a canvas of ``cols x rows`` shows of ``scene`` through ``view``.

    ``diagram`` is the scene's diagram when its cell i is the scene's site row i (a built
    diagram); otherwise (an edited scene) the diagram of the sites drawn is built here.
    """
    if scene is None or scene.n_sites == 0:
        raise TvoronoiError("there is no diagram to export")
    colours = np.asarray(scene.colours)
    if diagram is None:
        drawn = scene.drawn()
        diagram = tvoronoi.voronoi(scene.sites[drawn], bbox=scene.bbox)
        ids = np.asarray(drawn, np.int64)
    else:
        ids = np.arange(diagram.n_sites)
    window = view_window(view, cols, rows)
    offsets = np.asarray(diagram.cell_offsets, np.int64)
    xy = np.asarray(diagram.cell_points, np.float64)[np.asarray(diagram.cell_vertices, np.int64)]
    seen = np.flatnonzero(visible_cells(offsets, xy, window))
    fills = palette.fills
    rings = [xy[offsets[i] : offsets[i + 1]] for i in seen.tolist()]
    ring_colours = [fills[int(colours[ids[i]]) % len(fills)] for i in seen.tolist()]
    sites = np.asarray(diagram.sites, np.float64)
    x0, y0, x1, y1 = window
    shown = (sites[:, 0] >= x0) & (sites[:, 0] <= x1) & (sites[:, 1] >= y0) & (sites[:, 1] <= y1)
    links = np.asarray(scene.delaunay, np.float64).reshape(-1, 4) if delaunay else np.empty((0, 4))
    links = links[np.isfinite(links).all(axis=1)]
    if len(links):
        keep = (
            (np.maximum(links[:, 0], links[:, 2]) >= x0)
            & (np.minimum(links[:, 0], links[:, 2]) <= x1)
            & (np.maximum(links[:, 1], links[:, 3]) >= y0)
            & (np.minimum(links[:, 1], links[:, 3]) <= y1)
        )
        links = links[keep]
    has_cell = np.diff(offsets) > 0
    xmin, ymin, xmax, ymax = diagram.bbox
    return ViewPicture(
        rings=rings,
        colours=ring_colours,
        sites=sites[shown],
        delaunay=links,
        window=window,
        view=view,
        cols=cols,
        rows=rows,
        palette=palette,
        background=BACKGROUND[dark],
        owners=sites[has_cell],
        owner_colours=[fills[int(colours[i]) % len(fills)] for i in ids[has_cell]],
        bbox=(float(xmin), float(ymin), float(xmax), float(ymax)),
    )


# ---------------------------------------------------------------------------
# SVG


def _points_attr(px: np.ndarray) -> str:
    return " ".join(f"{x:.2f},{y:.2f}" for x, y in px.tolist())


def to_svg(pic: ViewPicture) -> str:
    """The picture as an SVG document: one ``<polygon>`` per visible cell (``fill`` its colour,
    ``class="cell"``), the Delaunay edges as ``<line class="delaunay">``, one ``<circle
    class="site">`` per visible site; drawn in the canvas's window, clipped to it."""
    w, h, pal = pic.width, pic.height, pic.palette
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">',
        f"<title>{escape('tvoronoi view')} {pic.window[0]:.6g} {pic.window[1]:.6g} "
        f"{pic.window[2]:.6g} {pic.window[3]:.6g}</title>",
        f'<rect class="background" x="0" y="0" width="{w}" height="{h}" fill="{pic.background}"/>',
        f'<g id="cells" stroke="{pal.edge}" stroke-width="{EDGE_WIDTH_PX}" stroke-linejoin="round">',
    ]
    for ring, colour in zip(pic.rings, pic.colours):
        out.append(f'<polygon class="cell" fill="{colour}" points="{_points_attr(pic.to_px(ring))}"/>')
    out.append("</g>")
    if len(pic.delaunay):
        out.append(f'<g id="delaunay" stroke="{pal.delaunay}" stroke-width="{EDGE_WIDTH_PX}">')
        a, b = pic.to_px(pic.delaunay[:, :2]), pic.to_px(pic.delaunay[:, 2:])
        for (ax, ay), (bx, by) in zip(a.tolist(), b.tolist()):
            out.append(f'<line class="delaunay" x1="{ax:.2f}" y1="{ay:.2f}" x2="{bx:.2f}" y2="{by:.2f}"/>')
        out.append("</g>")
    out.append(f'<g id="sites" fill="{pal.site}">')
    for x, y in pic.to_px(pic.sites).tolist():
        out.append(f'<circle class="site" cx="{x:.2f}" cy="{y:.2f}" r="{SITE_RADIUS_PX}"/>')
    out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------
# PNG


def _rgb(colour: str) -> tuple[int, int, int]:
    return int(colour[1:3], 16), int(colour[3:5], 16), int(colour[5:7], 16)


def rasterise(pic: ViewPicture) -> np.ndarray:
    """The picture as an (height, width, 3) uint8 image: each pixel inside the box the colour of the
    cell of its nearest site (that is the cell), edges where the owner changes, Delaunay edges, and
    the sites as small discs."""
    from scipy.spatial import cKDTree

    w, h = pic.width, pic.height
    image = np.empty((h, w, 3), np.uint8)
    image[:] = _rgb(pic.background)
    # pixel centres in the world
    u = (np.arange(w) + 0.5) / PX_PER_DOT
    v = (np.arange(h) + 0.5) / PX_PER_DOT
    xs, _ = pic.view.to_world(u, np.zeros_like(u), pic.cols, pic.rows)
    _, ys = pic.view.to_world(np.zeros_like(v), v, pic.cols, pic.rows)
    xmin, ymin, xmax, ymax = pic.bbox
    in_x, in_y = (xs >= xmin) & (xs <= xmax), (ys >= ymin) & (ys <= ymax)
    owner = np.full((h, w), -1, np.int64)
    if in_x.any() and in_y.any() and len(pic.owners):
        gx, gy = np.meshgrid(xs[in_x], ys[in_y])
        _, k = cKDTree(pic.owners).query(np.column_stack([gx.ravel(), gy.ravel()]))
        owner[np.ix_(np.flatnonzero(in_y), np.flatnonzero(in_x))] = k.reshape(gx.shape)
    table = np.array([_rgb(c) for c in pic.owner_colours] or [(0, 0, 0)], np.uint8)
    inside = owner >= 0
    image[inside] = table[owner[inside]]
    # edges: where the owner changes (a cell's side, or the box)
    edge = np.zeros((h, w), bool)
    edge[:, 1:] |= owner[:, 1:] != owner[:, :-1]
    edge[1:, :] |= owner[1:, :] != owner[:-1, :]
    image[edge] = _rgb(pic.palette.edge)
    if len(pic.delaunay):
        _draw_segments(
            image, pic.to_px(pic.delaunay[:, :2]), pic.to_px(pic.delaunay[:, 2:]), _rgb(pic.palette.delaunay)
        )
    if len(pic.sites):
        px = pic.to_px(pic.sites)
        r = int(np.ceil(SITE_RADIUS_PX))
        for dy in range(-r, r + 1):
            for dx in range(-r, r + 1):
                if dx * dx + dy * dy > SITE_RADIUS_PX**2:
                    continue
                cx = np.floor(px[:, 0]).astype(np.int64) + dx
                cy = np.floor(px[:, 1]).astype(np.int64) + dy
                ok = (cx >= 0) & (cx < w) & (cy >= 0) & (cy < h)
                image[cy[ok], cx[ok]] = _rgb(pic.palette.site)
    return image


def _draw_segments(image: np.ndarray, a: np.ndarray, b: np.ndarray, colour) -> None:
    """Segments from pixel points a to b, sampled every half pixel."""
    h, w = image.shape[:2]
    length = np.ceil(2 * np.hypot(*(b - a).T)).astype(np.int64) + 1
    owner = np.repeat(np.arange(len(a)), length)
    t = (np.arange(owner.size) - np.repeat(np.cumsum(length) - length, length)) / np.maximum(length[owner] - 1, 1)
    pts = a[owner] + t[:, None] * (b - a)[owner]
    cx, cy = np.floor(pts[:, 0]).astype(np.int64), np.floor(pts[:, 1]).astype(np.int64)
    ok = (cx >= 0) & (cx < w) & (cy >= 0) & (cy < h)
    image[cy[ok], cx[ok]] = colour


def png_bytes(image: np.ndarray) -> bytes:
    """An (h, w, 3) uint8 image as a PNG file (8-bit RGB, no interlace, filter 0 on every row)."""
    image = np.ascontiguousarray(image, np.uint8)
    h, w = image.shape[:2]
    raw = np.zeros((h, 1 + 3 * w), np.uint8)
    raw[:, 1:] = image.reshape(h, 3 * w)

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw.tobytes(), 6))
        + chunk(b"IEND", b"")
    )


def export_view(pic: ViewPicture, path: Path) -> str:
    """Write the picture to ``path`` as SVG or PNG (by its suffix); returns the format's name.

    Raises
    ------
    TvoronoiError
        A suffix other than .svg or .png.
    """
    from tvoronoi.writers.targets import open_output

    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise TvoronoiError(f"cannot export the view as {path.name!s}: give a name ending in .svg or .png")
    data = to_svg(pic).encode() if suffix == ".svg" else png_bytes(rasterise(pic))
    with open_output(str(path), overwrite=True) as out:
        out.write(data)
    return suffix[1:].upper()
