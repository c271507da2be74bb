"""Issue 12 item 5, "its latch leaks" (quitting): `q`, Ctrl+Q and Ctrl-C mid-run
stop the robot first -- the emergency stop, latched -- and then ask; a
SIGINT sent to the console does the same.  Before, `q` and Ctrl+Q quit at
once and Ctrl-C did not stop the robot at all."""

from __future__ import annotations

import asyncio
import os
import signal

import pytest
from pilot import SpyRobot, press, ready, spied_open, until

from stairbot.console.app import build_app
from stairbot.console.modals import ConfirmScreen


def estops(spy: SpyRobot) -> int:
    return [c[0] for c in spy.calls].count("estop")


@pytest.mark.parametrize("key", ["q", "ctrl+q", "ctrl+c", "SIGINT"])
def test_quitting_mid_run_stops_the_robot_first_then_asks(key: str) -> None:
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(speed="10x", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "s")
            spy = spies[-1]
            await until(pilot, lambda: bool(spy.motion(len(spy.calls) - 5)), "the robot moves")
            if key == "SIGINT":
                os.kill(os.getpid(), signal.SIGINT)
            else:
                await press(pilot, key)
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            # The robot was stopped before the question: its own e-stop, latched.
            assert estops(spy) == 1 and spy.inner.estopped
            assert app.state.view().status.estopped
            n = len(spy.calls)
            await press(pilot, "n")  # stay: the latch stays too, nothing moves
            await until(pilot, lambda: len(app.screen_stack) == 1, "the answer")
            await until(pilot, lambda: len(spy.calls) > n + 20, "ticks go on, held")
            assert app.is_running and app.engine.running
            assert spy.motion(n) == [] and app.state.view().status.estopped
            await press(pilot, "q")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "asked again")
            await press(pilot, "y")
            await until(pilot, lambda: not app.is_running, "the console quits")
        assert app.return_code == 0
        assert not app.engine.running
    asyncio.run(go())


def test_quitting_with_no_run_going_does_not_ask() -> None:
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "q")
            await until(pilot, lambda: not app.is_running, "the console quits")
    asyncio.run(go())
