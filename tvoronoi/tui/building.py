"""Building whole diagrams for the UI: now for small point sets, in a worker thread for large ones."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from textual import work
from textual.message import Message
from textual.worker import get_current_worker

import tvoronoi
from tvoronoi.diagram import Diagram
from tvoronoi.errors import TvoronoiError
from tvoronoi.readers.pointset import PointSet
from tvoronoi.tui.raster import Scene

# Work on this many sites or more runs in a worker thread; the status line and the panel's
# progress bar say so, and the canvas keeps the focus (and the last diagram) meanwhile.
BUILD_THREAD_MIN_SITES = 100_000

Clock = Callable[[], float]


@dataclass(frozen=True)
class Built:
    """A diagram ready to show, with what the status line says about it."""

    points: np.ndarray
    point_set: PointSet | None  # read from a file (its properties go into a save), else None
    diagram: Diagram
    scene: Scene
    engine_ms: float
    source: str


def build(points: np.ndarray, engine: str, source: str, clock: Clock, point_set: PointSet | None = None,
          bbox=None) -> Built:
    """Build the diagram of some points and prepare it for drawing (any thread)."""
    start = clock()
    diagram = tvoronoi.voronoi(points, engine=engine, bbox=bbox)
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


class BuildingMixin:
    """The App's part that builds diagrams and hands them to the canvas.

    Every whole diagram reaches the canvas through ``_request_build`` and
    ``DiagramReady``; point-by-point edits go through the editing part, and
    algorithm steps through the playback part.
    """

    _request = 0
    # what the status line says while a build runs in a worker (None: no build running)
    building: str | None = None

    def _engine(self) -> str:
        from textual.widgets import Select

        return str(self.query_one("#engine", Select).value)

    def _request_build(self, make_points: Callable[[], np.ndarray], *, source: str, size: int | None,
                       fit: bool = True, point_set=None, read: Callable[[], object] | None = None,
                       bbox=None) -> None:
        """Build a diagram now, or in a worker thread when it is large or its size unknown.

        ``make_points`` gives the sites; ``read``, if given, instead gives a
        PointSet whose ``.xy`` are the sites (a file read in the worker).
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
            return build(pts, engine, source, self.clock, point_set=ps, bbox=bbox)

        if size is not None and size < BUILD_THREAD_MIN_SITES:
            try:
                built = job()
            except TvoronoiError as exc:
                self._fail(str(exc))
                return
            self._accept(request, built, fit)
        else:
            what = f"{size:,} sites" if size is not None else source
            self._show_building(f"building {what} with {engine}…")
            self._build_in_thread(request, job, fit)

    def _show_building(self, text: str | None) -> None:
        """Say that a build runs (text) or that none does (None).

        Not the canvas's loading indicator: a widget that is loading cannot
        hold the focus, which would pass to the panel and take the keys.
        """
        from textual.widgets import ProgressBar

        self.building = text
        bar = self.query_one("#progress", ProgressBar)
        if text is not None:
            bar.update(total=None, progress=0)
            bar.display = True
            self._set_status(text)
        elif not self._saving:
            bar.display = False

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
            self._show_building(None)
        self._fail(message.error)
        self._update_status()
        if self.built is None and self.building is None:
            # nothing to keep (a file given at start could not be read): show the panel's points
            self.action_generate()

    def _accept(self, request: int, built: Built, fit: bool) -> None:
        if request != self._request:
            return  # a later request replaced this one
        self._show_building(None)
        self._diagram_replaced()
        self.built = built
        self.canvas.show_scene(built.scene, fit=fit)
        self._update_status()
        self._diagram_shown()

    def _fail(self, error: str) -> None:
        """Tell the user; the last good diagram stays."""
        self.notify(error, title="Not built", severity="error", timeout=8, markup=False)
