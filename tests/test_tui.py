"""The terminal UI: behaviour through the Textual pilot, looks through snapshots."""

import asyncio
import functools
from pathlib import Path

import numpy as np
import pytest
from textual.events import MouseMove, MouseScrollDown, MouseScrollUp
from textual.widgets import Input, Select
from textual.widgets._toast import Toast

import tvoronoi
from tvoronoi.errors import EngineError
from tvoronoi.generators import generate
from tvoronoi.tui.app import VoronoiApp
from tvoronoi.tui.screens import HelpScreen, PathDialog
from tvoronoi.tui.viewport import View

SIZE = (100, 40)
CITIES = Path(__file__).resolve().parent.parent / "data" / "cities.csv"


def pilot_test(test):
    """Run an async test body in its own event loop (no async plugin needed)."""

    @functools.wraps(test)
    def run(*args, **kwargs):
        asyncio.run(test(*args, **kwargs))

    return run


def fixed_clock() -> float:
    """A clock that never moves: the status line always says 0 ms."""
    return 0.0


def make_app(**kwargs) -> VoronoiApp:
    return VoronoiApp(clock=fixed_clock, **kwargs)


def error_toasts(app) -> list[str]:
    return [toast.render().plain for toast in app.screen.query(Toast) if toast.has_class("-error")]


def status_text(app) -> str:
    """What the status line says is shown, without where the view is (at its right end)."""
    text = str(app.query_one("#status").render()).rstrip()
    view = app.canvas.describe_view()
    for suffix in (view, view.rsplit(" ", 1)[-1]):
        if text.endswith(suffix):
            return text[: -len(suffix)].rstrip()
    return text


def view_text(app) -> str:
    """Where the status line says the view is."""
    return str(app.query_one("#status").render()).rstrip()[len(status_text(app)) :].strip()


@pilot_test
async def test_starts_with_300_uniform_points():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        assert app.built.diagram.n_sites == 300
        assert app.canvas.scene.n_sites == 300
        assert app.canvas.has_focus
        assert status_text(app).startswith("300 sites · ")
        assert "incremental" in status_text(app)


@pilot_test
async def test_given_points_are_shown():
    points = generate("gaussian", 40, seed=2)
    app = make_app(points=points)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        assert np.array_equal(app.built.diagram.sites, points)


@pilot_test
async def test_keys_pan_zoom_and_fit():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        canvas = app.canvas
        fitted = canvas.view
        await pilot.press("right")
        assert canvas.view.cx > fitted.cx and canvas.view.cy == fitted.cy
        await pilot.press("k")  # up
        assert canvas.view.cy > fitted.cy
        await pilot.press("h", "j")  # back left and down
        assert canvas.view.cx == pytest.approx(fitted.cx)
        assert canvas.view.cy == pytest.approx(fitted.cy)
        await pilot.press("plus")
        assert canvas.view.scale < fitted.scale
        await pilot.press("minus", "minus")
        assert canvas.view.scale > fitted.scale
        assert not canvas.fitted
        await pilot.press("0")
        assert canvas.view == fitted
        assert canvas.fitted


@pilot_test
async def test_mouse_wheel_zooms_about_the_pointer():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        canvas = app.canvas
        width, height = canvas.content_size
        before = canvas.view
        under = before.char_to_world(12, 7, width, height)
        # the pilot's own helper for mouse events, as used by its click()
        await pilot._post_mouse_events([MouseScrollUp], canvas, offset=(12, 7))
        after = canvas.view
        assert after.scale < before.scale
        assert after.char_to_world(12, 7, width, height) == pytest.approx(under)
        await pilot._post_mouse_events([MouseScrollDown], canvas, offset=(12, 7))
        assert canvas.view.scale == pytest.approx(before.scale)


@pilot_test
async def test_dragging_pans():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        canvas = app.canvas
        before = canvas.view
        await pilot.mouse_down(canvas, offset=(20, 10))
        await pilot._post_mouse_events([MouseMove], canvas, offset=(25, 10), button=1)
        await pilot.mouse_up(canvas, offset=(25, 10))
        # dragged 5 characters right: the world moved right, so the centre moved left
        assert canvas.view.cx == pytest.approx(before.cx - 5 * 2 * before.scale)
        assert canvas.view.cy == pytest.approx(before.cy)


