"""Editing the diagram site by site through dynamic updates: add, move and delete, by mouse or keyboard.

The first edit of a diagram makes a ``DynamicVoronoi`` of its points (made
ahead in a worker once a diagram is shown) and a ``LiveScene`` over it; each
edit then touches only the cells it changed. Another engine, playback or a
save start from the live sites.
"""

from __future__ import annotations

from typing import Any, Callable, Protocol

from textual.binding import Binding
from textual.message import Message
from textual.widget import Widget

import tvoronoi
from tvoronoi.errors import TvoronoiError
from tvoronoi.tui.building import Built, Clock
from tvoronoi.tui.canvas import DiagramCanvas
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
from tvoronoi.tui.host import Host
from tvoronoi.tui.live import LiveScene
from tvoronoi.tui.playback import Player

# A dynamic diagram is made ahead, in a worker, for diagrams up to this many sites;
# larger ones get theirs at the first edit.
PREPARE_MAX_SITES = 200_000

BINDINGS = [
    Binding("a", "add_site", "Add", show=False),
    Binding("x,delete", "remove_site", "Delete", show=False),
    Binding("m", "move_site", "Move", show=False),
    Binding("c", "toggle_cursor", "Cursor", show=False),
    Binding("shift+left", "cursor(-1, 0)", "Cursor", show=False),
    Binding("shift+right", "cursor(1, 0)", "Cursor", show=False),
    Binding("shift+up", "cursor(0, -1)", "Cursor", show=False),
    Binding("shift+down", "cursor(0, 1)", "Cursor", show=False),
    # while a site is picked up with m, the arrows move it
    Binding("left,h", "nudge(-1, 0)", "Move site", show=False, priority=True),
    Binding("right,l", "nudge(1, 0)", "Move site", show=False, priority=True),
    Binding("up,k", "nudge(0, -1)", "Move site", show=False, priority=True),
    Binding("down,j", "nudge(0, 1)", "Move site", show=False, priority=True),
    Binding("enter", "drop_site", "Drop", show=False, priority=True),
    Binding("escape", "cancel_move", "Put back", show=False, priority=True),
]

HELP = {
    "add_site": "add a site at the keyboard cursor",
    "remove_site": "delete the site under the cursor or pointer",
    "move_site": "pick up a site: arrows move it, enter drops, esc undoes",
    "toggle_cursor": "show / hide the keyboard cursor",
    "cursor(-1, 0)": "move the keyboard cursor",
}
# How the help names the keys of an action, where its own names are too many.
HELP_KEYS = {"cursor(-1, 0)": "shift+arrows"}
# Bindings the help leaves out (explained with another line).
HELP_HIDDEN = {
    "nudge(-1, 0)",
    "nudge(1, 0)",
    "nudge(0, -1)",
    "nudge(0, 1)",
    "drop_site",
    "cancel_move",
    "cursor(1, 0)",
    "cursor(0, -1)",
    "cursor(0, 1)",
}

EDITING_ACTIONS = {"add_site", "remove_site", "move_site", "toggle_cursor", "cursor"}
MOVING_ACTIONS = {"nudge", "drop_site", "cancel_move"}


def make_live(built: Built) -> LiveScene:
    """A LiveScene over a new DynamicVoronoi of a built diagram's points (any thread)."""
    diagram = built.diagram
    dynamic = tvoronoi.DynamicVoronoi(built.points, engine=diagram.engine, bbox=diagram.bbox)
    return LiveScene(dynamic, diagram, built.scene.colours)


class EditorReady(Message):
    """A LiveScene for a built diagram was made ahead of the first edit."""

    def __init__(self, built: Built, live: LiveScene) -> None:
        super().__init__()
        self.built = built
        self.live = live


class EditingHost(Host, Protocol):
    """What editing uses of the App."""

    clock: Clock

    @property
    def focused(self) -> Widget | None: ...
    @property
    def built(self) -> Built | None: ...
    @property
    def player(self) -> Player | None: ...
    def request_build(
        self,
        make_points: Callable[[], Any],
        *,
        source: str,
        size: int | None,
        fit: bool = ...,
        point_set: Any = ...,
        read: Any = ...,
        bbox: Any = ...,
    ) -> None: ...
    def set_status(self, text: str) -> None: ...
    def update_status(self) -> None: ...
    def refresh_bindings(self) -> None: ...


