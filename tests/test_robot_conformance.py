"""Every robot keeps the Robot protocol (stairbot/hardware.py): the same tests,
parametrised over the robots stairbot ships -- ``sim://``, ``serial://`` (fake
boards on a pseudo-terminal) and ``can://`` (fake boards on python-can's
virtual bus) -- each opened with ``open_robot(url, config, options)``.

The fake boards run in lockstep, so every robot's time is simulated: motion is
measured in turns after the clock advances, never against the wall clock.  The
boards' own wire timeout only bounds how long a dead link is waited for.

Tests a driver does not pass yet are marked ``xfail(strict=True)`` for that
robot only, each saying why (see ``NOT_YET``): when the driver is fixed the
test passes, strict xfail reports it, and the mark is removed.
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import can
import pytest

from stairbot.config import RobotConfig, load_config
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer
from stairbot.fakes.serial_boards import PtyPair, SerialBoardServer
from stairbot.hardware import (
    LIFT_MOTORS,
    WHEEL_MOTORS,
    HasScene,
    HasTruth,
    MotorId,
    MotorState,
    ReportsEvents,
    Robot,
    SensorId,
    SensorReading,
    Snapshot,
)
from stairbot.robots import RobotOptions, RobotSession, open_robot
from stairbot.scenario import Scenario, load_scenario

CONFIG: RobotConfig = load_config()
SCENARIO: Scenario = load_scenario()
TICK = CONFIG.algorithm.tick
FORWARD = dict.fromkeys(WHEEL_MOTORS, 1.0)  # turns/s: 0.5 s moves each wheel ~0.5 turn
MOVED = 0.1  # turns: a wheel that turned at least this far moved
STILL = 0.02  # turns: a wheel that turned less than this stood still
ROBOTS = ("sim", "serial", "can")
_channels = itertools.count()


@dataclass
class Rig:
    """One opened robot and how to break its link (None: it has none)."""

    kind: str
    session: RobotSession
    break_link: Callable[[], None] | None = None

    @property
    def robot(self) -> Robot:
        return self.session.robot

    def drive(self, speeds: dict[MotorId, float], seconds: float) -> None:
        """The control loop's rhythm: read, command, let one tick pass."""
        for _ in range(round(seconds / TICK)):
            self.robot.read()
            self.robot.command(speeds)
            self.session.clock.advance(TICK)

    def wait(self, seconds: float) -> None:
        """Let robot time pass reading, with no command.  (Reading each tick is
        the loop's rhythm; it feeds the boards' watchdogs, which in lockstep
        count simulated time.)"""
        for _ in range(round(seconds / TICK)):
            self.robot.read()
            self.session.clock.advance(TICK)

    def insist(self, speeds: dict[MotorId, float], seconds: float) -> None:
        """Command every tick without reading (what a latched robot must
        ignore).  Kept under the boards' 250 ms watchdog: no read feeds it."""
        assert seconds < 0.25
        for _ in range(round(seconds / TICK)):
            self.robot.command(speeds)
            self.session.clock.advance(TICK)


def wheels_moved(a: Snapshot, b: Snapshot) -> float:
    """The most any wheel turned between two snapshots."""
    return max(abs(b.turns(m) - a.turns(m)) for m in WHEEL_MOTORS)


def open_sim() -> Iterator[Rig]:
    session = open_robot("sim://", CONFIG, RobotOptions(world=SCENARIO))
    try:
        yield Rig("sim", session)
    finally:
        session.close()


def _served(kind: str, server: SerialBoardServer | CanBoardServer, url: str) -> Iterator[Rig]:
    """Serve fake boards on a thread and open ``url`` to them; stopped after."""
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()

    def stop_boards() -> None:
        server.stop()
        thread.join(5)

    try:
        session = open_robot(url, CONFIG)
        try:
            yield Rig(kind, session, stop_boards)
        finally:
            session.close()
    finally:
        stop_boards()


def open_serial() -> Iterator[Rig]:
    """Fake boards in lockstep on a pseudo-terminal, served on a thread."""
    world = make_world(CONFIG, SCENARIO, lockstep=True)
    pty = PtyPair()
    try:
        yield from _served("serial", SerialBoardServer(pty.master, world, make_boards(world)),
                           f"serial://{pty.path}?lockstep=1&timeout=0.5")
    finally:
        pty.close()


def open_can() -> Iterator[Rig]:
    """Fake boards in lockstep on a fresh python-can virtual channel, served
    on a thread (one process: a virtual bus does not leave it)."""
    channel = f"conformance-{next(_channels)}"
    world = make_world(CONFIG, SCENARIO, lockstep=True)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            make_boards(world))
    try:
        yield from _served("can", server, f"can://virtual/{channel}?lockstep=1&timeout=0.5")
    finally:
        server.bus.shutdown()


OPENERS = {"sim": open_sim, "serial": open_serial, "can": open_can}

# (test name, robot) -> (why the driver does not pass it yet, what it raises).
# Empty: every shipped robot passes every test.
NOT_YET: dict[tuple[str, str], tuple[str, type[BaseException]]] = {}


@pytest.fixture(params=ROBOTS)
def rig(request: pytest.FixtureRequest) -> Iterator[Rig]:
    kind: str = request.param
    not_yet = NOT_YET.get((request.node.originalname, kind))
    if not_yet is not None:
        why, raises = not_yet
        request.applymarker(pytest.mark.xfail(reason=why, raises=raises, strict=True))
    yield from OPENERS[kind]()