@pilot_test
async def test_generate_with_another_count():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        count = app.query_one("#count", Input)
        count.focus()
        count.value = ""
        await pilot.press("5", "0", "0", "enter")
        await pilot.pause()
        assert app.built.diagram.n_sites == 500
        assert status_text(app).startswith("500 sites")


@pilot_test
async def test_generate_button_and_distribution_parameters():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        app.query_one("#distribution", Select).value = "clustered"
        await pilot.pause()
        assert app.query_one("#clusters").parent.display
        assert not app.query_one("#sigma").parent.display
        app.query_one("#clusters", Input).value = "3"
        await pilot.click("#generate")
        await pilot.pause()
        assert app.built.source.startswith("clustered")
        assert "clusters 3" in status_text(app)


@pilot_test
async def test_bad_count_is_a_notification_and_the_diagram_stays():
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        built = app.built
        app.query_one("#count", Input).value = ""
        app.canvas.focus()
        await pilot.press("g")
        await pilot.pause()
        assert app.built is built
        assert any("count" in text for text in error_toasts(app))


def engine_refuses(monkeypatch):
    """Make the fortune engine raise an EngineError."""
    real = tvoronoi.voronoi

    def voronoi(points, *, engine="incremental", **kwargs):
        if engine == "fortune":
            raise EngineError("engine 'fortune' refused the points: use engine='incremental'")
        return real(points, engine=engine, **kwargs)

    monkeypatch.setattr(tvoronoi, "voronoi", voronoi)


async def pick_fortune(app, pilot):
    engine = app.query_one("#engine", Select)
    engine.focus()
    await pilot.press("enter", "down", "enter")  # open the list, pick fortune
    await pilot.pause()
    assert engine.value == "fortune"


@pilot_test
async def test_engine_error_is_a_notification_and_the_diagram_stays(monkeypatch):
    engine_refuses(monkeypatch)
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        built = app.built
        view = app.canvas.view
        await pick_fortune(app, pilot)
        assert app.built is built
        assert app.canvas.scene is built.scene
        assert app.canvas.view == view
        assert any("refused the points" in text for text in error_toasts(app))
        assert "incremental" in status_text(app)


@pilot_test
async def test_engine_selector_rebuilds_the_same_points():
    """With the real API the other engine rebuilds the same sites, and the status line says so."""
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        built = app.built
        await pick_fortune(app, pilot)
        assert app.built is not built and not error_toasts(app)
        assert app.built.diagram.engine == "fortune"
        assert np.array_equal(app.built.diagram.sites, built.diagram.sites)
        assert app.built.diagram.n_vertices == built.diagram.n_vertices
        assert "fortune" in status_text(app)


@pilot_test
async def test_help_opens_and_escape_closes_it():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("question_mark")
        assert isinstance(app.screen, HelpScreen)
        listed = " ".join(f"{keys} {what}" for keys, what in app.screen.keys)
        for key in ("q", "?", "d", "o", "s", "g", "0", "+", "-", "←", "h", "j", "k", "l"):
            assert key in listed.split(), key
        await pilot.press("escape")
        assert not isinstance(app.screen, HelpScreen)


@pilot_test
async def test_delaunay_toggle():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        assert not app.canvas.show_delaunay
        await pilot.press("d")
        assert app.canvas.show_delaunay
        assert "Delaunay" in status_text(app)
        await pilot.press("d")
        assert not app.canvas.show_delaunay


@pilot_test
async def test_q_quits():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("q")
        await pilot.pause()
        assert app.return_code == 0


@pilot_test
async def test_open_a_point_file(tmp_path):
    path = tmp_path / "points.csv"
    path.write_text("x,y\n0,0\n1,0\n0,1\n1,1\n0.5,0.4\n")
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("o")
        assert isinstance(app.screen, PathDialog)
        app.screen.query_one(Input).value = str(path)
        await pilot.press("enter")
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert app.built.diagram.n_sites == 5
        assert app.built.source == "points.csv"


