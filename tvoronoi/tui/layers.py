"""The layers of a frame: the marks in their order of precedence, the fills, and the cache of drawn layers."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from tvoronoi.tui.colours import MAX_COLOURS
from tvoronoi.tui.viewport import View

if TYPE_CHECKING:
    from tvoronoi.tui.raster import Painter

# The layers, in rising precedence: a character has one foreground colour,
# that of the highest layer with a dot in it. FUTURE (sites not reached yet),
# GROWING, CONFLICT, CIRCLE, BEACH, SWEEP and EVENT belong to algorithm playback,
# CURSOR to editing: the lowest, so that a site or edge under the keyboard cursor
# keeps its colour (the cursor's characters are lit up by their fill instead).
(NO_MARK, CURSOR, FUTURE, DELAUNAY, EDGE, GROWING, WALK, CONFLICT, CIRCLE, BEACH, SWEEP, VERTEX, SITE, EVENT) = range(
    14
)
N_MARKS = 14
# Fills: -1 none, 0 .. N_FILLS - 1 the cell colours, TINTED + c the tinted
# colour c, CONFLICT_FILL the inside of a conflict region, HIGHLIGHTED + c the
# colour c under the keyboard cursor.
N_FILLS = MAX_COLOURS
TINTED = N_FILLS
CONFLICT_FILL = 2 * N_FILLS
HIGHLIGHTED = 2 * N_FILLS + 1
# The layer cache keeps the layers of this many recent frames.
LAYER_FRAMES_KEPT = 4


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
                if (
                    entry[0] is not scene
                    or full[1] != scene.version
                    or full[3:] != (paint.cols, paint.rows, rest)
                    or not isinstance(old, View)
                    or (old.ax, old.ay, old.scale) != (view.ax, view.ay, view.scale)
                ):
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
        packed[max(-dr, 0) : rows - max(dr, 0), max(-dc, 0) : cols - max(dc, 0)] = old_packed[
            max(dr, 0) : rows - max(-dr, 0), max(dc, 0) : cols - max(-dc, 0)
        ]
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
        self._history = [frame for frame in kept + [self._used] if frame][-self.frames :]
        self._used = {}
