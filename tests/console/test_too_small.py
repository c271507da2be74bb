"""Issue 35, defect 7: no "too small".  At 60x20 the right column was cut
(sensor status, motor speeds, ``? help``); at 50 columns ``q quit`` was
gone.  Below 80x24 the panels now give way to a notice that says so and
names the keys that matter; the strip stays, and space still stops."""

from __future__ import annotations

import asyncio
from typing import Any

from pilot import ready, until


def test_a_small_terminal_is_told_so_and_a_large_one_shows_the_panels(still_app: Any) -> None:
    async def go() -> None:
        app = still_app()
        async with app.run_test(size=(60, 20)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: app.small_notice.display, "the notice")
            text = str(app.small_notice.render())
            assert "too small: 60x20" in text and "80x24" in text
            assert "space: EMERGENCY STOP" in text and "q: quit" in text
            assert not app.main_area.display
            await pilot.resize_terminal(50, 30)
            await until(pilot, lambda: "too small: 50x30" in str(app.small_notice.render()),
                        "50 columns")
            await pilot.resize_terminal(80, 24)
            await until(pilot, lambda: not app.small_notice.display, "the panels")
            assert app.main_area.display and app.sensors.region.width > 0
            await pilot.press("space")
            await until(pilot, lambda: app.state.view().status.estopped, "the e-stop")
    asyncio.run(go())


def test_the_e_stop_works_on_a_too_small_screen(still_app: Any) -> None:
    async def go() -> None:
        app = still_app()
        async with app.run_test(size=(60, 20)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: app.small_notice.display, "the notice")
            await pilot.press("space")
            await until(pilot, lambda: app.state.view().status.estopped, "the e-stop")
            assert "E-STOP" in app.banner.strip
    asyncio.run(go())
