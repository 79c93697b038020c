"""Playback of the engines in the terminal UI: keys, timeline, timer, pictures of steps, snapshots."""

import asyncio
import dataclasses

import numpy as np
import pytest
from textual.widgets import Button, Select
from textual.widgets._toast import Toast

import tvoronoi
from test_tui import SIZE, error_toasts, footer_keys, make_app, pilot_test, status_text
from tvoronoi.generators import generate
from tvoronoi.tui import playback
from tvoronoi.tui.colours import DARK, adjacency_lists, cell_adjacency, repair_colours
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
from tvoronoi.tui.layers import (
    BEACH,
    CIRCLE,
    CONFLICT,
    CONFLICT_FILL,
    EVENT,
    FUTURE,
    SITE,
    SWEEP,
    TINTED,
    WALK,
)
from tvoronoi.tui.overlay import beach_heights, circle_segments, fortune_picture, incremental_picture
from tvoronoi.tui.raster import rasterize
from tvoronoi.tui.scene import Scene
from tvoronoi.tui.screens import SampleDialog
from tvoronoi.tui.styles import frame_lines
from tvoronoi.tui.viewport import View


def warning_toasts(app) -> list[str]:
    return [toast.render().plain for toast in app.screen.query(Toast) if toast.has_class("-warning")]


async def start_playback(app, pilot, engine="incremental"):
    await pilot.pause()
    if engine != app.built.diagram.engine:
        app.query_one("#engine", Select).value = engine
        await pilot.pause()
        app.canvas.focus()
    await pilot.press("t")
    await pilot.pause()
    assert app.player is not None
    return app.player


def expected_describe(app, k: int) -> str:
    """What the step k of a fresh trace of the same points and engine says."""
    built = app.built
    trace = tvoronoi.steps(built.points, engine=built.diagram.engine, bbox=built.diagram.bbox)
    return trace.step(k).describe()


# -- keys --------------------------------------------------------------------


@pilot_test
async def test_t_starts_and_ends_playback():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        assert player.index == 0 and player.n_steps == 300
        assert app.timeline.display
        assert app.timeline.n_steps == 300
        assert status_text(app) == player.step.describe()
        assert app.canvas.overlay is not None
        await pilot.press("t")
        assert app.player is None
        assert not app.timeline.display
        assert app.canvas.scene is app.built.scene and app.canvas.overlay is None
        assert status_text(app).startswith("300 sites")


@pilot_test
async def test_step_keys_move_one_step_and_to_the_ends():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        await pilot.press("full_stop", "full_stop", "full_stop")
        assert player.index == 3 and player.step.index == 3
        await pilot.press("comma")
        assert player.index == 2
        await pilot.press("end")
        assert player.index == player.n_steps
        await pilot.press("full_stop")  # no step beyond the last
        assert player.index == player.n_steps
        await pilot.press("home")
        assert player.index == 0
        await pilot.press("comma")  # none before the first
        assert player.index == 0


@pilot_test
async def test_brackets_and_shift_arrows_move_by_a_tenth():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot, "fortune")
        tenth = round(0.1 * player.n_steps)
        await pilot.press("right_square_bracket")
        assert player.index == tenth
        await pilot.press("shift+right")
        assert player.index == 2 * tenth
        await pilot.press("left_square_bracket", "shift+left", "shift+left")
        assert player.index == 0


@pilot_test
async def test_status_line_says_what_the_step_did():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await start_playback(app, pilot, "fortune")
        for keys in (["full_stop"], ["right_square_bracket"], ["end"]):
            await pilot.press(*keys)
            k = app.player.index
            assert status_text(app) == expected_describe(app, k)
        # the last event of Fortune's sweep is a circle event
        assert status_text(app).startswith("circle event at (")
        assert "vertex" in status_text(app)


@pilot_test
async def test_incremental_status_names_the_inserted_site():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        await pilot.press(*["full_stop"] * 10)
        assert status_text(app) == expected_describe(app, 10)
        assert f"site {player.step.site} inserted at (" in status_text(app)