@pilot_test
async def test_a_missing_file_is_a_notification(tmp_path):
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        built = app.built
        await pilot.press("o")
        app.screen.query_one(Input).value = str(tmp_path / "nowhere.csv")
        await pilot.press("enter")
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert app.built is built
        assert any("nowhere.csv" in text for text in error_toasts(app))


@pilot_test
async def test_save_writes_geojson_and_asks_before_replacing(tmp_path):
    import json

    path = tmp_path / "cells.geojson"
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("s")
        assert isinstance(app.screen, PathDialog)
        app.screen.query_one(Input).value = str(path)
        await pilot.press("enter")
        await app.workers.wait_for_complete()
        await pilot.pause()
        features = json.loads(path.read_text())["features"]
        assert len(features) == 300
        # a second save to the same path needs a second Enter
        path.write_text("keep me")
        await pilot.press("s")
        app.screen.query_one(Input).value = str(path)
        await pilot.press("enter")
        assert isinstance(app.screen, PathDialog)
        await pilot.press("escape")
        await pilot.pause()
        assert path.read_text() == "keep me"


@pilot_test
async def test_large_count_builds_in_a_worker():
    app = make_app()
    seen = []
    async with app.run_test(size=SIZE, message_hook=lambda m: seen.append(type(m).__name__)) as pilot:
        await pilot.pause()
        app.query_one("#count", Input).value = "100000"
        app.canvas.focus()
        await pilot.press("g")
        await app.workers.wait_for_complete()
        await pilot.pause()
        # the worker hands its diagram over by message; the loading indicator is gone again
        assert "DiagramReady" in seen
        assert not app.canvas.loading
        assert app.built.diagram.n_sites == 100_000


@pilot_test
async def test_resize_keeps_a_fitted_view_fitted():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.resize_terminal(140, 50)
        await pilot.pause()
        width, height = app.canvas.content_size
        assert app.canvas.view == View.fit(app.canvas.scene.bbox, width, height)


# -- snapshots ---------------------------------------------------------------


def test_snapshot_initial_view(snap_compare):
    """The start: 300 uniform points fitted in the canvas, the side panel on the right,
    the status line and the footer's main keys."""
    assert snap_compare(make_app(), terminal_size=SIZE)


def test_snapshot_zoomed_with_delaunay(snap_compare):
    """Zoomed in twice and panned right once, with the Delaunay triangulation over the cells."""
    assert snap_compare(make_app(), press=["plus", "plus", "right", "d"], terminal_size=SIZE)


def test_snapshot_help_screen(snap_compare):
    """The help screen over the diagram, listing every key and mouse gesture."""
    assert snap_compare(make_app(), press=["question_mark"], terminal_size=SIZE)


def test_snapshot_narrow_terminal(snap_compare):
    """A 60 x 20 terminal: the panel is hidden and the diagram fills the width; the
    inspector's line above the status line says how to inspect a cell."""
    assert snap_compare(make_app(), terminal_size=(60, 20))


def test_snapshot_light_theme_zoomed_in(snap_compare):
    """The light theme, zoomed in three times: pastel fills, dark edges, sites as small
    blocks and the Voronoi vertices marked."""

    async def light(pilot):
        pilot.app.theme = "textual-light"
        await pilot.press("plus", "plus", "plus")

    assert snap_compare(make_app(), run_before=light, terminal_size=SIZE)


# -- focus, status and layout (issue 13's defects) ----------------------------


def footer_keys(app) -> list[str]:
    from textual.widgets._footer import FooterKey

    return [key.key_display for key in app.screen.query(FooterKey)]


def slow_builds(monkeypatch):
    """Make builds in a worker wait until the returned event is set."""
    import threading

    from tvoronoi.tui import building

    release = threading.Event()
    real = building.build

    def build(*args, **kwargs):
        if threading.current_thread() is not threading.main_thread():
            release.wait(10)
        return real(*args, **kwargs)

    monkeypatch.setattr(building, "build", build)
    return release


