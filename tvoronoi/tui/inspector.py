"""The inspector: what the UI knows of the cell under the keyboard cursor or the mouse pointer.

It names the site (its id, its row in the input and that row's other columns,
such as a city's name), gives its coordinates, the area of its cell clipped
to the box and the number of its neighbours; in the side panel, or in one
line above the status line when the panel is hidden or too short to show it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from rich.text import Text

if TYPE_CHECKING:
    from tvoronoi.diagram import Diagram
    from tvoronoi.readers.pointset import PointSet
    from tvoronoi.tui.building import Built
    from tvoronoi.tui.canvas import DiagramCanvas
    from tvoronoi.tui.live import LiveScene
    from tvoronoi.tui.playback import Player

# At most this many of a site's properties are listed in the panel.
MAX_PROPERTIES = 6
# A property's value is cut to this many characters in the panel (the panel is 30 wide).
PANEL_VALUE_WIDTH = 16
# Below this terminal height the panel cannot show the inspector under its controls:
# the one-line form is shown instead.
PANEL_MIN_HEIGHT = 32


@dataclass(frozen=True)
class CellInfo:
    """One cell as the inspector shows it.

    Attributes
    ----------
    site : int
        The site's id (its row in the input, unless it was added by an edit).
    row : int or None
        The input row of the site; None for a site added by an edit.
    x, y : float
        The site.
    area : float
        Area of the cell clipped to the box.
    n_neighbours : int
        Sites whose cells share an edge with this one.
    properties : dict
        The other columns of the input row (or its GeoJSON properties).
    moved : bool
        The site was moved by an edit (its properties are those of its row).
    """

    site: int
    row: int | None
    x: float
    y: float
    area: float
    n_neighbours: int
    properties: dict = field(default_factory=dict)
    moved: bool = False


def ring_area(ring: np.ndarray) -> float:
    """Area of a simple polygon given as a (k, 2) ring (shoelace formula); 0 for fewer than 3 points.

    >>> ring_area(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]))
    2.0
    """
    if len(ring) < 3:
        return 0.0
    x, y = ring[:, 0], ring[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2)


def row_properties(point_set: PointSet | None, row: int) -> dict[str, Any]:
    """The other columns (or GeoJSON properties) of an input row; empty without a point file."""
    if point_set is None:
        return {}
    if point_set.records is not None:
        return dict(point_set.records[row] or {})
    return {name: values[row] for name, values in point_set.columns.items()}


def diagram_neighbours(diagram: Diagram, i: int) -> np.ndarray:
    """The sites whose cells share an edge with cell i of a whole diagram."""
    cycle = diagram.half_edge_cycle(i)
    if not len(cycle):
        return np.empty(0, np.int64)
    twins = np.asarray(diagram.he_twin)[cycle]
    faces = np.asarray(diagram.he_face)[twins[twins >= 0]]
    return np.unique(faces[(faces >= 0) & (faces != i)])


def cell_info(built: Built, live: LiveScene | None, site: int) -> CellInfo:
    """What the inspector says of site ``site`` of the diagram shown (``live`` if edited)."""
    n_input = len(built.points)
    if live is None:
        diagram = built.diagram
        # a repeated point has no cell of its own: its first copy holds it
        site = int(diagram.site_of[site])
        ring = diagram.cell_polygon(site)
        n_neighbours = len(diagram_neighbours(diagram, site))
        x, y = (float(c) for c in diagram.sites[site])
        moved = False
    else:
        dynamic = live.dynamic.diagram()
        ring = dynamic.cell_polygon(site)
        n_neighbours = len(dynamic.neighbours(site))
        x, y = (float(c) for c in live.sites[site])
        moved = site < n_input and (x, y) != tuple(float(c) for c in built.points[site])
    row = site if site < n_input else None
    properties = {} if row is None else row_properties(built.point_set, row)
    return CellInfo(site, row, x, y, ring_area(ring), n_neighbours, properties, moved)


def _value(value: object) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return "" if value is None else str(value)


def _cut(text: str, width: int) -> str:
    return text if len(text) <= width else text[: width - 1] + "…"


def _row_text(info: CellInfo, source: str) -> str:
    if info.row is None:
        return "added by an edit"
    where = f"row {info.row:,} of {source}"
    return f"{where} (moved)" if info.moved else where


def panel_text(info: CellInfo | None, where: str, source: str) -> Text:
    """The inspector's lines for the side panel; ``where`` says what points at the cell."""
    if info is None:
        return Text("Point at a cell, or show the keyboard cursor (c).", style="dim")
    text = Text()
    text.append(f"site {info.site:,}", style="bold")
    text.append(f"  {where}\n", style="dim")
    text.append(_row_text(info, source) + "\n", style="dim")
    shown = list(info.properties.items())[:MAX_PROPERTIES]
    width = max((len(str(k)) for k, _ in shown), default=0)
    for key, value in shown:
        text.append(f"{str(key):<{width}} ", style="dim")
        text.append(_cut(_value(value), PANEL_VALUE_WIDTH) + "\n")
    if len(info.properties) > MAX_PROPERTIES:
        text.append(f"… {len(info.properties) - MAX_PROPERTIES} more\n", style="dim")
    text.append("x ", style="dim")
    text.append(f"{info.x:.6g}")
    text.append("   y ", style="dim")
    text.append(f"{info.y:.6g}\n")
    text.append("area ", style="dim")
    text.append(f"{info.area:.4g}\n")
    text.append("neighbours ", style="dim")
    text.append(f"{info.n_neighbours}")
    return text


