"""The console engine: the run on a worker thread, the latched emergency stop,
pause, and bad input, against the real simulated robot."""

from __future__ import annotations

import threading
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import pytest

from stairbot.console.engine import ConsoleEngine, describe_result
from stairbot.console.state import LiveState
from stairbot.control.robot_config import load_config
from stairbot.errors import InputError
from stairbot.hardware import LIFT_MOTORS, WHEEL_MOTORS, MotorId, Snapshot
from stairbot.run.runner import RunControl, RunResult

FORWARD = {m: 1.0 for m in WHEEL_MOTORS}


def stopped(steps_climbed: int = 0, ascent_end: str | None = None) -> RunResult:
    """How a stand-in loop ends."""
    return RunResult(outcome="stopped", ascent_end=ascent_end, steps_climbed=steps_climbed,
                     steps_descended=0, pauses=0, error=None, fell=False, max_pitch_deg=None,
                     final_offset_m=None, sim_time_s=0.0, wall_time_s=0.0, realtime_factor=None,
                     tilt_watched=True)


class DriveLoop:
    """Stands in for runner.run: the same read/command/advance loop with a
    controller that only drives forward, and that IGNORES the e-stop and pause
    (so the test proves the console's own gate stops the robot): it never
    carries out the RunControl's e-stops and clears."""

    def __init__(self) -> None:
        self.snaps: list[Snapshot] = []
        self.started = threading.Event()

    def __call__(self, session: Any, config: Any, sink: Any, mode: str, control: RunControl,
                 on_tick: Any, plan: Any) -> RunResult:
        robot, clock = session.robot, session.clock
        while control.stop_reason is None and len(self.snaps) < 20000:
            snap = robot.read()
            self.snaps.append(snap)
            robot.command(FORWARD)
            on_tick(SimpleNamespace(phase="drive", context=None), snap)
            clock.advance(config.algorithm.tick)
            self.started.set()
        robot.stop_all()
        return stopped()


def wait_for(cond: Any, what: str) -> None:
    """Wait on a condition the run thread makes true (no timing assertion: the
    limit only keeps a broken test from hanging)."""
    ev = threading.Event()
    for _ in range(120000):  # at least 2 minutes: a machine busy with a sweep is slow
        if cond():
            return
        ev.wait(0.001)
    raise AssertionError(f"never happened: {what}")


@pytest.fixture
def engine_and_loop() -> tuple[ConsoleEngine, DriveLoop]:
    loop = DriveLoop()
    engine = ConsoleEngine(LiveState(), load_config(), run_fn=loop, control_fn=RunControl)
    engine.open("sim://", None)
    return engine, loop


def test_estop_stops_every_motor_even_if_the_loop_ignores_it(
        engine_and_loop: tuple[ConsoleEngine, DriveLoop]) -> None:
    engine, loop = engine_and_loop
    worker = threading.Thread(target=engine.run, args=("full",))
    worker.start()
    try:
        wait_for(lambda: len(loop.snaps) > 100, "100 ticks")
        moving = loop.snaps[-1]
        assert moving.motors[MotorId.MWF].speed_tps > 0.5
        engine.estop()
        assert engine.robot is not None
        stop_tick = engine.robot.estop_tick
        assert stop_tick is not None
        wait_for(lambda: len(loop.snaps) > stop_tick + 100, "100 ticks after the stop")
    finally:
        engine.stop()
        worker.join()
    # The first command after the stop already stopped everything (the loop
    # itself kept asking for FORWARD).  Gravity may still settle the robot for a
    # moment after its motors stop, so from 25 ticks on: every motor is still
    # and no counter moves by more than 1 mm of wheel travel (0.01 turn) or
    # 0.1 mm of lift (0.05 turn).
    after = loop.snaps[stop_tick + 25:]
    first = after[0]
    for snap in after:
        for m in MotorId:
            assert abs(snap.motors[m].speed_tps) < 0.02, (m, snap.time_s)
            tol = 0.05 if m in LIFT_MOTORS else 0.01
            assert snap.motors[m].turns == pytest.approx(first.motors[m].turns, abs=tol)
    assert first.motors[MotorId.MWF].turns - moving.motors[MotorId.MWF].turns < 0.05
    view = engine.state.view()
    assert view.status.estopped
    assert "EMERGENCY STOP" in view.status.message


def test_a_run_cannot_start_until_the_estop_is_cleared(
        engine_and_loop: tuple[ConsoleEngine, DriveLoop]) -> None:
    engine, loop = engine_and_loop
    engine.estop()
    assert engine.run("full") is None
    assert "c clears it" in engine.state.view().status.message
    assert engine.clear_estop()
    assert not engine.state.view().status.estopped


def test_an_estop_with_no_robot_open_can_be_cleared() -> None:
    engine = ConsoleEngine(LiveState(), load_config())
    assert not engine.clear_estop()
    engine.estop()
    assert engine.state.view().status.estopped
    assert engine.clear_estop()
    assert not engine.state.view().status.estopped