@pilot_test
async def test_speed_keys_change_the_speed_shown():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        assert player.speed == playback.DEFAULT_SPEED
        await pilot.press("greater_than_sign")
        assert player.speed == 50 and app.timeline.speed == 50
        await pilot.press("less_than_sign", "less_than_sign")
        assert player.speed == 10
        assert "10 steps/s" in app.timeline.render().plain


@pilot_test
async def test_playback_keys_do_nothing_outside_playback():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        scene = app.canvas.scene
        await pilot.press("space", "full_stop", "end", "right_square_bracket")
        assert app.player is None and app.canvas.scene is scene


# -- timeline ------------------------------------------------------------------


@pilot_test
async def test_clicking_the_timeline_scrubs_proportionally():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot, "fortune")
        timeline = app.timeline
        start, width = timeline.bar_span()
        for fraction in (0.0, 0.25, 0.5, 0.8, 1.0):
            x = start + round(fraction * (width - 1))
            await pilot.click(timeline, offset=(x, 0))
            await pilot.pause()
            # within one column's worth of steps of the fraction clicked
            assert abs(player.index - fraction * player.n_steps) <= player.n_steps / (width - 1)
            assert player.index == timeline.step_at(x)
            assert status_text(app) == player.step.describe()
        assert player.index == player.n_steps


