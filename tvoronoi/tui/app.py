"""The tvoronoi terminal UI: a diagram canvas, a side panel of controls and a status line."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
from textual import on, work
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, VerticalScroll
from textual.message import Message
from textual.widgets import Button, Footer, Input, Label, ProgressBar, Select, Static
from textual.worker import get_current_worker

import tvoronoi
from tvoronoi.api import ENGINES
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import DISTRIBUTIONS, generate
from tvoronoi.tui.canvas import DiagramCanvas
from tvoronoi.tui.raster import Scene
from tvoronoi.tui.screens import HelpScreen, PathDialog

DEFAULT_DISTRIBUTION = "uniform"
DEFAULT_COUNT = 300
DEFAULT_SEED = 0
DEFAULT_PARAMS = {"sigma": "0.15", "clusters": "10", "spread": "0.02"}
# Work on this many sites or more runs in a worker thread behind a loading indicator.
THREAD_MIN_SITES = 100_000
# A guard against a typo eating the machine's memory.
MAX_SITES = 5_000_000
DEFAULT_SAVE_NAME = "cells.geojson"
# Width below which the side panel starts hidden (`p` shows it).
NARROW_WIDTH = 80

# The parameters of each distribution that the panel offers, as (input id, type).
PARAMETERS = {
    "uniform": (),
    "gaussian": (("sigma", float),),
    "clustered": (("clusters", int), ("spread", float)),
}

Clock = Callable[[], float]


@dataclass(frozen=True)
class Built:
    """A diagram ready to show, with what the status line says about it."""

    points: np.ndarray
    point_set: object | None  # the PointSet read from a file (its properties go into a save)
    diagram: object
    scene: Scene
    engine_ms: float
    source: str


def build(points: np.ndarray, engine: str, source: str, clock: Clock, point_set=None) -> Built:
    """Build the diagram of some points and prepare it for drawing (any thread)."""
    start = clock()
    diagram = tvoronoi.voronoi(points, engine=engine)
    engine_ms = (clock() - start) * 1000
    scene = Scene.from_diagram(diagram)
    return Built(np.asarray(points), point_set, diagram, scene, engine_ms, source)


class DiagramReady(Message):
    """A diagram was built and can be shown."""

    def __init__(self, request: int, built: Built, fit: bool) -> None:
        super().__init__()
        self.request = request
        self.built = built
        self.fit = fit


class BuildFailed(Message):
    """Points could not be made, read or built into a diagram."""

    def __init__(self, request: int, error: str) -> None:
        super().__init__()
        self.request = request
        self.error = error


class SaveProgress(Message):
    """Part of a save is written."""

    def __init__(self, done: int, total: int) -> None:
        super().__init__()
        self.done = done
        self.total = total


class SaveFinished(Message):
    """A save ended, well (error is None) or not."""

    def __init__(self, path: Path, count: int, error: str | None) -> None:
        super().__init__()
        self.path = path
        self.count = count
        self.error = error


class SidePanel(VerticalScroll, can_focus=False):
    """The controls beside the canvas; it scrolls when the terminal is short, but Tab skips it."""


def _tip(widget, text: str):
    widget.tooltip = text
    return widget


class VoronoiApp(App[int]):
    """Explore Voronoi diagrams in the terminal.

    Parameters
    ----------
    points : (n, 2) array, optional
        Sites to show first; by default 300 uniform points (seed 0).
    engine : str
        The engine selected at start.
    clock : callable
        Time source for the engine timing in the status line (tests pass a
        fixed one so that snapshots do not change).
    """

    CSS_PATH = "app.tcss"
    TITLE = "tvoronoi"

    BINDINGS = [
        Binding("q", "quit", "Quit"),
        Binding("question_mark", "help", "Help", key_display="?"),
        Binding("d", "toggle_delaunay", "Delaunay"),
        Binding("v", "toggle_vertices", "Vertices", show=False),
        Binding("g", "generate", "Generate"),
        Binding("o", "open", "Open"),
        Binding("s", "save", "Save"),
        Binding("p", "toggle_panel", "Panel", show=False),
        Binding("escape", "focus_canvas", "Back to the diagram", show=False),
    ]

    def __init__(self, points=None, *, engine: str = "incremental", clock: Clock = time.perf_counter) -> None:
        super().__init__()
        self.initial_points = None if points is None else np.asarray(points, np.float64)
        self.initial_engine = engine if engine in ENGINES else ENGINES[0]
        self.clock = clock
        self.built: Built | None = None
        self._request = 0
        self._saving = False
        self._panel_wanted: bool | None = None  # None: decided by the width

    # -- layout --------------------------------------------------------------

    def compose(self) -> ComposeResult:
        with Horizontal(id="main"):
            yield DiagramCanvas(id="canvas")
            with SidePanel(id="panel"):
                yield Label("Points", classes="heading")
                with Horizontal(classes="row"):
                    yield Label("shape")
                    yield _tip(
                        Select(
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
                        f"Number of points (0 to {MAX_SITES:,}); {THREAD_MIN_SITES:,} or more build "
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
                        Select(
                            [(name, name) for name in ENGINES],
                            value=self.initial_engine, allow_blank=False, compact=True, id="engine",
                        ),
                        "The algorithm that builds the diagram: randomized incremental "
                        "(Delaunay, then its dual) or Fortune's sweepline",
                    )
                yield ProgressBar(id="progress", show_eta=False)
        yield Static(id="status")
        yield Footer()

    def on_mount(self) -> None:
        self._show_parameters(DEFAULT_DISTRIBUTION)
        self.query_one("#progress").display = False
        self.canvas.focus()
        if self.initial_points is not None:
            self._request_build(lambda: self.initial_points, source="points given", size=len(self.initial_points))
        else:
            self.action_generate()

    def on_resize(self) -> None:
        self._layout_panel()

    def _layout_panel(self) -> None:
        wanted = self._panel_wanted
        if wanted is None:
            wanted = self.size.width >= NARROW_WIDTH
        self.query_one("#panel").display = wanted

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

    @on(Select.Changed, "#engine")
    def _engine_changed(self, event: Select.Changed) -> None:
        built = self.built
        if built is None or event.value == built.diagram.engine:
            return
        # the same points again, with the other engine; the view stays
        points, point_set = built.points, built.point_set
        self._request_build(lambda: points, source=built.source, size=len(points), fit=False, point_set=point_set)

    @on(Button.Pressed, "#generate")
    def _generate_pressed(self) -> None:
        self.action_generate()

    @on(Input.Submitted)
    def _input_submitted(self, event: Input.Submitted) -> None:
        if event.input.id in ("count", "seed", "sigma", "clusters", "spread"):
            self.action_generate()

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
        if count > MAX_SITES:
            raise TvoronoiError(f"count {count:,} is more than the UI takes ({MAX_SITES:,}); use the batch mode")
        seed = self._read_int("seed", "seed", 0)
        params = {}
        for name, kind in PARAMETERS[distribution]:
            params[name] = self._read_int(name, name, 1) if kind is int else self._read_float(name, name)
        return distribution, count, seed, params

    # -- building ------------------------------------------------------------

    def action_generate(self) -> None:
        """Make points from the panel's settings and build their diagram."""
        try:
            distribution, count, seed, params = self._panel_request()
        except TvoronoiError as exc:
            self._fail(str(exc))
            return
        shown = ", ".join([f"seed {seed}", *(f"{k} {v:g}" for k, v in params.items())])
        source = f"{distribution} ({shown})"
        self._request_build(lambda: generate(distribution, count, seed=seed, **params), source=source, size=count)

    def _engine(self) -> str:
        return str(self.query_one("#engine", Select).value)

    def _request_build(self, make_points: Callable[[], np.ndarray], *, source: str, size: int | None,
                       fit: bool = True, point_set=None, read: Callable[[], object] | None = None) -> None:
        """Build a diagram now, or in a worker thread when it is large or its size unknown.

        ``make_points`` gives the sites; ``read``, if given, instead gives a
        PointSet whose ``.xy`` are the sites (a file read in the worker).
        Every diagram reaches the canvas through here and ``DiagramReady``;
        point-by-point edits and algorithm playback are still to come, with
        their own messages.
        """
        self._request += 1
        request = self._request
        engine = self._engine()

        def job() -> Built:
            ps = point_set
            if read is not None:
                ps = read()
                pts = ps.xy
            else:
                pts = make_points()
            return build(pts, engine, source, self.clock, point_set=ps)

        if size is not None and size < THREAD_MIN_SITES:
            try:
                built = job()
            except TvoronoiError as exc:
                self._fail(str(exc))
                return
            self._accept(request, built, fit)
        else:
            what = f"{size:,} sites" if size is not None else source
            self._set_status(f"building {what} with {engine}…")
            self.canvas.loading = True
            self._build_in_thread(request, job, fit)

    @work(thread=True, exclusive=True, group="build", exit_on_error=False)
    def _build_in_thread(self, request: int, job: Callable[[], Built], fit: bool) -> None:
        worker = get_current_worker()
        try:
            built = job()
        except TvoronoiError as exc:
            self.post_message(BuildFailed(request, str(exc)))
            return
        except MemoryError:
            self.post_message(BuildFailed(request, "not enough memory for that many points"))
            return
        if not worker.is_cancelled:
            self.post_message(DiagramReady(request, built, fit))

    def on_diagram_ready(self, message: DiagramReady) -> None:
        self._accept(message.request, message.built, message.fit)

    def on_build_failed(self, message: BuildFailed) -> None:
        if message.request == self._request:
            self.canvas.loading = False
        self._fail(message.error)
        self._update_status()

    def _accept(self, request: int, built: Built, fit: bool) -> None:
        if request != self._request:
            return  # a later request replaced this one
        self.canvas.loading = False
        self.built = built
        self.canvas.show_scene(built.scene, fit=fit)
        self._update_status()

    def _fail(self, error: str) -> None:
        """Tell the user; the last good diagram stays."""
        self.notify(error, title="Not built", severity="error", timeout=8, markup=False)

    # -- status --------------------------------------------------------------

    def _set_status(self, text: str) -> None:
        self.query_one("#status", Static).update(text)

    def _update_status(self) -> None:
        built = self.built
        if built is None:
            self._set_status("no diagram")
            return
        d = built.diagram
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
        if not panel.display:
            self.canvas.focus()

    def action_focus_canvas(self) -> None:
        self.canvas.focus()

    def action_help(self) -> None:
        """List every key."""
        self.push_screen(HelpScreen(self.key_help()))

    def key_help(self) -> list[tuple[str, str]]:
        """(keys, what they do) for every binding of the canvas and the app."""
        rows: list[tuple[str, str]] = []
        seen: dict[str, int] = {}
        for binding in (*DiagramCanvas.BINDINGS, *self.BINDINGS):
            # each key by its own name (the footer shows only the first one's)
            keys = " ".join(
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

    def action_open(self) -> None:
        """Ask for a point file and show its diagram."""
        self.push_screen(
            PathDialog("Open a point file (CSV, text, GeoJSON, .npy)", placeholder="points.csv"),
            self._open_path,
        )

    def _open_path(self, path: Path | None) -> None:
        self.canvas.focus()
        if path is None:
            return
        from tvoronoi.readers import read_points

        self._request_build(
            lambda: None, source=path.name, size=None, read=lambda: read_points(str(path)),
        )

    def action_save(self) -> None:
        """Ask for a path and write the cells there as GeoJSON."""
        if self.built is None:
            self._fail("there is no diagram to save")
            return
        if self._saving:
            self.notify("a save is still running", severity="warning")
            return
        self.push_screen(
            PathDialog("Save the cells as GeoJSON", value=DEFAULT_SAVE_NAME, confirm_overwrite=True),
            self._save_path,
        )

    def _save_path(self, path: Path | None) -> None:
        self.canvas.focus()
        if path is None or self.built is None:
            return
        try:
            from tvoronoi.geojson import write_cells
        except ImportError:
            self.notify("saving GeoJSON is not available in this build", severity="error")
            return
        self._saving = True
        bar = self.query_one("#progress", ProgressBar)
        bar.update(total=None, progress=0)
        bar.display = True
        self._save_in_thread(write_cells, self.built, path)

    @work(thread=True, group="save", exit_on_error=False)
    def _save_in_thread(self, write_cells, built: Built, path: Path) -> None:
        try:
            count = write_cells(
                built.diagram, built.point_set, str(path),
                progress=lambda done, total: self.post_message(SaveProgress(done, total)),
                overwrite=True,  # the dialog asked before replacing a file
            )
        except (TvoronoiError, OSError) as exc:
            self.post_message(SaveFinished(path, 0, str(exc)))
            return
        self.post_message(SaveFinished(path, count, None))

    def on_save_progress(self, message: SaveProgress) -> None:
        self.query_one("#progress", ProgressBar).update(total=max(message.total, 1), progress=message.done)

    def on_save_finished(self, message: SaveFinished) -> None:
        self._saving = False
        self.query_one("#progress").display = False
        if message.error is not None:
            self.notify(message.error, title="Not saved", severity="error", timeout=8, markup=False)
        else:
            self.notify(f"{message.count:,} cells written to {message.path}", title="Saved", markup=False)


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
    "toggle_panel": "show / hide the side panel",
    "focus_canvas": "leave a text field, back to the diagram",
}


def main() -> int:
    """Run the terminal UI; the exit status of the app."""
    status = VoronoiApp().run()
    return status if isinstance(status, int) else 0


if __name__ == "__main__":
    raise SystemExit(main())
