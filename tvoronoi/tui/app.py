"""The tvoronoi terminal UI: a diagram canvas, a side panel of controls, a playback timeline and a status line.

The App is put together from parts, each in its own module: building whole
diagrams (``building``), opening and saving (``files``), algorithm playback
(``playback``) and editing through dynamic updates (``editing``).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from rich.text import Text
from textual import on
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.message import Message
from textual.widgets import Button, Footer, Input, Label, ProgressBar, Select, Static
from textual.widgets._select import SelectOverlay

from tvoronoi.api import ENGINES
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import DISTRIBUTIONS, generate
from tvoronoi.tui import editing, playback
from tvoronoi.tui.building import BUILD_THREAD_MIN_SITES, Built, BuildingMixin, Clock
from tvoronoi.tui.canvas import DiagramCanvas
from tvoronoi.tui.commands import app_commands
from tvoronoi.tui.editing import EditingMixin
from tvoronoi.tui.files import FilesMixin
from tvoronoi.tui.inspector import InspectorMixin
from tvoronoi.tui.legend import legend_text
from tvoronoi.tui.playback import PlaybackMixin
from tvoronoi.tui.relaxing import relaxed_live, relaxed_points, relaxed_source
from tvoronoi.tui.screens import HelpScreen, OpenRequest
from tvoronoi.tui.timeline import Timeline

DEFAULT_DISTRIBUTION = "uniform"
DEFAULT_COUNT = 300
DEFAULT_SEED = 0
DEFAULT_PARAMS = {"sigma": "0.15", "clusters": "10", "spread": "0.02"}
# A guard against a typo eating the machine's memory.
GENERATE_MAX_SITES = 5_000_000
# Width below which the side panel starts hidden (`p` shows it).
NARROW_WIDTH = 80

# The parameters of each distribution that the panel offers, as (input id, type).
PARAMETERS = {
    "uniform": (),
    "gaussian": (("sigma", float),),
    "clustered": (("clusters", int), ("spread", float)),
}

class Workspace(Horizontal):
    """The canvas and the side panel, as wide as the terminal: its resizes are the terminal's."""

    class Resized(Message):
        """The terminal changed size (the App itself does not hear of it)."""

    def on_resize(self) -> None:
        self.post_message(self.Resized())


class PanelSelect(Select):
    """A Select that reports every choice made in its list, the one already chosen included
    (``Select.Changed`` comes only for a new value)."""

    class Chosen(Message):
        """The user chose an option in the list."""

        def __init__(self, select: "PanelSelect") -> None:
            super().__init__()
            self.select = select

    @on(SelectOverlay.UpdateSelection)
    def _chosen(self) -> None:
        # Select's own handler (run after this one) sets the value and closes the list
        self.post_message(self.Chosen(self))


class SidePanel(VerticalScroll, can_focus=False):
    """The controls beside the canvas; it scrolls when the terminal is short, but Tab skips it."""


def _tip(widget, text: str):
    widget.tooltip = text
    return widget


