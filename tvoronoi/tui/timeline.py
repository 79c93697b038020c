"""The playback timeline: a one-line bar of the steps, with the play state, whether the view follows, and
the speed; click or drag to scrub."""

from __future__ import annotations

from rich.text import Text
from textual.events import MouseDown, MouseMove, MouseUp
from textual.message import Message
from textual.reactive import reactive
from textual.widget import Widget

# Words rather than symbols: the play and pause symbols are wide in some terminals.
PLAYING, PAUSED = "playing", "paused "
DONE, TODO, KNOB = "━", "─", "●"
# Whether the view follows the events, and the key that changes it.
FOLLOWING, FIXED = "f: follow", "f: fixed "


class Timeline(Widget):
    """Shows where playback is among the steps; a click or a drag on the bar asks for a step.

    The bar spans the width between a left label (play state, step, count)
    and a right label (speed); the step under the pointer is proportional to
    its position on the bar, the first and last columns being the first and
    last steps.
    """

    COMPONENT_CLASSES = {"timeline--label", "timeline--done", "timeline--todo"}

    index: reactive[int] = reactive(0)
    n_steps: reactive[int] = reactive(0)
    playing: reactive[bool] = reactive(False)
    speed: reactive[float] = reactive(20.0)
    engine: reactive[str] = reactive("")
    following: reactive[bool] = reactive(False)

    class Scrubbed(Message):
        """The user clicked or dragged on the bar: show ``step``."""

        def __init__(self, step: int) -> None:
            super().__init__()
            self.step = step

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self._scrubbing = False

    # -- geometry ------------------------------------------------------------

    def _labels(self) -> tuple[str, str]:
        digits = len(f"{self.n_steps:,}")
        left = f" {PLAYING if self.playing else PAUSED} {self.engine} {self.index:>{digits},}/{self.n_steps:,} "
        right = f" {FOLLOWING if self.following else FIXED} · {self.speed:g} steps/s "
        return left, right

    def bar_span(self) -> tuple[int, int]:
        """First column and width of the bar."""
        left, right = self._labels()
        width = max(self.content_size.width - len(left) - len(right), 1)
        return len(left), width

    def step_at(self, x: int) -> int:
        """The step under column x of the widget."""
        start, width = self.bar_span()
        if width <= 1:
            return 0
        fraction = min(max((x - start) / (width - 1), 0.0), 1.0)
        return round(fraction * self.n_steps)

    def column_of(self, step: int) -> int:
        """The column of the bar that shows ``step``."""
        start, width = self.bar_span()
        if self.n_steps <= 0:
            return start
        return start + round(step / self.n_steps * (width - 1))

    # -- drawing -------------------------------------------------------------

    def render(self) -> Text:
        left, right = self._labels()
        start, width = self.bar_span()
        knob = self.column_of(self.index) - start
        label = self.get_component_rich_style("timeline--label")
        done = self.get_component_rich_style("timeline--done")
        todo = self.get_component_rich_style("timeline--todo")
        text = Text(no_wrap=True, overflow="crop")
        text.append(left, style=label)
        text.append(DONE * knob, style=done)
        text.append(KNOB, style=done)
        text.append(TODO * max(width - knob - 1, 0), style=todo)
        text.append(right, style=label)
        return text

    # -- mouse ---------------------------------------------------------------

    def _scrub(self, event) -> None:
        offset = event.get_content_offset_capture(self)
        self.post_message(self.Scrubbed(self.step_at(offset.x)))

    def on_mouse_down(self, event: MouseDown) -> None:
        if event.button != 1:
            return
        self._scrubbing = True
        self.capture_mouse()
        self._scrub(event)
        event.stop()

    def on_mouse_move(self, event: MouseMove) -> None:
        if self._scrubbing and event.button:
            self._scrub(event)

    def on_mouse_up(self, event: MouseUp) -> None:
        if self._scrubbing:
            self._scrubbing = False
            self.capture_mouse(False)
