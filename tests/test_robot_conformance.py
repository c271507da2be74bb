"""Every robot keeps the Robot protocol (stairbot/hardware.py): the same tests,
parametrised over the robots stairbot ships -- ``sim://``, ``serial://`` (fake
boards on a pseudo-terminal), ``can://`` (fake boards on python-can's
virtual bus) and ``serial://`` to the boards' C firmware (firmware/, built
natively, on the same simulated world: ``fake-boards --firmware native``)
-- each opened with ``open_robot(url, config, options)``.

The fake boards run in lockstep, so every robot's time is simulated: motion is
measured in turns after the clock advances, never against the wall clock.  The
boards' own wire timeout only bounds how long a dead link is waited for.

Tests a driver does not pass yet are marked ``xfail(strict=True)`` for that
robot only, each saying why (see ``NOT_YET``): when the driver is fixed the
test passes, strict xfail reports it, and the mark is removed.

Each reading's age and the IMU are the simulation's: over a wire they must
arrive as the simulated robot's own snapshot holds them, to the wire's
resolution (docs/protocol.md) -- whatever the simulation reports, and also
for ages and an IMU that move every tick (an ``Aged`` world).
"""

from __future__ import annotations

import itertools
import math
import threading
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import can
import pytest

from stairbot.control.robot_config import load_config
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer
from stairbot.fakes.firmware_boards import FirmwareBoardServer, build_native, find_cc
from stairbot.fakes.serial_boards import PtyPair, SerialBoardServer
from stairbot.fakes.sim import motor_limits
from stairbot.hardware import (
    BASE_SENSORS,
    LIFT_MOTORS,
    WHEEL_MOTORS,
    HasScene,
    HasTruth,
    Imu,
    MotorId,
    MotorState,
    ReportsEvents,
    Robot,
    SensorId,
    SensorReading,
    Snapshot,
    Truth,
)
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario
from stairbot.run.robots import RobotOptions, RobotSession, open_robot

CONFIG: RobotConfig = load_config()
SCENARIO: Scenario = load_scenario()
TICK = CONFIG.algorithm.tick
FORWARD = dict.fromkeys(WHEEL_MOTORS, 1.0)  # turns/s: 0.5 s moves each wheel ~0.5 turn
MOVED = 0.1  # turns: a wheel that turned at least this far moved
STILL = 0.02  # turns: a wheel that turned less than this stood still
ROBOTS = ("sim", "serial", "can", "firmware")
_channels = itertools.count()


@dataclass
class Rig:
    """One opened robot, the simulated robot's own snapshot now (what the
    boards serve, for a robot on a wire), and how to break its link (None:
    it has none)."""

    kind: str
    session: RobotSession
    own: Callable[[], Snapshot]
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


class Aged:
    """The simulated robot, its readings older and an IMU added, both moving
    with time: what a simulation that models them would report (the boards
    must carry it whatever the simulation itself fills in)."""

    def __init__(self, robot: Robot) -> None:
        self.robot = robot

    def read(self) -> Snapshot:
        snap = self.robot.read()
        t = snap.time_s
        sensors: Mapping[SensorId, SensorReading] = {
            sid: replace(r, age_s=r.age_s + 0.0037 * (i + 1) + t % 0.05)
            for i, (sid, r) in enumerate(snap.sensors.items())}
        imu = Imu(pitch_deg=3.0 * math.sin(t) - 1.234, roll_deg=0.5 * math.cos(3 * t),
                  pitch_rate_dps=171.9 * math.cos(t), roll_rate_dps=-86.0 * math.sin(3 * t),
                  age_s=0.002 + t % 0.01)
        return replace(snap, sensors=sensors, imu=imu)

    def command(self, speeds: Mapping[MotorId, float]) -> None:
        self.robot.command(speeds)

    def stop_all(self) -> None:
        self.robot.stop_all()

    def truth(self) -> Truth:
        assert isinstance(self.robot, HasTruth)
        return self.robot.truth()


def open_sim() -> Iterator[Rig]:
    session = open_robot("sim://", CONFIG, RobotOptions(world=SCENARIO))
    try:
        yield Rig("sim", session, session.robot.read)  # reading again is its own snapshot
    finally:
        session.close()


def _served(kind: str, server: SerialBoardServer | CanBoardServer, url: str) -> Iterator[Rig]:
    """Serve fake boards on a thread and open ``url`` to them; stopped after."""
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()

    def stop_boards() -> None:
        server.stop()
        thread.join(5)

    def own() -> Snapshot:
        snap = server.world.snapshot()  # the instant the boards served (lockstep)
        assert snap is not None
        return snap

    try:
        session = open_robot(url, CONFIG)
        try:
            yield Rig(kind, session, own, stop_boards)
        finally:
            session.close()
    finally:
        stop_boards()


def _world(aged: bool) -> BoardWorld:
    world = make_world(CONFIG, SCENARIO, lockstep=True)
    if aged:
        world.robot = Aged(world.robot)  # type: ignore[assignment]
    return world


def open_serial(aged: bool = False) -> Iterator[Rig]:
    """Fake boards in lockstep on a pseudo-terminal, served on a thread."""
    world = _world(aged)
    pty = PtyPair()
    try:
        yield from _served("serial", SerialBoardServer(pty.master, world, make_boards(world)),
                           f"serial://{pty.path}?lockstep=1&timeout=0.5")
    finally:
        pty.close()