class Editing:
    """Edits sites in place: the live scene, the site picked up, the count and time of the edits."""

    def __init__(self, host: EditingHost) -> None:
        self.host = host
        self.live: LiveScene | None = None
        self._prepared: tuple[Built, LiveScene] | None = None
        # (site id, where it was) while a site is picked up with m
        self.moving: tuple[int, tuple[float, float]] | None = None
        self.last_edit_ms = 0.0
        self.n_edits = 0

    def allows(self, action: str) -> bool | None:
        """Whether the app may run ``action`` now as far as editing goes; None: editing has no say."""
        if action in MOVING_ACTIONS:
            return self.moving is not None and self.host.focused is self.host.canvas
        if action in EDITING_ACTIONS:
            return self.host.player is None
        return None

    # -- the live scene ------------------------------------------------------

    def prepare(self) -> None:
        """Make the dynamic diagram of the shown points in a worker, ahead of the first edit."""
        built = self.host.built
        if built is None or len(built.points) > PREPARE_MAX_SITES:
            return
        self.host.run_worker(
            lambda: self._prepare_in_thread(built),
            thread=True,
            exclusive=True,
            group="prepare-editing",
            exit_on_error=False,
        )

    def _prepare_in_thread(self, built: Built) -> None:
        try:
            live = make_live(built)
        except (TvoronoiError, MemoryError):
            return  # the first edit tries again and says why
        self.host.post_message(EditorReady(built, live))

    def editor_ready(self, message: EditorReady) -> None:
        """A worker made the live scene ahead: keep it for the first edit, if still wanted."""
        if message.built is self.host.built and self.live is None:
            self._prepared = (message.built, message.live)

    def editor(self) -> LiveScene | None:
        """The live scene, made now if need be; None (after saying why) if editing is not possible."""
        if self.live is not None:
            return self.live
        built = self.host.built
        if built is None:
            return None
        if self._prepared is not None and self._prepared[0] is built:
            live = self._prepared[1]
        else:
            try:
                live = make_live(built)
            except TvoronoiError as exc:
                self.host.notify(str(exc), title="Not edited", severity="error", timeout=8, markup=False)
                return None
        self._prepared = None
        self.live = live
        canvas = self.host.canvas
        if canvas.scene is built.scene and canvas.overlay is None:
            canvas.adopt_scene(live)  # it draws just as the built scene
        else:
            canvas.show_scene(live, fit=False)
        return live

    def finish(self) -> None:
        """Build the live sites into a whole diagram again (for another engine, playback)."""
        live, built = self.live, self.host.built
        if live is None or built is None:
            return
        points = live.points()
        source = built.source if built.source.endswith("(edited)") else f"{built.source} (edited)"
        self.host.request_build(lambda: points, source=source, size=len(points), fit=False, bbox=live.bbox)

    def drop(self) -> None:
        """Forget the live scene (a new diagram replaced it)."""
        self.live = None
        self._prepared = None
        self.moving = None
        self.n_edits = 0

    def _edit(self, what: str, change: Callable[[LiveScene], object]) -> bool:
        """Run one edit on the live scene; tell the user if it was refused."""
        live = self.editor()
        if live is None:
            return False
        clock = self.host.clock
        start = clock()
        try:
            change(live)
        except TvoronoiError as exc:
            self.host.notify(str(exc), title=f"Not {what}", severity="error", timeout=8, markup=False)
            return False
        self.last_edit_ms = (clock() - start) * 1000
        self.n_edits += 1
        self.host.canvas.refresh()
        self.host.update_status()
        return True

    def _site_under_cursor(self) -> int | None:
        """The site under the keyboard cursor if it is shown, else under the mouse pointer; None
        (after saying how to put the cursor on one) when there is none."""
        canvas = self.host.canvas
        where = canvas.cursor if canvas.cursor is not None else canvas.pointer
        site = None if where is None else canvas.site_at(*where)
        if site is None:
            self.host.notify(
                "no site under the cursor: move it onto one (shift+arrows) or point at one", severity="warning"
            )
        return site

    def _one_char(self) -> tuple[float, float]:
        scale = self.host.canvas.view.scale
        return DOT_COLS * scale, DOT_ROWS * scale

    def _cursor(self) -> tuple[float, float]:
        """The keyboard cursor, shown first (at the centre of the view) if it was hidden."""
        canvas = self.host.canvas
        if canvas.cursor is None:
            canvas.set_cursor((canvas.view.cx, canvas.view.cy))
        assert canvas.cursor is not None, "set just above"
        return canvas.cursor

    # -- what the keys do ------------------------------------------------------

    def toggle_cursor(self) -> None:
        """Show the keyboard cursor (at the centre of the view) or hide it."""
        canvas = self.host.canvas
        canvas.set_cursor(None if canvas.cursor is not None else (canvas.view.cx, canvas.view.cy))

    def move_cursor(self, dx: int, dy: int) -> None:
        """Move the keyboard cursor by one character (showing it first if hidden)."""
        canvas = self.host.canvas
        if canvas.cursor is None:
            canvas.set_cursor((canvas.view.cx, canvas.view.cy))
            return
        w, h = self._one_char()
        canvas.set_cursor((canvas.cursor[0] + dx * w, canvas.cursor[1] - dy * h))

    def add_site(self) -> None:
        """Add a site at the keyboard cursor."""
        x, y = self._cursor()
        self._edit("added", lambda live: live.insert(x, y))

    def add_site_at(self, x: float, y: float) -> None:
        """A click on empty space adds a site there."""
        if self.host.player is not None or self.moving is not None:
            return
        self._edit("added", lambda live: live.insert(x, y))

    def remove_site(self) -> None:
        """Delete the site under the cursor or the mouse pointer."""
        site = self._site_under_cursor()
        if site is None:
            return
        if self.moving is not None and self.moving[0] == site:
            self.moving = None
        self._edit("deleted", lambda live: live.remove(site))

    def pick_up(self) -> None:
        """Pick up the site under the cursor (m again drops it)."""
        if self.moving is not None:
            self.drop_site()
            return
        site = self._site_under_cursor()
        if site is None:
            return
        live = self.editor()
        if live is None:
            return
        x, y = (float(c) for c in live.sites[site])
        self.moving = (site, (x, y))
        self.host.canvas.set_cursor((x, y))
        self.host.refresh_bindings()
        self.host.set_status(f"moving site {site}: arrows move it · enter or m drops it · esc puts it back")

    def nudge(self, dx: int, dy: int) -> None:
        """Move the picked-up site by one character."""
        if self.moving is None or self.live is None:
            return
        site, _ = self.moving
        w, h = self._one_char()
        sx, sy = self.live.sites[site]
        x, y = float(sx + dx * w), float(sy - dy * h)
        if self._edit("moved", lambda live: live.move(site, x, y)):
            self.host.canvas.set_cursor((x, y))

    def drop_site(self) -> None:
        """Leave the picked-up site where it is."""
        self.moving = None
        self.host.refresh_bindings()
        self.host.update_status()

    def cancel_move(self) -> None:
        """Put the picked-up site back where it was."""
        if self.moving is None:
            return
        site, (x, y) = self.moving
        self.moving = None
        self.host.refresh_bindings()
        if self._edit("moved", lambda live: live.move(site, x, y)):
            self.host.canvas.set_cursor((x, y))

    def dragged(self, message: DiagramCanvas.SiteDragged) -> None:
        """A dragged site follows the pointer; a drag message that a newer one follows is skipped."""
        if self.host.player is not None:
            return
        if not message.done and message.serial != self.host.canvas.drag_serial:
            return
        site, x, y = message.site, message.x, message.y
        live = self.editor()
        if live is None or not live.alive(site):
            return
        self._edit("moved", lambda live: live.move(site, x, y))
