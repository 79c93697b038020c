"""The Relax key: one Lloyd step on the sites shown, as tvoronoi.lloyd computes it."""

import numpy as np
from textual.widgets._toast import Toast

from test_tui import SIZE, make_app, pilot_test, status_text
from tvoronoi.relax import lloyd


def warnings(app) -> list[str]:
    return [toast.render().plain for toast in app.screen.query(Toast) if toast.has_class("-warning")]


@pilot_test
async def test_relax_moves_every_site_to_its_centroid_step_by_step():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        start, box, engine = app.built.points.copy(), app.built.diagram.bbox, app.built.diagram.engine
        await pilot.press("r")
        await pilot.pause()
        one = lloyd(start, 1, bbox=box, engine=engine)
        assert np.array_equal(app.built.points, one)
        assert not np.array_equal(one, start)
        assert "relaxed ×1" in status_text(app)
        await pilot.press("r")
        await pilot.pause()
        assert np.array_equal(app.built.points, lloyd(start, 2, bbox=box, engine=engine))
        assert "relaxed ×2" in status_text(app)
        assert app.built.diagram.bbox == box


@pilot_test
async def test_relax_is_refused_during_playback():
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        before = app.built.points.copy()
        await pilot.press("t")
        await pilot.pause()
        assert app.player is not None
        await pilot.press("r")
        await pilot.pause()
        assert np.array_equal(app.built.points, before)
        assert any("playback" in w for w in warnings(app))


@pilot_test
async def test_relax_after_an_edit_relaxes_the_edited_sites():
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("c")  # the keyboard cursor, then a site added under it
        await pilot.press("a")
        await pilot.pause()
        live = app.live
        assert live is not None
        edited, box = live.points(), live.bbox
        await pilot.press("r")
        await pilot.pause()
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert np.array_equal(app.built.points, lloyd(edited, 1, bbox=box, engine=app.built.diagram.engine))
