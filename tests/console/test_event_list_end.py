"""The event list keeps its newest event in view when the screen around it
changes: the e-stop's banner takes two more rows from the list, and the
line the stop wrote must not be the one pushed out of sight.  An operator
who scrolls up to read keeps the place they scrolled to."""

from __future__ import annotations

import asyncio
from typing import Any

from pilot import until
from still_robot import make_still_app, show_climbing

from stairbot.console.app import StairbotConsole
from stairbot.console.robot_holder import LATCH_HINT
from stairbot.console.widgets.event_log import EventLog
from stairbot.events import Event, EventKind


async def listed_to_the_end(pilot: Any, app: StairbotConsole) -> EventLog:
    """The still robot's seven events listed, more than fit, the list at its end."""
    await app.workers.wait_for_complete()
    show_climbing(app)
    log = app.log_panel
    await until(pilot, lambda: log.listed == 7 and log.max_scroll_y > 0,
                "the events listed, more than fit")
    await until(pilot, lambda: log.scroll_y == log.max_scroll_y, "the list at its end")
    return log


def test_the_newest_event_stays_in_view_when_the_banner_grows() -> None:
    async def go() -> None:
        app = make_still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            log = await listed_to_the_end(pilot, app)
            rows = log.scrollable_content_region.height
            # the banner's two rows of the latch hint, with no event written
            app.state.set_status(severity="error", message=LATCH_HINT, estopped=True,
                                 latch="operator")
            await until(pilot, lambda: log.scrollable_content_region.height < rows,
                        "the list shortened by the banner")
            await pilot.pause(0.2)
            assert log.scroll_y == log.max_scroll_y, (log.scroll_y, log.max_scroll_y)

    asyncio.run(go())


def test_an_operator_scrolled_up_keeps_their_place_as_events_come() -> None:
    async def go() -> None:
        app = make_still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            log = await listed_to_the_end(pilot, app)
            log.scroll_home(animate=False)  # as the scroll bar or the wheel does
            await pilot.pause(0.1)
            app.state.on_event(Event(11.0, EventKind.INFO, "a later event"))
            await until(pilot, lambda: log.listed == 8, "the later event listed")
            await pilot.pause(0.2)
            assert log.scroll_y == 0
            log.scroll_end(animate=False)  # back at the end: the list follows again
            await pilot.pause(0.1)
            app.state.on_event(Event(11.5, EventKind.INFO, "one more"))
            await until(pilot, lambda: log.listed == 9, "one more listed")
            await pilot.pause(0.2)
            assert log.scroll_y == log.max_scroll_y

    asyncio.run(go())
