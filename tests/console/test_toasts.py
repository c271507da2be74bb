"""Issue 35, defect 8: toasts covered dialogs and the link panel.  A dialog
clears the toasts shown and takes none while it is up (the event list keeps
each message); toasts sit at the bottom left, over the event list, clear of
the link panel."""

from __future__ import annotations

import asyncio

from pilot import press, ready, said, until
from textual.widgets._toast import Toast

from stairbot.console.app import build_app
from stairbot.console.connect_screen import ConnectScreen


def test_a_dialog_is_never_covered_by_a_toast_nor_the_link_panel_console_defect_8() -> None:
    async def go() -> None:
        app = build_app()
        async with app.run_test(size=(80, 24), notifications=True) as pilot:
            await ready(pilot)
            app.say("before the dialog")
            await until(pilot, lambda: bool(app.screen.query(Toast)), "a toast")
            toast = app.screen.query(Toast).first()
            assert not toast.region.overlaps(app.link.region), (toast.region, app.link.region)
            await press(pilot, "u")  # the robot's URL? (a dialog)
            await until(pilot, lambda: isinstance(app.screen, ConnectScreen), "the dialog")
            await pilot.pause(0.2)
            assert not app.screen.query(Toast) and not app._notifications
            app.say("while it asks")
            await pilot.pause(0.2)
            assert not app.screen.query(Toast) and not app._notifications
            assert "while it asks" in said(app)  # kept in the event list
    asyncio.run(go())


def test_many_toasts_never_cover_the_robot_strip_at_the_top() -> None:
    async def go() -> None:
        app = build_app()
        async with app.run_test(size=(80, 24), notifications=True) as pilot:
            await ready(pilot)
            for n in range(8):  # x pressed again and again: a toast each
                app.say(f"no run is going on ({n})")
            await until(pilot, lambda: len(app.screen.query(Toast)) == 8, "the toasts")
            await pilot.pause(0.3)
            seen = []
            for toast in app.screen.query(Toast):
                try:
                    seen.append(app.screen.find_widget(toast).visible_region)
                except Exception:  # noqa: BLE001 - scrolled out of the rack: not on screen
                    continue
            assert any(region.area for region in seen), "no toast in sight"
            for region in seen:
                assert not region.overlaps(app.banner.region), (region, app.banner.region)
            newest = app.screen.query(Toast).last()
            assert "(7)" in str(newest.render())
    asyncio.run(go())
