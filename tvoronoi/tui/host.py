"""What every UI controller uses of the App: the canvas, notifications, messages and worker threads.

The modules of building, files, playback and editing each declare a Protocol
on top of this one (``BuildingHost``, ``FilesHost``, ``PlaybackHost``,
``EditingHost``) naming the rest of what they use; the inspector, which only
reads, declares its own (``InspectorHost``). The App satisfies them all, and
mypy checks that it does where it makes its controllers.
"""

from __future__ import annotations

from typing import Callable, Protocol

from textual.message import Message
from textual.notifications import SeverityLevel
from textual.worker import Worker

from tvoronoi.tui.canvas import DiagramCanvas


class Host(Protocol):
    """The App's services that every controller may use."""

    @property
    def canvas(self) -> DiagramCanvas: ...

    def notify(
        self,
        message: str,
        *,
        title: str = ...,
        severity: SeverityLevel = ...,
        timeout: float | None = ...,
        markup: bool = ...,
    ) -> None: ...

    def post_message(self, message: Message) -> bool:
        """Hand a message to the App (from any thread)."""
        ...

    def run_worker(
        self,
        work: Callable[[], None],
        name: str | None = ...,
        group: str = ...,
        description: str = ...,
        exit_on_error: bool = ...,
        start: bool = ...,
        exclusive: bool = ...,
        thread: bool = ...,
    ) -> Worker[None]:
        """Run ``work`` in a worker (a thread when ``thread``)."""
        ...
