"""The tvoronoi terminal UI: a diagram canvas, a side panel of controls, a playback timeline and a status line.

The App composes the widgets and holds its controllers, plain objects each in
its own module: building whole diagrams (``building``), opening, saving and
exporting (``files``), algorithm playback (``playback``), editing through
dynamic updates (``editing``) and the cell inspector (``inspector``). Each
controller keeps its own state and reaches the App only through the small
Protocol its module declares (``BuildingHost``, ``PlaybackHost``...); the App's
actions, message handlers and ``check_action`` hand over to them by name.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np
from rich.text import Text
from textual import on
from textual.app import App, ComposeResult, ScreenStackError, SystemCommand
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.message import Message
from textual.screen import Screen
from textual.widget import Widget
from textual.widgets import Button, Footer, Input, Label, ProgressBar, Select, Static
from textual.widgets._select import SelectOverlay

from tvoronoi.api import ENGINES
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import DISTRIBUTIONS, generate
from tvoronoi.readers.pointset import PointSet
from tvoronoi.tui import editing, playback, terminal
from tvoronoi.tui.building import BUILD_THREAD_MIN_SITES, Box, BuildFailed, Building, Built, Clock, DiagramReady
from tvoronoi.tui.canvas import DiagramCanvas
from tvoronoi.tui.commands import app_commands
from tvoronoi.tui.editing import Editing, EditorReady
from tvoronoi.tui.files import Files, SaveFinished, SaveProgress
from tvoronoi.tui.inspector import PANEL_MIN_HEIGHT, Inspector
from tvoronoi.tui.legend import legend_text
from tvoronoi.tui.live import LiveScene
from tvoronoi.tui.playback import Playback, Player, StepReady
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

        def __init__(self, select: PanelSelect) -> None:
            super().__init__()
            self.select = select

    @on(SelectOverlay.UpdateSelection)
    def _chosen(self) -> None:
        # Select's own handler (run after this one) sets the value and closes the list
        self.post_message(self.Chosen(self))


class SidePanel(VerticalScroll, can_focus=False):
    """The controls beside the canvas; it scrolls when the terminal is short, but Tab skips it."""


def _tip(widget: Widget, text: str) -> Widget:
    widget.tooltip = text
    return widget


class VoronoiApp(App[int]):
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

    def __init__(
        self,
        points: Any = None,
        *,
        path: str | Path | None = None,
        x: str | None = None,
        y: str | None = None,
        engine: str = "incremental",
        clock: Clock = time.perf_counter,
    ) -> None:
        super().__init__()
        self.initial_points = None if points is None else np.asarray(points, np.float64)
        self.initial_file = None if path is None else OpenRequest(Path(path), x, y)
        self.initial_engine = engine if engine in ENGINES else ENGINES[0]
        self.clock = clock
        # the controllers: each keeps its own state and uses the App through its module's Protocol
        self.building = Building(self)
        self.files = Files(self)
        self.playback = Playback(self)
        self.editing = Editing(self)
        self.inspector = Inspector(self)
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
                                value=DEFAULT_DISTRIBUTION,
                                allow_blank=False,
                                compact=True,
                                id="distribution",
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
                            value=self.initial_engine,
                            allow_blank=False,
                            compact=True,
                            id="engine",
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
        terminal.watch(self)  # exit when the terminal hangs up (a closed SSH session)
        self._show_parameters(DEFAULT_DISTRIBUTION)
        self.query_one("#progress").display = False
        self.timeline.display = False
        for widget in self.query(".playstate, .legend"):
            widget.display = False
        self.canvas.focus()
        self.watch(self.canvas, "view", self._show_view, init=False)
        if self.initial_points is not None:
            points = self.initial_points
            self.request_build(lambda: points, source="points given", size=len(points))
        elif self.initial_file is not None:
            self.files.open(self.initial_file)
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

    # -- what the controllers share: the diagram shown and the widgets ---------

    @property
    def canvas(self) -> DiagramCanvas:
        return self.query_one("#canvas", DiagramCanvas)

    @property
    def timeline(self) -> Timeline:
        return self.query_one("#timeline", Timeline)

    @property
    def built(self) -> Built | None:
        """The whole diagram shown (or last shown, under playback or edits); kept by building."""
        return self.building.built

    @property
    def live(self) -> LiveScene | None:
        """The diagram as edited, once an edit was made; kept by editing."""
        return self.editing.live

    @property
    def player(self) -> Player | None:
        """The playback session, while one runs; kept by playback."""
        return self.playback.player

    def selected_engine(self) -> str:
        """The engine chosen in the panel."""
        return str(self.query_one("#engine", Select).value)

    def request_build(
        self,
        make_points: Callable[[], Any],
        *,
        source: str,
        size: int | None,
        fit: bool = True,
        point_set: PointSet | None = None,
        read: Callable[[], PointSet] | None = None,
        bbox: Box | None = None,
    ) -> None:
        """Build a whole diagram and show it (see ``Building.request``)."""
        self.building.request(make_points, source=source, size=size, fit=fit, point_set=point_set, read=read, bbox=bbox)

    def fail(self, error: str) -> None:
        """Tell the user that nothing was built; the last good diagram stays."""
        self.building.fail(error)

    def finish_editing(self) -> None:
        """Build the edited sites into a whole diagram again."""
        self.editing.finish()

    def show_progress(self, done: int = 0, total: int | None = None) -> None:
        """Show the panel's progress bar (total None: no known end)."""
        bar = self.query_one("#progress", ProgressBar)
        bar.update(total=total, progress=done)
        bar.display = True

    def progress_done(self) -> None:
        """A build or a save ended: the bar goes, unless the other still runs."""
        if self.building.running is None and not self.files.saving:
            self.query_one("#progress").display = False

    def diagram_replaced(self) -> None:
        """A new whole diagram is about to be shown: playback and edits of the old one end."""
        self.playback.stop()
        self.editing.drop()

    def diagram_shown(self) -> None:
        """A new whole diagram is on screen: make it ready for editing; a file's ambiguous columns
        are asked about."""
        self.editing.prepare()
        self.files.offer_columns()

    def playback_started(self) -> None:
        """Playback began: the panel shows the engine's state, the keys are playback's."""
        self.refresh_bindings()
        self.inspect()  # hidden during playback
        self._show_engine_state(True)
        self.update_legend()

    def playback_ended(self) -> None:
        """Playback ended: the panel's controls and the diagram's status come back."""
        self._show_engine_state(False)
        self.refresh_bindings()
        self.update_status()

    def _show_engine_state(self, shown: bool) -> None:
        """During playback the panel shows the engine's state where the point controls were
        (new points wait until playback ends)."""
        self.query_one("#points-section").display = not shown
        for widget in self.query(".playstate"):
            widget.display = shown

    def set_engine_state(self, text: Text) -> None:
        self.query_one("#playstate", Static).update(text)

    def timeline_on_screen(self) -> bool:
        """The timeline is on the screen shown (no dialog over it, the app not closing)."""
        try:
            screen = self.screen
        except ScreenStackError:  # before the first screen, or after the last (a timer's tick while closing)
            return False
        return bool(screen.query("#timeline"))

    def inspect(self) -> None:
        """Show the cell under the cursor or pointer now."""
        self.inspector.inspect()

    def inspector_in_panel(self) -> bool:
        """Whether the side panel is shown and tall enough to hold the inspector."""
        return bool(self.query_one("#panel").display) and self.size.height >= PANEL_MIN_HEIGHT

    def show_inspector(self, text: Text, *, shown: bool, in_panel: bool) -> None:
        """The inspector's text, in the panel or in the line above the status line."""
        for widget in self.query(".inspector"):
            widget.display = shown and in_panel
        line = self.query_one("#inspect-line", Static)
        line.display = shown and not in_panel
        if in_panel:
            self.query_one("#inspector", Static).update(text)
        else:
            line.update(text, layout=False)

    # -- messages, handed to their controllers -----------------------------------

    def on_diagram_ready(self, message: DiagramReady) -> None:
        self.building.ready(message)

    def on_build_failed(self, message: BuildFailed) -> None:
        self.building.failed(message)

    def on_save_progress(self, message: SaveProgress) -> None:
        self.files.save_progress(message)

    def on_save_finished(self, message: SaveFinished) -> None:
        self.files.save_finished(message)

    def on_step_ready(self, message: StepReady) -> None:
        self.playback.step_ready(message)

    def on_timeline_scrubbed(self, message: Timeline.Scrubbed) -> None:
        self.playback.scrubbed(message.step)

    def on_diagram_canvas_view_changed(self) -> None:
        self.playback.view_changed()

    def on_editor_ready(self, message: EditorReady) -> None:
        self.editing.editor_ready(message)

    def on_diagram_canvas_clicked(self, message: DiagramCanvas.Clicked) -> None:
        self.editing.add_site_at(message.x, message.y)

    def on_diagram_canvas_site_dragged(self, message: DiagramCanvas.SiteDragged) -> None:
        self.editing.dragged(message)

    def on_diagram_canvas_target_changed(self) -> None:
        self.inspect()

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
            self.editing.finish()
            return
        points, point_set = built.points, built.point_set
        self.request_build(lambda: points, source=built.source, size=len(points), fit=False, point_set=point_set)

    def _back_to_canvas(self, control: Widget) -> None:
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

    def _panel_request(self) -> tuple[str, int, int, dict[str, float]]:
        """The distribution, count, seed and parameters set in the panel."""
        distribution = str(self.query_one("#distribution", Select).value)
        count = self._read_int("count", "count", 0)
        if count > GENERATE_MAX_SITES:
            raise TvoronoiError(
                f"count {count:,} is more than the UI takes ({GENERATE_MAX_SITES:,}); use the batch mode"
            )
        seed = self._read_int("seed", "seed", 0)
        params: dict[str, float] = {}
        for name, kind in PARAMETERS[distribution]:
            params[name] = self._read_int(name, name, 1) if kind is int else self._read_float(name, name)
        return distribution, count, seed, params

    def _generate(self) -> bool:
        """Make points from the panel's settings and build their diagram; False if a setting is bad."""
        try:
            distribution, count, seed, params = self._panel_request()
        except TvoronoiError as exc:
            self.fail(str(exc))
            return False
        shown = ", ".join([f"seed {seed}", *(f"{k} {v:g}" for k, v in params.items())])
        source = f"{distribution} ({shown})"
        self.request_build(lambda: generate(distribution, count, seed=seed, **params), source=source, size=count)
        return True

    # -- status --------------------------------------------------------------

    def set_status(self, text: str) -> None:
        """Say what is shown, at the left of the status line."""
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
            right = right[right.rindex(" ") + 1 :] if right else ""  # the zoom alone
            if len(left) + 2 + len(right) > room:
                right = ""
        line = Text(left, no_wrap=True, overflow="ellipsis")
        if right:
            line.append(" " * (room - len(left) - len(right)))
            line.append(right, style="dim")
        status.update(line, layout=False)

    def update_status(self) -> None:
        """Say what is shown: in the status line, and the inspected cell (which may have changed)."""
        self.inspect()
        self.update_legend()
        self._show_view()
        if self.building.running is not None:
            self.set_status(self.building.running)  # the old diagram's status would hide the running build
            return
        built = self.built
        if built is None:
            self.set_status("no diagram")
            return
        player = self.player
        if player is not None:
            if player.step is not None:
                self.set_status(player.step.describe())
            return
        d = built.diagram
        live = self.live
        if live is not None:
            edits = self.editing
            parts = [
                f"{live.n_sites:,} sites",
                d.engine,
                f"{edits.n_edits:,} edits, last {edits.last_edit_ms:.1f} ms",
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
        self.set_status(" · ".join(parts))

    # -- actions -------------------------------------------------------------

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        """Whether a key's action runs now: the legend's two bindings by playback, then what playback
        and editing allow; every other action always."""
        if action == "toggle_legend":
            return (self.player is not None) == bool(parameters)
        for controller in (self.playback, self.editing):
            allowed = controller.allows(action)
            if allowed is not None:
                return allowed
        return True

    def get_system_commands(self, screen: Screen[Any]) -> Iterable[SystemCommand]:
        """The command palette: Textual's commands, then the app's own (tui/commands.py)."""
        yield from super().get_system_commands(screen)
        yield from app_commands(self)

    def action_generate(self) -> None:
        """Make points from the panel's settings and build their diagram."""
        self._generate()

    def action_open(self) -> None:
        """Ask for a point file and show its diagram."""
        self.files.ask_open()

    def action_save(self) -> None:
        """Ask for a path and write the cells there as GeoJSON."""
        self.files.ask_save()

    def action_export(self) -> None:
        """Ask for a path and write the view there: .svg (vector) or .png."""
        self.files.ask_export()

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
            self.notify(
                "relaxing changes the sites: end playback first (t)", title="Not relaxed", severity="warning", timeout=5
            )
            return
        source = relaxed_source(built.source)
        live = self.live
        if live is not None:
            # edited sites: their whole diagram is built once to find the centroids
            points = relaxed_live(live.points(), live.bbox, self.selected_engine())
            bbox = live.bbox
        else:
            points = relaxed_points(built.diagram, built.points)
            bbox = built.diagram.bbox
        self.request_build(
            lambda: points, source=source, size=len(points), fit=False, point_set=built.point_set, bbox=bbox
        )

    def action_toggle_delaunay(self) -> None:
        """Show or hide the Delaunay triangulation over the cells."""
        self.canvas.show_delaunay = not self.canvas.show_delaunay
        self.update_status()

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

    def action_help(self) -> None:
        """List every key."""
        self.push_screen(HelpScreen(self.key_help()))

    # playback (tui/playback.py)

    def action_toggle_playback(self) -> None:
        """Start playing the selected engine's steps, or stop and show the diagram again."""
        self.playback.toggle()

    def action_play_pause(self) -> None:
        self.playback.play_pause()

    def action_step(self, delta: int) -> None:
        self.playback.step(delta)

    def action_step_to(self, where: str) -> None:
        self.playback.step_to(where)

    def action_jump(self, direction: int) -> None:
        self.playback.jump(direction)

    def action_speed(self, direction: int) -> None:
        self.playback.change_speed(direction)

    def action_toggle_follow(self) -> None:
        self.playback.toggle_follow()

    # editing (tui/editing.py)

    def action_toggle_cursor(self) -> None:
        self.editing.toggle_cursor()

    def action_cursor(self, dx: int, dy: int) -> None:
        self.editing.move_cursor(dx, dy)

    def action_add_site(self) -> None:
        self.editing.add_site()

    def action_remove_site(self) -> None:
        self.editing.remove_site()

    def action_move_site(self) -> None:
        self.editing.pick_up()

    def action_nudge(self, dx: int, dy: int) -> None:
        self.editing.nudge(dx, dy)

    def action_drop_site(self) -> None:
        self.editing.drop_site()

    def action_cancel_move(self) -> None:
        self.editing.cancel_move()

    def key_help(self) -> list[tuple[str, str]]:
        """(keys, what they do) for every binding of the canvas and the app."""
        rows: list[tuple[str, str]] = []
        seen: dict[str, int] = {}
        for binding in (*DiagramCanvas.BINDINGS, *self.BINDINGS):
            if not isinstance(binding, Binding):
                continue
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
