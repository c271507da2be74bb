"""Issue 35, defect 5: typed text ran as commands.  Letters typed while a
refusal showed (a URL, after u was refused mid-run) ran as single-key
commands -- p, t, ? -- and a URL's r answered a Resume offer; a single
letter (y) answered a question that lets the robot move.  Now a refusal is
a notice that takes every key, and motion is given only by typing yes and
Enter into the question."""

from __future__ import annotations

import asyncio
from typing import Any

from pilot import press, ready, say_yes, until

from stairbot.console.app import build_app
from stairbot.console.help import HelpScreen
from stairbot.console.modals import MotionConfirm, Notice


def test_a_url_typed_into_a_refusal_mid_run_runs_no_command() -> None:
    async def go() -> None:
        app = build_app(speed="1x")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            await until(pilot, lambda: app.engine.running, "the run")
            top = app.top_shown
            await press(pilot, "u")
            await until(pilot, lambda: isinstance(app.screen, Notice), "the refusal")
            await press(pilot, *"serial://tpr?", "g", "enter")
            await until(pilot, lambda: len(app.screen_stack) == 1, "closed by enter")
            await pilot.pause(0.2)
            assert not app.state.view().status.paused  # p ran nothing
            assert app.top_shown == top  # nor t
            assert not any(isinstance(s, HelpScreen) for s in app.screen_stack)  # nor ?
            assert app.engine.running
            await press(pilot, "x")
            await until(pilot, lambda: not app.engine.running, "stopped")
    asyncio.run(go())


def test_no_stray_letter_lets_a_robot_on_a_wire_move(still_app: Any) -> None:
    async def go() -> None:
        app = still_app(simulated=True, wired=True, url="serial://loop://")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            robot = app.engine.session.robot
            await press(pilot, "s")
            await until(pilot, lambda: isinstance(app.screen, MotionConfirm), "the question")
            await press(pilot, "y", "enter")
            await pilot.pause(0.2)
            await press(pilot, *"serial:///dev/ttyUSB0?y", "enter")  # text meant elsewhere
            await pilot.pause(0.2)
            assert isinstance(app.screen, MotionConfirm) and not app.engine.running
            assert robot.commands == []
            assert "nothing moved" in str(app.screen.query_one("#motion-hint").render())
            await say_yes(pilot)
            await until(pilot, lambda: app.engine.running or bool(robot.commands), "the start")
            await press(pilot, "x")
    asyncio.run(go())
