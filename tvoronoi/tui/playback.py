"""Step-by-step playback of the selected engine: a trace, a timeline, a timer and the keys that drive them.

Each step is recomputed from the trace (the engine reruns up to it) and drawn
as a picture (tui.overlay). Up to ``STEP_THREAD_MIN_SITES`` sites that takes a few
milliseconds and happens at once; above, a worker computes the latest step
asked for while the timeline already shows it, so neither scrubbing nor fast
playback ever waits on the engine.
"""

from __future__ import annotations

import time

import numpy as np
from textual import work
from textual.binding import Binding
from textual.message import Message
from textual.widgets import Static

import tvoronoi
from tvoronoi.tui.colours import cell_colours
from tvoronoi.tui.follow import focus_box
from tvoronoi.tui.overlay import fortune_picture, incremental_picture
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


class Player:
    """One playback session: the trace, the step asked for, the step shown, and the pace."""

    def __init__(self, points: np.ndarray, engine: str, colours: np.ndarray, bbox) -> None:
        self.points = np.asarray(points, np.float64)
        self.engine = engine
        self.colours = colours
        self.bbox = bbox
        if engine == "fortune":
            self.trace = tvoronoi.fortune_steps(self.points)
        else:
            self.trace = tvoronoi.incremental_steps(self.points, bbox=bbox)
        self.n_steps = len(self.trace)
        self.threaded = len(self.points) >= STEP_THREAD_MIN_SITES
        self.index = 0          # the step asked for
        self.step = None        # the step on screen
        self.busy = False       # a worker is computing a step
        self.playing = False
        self.speed = DEFAULT_SPEED
        self.carry = 0.0        # steps due but not taken (a fraction)
        self.last_tick: float | None = None
        self.sample = False  # the points are a sample of the diagram's
        self.view_before = None  # the canvas's view and whether it was fitted, before playback

    def picture(self, k: int):
        """The step k with its scene and overlay (any thread)."""
        step = self.trace.step(k)
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

    def __init__(self, player: Player, picture) -> None:
        super().__init__()
        self.player = player
        self.picture = picture


