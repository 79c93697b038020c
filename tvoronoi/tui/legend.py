"""The legend: a swatch and a few words for every colour and mark the canvas draws, in the normal
view and in the playback of each engine."""

from __future__ import annotations

from rich.style import Style
from rich.text import Text

from tvoronoi.tui.colours import Palette

# What the view draws, as (swatch kind, palette colour name, words). Swatch kinds: "line", "dash",
# "dot", "ring", "fill" (a colour name among the palette's backgrounds: "fill", "tint", "conflict_fill").
NORMAL = (
    ("fill", "fill", "cells"),
    ("line", "edge", "Voronoi edges, the box"),
    ("dot", "site", "sites"),
    ("dot", "vertex", "vertices (zoomed in)"),
    ("line", "delaunay", "Delaunay edges (d)"),
    ("dot", "cursor", "keyboard cursor (c)"),
)
FORTUNE = (
    ("line", "sweep", "sweep line"),
    ("line", "beach", "beach line (its arcs)"),
    ("ring", "circle", "circle events to come"),
    ("dash", "growing", "growing edges"),
    ("line", "edge", "finished edges"),
    ("fill", "fill", "finished cells"),
    ("dot", "site", "sites swept"),
    ("dot", "future", "sites to come"),
    ("dot", "event", "this event (site, vertex)"),
)
INCREMENTAL = (
    ("dot", "event", "the new site"),
    ("line", "walk", "location walk"),
    ("line", "conflict", "conflict triangles"),
    ("fill", "conflict_fill", "the cavity"),
    ("dash", "growing", "new Delaunay edges"),
    ("fill", "tint", "cells that lost area"),
    ("fill", "fill", "cells so far"),
    ("line", "edge", "Voronoi edges"),
    ("dot", "site", "sites inserted"),
    ("dot", "future", "sites to come"),
)
ENTRIES = {"normal": NORMAL, "fortune": FORTUNE, "incremental": INCREMENTAL}
TITLES = {"normal": "the diagram", "fortune": "Fortune's sweep", "incremental": "incremental insertion"}

SWATCH = {"line": "━━", "dash": "╍╍", "dot": " ● ", "ring": " ◯ ", "fill": "  "}


def _swatch(kind: str, colour: str, palette: Palette) -> tuple[str, Style]:
    if kind == "fill":
        if not palette.filled and colour != "conflict_fill":
            return " ░░", Style(dim=True)
        bg = {"fill": palette.fills[0], "tint": palette.tints[0]}.get(colour) or getattr(palette, colour)
        return " " + SWATCH[kind], Style(bgcolor=bg)
    text = SWATCH[kind] if kind in ("dot", "ring") else " " + SWATCH[kind]
    return text, Style(color=getattr(palette, colour), bold=True)


def legend_text(mode: str, palette: Palette) -> Text:
    """The legend of ``mode`` ("normal", "fortune" or "incremental") in the palette's colours."""
    text = Text(no_wrap=True, overflow="ellipsis")
    text.append(TITLES[mode], style="italic")
    for kind, colour, words in ENTRIES[mode]:
        swatch, style = _swatch(kind, colour, palette)
        text.append("\n")
        text.append(f"{swatch:<3}", style=style)
        text.append(f" {words}")
    return text
