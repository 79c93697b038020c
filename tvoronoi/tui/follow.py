"""The view that follows playback: the world region of a step's event, and a view that shows it.

Fortune: a site event shows the new site and the arc it hit (the arc's site
and ends); a circle event shows its circle. An insertion shows its
cavity (the triangles it destroyed) around the new site. The region is never
smaller than a few typical site spacings, so the view does not zoom to a point,
and the view moves only when the region leaves it or has become small in it,
so that playback does not jitter from step to step.
"""

from __future__ import annotations

import math

import numpy as np

from tvoronoi.trace import IncrementalStep
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
from tvoronoi.tui.viewport import View

# The region shown is at least this many typical site spacings (sqrt(box area / n)) across.
MIN_SPACINGS = 6.0
# The region is cut to this fraction of the box's larger side, about the event.
MAX_SHARE = 0.3
# The region is shown with this fraction of its size free on each side.
MARGIN = 0.25
# The view stays while the region fits in it and is at least this fraction of its smaller side.
MIN_SHARE = 0.4


def focus_box(step, points: np.ndarray, bbox) -> tuple[float, float, float, float] | None:
    """The world box (x0, y0, x1, y1) around what ``step`` did, grown to the minimum size and cut to
    the maximum about the event; None when the step has no place (before the first event)."""
    points = np.asarray(points, np.float64).reshape(-1, 2)
    found = _event_points(step, points)
    if found is None:
        return None
    (ax, ay), xy = found
    xy = xy[np.isfinite(xy).all(axis=1)]
    xmin, ymin, xmax, ymax = (float(c) for c in bbox)
    extent = max(xmax - xmin, ymax - ymin) or 1.0
    # an arc of the first rows, or a huge circle, reaches far: keep to the part about the event
    reach = MAX_SHARE * extent / 2
    x0, y0 = max(xy[:, 0].min(), ax - reach), max(xy[:, 1].min(), ay - reach)
    x1, y1 = min(xy[:, 0].max(), ax + reach), min(xy[:, 1].max(), ay + reach)
    spacing = math.sqrt(max((xmax - xmin) * (ymax - ymin), 0.0) / max(len(points), 1))
    least = min(MIN_SPACINGS * spacing, extent) or extent
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    half_w, half_h = max(x1 - x0, least) / 2, max(y1 - y0, least) / 2
    return (float(cx - half_w), float(cy - half_h), float(cx + half_w), float(cy + half_h))


def _event_points(step, points: np.ndarray):
    """The anchor of the step's event (the site, or the new vertex) and the points whose box is its
    region; None for a step with no event."""
    if isinstance(step, IncrementalStep):  # an insertion: the new site, its cavity and the walk that found it
        if step.site < 0:
            return None
        site = points[step.site]
        corners = points[np.asarray(step.conflict, np.int64).ravel()]
        walked = np.asarray(step.walk, np.int64).ravel()
        return site, np.vstack([site[None], corners, points[walked[walked >= 0]]])
    kind = step.kind
    if kind == "circle":  # the circle that emptied
        vx, vy = step.vertex
        r = step.sweep_y - vy
        return (vx, vy), np.array([[vx - r, vy - r], [vx + r, vy + r]])
    if kind in ("site", "repeat"):
        # the new site, the point of the arc above which it appears, that arc's ends and its site
        sx, sy = step.position
        near = [np.array([[sx, sy]])]
        beach = np.asarray(step.beach, np.int64)
        bps = np.asarray(step.breakpoints, np.float64).reshape(-1, 2)
        at = np.flatnonzero(beach == step.site)
        if len(at):
            k = int(at[len(at) // 2])
            if k >= 1:
                near.append(points[beach[[k - 1]]])
            ends = [j for j in (k - 2, k + 1) if 0 <= j < len(bps)]
            near.append(bps[ends])
            if k >= 1 and 0 <= k - 1 < len(bps):
                near.append(np.array([[sx, bps[k - 1, 1]]]))  # the split point, on the arc
        return (sx, sy), np.vstack(near)
    return None


def follow_view(view: View, box, cols: int, rows: int) -> View:
    """``view`` if it shows ``box`` well already; else the view centred on the box, with a margin."""
    x0, y0, x1, y1 = box
    w_world, h_world = cols * DOT_COLS * view.scale, rows * DOT_ROWS * view.scale
    vx0, vy0 = view.cx - w_world / 2, view.cy - h_world / 2
    inside = vx0 <= x0 and x1 <= vx0 + w_world and vy0 <= y0 and y1 <= vy0 + h_world
    share = max((x1 - x0) / w_world, (y1 - y0) / h_world) if w_world > 0 and h_world > 0 else 0.0
    if inside and share >= MIN_SHARE:
        return view
    grow_x, grow_y = (x1 - x0) * MARGIN, (y1 - y0) * MARGIN
    return View.fit((x0 - grow_x, y0 - grow_y, x1 + grow_x, y1 + grow_y), cols, rows)