@pilot_test
async def test_dragging_on_the_timeline_scrubs():
    from textual.events import MouseMove

    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        timeline = app.timeline
        start, width = timeline.bar_span()
        await pilot.mouse_down(timeline, offset=(start + 2, 0))
        first = player.index
        await pilot._post_mouse_events([MouseMove], timeline, offset=(start + width // 2, 0), button=1)
        await pilot.mouse_up(timeline, offset=(start + width // 2, 0))
        await pilot.pause()
        assert first < player.index == timeline.step_at(start + width // 2)


# -- time ----------------------------------------------------------------------


class FakeClock:
    """The playback clock hook: time moves only when a test moves it; each read (one per timer tick
    while playing) sets ``read``, so a test waits for the next tick instead of sleeping."""

    def __init__(self, now: float) -> None:
        self.now = now
        self.read = asyncio.Event()

    def __call__(self) -> float:
        self.read.set()
        return self.now

    async def next_tick(self, pilot) -> None:
        """Wait until the playback timer has read the clock once more, then until the app is idle."""
        self.read.clear()
        await asyncio.wait_for(self.read.wait(), timeout=10)
        await pilot.pause()


@pilot_test
async def test_playing_advances_with_the_clock():
    app = make_app()
    clock = FakeClock(100.0)
    app.playback.clock = clock
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        await pilot.press("space")
        assert player.playing and app.timeline.playing
        await clock.next_tick(pilot)
        assert player.index == 0  # the clock has not moved
        clock.now += 0.5
        await clock.next_tick(pilot)
        assert player.index == round(0.5 * player.speed)
        clock.now += 100.0  # far past the end: playback stops at the last step
        await clock.next_tick(pilot)
        assert player.index == player.n_steps and not player.playing
        await pilot.press("space")  # playing again from the end starts over
        assert player.index == 0 and player.playing


@pilot_test
async def test_time_spent_paused_does_not_count():
    app = make_app()
    clock = FakeClock(100.0)
    app.playback.clock = clock
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        await pilot.press("space")
        clock.now += 0.5
        await clock.next_tick(pilot)
        paused_at = player.index
        assert paused_at == round(0.5 * player.speed)
        await pilot.press("space")  # pause
        assert not player.playing
        clock.now += 50.0  # a long pause
        await pilot.press("space")  # play on: the pause is not made up for
        await clock.next_tick(pilot)
        assert player.index == paused_at
        clock.now += 0.25  # a binary fraction: the steps due are exact
        await clock.next_tick(pilot)
        assert player.index == paused_at + round(0.25 * player.speed)


@pilot_test
async def test_a_tick_while_closing_is_ignored():
    """The playback timer may tick once more after the app's last screen is gone (the app closing while
    it plays): the tick finds no timeline and does nothing, where it raised ScreenStackError."""
    app = make_app()
    clock = FakeClock(100.0)
    app.playback.clock = clock
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        await pilot.press("space")
        assert player.playing
    assert not app.timeline_on_screen()  # no screen left
    index = player.index
    clock.now += 10.0
    app.playback.tick()
    assert player.index == index


@pilot_test
async def test_playing_advances_in_real_time():
    """Without the hook the clock is the real one: wait (at most 10 s) for the first step, not a set time."""
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        await pilot.press("greater_than_sign", "greater_than_sign")  # 100 steps/s
        await pilot.press("space")
        loop = asyncio.get_running_loop()
        deadline = loop.time() + 10
        while player.index == 0 and loop.time() < deadline:
            await pilot.pause()
        assert player.index > 0
        await pilot.press("space")  # pause before the app closes (its timer would tick on a closing screen)
        assert not player.playing


# -- large point sets ----------------------------------------------------------------


@pilot_test
async def test_too_many_sites_to_play_all_offers_only_the_sample(monkeypatch):
    monkeypatch.setattr(playback, "PLAYBACK_MAX_SITES", 100)
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        await pilot.press("t")
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, SampleDialog)
        assert dialog.query_one("#all", Button).disabled
        assert "up to 100 sites" in str(dialog.query_one("#dialog-hint").render())
        await pilot.press("a")  # not offered: nothing happens
        assert app.screen is dialog and app.player is None
        await pilot.press("escape")
        await pilot.pause()
        assert app.player is None and app.canvas.has_focus
        assert not error_toasts(app)


def many_points():
    return generate("uniform", 800, seed=4)


@pilot_test
async def test_many_sites_offer_a_teaching_sample_of_the_same_points():
    app = make_app(points=many_points())
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("t")
        await pilot.pause()
        assert isinstance(app.screen, SampleDialog) and app.player is None
        await pilot.press("s")
        await pilot.pause()
        player = app.player
        assert player is not None and player.sample and app.canvas.has_focus
        assert len(player.points) == playback.SAMPLE_SITES == player.n_steps
        # a random subset of the points on screen, so spread as they are
        rows = {tuple(p) for p in app.built.points}
        assert all(tuple(p) in rows for p in player.points)
        assert player.points[:, 1].min() < 0.3 and player.points[:, 1].max() > 0.7
        assert "sample" in app.timeline.render().plain
        await pilot.press("end")
        assert app.player.step.diagram.n_sites == playback.SAMPLE_SITES
        await pilot.press("t")  # back to the whole diagram
        assert app.player is None and len(app.canvas.scene.sites) == 800


@pilot_test
async def test_many_sites_can_still_be_played_all():
    app = make_app(points=many_points())
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("t")
        await pilot.pause()
        await pilot.click("#all")
        await pilot.pause()
        assert app.player is not None and not app.player.sample
        assert app.player.n_steps == 800


@pilot_test
async def test_a_few_hundred_sites_play_at_once():
    app = make_app()  # 300 sites: the follow view makes them readable
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("t")
        assert app.player is not None and app.player.n_steps == 300


@pilot_test
async def test_large_point_sets_compute_steps_in_a_worker(monkeypatch):
    monkeypatch.setattr(playback, "STEP_THREAD_MIN_SITES", 100)
    app = make_app()
    seen = []
    async with app.run_test(size=SIZE, message_hook=lambda m: seen.append(type(m).__name__)) as pilot:
        player = await start_playback(app, pilot, "fortune")
        assert player.threaded
        await pilot.press(*["full_stop"] * 5, "right_square_bracket")
        # the timeline already shows the step asked for; the picture follows
        assert app.timeline.index == player.index == 5 + round(0.1 * player.n_steps)
        for _ in range(20):
            await app.workers.wait_for_complete()
            await pilot.pause()
            if player.step.index == player.index:
                break
        assert "StepReady" in seen
        assert player.step.index == player.index
        assert status_text(app) == expected_describe(app, player.index)


@pilot_test
async def test_a_new_diagram_ends_playback():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await start_playback(app, pilot)
        app.query_one("#generate").press()
        await pilot.pause()
        assert app.player is None and not app.timeline.display


# -- pictures ------------------------------------------------------------------


@pytest.fixture(scope="module")
def fortune_case():
    points = generate("uniform", 200, seed=4)
    diagram = tvoronoi.voronoi(points)
    return points, diagram, Scene.from_diagram(diagram)


def test_fortune_picture_draws_the_sweep_state(fortune_case):
    points, diagram, full = fortune_case
    trace = tvoronoi.fortune_steps(points)
    k = next(
        k for k in range(len(trace) // 2, len(trace)) if trace.step(k).kind == "circle" and len(trace.step(k).circles)
    )
    step = trace.step(k)
    scene, overlay = fortune_picture(step, points, full.colours, diagram.bbox)
    # the sites reached and the others
    assert len(scene.sites) + len(overlay.future) == len(points)
    assert (scene.sites[:, 1] <= step.sweep_y).all() and (overlay.future[:, 1] >= step.sweep_y).all()
    view = View.fit(diagram.bbox, 90, 36)
    frame = rasterize(scene, view, 90, 36, overlay=overlay)
    for layer in (BEACH, SWEEP, CIRCLE, FUTURE, EVENT, SITE):
        assert (frame.mark == layer).any(), layer
    # the fill is the finished diagram's, and only below the beach line
    xs = np.linspace(0.05, 0.95, 50)
    heights = beach_heights(step, points, xs)
    assert (heights[np.isfinite(heights)] <= step.sweep_y + 1e-12).all()
    assert (frame.fill >= 0).any() and (frame.fill < 0).any()
    assert len(frame_lines(frame, DARK)) == 36


def test_beach_line_passes_through_the_breakpoints(fortune_case):
    points, _, _ = fortune_case
    trace = tvoronoi.fortune_steps(points)
    step = trace.step(len(trace) // 3)
    bps = step.breakpoints[np.isfinite(step.breakpoints).all(axis=1)]
    heights = beach_heights(step, points, bps[:, 0])
    assert np.allclose(heights, bps[:, 1], rtol=1e-6, atol=1e-9)


def test_circle_outlines_are_round():
    segs = circle_segments([[1.0, 2.0, 0.5]], scale=0.01)
    ends = segs[:, :2]
    assert np.allclose(np.hypot(ends[:, 0] - 1.0, ends[:, 1] - 2.0), 0.5)
    # a side is about a dot and a half long
    assert np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]).max() <= 0.02


def test_incremental_picture_shows_the_conflict_region(fortune_case):
    points, diagram, full = fortune_case
    trace = tvoronoi.incremental_steps(points, bbox=diagram.bbox)
    step = trace.step(120)
    assert len(step.conflict) and len(step.stolen_from)
    scene, overlay = incremental_picture(step, points, full.colours)
    assert len(scene.sites) == 120 and len(overlay.future) == 80
    view = View.fit(diagram.bbox, 90, 36)
    frame = rasterize(scene, view, 90, 36, overlay=overlay)
    assert (frame.mark == CONFLICT).any() and (frame.mark == EVENT).any()
    assert (frame.fill == CONFLICT_FILL).any()
    assert ((frame.fill >= TINTED) & (frame.fill < CONFLICT_FILL)).any()
    # neighbours in the partial diagram still differ in colour
    a, b = cell_adjacency(step.diagram)
    colours = np.full(len(points), -1, np.int8)
    colours[step.inserted] = scene.colours
    assert not (colours[a] == colours[b]).any()


def test_incremental_picture_draws_the_location_walk(fortune_case):
    """The triangles the walk visited are outlined in the walk's colour, along their sides."""
    points, diagram, full = fortune_case
    trace = tvoronoi.incremental_steps(points, bbox=diagram.bbox)
    k = next(k for k in range(60, len(trace)) if len(trace.step(k).walk) >= 4 and (trace.step(k).walk >= 0).all())
    step = trace.step(k)
    scene, overlay = incremental_picture(step, points, full.colours)
    # every side of a visited triangle, each once
    sides = {tuple(sorted((a, b))) for t in step.walk.tolist() for a, b in zip(t, t[1:] + t[:1])}
    assert len(overlay.walk) == len(sides)
    view = View.fit(diagram.bbox, 100, 40)
    frame = rasterize(scene, view, 100, 40, overlay=overlay)
    walked = np.argwhere(frame.mark == WALK)
    assert len(walked) >= 10
    # each character marked lies on a side of the walk (within a character of one)
    centres = np.column_stack(view.to_world((walked[:, 1] + 0.5) * DOT_COLS, (walked[:, 0] + 0.5) * DOT_ROWS, 100, 40))
    a, b = overlay.walk[:, :2], overlay.walk[:, 2:]
    ab = b - a
    t = np.clip(np.einsum("pkd,kd->pk", centres[:, None] - a[None], ab) / np.einsum("kd,kd->k", ab, ab), 0, 1)
    gap = np.linalg.norm(centres[:, None] - (a[None] + t[..., None] * ab[None]), axis=2).min(axis=1)
    assert (gap <= 2.5 * DOT_ROWS * view.scale).all()
    # and without the walk, none is
    bare = rasterize(scene, view, 100, 40, overlay=dataclasses.replace(overlay, walk=np.empty((0, 4))))
    assert not (bare.mark == WALK).any()


def test_the_last_incremental_step_keeps_the_final_colours(fortune_case):
    """At the end of playback the colours are those of the diagram shown before it."""
    points, diagram, full = fortune_case
    trace = tvoronoi.incremental_steps(points, bbox=diagram.bbox)
    scene, _ = incremental_picture(trace.step(len(trace)), points, full.colours)
    assert np.array_equal(scene.colours, full.colours)


def test_repair_colours_changes_only_clashing_cells():
    diagram = tvoronoi.voronoi(generate("uniform", 100, seed=2))
    a, b = cell_adjacency(diagram)
    colours = np.zeros(100, np.int8)  # every cell the same colour
    before = colours.copy()
    neighbours = adjacency_lists(100, a, b)
    repair_colours(colours, neighbours, range(100))
    assert not (colours[a] == colours[b]).any()
    # a valid colouring is left alone
    again = colours.copy()
    repair_colours(again, neighbours, range(100))
    assert np.array_equal(again, colours)
    assert (colours != before).any()


# -- snapshots -----------------------------------------------------------------


def test_snapshot_fortune_step(snap_compare):
    """Fortune's sweep at step 352 of 882: the cells behind the beach line filled, the
    sweep line, the beach line's arcs below it, pending circle events, growing edges
    dashed, the new vertex highlighted, the sites not reached dimmed; the timeline
    and the status line saying what the step did; the panel shows the engine's state. The view
    does not follow (f; the timeline says "f: fixed"): the whole box."""

    async def to_step(pilot):
        pilot.app.query_one("#engine", Select).value = "fortune"
        await pilot.pause()
        pilot.app.canvas.focus()
        await pilot.press("t", "f", *["right_square_bracket"] * 4)

    assert snap_compare(make_app(), run_before=to_step, terminal_size=SIZE)


def test_snapshot_incremental_step(snap_compare):
    """The incremental engine after 150 insertions: the new site highlighted, its conflict
    region (the destroyed Delaunay triangles) outlined and filled, the cells it took
    area from tinted, the sites still to come dimmed; the panel shows the engine's state. The
    view does not follow (f; the timeline says "f: fixed"): the whole box."""
    assert snap_compare(make_app(), press=["t", "f", *["right_square_bracket"] * 5], terminal_size=SIZE)


# -- the view follows the events ---------------------------------------------


def world_box(app):
    """The world box the canvas shows now."""
    width, height = app.canvas.content_size
    x0, y1 = app.canvas.world_at(-0.5, -0.5)
    x1, y0 = app.canvas.world_at(width - 0.5, height - 0.5)
    return x0, y0, x1, y1


def shows(app, x, y) -> bool:
    x0, y0, x1, y1 = world_box(app)
    return x0 <= x <= x1 and y0 <= y <= y1


async def step_until(app, pilot, kind, limit=400):
    """Step on until the step shown is of ``kind`` (Fortune)."""
    for _ in range(limit):
        await pilot.press("full_stop")
        if app.player.step.kind == kind:
            return app.player.step
    raise AssertionError(f"no {kind} event")


@pilot_test
async def test_follow_zooms_to_a_site_event_and_its_arcs():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await start_playback(app, pilot, "fortune")
        assert app.playback.follow and app.timeline.following
        assert "f: follow" in app.timeline.render().plain
        await pilot.press(*["full_stop"] * 40)
        step = await step_until(app, pilot, "site")
        assert app.canvas.zoom() > 1.5  # zoomed in on the event
        assert shows(app, *step.position)
        # the point where it splits the arc it hit is in view too
        k = int(np.flatnonzero(step.beach == step.site)[0])
        assert shows(app, step.position[0], step.breakpoints[k - 1][1])


@pilot_test
async def test_follow_shows_the_whole_circle_of_a_circle_event():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await start_playback(app, pilot, "fortune")
        await pilot.press(*["full_stop"] * 40)
        step = await step_until(app, pilot, "circle")
        vx, vy = step.vertex
        r = step.sweep_y - vy
        for x, y in ((vx - r, vy), (vx + r, vy), (vx, vy - r), (vx, vy + r)):
            assert shows(app, x, y)
        assert app.canvas.zoom() > 1.5


@pilot_test
async def test_follow_shows_the_cavity_of_an_insertion():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        await pilot.press(*["full_stop"] * 150)
        while len(player.step.walk) < 3 and player.step.index < 250:  # a walk across a few triangles
            await pilot.press("full_stop")
        step = player.step
        assert len(step.conflict) and len(step.walk) >= 3
        for x, y in player.points[step.conflict.ravel()]:
            assert shows(app, x, y)
        # and the location walk that found the site
        for x, y in player.points[step.walk[step.walk >= 0]]:
            assert shows(app, x, y)
        assert app.canvas.zoom() > 1.5


@pilot_test
async def test_follow_never_zooms_to_a_point():
    from tvoronoi.tui.follow import MIN_SPACINGS, focus_box

    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot, "fortune")
        for k in range(1, player.n_steps, 37):
            x0, y0, x1, y1 = focus_box(player.trace.step(k), player.points, player.bbox)
            spacing = (1.0 / len(player.points)) ** 0.5  # the unit box, about
            assert min(x1 - x0, y1 - y0) >= 0.9 * MIN_SPACINGS * spacing


@pilot_test
async def test_f_stops_following_and_the_view_stays():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot, "fortune")
        await pilot.press("f")
        assert not app.playback.follow and not app.timeline.following
        assert "f: fixed" in app.timeline.render().plain
        view = app.canvas.view
        await pilot.press(*["full_stop"] * 60)
        assert player.index == 60 and app.canvas.view == view
        step = await step_until(app, pilot, "site")
        assert app.canvas.view == view
        await pilot.press("f")  # on again: straight to the current event
        assert app.playback.follow and app.canvas.zoom() > 1.5 and shows(app, *step.position)


@pilot_test
async def test_panning_during_follow_turns_it_off_and_the_view_stays():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await start_playback(app, pilot, "fortune")
        await pilot.press(*["full_stop"] * 30)
        await pilot.press("minus")
        assert not app.playback.follow
        view = app.canvas.view
        await pilot.press(*["full_stop"] * 30)
        assert app.canvas.view == view


@pilot_test
async def test_leaving_playback_gives_back_the_view_before_it():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("plus")
        view = app.canvas.view
        await start_playback(app, pilot, "fortune")
        await pilot.press(*["full_stop"] * 50)
        assert app.canvas.view != view
        await pilot.press("t")
        assert app.canvas.view == view


# -- the legend and the engine's state in the panel ---------------------------


def legend_shown(app) -> str:
    legend = app.query_one("#legend")
    return str(legend.render()) if legend.display else ""


@pilot_test
async def test_L_shows_the_legend_of_what_is_drawn_and_hides_it():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        assert legend_shown(app) == ""
        assert "L" in footer_keys(app)
        await pilot.press("L")
        for words in ("cells", "Voronoi edges", "sites", "vertices", "Delaunay", "cursor"):
            assert words in legend_shown(app)
        await pilot.press("L")
        assert legend_shown(app) == ""


@pilot_test
async def test_the_legend_follows_playback_of_each_engine():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("L")
        await start_playback(app, pilot)
        for words in ("the new site", "conflict triangles", "new Delaunay edges", "lost area", "sites to come"):
            assert words in legend_shown(app)
        assert "L" not in footer_keys(app)  # the playback keys need the room; L still works
        await pilot.press("t")
        await start_playback(app, pilot, "fortune")
        for words in ("sweep line", "beach line", "circle events", "growing edges", "finished edges", "sites to come"):
            assert words in legend_shown(app)
        await pilot.press("L")
        assert legend_shown(app) == ""
        await pilot.press("t", "L")
        assert "Voronoi edges" in legend_shown(app) and "sweep" not in legend_shown(app)


@pilot_test
async def test_L_on_a_narrow_terminal_shows_the_panel_with_the_legend():
    app = make_app()
    async with app.run_test(size=(60, 20)) as pilot:
        await pilot.pause()
        assert not app.query_one("#panel").display
        await pilot.press("L")
        assert app.query_one("#panel").display and "sites" in legend_shown(app)
        assert app.canvas.has_focus


def engine_state(app) -> str:
    state = app.query_one("#playstate")
    return str(state.render()) if state.display else ""


@pilot_test
async def test_the_panel_shows_fortunes_queue_beach_line_and_counts():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        assert engine_state(app) == ""
        player = await start_playback(app, pilot, "fortune")
        assert not app.query_one("#points-section").display  # new points wait until playback ends
        await pilot.press("right_square_bracket", "right_square_bracket", "right_square_bracket")
        step = player.step
        text = engine_state(app)
        assert "Next events" in text
        assert f"Beach line: {len(step.beach)} arcs" in text
        assert (f"▶ site {step.site}" if step.kind == "site" else f"✕ site {step.site}") in text
        assert f"{len(step.vertices)} vertices" in text
        assert f"{len(step.finished_edges)} edges, {len(step.growing_edges)} growing" in text
        await step_until(app, pilot, "circle")  # the vanished arc is marked where it was
        assert f"✕ site {player.step.site}" in engine_state(app)
        await step_until(app, pilot, "site")
        assert f"▶ site {player.step.site}" in engine_state(app)
        await pilot.press("t")
        assert engine_state(app) == "" and app.query_one("#points-section").display


def test_the_next_events_listed_are_the_events_that_come():
    from tvoronoi.tui.state import next_events

    points = generate("uniform", 200, seed=3)
    trace = tvoronoi.fortune_steps(points)
    for k in range(0, len(trace), 7):
        now, then = trace.step(k), trace.step(k + 1)
        kind, x, y = next_events(now, points)[0]
        assert kind == then.kind
        if kind == "site":
            assert (x, y) == then.position
        else:
            assert x == pytest.approx(then.vertex[0]) and y == pytest.approx(then.sweep_y)


@pilot_test
async def test_the_panel_shows_the_cavity_and_the_cells_that_lost_area():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        player = await start_playback(app, pilot)
        await pilot.press(*["full_stop"] * 150)
        step = player.step
        text = engine_state(app)
        assert f"Site {step.site} inserted" in text and "150 of 300" in text
        assert f"{len(step.conflict)} triangles in conflict" in text
        assert f"Cells that lost area: {len(step.stolen_from)}" in text
        assert str(step.stolen_from[0]) in text
        # the location walk: its length and the triangle it ended in
        assert f"Location walk: {len(step.walk)} triangle" in text
        assert "▶ " + " ".join(str(v) for v in step.walk[-1]) in text


def test_snapshot_legend_of_the_diagram(snap_compare):
    """L pressed on the start view: the panel's Legend section names each colour and mark of the
    diagram (cells, Voronoi edges and the box, sites, vertices, Delaunay edges, the keyboard
    cursor), each beside a swatch in its own colour; the footer names L."""
    assert snap_compare(make_app(), press=["L"], terminal_size=SIZE)


def test_snapshot_fortune_panel_following(snap_compare):
    """Fortune's sweep at step 353 with the view following (the default): zoomed on the
    event's region; the panel's Engine state lists the next events of the queue (site or
    circle, where), the beach line's arcs about the current one (marked ▶) and the vertices
    and edges so far; the timeline says "f: follow"."""

    async def to_step(pilot):
        pilot.app.query_one("#engine", Select).value = "fortune"
        await pilot.pause()
        pilot.app.canvas.focus()
        await pilot.press("t", *["right_square_bracket"] * 4, "full_stop")

    assert snap_compare(make_app(), run_before=to_step, terminal_size=SIZE)


def test_snapshot_incremental_panel_following(snap_compare):
    """The incremental engine after 150 insertions with the view following: zoomed on the new
    site's cavity (the conflict triangles outlined and filled, the cells that lost area
    tinted, the triangles the location walk visited outlined in blue); the panel's Engine state
    names the site, the location walk (its length, its first triangles and the one it ended in),
    the cavity's size, the ids of the cells that lost area and the counts so far."""
    assert snap_compare(make_app(), press=["t", *["right_square_bracket"] * 5], terminal_size=SIZE)


# -- circles far larger than the view -----------------------------------------


def test_a_huge_circle_is_the_arc_that_enters_the_view():
    # the view is the unit square; the circle's top pokes into it from far below
    window = (0.0, 0.0, 1.0, 1.0)
    r = 1e4
    segs = circle_segments([[0.5, 0.5 - r, r]], scale=0.005, window=window)
    assert len(segs)
    ends = np.vstack([segs[:, :2], segs[:, 2:]])
    assert (ends[:, 0] >= -1e-9).all() and (ends[:, 0] <= 1 + 1e-9).all()
    assert (ends[:, 1] >= -1e-9).all() and (ends[:, 1] <= 1 + 1e-9).all()
    # finely divided: each side about a dot and a half, so the arc is not a chord across the view
    assert np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]).max() <= 0.01
    assert np.allclose(np.hypot(ends[:, 0] - 0.5, ends[:, 1] - (0.5 - r)), r, rtol=1e-12)
    # it runs from the left side of the view to the right
    assert ends[:, 0].min() < 0.01 and ends[:, 0].max() > 0.99


