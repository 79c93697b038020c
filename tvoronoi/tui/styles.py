"""A frame as styled text: rich segments, one per run of characters of one style."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from rich.segment import Segment
from rich.style import Style

from tvoronoi.tui.colours import Palette
from tvoronoi.tui.dots import braille_text
from tvoronoi.tui.layers import (
    BEACH,
    CIRCLE,
    CONFLICT,
    CURSOR,
    DELAUNAY,
    EDGE,
    EVENT,
    FUTURE,
    GROWING,
    N_MARKS,
    NO_MARK,
    SITE,
    SWEEP,
    VERTEX,
    WALK,
)
from tvoronoi.tui.raster import Frame


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
        make(Segment, (text[s:e], style, None)) for s, e, style in zip(starts.tolist(), ends.tolist(), run_styles)
    ]
    per_row = np.bincount(starts // cols, minlength=rows).tolist()
    lines, at = [], 0
    for count in per_row:
        lines.append(segments[at : at + count])
        at += count
    return lines
