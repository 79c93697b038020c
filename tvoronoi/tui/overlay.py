"""Pictures of algorithm steps: a scene of the diagram so far and an overlay of what the step shows.

Fortune: the sweep line, the beach line's arcs, pending circle events,
growing edges, the event just handled, the sites not reached yet; the cells
behind the beach line (which are final) are filled. Incremental: the diagram
of the sites inserted so far, the new site, its conflict region and the cells
it took area from, and the location walk that found it (the triangles
visited, and the hull edge it ended beyond when the site lies outside).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from tvoronoi.trace import FortuneStep, IncrementalStep, parabola_y
from tvoronoi.tui.colours import adjacency_lists, cell_adjacency, repair_colours
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS, clip_segments
from tvoronoi.tui.layers import (
    BEACH,
    CIRCLE,
    CONFLICT,
    CONFLICT_FILL,
    EVENT,
    FUTURE,
    GROWING,
    SWEEP,
    TINTED,
    WALK,
)
from tvoronoi.tui.raster import SPARSE_SITES_PER_CHAR, Painter, per_char
from tvoronoi.tui.scene import Scene
from tvoronoi.tui.viewport import View, ViewLike, char_centres

# Circles are drawn as polygons with about one corner per this many dots of
# circumference, and between these many corners.
CIRCLE_DOTS_PER_SIDE = 1.5
CIRCLE_MIN_SIDES, CIRCLE_MAX_SIDES = 12, 720
# Lines that run off to infinity (growing edges of the first row, a lone
# site's arc) end this many canvas heights beyond the view.
FAR_VIEWS = 4.0
# Growing edges and new Delaunay edges are dashed: this many dots on, as many off.
DASH = 2


def _empty_segments() -> np.ndarray:
    return np.empty((0, 4))


def _far_below(view: ViewLike, cols: int, rows: int) -> float:
    """A height this many canvas heights below the bottom of the view."""
    _, y = view.to_world(0.0, (1.0 + FAR_VIEWS) * rows * DOT_ROWS, cols, rows)
    return float(y)


def _triangle_segments(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The three sides of each triangle (t, 3 point rows) as (3t, 4) segments."""
    triangles = np.asarray(triangles, np.int64).reshape(-1, 3)
    a = points[triangles.ravel()]
    b = points[triangles[:, [1, 2, 0]].ravel()]
    return np.hstack([a, b]) if len(a) else _empty_segments()


def walk_segments(points: np.ndarray, walk: np.ndarray) -> np.ndarray:
    """The sides of the triangles a location walk visited (w, 3 point rows, -1 at infinity), each
    once: the finite triangles whole, of an infinite one its finite side (the hull edge)."""
    walk = np.asarray(walk, np.int64).reshape(-1, 3)
    if not len(walk):
        return _empty_segments()
    a, b = walk.ravel(), walk[:, [1, 2, 0]].ravel()
    keep = (a >= 0) & (b >= 0)
    a, b = a[keep], b[keep]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    _, first = np.unique(lo * len(points) + hi, return_index=True)
    first = np.sort(first)
    return np.hstack([points[a[first]], points[b[first]]])


