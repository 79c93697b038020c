"""The UI's controllers without a running App: playback and editing driven through a small fake of the
Protocol each declares (``PlaybackHost``, ``EditingHost``), checked against the engines and traces."""

from types import SimpleNamespace

import numpy as np
import pytest
from shapely.geometry import Polygon

import tvoronoi
from tvoronoi.generators import generate
from tvoronoi.tui import playback
from tvoronoi.tui.building import build
from tvoronoi.tui.canvas import PICK_RADIUS_DOTS
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
from tvoronoi.tui.editing import Editing, EditorReady
from tvoronoi.tui.overlay import fortune_picture, incremental_picture
from tvoronoi.tui.playback import Playback, StepReady
from tvoronoi.tui.raster import View
from tvoronoi.tui.state import fortune_state, incremental_state

COLS, ROWS = 80, 30


class FakeCanvas:
    """What the controllers use of the canvas: the scene and overlay shown, the view, the cursor."""

    def __init__(self, bbox) -> None:
        self.view = View.fit(bbox, COLS, ROWS)
        self.fitted = True
        self.scene = None
        self.overlay = None
        self.editable = True
        self.cursor = None
        self.pointer = None
        self.drag_serial = 0
        self.followed = []
        self.refreshed = 0

    def show_scene(self, scene, *, fit=True, overlay=None) -> None:
        self.scene, self.overlay = scene, overlay

    def adopt_scene(self, scene) -> None:
        self.scene = scene

    def follow(self, box) -> None:
        self.followed.append(box)

    def focus(self) -> None:
        pass

    def refresh(self) -> None:
        self.refreshed += 1

    def set_cursor(self, cursor) -> None:
        self.cursor = cursor

    def site_at(self, x, y):
        return None if self.scene is None else self.scene.site_near(x, y, PICK_RADIUS_DOTS * self.view.scale)


class FakeTimer:
    def __init__(self, callback) -> None:
        self.callback = callback
        self.stopped = False

    def stop(self) -> None:
        self.stopped = True


class FakeHost:
    """The App as a controller sees it: what they call is recorded; workers run at once, their messages
    wait in ``posted`` until the test hands them over."""

    def __init__(self, built) -> None:
        self.built = built
        self.live = None
        self.player = None
        self.canvas = FakeCanvas(built.diagram.bbox)
        self.focused = self.canvas
        self.timeline = SimpleNamespace(
            n_steps=0, engine="", speed=0, playing=False, following=False, display=False, index=0
        )
        self.now = 0.0
        self.clock = lambda: self.now
        self.status = ""
        self.engine_state = None
        self.notes = []
        self.screens = []
        self.posted = []
        self.workers = 0
        self.timers = []
        self.builds = []
        self.events = []

    # what both controllers use
    def set_status(self, text) -> None:
        self.status = text

    def update_status(self) -> None:
        self.events.append("status")

    def notify(self, message, *, title="", severity="information", timeout=None, markup=True) -> None:
        self.notes.append((severity, title, message))

    def push_screen(self, screen, callback) -> None:
        self.screens.append((screen, callback))

    def post_message(self, message) -> bool:
        self.posted.append(message)
        return True

    def run_worker(
        self,
        work,
        name="",
        group="default",
        description="",
        exit_on_error=True,
        start=True,
        exclusive=False,
        thread=False,
    ):
        self.workers += 1
        work()

    def refresh_bindings(self) -> None:
        self.events.append("bindings")

    # playback's
    def set_interval(self, interval, callback):
        self.timers.append(FakeTimer(callback))
        return self.timers[-1]

    def finish_editing(self) -> None:
        self.events.append("finish editing")

    def timeline_on_screen(self) -> bool:
        return True

    def playback_started(self) -> None:
        self.events.append("started")

    def playback_ended(self) -> None:
        self.events.append("ended")

    def set_engine_state(self, text) -> None:
        self.engine_state = text.plain

    # editing's
    def request_build(self, make_points, *, source, size, fit=True, point_set=None, read=None, bbox=None):
        self.builds.append((make_points(), source, size, fit, bbox))


@pytest.fixture
def small():
    """A host showing the diagram of 60 uniform points."""
    return FakeHost(build(generate("uniform", 60, seed=3), "incremental", "test", lambda: 0.0))


def same_picture(canvas, picture) -> bool:
    """The canvas shows the scene and overlay of ``picture`` (made afresh from another trace)."""
    scene, overlay = picture
    if not (np.array_equal(canvas.scene.sites, scene.sites) and np.array_equal(canvas.scene.edges, scene.edges)):
        return False
    fields = [name for name, value in vars(overlay).items() if isinstance(value, np.ndarray)]
    assert fields, "the overlay holds arrays to compare"
    return all(np.array_equal(getattr(canvas.overlay, name), getattr(overlay, name)) for name in fields)


# -- playback ------------------------------------------------------------------


