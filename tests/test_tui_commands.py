"""The command palette lists the app's own actions and runs them."""

import numpy as np
from textual.command import CommandList, CommandPalette

from test_tui import SIZE, make_app, pilot_test
from tvoronoi.relax import lloyd
from tvoronoi.tui.commands import COMMANDS, app_commands


@pilot_test
async def test_every_command_names_an_action_that_exists():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        for _title, _help, target in COMMANDS:
            where, action = target.split(".", 1)
            owner = app if where == "app" else app.canvas
            assert callable(getattr(owner, f"action_{action}", None)), target
        titles = [command.title for command in app_commands(app)]
        assert {"Generate", "Relax", "Delaunay", "Playback", "Fit", "Engine"} <= set(titles)
        assert "Follow" not in titles  # only during playback


@pilot_test
async def test_relax_from_the_palette():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        start, box, engine = app.built.points.copy(), app.built.diagram.bbox, app.built.diagram.engine
        await pilot.press("ctrl+p")
        await pilot.pause()
        assert isinstance(app.screen, CommandPalette)
        await pilot.press(*"relax")
        hits = app.screen.query_one(CommandList)
        for _ in range(100):  # the palette searches in a worker: wait for its hits, not for a set time
            await pilot.pause()
            if hits.option_count and "Relax" in str(hits.get_option_at_index(0).prompt):
                break
        assert "Relax" in str(hits.get_option_at_index(0).prompt)
        await pilot.press("enter")
        await pilot.pause()
        assert np.array_equal(app.built.points, lloyd(start, 1, bbox=box, engine=engine))


@pilot_test
async def test_engine_and_delaunay_from_the_palette():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        before = app.built.diagram.engine
        shown = app.canvas.show_delaunay
        for command in app_commands(app):
            if command.title in ("Engine", "Delaunay"):
                command.callback()
        await pilot.pause()
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert app.built.diagram.engine != before
        assert app.canvas.show_delaunay != shown
