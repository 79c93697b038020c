"""The inspector of the terminal UI: the cell under the keyboard cursor or the mouse pointer."""

import numpy as np
import pytest
from shapely.geometry import Polygon
from textual.widgets import Input

from test_tui import CITIES, SIZE, make_app, pilot_test
from tvoronoi.tui.inspector import diagram_neighbours, ring_area


async def open_cities(app, pilot):
    await pilot.pause()
    await pilot.press("o")
    app.screen.query_one("#path", Input).value = str(CITIES)
    await pilot.press("enter")
    await app.workers.wait_for_complete()
    await pilot.pause()


def row_of(app, name: str) -> int:
    return app.built.point_set.columns["name"].index(name)


def text_of(app, selector: str) -> str:
    return str(app.query_one(selector).render())


@pilot_test
async def test_the_inspector_names_the_city_under_the_keyboard_cursor():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await open_cities(app, pilot)
        assert app.inspector.inspected is None
        await pilot.press("c")
        i = row_of(app, "Lisbon")
        x, y = app.built.diagram.sites[i]
        app.canvas.set_cursor((float(x), float(y)))
        await pilot.pause()
        info = app.inspector.inspected
        assert info.site == i and info.row == i
        assert info.properties["name"] == "Lisbon"
        assert (info.x, info.y) == (x, y)
        ring = app.built.diagram.cell_polygon(i)
        assert info.area == pytest.approx(Polygon(ring).area)
        assert info.n_neighbours == len(diagram_neighbours(app.built.diagram, i)) > 0
        shown = text_of(app, "#inspector")
        assert "site" in shown and "Lisbon" in shown and "neighbours" in shown
        assert "row" in shown and "cities.csv" in shown
        # the cursor moves one character at a time: the inspector follows it
        await pilot.press("shift+right")
        await pilot.pause()
        assert app.inspector.inspected.site == app.canvas.cell_at(*app.canvas.cursor)
        await pilot.press("c")  # hidden: nothing under it any more
        await pilot.pause()
        assert app.inspector.inspected is None


@pilot_test
async def test_the_inspector_follows_the_mouse_pointer():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        canvas = app.canvas
        await pilot.hover(canvas, offset=(20, 10))
        await pilot.pause()
        x, y = canvas.world_at(20, 10)
        expected = int(np.argmin(((app.built.diagram.sites - (x, y)) ** 2).sum(axis=1)))
        assert app.inspector.inspected.site == expected
        assert app.inspector.inspected.properties == {}
        assert "pointer" in text_of(app, "#inspector")


@pilot_test
async def test_an_added_site_is_inspected_as_added():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await app.workers.wait_for_complete()
        await pilot.press("c", "a")
        await pilot.pause()
        info = app.inspector.inspected
        assert info.site == 300 and info.row is None
        ring = app.live.dynamic.diagram().cell_polygon(300)
        assert info.area == pytest.approx(ring_area(ring))
        assert "added by an edit" in text_of(app, "#inspector")


@pilot_test
async def test_a_short_or_narrow_terminal_shows_the_inspector_in_one_line():
    app = make_app()
    async with app.run_test(size=(80, 24)) as pilot:
        await open_cities(app, pilot)
        line = app.query_one("#inspect-line")
        assert line.display and not app.query_one("#inspector").display
        i = row_of(app, "Madrid")
        await pilot.press("c")
        app.canvas.set_cursor(tuple(float(c) for c in app.built.diagram.sites[i]))
        await pilot.pause()
        assert "Madrid" in text_of(app, "#inspect-line")
        await pilot.resize_terminal(120, 40)
        await pilot.pause()
        assert not line.display and app.query_one("#inspector").display
        assert "Madrid" in text_of(app, "#inspector")


def test_snapshot_inspector_on_a_city(snap_compare):
    """data/cities.csv opened, the keyboard cursor moved onto Paris: the panel's Cell
    section names the site, its row and its columns (name, id), its coordinates, the
    area of its cell and its number of neighbours."""

    async def paris(pilot):
        app = pilot.app
        await open_cities(app, pilot)
        await pilot.press("c")
        i = row_of(app, "Paris")
        app.canvas.set_cursor(tuple(float(c) for c in app.built.diagram.sites[i]))
        await pilot.pause()

    assert snap_compare(make_app(), run_before=paris, terminal_size=SIZE)


def test_snapshot_inspector_line_at_80x24(snap_compare):
    """80 x 24 with data/cities.csv and the keyboard cursor on Rome: the panel has no room
    for the inspector, so one line above the status line names the city and its cell."""

    async def rome(pilot):
        app = pilot.app
        await open_cities(app, pilot)
        await pilot.press("c")
        i = row_of(app, "Rome")
        app.canvas.set_cursor(tuple(float(c) for c in app.built.diagram.sites[i]))
        await pilot.pause()

    assert snap_compare(make_app(), run_before=rome, terminal_size=(80, 24))