def open_firmware(build_dir: Path, aged: bool = False) -> Iterator[Rig]:
    """The boards' C firmware in lockstep, its programs on the world's plant
    link, the relay served on a thread."""
    world = _world(aged)
    pty = PtyPair()
    try:
        server = FirmwareBoardServer(pty.master, world, build_dir, motor_limits(CONFIG), (1, 2))
        try:
            yield from _served("firmware", server, f"serial://{pty.path}?lockstep=1&timeout=0.5")
        finally:
            server.close()
    finally:
        pty.close()


@pytest.fixture(scope="session")
def native_firmware(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The boards' native programs, built once (skipped, saying why, without a C compiler)."""
    if find_cc() is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    return build_native(tmp_path_factory.mktemp("firmware"))


def open_can(aged: bool = False) -> Iterator[Rig]:
    """Fake boards in lockstep on a fresh python-can virtual channel, served
    on a thread (one process: a virtual bus does not leave it)."""
    channel = f"conformance-{next(_channels)}"
    world = _world(aged)
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
    if kind == "firmware":
        yield from open_firmware(request.getfixturevalue("native_firmware"))
    else:
        yield from OPENERS[kind]()


# -- the protocol --------------------------------------------------------------------

def test_is_a_robot_and_starts_unlatched(rig: Rig) -> None:
    assert isinstance(rig.robot, Robot)
    assert rig.robot.estopped is False


def test_read_gives_every_sensor_and_every_motor(rig: Rig) -> None:
    snap = rig.robot.read()
    assert set(snap.sensors) == set(BASE_SENSORS) and len(BASE_SENSORS) == 4  # no side pair
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
    assert set(b.sensors) == set(BASE_SENSORS) and set(b.motors) == set(MotorId)
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


# -- what the readings are worth: ages and the IMU ------------------------------------

AGE_S, ANGLE_DEG, RATE_DPS = 0.001, 0.01, 0.1  # the wire's resolution (docs/protocol.md)
AGE_MAX_S, ANGLE_MAX_DEG, RATE_MAX_DPS = 65.535, 180.0, 3276.7


def near(got: float, want: float, resolution: float) -> bool:
    """Equal to the wire's resolution (nearest rounding: half a step)."""
    return abs(got - want) <= resolution / 2 + 1e-9


def carried(imu: Imu | None) -> Imu | None:
    """What protocol 2.0 carries of an IMU: nothing of one it cannot express
    (a number that is not one, an angle beyond +-180: the board says ERROR);
    rates and the age saturate."""
    if imu is None:
        return None
    if not all(math.isfinite(x) for x in (imu.pitch_deg, imu.roll_deg, imu.pitch_rate_dps,
                                           imu.roll_rate_dps)):
        return None
    if max(abs(imu.pitch_deg), abs(imu.roll_deg)) > ANGLE_MAX_DEG + ANGLE_DEG / 2:
        return None
    return replace(imu, pitch_rate_dps=max(-RATE_MAX_DPS, min(RATE_MAX_DPS, imu.pitch_rate_dps)),
                   roll_rate_dps=max(-RATE_MAX_DPS, min(RATE_MAX_DPS, imu.roll_rate_dps)),
                   age_s=min(AGE_MAX_S, imu.age_s))


def assert_as_reported(got: Snapshot, own: Snapshot) -> None:
    """``got`` (read through the robot) holds the ages and the IMU of ``own``
    (the simulated robot's snapshot of the same instant)."""
    assert set(got.sensors) == set(own.sensors)
    for sid in own.sensors:
        want = min(AGE_MAX_S, own.sensors[sid].age_s)
        assert near(got.sensors[sid].age_s, want, AGE_S), (sid, got.sensors[sid], want)
    want_imu = carried(own.imu)
    if want_imu is None:
        assert got.imu is None
        return
    assert got.imu is not None, own.imu
    for name, resolution in (("pitch_deg", ANGLE_DEG), ("roll_deg", ANGLE_DEG),
                             ("pitch_rate_dps", RATE_DPS), ("roll_rate_dps", RATE_DPS),
                             ("age_s", AGE_S)):
        assert near(getattr(got.imu, name), getattr(want_imu, name), resolution), (
            name, got.imu, want_imu)


def test_ages_and_imu_arrive_as_the_simulation_reports_them(rig: Rig) -> None:
    """Whatever ages and IMU the simulation fills in (none yet, or its own
    model's), every robot reports them as the simulated robot's snapshot of
    that instant holds them."""
    for _ in range(3):
        assert_as_reported(rig.robot.read(), rig.own())
        rig.drive(FORWARD, 0.1)


@pytest.fixture(params=("serial", "can", "firmware"))
def aged_rig(request: pytest.FixtureRequest) -> Iterator[Rig]:
    if request.param == "firmware":
        yield from open_firmware(request.getfixturevalue("native_firmware"), aged=True)
    else:
        yield from {"serial": open_serial, "can": open_can}[request.param](aged=True)


def test_ages_and_an_imu_that_move_each_tick_cross_the_wire(aged_rig: Rig) -> None:
    """Over an Aged world: every tick's ages and IMU arrive as reported."""
    for _ in range(10):
        got = aged_rig.robot.read()
        assert got.imu is not None
        assert_as_reported(got, aged_rig.own())
        aged_rig.robot.command(FORWARD)
        aged_rig.session.clock.advance(TICK)