class VoronoiApp(BuildingMixin, FilesMixin, PlaybackMixin, EditingMixin, InspectorMixin, App[int]):
    """Explore Voronoi diagrams in the terminal.

    Parameters
    ----------
    points : (n, 2) array, optional
        Sites to show first; by default 300 uniform points (seed 0).
    path : str or os.PathLike, optional
        A point file to open at start instead (read as the Open dialog reads
        it; if it cannot be read, the default points are shown after the error).
    x, y : str, optional
        The x and y columns of that file (default: found from the file).
    engine : str
        The engine selected at start.
    clock : callable
        Time source for the engine timing in the status line (tests pass a
        fixed one so that snapshots do not change).
    """

    CSS_PATH = "app.tcss"
    TITLE = "tvoronoi"

    BINDINGS = [
        Binding("q", "quit", "Quit", show=False),  # in the help: the footer keeps 80 columns for the rest
        Binding("question_mark", "help", "Help", key_display="?"),
        Binding("d", "toggle_delaunay", "Delaunay"),
        Binding("v", "toggle_vertices", "Vertices", show=False),
        Binding("g", "generate", "Generate"),
        Binding("o", "open", "Open", show=False),
        Binding("s", "save", "Save", show=False),
        Binding("e", "export", "Export", show=False),
        Binding("p", "toggle_panel", "Panel", show=False),
        Binding("r", "relax", "Relax", show=False),
        Binding("escape", "focus_canvas", "Back to the diagram", show=False),
        *playback.BINDINGS,
        # the footer names L outside playback only: there the playback keys need the room
        Binding("L", "toggle_legend", "Legend"),
        Binding("L", "toggle_legend('playback')", "Legend", show=False),
        *editing.BINDINGS,
    ]

    def __init__(self, points=None, *, path=None, x: str | None = None, y: str | None = None,
                 engine: str = "incremental", clock: Clock = time.perf_counter) -> None:
        super().__init__()
        self.initial_points = None if points is None else np.asarray(points, np.float64)
        self.initial_file = None if path is None else OpenRequest(Path(path), x, y)
        self.initial_engine = engine if engine in ENGINES else ENGINES[0]
        self.clock = clock
        self.built: Built | None = None
        self._panel_wanted: bool | None = None  # None: decided by the width
        self._narrow: bool | None = None  # whether the panel was last laid out for a narrow terminal
        self._status_text = ""  # the left part of the status line
        self._view_text = ""  # its right part: where the view is
        self.legend_shown = False
        self._legend_seen: tuple | None = None

    # -- layout --------------------------------------------------------------

    def compose(self) -> ComposeResult:
        with Workspace(id="main"):
            yield DiagramCanvas(id="canvas")
            with SidePanel(id="panel"):
                with Vertical(id="points-section"):
                    yield Label("Points", classes="heading")
                    with Horizontal(classes="row"):
                        yield Label("shape")
                        yield _tip(
                            PanelSelect(
                                [(name, name) for name in DISTRIBUTIONS],
                                value=DEFAULT_DISTRIBUTION, allow_blank=False, compact=True, id="distribution",
                            ),
                            "How the points are spread: uniform in the unit square, one gaussian blob, "
                            "or gaussian clusters",
                        )
                    with Horizontal(classes="row"):
                        yield Label("count")
                        yield _tip(
                            Input(str(DEFAULT_COUNT), type="integer", compact=True, id="count"),
                            f"Number of points (0 to {GENERATE_MAX_SITES:,}); {BUILD_THREAD_MIN_SITES:,} or more build "
                            "in the background. Enter generates.",
                        )
                    with Horizontal(classes="row"):
                        yield Label("seed")
                        yield _tip(
                            Input(str(DEFAULT_SEED), type="integer", compact=True, id="seed"),
                            "Seed of the random generator: the same seed gives the same points",
                        )
                    with Horizontal(classes="row param gaussian"):
                        yield Label("sigma")
                        yield _tip(
                            Input(DEFAULT_PARAMS["sigma"], type="number", compact=True, id="sigma"),
                            "Standard deviation of the gaussian blob (> 0)",
                        )
                    with Horizontal(classes="row param clustered"):
                        yield Label("clusters")
                        yield _tip(
                            Input(DEFAULT_PARAMS["clusters"], type="integer", compact=True, id="clusters"),
                            "Number of cluster centres (>= 1)",
                        )
                    with Horizontal(classes="row param clustered"):
                        yield Label("spread")
                        yield _tip(
                            Input(DEFAULT_PARAMS["spread"], type="number", compact=True, id="spread"),
                            "Standard deviation of each cluster (> 0)",
                        )
                    yield _tip(
                        Button("Generate", variant="primary", compact=True, id="generate"),
                        "Make new points with these settings and build their diagram (g)",
                    )
                yield Label("Diagram", classes="heading")
                with Horizontal(classes="row"):
                    yield Label("engine")
                    yield _tip(
                        PanelSelect(
                            [(name, name) for name in ENGINES],
                            value=self.initial_engine, allow_blank=False, compact=True, id="engine",
                        ),
                        "The algorithm that builds the diagram: randomized incremental "
                        "(Delaunay, then its dual) or Fortune's sweepline",
                    )
                yield _tip(
                    Button("Playback", compact=True, id="playback"),
                    "Watch the engine build this diagram step by step (t)",
                )
                yield ProgressBar(id="progress", show_eta=False)
                yield Label("Engine state", classes="heading playstate")
                yield Static(id="playstate", classes="playstate")
                yield Label("Cell", classes="heading inspector")
                yield Static(id="inspector", classes="inspector")
                yield Label("Legend", classes="heading legend")
                yield Static(id="legend", classes="legend")
        yield Timeline(id="timeline")
        yield Static(id="inspect-line")
        yield _tip(
            Static(id="status"),
            "What is shown; on the right, the world point at the centre of the view and the zoom "
            "against the view that fits the box (0 fits it again)",
        )
        yield Footer(show_command_palette=False)

    def on_mount(self) -> None:
        self._show_parameters(DEFAULT_DISTRIBUTION)
        self.query_one("#progress").display = False
        self.timeline.display = False
        for widget in self.query(".playstate, .legend"):
            widget.display = False
        self.canvas.focus()
        self.watch(self.canvas, "view", self._show_view, init=False)
        if self.initial_points is not None:
            self._request_build(lambda: self.initial_points, source="points given", size=len(self.initial_points))
        elif self.initial_file is not None:
            self._open_path(self.initial_file)
        else:
            self.action_generate()

    def on_workspace_resized(self) -> None:
        self._layout_panel()
        self.inspect()
        self._show_view()

    def _show_view(self) -> None:
        """Say where the view is (its centre and zoom) at the right of the status line."""
        self._view_text = self.canvas.describe_view() if self.built is not None else ""
        self._render_status()

    def on_diagram_canvas_target_changed(self) -> None:
        self.inspect()

    def _layout_panel(self) -> None:
        """Show or hide the side panel: as the user chose with `p`, else by the terminal's width.

        A resize across NARROW_WIDTH decides again by the width (the choice was
        made for the other size).
        """
        narrow = self.size.width < NARROW_WIDTH
        if narrow != self._narrow:
            self._narrow = narrow
            self._panel_wanted = None
        wanted = self._panel_wanted
        if wanted is None:
            wanted = not narrow
        panel = self.query_one("#panel")
        panel.display = wanted
        if not wanted and panel.has_focus_within:
            self.canvas.focus()

    @property
    def canvas(self) -> DiagramCanvas:
        return self.query_one("#canvas", DiagramCanvas)

    # -- the panel -----------------------------------------------------------

    def _show_parameters(self, distribution: str) -> None:
        for row in self.query(".param"):
            row.display = row.has_class(distribution)

    @on(Select.Changed, "#distribution")
    def _distribution_changed(self, event: Select.Changed) -> None:
        self._show_parameters(str(event.value))

    def on_panel_select_chosen(self, message: PanelSelect.Chosen) -> None:
        self.canvas.focus()  # after Select's own focus on itself

    @on(Select.Changed, "#engine")
    def _engine_changed(self, event: Select.Changed) -> None:
        built = self.built
        if built is None or event.value == built.diagram.engine:
            return
        # the same points again (as edited), with the other engine; the view stays
        if self.live is not None:
            self.finish_editing()
            return
        points, point_set = built.points, built.point_set
        self._request_build(lambda: points, source=built.source, size=len(points), fit=False, point_set=point_set)

    def _back_to_canvas(self, control) -> None:
        """A control was used (a choice made, a field submitted): the keys go to the diagram again."""
        if control.has_focus:
            self.canvas.focus()

    @on(Button.Pressed, "#generate")
    def _generate_pressed(self, event: Button.Pressed) -> None:
        if self._generate():
            self._back_to_canvas(event.button)

    @on(Button.Pressed, "#playback")
    def _playback_pressed(self) -> None:
        self.action_toggle_playback()
        self.canvas.focus()

    @on(Input.Submitted)
    def _input_submitted(self, event: Input.Submitted) -> None:
        # a bad value keeps the focus in its field, for the user to fix it
        if event.input.id in ("count", "seed", "sigma", "clusters", "spread") and self._generate():
            self._back_to_canvas(event.input)

    def _read_int(self, input_id: str, name: str, minimum: int) -> int:
        text = self.query_one(f"#{input_id}", Input).value.strip()
        try:
            value = int(text)
        except ValueError:
            raise TvoronoiError(f"{name} must be a whole number, got {text!r}") from None
        if value < minimum:
            raise TvoronoiError(f"{name} must be at least {minimum}, got {value}")
        return value

    def _read_float(self, input_id: str, name: str) -> float:
        text = self.query_one(f"#{input_id}", Input).value.strip()
        try:
            return float(text)
        except ValueError:
            raise TvoronoiError(f"{name} must be a number, got {text!r}") from None

    def _panel_request(self) -> tuple[str, int, int, dict]:
        """The distribution, count, seed and parameters set in the panel."""
        distribution = str(self.query_one("#distribution", Select).value)
        count = self._read_int("count", "count", 0)
        if count > GENERATE_MAX_SITES:
            raise TvoronoiError(
                f"count {count:,} is more than the UI takes ({GENERATE_MAX_SITES:,}); use the batch mode"
            )
        seed = self._read_int("seed", "seed", 0)
        params = {}
        for name, kind in PARAMETERS[distribution]:
            params[name] = self._read_int(name, name, 1) if kind is int else self._read_float(name, name)
        return distribution, count, seed, params

    # -- building ------------------------------------------------------------

    def action_generate(self) -> None:
        """Make points from the panel's settings and build their diagram."""
        self._generate()

    def _generate(self) -> bool:
        """Make points from the panel's settings and build their diagram; False if a setting is bad."""
        try:
            distribution, count, seed, params = self._panel_request()
        except TvoronoiError as exc:
            self._fail(str(exc))
            return False
        shown = ", ".join([f"seed {seed}", *(f"{k} {v:g}" for k, v in params.items())])
        source = f"{distribution} ({shown})"
        self._request_build(lambda: generate(distribution, count, seed=seed, **params), source=source, size=count)
        return True

    # -- status --------------------------------------------------------------

    def _set_status(self, text: str) -> None:
        self._status_text = text
        self._render_status()

    def _render_status(self) -> None:
        """The status line: what is shown on the left, where the view is on the right.

        What is shown comes first: the view's text shrinks to its zoom, then
        goes, when both do not fit. The line has a fixed size: no layout pass
        (it would delay the canvas's frame).
        """
        status = self.query_one("#status", Static)
        left, right = self._status_text, self._view_text
        room = status.content_size.width or max(self.size.width - 2, 0)
        if len(left) + 2 + len(right) > room:
            right = right[right.rindex(" ") + 1:] if right else ""  # the zoom alone
            if len(left) + 2 + len(right) > room:
                right = ""
        line = Text(left, no_wrap=True, overflow="ellipsis")
        if right:
            line.append(" " * (room - len(left) - len(right)))
            line.append(right, style="dim")
        status.update(line, layout=False)

    def _update_status(self) -> None:
        """Say what is shown: in the status line, and the inspected cell (which may have changed)."""
        self.inspect()
        self.update_legend()
        self._show_view()
        if self.building is not None:
            self._set_status(self.building)  # the old diagram's status would hide the running build
            return
        built = self.built
        if built is None:
            self._set_status("no diagram")
            return
        if self.player is not None:
            if self.player.step is not None:
                self._set_status(self.player.step.describe())
            return
        d = built.diagram
        if self.live is not None:
            parts = [
                f"{self.live.n_sites:,} sites",
                d.engine,
                f"{self.n_edits:,} edits, last {self.last_edit_ms:.1f} ms",
                f"{built.source} (edited)",
            ]
        else:
            parts = [
                f"{d.n_sites:,} sites",
                f"{d.n_vertices:,} vertices",
                d.engine,
                f"{built.engine_ms:.0f} ms",
                built.source,
            ]
        if self.canvas.show_delaunay:
            parts.append("Delaunay shown")
        self._set_status(" · ".join(parts))

    # -- actions -------------------------------------------------------------

    def get_system_commands(self, screen):
        """The command palette: Textual's commands, then the app's own (tui/commands.py)."""
        yield from super().get_system_commands(screen)
        yield from app_commands(self)

    def action_next_engine(self) -> None:
        """Switch to the other engine: the same points again, the view kept."""
        select = self.query_one("#engine", Select)
        engines = list(ENGINES)
        select.value = engines[(engines.index(str(select.value)) + 1) % len(engines)]

    def action_relax(self) -> None:
        """One Lloyd step: every site moves to the centroid of its cell, and the diagram is rebuilt."""
        built = self.built
        if built is None:
            return
        if self.player is not None:
            self.notify("relaxing changes the sites: end playback first (t)", title="Not relaxed",
                        severity="warning", timeout=5)
            return
        source = relaxed_source(built.source)
        if self.live is not None:
            # edited sites: their whole diagram is built once to find the centroids
            live = self.live
            points = relaxed_live(live.points(), live.bbox, self._engine())
            bbox = live.bbox
        else:
            points = relaxed_points(built.diagram, built.points)
            bbox = built.diagram.bbox
        self._request_build(lambda: points, source=source, size=len(points), fit=False,
                            point_set=built.point_set, bbox=bbox)

    def action_toggle_delaunay(self) -> None:
        """Show or hide the Delaunay triangulation over the cells."""
        self.canvas.show_delaunay = not self.canvas.show_delaunay
        self._update_status()

    def action_toggle_vertices(self) -> None:
        """Show or hide the Voronoi vertex marks."""
        self.canvas.show_vertices = not self.canvas.show_vertices

    def action_toggle_panel(self) -> None:
        """Show or hide the side panel."""
        panel = self.query_one("#panel")
        self._panel_wanted = not panel.display
        self._layout_panel()
        self.inspect()
        if not panel.display:
            self.canvas.focus()

    def action_toggle_legend(self, during: str = "") -> None:
        """Show or hide the legend of what the canvas draws (in the side panel, shown with it)."""
        self.legend_shown = not self.legend_shown
        panel = self.query_one("#panel")
        if self.legend_shown and not panel.display:
            self._panel_wanted = True
            self._layout_panel()
        self.update_legend()
        if self.legend_shown:
            self.query_one("#legend").scroll_visible(animate=False)

    def check_action(self, action: str, parameters: tuple) -> bool | None:
        if action == "toggle_legend":
            return (self.player is not None) == bool(parameters)
        return super().check_action(action, parameters)

    def update_legend(self) -> None:
        """The legend of what is drawn now: the diagram, or the playback of its engine."""
        mode = "normal" if self.player is None else self.player.engine
        palette = self.canvas.palette()
        seen = (self.legend_shown, mode, palette)
        if seen == self._legend_seen:
            return
        self._legend_seen = seen
        for widget in self.query(".legend"):
            widget.display = self.legend_shown
        if self.legend_shown:
            self.query_one("#legend", Static).update(legend_text(mode, palette))

    def action_focus_canvas(self) -> None:
        self.canvas.focus()

    def _diagram_replaced(self) -> None:
        """A new whole diagram is about to be shown: playback and edits of the old one end."""
        self.stop_playback()
        self.drop_editing()

    def _diagram_shown(self) -> None:
        """A new whole diagram is on screen: make it ready for editing; a file's ambiguous columns
        are asked about."""
        self.prepare_editing()
        self.offer_columns()

    def action_help(self) -> None:
        """List every key."""
        self.push_screen(HelpScreen(self.key_help()))

    def key_help(self) -> list[tuple[str, str]]:
        """(keys, what they do) for every binding of the canvas and the app."""
        rows: list[tuple[str, str]] = []
        seen: dict[str, int] = {}
        for binding in (*DiagramCanvas.BINDINGS, *self.BINDINGS):
            if binding.action in editing.HELP_HIDDEN or binding.action in HELP_HIDDEN:
                continue
            # each key by its own name (the footer shows only the first one's)
            keys = editing.HELP_KEYS.get(binding.action) or " ".join(
                self.get_key_display(b.with_key(b.key)) for b in Binding.make_bindings([binding])
            )
            what = HELP_TEXT.get(binding.action, binding.description)
            if what in seen:  # pan left, pan right, ... share a line
                i = seen[what]
                rows[i] = (f"{rows[i][0]} {keys}", what)
            else:
                seen[what] = len(rows)
                rows.append((keys, what))
        rows.append(("tab", "next control"))
        rows.append(("ctrl+p", "command palette (themes, screenshot, quit)"))
        return rows


