"""Issue 35, defect 8: `can://nope`'s message was cut at 80x24 (the banner
holds the strip and four lines of message), the list of allowed interfaces
lost off its end.  A message longer than that ends in "… (whole in the
events)", and the event list holds it whole, once.  At 80x24 the message
keeps one line: more pushed the link panel's lines off the screen."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from pilot import ready, shown, until
from still_robot import HEALTH, StillClock, StillRobot

from stairbot.console.app import build_app
from stairbot.console.roomy import FAULT_LINES
from stairbot.console.widgets.banner import CUT, CUT_SHORT, MESSAGE_LINES
from stairbot.run.robots import RobotSession


@pytest.mark.parametrize("rows", [24, 30])
def test_a_message_too_long_for_the_banner_is_whole_in_the_events_console_defect_8(
        rows: int) -> None:
    async def go() -> None:
        app = build_app(url="can://nope")
        async with app.run_test(size=(80, rows)) as pilot:
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "FAULT" in app.banner.plain, "the refusal")
            await pilot.pause(0.3)
            lines = app.banner.plain.split("\n")
            room = app.banner.room  # a fault's: all four lines, at 80x24 too
            assert room == (MESSAGE_LINES if rows == 30 else FAULT_LINES)
            cut = CUT if room > 1 else CUT_SHORT
            assert len(lines) == 1 + room and lines[-1].endswith(cut), lines
            assert all(len(line) <= app.banner.content_region.width for line in lines)
            message = app.state.view().status.message
            assert "or default" in message and "or default" not in app.banner.plain
            listed = [e.message for _, e in app.state.view().events]
            assert listed.count(message) == 1, listed
    asyncio.run(go())


URL = "serial:///dev/pts/1?baud=1000000"


def test_a_long_message_at_80x24_leaves_the_link_panels_lines_and_live_in_view() -> None:
    """Issue 35's closing note: a 3-4 line message pushed the link panel's
    lines off the bottom of an 80x24 screen."""
    def open_fn(url: str, cfg: Any, scenario: Any, options: Any) -> RobotSession:
        return RobotSession(StillRobot(HEALTH), StillClock(), url, False, None)

    async def go() -> None:
        app = build_app(url=URL, open_fn=open_fn, ages_wall=lambda: 0.0)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            message = "the boards say: " + " ".join(f"word{i}" for i in range(40))
            app.state.set_status(severity="warning", message=message)
            await until(pilot, lambda: app.banner.plain.endswith(CUT_SHORT), "the message cut")
            await pilot.pause(0.3)
            assert app.banner.plain.count("\n") == 1, app.banner.plain
            assert "the boards say: word0 word1" in app.banner.plain
            assert "LIVE" in app.banner.strip and app.banner.region.y == 0
            link = app.link
            assert link.region.bottom <= app.screen.region.height - 1  # over the footer
            text = shown(link)
            assert "fps 1480" in text and "errors 0" in text, text
            listed = [e.message for _, e in app.state.view().events]
            assert listed.count(message) == 1
    asyncio.run(go())
