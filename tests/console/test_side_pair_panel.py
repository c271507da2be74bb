"""The side pair SSR/SSL in the console: the sensors panel has a line for it
only on a robot with the pair (its config, or readings that carry it), with
the staleness rules of every reading; the graphs (g) draw the pair's lines
then too; and at 80x24 nothing an operator needs is cut (the pair's line
takes the row the link panel had to spare)."""

from __future__ import annotations

import asyncio
import math
from dataclasses import replace
from typing import Any

from pilot import press, ready, shown, until
from still_robot import HEALTH, StillClock, StillRobot, StillSim

from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.freshness import STALE_S
from stairbot.console.history import COLUMNS, NOT_CARRIED, SERIES, column, row_of
from stairbot.control.robot_config import load_config, parse_config
from stairbot.errors import LinkLostError
from stairbot.hardware import SensorId, SensorReading, SensorStatus, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.run.robots import RobotSession

SIDE_CONFIG: RobotConfig = parse_config(
    'extends = "reference"\n[sensors]\nside_model = "vl53l0x"\n', "side.toml")
SIDE = {SensorId.SSR: SensorReading(0.6204), SensorId.SSL: SensorReading(1.3,
                                                                        SensorStatus.OUT_OF_RANGE)}


class SideRobot(StillRobot):
    """The still robot, with the side pair's readings (``side``: None, none)."""

    def __init__(self, side: dict[SensorId, SensorReading] | None,
                 health: dict[str, float] | None = None) -> None:
        super().__init__(health)
        self.side = side
        self.silent = False

    def read(self) -> Snapshot:
        if self.silent:
            raise LinkLostError("link lost: no reply (the test's robot is silent)")
        snap = super().read()
        if self.side is None:
            return snap
        return replace(snap, sensors={**snap.sensors, **self.side})


def app_of(config: RobotConfig, side: dict[SensorId, SensorReading] | None,
           wired: bool = False, ages: list[float] | None = None,
           robots: list[SideRobot] | None = None) -> StairbotConsole:
    def open_fn(url: str, cfg: Any, scenario: Any, options: Any) -> RobotSession:
        robot = SideRobot(side, HEALTH if wired else None)
        if robots is not None:
            robots.append(robot)
        return RobotSession(robot, StillClock(), url, not wired, None if wired else StillSim())

    wall = ages or [0.0]
    return build_app(config, open_fn=open_fn, ages_wall=lambda: wall[0])


def side_line(app: StairbotConsole) -> str | None:
    found = [li for li in shown(app.sensors).splitlines() if li.strip().startswith("side ")]
    assert len(found) <= 1
    return found[0].strip() if found else None


def run(go: Any) -> None:
    asyncio.run(go())


def test_a_robot_with_the_pair_shows_its_line() -> None:
    async def go() -> None:
        app = app_of(SIDE_CONFIG, SIDE)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: side_line(app) is not None, "the side line")
            assert side_line(app) == "side  SSR 0.620 ok     SSL 1.300 out"
            lines = shown(app.sensors).splitlines()
            assert [li.split()[0] for li in lines[1:]] == [
                "front", "front", "back", "back", "side"]  # under the base four
    run(go)


def test_a_robot_without_the_pair_shows_none_of_it() -> None:
    async def go() -> None:
        app = app_of(load_config(), None)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await pilot.pause(0.3)
            assert "SFR" in shown(app.sensors)
            assert side_line(app) is None and "SSR" not in shown(app.sensors)
            assert "SSR" not in app.trends.lines and app.trends.series == SERIES
    run(go)


def test_a_config_with_the_pair_whose_readings_lack_it_says_none() -> None:
    """(A simulation that does not read the pair yet.)  Nothing is made up:
    no value, no ERROR either -- no reading."""
    async def go() -> None:
        app = app_of(SIDE_CONFIG, None)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: side_line(app) is not None, "the side line")
            assert side_line(app) == "side  SSR   —   none   SSL   —   none"
    run(go)


def test_readings_that_carry_the_pair_show_it_whatever_the_config() -> None:
    """A replay of a recording whose config was not kept: the readings say."""
    async def go() -> None:
        app = app_of(load_config(), SIDE)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: side_line(app) is not None, "the side line")
    run(go)


def test_the_pair_goes_old_and_stale_as_every_reading() -> None:
    ages = [0.0]
    old = {SensorId.SSR: SensorReading(0.62, age_s=STALE_S + 0.5),
           SensorId.SSL: SensorReading(0.8, SensorStatus.ERROR)}

    robots: list[SideRobot] = []

    async def go() -> None:
        app = app_of(SIDE_CONFIG, old, ages=ages, robots=robots)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await until(pilot, lambda: side_line(app) is not None, "the side line")
            assert side_line(app) == "side  SSR 0.620 old    SSL   —   ERROR"
            # nothing read since: the whole panel is stale (the robot silent: an
            # idle poll that read it again would make the values fresh, and did
            # once in the whole suite on a loaded machine)
            for robot in robots:
                robot.silent = True
            ages[0] += STALE_S + 1
            await until(pilot, lambda: app.sensors.has_class("-stale"), "dimmed")
            assert "STALE" in str(app.sensors.border_title)
    run(go)


def test_at_80x24_the_pair_costs_the_link_panel_nothing_it_shows() -> None:
    """A wired robot's link panel has two lines of figures: both stay."""
    async def go() -> None:
        regions = {}
        for config, side in ((load_config(), None), (SIDE_CONFIG, SIDE)):
            app = app_of(config, side, wired=True)
            async with app.run_test(size=(80, 24)) as pilot:
                await ready(pilot)
                await pilot.pause(0.3)
                link = shown(app.link).splitlines()
                assert any("rtt" in li for li in link) and any("retries" in li for li in link)
                panels = (app.sensors, app.motors, app.phase, app.link)
                regions[side is not None] = [p.region for p in panels]
                assert all(app.screen.region.contains_region(p.region) for p in panels)
                assert regions[side is not None][-1].bottom <= 23  # above the footer
        # one row more for the sensors, one less for the link panel's spare
        assert regions[True][0].height == regions[False][0].height + 1
        assert regions[True][3].height == regions[False][3].height - 1
    run(go)


def test_the_graphs_draw_the_pair_on_a_robot_with_it() -> None:
    async def go() -> None:
        app = app_of(SIDE_CONFIG, SIDE)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            await press(pilot, "g")
            await until(pilot, lambda: bool(app.trends.display), "the graphs")
            assert app.trends.series == COLUMNS
            screen = app.screen.region
            for name in ("SSR", "SSL"):
                line = app.trends.lines[name].region
                assert line.width >= 10 and screen.contains_region(line) and line.bottom <= 23
            await until(pilot, lambda: app.trends.plain.get("SSR", "").startswith("side R"),
                        "the SSR line")
            assert app.trends.plain["SSR"] == "side R   0.620 | 0.620…0.620"
            assert app.trends.plain["SSL"] == "side L   1.300 | 1.300…1.300"
    run(go)


def test_a_row_marks_a_sensor_not_carried_apart_from_one_in_error() -> None:
    base = StillRobot().read()
    row = row_of(base)
    assert row[column("SSR")] == row[column("SSL")] == NOT_CARRIED
    with_pair = row_of(replace(base, sensors={**base.sensors, **SIDE,
                                              SensorId.SSL: SensorReading(0.0,
                                                                          SensorStatus.ERROR)}))
    assert with_pair[column("SSR")] == 0.6204 and math.isnan(with_pair[column("SSL")])
