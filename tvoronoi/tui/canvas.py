"""The diagram canvas: a Textual widget that draws a scene in braille, with pan and zoom."""

from __future__ import annotations

import time

from rich.segment import Segment
from textual.binding import Binding
from textual.events import MouseDown, MouseMove, MouseScrollDown, MouseScrollUp, MouseUp, Resize
from textual.geometry import Size
from textual.message import Message
from textual.reactive import reactive
from textual.strip import Strip
from textual.widget import Widget

from tvoronoi.tui.colours import palette_for
from tvoronoi.tui.raster import DOT_COLS, DOT_ROWS, Scene, View, frame_lines, rasterize

# One key press pans by this fraction of the canvas.
PAN_STEP = 0.10
# One key press or one wheel step zooms by this factor.
ZOOM_STEP = 1.25
# Zoom limits, as a factor of the view that fits the box.
MAX_ZOOM_IN = 1e6
MAX_ZOOM_OUT = 50.0

PAN = Binding.Group("Pan", compact=True)
ZOOM = Binding.Group("Zoom", compact=True)


class DiagramCanvas(Widget, can_focus=True):
    """Draws the current diagram and owns the view (centre and scale).

    Keys pan and zoom; the mouse wheel zooms about the pointer and dragging
    pans. The view fits the box until the user moves it; until then a resize
    fits it again.
    """

    BINDINGS = [
        Binding("left,h", "pan(-1, 0)", "Pan", key_display="←", group=PAN),
        Binding("right,l", "pan(1, 0)", "Pan", key_display="→", group=PAN),
        Binding("up,k", "pan(0, -1)", "Pan", key_display="↑", group=PAN),
        Binding("down,j", "pan(0, 1)", "Pan", key_display="↓", group=PAN),
        Binding("plus,equals_sign", "zoom(1)", "Zoom", key_display="+", group=ZOOM),
        Binding("minus", "zoom(-1)", "Zoom", key_display="-", group=ZOOM),
        Binding("0", "fit", "Fit"),
    ]

    view: reactive[View] = reactive(View, always_update=False)
    show_delaunay: reactive[bool] = reactive(False)
    show_vertices: reactive[bool] = reactive(True)

    class ViewChanged(Message):
        """The user panned, zoomed or fitted the view."""

        def __init__(self, view: View) -> None:
            super().__init__()
            self.view = view

    def __init__(self, *, name: str | None = None, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(name=name, id=id, classes=classes)
        self.scene: Scene | None = None
        # True while the view is the fitted one: a resize then fits again
        self.fitted = True
        self.last_draw_ms = 0.0
        self._frame_key: tuple | None = None
        self._lines: list[list[Segment]] = []
        self._drag_from: tuple[int, int] | None = None
        self._fit_size: Size | None = None

    def on_mount(self) -> None:
        self.app.theme_changed_signal.subscribe(self, lambda _theme: self.refresh())

    # -- the scene -----------------------------------------------------------

    def show_scene(self, scene: Scene, *, fit: bool = True) -> None:
        """Draw a new scene; fit the view to its box unless told to keep the view."""
        self.scene = scene
        if fit or self.fitted:
            self.fit()
        self.refresh()

    def fit(self) -> None:
        """Show the whole box."""
        self.fitted = True
        self._fit_size = None
        self._keep_fitted()

    def _keep_fitted(self) -> None:
        """Fit the view again if it is the fitted one and the canvas has changed size since.

        Before the first layout the canvas has no size; the fit then waits
        for it (for the first draw, or the first key).
        """
        size = self.content_size
        if not self.fitted or self.scene is None or size.area == 0 or size == self._fit_size:
            return
        self._fit_size = size
        self.view = View.fit(self.scene.bbox, size.width, size.height)

    def _canvas_size(self) -> tuple[int, int]:
        size = self.content_size
        return max(size.width, 1), max(size.height, 1)

    def _set_view(self, view: View) -> None:
        """Move the view by user action, within the zoom limits."""
        if self.scene is not None:
            width, height = self._canvas_size()
            fitted = View.fit(self.scene.bbox, width, height).scale
            scale = min(max(view.scale, fitted / MAX_ZOOM_IN), fitted * MAX_ZOOM_OUT)
            view = View(view.cx, view.cy, scale)
        self.fitted = False
        self.view = view
        self.post_message(self.ViewChanged(view))

    # -- actions -------------------------------------------------------------

    def action_pan(self, right: int, down: int) -> None:
        """Pan by a tenth of the canvas (right, down are -1, 0 or 1)."""
        self._keep_fitted()
        width, height = self._canvas_size()
        step = PAN_STEP * min(width * DOT_COLS, height * DOT_ROWS)
        self._set_view(self.view.panned(right * step, down * step))

    def action_zoom(self, direction: int) -> None:
        """Zoom in (1) or out (-1) about the centre."""
        self._keep_fitted()
        self._set_view(self.view.zoomed(ZOOM_STEP if direction > 0 else 1 / ZOOM_STEP))

    def action_fit(self) -> None:
        """Fit the whole box in the canvas."""
        self.fit()
        self.post_message(self.ViewChanged(self.view))

    # -- mouse ---------------------------------------------------------------

    def _zoom_at(self, event, factor: float) -> None:
        offset = event.get_content_offset(self)
        if offset is None:
            return
        self._keep_fitted()
        width, height = self._canvas_size()
        about = self.view.char_to_world(offset.x, offset.y, width, height)
        self._set_view(self.view.zoomed(factor, about))
        event.stop()

    def on_mouse_scroll_up(self, event: MouseScrollUp) -> None:
        self._zoom_at(event, ZOOM_STEP)

    def on_mouse_scroll_down(self, event: MouseScrollDown) -> None:
        self._zoom_at(event, 1 / ZOOM_STEP)

    def on_mouse_down(self, event: MouseDown) -> None:
        if event.button != 1:
            return
        # Dragging always pans for now; moving a site by dragging it belongs here
        # once the diagram can be updated point by point.
        self._drag_from = (event.screen_x, event.screen_y)
        self.capture_mouse()
        self.focus()

    def on_mouse_move(self, event: MouseMove) -> None:
        if self._drag_from is None or not event.button:
            return
        x0, y0 = self._drag_from
        dx, dy = event.screen_x - x0, event.screen_y - y0
        if dx or dy:
            self._keep_fitted()
            self._drag_from = (event.screen_x, event.screen_y)
            # the world follows the pointer: move the view the other way
            self._set_view(self.view.panned(-dx * DOT_COLS, -dy * DOT_ROWS))

    def on_mouse_up(self, event: MouseUp) -> None:
        if self._drag_from is not None:
            self._drag_from = None
            self.capture_mouse(False)

    def on_resize(self, event: Resize) -> None:
        self._keep_fitted()
        self.refresh()

    # -- drawing -------------------------------------------------------------

    def _draw(self, size: Size) -> list[list[Segment]]:
        """The rows of the current frame, drawn again only when something changed."""
        if self.fitted and self.scene is not None and size.area and size != self._fit_size:
            # the size changed since the view was fitted (a resize not yet seen): fit it
            # again, quietly, since this is the drawing itself
            self._fit_size = size
            self.set_reactive(DiagramCanvas.view, View.fit(self.scene.bbox, size.width, size.height))
        dark = self.app.current_theme.dark
        key = (id(self.scene), self.view, size, self.show_delaunay, self.show_vertices, dark)
        if key != self._frame_key:
            start = time.perf_counter()
            if self.scene is None:
                self._lines = [[] for _ in range(size.height)]
            else:
                frame = rasterize(
                    self.scene, self.view, size.width, size.height,
                    delaunay=self.show_delaunay, vertices=self.show_vertices,
                )
                self._lines = frame_lines(frame, palette_for(dark))
            self._frame_key = key
            self.last_draw_ms = (time.perf_counter() - start) * 1000
        return self._lines

    def render_line(self, y: int) -> Strip:
        size = self.content_size
        lines = self._draw(size)
        if y >= len(lines) or not lines[y]:
            return Strip.blank(size.width, self.rich_style)
        return Strip(lines[y], size.width).apply_style(self.rich_style)
