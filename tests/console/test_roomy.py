"""Issue 35, defect 8: in the browser at 1100x640 (about 110x35 cells) about
13 rows of the right column's last panel stayed empty while the event list,
under the picture, was squeezed to the left column's width.  With rows to
spare under the right column the event list now runs the whole width under
both columns, and the right column takes the rows its panels need; at 80x24
the right column runs the whole height as before (console/roomy.py)."""

from __future__ import annotations

import asyncio
from typing import Any

from pilot import ready, until

from stairbot.console.roomy import LOG_MIN_ROWS


def test_rows_to_spare_go_to_the_event_list_not_to_an_empty_panel(still_app: Any) -> None:
    async def go() -> None:
        app = still_app()
        async with app.run_test(size=(110, 35)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: app.main_area.has_class("-roomy"), "roomy")
            await pilot.pause(0.2)
            link, log, picture = app.link.region, app.log_panel.region, app.picture.region
            assert link.height == 1 + app.link.lines_shown  # its title's line and its own
            assert log.width == 110 and log.y >= link.bottom  # under both columns
            assert log.height >= LOG_MIN_ROWS
            assert picture.bottom == log.y  # the picture's row is the right column's
            # smaller again: the right column runs the whole height, the list under the picture
            await pilot.resize_terminal(80, 24)
            await until(pilot, lambda: not app.main_area.has_class("-roomy"), "not roomy")
            await pilot.pause(0.2)
            link, log = app.link.region, app.log_panel.region
            assert log.x == 0 and log.right <= app.sensors.region.x
            assert link.bottom == app.main_area.region.bottom
    asyncio.run(go())
