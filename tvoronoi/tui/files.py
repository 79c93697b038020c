"""Opening point files, saving cells and exporting the view from the UI; the save runs in a worker
thread."""

from __future__ import annotations

from pathlib import Path

from textual import work
from textual.message import Message
from textual.widgets import ProgressBar

import tvoronoi
from tvoronoi.errors import TvoronoiError
from tvoronoi.tui.colours import palette_for
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


class FilesMixin:
    """The App's part that opens point files and saves the cells as GeoJSON."""

    _saving = False
    # the last export's path, offered again
    _last_export: str = DEFAULT_EXPORT_NAME
    # the last file asked for, to offer it again, and its folder, where the Open dialog's tree starts
    _last_open: OpenRequest | None = None
    _last_folder: Path | None = None
    # a file opened without x and y columns given: once read, ask which columns if that was ambiguous
    _columns_pending: OpenRequest | None = None

    def action_open(self) -> None:
        """Ask for a point file and show its diagram."""
        last = self._last_open
        self.push_screen(
            OpenDialog(
                "Open a point file (CSV, text, GeoJSON, .npy)", placeholder="points.csv",
                value="" if last is None else str(last.path),
                x=None if last is None else last.x, y=None if last is None else last.y,
                folder=self._last_folder,
            ),
            self._open_path,
        )

    def _open_path(self, request: OpenRequest | None) -> None:
        self.canvas.focus()
        if request is None:
            return
        self._last_open = request
        folder = request.path.expanduser().parent
        if folder.is_dir():
            self._last_folder = folder.resolve()
        self._columns_pending = request if request.x is None and request.y is None else None

        def read():
            from tvoronoi.readers import read_points

            try:
                return read_points(str(request.path), x=request.x, y=request.y)
            except TvoronoiError as exc:
                raise ReadFailed(ui_advice(str(exc))) from exc

        self._request_build(lambda: None, source=request.path.name, size=None, read=read)

    def offer_columns(self) -> None:
        """A file was just shown: if its x and y columns were taken by position among several
        numeric ones, ask which columns are x and y (the reader's choice stays unless changed)."""
        request, self._columns_pending = self._columns_pending, None
        built = self.built
        point_set = None if built is None else built.point_set
        if request is None or point_set is None or not point_set.candidates:
            return
        chosen = point_set.xy_columns

        def chosen_columns(columns: tuple[str, str] | None) -> None:
            self.canvas.focus()
            if columns is not None and tuple(columns) != tuple(chosen):
                self._open_path(OpenRequest(request.path, *columns))

        self.push_screen(ColumnsDialog(request.path.name, point_set.candidates, chosen), chosen_columns)

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
            from tvoronoi.writers.geojson_diagram import write_cells
        except ImportError:
            self.notify("saving GeoJSON is not available in this build", severity="error")
            return
        self._saving = True
        bar = self.query_one("#progress", ProgressBar)
        bar.update(total=None, progress=0)
        bar.display = True
        live, built = self.live, self.built
        if live is None:
            self._save_in_thread(write_cells, lambda: (built.diagram, built.point_set), path)
        else:
            # an edited diagram: the live sites, numbered afresh, built in the worker
            points, engine, bbox = live.points(), built.diagram.engine, live.bbox
            self._save_in_thread(
                write_cells, lambda: (tvoronoi.voronoi(points, engine=engine, bbox=bbox), None), path,
            )

    @work(thread=True, group="save", exit_on_error=False)
    def _save_in_thread(self, write_cells, what, path: Path) -> None:
        try:
            diagram, point_set = what()
            count = write_cells(
                diagram, point_set, str(path),
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
        if self.building is None:  # the bar stays while a build runs
            self.query_one("#progress").display = False
        if message.error is not None:
            self.notify(message.error, title="Not saved", severity="error", timeout=8, markup=False)
        else:
            self.notify(f"{message.count:,} cells written to {message.path}", title="Saved", markup=False)

    # -- exporting the view ----------------------------------------------------

    def action_export(self) -> None:
        """Ask for a path and write the view there: .svg (vector) or .png."""
        if self.built is None:
            self._fail("there is no diagram to export")
            return
        self.push_screen(
            PathDialog("Export the view as SVG or PNG (by the name's ending)", value=self._last_export,
                       placeholder="view.svg", confirm_overwrite=True),
            self._export_path,
        )

    def _export_path(self, path: Path | None) -> None:
        self.canvas.focus()
        if path is None or self.built is None:
            return
        self._last_export = str(path)
        canvas = self.canvas
        size = canvas.content_size
        scene = canvas.scene
        # the built diagram's cells are the scene's rows; an edited scene builds its own
        diagram = self.built.diagram if scene is self.built.scene else None
        dark = self.current_theme.dark
        self._export_in_thread(scene, canvas.view, max(size.width, 1), max(size.height, 1), dark,
                               canvas.show_delaunay, diagram, path)

    @work(thread=True, group="export", exit_on_error=False)
    def _export_in_thread(self, scene, view, cols: int, rows: int, dark: bool, delaunay: bool, diagram,
                          path: Path) -> None:
        from tvoronoi.tui.export import export_view, picture

        try:
            pic = picture(scene, view, cols, rows, palette_for(dark), dark=dark, delaunay=delaunay,
                          diagram=diagram)
            kind = export_view(pic, path)
        except (TvoronoiError, OSError) as exc:
            self.call_from_thread(self.notify, str(exc), title="Not exported", severity="error", timeout=8,
                                  markup=False)
            return
        self.call_from_thread(self.notify, f"{len(pic.rings):,} cells and {len(pic.sites):,} sites written "
                              f"to {path} ({kind})", title="Exported", markup=False)