class PlaybackMixin:
    """The App's part that plays an engine step by step."""

    player: Player | None = None
    # the time source of playback (tests put a fake one here)
    playback_clock = staticmethod(time.monotonic)
    _play_timer = None
    # whether the view follows the events (kept from one playback to the next)
    follow = True

    @property
    def timeline(self) -> Timeline:
        return self.query_one("#timeline", Timeline)

    def check_action(self, action: str, parameters: tuple) -> bool | None:
        if action in PLAYBACK_ACTIONS:
            return self.player is not None
        if action in PAUSED_ACTIONS and self.player is not None:
            return False
        return super().check_action(action, parameters)

    # -- starting and stopping -----------------------------------------------

    def action_toggle_playback(self) -> None:
        """Start playing the selected engine's steps, or stop and show the diagram again."""
        if self.player is not None:
            self.stop_playback()
            return
        if self.built is None:
            return
        n = self.live.n_sites if self.live is not None else len(self.built.points)
        if n > TEACHING_MAX_SITES or n > PLAYBACK_MAX_SITES:
            allowed = n <= PLAYBACK_MAX_SITES
            why = "" if allowed else (f"Playback takes up to {PLAYBACK_MAX_SITES:,} sites: "
                                      "a sample, or generate fewer points · Esc to cancel")
            self.push_screen(SampleDialog(n, SAMPLE_SITES, all_allowed=allowed, why=why), self._playback_chosen)
            return
        self._start_playback()

    def _playback_chosen(self, choice: str | None) -> None:
        self.canvas.focus()
        if choice is not None and self.player is None:
            self._start_playback(sample=choice == "sample")

    def _start_playback(self, *, sample: bool = False) -> None:
        """Play the engine on the sites as they are now, or on a random sample of them."""
        if self.live is not None:
            self.finish_editing()  # playback replays the sites as they are now
        built = self.built
        engine, bbox = built.diagram.engine, built.diagram.bbox
        if sample:
            points = sample_of(built.points, SAMPLE_SITES)
            colours = cell_colours(tvoronoi.voronoi(points, engine=engine, bbox=bbox))
        else:
            points, colours = built.points, built.scene.colours
        self.player = Player(points, engine, colours, bbox)
        self.player.sample = sample
        self.player.view_before = (self.canvas.view, self.canvas.fitted)
        timeline = self.timeline
        timeline.n_steps = self.player.n_steps
        timeline.engine = f"{self.player.engine} sample" if sample else self.player.engine
        timeline.speed = self.player.speed
        timeline.playing = False
        timeline.following = self.follow
        timeline.display = True
        self.canvas.editable = False
        self._play_timer = self.set_interval(1 / TICK_HZ, self._playback_tick)
        self.refresh_bindings()
        self.inspect()  # hidden during playback
        self._show_engine_state(True)
        self.update_legend()
        self._goto(0)

    def stop_playback(self) -> None:
        """Leave playback; the built diagram comes back with the view as it is."""
        if self.player is None:
            return
        player, self.player = self.player, None
        if self.follow:
            # the view the user had, not the one that followed the last event
            self.canvas.view, self.canvas.fitted = player.view_before
        if self._play_timer is not None:
            self._play_timer.stop()
            self._play_timer = None
        self.timeline.display = False
        self._show_engine_state(False)
        self.canvas.editable = True
        if self.built is not None:
            self.canvas.show_scene(self.built.scene, fit=False)
        self.refresh_bindings()
        self._update_status()

    # -- moving along --------------------------------------------------------

    def _goto(self, k: int) -> None:
        player = self.player
        k = min(max(int(k), 0), player.n_steps)
        player.index = k
        self.timeline.index = k
        if not player.threaded:
            self._show_picture(player.picture(k))
        elif not player.busy:
            player.busy = True
            self._compute_step(player, k)

    @work(thread=True, group="playback", exit_on_error=False)
    def _compute_step(self, player: Player, k: int) -> None:
        self.post_message(StepReady(player, player.picture(k)))

    def on_step_ready(self, message: StepReady) -> None:
        player = message.player
        if player is not self.player:
            return  # playback stopped meanwhile
        player.busy = False
        self._show_picture(message.picture)
        if message.picture[0].index != player.index:
            # more steps were asked for meanwhile: compute the latest
            player.busy = True
            self._compute_step(player, player.index)

    def _show_picture(self, picture) -> None:
        step, scene, overlay = picture
        self.player.step = step
        self.canvas.show_scene(scene, fit=False, overlay=overlay)
        if self.follow:
            self._follow_step(step)
        state = self.query_one("#playstate", Static)
        if self.player.engine == "fortune":
            state.update(fortune_state(step, self.player.points))
        else:
            state.update(incremental_state(step))
        self._set_status(step.describe())

    def _show_engine_state(self, shown: bool) -> None:
        """During playback the panel shows the engine's state where the point controls were
        (new points wait until playback ends)."""
        self.query_one("#points-section").display = not shown
        for widget in self.query(".playstate"):
            widget.display = shown

    def _follow_step(self, step) -> None:
        """Move the view to the region of the step's event, unless it shows it well already."""
        player = self.player
        box = focus_box(step, player.points, player.bbox)
        if box is not None:
            self.canvas.follow(box)

    def _playback_tick(self) -> None:
        player = self.player
        if player is None or not player.playing:
            return
        if not self.screen.query("#timeline"):
            return              # the app is closing: its widgets are gone, and the timer with them next
        now = self.playback_clock()
        if player.last_tick is not None:
            player.carry += (now - player.last_tick) * player.speed
        player.last_tick = now
        due = int(player.carry)
        if due <= 0:
            return
        player.carry -= due
        self._goto(player.index + due)
        if player.index >= player.n_steps:
            self._set_playing(False)

    def _set_playing(self, playing: bool) -> None:
        player = self.player
        player.playing = playing
        player.last_tick = self.playback_clock() if playing else None
        player.carry = 0.0
        self.timeline.playing = playing

    # -- actions -------------------------------------------------------------

    def action_play_pause(self) -> None:
        """Play or pause; playing from the last step starts again from the first."""
        player = self.player
        if not player.playing and player.index >= player.n_steps:
            self._goto(0)
        self._set_playing(not player.playing)

    def action_step(self, delta: int) -> None:
        """One step on or back (pauses)."""
        self._set_playing(False)
        self._goto(self.player.index + delta)

    def action_step_to(self, where: str) -> None:
        """The first or the last step."""
        self._set_playing(False)
        self._goto(0 if where == "start" else self.player.n_steps)

    def action_jump(self, direction: int) -> None:
        """A tenth of the steps on or back."""
        player = self.player
        self._goto(player.index + direction * max(1, round(JUMP * player.n_steps)))

    def action_speed(self, direction: int) -> None:
        """The next speed up or down."""
        player = self.player
        at = min(range(len(SPEEDS)), key=lambda i: abs(SPEEDS[i] - player.speed))
        player.speed = SPEEDS[min(max(at + direction, 0), len(SPEEDS) - 1)]
        self.timeline.speed = player.speed

    def action_toggle_follow(self) -> None:
        """Let the view follow the events, or stay where it is."""
        self._set_follow(not self.follow)
        if self.follow and self.player.step is not None:
            self._follow_step(self.player.step)

    def _set_follow(self, follow: bool) -> None:
        self.follow = follow
        self.timeline.following = follow

    def on_diagram_canvas_view_changed(self) -> None:
        # the user moved the view: it stays where they put it
        if self.player is not None and self.follow:
            self._set_follow(False)
            self.notify("the view stays where you put it; f follows the events again",
                        title="Follow off", timeout=4)

    def on_timeline_scrubbed(self, message: Timeline.Scrubbed) -> None:
        if self.player is not None:
            self._goto(message.step)
