"""Editing in the terminal UI through dynamic updates: add, move and delete sites by mouse and keyboard."""

import json

import numpy as np
import pytest
from shapely.geometry import Point, Polygon
from textual.events import MouseMove
from textual.widgets import Input, Select
from textual.widgets._toast import Toast

import tvoronoi
from test_tui import SIZE, error_toasts, make_app, pilot_test, status_text
from tvoronoi.generators import generate
from tvoronoi.tui.building import build
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
from tvoronoi.tui.editing import make_live
from tvoronoi.tui.raster import rasterize, redraw_part
from tvoronoi.tui.scene import cell_owner
from tvoronoi.tui.viewport import View


def toasts(app) -> list[str]:
    return [toast.render().plain for toast in app.screen.query(Toast)]


async def ready(app, pilot):
    """The app started, its dynamic diagram made ahead."""
    await pilot.pause()
    await app.workers.wait_for_complete()
    await pilot.pause()


def char_of(canvas, x, y) -> tuple[int, int]:
    width, height = canvas.content_size
    u, v = canvas.view.to_dots(x, y, width, height)
    return int(u // DOT_COLS), int(v // DOT_ROWS)


def empty_char(canvas, row: int = 12) -> tuple[int, int]:
    """A character of the canvas, inside the box, with no site under it."""
    width, _ = canvas.content_size
    xmin, _, xmax, _ = canvas.scene.bbox
    for col in range(4, width - 4):
        x, y = canvas.world_at(col, row)
        if xmin < x < xmax and canvas.site_at(x, y) is None:
            return col, row
    raise AssertionError("no empty character")


def site_with_room(canvas, ids) -> int:
    """A site whose character is some way inside the canvas."""
    width, height = canvas.content_size
    for i in ids:
        col, row = char_of(canvas, *canvas.scene.sites[i])
        if 8 <= col < width - 8 and 4 <= row < height - 4 and canvas.site_at(*canvas.world_at(col, row)) == i:
            return int(i)
    raise AssertionError("no site with room around it")


def inside_cell(app, i, x, y) -> bool:
    ring = app.live.dynamic.diagram().cell_polygon(i)
    return Polygon(ring).buffer(1e-12).contains(Point(x, y))


def no_colour_clash(live) -> bool:
    alive = np.flatnonzero(live._alive)
    d = live.dynamic.diagram()
    return all((live.colours[d.neighbours(i)] != live.colours[i]).all() for i in alive.tolist())


@pilot_test
async def test_click_on_empty_space_adds_a_site():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        col, row = empty_char(canvas)
        x, y = canvas.world_at(col, row)
        await pilot.click(canvas, offset=(col, row))
        await pilot.pause()
        live = app.live
        assert live is not None and canvas.scene is live
        assert live.n_sites == 301
        assert np.allclose(live.sites[300], (x, y))
        assert inside_cell(app, 300, x, y)
        assert status_text(app).startswith("301 sites")
        assert no_colour_clash(live)


@pilot_test
async def test_x_deletes_the_site_under_the_pointer():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        i = site_with_room(canvas, range(40, 300))
        await pilot.hover(canvas, offset=char_of(canvas, *canvas.scene.sites[i]))
        await pilot.press("x")
        await pilot.pause()
        assert app.live.n_sites == 299
        assert not app.live.alive(i)
        assert len(app.live.dynamic.diagram().cell_polygon(i)) == 0
        assert status_text(app).startswith("299 sites")
        assert no_colour_clash(app.live)


@pilot_test
async def test_delete_key_with_the_keyboard_cursor():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        i = site_with_room(canvas, range(300))
        canvas.set_cursor(tuple(canvas.scene.sites[i]))
        await pilot.press("delete")
        await pilot.pause()
        assert not app.live.alive(i) and app.live.n_sites == 299


@pilot_test
async def test_x_without_a_site_is_a_warning_and_nothing_changes():
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        canvas.set_cursor(canvas.world_at(*empty_char(canvas)))
        await pilot.press("x")
        await pilot.pause()
        assert app.live is None or app.live.n_sites == 300
        assert any("no site under the cursor" in t for t in toasts(app))


@pilot_test
async def test_dragging_a_site_moves_it_and_its_cell_follows():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        view = canvas.view
        i = site_with_room(canvas, range(300))
        col, row = char_of(canvas, *canvas.scene.sites[i])
        await pilot.mouse_down(canvas, offset=(col, row))
        for step in (1, 2, 3):
            await pilot._post_mouse_events([MouseMove], canvas, offset=(col + 2 * step, row + step), button=1)
        await pilot.mouse_up(canvas, offset=(col + 6, row + 3))
        await pilot.pause()
        x, y = canvas.world_at(col + 6, row + 3)
        assert canvas.view == view  # the view did not pan
        assert app.live.n_sites == 300
        assert np.allclose(app.live.sites[i], (x, y))
        assert inside_cell(app, i, x, y)
        assert no_colour_clash(app.live)


@pilot_test
async def test_dragging_empty_space_still_pans():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        before = canvas.view
        col, row = empty_char(canvas)
        await pilot.mouse_down(canvas, offset=(col, row))
        await pilot._post_mouse_events([MouseMove], canvas, offset=(col + 4, row), button=1)
        await pilot.mouse_up(canvas, offset=(col + 4, row))
        assert canvas.view.cx == pytest.approx(before.cx - 4 * DOT_COLS * before.scale)
        assert app.live is None  # nothing was edited


@pilot_test
async def test_keyboard_cursor_and_a_add_a_site():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        await pilot.press("c")
        assert canvas.cursor == pytest.approx((canvas.view.cx, canvas.view.cy))
        await pilot.press("shift+right", "shift+right", "shift+up")
        scale = canvas.view.scale
        expected = (canvas.view.cx + 2 * DOT_COLS * scale, canvas.view.cy + DOT_ROWS * scale)
        assert canvas.cursor == pytest.approx(expected)
        await pilot.press("a")
        await pilot.pause()
        assert app.live.n_sites == 301
        assert np.allclose(app.live.sites[300], expected)
        await pilot.press("c")
        assert canvas.cursor is None


@pilot_test
async def test_m_and_arrows_move_a_site_enter_drops_it():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        i = site_with_room(canvas, range(300))
        x0, y0 = canvas.scene.sites[i]
        canvas.set_cursor((x0, y0))
        view = canvas.view
        await pilot.press("m", "right", "right", "down", "enter")
        await pilot.pause()
        assert canvas.view == view  # the arrows moved the site, not the view
        scale = view.scale
        expected = (x0 + 2 * DOT_COLS * scale, y0 - DOT_ROWS * scale)
        assert np.allclose(app.live.sites[i], expected)
        assert canvas.cursor == pytest.approx(expected)
        assert inside_cell(app, i, *expected)
        # the move is over: arrows pan again
        await pilot.press("right")
        assert canvas.view.cx > view.cx


@pilot_test
async def test_after_a_large_start_m_and_arrows_move_a_site():
    """Started on 100,000 points (built in a worker), the keys still reach the canvas."""
    app = make_app(points=generate("uniform", 100_000, seed=4))
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        assert canvas.has_focus
        for _ in range(6):  # zoom in until sites have room around them
            await pilot.press("plus")
        inside = canvas.scene.nearest(np.array([[canvas.view.cx, canvas.view.cy]]))
        near = np.argsort(((canvas.scene.sites - canvas.scene.sites[inside[0]]) ** 2).sum(axis=1))[:200]
        i = site_with_room(canvas, near)
        x0, y0 = canvas.scene.sites[i]
        canvas.set_cursor((x0, y0))
        await pilot.press("m", "right", "enter")
        await pilot.pause()
        assert np.allclose(app.live.sites[i], (x0 + DOT_COLS * canvas.view.scale, y0))


@pilot_test
async def test_escape_puts_a_moved_site_back():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        i = site_with_room(canvas, range(300))
        x0, y0 = canvas.scene.sites[i]
        canvas.set_cursor((x0, y0))
        await pilot.press("m", "left", "up", "up", "escape")
        await pilot.pause()
        assert np.allclose(app.live.sites[i], (x0, y0))
        assert app.editing.moving is None


@pilot_test
async def test_a_refused_edit_is_an_error_and_nothing_changes():
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await ready(app, pilot)
        await pilot.press("a")  # make the live scene
        await pilot.pause()
        live = app.live
        version = live.version
        app.canvas.set_cursor((1e70, 0.5))  # beyond the range the exact predicates take
        await pilot.press("a")
        await pilot.pause()
        assert live.version == version and live.n_sites == 301
        assert error_toasts(app)


@pilot_test
async def test_editing_is_off_during_playback():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        await pilot.press("t")
        canvas = app.canvas
        await pilot.click(canvas, offset=empty_char(canvas))
        await pilot.press("a")
        await pilot.pause()
        assert app.live is None


@pilot_test
async def test_another_engine_and_playback_start_from_the_edited_sites():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        await pilot.press("a", "a")  # the second lands on the first: a repeated place
        await pilot.press("shift+left", "a")
        await pilot.pause()
        assert app.live.n_sites == 303
        app.query_one("#engine", Select).value = "fortune"
        await pilot.pause()
        assert app.live is None
        assert app.built.diagram.engine == "fortune" and app.built.diagram.n_sites == 303
        assert app.built.source.endswith("(edited)")
        app.canvas.focus()
        await pilot.press("a")
        await pilot.pause()
        await pilot.press("t")
        await pilot.pause()
        assert app.player is not None and len(app.player.points) == 304


@pilot_test
async def test_save_after_edits_writes_the_live_cells(tmp_path):
    path = tmp_path / "cells.geojson"
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        await pilot.click(canvas, offset=empty_char(canvas))
        i = site_with_room(canvas, range(300))
        canvas.set_cursor(tuple(canvas.scene.sites[i]))
        await pilot.press("x", "x")  # the second finds no site there any more
        await pilot.pause()
        assert app.live.n_sites == 300
        await pilot.press("s")
        app.screen.query_one(Input).value = str(path)
        await pilot.press("enter")
        await app.workers.wait_for_complete()
        await pilot.pause()
        features = json.loads(path.read_text())["features"]
        assert len(features) == 300


def assert_frame_is_fresh(canvas):
    """The frame the canvas shows, updated part by part, equals one drawn afresh."""
    width, height = canvas.content_size
    canvas._draw(canvas.content_size)
    fresh = rasterize(
        canvas.scene,
        canvas.view,
        width,
        height,
        delaunay=canvas.show_delaunay,
        vertices=canvas.show_vertices,
        cursor=canvas.cursor,
    )
    shown = canvas._frame
    for name in ("codes", "mark", "fill", "owner"):
        assert np.array_equal(getattr(shown, name), getattr(fresh, name)), name


@pilot_test
async def test_edits_redraw_only_their_part_and_the_frame_stays_right():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await ready(app, pilot)
        canvas = app.canvas
        await pilot.press("d")  # the Delaunay edges too
        canvas._draw(canvas.content_size)
        await pilot.click(canvas, offset=empty_char(canvas))
        await pilot.pause()
        # the first edit kept the frame of the built scene and redrew a part of it
        assert canvas.scene is app.live
        assert_frame_is_fresh(canvas)
        i = site_with_room(canvas, range(300))
        col, row = char_of(canvas, *canvas.scene.sites[i])
        await pilot.mouse_down(canvas, offset=(col, row))
        await pilot._post_mouse_events([MouseMove], canvas, offset=(col + 3, row + 2), button=1)
        await pilot.mouse_up(canvas, offset=(col + 3, row + 2))
        await pilot.pause()
        assert_frame_is_fresh(canvas)
        await pilot.press("c", "shift+left", "a", "x", "shift+down", "shift+down")
        await pilot.pause()
        assert_frame_is_fresh(canvas)


# -- the live scene without a terminal -----------------------------------------------


@pytest.fixture
def live_case():
    built = build(generate("uniform", 400, seed=9), "incremental", "test", lambda: 0.0)
    return built, make_live(built)


def test_live_scene_matches_a_rebuild_after_random_edits(live_case):
    """Cells, owners and frames of the live scene, updated part by part, equal those drawn afresh."""
    built, live = live_case
    cols, rows = 80, 30
    view = View.fit(live.bbox, cols, rows)
    frame = rasterize(live, view, cols, rows, delaunay=True)
    rng = np.random.default_rng(5)
    for k in range(60):
        version = live.version
        alive = np.flatnonzero(live._alive)
        if k % 3 == 0:
            live.insert(*(0.05 + 0.9 * rng.random(2)))
        elif k % 3 == 1:
            live.remove(int(rng.choice(alive)))
        else:
            i = int(rng.choice(alive))
            live.move(i, *np.clip(live.sites[i] + 0.05 * rng.standard_normal(2), 0.01, 0.99))
        ids, box = live.changes_since(version)
        span = view.char_span(box, cols, rows)
        if span is not None:
            c0, r0, c1, r1 = span
            part = view.window(c0, r0, cols, rows)
            owner = live.update_owner(frame.owner[r0:r1, c0:c1], ids, part, c1 - c0, r1 - r0)
            redraw_part(frame, live, view, cols, rows, span, owner=owner, delaunay=True)
    fresh = rasterize(live, view, cols, rows, delaunay=True)
    assert np.array_equal(frame.owner, fresh.owner)
    assert np.array_equal(frame.fill, fresh.fill)
    assert np.array_equal(frame.codes, fresh.codes)
    assert np.array_equal(frame.mark, fresh.mark)
    # the owners are the nearest live sites
    assert np.array_equal(frame.owner, cell_owner(live, view, cols, rows))
    # and the cells are those of a diagram built from scratch
    d = tvoronoi.voronoi(live.points(), bbox=live.bbox)
    ids = np.flatnonzero(live._alive)
    for row, i in enumerate(ids.tolist()[:50]):
        a = Polygon(live.dynamic.diagram().cell_polygon(i))
        b = Polygon(d.cell_polygon(row))
        assert a.symmetric_difference(b).area < 1e-12
    assert no_colour_clash(live)


def test_neighbours_keep_their_colours(live_case):
    """An insertion recolours at most the cells that now touch their own colour."""
    _, live = live_case
    before = live.colours.copy()
    i = live.insert(0.5, 0.5)
    changed = set(np.asarray(live.dynamic.changed).tolist()) | {i}
    differ = set(np.flatnonzero(live.colours[: len(before)] != before).tolist())
    assert differ <= changed
    assert live.colours[i] >= 0
    assert no_colour_clash(live)


def test_nearest_after_edits_measures_a_few_points_without_the_tree(live_case):
    """After an edit, a few points (the inspector's) are matched to their nearest live cell owner
    without rebuilding the k-d tree; the answers are those of a fresh tree and of brute force."""
    from scipy.spatial import cKDTree

    _, live = live_case
    rng = np.random.default_rng(11)
    for k in range(6):
        live.insert(*(0.05 + 0.9 * rng.random(2)))
        if k % 2:
            live.remove(int(rng.choice(np.flatnonzero(live._alive))))
        points = rng.random((5, 2))
        got = live.nearest(points)
        assert live._tree is None
        ids = live.drawn()
        _, k_tree = cKDTree(live.sites[ids]).query(points)
        assert np.array_equal(got, ids[k_tree])
        d2 = ((live.sites[ids][None, :, :] - points[:, None, :]) ** 2).sum(axis=2)
        assert np.array_equal(got, ids[np.argmin(d2, axis=1)])
    many = rng.random((50, 2))
    assert np.array_equal(live.nearest(many)[:5], live.nearest(many[:5]))
    assert live._tree is not None


def test_edits_far_from_the_view_redraw_nothing(live_case):
    _, live = live_case
    view = View(0.1, 0.1, 0.0005)  # zoomed in near a corner
    version = live.version
    live.insert(0.9, 0.9)
    ids, box = live.changes_since(version)
    assert view.char_span(box, 60, 20) is None


def test_snapshot_editing_with_the_keyboard_cursor(snap_compare):
    """Zoomed in twice, two sites added with the keyboard cursor (a pink cross over darker
    cell colours, the site under it still yellow) and the second one moved one character
    left with m: their cells cut into their neighbours', which keep their colours; the
    status line counts the edits."""
    keys = ["plus", "plus", "c", "shift+right", "shift+right", "a", "shift+up", "shift+up", "a", "m", "left", "enter"]
    assert snap_compare(make_app(), press=keys, terminal_size=SIZE)
