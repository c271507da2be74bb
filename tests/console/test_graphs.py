"""Issue 12, "runs you can look at": the console's graphs (key g) -- the
IMU's pitch, the distance sensors and the lifts over the last 30 s of robot
time, one Textual Sparkline each.  They fit 80x24 (in the picture's place,
nothing else cut), show under the picture on a tall screen, follow the
robot's clock, and stop and dim with the readings when those go stale."""

from __future__ import annotations

import asyncio

from pilot import press, ready, until
from still_robot import ScriptedRobot, scripted_app

from stairbot.console.app import StairbotConsole, build_app
from stairbot.console.freshness import STALE_S
from stairbot.console.history import SERIES, History
from stairbot.control.robot_config import load_config
from stairbot.hardware import (
    Imu,
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)

PER_TURN = load_config().motors.lift_travel_per_turn


def snap(t: float, pitch: float, sfr: float = 0.3, mtf_turns: float = 0.0,
         sfl_status: SensorStatus = SensorStatus.OK) -> Snapshot:
    sensors = {SensorId.SFR: SensorReading(sfr), SensorId.SFL: SensorReading(0.31, sfl_status),
               SensorId.SBR: SensorReading(0.04), SensorId.SBL: SensorReading(0.05)}
    motors = {m: MotorState(1.0) for m in MotorId}
    motors[MotorId.MTF] = MotorState(mtf_turns)
    return Snapshot(t, sensors, motors, imu=Imu(pitch, 0.0))




def feed(app: StairbotConsole, robot: ScriptedRobot, snaps: list[Snapshot]) -> None:
    for s in snaps:
        robot.snap = s  # what the idle poll reads too
        app.state.on_read(s)


def test_history_keeps_the_window_by_robot_time_and_ignores_repeats() -> None:
    h = History(window_s=1.0)
    for i in range(100):
        h.add(snap(i * 0.02, pitch=i))
    h.add(snap(99 * 0.02, pitch=-50))  # read again, the clock standing: nothing added
    rows = h.rows()
    assert rows[-1][0] == 99 * 0.02 and rows[-1][1] == 99
    assert rows[0][0] >= 99 * 0.02 - 1.0 and len(rows) == 51
    h.add(snap(0.5, pitch=1))  # a clock that went back: afresh
    assert [r[1] for r in h.rows()] == [1]


def test_graphs_fit_80x24_in_the_pictures_place_and_cut_nothing_else() -> None:
    robot, ages = ScriptedRobot(snap(0.0, 0.0)), [0.0]

    async def go() -> None:
        app = scripted_app(robot, ages)
        async with app.run_test(size=(80, 24)) as pilot:
            await ready(pilot)
            assert app.picture.display and not app.trends.display  # 80x24: the picture
            panels = (app.banner, app.sensors, app.motors, app.phase, app.link)
            before = [p.region for p in panels]
            await press(pilot, "g")
            await until(pilot, lambda: app.trends.display and not app.picture.display,
                        "the graphs in the picture's place")
            await pilot.pause(0.2)
            assert [p.region for p in panels] == before
            screen = app.screen.region
            for name in SERIES:
                line = app.trends.lines[name].region
                assert line.width >= 10 and screen.contains_region(line), name
                assert line.bottom <= 23  # above the footer
            assert app.log_panel.region.height >= 4  # the events still there
            await press(pilot, "g")
            await until(pilot, lambda: app.picture.display and not app.trends.display,
                        "the picture back")
    asyncio.run(go())


def test_on_a_tall_screen_the_graphs_show_under_the_picture() -> None:
    robot, ages = ScriptedRobot(snap(0.0, 0.0)), [0.0]

    async def go() -> None:
        app = scripted_app(robot, ages)
        async with app.run_test(size=(100, 40)) as pilot:
            await ready(pilot)
            assert app.picture.display and app.trends.display
            assert app.trends.region.y > app.picture.region.y
            await pilot.resize_terminal(80, 24)
            await until(pilot, lambda: not app.trends.display, "hidden on 80x24")
            assert app.picture.display
    asyncio.run(go())


def test_graphs_draw_the_readings_and_stop_and_dim_when_they_go_stale() -> None:
    robot, ages = ScriptedRobot(snap(0.0, 0.0)), [0.0]
    snaps = [snap(10 + i * 0.02, pitch=i / 10, sfr=0.2 + i / 1000, mtf_turns=i)
             for i in range(50)]

    robot.snap = snaps[0]  # what the robot reads when opened

    async def go() -> None:
        app = scripted_app(robot, ages)
        async with app.run_test(size=(100, 40)) as pilot:
            await ready(pilot)
            feed(app, robot, snaps)
            await until(pilot, lambda: len(app.trends.lines["pitch"].data or []) == 50,
                        "fifty readings drawn")
            assert list(app.trends.lines["pitch"].data or []) == [i / 10 for i in range(50)]
            assert app.trends.plain["pitch"] == "pitch    +4.9° | +0.0…+4.9°"
            assert app.trends.plain["SFR"] == "front R  0.249 | 0.200…0.249"
            mm = f"{49 * PER_TURN * 1000:+.0f}"
            assert app.trends.plain["MTF"] == f"MTF     {mm + 'mm':>6} | +0…{mm}"
            assert "last 1 s" in str(app.trends.border_title)  # 0.98 s of robot time
            assert not app.trends.has_class("-stale")
            # an ERROR reading: its distance is not drawn, the label says so
            feed(app, robot, [snap(11.0, pitch=5.0, sfl_status=SensorStatus.ERROR)])
            await until(pilot, lambda: "ERROR" in app.trends.plain["SFL"], "SFL in error")
            assert len(app.trends.lines["SFL"].data or []) == 50
            assert len(app.trends.lines["pitch"].data or []) == 51
            # no reading for longer than STALE_S: stopped and dimmed, said STALE
            # (the robot silent: an idle poll that read it again would make the
            # values fresh, and did, once, on a loaded machine)
            robot.silent = True
            ages[0] += STALE_S + 1
            await until(pilot, lambda: app.trends.has_class("-stale"), "the graphs dimmed")
            assert "STALE" in str(app.trends.border_title)
            assert len(app.trends.lines["pitch"].data or []) == 51  # nothing drawn since
    asyncio.run(go())


def test_graphs_fill_during_a_simulated_run() -> None:
    async def go() -> None:
        app = build_app(speed="max")
        async with app.run_test(size=(100, 40)) as pilot:
            await ready(pilot)
            await press(pilot, "k")  # calibration only: a short run
            await until(pilot, lambda: "ENDED" in app.banner.plain, "the calibration ends")
            await pilot.pause(0.3)
            view = app.state.view()
            assert view.snapshot is not None
            data = app.trends.lines["SFR"].data or []
            assert len(data) > 100  # ticks of 20 ms over the last 30 s
            assert data[-1] == view.snapshot.sensors[SensorId.SFR].distance_m
            shown = f"{view.snapshot.sensors[SensorId.SFR].distance_m:.3f}"
            assert app.trends.plain["SFR"].startswith(f"front R  {shown} | ")
    asyncio.run(go())
