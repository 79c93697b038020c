"""The command palette (ctrl+p): the app's own actions, listed beside Textual's."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

from textual.app import SystemCommand

if TYPE_CHECKING:
    from tvoronoi.tui.app import VoronoiApp

# (title, what it does, the action that runs it: "app.<name>" on the App, "canvas.<name>" on the canvas)
COMMANDS = (
    ("Generate", "Make points from the panel's settings and show their diagram (g)", "app.generate"),
    ("Open", "Open a point file: CSV, GeoJSON, .npy, (Geo)Parquet (o)", "app.open"),
    ("Save", "Save the cells as GeoJSON, GeoJSONSeq or GeoParquet (s)", "app.save"),
    ("Export", "Export the view (cells, edges, sites shown) as SVG or PNG (e)", "app.export"),
    ("Playback", "Step through the engine's algorithm, event by event (t)", "app.toggle_playback"),
    ("Engine", "Switch between the incremental algorithm and Fortune's sweep", "app.next_engine"),
    ("Delaunay", "Show or hide the Delaunay triangulation (d)", "app.toggle_delaunay"),
    ("Vertices", "Show or hide the Voronoi vertices (v)", "app.toggle_vertices"),
    ("Fit", "Fit the view to the diagram (0)", "canvas.fit"),
    ("Legend", "Show or hide what each colour and mark means (L)", "app.toggle_legend"),
    ("Follow", "During playback, let the view follow the current event (f)", "app.toggle_follow"),
    ("Relax", "One Lloyd step: every site to the centroid of its cell (r)", "app.relax"),
)


def app_commands(app: VoronoiApp) -> Iterable[SystemCommand]:
    """The palette's entries for what the app can do now (an action it would refuse is left out)."""
    for title, help_text, target in COMMANDS:
        where, action = target.split(".", 1)
        if where == "app":
            parameters: tuple[str, ...] = ("playback",) if action == "toggle_legend" and app.player is not None else ()
            if app.check_action(action, parameters) is False:
                continue
            yield SystemCommand(title, help_text, _runner(app, action, parameters))
        else:
            yield SystemCommand(title, help_text, getattr(app.canvas, f"action_{action}"))


def _runner(app: VoronoiApp, action: str, parameters: tuple[str, ...]) -> Callable[[], object]:
    method = getattr(app, f"action_{action}")
    return lambda: method(*parameters)
