"""The engine's state during playback, as text for the side panel.

Fortune: the next events of the queue (site or circle, and where), the beach
line's arcs in order (a window about the current arc when it is long), and the
vertices and edges so far. Incremental: the site inserted, the location walk
that found it (the triangles visited), its cavity and the cells that lost area
to it.
"""

from __future__ import annotations

import numpy as np
from rich.text import Text

# Events of the queue listed.
NEXT_EVENTS = 4
# Arcs of the beach line listed each side of the current one.
ARCS_EACH_SIDE = 2
# Cells that lost area listed by id.
LOSERS_LISTED = 8
# Triangles of the location walk listed: the first ones and the last (where it ended).
WALK_LISTED = 4


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}{'' if n == 1 else 's'}"


def _xy(x: float, y: float) -> str:
    return f"({x:.3g}, {y:.3g})"


def next_events(step, points: np.ndarray, count: int = NEXT_EVENTS) -> list[tuple[str, float, float]]:
    """The next ``count`` events of Fortune's queue after ``step``, as (kind, x, y): a site event at
    its site, a circle event at the top of its circle (where the sweep line meets it).

    The sweep line moves up: the next site is the lowest one above it (left to right on one height).
    """
    points = np.asarray(points, np.float64).reshape(-1, 2)
    xs, ys = points[:, 0], points[:, 1]
    sweep = step.sweep_y
    ahead = ys > sweep
    if step.kind in ("site", "repeat"):
        ahead |= (ys == sweep) & (xs > step.position[0])
    elif step.kind == "start":
        ahead[:] = True
    rows = np.flatnonzero(ahead)
    order = np.lexsort((xs[rows], ys[rows]))[:count]
    events = [("site", float(xs[r]), float(ys[r])) for r in rows[order]]
    circles = np.asarray(step.circles, np.float64).reshape(-1, 3)
    if len(circles):
        tops = circles[:, 1] + circles[:, 2]
        for i in np.argsort(tops, kind="stable")[:count]:
            events.append(("circle", float(circles[i, 0]), float(tops[i])))
    # sites before circles at one height, as the queue takes them
    events.sort(key=lambda e: (e[2], e[0] != "site", e[1]))
    return events[:count]


def current_arc(step) -> tuple[int, int]:
    """Where in the beach line the step happened: (the new site's arc, -1) for a site event,
    (-1, g) for a circle event whose arc vanished between arcs g and g + 1, (-1, -1) otherwise."""
    beach = np.asarray(step.beach)
    if step.kind in ("site", "repeat"):
        at = np.flatnonzero(beach == step.site)
        if len(at):
            return int(at[len(at) // 2]), -1
    if step.kind == "circle" and len(beach) > 1:
        bp_x = np.asarray(step.breakpoints, np.float64).reshape(-1, 2)[:, 0]
        return -1, int(np.argmin(np.abs(bp_x - step.vertex[0])))
    return -1, -1


def fortune_state(step, points: np.ndarray) -> Text:
    """The panel's text for a Fortune step."""
    text = Text(no_wrap=True, overflow="ellipsis")
    text.append("Next events", style="bold")
    events = next_events(step, points)
    if not events:
        text.append("\n  none: the sweep is done", style="dim")
    for kind, x, y in events:
        text.append(f"\n  {kind:<7}", style="bold" if kind == "circle" else "")
        text.append(_xy(x, y))
    beach = [int(s) for s in np.asarray(step.beach)]
    text.append(f"\nBeach line: {_count(len(beach), 'arc')}", style="bold")
    points = np.asarray(points, np.float64).reshape(-1, 2)
    if beach:
        here, gap = current_arc(step)
        centre = max(here, gap, 0)
        lo, hi = max(centre - ARCS_EACH_SIDE, 0), min(centre + ARCS_EACH_SIDE + 1, len(beach))
        if lo > 0:
            text.append(f"\n  … {lo} more to the left", style="dim")
        for i in range(lo, hi):
            x, y = points[beach[i]]
            mark = "▶ " if i == here else "  "
            text.append(f"\n{mark}site {beach[i]:<4}", style="bold" if i == here else "")
            text.append(f" {_xy(x, y)}", style="dim")
            if i == gap:
                text.append(f"\n✕ site {step.site:<4} vanished", style="bold")
        if hi < len(beach):
            text.append(f"\n  … {len(beach) - hi} more to the right", style="dim")
    n_vertices = len(np.asarray(step.vertices).reshape(-1, 2))
    n_finished, n_growing = len(step.finished_edges), len(step.growing_edges)
    text.append("\nSo far", style="bold")
    text.append(f"\n  {n_vertices} vert{'ex' if n_vertices == 1 else 'ices'}")
    text.append(f"\n  {n_finished} edges, {n_growing} growing")
    return text


def incremental_state(step) -> Text:
    """The panel's text for an insertion step."""
    text = Text(no_wrap=True, overflow="ellipsis")
    if step.site < 0:
        text.append("Before the first insertion", style="bold")
        text.append(f"\n  {step.n_steps} sites to insert")
        return text
    text.append(f"Site {step.site} inserted", style="bold")
    text.append(f"\n  {step.index} of {step.n_steps}")
    _walk_lines(text, step)
    text.append("\nCavity", style="bold")
    n_conflict = len(step.conflict)
    text.append(f"\n  {_count(n_conflict, 'triangle')} in conflict")
    text.append(f"\n  {len(step.new_triangles)} new triangles")
    losers = [int(s) for s in np.asarray(step.stolen_from)]
    text.append(f"\nCells that lost area: {len(losers)}", style="bold")
    if losers:
        shown = " ".join(str(s) for s in losers[:LOSERS_LISTED])
        more = f" +{len(losers) - LOSERS_LISTED}" if len(losers) > LOSERS_LISTED else ""
        text.append(f"\n  {shown}{more}")
    d = step.diagram
    text.append("\nSo far", style="bold")
    text.append(f"\n  {_count(len(step.inserted), 'site')}")
    text.append(f"\n  {d.n_vertices} vertices")
    return text


def _triangle(tri) -> str:
    return " ".join("∞" if v < 0 else str(int(v)) for v in tri)


def _walk_lines(text: Text, step) -> None:
    """The location walk: how many triangles it visited, the first few and the one it ended in."""
    walk = np.asarray(step.walk, np.int64).reshape(-1, 3)
    if not len(walk):
        text.append("\nLocation: the first triangle", style="bold")
        return
    text.append(f"\nLocation walk: {_count(len(walk), 'triangle')}", style="bold")
    shown = list(range(min(len(walk), WALK_LISTED)))
    if len(walk) > WALK_LISTED:
        shown[-1] = len(walk) - 1
    for n, i in enumerate(shown):
        if n and i != shown[n - 1] + 1:
            text.append(f"\n  … {i - shown[n - 1] - 1} more", style="dim")
        last = i == len(walk) - 1
        text.append(f"\n{'▶ ' if last else '  '}{_triangle(walk[i])}", style="bold" if last else "")
    if (walk[-1] < 0).any():
        text.append("\n  beyond the hull: outside", style="dim")
    else:
        text.append("\n  holds the site", style="dim")
