"""The canvas's view of the world: centre, scale and pans in whole characters; world to dot coordinates."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS

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
            return View(
                self.ax, self.ay, self.scale, self.dc + int(dx_dots) // DOT_COLS, self.dr + int(dy_dots) // DOT_ROWS
            )
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
        return self.view.to_world(
            np.asarray(u) + self.c0 * DOT_COLS, np.asarray(v) + self.r0 * DOT_ROWS, self.cols, self.rows
        )


# What the rasterizer draws through: a whole canvas's view, or a part of it.
ViewLike = View | Window


def char_centres(view: ViewLike, cols: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """World x of each character column's centre (cols,) and y of each row's centre (rows,)."""
    u = (np.arange(cols) + 0.5) * DOT_COLS
    v = (np.arange(rows) + 0.5) * DOT_ROWS
    xs, _ = view.to_world(u, np.zeros_like(u), cols, rows)
    _, ys = view.to_world(np.zeros_like(v), v, cols, rows)
    return xs, ys
