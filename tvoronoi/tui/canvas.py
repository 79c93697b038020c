"""The diagram canvas: a Textual widget that draws a scene in braille, with pan, zoom and site dragging."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from rich.segment import Segment
from textual.binding import Binding
from textual.events import MouseDown, MouseMove, MouseScrollDown, MouseScrollUp, MouseUp, Resize
from textual.geometry import Size
from textual.message import Message
from textual.reactive import reactive
from textual.strip import Strip
from textual.widget import Widget

from tvoronoi.tui.colours import Palette, palette_for
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
from tvoronoi.tui.follow import follow_view
from tvoronoi.tui.layers import LayerCache
from tvoronoi.tui.raster import CURSOR_ARM, Frame, rasterize, redraw_part
from tvoronoi.tui.scene import Drawable
from tvoronoi.tui.styles import frame_lines
from tvoronoi.tui.viewport import View

# One key press pans by this fraction of the canvas.
PAN_STEP = 0.10
# One key press or one wheel step zooms by this factor.
ZOOM_STEP = 1.25
# A site within this many dots of the pointer is under it (a character is 2 x 4 dots).
PICK_RADIUS_DOTS = 2.5
# An edit or cursor move that touches more than this fraction of the characters draws
# the whole frame again rather than just those characters.
PARTIAL_MAX_FRACTION = 0.5
# Zoom limits, as a factor of the view that fits the box.
MAX_ZOOM_IN = 1e6
MAX_ZOOM_OUT = 50.0

# The colour systems (rich's names) of terminals with 16 colours or fewer: cells are not filled.
PLAIN_COLOR_SYSTEMS = ("standard", "windows")


def plain_terminal(app) -> bool:
    """Whether the app's terminal shows no colours (NO_COLOR) or only 16: cells are not filled then."""
    if app.no_color:
        return True
    # a headless app (tests, snapshots) draws in full colour, whatever TERM says
    return not app.is_headless and app.console.color_system in PLAIN_COLOR_SYSTEMS


if TYPE_CHECKING:
    from tvoronoi.tui.live import LiveScene
    from tvoronoi.tui.scene import Scene

    def _drawables(scene: Scene, live: LiveScene) -> tuple[Drawable, Drawable]:
        """For mypy: both kinds of scene are what the canvas draws."""
        return scene, live


PAN = Binding.Group("Pan", compact=True)
ZOOM = Binding.Group("Zoom", compact=True)


