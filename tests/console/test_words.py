"""Issue 12 item 5, "it speaks code": operator words first, the seed's names
beside them; a help screen (`?`); at 80x24 and wider nothing an operator
needs is cut -- the banner is not covered, the footer is on screen with the
keys that matter.  (Lift arrows: tests/console/test_canvas_scene.py.)"""

from __future__ import annotations

import asyncio

import pytest
from pilot import press, ready, shown, until
from still_robot import make_still_app, show_climbing
from textual.geometry import Region
from textual.widgets import Footer, Static
from textual.widgets._footer import FooterKey

from stairbot.console.help import HelpScreen


def lines(widget: Static) -> list[str]:
    """The widget's lines as shown, below its border, without the left padding."""
    return [line[1:] for line in shown(widget).splitlines()[1:]]


def test_operator_words_first_and_the_seeds_names_beside() -> None:
    """Finding: the phase panel led with the seed's label ("ascent 3 — lift
    segment 1", constants such as SAFE_DISTANCE_IN_FRONT_OF_STEP), and the
    sensors and motors with SFR, MWF..."""
    async def go() -> None:
        app = make_still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            show_climbing(app)
            await pilot.pause(0.3)
            phase = lines(app.phase)
            assert phase[0] == "raising segment 1 (front)"
            assert phase[1] == "ascent 3 — lift segment 1"
            assert phase[3].startswith("steps climbed 2")
            assert phase[4].startswith("treads mm 143 146")
            sensors = lines(app.sensors)
            assert [s.split(" SF")[0].split(" SB")[0] for s in sensors] == [
                "front R", "front L", "back R ", "back L "]
            motors = lines(app.motors)
            assert motors[0].startswith("front wheels MWF")
            assert motors[4].startswith("front lift   MTF")
    asyncio.run(go())


def test_help_screen_lists_every_key() -> None:
    """Finding: there was no help screen."""
    async def go() -> None:
        app = make_still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "question_mark")
            await until(pilot, lambda: isinstance(app.screen, HelpScreen), "the help")
            text = str(app.screen.query_one(Static).render())  # the whole text, scrolled or not
            for key in ("space", "EMERGENCY STOP", "c ", "s ", "p ", "x ", "q ", "u ", "w ",
                        "STALE", "1▲"):
                assert key in text, key
            await press(pilot, "escape")
            await until(pilot, lambda: not isinstance(app.screen, HelpScreen), "closed")
    asyncio.run(go())


@pytest.mark.parametrize("which", ["console", "replay"])
def test_no_help_line_wraps_at_80x24(which: str) -> None:
    """Found: at 80x24 the help's longest lines wrapped ("...from any" and
    "screen," on two lines), reading as two keys' worth of text."""
    from stairbot.console.replay_app import REPLAY_HELP

    text = REPLAY_HELP if which == "replay" else None

    async def go() -> None:
        app = make_still_app()
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            app.push_screen(HelpScreen(text) if text else HelpScreen())
            await until(pilot, lambda: isinstance(app.screen, HelpScreen), "the help")
            await pilot.pause(0.1)
            static = app.screen.query_one(Static)
            longest = max(len(line) for line in str(static.render()).splitlines())
            assert longest <= static.content_region.width, (longest, static.content_region)
    asyncio.run(go())


@pytest.mark.parametrize("size", [(80, 24), (100, 24), (100, 30), (120, 40)])
def test_nothing_an_operator_needs_is_cut(size: tuple[int, int]) -> None:
    """Findings: at 80 columns the banner's key text was cut (the e-stop button
    covered its end); at 100 columns keys were missing from the footer."""
    async def go() -> None:
        app = make_still_app()
        async with app.run_test(size=size) as pilot:
            await ready(pilot)
            await pilot.pause(0.3)  # the footer is laid out after the first refresh
            screen = Region(0, 0, *size)
            footer = app.query_one(Footer)
            assert screen.contains_region(footer.region) and footer.region.height == 1
            on_screen = {k.description for k in footer.query(FooterKey)
                         if k.region.width and footer.region.contains_region(k.region)}
            for key in ("E-STOP", "clear", "start", "pause", "stop", "quit", "help"):
                assert key in on_screen, (key, on_screen)
            button = app.query_one("#estop").region
            assert not app.banner.region.overlaps(button)
            assert screen.contains_region(button)
            for panel in (app.sensors, app.motors, app.phase, app.link):
                assert screen.contains_region(panel.region), panel
    asyncio.run(go())