def _inside_triangles(xs: np.ndarray, ys: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Whether each point (xs, ys flat arrays) lies in any triangle of ``corners`` (t, 3, 2)."""
    inside = np.zeros(xs.shape, bool)
    for tri in corners:
        signs = []
        for k in range(3):
            (ax, ay), (bx, by) = tri[k], tri[(k + 1) % 3]
            signs.append((bx - ax) * (ys - ay) - (by - ay) * (xs - ax))
        s0, s1, s2 = signs
        inside |= ((s0 >= 0) & (s1 >= 0) & (s2 >= 0)) | ((s0 <= 0) & (s1 <= 0) & (s2 <= 0))
    return inside


def circle_segments(circles: npt.ArrayLike, scale: float, window=None) -> np.ndarray:
    """Outlines of circles (m, 3: cx, cy, r) as polygon sides (k, 4), fine enough for dots of ``scale``.

    With a ``window`` (x0, y0, x1, y1), the world box the canvas shows, only what lies in it is
    drawn: a circle far larger than the view, or far outside the box, becomes the arc that enters
    the view (finely divided, however large the circle), one wholly outside it or holding the
    whole view inside it draws nothing.
    """
    circles = np.asarray(circles, np.float64).reshape(-1, 3)
    circles = circles[np.isfinite(circles).all(axis=1)]
    if window is None or not len(circles):
        return _full_circles(circles, scale)
    x0, y0, x1, y1 = (float(c) for c in window)
    cx, cy, r = circles.T
    # the nearest and farthest points of the window from each centre
    near = np.hypot(np.clip(cx, x0, x1) - cx, np.clip(cy, y0, y1) - cy)
    far = np.hypot(np.maximum(np.abs(cx - x0), np.abs(cx - x1)), np.maximum(np.abs(cy - y0), np.abs(cy - y1)))
    meets = (near <= r) & (far >= r)
    inside = (cx - r >= x0) & (cx + r <= x1) & (cy - r >= y0) & (cy + r <= y1)
    parts = [_full_circles(circles[meets & inside], scale)]
    for c in circles[meets & ~inside]:
        parts.append(_arcs_in_window(c, scale, (x0, y0, x1, y1)))
    return np.concatenate(parts)


def _full_circles(circles: np.ndarray, scale: float) -> np.ndarray:
    if not len(circles):
        return _empty_segments()
    around = 2 * np.pi * circles[:, 2] / scale / CIRCLE_DOTS_PER_SIDE
    sides = np.clip(np.ceil(around), CIRCLE_MIN_SIDES, CIRCLE_MAX_SIDES).astype(np.int64)
    owner = np.repeat(np.arange(len(circles)), sides)
    first = np.cumsum(sides) - sides
    k = np.arange(owner.size) - first[owner]
    t0 = 2 * np.pi * k / sides[owner]
    t1 = 2 * np.pi * (k + 1) / sides[owner]
    cx, cy, r = circles[owner, 0], circles[owner, 1], circles[owner, 2]
    return np.column_stack([cx + r * np.cos(t0), cy + r * np.sin(t0), cx + r * np.cos(t1), cy + r * np.sin(t1)])


def _arcs_in_window(circle: np.ndarray, scale: float, window) -> np.ndarray:
    """The arcs of one circle inside the window, as polygon sides of about CIRCLE_DOTS_PER_SIDE dots."""
    cx, cy, r = (float(c) for c in circle)
    x0, y0, x1, y1 = window
    # the angles where the circle crosses the window's four lines cut it into arcs, each wholly
    # inside or wholly outside
    cuts = [0.0, 2 * math.pi]
    for x in (x0, x1):
        if abs(x - cx) <= r:
            a = math.acos(min(max((x - cx) / r, -1.0), 1.0))
            cuts += [a, 2 * math.pi - a]
    for y in (y0, y1):
        if abs(y - cy) <= r:
            a = math.asin(min(max((y - cy) / r, -1.0), 1.0))
            cuts += [a % (2 * math.pi), (math.pi - a) % (2 * math.pi)]
    angles = np.unique(cuts)
    parts = []
    for t0, t1 in zip(angles[:-1], angles[1:]):
        mid = (t0 + t1) / 2
        mx, my = cx + r * math.cos(mid), cy + r * math.sin(mid)
        if not (x0 <= mx <= x1 and y0 <= my <= y1) or t1 <= t0:
            continue
        sides = int(min(max(math.ceil((t1 - t0) * r / scale / CIRCLE_DOTS_PER_SIDE), 1), CIRCLE_MAX_SIDES))
        t = np.linspace(t0, t1, sides + 1)
        xs, ys = cx + r * np.cos(t), cy + r * np.sin(t)
        parts.append(np.column_stack([xs[:-1], ys[:-1], xs[1:], ys[1:]]))
    return np.concatenate(parts) if parts else _empty_segments()


def beach_heights(step, points: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """Height of the beach line above each x (sorted or not); NaN where it is undefined.

    The arc above x is the one between the breakpoints that bracket x; an arc
    whose site lies on the sweep line has no width (it is a vertical ray).
    """
    beach = np.asarray(step.beach, np.int64)
    if not len(beach) or not math.isfinite(step.sweep_y):
        return np.full(np.shape(xs), np.nan)
    bp_x = np.asarray(step.breakpoints, np.float64).reshape(-1, 2)[:, 0]
    arc = np.searchsorted(bp_x, xs, side="right")
    site = points[beach[arc]]
    ys = parabola_y(site[:, 0], site[:, 1], xs, step.sweep_y)
    return np.where(np.isfinite(ys), ys, np.nan)


@dataclass(eq=False)
class FortuneOverlay:
    """What a Fortune step draws over the cells finished so far."""

    step: FortuneStep
    points: np.ndarray
    future: np.ndarray  # (k, 2) sites beyond the sweep line
    bbox: tuple  # the diagram's box: edges are cut to it, as in the finished diagram

    def draw(self, paint: Painter) -> None:
        step, view, cols, rows = self.step, paint.view, paint.cols, paint.rows
        sparse = per_char(len(self.points), self, view) < SPARSE_SITES_PER_CHAR
        paint.points(FUTURE, self.future, block=sparse)
        if len(step.growing_edges):
            grow = np.asarray(step.growing_edges, np.float64).reshape(-1, 4).copy()
            # the first row's edges start at -inf: from below the box
            grow[:, [1, 3]] = np.maximum(grow[:, [1, 3]], self.bbox[1] - 1.0)
            paint.segments(GROWING, clip_segments(grow, self.bbox), dash=DASH)
        paint.segments(CIRCLE, circle_segments(step.circles, view.scale, paint.world))
        paint.segments(BEACH, self.beach_segments(view, cols, rows))
        if math.isfinite(step.sweep_y):
            x0, _ = view.to_world(-1.0, 0.0, cols, rows)
            x1, _ = view.to_world(cols * DOT_COLS + 1.0, 0.0, cols, rows)
            paint.segments(SWEEP, [[float(x0), step.sweep_y, float(x1), step.sweep_y]])
        if step.kind == "circle":
            assert step.vertex is not None, "a circle event creates a vertex"
            vx, vy = step.vertex
            # the circle that just emptied, and its centre: the new vertex
            paint.segments(EVENT, circle_segments([[vx, vy, step.sweep_y - vy]], view.scale, paint.world), dash=DASH)
            paint.points(EVENT, [[vx, vy]], block=True)
        elif step.kind in ("site", "repeat"):
            paint.points(EVENT, [step.position], block=True)

    def beach_segments(self, view: ViewLike, cols: int, rows: int) -> np.ndarray:
        """The beach line as short segments: sampled at every dot column and at every breakpoint."""
        step = self.step
        beach = np.asarray(step.beach, np.int64)
        if not len(beach) or not math.isfinite(step.sweep_y):
            return _empty_segments()
        u = np.arange(-1, cols * DOT_COLS + 2, dtype=np.float64)
        xs, _ = view.to_world(u, np.zeros_like(u), cols, rows)
        lo, hi = xs[0], xs[-1]
        bps = np.asarray(step.breakpoints, np.float64).reshape(-1, 2)
        bp_x = bps[:, 0]
        xs = np.unique(np.concatenate([xs, bp_x[(bp_x > lo) & (bp_x < hi)]]))
        ys = beach_heights(step, self.points, xs)
        far = _far_below(view, cols, rows)
        ys = np.maximum(ys, far)  # NaN stays NaN: no segment there
        segs = [np.column_stack([xs[:-1], ys[:-1], xs[1:], ys[1:]])]
        # an arc with no width (its site on the sweep line) is a vertical ray
        # from the site down to the arc below
        sites = self.points[beach]
        flat = sites[:, 1] == step.sweep_y
        if flat.any():
            below = beach_heights(step, self.points, sites[flat, 0] + 0.0)
            # the breakpoints either side hold the point below; use them where known
            idx = np.flatnonzero(flat)
            down = np.full(len(idx), far)
            for n, k in enumerate(idx.tolist()):
                ends = [bps[j, 1] for j in (k - 1, k) if 0 <= j < len(bps) and math.isfinite(bps[j, 1])]
                if ends:
                    down[n] = max(min(ends), far)
                elif math.isfinite(below[n]):
                    down[n] = max(below[n], far)
            segs.append(np.column_stack([sites[flat, 0], sites[flat, 1], sites[flat, 0], down]))
        return np.concatenate(segs)

    def refill(self, fill: np.ndarray, owner: np.ndarray, view: View, cols: int, rows: int) -> np.ndarray:
        """Only the part below the beach line is final: no fill above it."""
        xs, ys = char_centres(view, cols, rows)
        heights = beach_heights(self.step, self.points, xs)
        above = ~(ys[:, None] < heights[None, :])  # NaN heights: nothing is final
        fill = fill.copy()
        fill[above] = -1
        return fill


@dataclass(eq=False)
class IncrementalOverlay:
    """What an insertion step draws over the diagram of the sites inserted so far."""

    step: IncrementalStep
    points: np.ndarray
    future: np.ndarray  # (k, 2) sites not inserted yet
    conflict: np.ndarray  # (c, 3, 2) corners of the destroyed triangles
    new_edges: np.ndarray  # (e, 4) Delaunay edges of the new triangles
    stolen_rows: np.ndarray  # rows of scene.sites whose cells lost area
    bbox: tuple
    walk: np.ndarray = dataclasses.field(default_factory=_empty_segments)  # (w, 4) sides visited

    def draw(self, paint: Painter) -> None:
        sparse = per_char(len(self.points), self, paint.view) < SPARSE_SITES_PER_CHAR
        paint.points(FUTURE, self.future, block=sparse)
        paint.segments(GROWING, self.new_edges, dash=DASH)
        paint.segments(WALK, self.walk)
        corners = self.conflict
        if len(corners):
            sides = np.concatenate([np.hstack([corners[:, k], corners[:, (k + 1) % 3]]) for k in range(3)])
            paint.segments(CONFLICT, sides)
        if self.step.site >= 0:
            paint.points(EVENT, self.points[[self.step.site]], block=True)

    def refill(self, fill: np.ndarray, owner: np.ndarray, view: View, cols: int, rows: int) -> np.ndarray:
        """Tint the cells the new site took area from; fill its conflict region."""
        fill = fill.copy()
        if len(self.stolen_rows):
            tinted = np.isin(owner, self.stolen_rows) & (fill >= 0)
            fill[tinted] += TINTED
        if len(self.conflict):
            xs, ys = char_centres(view, cols, rows)
            gx, gy = np.meshgrid(xs, ys)
            inside = _inside_triangles(gx.ravel(), gy.ravel(), self.conflict).reshape(gx.shape)
            fill[inside] = CONFLICT_FILL
        return fill


def fortune_picture(step, points: np.ndarray, colours: np.ndarray, bbox) -> tuple[Scene, FortuneOverlay]:
    """The scene and overlay of a Fortune step.

    Parameters
    ----------
    step : FortuneStep
    points : (n, 2) float64, all the sites
    colours : (n,) int8, the cell colours of the finished diagram (the cells
        behind the beach line are final, so they keep these)
    bbox : the box of the finished diagram
    """
    points = np.asarray(points, np.float64)
    ys, xs = points[:, 1], points[:, 0]
    sweep = step.sweep_y
    swept = ys < sweep
    if step.kind in ("site", "repeat"):
        # sites on the sweep line are handled left to right
        swept |= (ys == sweep) & (xs <= step.position[0])
    rows = np.flatnonzero(swept)
    vertices = np.asarray(step.vertices, np.float64).reshape(-1, 2)
    xmin, ymin, xmax, ymax = bbox
    inside = (vertices[:, 0] >= xmin) & (vertices[:, 0] <= xmax) & (vertices[:, 1] >= ymin) & (vertices[:, 1] <= ymax)
    box = tuple(float(c) for c in bbox)
    xmin, ymin, xmax, ymax = box
    outline = np.array(
        [[xmin, ymin, xmax, ymin], [xmax, ymin, xmax, ymax], [xmax, ymax, xmin, ymax], [xmin, ymax, xmin, ymin]]
    )
    finished = clip_segments(np.asarray(step.finished_edges, np.float64).reshape(-1, 4), box)
    scene = _SubScene(
        rows,
        sites=points[rows],
        edges=np.concatenate([outline, finished]),
        delaunay_edges=_empty_segments(),
        vertices=vertices[inside],
        colours=np.asarray(colours)[rows],
        bbox=tuple(float(c) for c in bbox),
    )
    return scene, FortuneOverlay(step, points, points[~swept], box)


def incremental_picture(step, points: np.ndarray, colours: np.ndarray) -> tuple[Scene, IncrementalOverlay]:
    """The scene and overlay of an insertion step.

    ``colours`` are the cell colours of the finished diagram; cells that now
    touch a cell of their colour get another one (the same one for the same
    step, whatever step came before).
    """
    points = np.asarray(points, np.float64)
    diagram = step.diagram
    rows = np.asarray(step.inserted, np.int64)
    a, b = cell_adjacency(diagram)
    mine = np.asarray(colours, np.int8).copy()
    # one end of each edge between equal colours takes a colour free around it
    clash = np.unique(b[mine[a] == mine[b]])
    if len(clash):
        repair_colours(mine, adjacency_lists(len(points), a, b), clash)
    full = Scene.from_diagram(diagram, colours=mine)
    scene = _SubScene(
        rows,
        sites=points[rows],
        edge_mesh=full.edge_mesh,
        delaunay_edges=full.delaunay,
        vertices=full.vertices,
        colours=mine[rows],
        bbox=full.bbox,
    )
    pending = np.ones(len(points), bool)
    pending[rows] = False
    conflict = points[np.asarray(step.conflict, np.int64).reshape(-1, 3)].reshape(-1, 3, 2)
    new_tri = np.asarray(step.new_triangles, np.int64).reshape(-1, 3)
    overlay = IncrementalOverlay(
        step=step,
        points=points,
        future=points[pending],
        conflict=conflict,
        new_edges=_triangle_segments(points, new_tri),
        stolen_rows=np.flatnonzero(np.isin(rows, step.stolen_from)),
        bbox=full.bbox,
        walk=walk_segments(points, step.walk),
    )
    return scene, overlay


class _SubScene(Scene):
    """A scene of some of the sites: ``rows`` gives each drawn site's id."""

    def __init__(self, rows: np.ndarray, **scene) -> None:
        super().__init__(**scene)
        self.rows = rows

    def site_ids(self) -> np.ndarray:
        return self.rows