class DiagramCanvas(Widget, can_focus=True):
    """Draws the current diagram and owns the view (centre and scale).

    Keys pan and zoom; the mouse wheel zooms about the pointer. Dragging a
    site (when ``editable``) reports ``SiteDragged``; dragging elsewhere pans,
    and a click without a drag reports ``Clicked``. The view fits the box
    until the user moves it; until then a resize fits it again.

    The scene may be a ``Scene``, a scene of some sites with an ``overlay``
    (algorithm playback), or a ``LiveScene`` edited in place: the canvas
    then draws again when its ``version`` changes, and asks it for the owners
    of only the characters that changed.
    """

    BINDINGS = [
        Binding("left,h", "pan(-1, 0)", "Pan", key_display="←", group=PAN),
        Binding("right,l", "pan(1, 0)", "Pan", key_display="→", group=PAN),
        Binding("up,k", "pan(0, -1)", "Pan", key_display="↑", group=PAN),
        Binding("down,j", "pan(0, 1)", "Pan", key_display="↓", group=PAN),
        Binding("plus,equals_sign", "zoom(1)", "Zoom", key_display="+", group=ZOOM),
        Binding("minus", "zoom(-1)", "Zoom", key_display="-", group=ZOOM),
        Binding("0", "fit", "Fit", show=False),
    ]

    view: reactive[View] = reactive(View, always_update=False)
    show_delaunay: reactive[bool] = reactive(False)
    show_vertices: reactive[bool] = reactive(True)

    class ViewChanged(Message):
        """The user panned, zoomed or fitted the view."""

        def __init__(self, view: View) -> None:
            super().__init__()
            self.view = view

    class Clicked(Message):
        """A click (press and release without a drag) at a world point, not on a site being dragged."""

        def __init__(self, x: float, y: float) -> None:
            super().__init__()
            self.x = x
            self.y = y

    class TargetChanged(Message):
        """The keyboard cursor or the mouse pointer moved, or left: what they point at may differ."""

    class SiteDragged(Message):
        """The user dragged site ``site`` to (x, y); ``done`` when the button was released.

        ``serial`` grows with every drag message: a handler may skip a message
        that a newer one follows.
        """

        def __init__(self, site: int, x: float, y: float, done: bool, serial: int) -> None:
            super().__init__()
            self.site = site
            self.x = x
            self.y = y
            self.done = done
            self.serial = serial

    def __init__(self, *, name: str | None = None, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(name=name, id=id, classes=classes)
        self.scene: Drawable | None = None
        self.overlay = None
        # the keyboard cursor, a world point (None: hidden)
        self.cursor: tuple[float, float] | None = None
        # the world point under the mouse pointer (None: not over the canvas)
        self.pointer: tuple[float, float] | None = None
        # whether pressing on a site drags it
        self.editable = True
        # True while the view is the fitted one: a resize then fits again
        self.fitted = True
        self._frame_key: tuple | None = None
        self._lines: list[list[Segment]] = []
        self._frame: Frame | None = None
        # the diagram's layers of the last frame, for a frame that differs only in others
        self._layers = LayerCache()
        self._base_key: tuple | None = None
        self._frame_version = 0
        self._frame_cursor: tuple[float, float] | None = None
        self._owner_key: tuple | None = None
        self._press: tuple[int, int] | None = None
        self._drag_from: tuple[int, int] | None = None
        self._grabbed: int | None = None
        self._moved = False
        self.drag_serial = 0
        self._fit_size: Size | None = None

    def on_mount(self) -> None:
        self.app.theme_changed_signal.subscribe(self, lambda _theme: self.refresh())

    # -- the scene -----------------------------------------------------------

    def show_scene(self, scene: Drawable, *, fit: bool = True, overlay=None) -> None:
        """Draw a new scene (and overlay); fit the view to its box unless told to keep the view."""
        self.scene = scene
        self.overlay = overlay
        if fit or self.fitted:
            self.fit()
        self.refresh()

    def adopt_scene(self, scene: Drawable) -> None:
        """Show a scene that draws exactly as the one shown (the same diagram in an editable
        form): the frame on screen stays, and later changes of the scene redraw only their part."""
        if self._base_key is None or self._frame_key is None:
            self.show_scene(scene, fit=False)
            return
        self.scene = scene
        version = scene.version
        self._base_key = (id(scene), *self._base_key[1:])
        self._frame_key = (self._base_key, version, self._frame_key[2])
        self._frame_version = version
        self.refresh()

    def follow(self, box) -> None:
        """Show the world box (x0, y0, x1, y1) as the program's own move: no ``ViewChanged``.

        The view moves only if it does not show the box well already (see ``follow.follow_view``).
        """
        width, height = self._canvas_size()
        view = follow_view(self.view, box, width, height)
        if view != self.view:
            self.fitted = False
            self.view = view

    def set_cursor(self, cursor: tuple[float, float] | None) -> None:
        self.cursor = cursor
        self.refresh()
        self.post_message(self.TargetChanged())

    def cell_at(self, x: float, y: float) -> int | None:
        """The id of the site whose cell holds the world point (x, y); None outside the box."""
        scene = self.scene
        if scene is None or scene.n_sites == 0:
            return None
        xmin, ymin, xmax, ymax = scene.bbox
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            return None
        return int(scene.nearest(np.array([[x, y]]))[0])

    def world_at(self, col: float, row: float) -> tuple[float, float]:
        """The world point at the centre of character (col, row)."""
        width, height = self._canvas_size()
        return self.view.char_to_world(col, row, width, height)

    def pick_radius(self) -> float:
        """How near the pointer (world units) a site must be to lie under it."""
        return PICK_RADIUS_DOTS * self.view.scale

    def site_at(self, x: float, y: float) -> int | None:
        """The id of the site under the world point (x, y), or None."""
        if self.scene is None:
            return None
        return self.scene.site_near(x, y, self.pick_radius())

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

    def zoom(self) -> float:
        """How much the view is magnified against the one that fits the box (1: fitted)."""
        if self.scene is None:
            return 1.0
        width, height = self._canvas_size()
        return View.fit(self.scene.bbox, width, height).scale / self.view.scale

    def describe_view(self) -> str:
        """The world point at the centre of the view and the zoom, as "(x, y) ×zoom", with as
        many digits as a character's width needs."""
        view = self.view
        char_width = view.scale * DOT_COLS
        digits = min(max(1 - math.floor(math.log10(char_width)), 0), 12) if char_width > 0 else 3
        zoom = self.zoom()
        shown = f"{zoom:.3g}" if zoom < 1000 else f"{zoom:,.0f}"
        return f"({view.cx:.{digits}f}, {view.cy:.{digits}f}) ×{shown}"

    def _canvas_size(self) -> tuple[int, int]:
        size = self.content_size
        return max(size.width, 1), max(size.height, 1)

    def _set_view(self, view: View) -> None:
        """Move the view by user action, within the zoom limits."""
        if self.scene is not None:
            width, height = self._canvas_size()
            fitted = View.fit(self.scene.bbox, width, height).scale
            scale = min(max(view.scale, fitted / MAX_ZOOM_IN), fitted * MAX_ZOOM_OUT)
            if scale != view.scale:
                view = View(view.cx, view.cy, scale)
        self.fitted = False
        self.view = view
        self.post_message(self.ViewChanged(view))

    # -- actions -------------------------------------------------------------

    def action_pan(self, right: int, down: int) -> None:
        """Pan by about a tenth of the canvas (right, down are -1, 0 or 1), in whole characters,
        so that the layers drawn before are moved rather than drawn again."""
        self._keep_fitted()
        width, height = self._canvas_size()
        step = PAN_STEP * min(width * DOT_COLS, height * DOT_ROWS)
        step_cols, step_rows = max(round(step / DOT_COLS), 1), max(round(step / DOT_ROWS), 1)
        self._set_view(self.view.panned(right * step_cols * DOT_COLS, down * step_rows * DOT_ROWS))

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

    def _world_of(self, event) -> tuple[float, float]:
        offset = event.get_content_offset_capture(self)
        return self.world_at(offset.x, offset.y)

    def on_mouse_down(self, event: MouseDown) -> None:
        if event.button != 1:
            return
        self._keep_fitted()
        self._press = self._drag_from = (event.screen_x, event.screen_y)
        self._moved = False
        self._grabbed = self.site_at(*self._world_of(event)) if self.editable else None
        self.capture_mouse()
        self.focus()

    def on_mouse_move(self, event: MouseMove) -> None:
        if self._press is None or not event.button:
            offset = event.get_content_offset(self)
            self.pointer = None if offset is None else self.world_at(offset.x, offset.y)
            self.post_message(self.TargetChanged())
            return
        if self._drag_from is None:
            return
        x0, y0 = self._drag_from
        dx, dy = event.screen_x - x0, event.screen_y - y0
        if not (dx or dy):
            return
        self._moved = True
        self._drag_from = (event.screen_x, event.screen_y)
        if self._grabbed is not None:
            self.drag_serial += 1
            self.post_message(self.SiteDragged(self._grabbed, *self._world_of(event), False, self.drag_serial))
            return
        self._keep_fitted()
        # the world follows the pointer: move the view the other way
        self._set_view(self.view.panned(-dx * DOT_COLS, -dy * DOT_ROWS))

    def on_mouse_up(self, event: MouseUp) -> None:
        if self._press is None:
            return
        x, y = self._world_of(event)
        if self._grabbed is not None and self._moved:
            self.drag_serial += 1
            self.post_message(self.SiteDragged(self._grabbed, x, y, True, self.drag_serial))
        elif not self._moved:
            self.post_message(self.Clicked(x, y))
        self._press = self._drag_from = None
        self._grabbed = None
        self.capture_mouse(False)

    def on_leave(self) -> None:
        self.pointer = None
        self.post_message(self.TargetChanged())

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
        palette = self.palette()
        scene = self.scene
        version = 0 if scene is None else scene.version
        base = (id(scene), id(self.overlay), self.view, size, self.show_delaunay, self.show_vertices, palette)
        key = (base, version, self.cursor)
        if key == self._frame_key:
            return self._lines
        if scene is None:
            self._frame = None
            self._lines = [[] for _ in range(size.height)]
        elif base != self._base_key or not self._redraw_changes(scene, size, palette):
            # the cells under the characters stay while the scene, its version, the view and size do
            # (the scene itself is held, so that another scene cannot take its id)
            same = (
                self._owner_key is not None
                and self._owner_key[0] is scene
                and self._owner_key[1:] == (version, self.view, size)
            )
            owner = self._frame.owner if self._frame is not None and same else None
            self._frame = rasterize(
                scene,
                self.view,
                size.width,
                size.height,
                delaunay=self.show_delaunay,
                vertices=self.show_vertices,
                overlay=self.overlay,
                cursor=self.cursor,
                site_blocks=not palette.filled,
                layers=self._layers,
                owner=owner,
            )
            self._lines = frame_lines(self._frame, palette)
        self._frame_key, self._base_key = key, base
        self._frame_version, self._frame_cursor = version, self.cursor
        self._owner_key = None if scene is None else (scene, version, self.view, size)
        return self._lines

    def palette(self) -> Palette:
        """The colours for the theme, without cell fills where the terminal cannot show them
        (NO_COLOR, or 16 colours)."""
        app = self.app
        return palette_for(app.current_theme.dark, plain_terminal(app))

    def _redraw_changes(self, scene, size: Size, palette: Palette) -> bool:
        """Draw again only the characters that an edit of a live scene or a cursor move touched.

        Returns False when that is not possible (the scene cannot say what
        changed, or too much did); the caller then draws everything.
        """
        cols, rows = size.width, size.height
        boxes, ids = [], None
        if scene.version != self._frame_version:
            changes = scene.changes_since(self._frame_version)
            if changes is None:
                return False
            ids, box = changes
            boxes.append(box)
        if self.cursor != self._frame_cursor:
            reach = (CURSOR_ARM + 1) * self.view.scale * DOT_ROWS
            for cursor in (self.cursor, self._frame_cursor):
                if cursor is not None:
                    x, y = cursor
                    boxes.append((x - reach, y - reach, x + reach, y + reach))
        found = [self.view.char_span(b, cols, rows) for b in boxes if b is not None]
        spans = [s for s in found if s is not None]
        if not spans:
            return True
        c0, r0 = min(s[0] for s in spans), min(s[1] for s in spans)
        c1, r1 = max(s[2] for s in spans), max(s[3] for s in spans)
        if (c1 - c0) * (r1 - r0) > PARTIAL_MAX_FRACTION * cols * rows:
            return False
        frame = self._frame
        if frame is None:
            return False
        owner = None
        if ids is not None:
            part_view = self.view.window(c0, r0, cols, rows)
            owner = scene.update_owner(frame.owner[r0:r1, c0:c1], ids, part_view, c1 - c0, r1 - r0)
        redraw_part(
            frame,
            scene,
            self.view,
            cols,
            rows,
            (c0, r0, c1, r1),
            owner=owner,
            delaunay=self.show_delaunay,
            vertices=self.show_vertices,
            overlay=self.overlay,
            cursor=self.cursor,
            site_blocks=not palette.filled,
        )
        part = Frame(frame.codes[r0:r1], frame.mark[r0:r1], frame.fill[r0:r1], frame.owner[r0:r1])
        self._lines[r0:r1] = frame_lines(part, palette)
        return True

    def render_line(self, y: int) -> Strip:
        size = self.content_size
        lines = self._draw(size)
        if y >= len(lines) or not lines[y]:
            return Strip.blank(size.width, self.rich_style)
        return Strip(lines[y], size.width).apply_style(self.rich_style)