@pilot_test
async def test_a_large_start_keeps_the_focus_on_the_canvas():
    """Starting on 100,000 points (built in a worker) leaves the keys to the canvas."""
    app = make_app(points=generate("uniform", 100_000, seed=1))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        assert app.canvas.has_focus
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert app.built.diagram.n_sites == 100_000
        assert app.canvas.has_focus
        fitted = app.canvas.view
        await pilot.press("right", "plus")
        assert app.canvas.view.cx > fitted.cx and app.canvas.view.scale < fitted.scale


@pilot_test
async def test_d_during_a_large_build_keeps_the_building_status(monkeypatch):
    release = slow_builds(monkeypatch)
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        app.query_one("#count", Input).value = "100000"
        app.canvas.focus()
        await pilot.press("g")
        assert status_text(app).startswith("building 100,000 sites")
        await pilot.press("d")
        assert app.canvas.show_delaunay
        assert status_text(app).startswith("building 100,000 sites")
        assert app.canvas.has_focus
        release.set()
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert status_text(app).startswith("100,000 sites")
        assert "Delaunay shown" in status_text(app)


@pilot_test
async def test_the_panel_follows_the_terminal_width():
    app = make_app()
    async with app.run_test(size=(70, 20)) as pilot:
        await pilot.pause()
        panel = app.query_one("#panel")
        assert not panel.display
        await pilot.resize_terminal(120, 30)
        await pilot.pause()
        assert panel.display
        await pilot.resize_terminal(60, 20)
        await pilot.pause()
        assert not panel.display
        assert app.canvas.content_size.width == 60
        # p shows it at this width; a resize to a wide terminal decides again
        await pilot.press("p")
        assert panel.display
        await pilot.resize_terminal(120, 30)
        await pilot.pause()
        assert panel.display


@pilot_test
async def test_the_footer_shows_the_canvas_keys_after_a_file_is_opened(tmp_path):
    path = tmp_path / "points.csv"
    path.write_text("x,y\n0,0\n1,0\n0,1\n1,1\n0.5,0.4\n")
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        assert "←" in footer_keys(app)
        await pilot.press("o")
        app.screen.query_one(Input).value = str(path)
        await pilot.press("enter")
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert app.built.source == "points.csv"
        assert app.canvas.has_focus
        assert "←" in footer_keys(app) and "+" in footer_keys(app)


@pilot_test
async def test_enter_in_a_field_hands_the_keys_back_to_the_canvas():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        count = app.query_one("#count", Input)
        count.focus()
        count.value = ""
        await pilot.press("4", "0", "0", "enter")
        await pilot.pause()
        assert app.built.diagram.n_sites == 400
        assert app.canvas.has_focus
        await pilot.press("d")
        assert app.canvas.show_delaunay
        # a bad value keeps the focus in the field, to be fixed
        count.focus()
        count.value = ""
        await pilot.press("x", "enter")
        await pilot.pause()
        assert count.has_focus


@pilot_test
async def test_a_choice_in_a_select_hands_the_keys_back_to_the_canvas():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pick_fortune(app, pilot)
        assert app.canvas.has_focus
        await pilot.press("d")
        assert app.canvas.show_delaunay
        shape = app.query_one("#distribution", Select)
        shape.focus()
        await pilot.press("enter", "down", "enter")
        await pilot.pause()
        assert shape.value == "gaussian"
        assert app.canvas.has_focus


@pilot_test
async def test_tab_shows_which_control_has_the_focus():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        shape = app.query_one("#distribution", Select)
        engine = app.query_one("#engine", Select)
        count = app.query_one("#count", Input)
        seed = app.query_one("#seed", Input)
        await pilot.press("tab")
        assert shape.has_focus
        await pilot.pause()

        def looks(widget):
            label = widget.parent.query_one("Label")
            body = widget.query_one("SelectCurrent") if isinstance(widget, Select) else widget
            return body.styles.background, label.styles.color, label.styles.text_style

        assert looks(shape) != looks(engine)
        await pilot.press("tab")
        await pilot.pause()
        assert count.has_focus
        assert looks(count) != looks(seed)