def test_circles_outside_the_view_or_around_it_draw_nothing():
    window = (0.0, 0.0, 1.0, 1.0)
    around = [0.5, 0.5, 5.0]  # holds the whole view
    beside = [3.0, 0.5, 1.0]  # wholly to the right
    assert len(circle_segments([around, beside], scale=0.005, window=window)) == 0
    inside = [0.5, 0.5, 0.2]  # drawn whole, as without a window
    assert np.array_equal(circle_segments([inside], 0.005, window), circle_segments([inside], 0.005))


def test_a_circle_event_far_outside_the_box_draws_only_what_the_view_shows():
    from tvoronoi.tui.raster import Painter

    # three sites almost on a line: their circle is huge, its centre far outside the box
    points = np.array([[0.0, 0.0], [0.5, 1e-4], [1.0, 0.0], [0.5, 1.0]])
    trace = tvoronoi.fortune_steps(points)
    step = next(s for s in (trace.step(k) for k in range(len(trace) + 1)) if len(s.circles))
    assert step.circles[:, 2].max() > 100
    view = View.fit((0, 0, 1, 1), 60, 20)
    paint = Painter(view, 60, 20)
    segs = circle_segments(step.circles, view.scale, paint.world)
    x0, y0, x1, y1 = paint.world
    assert len(segs) < 2000
    assert (segs[:, [0, 2]] >= x0 - 1e-9).all() and (segs[:, [0, 2]] <= x1 + 1e-9).all()
    assert (segs[:, [1, 3]] >= y0 - 1e-9).all() and (segs[:, [1, 3]] <= y1 + 1e-9).all()


def test_closing_while_playing_is_quiet(capfd):
    """The app closes in the middle of playback, three times: no tick touches a closing screen (the
    error, raised in a timer, would be printed as the app exits)."""

    async def close_while_playing():
        app = make_app()
        async with app.run_test(size=SIZE) as pilot:
            player = await start_playback(app, pilot)
            await pilot.press("greater_than_sign", "greater_than_sign")
            await pilot.press("space")
            loop = asyncio.get_running_loop()
            deadline = loop.time() + 10
            while player.index == 0 and loop.time() < deadline:
                await pilot.pause()
            assert player.playing
        return app

    for _ in range(3):
        app = asyncio.run(close_while_playing())
        assert app.return_code in (None, 0)
    err = capfd.readouterr().err
    assert "NoMatches" not in err and "Traceback" not in err, err[-2000:]