# Second bindings of a key, already in the help under the first.
HELP_HIDDEN = {"toggle_legend('playback')"}

# What the help says for an action, where the footer's short label is not enough.
HELP_TEXT = {
    "pan(-1, 0)": "pan (arrows or h j k l)",
    "pan(0, 1)": "pan (arrows or h j k l)",
    "pan(0, -1)": "pan (arrows or h j k l)",
    "pan(1, 0)": "pan (arrows or h j k l)",
    "zoom(1)": "zoom in / out",
    "zoom(-1)": "zoom in / out",
    "fit": "fit the whole box",
    "quit": "quit",
    "help": "this help",
    "toggle_delaunay": "show / hide the Delaunay triangulation",
    "toggle_vertices": "show / hide the Voronoi vertices (marked once zoomed in)",
    "generate": "generate points from the panel's settings",
    "open": "open a point file",
    "save": "save the cells as GeoJSON",
    "export": "export the view as SVG or PNG",
    "toggle_panel": "show / hide the side panel",
    "relax": "relax: one Lloyd step (each site to its cell's centroid)",
    "toggle_legend": "show / hide the legend of the colours and marks (in the panel)",
    "focus_canvas": "leave a text field, back to the diagram",
    **playback.HELP,
    **editing.HELP,
}


def main(path=None) -> int:
    """Run the terminal UI, on the point file ``path`` if given; the exit status of the app."""
    status = VoronoiApp(path=path).run()
    return status if isinstance(status, int) else 0


if __name__ == "__main__":
    # python -m tvoronoi.tui.app [FILE]
    raise SystemExit(main(*sys.argv[1:2]))