@pilot_test
async def test_a_file_error_names_the_open_dialogs_column_fields(tmp_path):
    path = tmp_path / "words.csv"
    path.write_text("name,kind\nLisbon,city\nMadrid,city\n")
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        await pilot.press("o")
        app.screen.query_one("#path", Input).value = str(path)
        await pilot.press("enter")
        await app.workers.wait_for_complete()
        await pilot.pause()
        text = " ".join(error_toasts(app))
        assert "words.csv" in text
        assert "--x" not in text and "--y" not in text
        assert "x and y column fields of the Open dialog" in text


@pilot_test
async def test_the_open_dialog_chooses_the_columns(tmp_path):
    path = tmp_path / "table.csv"
    path.write_text("a,b,c\n1,10,100\n2,20,200\n3,30,300\n4,40,250\n")
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("o")
        app.screen.query_one("#path", Input).value = str(path)
        app.screen.query_one("#x-column", Input).value = "c"
        app.screen.query_one("#y-column", Input).value = "a"
        await pilot.press("enter")
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert app.built.diagram.sites.tolist() == [[100, 1], [200, 2], [300, 3], [250, 4]]
        # the dialog offers the same file and columns again
        await pilot.press("o")
        assert app.screen.query_one("#path", Input).value == str(path)
        assert app.screen.query_one("#x-column", Input).value == "c"


def footer_fits(app, width: int) -> bool:
    from textual.widgets._footer import FooterKey

    keys = list(app.screen.query(FooterKey))
    return bool(keys) and max(key.region.right for key in keys) <= width


@pilot_test
async def test_the_footer_fits_80_columns_in_every_mode():
    app = make_app()
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        assert footer_fits(app, 80)
        assert {"←", "+", "?", "d", "g", "t"} <= set(footer_keys(app))
        await pilot.press("t")
        await pilot.pause()
        assert footer_fits(app, 80)
        assert {"?", "t", "space", ",", "."} <= set(footer_keys(app))


@pilot_test
async def test_no_color_draws_no_fills_and_sites_stand_out(monkeypatch):
    """With NO_COLOR the cells are not filled (their greys would look alike) and every
    site is a bold block of dots in the brightest colour."""
    from tvoronoi.tui.colours import PLAIN_DARK
    from tvoronoi.tui.layers import SITE

    monkeypatch.setenv("NO_COLOR", "1")
    app = make_app(points=generate("uniform", 300, seed=0))
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        canvas = app.canvas
        assert canvas.palette() is PLAIN_DARK
        canvas.render_line(0)
        frame = canvas._frame
        styles = {seg.style for line in canvas._lines for seg in line}
        assert all(style.bgcolor is None for style in styles)
        sites = frame.mark == SITE
        assert sites.sum() > 100
        # a block: at least 4 of the 8 dots of a site's character are set
        assert (np.unpackbits(frame.codes[sites][:, None], axis=1).sum(axis=1) >= 4).mean() > 0.9
        assert footer_fits(app, 80)


def test_sixteen_colours_draw_no_fills():
    from types import SimpleNamespace

    from tvoronoi.tui.canvas import plain_terminal

    def app(no_color=False, system="truecolor", headless=False):
        return SimpleNamespace(no_color=no_color, is_headless=headless, console=SimpleNamespace(color_system=system))

    assert plain_terminal(app(system="standard"))
    assert plain_terminal(app(system="windows"))
    assert plain_terminal(app(no_color=True))
    assert not plain_terminal(app(system="256"))
    assert not plain_terminal(app(system="truecolor"))
    # tests and snapshots draw in full colour whatever TERM says
    assert not plain_terminal(app(system="standard", headless=True))


def test_snapshot_no_color_80x24(snap_compare, monkeypatch):
    """NO_COLOR at 80 x 24 (greys only): no cell fills, grey edges, the sites as bright bold
    blocks, the panel beside them (too short for the inspector, whose line sits above the
    status line), and the footer's keys all within the 80 columns."""
    monkeypatch.setenv("NO_COLOR", "1")
    assert snap_compare(make_app(), terminal_size=(80, 24))


