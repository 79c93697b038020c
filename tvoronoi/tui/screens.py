"""The modal screens of the terminal UI: the key help, the path dialog for open and save, and the choice
between a sample and all the sites for playback."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Static

# Mouse gestures, listed in the help beside the keys.
MOUSE_HELP = (
    ("wheel", "zoom about the pointer"),
    ("drag", "pan; a site dragged moves (its cell follows)"),
    ("click", "add a site (empty space); focus a control, hover for its tooltip"),
    ("timeline", "click or drag to go to a step of the playback"),
)


def _plain(text: str) -> str:
    """Text shown as it is, not read as markup (keys such as [ and ])."""
    return text.replace("[", "\\[")


class HelpScreen(ModalScreen[None]):
    """Every key of the UI, with what it does."""

    BINDINGS = [
        Binding("escape,question_mark,q", "dismiss", "Close", key_display="esc"),
    ]

    def __init__(self, keys: list[tuple[str, str]]) -> None:
        super().__init__()
        self.keys = keys

    def compose(self) -> ComposeResult:
        width = max((len(k) for k, _ in (*self.keys, *MOUSE_HELP)), default=0)
        lines = ["[b]Keys[/b]"]
        lines += [f"  [b $accent]{_plain(f'{key:<{width}}')}[/]  {_plain(what)}" for key, what in self.keys]
        lines += ["", "[b]Mouse[/b]"]
        lines += [f"  [b $accent]{_plain(f'{key:<{width}}')}[/]  {_plain(what)}" for key, what in MOUSE_HELP]
        lines += ["", "[dim]In a text field, Esc returns to the diagram; Tab moves between controls.[/dim]"]
        with VerticalScroll(id="help-box") as box:
            box.border_title = "tvoronoi help"
            box.border_subtitle = "esc to close"
            yield Static("\n".join(lines), id="help-text")

    def action_dismiss(self) -> None:
        self.dismiss(None)


class PathDialog(ModalScreen[Path | None]):
    """Ask for a file path; dismissed with the path, or None when cancelled.

    With ``confirm_overwrite``, a path that exists must be submitted twice.
    """

    BINDINGS = [Binding("escape", "cancel", "Cancel")]

    def __init__(self, title: str, *, value: str = "", placeholder: str = "",
                 confirm_overwrite: bool = False) -> None:
        super().__init__()
        self.title_text = title
        self.value = value
        self.placeholder = placeholder
        self.confirm_overwrite = confirm_overwrite
        self._confirmed: str | None = None

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = self.title_text
            yield Input(self.value, placeholder=self.placeholder, id="path")
            yield Label("Enter to accept · Esc to cancel", id="dialog-hint")

    def on_mount(self) -> None:
        self.query_one("#path", Input).focus()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        text = self.query_one("#path", Input).value.strip()
        hint = self.query_one("#dialog-hint", Label)
        if not text:
            hint.update("[b $error]Give a path[/] · Esc to cancel")
            return
        path = Path(text).expanduser()
        if self.confirm_overwrite and path.exists() and self._confirmed != text:
            self._confirmed = text
            hint.update(f"[b $warning]{path.name} exists:[/] Enter again to replace it · Esc to cancel")
            return
        self.dismiss(self.result(path))

    def result(self, path: Path):
        """What the dialog is dismissed with once a path is accepted."""
        return path

    def on_input_changed(self, event: Input.Changed) -> None:
        # a changed path needs its own confirmation
        if event.input.id == "path":
            self._confirmed = None

    def action_cancel(self) -> None:
        self.dismiss(None)


@dataclass(frozen=True)
class OpenRequest:
    """A point file to open, and its x and y columns (None: found from the file)."""

    path: Path
    x: str | None = None
    y: str | None = None


class OpenDialog(PathDialog):
    """Ask for a point file and, optionally, which columns of a table hold x and y.

    Dismissed with an ``OpenRequest``, or None when cancelled.
    """

    def __init__(self, title: str, *, value: str = "", placeholder: str = "",
                 x: str | None = None, y: str | None = None) -> None:
        super().__init__(title, value=value, placeholder=placeholder)
        self.x = x
        self.y = y

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = self.title_text
            yield Input(self.value, placeholder=self.placeholder, id="path")
            with Horizontal(id="columns"):
                yield Label("x column")
                yield Input(self.x or "", placeholder="auto", compact=True, id="x-column")
                yield Label("y column")
                yield Input(self.y or "", placeholder="auto", compact=True, id="y-column")
            yield Label("Enter to open · Tab: columns (a name, an index or colN) · Esc to cancel",
                        id="dialog-hint")

    def result(self, path: Path) -> OpenRequest:
        x = self.query_one("#x-column", Input).value.strip() or None
        y = self.query_one("#y-column", Input).value.strip() or None
        return OpenRequest(path, x, y)


class SampleDialog(ModalScreen[str | None]):
    """Playback of many sites: offer a teaching-size sample, or all the sites.

    Dismissed with "sample", "all" or None (cancelled). ``all_allowed`` False: too many sites
    to play them all (``why`` says so).
    """

    BINDINGS = [
        Binding("s", "choose('sample')", "Sample"),
        Binding("a", "choose('all')", "All"),
        Binding("escape", "choose('')", "Cancel"),
    ]

    def __init__(self, n_sites: int, sample_size: int, *, all_allowed: bool = True, why: str = "") -> None:
        super().__init__()
        self.n_sites = n_sites
        self.sample_size = sample_size
        self.all_allowed = all_allowed
        self.why = why

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = "Playback"
            yield Static(
                f"{self.n_sites:,} sites are more than the eye can follow. A sample of "
                f"{self.sample_size} of them (picked at random, so spread as they are) shows "
                "each step of the engine clearly.",
                id="sample-text",
            )
            with Horizontal(id="sample-buttons"):
                yield Button(f"Sample of {self.sample_size} (s)", variant="primary", compact=True, id="sample")
                yield Button(f"All {self.n_sites:,} (a)", compact=True, id="all", disabled=not self.all_allowed)
            hint = self.why if not self.all_allowed else "Esc to cancel"
            yield Label(hint, id="dialog-hint")

    def on_mount(self) -> None:
        self.query_one("#sample", Button).focus()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.action_choose(event.button.id)

    def action_choose(self, choice: str) -> None:
        if choice == "all" and not self.all_allowed:
            return
        self.dismiss(choice or None)
