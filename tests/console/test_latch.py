"""Issue 12 item 5, "its latch leaks": the emergency stop latch is cleared
only by `c`, and only once the operator confirms; nothing else clears it --
not `x` then `r`, not opening a URL.  Boards that hold a latch are refused
when opened, naming `c` and `stairbot clear`, as `stairbot run` does."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Any

from pilot import SpyRobot, answer_prompt, banner, press, ready, said, spied_open, until
from still_robot import StillClock, StillRobot

from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.modals import ConfirmScreen
from stairbot.errors import LatchedError
from stairbot.run.robots import RobotSession


def latched(app: StairbotConsole) -> bool:
    return app.state.view().status.estopped


async def stopped_run(pilot: Any, spies: list[SpyRobot]) -> None:
    """Start a run, hit the emergency stop, end the run with x."""
    app = pilot.app
    await press(pilot, "s")
    await until(pilot, lambda: app.engine.running, "the run starts")
    await press(pilot, "space")
    await until(pilot, lambda: latched(app) and spies[-1].inner.estopped, "the stop")
    await press(pilot, "x")
    await until(pilot, lambda: not app.engine.running, "the run ends")


def test_x_then_r_does_not_clear_the_latch() -> None:
    """Finding: `x` then `r` (reset the simulation) cleared the latch without `c`."""
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(speed="10x", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await stopped_run(pilot, spies)
            await press(pilot, "r")
            await until(pilot, lambda: len(spies) == 2, "the simulation reopened")
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "E-STOP" in banner(app), "the latch shown")
            assert latched(app) and spies[-1].inner.estopped  # the new world is latched too
            n = len(spies[-1].calls)
            await press(pilot, "s")
            await pilot.pause(0.3)
            await app.workers.wait_for_complete()
            assert not app.engine.running and spies[-1].motion(n) == []
            assert "c clears it" in banner(app)
    asyncio.run(go())


def test_opening_a_url_does_not_clear_the_latch() -> None:
    """Finding: opening a new URL (u) cleared the latch without `c`."""
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(speed="10x", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "space")
            await until(pilot, lambda: latched(app), "the stop")
            await answer_prompt(pilot, "u", "sim://")
            await until(pilot, lambda: len(spies) == 2, "the new robot opened")
            await app.workers.wait_for_complete()
            await pilot.pause(0.2)
            assert latched(app) and spies[-1].inner.estopped
            assert "E-STOP" in banner(app)
    asyncio.run(go())


def test_c_clears_the_latch_only_once_confirmed() -> None:
    """Finding: `c` cleared the latch at once, with no question."""
    spies: list[SpyRobot] = []

    async def go() -> None:
        app = build_app(speed="10x", open_fn=spied_open(spies))
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "space")
            await until(pilot, lambda: latched(app), "the stop")
            await press(pilot, "c")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await press(pilot, "n")
            await until(pilot, lambda: len(app.screen_stack) == 1, "the answer")
            await pilot.pause(0.2)
            assert latched(app) and spies[-1].inner.estopped
            assert [c[0] for c in spies[-1].calls].count("clear") == 0
            await press(pilot, "c")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await press(pilot, "y")
            await until(pilot, lambda: not latched(app), "cleared")
            assert not spies[-1].inner.estopped
            assert [c[0] for c in spies[-1].calls].count("clear") == 1
    asyncio.run(go())


def latched_boards(cleared: list[str]) -> Callable[..., RobotSession]:
    """Boards that hold an e-stop latch: refused unless opened to be cleared."""
    def open_fn(url: str, config: Any, scenario: Any, options: Any) -> RobotSession:
        if not options.allow_latched:
            raise LatchedError(f"{url}: the motor board has its emergency stop latched; "
                               "opening never clears a latch: check the robot, then "
                               f"`stairbot clear --robot {url}`")
        robot = StillRobot()
        robot.estopped = True
        real_clear = robot.clear

        def clear() -> None:
            cleared.append(url)
            real_clear()

        robot.clear = clear  # type: ignore[method-assign]
        return RobotSession(robot, StillClock(), url, False, None)
    return open_fn


def test_latched_boards_are_refused_naming_c_and_cleared_only_when_confirmed() -> None:
    """Finding: boards holding a latch must be refused as `stairbot run` refuses
    them, with `c` here as the way to clear them after looking at the robot."""
    cleared: list[str] = []

    async def go() -> None:
        app = build_app(url="serial://boards", open_fn=latched_boards(cleared))
        async with app.run_test(size=(80, 24)) as pilot:
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "FAULT" in banner(app), "the refusal")
            text = banner(app)
            assert "emergency stop latched" in text and "stairbot clear" in text
            assert "c here" in text
            assert app.engine.session is None and "c here" in said(app)
            await press(pilot, "c")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await press(pilot, "n")
            await until(pilot, lambda: len(app.screen_stack) == 1, "the answer")
            await app.workers.wait_for_complete()
            assert cleared == [] and app.engine.session is None
            await press(pilot, "c")
            await until(pilot, lambda: isinstance(app.screen, ConfirmScreen), "the question")
            await press(pilot, "y")
            await until(pilot, lambda: "READY" in banner(app), "cleared and ready")
            assert cleared == ["serial://boards"]
            assert not latched(app)
    asyncio.run(go())
