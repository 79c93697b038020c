"""The modal screens of the terminal UI: the key help, the path dialog for open, save and export (the
Open dialog browses: a directory tree and path completion), the choice of a table's x and y columns,
and the choice between a sample and all the sites for playback."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.suggester import Suggester
from textual.widgets import Button, DirectoryTree, Input, Label, Select, Static

from tvoronoi.readers import EXTENSIONS

# Entries of the Open dialog's tree listed per folder, at most (a folder of a million files stays quick).
TREE_MAX_ENTRIES = 2000

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


class PathDialog(ModalScreen[Path | None]):
    """Ask for a file path; dismissed with the path, or None when cancelled.

    With ``confirm_overwrite``, a path that exists must be submitted twice.
    """

    BINDINGS = [Binding("escape", "cancel", "Cancel")]

    def __init__(self, title: str, *, value: str = "", placeholder: str = "", confirm_overwrite: bool = False) -> None:
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
        self.accept()

    def accept(self) -> None:
        """Take the path in the field (asking once more before replacing a file, if so told)."""
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


class PathSuggester(Suggester):
    """Completes a path as it is typed: the first entry of its folder that starts with the last part
    (folders end with a slash); the right arrow at the end of the field takes it."""

    def __init__(self) -> None:
        super().__init__(use_cache=False, case_sensitive=True)

    async def get_suggestion(self, value: str) -> str | None:
        return complete_path(value)


def complete_path(value: str) -> str | None:
    """The first completion of a partly typed path, or None (nothing typed, no match, no folder)."""
    if not value:
        return None
    typed = Path(value).expanduser()
    folder, stem = (typed, "") if value.endswith("/") else (typed.parent, typed.name)
    try:
        names = sorted(
            entry.name + ("/" if entry.is_dir() else "")
            for entry in folder.iterdir()
            if entry.name.startswith(stem) and (stem.startswith(".") or not entry.name.startswith("."))
        )
    except OSError:
        return None
    if not names or names[0] == stem:
        return None
    return value + names[0][len(stem) :]


class PointFileTree(DirectoryTree):
    """A directory tree that lists folders and the files tvoronoi reads (by their ending), no hidden ones."""

    def filter_paths(self, paths):
        shown = []
        for path in paths:
            if path.name.startswith("."):
                continue
            try:
                if path.is_dir() or path.suffix.lower() in EXTENSIONS:
                    shown.append(path)
            except OSError:
                continue
            if len(shown) >= TREE_MAX_ENTRIES:
                break
        return shown


class OpenDialog(PathDialog):
    """Ask for a point file and, optionally, which columns of a table hold x and y.

    The path field completes what is typed (right arrow takes the completion); the tree below,
    rooted at ``folder`` (the folder of the last file opened), puts a file chosen there in the field
    (Enter in the tree on a file opens it). Dismissed with an ``OpenRequest``, or None when
    cancelled.
    """

    def __init__(
        self,
        title: str,
        *,
        value: str = "",
        placeholder: str = "",
        x: str | None = None,
        y: str | None = None,
        folder: Path | None = None,
    ) -> None:
        super().__init__(title, value=value, placeholder=placeholder)
        self.x = x
        self.y = y
        self.folder = folder if folder is not None and folder.is_dir() else Path.cwd()

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = self.title_text
            yield Input(self.value, placeholder=self.placeholder, id="path", suggester=PathSuggester())
            yield PointFileTree(self.folder, id="tree")
            with Horizontal(id="columns"):
                yield Label("x column")
                yield Input(self.x or "", placeholder="auto", compact=True, id="x-column")
                yield Label("y column")
                yield Input(self.y or "", placeholder="auto", compact=True, id="y-column")
            yield Label(
                "Enter to open · → completes · Tab: the tree, the columns (a name, an index or colN) · Esc to cancel",
                id="dialog-hint",
            )

    def on_directory_tree_file_selected(self, event: DirectoryTree.FileSelected) -> None:
        """A file chosen in the tree: into the field; chosen again (Enter twice), opened."""
        event.stop()
        field = self.query_one("#path", Input)
        path = str(event.path)
        if field.value == path:
            self.accept()
            return
        field.value = path
        field.cursor_position = len(path)

    def result(self, path: Path) -> OpenRequest:
        x = self.query_one("#x-column", Input).value.strip() or None
        y = self.query_one("#y-column", Input).value.strip() or None
        return OpenRequest(path, x, y)


class ColumnsDialog(ModalScreen[tuple[str, str] | None]):
    """A table whose x and y columns were taken by position among several numeric ones: ask which.

    Dismissed with the (x, y) column names chosen, or None (Esc: keep the reader's choice).
    """

    BINDINGS = [Binding("escape", "keep", "Keep")]

    def __init__(self, source: str, candidates: tuple[str, ...], chosen: tuple[str, str]) -> None:
        super().__init__()
        self.source = source
        self.candidates = candidates
        self.chosen = chosen

    def compose(self) -> ComposeResult:
        options = [(name, name) for name in self.candidates]
        with Vertical(id="dialog") as box:
            box.border_title = "Which columns are x and y?"
            yield Static(
                f"{self.source} has {len(self.candidates)} numeric columns and none is named x/y or "
                f'lon/lat: x = "{self.chosen[0]}" and y = "{self.chosen[1]}" were taken as the first two.',
                id="columns-text",
            )
            with Horizontal(id="columns"):
                yield Label("x column")
                yield Select(options, value=self.chosen[0], allow_blank=False, compact=True, id="x-choice")
                yield Label("y column")
                yield Select(options, value=self.chosen[1], allow_blank=False, compact=True, id="y-choice")
            with Horizontal(id="sample-buttons"):
                yield Button("Use these", variant="primary", compact=True, id="use")
            yield Label("Enter on Use these · Esc keeps the first two", id="dialog-hint")

    def on_mount(self) -> None:
        self.query_one("#x-choice", Select).focus()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        x = str(self.query_one("#x-choice", Select).value)
        y = str(self.query_one("#y-choice", Select).value)
        if x == y:
            self.query_one("#dialog-hint", Label).update("[b $error]x and y must differ[/] · Esc keeps the first two")
            return
        self.dismiss((x, y))

    def action_keep(self) -> None:
        self.dismiss(None)


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
        self.action_choose(event.button.id or "")

    def action_choose(self, choice: str) -> None:
        if choice == "all" and not self.all_allowed:
            return
        self.dismiss(choice or None)
