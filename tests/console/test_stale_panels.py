"""Issue 35, defect 3: stale values kept their live colours.  A stale panel
was dimmed and titled STALE, but ``ok`` stayed green, ``DIFFER`` red,
``agree`` green, a motor arrow ``1▲ +10.0`` bold, link health ``fps 307``:
values of a robot gone, drawn as if live.  Stale now: no colour, no arrow,
no verdict on the pairs."""

from __future__ import annotations

import asyncio
from typing import Any

from pilot import ready, until
from rich.console import Group
from rich.text import Text
from still_robot import HEALTH, StillClock, StillRobot, StillSim

from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.freshness import STALE_S
from stairbot.errors import LinkLostError
from stairbot.hardware import Snapshot
from stairbot.run.robots import RobotSession


class GoesSilent(StillRobot):
    def __init__(self, health: dict[str, float] | None) -> None:
        super().__init__(health)
        self.silent = False

    def read(self) -> Snapshot:
        if self.silent:
            raise LinkLostError("link lost: no reply (the test's robot is silent)")
        return super().read()


def lines(panel: Any) -> list[Text]:
    """The Text lines a panel was last given."""
    content = panel.content
    if isinstance(content, Group):
        return [t for t in content.renderables if isinstance(t, Text)]
    assert isinstance(content, Text)
    return [content]


def coloured(panel: Any) -> list[str]:
    """The parts of a panel's text drawn in a style of their own (a colour,
    bold), not the panel's dim."""
    out = []
    for text in lines(panel):
        out += [text.plain[s.start:s.end] for s in text.spans if str(s.style) != "dim"]
        if str(text.style) not in ("", "dim"):
            out.append(text.plain)
    return out


def app_of(robots: list[GoesSilent], wall: list[float], wired: bool) -> StairbotConsole:
    def open_fn(url: str, cfg: Any, scenario: Any, options: Any) -> RobotSession:
        robot = GoesSilent(HEALTH if wired else None)
        robots.append(robot)
        return RobotSession(robot, StillClock(), url, not wired, None if wired else StillSim())

    return build_app(open_fn=open_fn, ages_wall=lambda: wall[0])


def check(wired: bool) -> None:
    robots: list[GoesSilent] = []
    wall = [0.0]

    async def go() -> None:
        app = app_of(robots, wall, wired)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: bool(coloured(app.sensors)), "live colours")
            live = " ".join(coloured(app.sensors)) + " " + " ".join(coloured(app.motors))
            assert "ok" in live and "agree" in live and "1▲" in live
            for robot in robots:
                robot.silent = True
            wall[0] += STALE_S + 1
            await until(pilot, lambda: all(p.has_class("-stale") for p in
                                           (app.sensors, app.motors, app.link)), "stale")
            for panel in (app.sensors, app.motors, app.link):
                assert coloured(panel) == [], (panel, coloured(panel))
            sensors = "\n".join(t.plain for t in lines(app.sensors))
            assert "agree" not in sensors and "DIFFER" not in sensors
            motors = "\n".join(t.plain for t in lines(app.motors))
            assert "▲" not in motors and "▼" not in motors and "■" not in motors
            assert "?" in motors
    asyncio.run(go())


def test_a_stale_simulation_shows_no_status_colour_arrow_or_verdict() -> None:
    check(wired=False)


def test_stale_boards_show_no_status_colour_arrow_verdict_or_bold_figure() -> None:
    check(wired=True)