# -- the protocol --------------------------------------------------------------------

def test_is_a_robot_and_starts_unlatched(rig: Rig) -> None:
    assert isinstance(rig.robot, Robot)
    assert rig.robot.estopped is False


def test_read_gives_every_sensor_and_every_motor(rig: Rig) -> None:
    snap = rig.robot.read()
    assert set(snap.sensors) == set(SensorId) and len(SensorId) == 4
    assert set(snap.motors) == set(MotorId) and len(MotorId) == 6
    assert all(isinstance(r, SensorReading) for r in snap.sensors.values())
    assert all(isinstance(s, MotorState) for s in snap.motors.values())


def test_a_command_turns_the_wheels_as_the_clock_advances(rig: Rig) -> None:
    before = rig.robot.read()
    rig.drive(FORWARD, 0.5)
    after = rig.robot.read()
    for m in WHEEL_MOTORS:
        assert after.turns(m) - before.turns(m) > MOVED, m
    assert after.time_s > before.time_s


def test_stop_all_stops_every_motor_and_does_not_latch(rig: Rig) -> None:
    rig.drive(FORWARD, 0.3)
    rig.robot.stop_all()
    rig.wait(0.2)  # the robot comes to rest
    rest = rig.robot.read()
    rig.wait(0.5)
    assert wheels_moved(rest, rig.robot.read()) < STILL
    assert rig.robot.estopped is False
    before = rig.robot.read()
    rig.drive(FORWARD, 0.3)
    assert wheels_moved(before, rig.robot.read()) > MOVED


def test_estop_latches_commands_move_nothing(rig: Rig) -> None:
    rig.drive(FORWARD, 0.3)
    moving = rig.robot.read()
    rig.robot.estop()
    rig.insist(FORWARD, 0.2)  # the loop keeps asking; the latch holds
    rig.robot.clear()  # (read after the clear: reading while latched is its own test)
    after = rig.robot.read()
    assert wheels_moved(moving, after) < 0.05  # what the wheels took to stop, at most
    for m in LIFT_MOTORS:
        assert after.turns(m) == pytest.approx(moving.turns(m), abs=STILL)  # lifts hold


def test_estopped_is_true_from_estop_until_clear(rig: Rig) -> None:
    rig.robot.estop()
    assert rig.robot.estopped is True
    rig.robot.command(FORWARD)
    assert rig.robot.estopped is True
    rig.robot.clear()
    assert rig.robot.estopped is False


def test_read_goes_on_while_latched(rig: Rig) -> None:
    rig.drive(FORWARD, 0.2)
    rig.robot.estop()
    rig.wait(0.2)
    a = rig.robot.read()
    rig.robot.command(FORWARD)
    rig.wait(0.5)
    b = rig.robot.read()
    assert set(b.sensors) == set(SensorId) and set(b.motors) == set(MotorId)
    assert wheels_moved(a, b) < STILL


def test_clearing_alone_moves_nothing_a_new_command_does(rig: Rig) -> None:
    rig.drive(FORWARD, 0.2)
    rig.robot.estop()
    rig.insist({}, 0.2)
    rig.robot.clear()
    assert rig.robot.estopped is False
    rest = rig.robot.read()
    rig.wait(0.5)
    still = rig.robot.read()
    assert wheels_moved(rest, still) < STILL
    rig.drive(FORWARD, 0.5)
    assert wheels_moved(still, rig.robot.read()) > MOVED


def test_estop_twice_then_one_clear(rig: Rig) -> None:
    rig.robot.estop()
    rig.robot.estop()
    assert rig.robot.estopped is True
    rig.robot.clear()
    assert rig.robot.estopped is False
    before = rig.robot.read()
    rig.drive(FORWARD, 0.5)
    assert wheels_moved(before, rig.robot.read()) > MOVED


def test_close_twice_is_harmless(rig: Rig) -> None:
    rig.drive(FORWARD, 0.1)
    rig.robot.close()
    rig.robot.close()


def test_estop_and_stop_all_never_raise_after_close(rig: Rig) -> None:
    rig.robot.close()
    rig.robot.stop_all()
    rig.robot.estop()
    assert rig.robot.estopped is True


def test_estop_never_raises_on_a_dead_link(rig: Rig) -> None:
    if rig.break_link is None:
        pytest.skip(f"{rig.kind}:// has no link to lose")
    rig.drive(FORWARD, 0.1)
    rig.break_link()
    rig.robot.stop_all()
    rig.robot.estop()
    assert rig.robot.estopped is True


# -- capabilities, as each robot should have them --------------------------------------

def test_truth_of_a_simulated_world(rig: Rig) -> None:
    """All three robots here drive a simulated world, so each tells its truth."""
    assert isinstance(rig.robot, HasTruth)
    start = rig.robot.truth()
    assert start.fell is False
    rig.drive(FORWARD, 0.5)
    moved = rig.robot.truth()
    assert moved.fell is False
    assert moved.offset_m is not None and moved.offset_m > 0.01
    assert moved.max_pitch_deg is not None and moved.max_pitch_deg < 5.0


def test_events_and_picture_as_each_robot_has_them(rig: Rig) -> None:
    """A robot on a wire reports link events; only the in-process simulation
    can be drawn."""
    wired = rig.kind != "sim"
    assert isinstance(rig.robot, ReportsEvents) is wired
    assert isinstance(rig.session.sim, HasScene) is not wired
    if not wired:
        assert rig.session.sim is rig.robot
