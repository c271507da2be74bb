"""Issue 35, defect 8: `can://nope`'s message was cut at 80x24 (the banner
holds the strip and four lines of message), the list of allowed interfaces
lost off its end.  A message longer than that ends in "… (whole in the
events)", and the event list holds it whole, once."""

from __future__ import annotations

import asyncio

from pilot import until

from stairbot.console.app import build_app
from stairbot.console.widgets.banner import CUT, MESSAGE_LINES


def test_a_message_too_long_for_the_banner_is_whole_in_the_events_console_defect_8() -> None:
    async def go() -> None:
        app = build_app(url="can://nope")
        async with app.run_test(size=(80, 24)) as pilot:
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "FAULT" in app.banner.plain, "the refusal")
            await pilot.pause(0.3)
            lines = app.banner.plain.split("\n")
            assert len(lines) == 1 + MESSAGE_LINES and lines[-1].endswith(CUT), lines
            assert all(len(line) <= app.banner.content_region.width for line in lines)
            message = app.state.view().status.message
            assert "or default" in message and "or default" not in app.banner.plain
            listed = [e.message for _, e in app.state.view().events]
            assert listed.count(message) == 1, listed
    asyncio.run(go())
