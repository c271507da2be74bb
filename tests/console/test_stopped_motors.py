"""Issue 35, defect 1: a motor shown moving after a stop.  After an e-stop
at 10x the front lift read ``1▲ +10.0 ... "0.3 s ago"`` for as long as the
console stayed open: the idle reads of the in-process simulation read a world
whose time no longer passed, so its motors kept the speeds they had when the
run stopped.  And a wheel turning -0.02 turn/s showed ``◀ +0.0``: the arrow
and the figure used different thresholds."""

from __future__ import annotations

import pytest

from stairbot.console.engine import ConsoleEngine
from stairbot.console.state import LiveState
from stairbot.console.widgets.motors import motor_line
from stairbot.control.robot_config import load_config
from stairbot.hardware import MotorId, MotorState


class Wall:
    """A wall clock the test moves."""

    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def test_an_idle_simulation_reads_its_motors_stopped_after_a_stop() -> None:
    wall = Wall()
    config = load_config()
    engine = ConsoleEngine(LiveState(), config, wall=wall, sleep=lambda _s: None)
    engine.open("sim://", None)
    robot, clock = engine.robot, engine.clock
    assert robot is not None and clock is not None
    robot.command({MotorId.MTF: 1.0})
    for _ in range(25):
        robot.read()
        clock.advance(config.algorithm.tick)
    moving = robot.read()
    assert moving.motors[MotorId.MTF].speed_tps > 0.5
    robot.stop_all()
    engine.poll()  # the first idle read: the world as the stop left it
    wall.t += 0.5
    engine.poll()
    view = engine.state.view()
    assert view.snapshot is not None
    assert view.snapshot.time_s == pytest.approx(moving.time_s + 0.5, abs=0.03)
    assert view.snapshot.motors[MotorId.MTF].speed_tps == pytest.approx(0.0, abs=0.01)
    line = str(motor_line(MotorId.MTF, view.snapshot.motors[MotorId.MTF], 0.0))
    assert "■" in line and "▲" not in line
    engine.close()


def stopped_mid_motion(wall: Wall) -> ConsoleEngine:
    """A console whose simulation's wheels were driving when they stopped."""
    config = load_config()
    engine = ConsoleEngine(LiveState(), config, wall=wall, sleep=lambda _s: None)
    engine.open("sim://", None)
    robot, clock = engine.robot, engine.clock
    assert robot is not None and clock is not None
    robot.command({m: 1.0 for m in (MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL)})
    for _ in range(10):
        robot.read()
        clock.advance(config.algorithm.tick)
    robot.read()
    robot.stop_all()
    return engine


def test_an_idle_read_passes_at_most_a_bounded_time() -> None:
    """A console that was asleep for a minute does not simulate the minute."""
    wall = Wall()
    engine = stopped_mid_motion(wall)
    engine.poll()
    before = engine.state.view().snapshot
    wall.t += 60.0
    engine.poll()
    after = engine.state.view().snapshot
    assert before is not None and after is not None
    assert 0.0 < after.time_s - before.time_s <= 2.0 + 1e-9
    engine.close()


def test_a_simulation_at_rest_stays_as_it_is() -> None:
    """Once its motors read still, idle reads pass no more time: a run
    started then is the run a headless `stairbot run` makes from there."""
    wall = Wall()
    engine = stopped_mid_motion(wall)
    for _ in range(4):
        engine.poll()
        wall.t += 0.5
    rest = engine.state.view().snapshot
    assert rest is not None
    assert all(abs(m.speed_tps) < 0.05 for m in rest.motors.values())
    for _ in range(4):
        engine.poll()
        wall.t += 0.5
    later = engine.state.view().snapshot
    assert later is not None and later.time_s == rest.time_s
    engine.close()

    fresh = ConsoleEngine(LiveState(), load_config(), wall=wall, sleep=lambda _s: None)
    fresh.open("sim://", None)
    for _ in range(3):
        fresh.poll()
        wall.t += 0.5
    snap = fresh.state.view().snapshot
    assert snap is not None and snap.time_s == 0.0
    fresh.close()


@pytest.mark.parametrize("speed", [-0.02, 0.0, 0.049, -0.049])
def test_a_speed_shown_as_zero_shows_no_arrow(speed: float) -> None:
    line = str(motor_line(MotorId.MWF, MotorState(5.0, speed), 0.0))
    assert "■" in line and "+0.0" in line
    assert "◀" not in line and "▶" not in line


def test_a_speed_shown_moving_shows_its_arrow() -> None:
    assert "◀" in str(motor_line(MotorId.MWF, MotorState(5.0, -0.05), -0.05))
    assert "▶" in str(motor_line(MotorId.MWF, MotorState(5.0, 0.3), 0.3))
