"""Issue 35, defect 4: an e-stop that claimed what it did not do.  In a
console refused for "port in use by another stairbot", space showed
``FAULT E-STOP (operator) EMERGENCY STOP latched``: nothing was latched
anywhere, no robot being connected.  And that console's panel for a serial
robot was titled ``simulation · never read``."""

from __future__ import annotations

import asyncio
from typing import Any

from pilot import banner, press, said, until

from stairbot.console.app import build_app
from stairbot.console.engine import ConsoleEngine
from stairbot.console.state import LiveState
from stairbot.control.robot_config import load_config
from stairbot.errors import HardwareError
from stairbot.run.robots import RobotSession

URL = "serial:///dev/pts/97?baud=1000000"


def refused(url: str, cfg: Any, scenario: Any, options: Any) -> RobotSession:
    raise HardwareError("serial port /dev/pts/97 is in use by another stairbot (pid 4242)")


def test_an_estop_in_a_console_refused_its_robot_says_nothing_was_stopped() -> None:
    async def go() -> None:
        app = build_app(url=URL, open_fn=refused)
        async with app.run_test(size=(80, 24)) as pilot:
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "FAULT" in banner(app), "the refusal")
            assert app.engine.session is None
            assert "simulation" not in str(app.link.border_title)
            assert "link health" in str(app.link.border_title)
            await press(pilot, "space")
            await until(pilot, lambda: "E-STOP" in banner(app), "the e-stop")
            assert "no robot connected: nothing was stopped" in banner(app)
            assert "EMERGENCY STOP latched" not in banner(app)
            assert "no robot connected: nothing was stopped" in said(app)
    asyncio.run(go())


def test_the_consoles_latch_still_holds_the_robot_opened_next() -> None:
    """Nothing was stopped, but the console keeps its latch: the next robot
    opens stopped, until c clears it."""
    engine = ConsoleEngine(LiveState(), load_config())
    engine.estop()
    assert engine.state.view().status.estopped
    engine.open("sim://", None)
    assert engine.robot is not None and engine.robot.estopped
    assert engine.run("full") is None
    engine.close()