def line_text(info: CellInfo, where: str) -> Text:
    """The inspector in one line, for a terminal without room for it in the panel."""
    text = Text(no_wrap=True, overflow="ellipsis")
    text.append(f"{where}: ", style="dim")
    text.append(f"site {info.site:,}", style="bold")
    label = next((_value(v) for v in info.properties.values() if isinstance(v, str) and v), None)
    if label is not None:
        text.append(f" {label}", style="bold")
    if info.row is None:
        text.append(" (added)", style="dim")
    elif info.moved:
        text.append(" (moved)", style="dim")
    text.append(f" · x {info.x:.6g} y {info.y:.6g} · area {info.area:.4g} · {info.n_neighbours} neighbours")
    return text


class InspectorHost(Protocol):
    """What the inspector uses of the App."""

    @property
    def canvas(self) -> DiagramCanvas: ...
    @property
    def built(self) -> Built | None: ...
    @property
    def live(self) -> LiveScene | None: ...
    @property
    def player(self) -> Player | None: ...
    def inspector_in_panel(self) -> bool: ...
    def show_inspector(self, text: Text, *, shown: bool, in_panel: bool) -> None: ...


class Inspector:
    """Shows the cell under the keyboard cursor, else under the mouse pointer."""

    def __init__(self, host: InspectorHost) -> None:
        self.host = host
        self.inspected: CellInfo | None = None
        self._seen: tuple | None = None

    def inspect(self) -> None:
        """Show the cell under the cursor or pointer now (after a move, an edit, a new diagram)."""
        host = self.host
        canvas, built = host.canvas, host.built
        info, where = None, ""
        point: tuple[float, float] | None
        if host.player is None and built is not None:
            if canvas.cursor is not None:
                point, where = canvas.cursor, "cursor"
            else:
                point, where = canvas.pointer, "pointer"
            site = None if point is None else canvas.cell_at(*point)
            if site is not None:
                info = cell_info(built, host.live, site)
        self.inspected = info
        # playback shows the engine's own state, not cells: no inspector then
        shown = host.player is None
        in_panel = host.inspector_in_panel()
        source = built.source if built is not None else ""
        # the pointer moves a character at a time: most moves stay in the same cell
        seen = (info, where, shown, in_panel, source)
        if seen == self._seen:
            return
        self._seen = seen
        if in_panel:
            text = panel_text(info, where, source)
        elif info is None:
            text = Text("point at a cell or press c to inspect it", style="dim")
        else:
            text = line_text(info, where)
        host.show_inspector(text, shown=shown, in_panel=in_panel)
