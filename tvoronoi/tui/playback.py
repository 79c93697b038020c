"""Step-by-step playback of the selected engine: a trace, a timeline, a timer and the keys that drive them.

Each step is recomputed from the trace (the engine reruns up to it) and drawn
as a picture (tui.overlay). Up to ``STEP_THREAD_MIN_SITES`` sites that takes a few
milliseconds and happens at once; above, a worker computes the latest step
asked for while the timeline already shows it, so neither scrubbing nor fast
playback ever waits on the engine.
"""

from __future__ import annotations

import time
from typing import Any, Callable, Protocol

import numpy as np
from rich.text import Text
from textual.binding import Binding
from textual.message import Message
from textual.screen import Screen
from textual.timer import Timer

import tvoronoi
from tvoronoi.trace import FortuneStep, FortuneTrace, IncrementalStep, IncrementalTrace
from tvoronoi.tui.building import Built
from tvoronoi.tui.colours import cell_colours
from tvoronoi.tui.follow import focus_box
from tvoronoi.tui.host import Host
from tvoronoi.tui.live import LiveScene
from tvoronoi.tui.overlay import FortuneOverlay, IncrementalOverlay, fortune_picture, incremental_picture
from tvoronoi.tui.raster import Scene, View
from tvoronoi.tui.screens import SampleDialog
from tvoronoi.tui.state import fortune_state, incremental_state
from tvoronoi.tui.timeline import Timeline

# Playback refuses larger point sets: a step of Fortune's sweep costs ~2 ms per
# 1,000 sites, and the picture is drawn on every step.
PLAYBACK_MAX_SITES = 20_000
# Above this many sites, playback offers a teaching-size sample first (all the sites stay a choice).
TEACHING_MAX_SITES = 500
SAMPLE_SITES = 30
# From this many sites on, steps are computed in a worker thread.
STEP_THREAD_MIN_SITES = 2_000
# Steps per second to choose from with < and >.
SPEEDS = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1_000, 2_000)
DEFAULT_SPEED = 20
# The timer looks at the clock this often while playing; each tick moves on by
# as many steps as the speed and the time since the last tick give.
TICK_HZ = 30
# [ ] and shift+arrows move by this fraction of the steps.
JUMP = 0.10

BINDINGS = [
    Binding("t", "toggle_playback", "Playback"),
    Binding("space", "play_pause", "Play"),
    Binding("comma", "step(-1)", "Back", key_display=","),
    Binding("full_stop", "step(1)", "Step", key_display="."),
    Binding("home", "step_to('start')", "Start", show=False),
    Binding("end", "step_to('end')", "End", show=False),
    Binding("left_square_bracket,shift+left", "jump(-1)", "-10%", key_display="[", show=False),
    Binding("right_square_bracket,shift+right", "jump(1)", "+10%", key_display="]", show=False),
    # the timeline says whether the view follows, and names f: the footer has no room at 80 columns
    Binding("f", "toggle_follow", "Follow", show=False),
    Binding("less_than_sign", "speed(-1)", "Slower", key_display="<", show=False),
    Binding("greater_than_sign", "speed(1)", "Faster", key_display=">", show=False),
]

HELP = {
    "toggle_playback": "playback: the engine step by step (on / off)",
    "play_pause": "playback: play / pause",
    "step(-1)": "playback: one step back",
    "step(1)": "playback: one step on",
    "step_to('start')": "playback: first step",
    "step_to('end')": "playback: last step",
    "jump(-1)": "playback: back 10% of the steps",
    "jump(1)": "playback: on 10% of the steps",
    "speed(-1)": "playback: slower",
    "speed(1)": "playback: faster",
    "toggle_follow": "playback: the view follows the events (on / off)",
}

# The actions that only make sense during playback, and those that wait until it ends
# (which also leaves room in the footer for the playback keys).
PLAYBACK_ACTIONS = {"play_pause", "step", "step_to", "jump", "speed", "toggle_follow"}
PAUSED_ACTIONS = {"generate", "open", "save", "export"}


Step = FortuneStep | IncrementalStep
# a step, the scene of its sites and the overlay of the engine's state
Picture = tuple[Step, Scene, FortuneOverlay | IncrementalOverlay]


class Player:
    """One playback session: the trace, the step asked for, the step shown, and the pace."""

    def __init__(self, points: np.ndarray, engine: str, colours: np.ndarray, bbox: tuple) -> None:
        self.points = np.asarray(points, np.float64)
        self.engine = engine
        self.colours = colours
        self.bbox = bbox
        self.trace: FortuneTrace | IncrementalTrace = tvoronoi.steps(self.points, engine=engine, bbox=bbox)
        self.n_steps = len(self.trace)
        self.threaded = len(self.points) >= STEP_THREAD_MIN_SITES
        self.index = 0  # the step asked for
        self.step: Step | None = None  # the step on screen
        self.busy = False  # a worker is computing a step
        self.playing = False
        self.speed = DEFAULT_SPEED
        self.carry = 0.0  # steps due but not taken (a fraction)
        self.last_tick: float | None = None
        self.sample = False  # the points are a sample of the diagram's
        # the canvas's view and whether it was fitted, before playback
        self.view_before: tuple[View, bool] | None = None

    def picture(self, k: int) -> Picture:
        """The step k with its scene and overlay (any thread)."""
        step = self.trace.step(k)
        overlay: FortuneOverlay | IncrementalOverlay
        if self.engine == "fortune":
            scene, overlay = fortune_picture(step, self.points, self.colours, self.bbox)
        else:
            scene, overlay = incremental_picture(step, self.points, self.colours)
        return step, scene, overlay