def test_stepping_forward_and_back_shows_the_trace_s_steps(small):
    host = small
    built = host.built
    control = Playback(host)
    control.toggle()
    player = control.player
    assert player is not None and host.events == ["started"]
    assert host.timeline.display and host.timeline.n_steps == player.n_steps == 60
    assert host.canvas.editable is False and len(host.timers) == 1
    # a trace of its own, to check each picture against
    trace = tvoronoi.incremental_steps(built.points, bbox=built.diagram.bbox)
    colours = built.scene.colours
    assert same_picture(host.canvas, incremental_picture(trace.step(0), built.points, colours))
    for _ in range(7):
        control.step(1)
    assert player.index == host.timeline.index == 7
    assert len(host.canvas.scene.sites) == 7  # the sites inserted so far
    assert same_picture(host.canvas, incremental_picture(trace.step(7), built.points, colours))
    assert host.status == trace.step(7).describe()
    assert host.engine_state == incremental_state(trace.step(7)).plain
    control.step(-1)
    assert player.index == 6 and len(host.canvas.scene.sites) == 6
    assert same_picture(host.canvas, incremental_picture(trace.step(6), built.points, colours))
    # back past the start stays at the start; the end is the last step
    for _ in range(10):
        control.step(-1)
    assert player.index == 0
    control.step_to("end")
    assert player.index == player.n_steps
    assert same_picture(host.canvas, incremental_picture(trace.step(60), built.points, colours))


def test_fortune_steps_draw_the_sweep(small):
    host = small
    host.built = build(host.built.points, "fortune", "test", lambda: 0.0)
    built = host.built
    control = Playback(host)
    control.toggle()
    player = control.player
    trace = tvoronoi.fortune_steps(built.points)
    assert player.n_steps == len(trace)
    control.jump(1)
    k = max(1, round(playback.JUMP * len(trace)))
    assert player.index == k
    step = trace.step(k)
    assert same_picture(host.canvas, fortune_picture(step, built.points, built.scene.colours, built.diagram.bbox))
    assert host.engine_state == fortune_state(step, built.points).plain
    # the view followed the event
    assert host.canvas.followed


def test_stopping_gives_back_the_diagram_and_the_view(small):
    host = small
    control = Playback(host)
    view_before = host.canvas.view
    control.toggle()
    host.canvas.view, host.canvas.fitted = host.canvas.view.zoomed(2.0), False
    control.toggle()  # t again stops
    assert control.player is None and host.events == ["started", "ended"]
    assert host.timers[0].stopped and not host.timeline.display
    assert host.canvas.scene is host.built.scene and host.canvas.overlay is None
    assert host.canvas.editable
    # the view that followed the events goes; the user's comes back
    assert host.canvas.view == view_before and host.canvas.fitted


def test_the_clock_moves_playback_on_and_it_stops_at_the_end(small):
    host = small
    control = Playback(host)
    control.clock = host.clock
    control.toggle()
    player = control.player
    tick = host.timers[0].callback
    control.play_pause()
    assert player.playing and host.timeline.playing
    host.now += 0.5
    tick()
    assert player.index == round(0.5 * player.speed)
    control.change_speed(1)
    assert player.speed == host.timeline.speed > playback.DEFAULT_SPEED
    host.now += 100.0
    tick()
    assert player.index == player.n_steps and not player.playing and not host.timeline.playing
    control.play_pause()  # from the end: again from the first step
    assert player.index == 0 and player.playing


def test_a_worker_computes_only_the_latest_step_asked_for(small, monkeypatch):
    monkeypatch.setattr(playback, "STEP_THREAD_MIN_SITES", 10)
    host = small
    built = host.built
    control = Playback(host)
    control.toggle()
    player = control.player
    assert player.threaded and host.workers == 1
    control.step_ready(host.posted.pop())
    assert player.step.index == 0
    control.step(1)  # a worker computes step 1
    for _ in range(4):
        control.step(1)  # asked for while it runs: no other worker
    assert host.workers == 2 and player.index == host.timeline.index == 5
    control.step_ready(host.posted.pop())
    assert player.step.index == 1 and host.workers == 3  # and now step 5
    message = host.posted.pop()
    assert isinstance(message, StepReady) and message.picture[0].index == 5
    control.step_ready(message)
    trace = tvoronoi.incremental_steps(built.points, bbox=built.diagram.bbox)
    assert same_picture(host.canvas, incremental_picture(trace.step(5), built.points, built.scene.colours))
    # a step that arrives after playback ended is dropped
    control.step(1)
    late = host.posted.pop()
    control.stop()
    control.step_ready(late)
    assert host.canvas.scene is built.scene and host.canvas.overlay is None


def test_playback_allows_its_keys_only_while_it_runs(small):
    control = Playback(small)
    assert control.allows("step") is False and control.allows("generate") is None
    assert control.allows("quit") is None
    control.toggle()
    assert control.allows("step") is True and control.allows("toggle_follow") is True
    assert control.allows("generate") is False and control.allows("save") is False
    assert control.allows("toggle_delaunay") is None


