"""Building whole diagrams for the UI: now for small point sets, in a worker thread for large ones."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np
from textual.message import Message
from textual.worker import get_current_worker

import tvoronoi
from tvoronoi.diagram import Diagram
from tvoronoi.errors import TvoronoiError
from tvoronoi.readers.pointset import PointSet
from tvoronoi.tui.host import Host
from tvoronoi.tui.raster import Scene

# Work on this many sites or more runs in a worker thread; the status line and the panel's
# progress bar say so, and the canvas keeps the focus (and the last diagram) meanwhile.
BUILD_THREAD_MIN_SITES = 100_000

Clock = Callable[[], float]
# a box (xmin, ymin, xmax, ymax), as the API takes it
Box = tuple[float, ...]


@dataclass(frozen=True)
class Built:
    """A diagram ready to show, with what the status line says about it."""

    points: np.ndarray
    point_set: PointSet | None  # read from a file (its properties go into a save), else None
    diagram: Diagram
    scene: Scene
    engine_ms: float
    source: str


def build(
    points: np.ndarray,
    engine: str,
    source: str,
    clock: Clock,
    point_set: PointSet | None = None,
    bbox: Box | None = None,
) -> Built:
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


class BuildingHost(Host, Protocol):
    """What building uses of the App."""

    clock: Clock

    def selected_engine(self) -> str: ...
    def set_status(self, text: str) -> None: ...
    def update_status(self) -> None: ...
    def show_progress(self, done: int = 0, total: int | None = None) -> None: ...
    def progress_done(self) -> None: ...
    def diagram_replaced(self) -> None: ...
    def diagram_shown(self) -> None: ...
    def action_generate(self) -> None: ...


class Building:
    """Builds diagrams and hands them to the canvas; holds the diagram shown.

    Every whole diagram reaches the canvas through ``request`` and
    ``DiagramReady``; point-by-point edits go through the editing controller,
    and algorithm steps through the playback controller.
    """

    def __init__(self, host: BuildingHost) -> None:
        self.host = host
        self.built: Built | None = None
        # what the status line says while a build runs in a worker (None: no build running)
        self.running: str | None = None
        self._request = 0

    def request(
        self,
        make_points: Callable[[], np.ndarray],
        *,
        source: str,
        size: int | None,
        fit: bool = True,
        point_set: PointSet | None = None,
        read: Callable[[], PointSet] | None = None,
        bbox: Box | None = None,
    ) -> None:
        """Build a diagram now, or in a worker thread when it is large or its size unknown.

        ``make_points`` gives the sites; ``read``, if given, instead gives a
        PointSet whose ``.xy`` are the sites (a file read in the worker).
        """
        self._request += 1
        request = self._request
        engine = self.host.selected_engine()
        clock = self.host.clock

        def job() -> Built:
            ps = point_set
            if read is not None:
                ps = read()
                pts = ps.xy
            else:
                pts = make_points()
            return build(pts, engine, source, clock, point_set=ps, bbox=bbox)

        if size is not None and size < BUILD_THREAD_MIN_SITES:
            try:
                built = job()
            except TvoronoiError as exc:
                self.fail(str(exc))
                return
            self._accept(request, built, fit)
        else:
            what = f"{size:,} sites" if size is not None else source
            self._show_running(f"building {what} with {engine}…")
            self.host.run_worker(
                lambda: self._build_in_thread(request, job, fit),
                thread=True,
                exclusive=True,
                group="build",
                exit_on_error=False,
            )

    def _show_running(self, text: str | None) -> None:
        """Say that a build runs (text) or that none does (None).

        Not the canvas's loading indicator: a widget that is loading cannot
        hold the focus, which would pass to the panel and take the keys.
        """
        self.running = text
        if text is not None:
            self.host.show_progress()
            self.host.set_status(text)
        else:
            self.host.progress_done()

    def _build_in_thread(self, request: int, job: Callable[[], Built], fit: bool) -> None:
        worker = get_current_worker()
        try:
            built = job()
        except TvoronoiError as exc:
            self.host.post_message(BuildFailed(request, str(exc)))
            return
        except MemoryError:
            self.host.post_message(BuildFailed(request, "not enough memory for that many points"))
            return
        if not worker.is_cancelled:
            self.host.post_message(DiagramReady(request, built, fit))

    def ready(self, message: DiagramReady) -> None:
        """A worker built a diagram: show it, unless a later request replaced it."""
        self._accept(message.request, message.built, message.fit)

    def failed(self, message: BuildFailed) -> None:
        """A worker could not build: say why; the last good diagram stays."""
        if message.request == self._request:
            self._show_running(None)
        self.fail(message.error)
        self.host.update_status()
        if self.built is None and self.running is None:
            # nothing to keep (a file given at start could not be read): show the panel's points
            self.host.action_generate()

    def _accept(self, request: int, built: Built, fit: bool) -> None:
        if request != self._request:
            return  # a later request replaced this one
        self._show_running(None)
        self.host.diagram_replaced()
        self.built = built
        self.host.canvas.show_scene(built.scene, fit=fit)
        self.host.update_status()
        self.host.diagram_shown()

    def fail(self, error: str) -> None:
        """Tell the user; the last good diagram stays."""
        self.host.notify(error, title="Not built", severity="error", timeout=8, markup=False)
