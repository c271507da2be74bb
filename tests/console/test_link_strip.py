"""Issue 35, defect 2 (and 8's long URL): link health pushed off the screen
when the link died.  Boards killed at 80x24: the banner wrapped to 5-6
lines, the link panel went off the screen, and the message named the URL
twice (``no reading from serial:///dev/pts/1: serial:///dev/pts/1: link
lost``); a 5,000-character URL filled the banner and hid the reason.  Now
the banner's first line is a strip no message can push off (LIVE/DOWN and
the last reading's age, the boards, the URL, cut at the edge), and the
message under it leaves the URL to the strip."""

from __future__ import annotations

import asyncio
from typing import Any

from pilot import banner, ready, until
from still_robot import HEALTH, StillClock, StillRobot

from stairbot.console.app import build_app
from stairbot.console.freshness import STALE_S
from stairbot.errors import HardwareError, LinkLostError
from stairbot.hardware import Snapshot
from stairbot.run.robots import RobotSession

URL = "serial:///dev/pts/1?baud=1000000"


class Boards(StillRobot):
    """A still robot on a wire whose link dies when told; its driver's
    message names the URL, as the serial driver's does."""

    def __init__(self) -> None:
        super().__init__(HEALTH)
        self.dead = False

    def read(self) -> Snapshot:
        if self.dead:
            raise LinkLostError(f"{URL}: link lost: no reply from the sensor board")
        return super().read()

    def identity(self) -> dict[str, dict[str, int]]:
        return {"motor": {"serial": 4660, "uptime_ms": 1, "boot": 7},
                "sensor": {"serial": 22136, "uptime_ms": 1, "boot": 8}}


def test_boards_gone_at_80x24_leave_the_strip_saying_down_and_the_url_once() -> None:
    robots: list[Boards] = []
    wall = [0.0]

    def open_fn(url: str, cfg: Any, scenario: Any, options: Any) -> RobotSession:
        robots.append(Boards())
        return RobotSession(robots[-1], StillClock(), url, False, None)

    async def go() -> None:
        app = build_app(url=URL, open_fn=open_fn, ages_wall=lambda: wall[0])
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: "LIVE" in app.banner.strip, "live")
            assert "motor #4660 · sensor #22136" in app.banner.strip
            robots[-1].dead = True
            wall[0] += STALE_S + 2
            await until(pilot, lambda: "FAULT" in banner(app), "the fault")
            await until(pilot, lambda: "DOWN" in app.banner.strip, "down")
            await pilot.pause(0.2)
            assert banner(app).count(URL) == 1, banner(app)
            message = banner(app).removeprefix(app.banner.strip)
            assert "no reading from the robot: link lost: no reply" in message, message
            assert app.banner.region.y == 0 and app.banner.size.height <= 5
            assert app.banner.strip.startswith(" FAULT")
    asyncio.run(go())


def test_a_5000_character_url_leaves_the_reason_in_view() -> None:
    url = "serial:///dev/" + "A" * 5000

    def refused(url: str, cfg: Any, scenario: Any, options: Any) -> RobotSession:
        raise HardwareError(f"cannot open {url}: no such port")

    async def go() -> None:
        app = build_app(url=url, open_fn=refused)
        async with app.run_test(size=(80, 24)) as pilot:
            await app.workers.wait_for_complete()
            await until(pilot, lambda: "FAULT" in banner(app), "the refusal")
            await pilot.pause(0.2)
            strip = app.banner.strip
            message = banner(app).removeprefix(strip)
            assert url in strip and url not in message
            assert "no such port" in message
            assert app.banner.size.height <= 5
            shown = app.banner.render_lines(app.banner.region.reset_offset)
            assert "no such port" in " ".join(" ".join(s.text for s in shown).split())
    asyncio.run(go())


def test_a_run_held_by_the_latch_is_in_the_e_stop_state_not_paused() -> None:
    """Issue 35, defect 8: an e-stop mid-run read ``PAUSED E-STOP``."""
    from stairbot.console.state import RunStatus
    from stairbot.console.widgets.banner import strip_text

    held = RunStatus(robot="running", estopped=True, paused=True, latch="operator")
    strip = strip_text("sim://", "default", held, link="LIVE 0.1 s").plain
    assert strip.startswith(" E-STOP  (operator)") and "PAUSED" not in strip
    paused = RunStatus(robot="running", paused=True)
    assert strip_text("sim://", "default", paused).plain.startswith(" PAUSED ")
    refused = RunStatus(robot="fault", estopped=True, latch="operator")
    assert strip_text("sim://", "", refused).plain.startswith(" FAULT   E-STOP  (operator)")