def test_many_sites_ask_for_a_sample_first():
    host = FakeHost(
        build(generate("uniform", playback.TEACHING_MAX_SITES + 1, seed=1), "incremental", "test", lambda: 0.0)
    )
    control = Playback(host)
    control.toggle()
    assert control.player is None and len(host.screens) == 1
    _, chosen = host.screens[0]
    chosen("sample")
    player = control.player
    assert player.sample and len(player.points) == playback.SAMPLE_SITES
    # the sample's points are among the diagram's
    rows = {tuple(p) for p in host.built.points.tolist()}
    assert all(tuple(p) in rows for p in player.points.tolist())


# -- editing -------------------------------------------------------------------


def cells_match_a_rebuild(live) -> bool:
    """Every live cell equals the cell of its site in a diagram built from scratch by the engine."""
    fresh = tvoronoi.voronoi(live.points(), engine=live.dynamic.engine, bbox=live.bbox)
    ids = np.flatnonzero(live._alive)
    dynamic = live.dynamic.diagram()
    return all(
        Polygon(dynamic.cell_polygon(i)).symmetric_difference(Polygon(fresh.cell_polygon(row))).area < 1e-12
        for row, i in enumerate(ids.tolist())
    )


def test_adding_a_site_at_the_cursor_updates_the_diagram(small):
    host = small
    control = Editing(host)
    control.add_site()  # the cursor appears at the centre of the view, and a site there
    live = control.live
    assert live is not None and host.canvas.scene is live
    assert host.canvas.cursor == (host.canvas.view.cx, host.canvas.view.cy)
    assert live.n_sites == 61 and np.allclose(live.sites[60], host.canvas.cursor)
    assert control.n_edits == 1 and host.events == ["status"]
    assert cells_match_a_rebuild(live)


def test_moving_a_site_with_the_keys_updates_the_diagram_like_the_engine(small):
    host = small
    control = Editing(host)
    i = 17
    x0, y0 = (float(c) for c in host.built.points[i])
    host.canvas.scene = host.built.scene
    host.canvas.cursor = (x0, y0)
    control.pick_up()
    assert control.moving == (i, (x0, y0)) and host.status.startswith(f"moving site {i}")
    assert control.allows("nudge") is True
    control.nudge(1, 0)
    control.nudge(0, -1)
    live = control.live
    w, h = DOT_COLS * host.canvas.view.scale, DOT_ROWS * host.canvas.view.scale
    assert np.allclose(live.sites[i], (x0 + w, y0 + h))
    assert np.allclose(host.canvas.cursor, (x0 + w, y0 + h))
    assert cells_match_a_rebuild(live)
    # escape puts it back: the diagram is the one built at first
    control.cancel_move()
    assert control.moving is None and np.allclose(live.sites[i], (x0, y0))
    assert control.allows("nudge") is False
    assert cells_match_a_rebuild(live)
    for row in range(len(host.built.points)):
        a = Polygon(live.dynamic.diagram().cell_polygon(row))
        b = Polygon(host.built.diagram.cell_polygon(row))
        assert a.symmetric_difference(b).area < 1e-12


def test_deleting_needs_a_site_under_the_cursor(small):
    host = small
    control = Editing(host)
    host.canvas.scene = host.built.scene
    host.canvas.cursor = (-5.0, -5.0)  # nowhere near a site
    control.remove_site()
    assert control.live is None and host.notes and host.notes[-1][0] == "warning"
    i = 5
    host.canvas.cursor = tuple(float(c) for c in host.built.points[i])
    control.remove_site()
    live = control.live
    assert live.n_sites == 59 and not live.alive(i)
    assert cells_match_a_rebuild(live)


def test_a_refused_edit_changes_nothing_and_says_why(small):
    host = small
    control = Editing(host)
    control.add_site()
    live, version = control.live, control.live.version
    host.canvas.cursor = (1e70, 0.5)  # beyond the range the exact predicates take
    control.add_site()
    assert live.version == version and live.n_sites == 61 and control.n_edits == 1
    severity, title, _ = host.notes[-1]
    assert severity == "error" and title == "Not added"


def test_editing_waits_for_playback_and_a_prepared_editor_is_used(small):
    host = small
    control = Editing(host)
    host.player = object()  # playback runs
    assert control.allows("add_site") is False
    control.add_site_at(0.5, 0.5)
    assert control.live is None
    host.player = None
    assert control.allows("add_site") is True
    control.prepare()  # made ahead in a worker, handed over as a message
    message = host.posted.pop()
    assert isinstance(message, EditorReady) and message.built is host.built
    control.editor_ready(message)
    control.add_site_at(0.25, 0.75)
    assert control.live is message.live and control.live.n_sites == 61


def test_finishing_builds_the_edited_sites_again(small):
    host = small
    control = Editing(host)
    control.add_site_at(0.3, 0.3)
    control.finish()
    points, source, size, fit, bbox = host.builds[-1]
    assert np.array_equal(points, control.live.points()) and size == 61
    assert source == "test (edited)" and fit is False and bbox == control.live.bbox
    control.drop()
    assert control.live is None and control.n_edits == 0
