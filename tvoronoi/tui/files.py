"""Opening point files, saving cells and exporting the view from the UI; saves and exports run in worker
threads."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Protocol

from textual.message import Message
from textual.screen import Screen
from textual.theme import Theme

import tvoronoi
from tvoronoi.diagram import Diagram
from tvoronoi.errors import TvoronoiError
from tvoronoi.readers.pointset import PointSet
from tvoronoi.tui.building import Built
from tvoronoi.tui.colours import palette_for
from tvoronoi.tui.host import Host
from tvoronoi.tui.live import LiveScene
from tvoronoi.tui.raster import Drawable, View
from tvoronoi.tui.screens import ColumnsDialog, OpenDialog, OpenRequest, PathDialog

DEFAULT_SAVE_NAME = "cells.geojson"
DEFAULT_EXPORT_NAME = "view.svg"
# The readers' messages advise the command line's --x/--y; in the UI the Open
# dialog's column fields do that job. Replaced in this order (the longer phrases first).
CLI_ADVICE = (
    ("drop --x/--y", "leave the x and y column fields of the Open dialog empty"),
    ("--x/--y choose table columns", "the x and y column fields choose table columns"),
    ("--x/--y", "the x and y column fields of the Open dialog (o)"),
)


def ui_advice(message: str) -> str:
    """A reader's error message with its command-line advice turned into the UI's controls."""
    for cli, ui in CLI_ADVICE:
        message = message.replace(cli, ui)
    return message


class ReadFailed(TvoronoiError):
    """A point file could not be read; the message names the UI's controls, not the CLI's flags."""


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


class FilesHost(Host, Protocol):
    """What opening, saving and exporting use of the App."""

    @property
    def built(self) -> Built | None: ...
    @property
    def live(self) -> LiveScene | None: ...
    @property
    def current_theme(self) -> Theme: ...
    def request_build(
        self,
        make_points: Callable[[], Any],
        *,
        source: str,
        size: int | None,
        fit: bool = ...,
        point_set: PointSet | None = ...,
        read: Callable[[], PointSet] | None = ...,
        bbox: Any = ...,
    ) -> None: ...
    def fail(self, error: str) -> None: ...
    def show_progress(self, done: int = 0, total: int | None = None) -> None: ...
    def progress_done(self) -> None: ...
    def push_screen(self, screen: Screen[Any], callback: Callable[[Any], None]) -> Any: ...
    def call_from_thread(self, callback: Callable[..., Any], *args: Any, **kwargs: Any) -> Any: ...


class Files:
    """Opens point files, saves the cells as GeoJSON and exports the view."""

    def __init__(self, host: FilesHost) -> None:
        self.host = host
        self.saving = False
        # the last export's path, offered again
        self.last_export: str = DEFAULT_EXPORT_NAME
        # the last file asked for, to offer it again, and its folder, where the Open dialog's tree starts
        self.last_open: OpenRequest | None = None
        self.last_folder: Path | None = None
        # a file opened without x and y columns given: once read, ask which columns if that was ambiguous
        self._columns_pending: OpenRequest | None = None

    # -- opening ---------------------------------------------------------------

    def ask_open(self) -> None:
        """Ask for a point file and show its diagram."""
        last = self.last_open
        self.host.push_screen(
            OpenDialog(
                "Open a point file (CSV, text, GeoJSON, .npy)",
                placeholder="points.csv",
                value="" if last is None else str(last.path),
                x=None if last is None else last.x,
                y=None if last is None else last.y,
                folder=self.last_folder,
            ),
            self.open,
        )

    def open(self, request: OpenRequest | None) -> None:
        """Read the file asked for (in a worker) and show its diagram; None: the dialog was cancelled."""
        self.host.canvas.focus()
        if request is None:
            return
        self.last_open = request
        folder = request.path.expanduser().parent
        if folder.is_dir():
            self.last_folder = folder.resolve()
        self._columns_pending = request if request.x is None and request.y is None else None

        def read() -> PointSet:
            from tvoronoi.readers import read_points

            try:
                return read_points(str(request.path), x=request.x, y=request.y)
            except TvoronoiError as exc:
                raise ReadFailed(ui_advice(str(exc))) from exc

        self.host.request_build(lambda: None, source=request.path.name, size=None, read=read)

    def offer_columns(self) -> None:
        """A file was just shown: if its x and y columns were taken by position among several
        numeric ones, ask which columns are x and y (the reader's choice stays unless changed)."""
        request, self._columns_pending = self._columns_pending, None
        built = self.host.built
        point_set = None if built is None else built.point_set
        if request is None or point_set is None or not point_set.candidates:
            return
        chosen = point_set.xy_columns
        if chosen is None:
            return

        def chosen_columns(columns: tuple[str, str] | None) -> None:
            self.host.canvas.focus()
            if columns is not None and tuple(columns) != tuple(chosen):
                self.open(OpenRequest(request.path, *columns))

        self.host.push_screen(ColumnsDialog(request.path.name, point_set.candidates, chosen), chosen_columns)

    # -- saving ----------------------------------------------------------------

    def ask_save(self) -> None:
        """Ask for a path and write the cells there as GeoJSON."""
        if self.host.built is None:
            self.host.fail("there is no diagram to save")
            return
        if self.saving:
            self.host.notify("a save is still running", severity="warning")
            return
        self.host.push_screen(
            PathDialog("Save the cells as GeoJSON", value=DEFAULT_SAVE_NAME, confirm_overwrite=True),
            self._save_path,
        )

    def _save_path(self, path: Path | None) -> None:
        self.host.canvas.focus()
        built = self.host.built
        if path is None or built is None:
            return
        try:
            from tvoronoi.writers.geojson_diagram import write_cells
        except ImportError:
            self.host.notify("saving GeoJSON is not available in this build", severity="error")
            return
        self.saving = True
        self.host.show_progress()
        live = self.host.live
        what: Callable[[], tuple[Diagram, PointSet | None]]
        if live is None:
            what = lambda: (built.diagram, built.point_set)  # noqa: E731
        else:
            # an edited diagram: the live sites, numbered afresh, built in the worker
            points, engine, bbox = live.points(), built.diagram.engine, live.bbox
            what = lambda: (tvoronoi.voronoi(points, engine=engine, bbox=bbox), None)  # noqa: E731
        self.host.run_worker(
            lambda: self._save_in_thread(write_cells, what, path), thread=True, group="save", exit_on_error=False
        )

    def _save_in_thread(
        self, write_cells: Callable[..., int], what: Callable[[], tuple[Diagram, PointSet | None]], path: Path
    ) -> None:
        try:
            diagram, point_set = what()
            count = write_cells(
                diagram,
                point_set,
                str(path),
                progress=lambda done, total: self.host.post_message(SaveProgress(done, total)),
                overwrite=True,  # the dialog asked before replacing a file
            )
        except (TvoronoiError, OSError) as exc:
            self.host.post_message(SaveFinished(path, 0, str(exc)))
            return
        self.host.post_message(SaveFinished(path, count, None))

    def save_progress(self, message: SaveProgress) -> None:
        self.host.show_progress(message.done, max(message.total, 1))

    def save_finished(self, message: SaveFinished) -> None:
        self.saving = False
        self.host.progress_done()
        if message.error is not None:
            self.host.notify(message.error, title="Not saved", severity="error", timeout=8, markup=False)
        else:
            self.host.notify(f"{message.count:,} cells written to {message.path}", title="Saved", markup=False)

    # -- exporting the view ----------------------------------------------------

    def ask_export(self) -> None:
        """Ask for a path and write the view there: .svg (vector) or .png."""
        if self.host.built is None:
            self.host.fail("there is no diagram to export")
            return
        self.host.push_screen(
            PathDialog(
                "Export the view as SVG or PNG (by the name's ending)",
                value=self.last_export,
                placeholder="view.svg",
                confirm_overwrite=True,
            ),
            self._export_path,
        )

    def _export_path(self, path: Path | None) -> None:
        self.host.canvas.focus()
        built = self.host.built
        if path is None or built is None:
            return
        self.last_export = str(path)
        canvas = self.host.canvas
        size = canvas.content_size
        scene = canvas.scene
        # the built diagram's cells are the scene's rows; an edited scene builds its own
        diagram = built.diagram if scene is built.scene else None
        dark = self.host.current_theme.dark
        view, delaunay = canvas.view, canvas.show_delaunay
        cols, rows = max(size.width, 1), max(size.height, 1)
        self.host.run_worker(
            lambda: self._export_in_thread(scene, view, cols, rows, dark, delaunay, diagram, path),
            thread=True,
            group="export",
            exit_on_error=False,
        )

    def _export_in_thread(
        self,
        scene: Drawable | None,
        view: View,
        cols: int,
        rows: int,
        dark: bool,
        delaunay: bool,
        diagram: Diagram | None,
        path: Path,
    ) -> None:
        from tvoronoi.tui.export import export_view, picture

        try:
            pic = picture(scene, view, cols, rows, palette_for(dark), dark=dark, delaunay=delaunay, diagram=diagram)
            kind = export_view(pic, path)
        except (TvoronoiError, OSError) as exc:
            self.host.call_from_thread(
                self.host.notify, str(exc), title="Not exported", severity="error", timeout=8, markup=False
            )
            return
        self.host.call_from_thread(
            self.host.notify,
            f"{len(pic.rings):,} cells and {len(pic.sites):,} sites written to {path} ({kind})",
            title="Exported",
            markup=False,
        )