def test_bad_scenario_and_url_raise_input_errors() -> None:
    engine = ConsoleEngine(LiveState(), load_config())
    with pytest.raises(InputError, match="cannot read"):
        engine.open("sim://", "/nonexistent/stairs.toml")
    with pytest.raises(InputError, match="unknown scheme"):
        engine.open("bogus://x", None)


def test_describe_result() -> None:
    done = replace(stopped(5, "top_reached"), outcome="completed", steps_descended=5)
    line, severity = describe_result(done)
    assert line == "run completed · top reached · climbed 5, descended 5"
    assert severity == "good"


class HeldLoop(DriveLoop):
    """The DriveLoop, held between two ticks (after its 50th) until released."""

    def __init__(self) -> None:
        super().__init__()
        self.held = threading.Event()
        self.release = threading.Event()

    def __call__(self, session: Any, config: Any, sink: Any, mode: str, control: RunControl,
                 on_tick: Any, plan: Any) -> RunResult:
        robot, clock = session.robot, session.clock
        while control.stop_reason is None:
            self.snaps.append(robot.read())
            robot.command(FORWARD)
            clock.advance(config.algorithm.tick)
            if len(self.snaps) == 50:
                self.held.set()
                self.release.wait()
        robot.stop_all()
        return stopped()


def test_estop_stops_the_robot_itself_without_waiting_for_the_next_tick() -> None:
    """The operator's stop reaches the robot from the key handler's thread, at
    once: it does not wait for the run loop to come round (here it never does)."""
    calls: list[str] = []

    class Spy:
        def __init__(self, inner: Any) -> None:
            self.inner = inner

        def __getattr__(self, name: str) -> Any:
            calls.append(name)
            return getattr(self.inner, name)

    def spy_open(url: str, config: Any, scenario: Any, options: Any) -> Any:
        from stairbot.run.robots import RobotSession, open_robot

        s = open_robot(url, config, replace(options, world=scenario))
        return RobotSession(Spy(s.robot), s.clock, s.url, s.simulated, s.sim)

    loop = HeldLoop()
    engine = ConsoleEngine(LiveState(), load_config(), open_fn=spy_open, run_fn=loop,
                           control_fn=RunControl)
    engine.open("sim://", None)
    worker = threading.Thread(target=engine.run, args=("full",))
    worker.start()
    try:
        wait_for(loop.held.is_set, "the loop held between two ticks")
        before = len(calls)
        engine.estop()
        assert calls[before:] == ["estop"]
    finally:
        engine.stop()
        loop.release.set()
        worker.join()


class Wrapped:
    """A robot that does what ``inner`` does, but for the methods a subclass
    gives it."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


def test_a_robot_whose_estop_raises_does_not_take_the_console_down() -> None:
    """estop() never raises by the protocol; a driver that breaks it (a lost
    link) still gets every later command turned into a stop, and the banner
    says the robot did not confirm."""
    from stairbot.errors import LinkLostError

    class EstopRaises(Wrapped):
        """The simulated robot, whose estop() raises (a wrapper: a compiled
        robot's methods cannot be replaced on it)."""

        def estop(self) -> None:
            raise LinkLostError("motor board: no reply to EStop")

    def broken_open(url: str, config: Any, scenario: Any, options: Any) -> Any:
        from stairbot.run.robots import RobotSession, open_robot

        s = open_robot(url, config, replace(options, world=scenario))
        return RobotSession(EstopRaises(s.robot), s.clock, s.url, s.simulated, s.sim)

    engine = ConsoleEngine(LiveState(), load_config(), open_fn=broken_open)
    engine.open("sim://", None)
    assert engine.robot is not None
    engine.robot.command(FORWARD)
    engine.estop()  # does not raise
    status = engine.state.view().status
    assert status.estopped and "did not confirm its e-stop" in status.message
    assert engine.robot.estopped
    engine.robot.command(FORWARD)  # turned into a stop
    assert engine.state.view().commands == dict.fromkeys(MotorId, 0.0)


class LosesTheLink(Wrapped):
    """The simulated robot, whose link is lost at its 50th read."""

    def __init__(self, inner: Any) -> None:
        super().__init__(inner)
        self.reads = 0

    def read(self) -> Snapshot:
        from stairbot.errors import LinkLostError

        self.reads += 1
        if self.reads >= 50:
            raise LinkLostError("link lost: no reply from the sensor board for 0.62 s")
        snap: Snapshot = self.inner.read()
        return snap


def test_a_lost_link_leaves_the_robot_in_fault_not_ended() -> None:
    from stairbot.console.robot_holder import default_open

    def open_fn(*args: Any) -> Any:
        session = default_open(*args)
        return replace(session, robot=LosesTheLink(session.robot))

    engine = ConsoleEngine(LiveState(), load_config(), open_fn=open_fn)
    engine.open("sim://", None)
    result = engine.run("full")
    assert result is not None and result.outcome == "error" and result.fault == "link"
    status = engine.state.view().status
    assert status.robot == "fault" and "no reply from the sensor board" in status.message