@pilot_test
async def test_the_status_line_shows_where_the_view_is_and_its_zoom():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()

        def shown() -> str:
            return view_text(app)

        view = app.canvas.view
        assert shown() == f"({view.cx:.3f}, {view.cy:.3f}) ×1"
        await pilot.press("plus")
        assert shown().endswith("×1.25")
        await pilot.press("right")
        assert shown().startswith(f"({app.canvas.view.cx:.3f}, ")
        assert app.canvas.view.cx > view.cx
        # zoomed far in, the coordinates get the digits a character needs
        for _ in range(12):
            await pilot.press("plus")
        assert shown().endswith(f"×{1.25**13:.3g}")
        assert len(shown().split(",")[0]) > len("(0.500")
        await pilot.press("0")
        assert shown() == f"({view.cx:.3f}, {view.cy:.3f}) ×1"


@pilot_test
async def test_a_point_file_given_at_start_is_opened():
    app = make_app(path=CITIES)
    async with app.run_test(size=SIZE) as pilot:
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert app.built.source == "cities.csv"
        assert app.built.diagram.n_sites == len(app.built.point_set)
        assert app.canvas.has_focus
        # the Open dialog offers it again
        await pilot.press("o")
        assert app.screen.query_one("#path", Input).value == str(CITIES)


@pilot_test
async def test_an_unreadable_file_at_start_is_an_error_and_the_default_points_show(tmp_path):
    app = make_app(path=tmp_path / "nowhere.csv")
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert any("nowhere.csv" in text for text in error_toasts(app))
        assert app.built.diagram.n_sites == 300


@pytest.mark.parametrize(
    "name, text, columns",
    [
        ("words.csv", "name,kind\nLisbon,city\n", {}),
        ("bad.csv", "x,y\n0,0\nabc,1\n", {}),
        ("points.geojson", '{"type": "FeatureCollection", "features": []}', {"x": "a", "y": "b"}),
    ],
)
def test_reader_advice_names_the_open_dialogs_fields(tmp_path, name, text, columns):
    from tvoronoi.errors import TvoronoiError
    from tvoronoi.readers import read_points
    from tvoronoi.tui.files import ui_advice

    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(TvoronoiError) as caught:
        read_points(path, **columns)
    assert "--x" in str(caught.value)  # the readers speak to the command line
    message = ui_advice(str(caught.value))
    assert "--x" not in message and "--y" not in message
    assert "column fields" in message


@pilot_test
async def test_choosing_the_option_already_chosen_also_hands_the_keys_back():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        engine = app.query_one("#engine", Select)
        engine.focus()
        await pilot.press("enter", "enter")  # open the list, choose incremental again
        await pilot.pause()
        assert engine.value == "incremental"
        assert app.canvas.has_focus
        # Escape closes the list without a choice: the focus stays in the Select
        engine.focus()
        await pilot.press("enter", "escape")
        await pilot.pause()
        assert engine.has_focus


@pilot_test
async def test_toggling_a_layer_keeps_the_cells_under_the_characters(monkeypatch):
    """Showing the Delaunay edges or moving the view by whole characters gives the frame a fresh
    drawing gives; only a change of view finds the cells under the characters again."""
    from tvoronoi.tui import raster

    calls = []
    real = raster.cell_owner
    monkeypatch.setattr(raster, "cell_owner", lambda *a, **k: (calls.append(1), real(*a, **k))[1])
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        canvas = app.canvas
        for key, finds in (("d", False), ("right", True), ("d", False), ("down", True), ("plus", True)):
            calls.clear()
            await pilot.press(key)
            await pilot.pause()
            frame = canvas._frame
            assert bool(calls) == finds, key
            width, height = canvas.content_size.width, canvas.content_size.height
            fresh = raster.rasterize(
                canvas.scene,
                canvas.view,
                width,
                height,
                delaunay=canvas.show_delaunay,
                vertices=canvas.show_vertices,
                site_blocks=not canvas.palette().filled,
            )
            for a, b in (
                (frame.codes, fresh.codes),
                (frame.mark, fresh.mark),
                (frame.fill, fresh.fill),
                (frame.owner, fresh.owner),
            ):
                assert np.array_equal(a, b), key