def sample_of(points: np.ndarray, size: int) -> np.ndarray:
    """``size`` of the points picked at random (the same ones for the same points), in their order:
    they are spread as the points are."""
    points = np.asarray(points, np.float64)
    rng = np.random.default_rng(len(points))
    return points[np.sort(rng.choice(len(points), size=min(size, len(points)), replace=False))]


class StepReady(Message):
    """A worker computed a step and its picture."""

    def __init__(self, player: Player, picture: Picture) -> None:
        super().__init__()
        self.player = player
        self.picture = picture


class PlaybackHost(Host, Protocol):
    """What playback uses of the App."""

    @property
    def timeline(self) -> Timeline: ...
    @property
    def built(self) -> Built | None: ...
    @property
    def live(self) -> LiveScene | None: ...
    def finish_editing(self) -> None: ...
    def timeline_on_screen(self) -> bool: ...
    def playback_started(self) -> None: ...
    def playback_ended(self) -> None: ...
    def set_engine_state(self, text: Text) -> None: ...
    def set_status(self, text: str) -> None: ...
    def push_screen(self, screen: Screen[Any], callback: Callable[[Any], None]) -> Any: ...
    def set_interval(self, interval: float, callback: Callable[[], None]) -> Timer: ...


class Playback:
    """Plays an engine step by step: the player, its timer, the timeline and whether the view follows."""

    def __init__(self, host: PlaybackHost) -> None:
        self.host = host
        self.player: Player | None = None
        # the time source of playback (tests put a fake one here)
        self.clock: Callable[[], float] = time.monotonic
        self._timer: Timer | None = None
        # whether the view follows the events (kept from one playback to the next)
        self.follow = True

    def allows(self, action: str) -> bool | None:
        """Whether the app may run ``action`` now as far as playback goes; None: playback has no say."""
        if action in PLAYBACK_ACTIONS:
            return self.player is not None
        if action in PAUSED_ACTIONS and self.player is not None:
            return False
        return None

    # -- starting and stopping -----------------------------------------------

    def toggle(self) -> None:
        """Start playing the selected engine's steps, or stop and show the diagram again."""
        if self.player is not None:
            self.stop()
            return
        built, live = self.host.built, self.host.live
        if built is None:
            return
        n = live.n_sites if live is not None else len(built.points)
        if n > TEACHING_MAX_SITES or n > PLAYBACK_MAX_SITES:
            allowed = n <= PLAYBACK_MAX_SITES
            why = (
                ""
                if allowed
                else (
                    f"Playback takes up to {PLAYBACK_MAX_SITES:,} sites: "
                    "a sample, or generate fewer points · Esc to cancel"
                )
            )
            self.host.push_screen(SampleDialog(n, SAMPLE_SITES, all_allowed=allowed, why=why), self._chosen)
            return
        self.start()

    def _chosen(self, choice: str | None) -> None:
        self.host.canvas.focus()
        if choice is not None and self.player is None:
            self.start(sample=choice == "sample")

    def start(self, *, sample: bool = False) -> None:
        """Play the engine on the sites as they are now, or on a random sample of them."""
        if self.host.live is not None:
            self.host.finish_editing()  # playback replays the sites as they are now
        built = self.host.built
        if built is None:
            return
        engine, bbox = built.diagram.engine, built.diagram.bbox
        if sample:
            points = sample_of(built.points, SAMPLE_SITES)
            colours = cell_colours(tvoronoi.voronoi(points, engine=engine, bbox=bbox))
        else:
            points, colours = built.points, built.scene.colours
        canvas = self.host.canvas
        player = self.player = Player(points, engine, colours, bbox)
        player.sample = sample
        player.view_before = (canvas.view, canvas.fitted)
        timeline = self.host.timeline
        timeline.n_steps = player.n_steps
        timeline.engine = f"{player.engine} sample" if sample else player.engine
        timeline.speed = player.speed
        timeline.playing = False
        timeline.following = self.follow
        timeline.display = True
        canvas.editable = False
        self._timer = self.host.set_interval(1 / TICK_HZ, self.tick)
        self.host.playback_started()
        self.goto(0)

    def stop(self) -> None:
        """Leave playback; the built diagram comes back with the view as it is."""
        if self.player is None:
            return
        player, self.player = self.player, None
        canvas = self.host.canvas
        if self.follow and player.view_before is not None:
            # the view the user had, not the one that followed the last event
            canvas.view, canvas.fitted = player.view_before
        if self._timer is not None:
            self._timer.stop()
            self._timer = None
        self.host.timeline.display = False
        canvas.editable = True
        built = self.host.built
        if built is not None:
            canvas.show_scene(built.scene, fit=False)
        self.host.playback_ended()

    # -- moving along --------------------------------------------------------

    def goto(self, k: int) -> None:
        """Ask for step k (clamped to the trace): shown now, or once a worker has computed it."""
        player = self.player
        if player is None:
            return
        k = min(max(int(k), 0), player.n_steps)
        player.index = k
        self.host.timeline.index = k
        if not player.threaded:
            self._show_picture(player.picture(k))
        elif not player.busy:
            player.busy = True
            self._compute_step(player, k)

    def _compute_step(self, player: Player, k: int) -> None:
        self.host.run_worker(
            lambda: self._step_in_thread(player, k), thread=True, group="playback", exit_on_error=False
        )

    def _step_in_thread(self, player: Player, k: int) -> None:
        self.host.post_message(StepReady(player, player.picture(k)))

    def step_ready(self, message: StepReady) -> None:
        """A worker computed a step: show it, and compute the latest step asked for meanwhile."""
        player = message.player
        if player is not self.player:
            return  # playback stopped meanwhile
        player.busy = False
        self._show_picture(message.picture)
        if message.picture[0].index != player.index:
            # more steps were asked for meanwhile: compute the latest
            player.busy = True
            self._compute_step(player, player.index)

    def _show_picture(self, picture: Picture) -> None:
        player = self.player
        assert player is not None, "a picture is shown during playback"
        step, scene, overlay = picture
        player.step = step
        self.host.canvas.show_scene(scene, fit=False, overlay=overlay)
        if self.follow:
            self._follow_step(player, step)
        if isinstance(step, FortuneStep):
            self.host.set_engine_state(fortune_state(step, player.points))
        else:
            self.host.set_engine_state(incremental_state(step))
        self.host.set_status(step.describe())

    def _follow_step(self, player: Player, step: Step) -> None:
        """Move the view to the region of the step's event, unless it shows it well already."""
        box = focus_box(step, player.points, player.bbox)
        if box is not None:
            self.host.canvas.follow(box)

    def tick(self) -> None:
        """The timer: move on by the steps due since the last tick at the speed chosen."""
        player = self.player
        if player is None or not player.playing:
            return
        if not self.host.timeline_on_screen():
            return  # a dialog is over the timeline, or the app is closing
        now = self.clock()
        if player.last_tick is not None:
            player.carry += (now - player.last_tick) * player.speed
        player.last_tick = now
        due = int(player.carry)
        if due <= 0:
            return
        player.carry -= due
        self.goto(player.index + due)
        if player.index >= player.n_steps:
            self._set_playing(player, False)

    def _set_playing(self, player: Player, playing: bool) -> None:
        player.playing = playing
        player.last_tick = self.clock() if playing else None
        player.carry = 0.0
        self.host.timeline.playing = playing

    # -- what the keys do ------------------------------------------------------

    def play_pause(self) -> None:
        """Play or pause; playing from the last step starts again from the first."""
        player = self.player
        if player is None:
            return
        if not player.playing and player.index >= player.n_steps:
            self.goto(0)
        self._set_playing(player, not player.playing)

    def step(self, delta: int) -> None:
        """One step on or back (pauses)."""
        player = self.player
        if player is None:
            return
        self._set_playing(player, False)
        self.goto(player.index + delta)

    def step_to(self, where: str) -> None:
        """The first or the last step."""
        player = self.player
        if player is None:
            return
        self._set_playing(player, False)
        self.goto(0 if where == "start" else player.n_steps)

    def jump(self, direction: int) -> None:
        """A tenth of the steps on or back."""
        player = self.player
        if player is None:
            return
        self.goto(player.index + direction * max(1, round(JUMP * player.n_steps)))

    def change_speed(self, direction: int) -> None:
        """The next speed up or down."""
        player = self.player
        if player is None:
            return
        at = min(range(len(SPEEDS)), key=lambda i: abs(SPEEDS[i] - player.speed))
        player.speed = SPEEDS[min(max(at + direction, 0), len(SPEEDS) - 1)]
        self.host.timeline.speed = player.speed

    def toggle_follow(self) -> None:
        """Let the view follow the events, or stay where it is."""
        self._set_follow(not self.follow)
        player = self.player
        if self.follow and player is not None and player.step is not None:
            self._follow_step(player, player.step)

    def _set_follow(self, follow: bool) -> None:
        self.follow = follow
        self.host.timeline.following = follow

    def view_changed(self) -> None:
        """The user moved the view: it stays where they put it."""
        if self.player is not None and self.follow:
            self._set_follow(False)
            self.host.notify(
                "the view stays where you put it; f follows the events again", title="Follow off", timeout=4
            )

    def scrubbed(self, step: int) -> None:
        """The timeline was clicked or dragged at ``step``."""
        if self.player is not None:
            self.goto(step)
