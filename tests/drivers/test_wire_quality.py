"""Each reading's age and the sensor board's IMU on both wires (protocol 2.0):
they arrive as the boards' world holds them, to the wire's resolution; the
time a reply took is added to the age; a board of protocol 1 is refused with
one error; and IMU values the protocol does not allow read as no IMU, never
as a number.  The boards are served inline (no thread), in lockstep, over a
world whose snapshot the test sets."""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import replace

import can
import pytest
from cobs import cobs
from scripted_boards import WIRES, Boards, Scripted, ScriptedClock, link_to, wired

import stairbot.fakes.lockstep  # noqa: F401 - registers the lockstep robot with the drivers
from stairbot.drivers import messages as m
from stairbot.drivers.board_robot import BoardRobot
from stairbot.drivers.board_session import open_board_session
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.can_wire import wire
from stairbot.drivers.serial_wire import FrameReader, crc16
from stairbot.errors import ProtocolVersionError
from stairbot.events import EventKind
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import Board, SensorBoard, make_boards
from stairbot.hardware import BASE_SENSORS, Imu, SensorId

_channels = itertools.count()
AGES = dict(zip(BASE_SENSORS, (0.0123, 0.2, 1.5, 100.0), strict=True))  # the last saturates
IMU = Imu(5.234, -0.756, 1.52, -0.24, 0.0031)


def near(a: float, b: float, resolution: float) -> bool:
    return abs(a - b) <= resolution / 2 + 1e-9


@pytest.mark.parametrize("kind", WIRES)
def test_ages_and_imu_arrive_to_the_wires_resolution(kind: str) -> None:
    with wired(kind) as (host, robot, _):
        robot.ages, robot.imu = AGES, IMU
        host.clock.advance(0.02)
        snap = host.read()
        assert [snap.sensors[s].age_s for s in BASE_SENSORS] == [0.012, 0.2, 1.5, 65.535]
        assert set(snap.sensors) == set(BASE_SENSORS)  # this robot has no side pair
        assert snap.imu is not None
        assert near(snap.imu.pitch_deg, IMU.pitch_deg, 0.01)
        assert near(snap.imu.roll_deg, IMU.roll_deg, 0.01)
        assert near(snap.imu.pitch_rate_dps, IMU.pitch_rate_dps, 0.1)
        assert near(snap.imu.roll_rate_dps, IMU.roll_rate_dps, 0.1)
        assert near(snap.imu.age_s, IMU.age_s, 0.001)
        assert host.diagnostics()["imu"] == {"state": "ok", "problem": None, "rejected": 0}


@pytest.mark.parametrize("kind", WIRES)
def test_no_imu_and_a_failed_imu_read_as_none(kind: str) -> None:
    with wired(kind) as (host, robot, events):
        assert host.read().imu is None  # the world has no IMU: the board says ABSENT
        assert host.replies.imu_read.state == "absent"
        robot.imu = replace(IMU, roll_deg=float("nan"))  # the board says ERROR
        host.clock.advance(0.02)
        assert host.read().imu is None
        assert host.replies.imu_read.state == "error"
        assert host.replies.imu_rejected == 0 and not events  # the board kept the protocol


def test_the_age_counts_the_time_the_reply_took() -> None:
    """Away from lockstep the robot's clock runs while the host waits for
    the boards: that time is added to every age (here 7 ms between sending
    ReadAll and the snapshot, on a clock that moves 7 ms each time it is read)."""

    class Ticking:
        def __init__(self) -> None:
            self.t = 0.0

        def now(self) -> float:
            self.t += 0.007
            return self.t

        def advance(self, dt: float) -> None:
            self.t += dt

    robot = Scripted()
    robot.ages, robot.imu = AGES, IMU
    world = BoardWorld(robot, ScriptedClock(robot), lockstep=False)
    with link_to("serial", world, make_boards(world)) as link:
        host = BoardRobot(link, "serial://inline", watchdog_ms=0, clock=Ticking(),
                          keepalive=False)
        snap = host.read()
        host.close()
    assert snap.sensors[SensorId.SFR].age_s == pytest.approx(0.012 + 0.007)
    assert snap.sensors[SensorId.SBL].age_s == pytest.approx(65.535 + 0.007)  # at least
    assert snap.imu is not None and snap.imu.age_s == pytest.approx(0.003 + 0.007)


# -- a board of protocol 1 ---------------------------------------------------------


class Protocol1Sensor(SensorBoard):
    """A sensor board of protocol 1.0 (its Ident says so; Ident has one layout
    in every version)."""

    def answer(self, msg: m.Message) -> list[m.Message]:
        if isinstance(msg, m.Identify):
            return [m.Ident(self.BOARD, 1, 0, self.CHANNELS, 0x0100, self.serial)]
        return super().answer(msg)


def protocol1_boards(world: BoardWorld) -> dict[int, Board]:
    boards = make_boards(world)
    boards[m.Board.SENSOR] = Protocol1Sensor(world)
    return boards


@pytest.mark.parametrize("kind", WIRES)
def test_a_protocol_1_board_is_refused_with_one_error(kind: str) -> None:
    robot = Scripted()
    world = BoardWorld(robot, ScriptedClock(robot), lockstep=True)
    with (link_to(kind, world, protocol1_boards(world)) as link,
          pytest.raises(ProtocolVersionError) as info):
        open_board_session(link, f"{kind}://old", watchdog_ms=250, lockstep=True,
                           time_scale=1.0)
    assert str(info.value) == (
        f"{kind}://old: the sensor board speaks protocol 1.0; this host speaks "
        f"{m.PROTOCOL_MAJOR}.x "
        "(docs/protocol.md): update the board's firmware or the host")


def test_a_protocol_1_sensor_telemetry_is_malformed_on_both_wires_never_misread() -> None:
    old = bytes.fromhex("00 00 f1 01 2a 00")  # channel 0, ok, 497 mm, sample 42: 6 bytes
    with pytest.raises(m.CodecError, match="SensorTelemetry: payload of 6 bytes, expected 8"):
        m.decode(m.SensorTelemetry.TYPE, old)
    with pytest.raises(m.CodecError, match="SensorTelemetry_Sensor: 6 data bytes, expected 8"):
        wire().decode(0x232 << 18, old)


# -- IMU values the protocol does not allow ----------------------------------------


def sensor_boards_sending(imu: Callable[[m.ImuAxis], m.ImuTelemetry | None]) -> Boards:
    """Boards whose sensor board sends ``imu(axis)`` for each axis (None: leaves
    that axis out of the reply)."""

    class Broken(SensorBoard):
        def answer(self, msg: m.Message) -> list[m.Message]:
            replies = super().answer(msg)
            if not isinstance(msg, m.ReadAll):
                return replies
            kept = [r for r in replies if not isinstance(r, m.ImuTelemetry)]
            return kept + [t for t in map(imu, m.IMU_AXES) if t is not None]

    def make(world: BoardWorld) -> dict[int, Board]:
        boards = make_boards(world)
        boards[m.Board.SENSOR] = Broken(world)
        return boards

    return make


def ok_axis(axis: m.ImuAxis) -> m.ImuTelemetry:
    return m.ImuTelemetry(int(axis), m.ImuCode.OK, 100, 10, 2)


@pytest.mark.parametrize("kind", WIRES)
@pytest.mark.parametrize(("bad", "problem"), [
    (lambda n: m.ImuTelemetry(1, m.ImuCode.OK, 20000 + n, 0, 2),
     "(roll) angle_cdeg = 2000"),
    (lambda n: m.ImuTelemetry(1, m.ImuCode.OK, n, -32768, 2),
     "(roll) rate_ddps = -32768: allowed"),
], ids=["angle-beyond-180", "rate-not-a-number"])
def test_an_imu_value_the_protocol_forbids_reads_as_no_imu(
        kind: str, bad: Callable[[int], m.ImuTelemetry], problem: str) -> None:
    """The bad value changes every tick: still one trouble, told once."""
    count = itertools.count()

    def imu(axis: m.ImuAxis) -> m.ImuTelemetry:
        return bad(next(count)) if axis == m.ImuAxis.ROLL else ok_axis(axis)

    with wired(kind, sensor_boards_sending(imu)) as (host, _, events):
        for _ in range(3):
            snap = host.read()
            assert snap.imu is None
            assert set(snap.sensors) == set(BASE_SENSORS)  # the distances still count
            host.clock.advance(0.02)
        diag = host.diagnostics()["imu"]
        assert isinstance(diag, dict) and diag["state"] == "invalid" and diag["rejected"] == 3
        assert problem in str(diag["problem"])
        warnings = [e for e in events if e.kind is EventKind.WARNING]
        assert len(warnings) == 1 and problem in warnings[0].message  # told once


@pytest.mark.parametrize("kind", WIRES)
def test_an_unknown_imu_status_reads_as_a_failed_imu(kind: str) -> None:
    boards = sensor_boards_sending(lambda a: m.ImuTelemetry(int(a), 7, 20000, -32768, 0))
    with wired(kind, boards) as (host, _, events):
        assert host.read().imu is None
        assert host.replies.imu_read.state == "error" and not events


def test_a_serial_reply_without_an_imu_axis_reads_as_no_imu() -> None:
    """(On CAN a reply lacking a frame never completes: that is a lost link.)"""
    boards = sensor_boards_sending(lambda a: ok_axis(a) if a == m.ImuAxis.PITCH else None)
    with wired("serial", boards) as (host, _, events):
        assert host.read().imu is None
        assert host.replies.imu_read.state == "missing"
        assert host.replies.imu_read.problem == (
            "the sensor board's ReadAll reply has no ImuTelemetry for roll")
        assert len(events) == 1


def test_an_imu_frame_of_the_wrong_length_is_malformed_on_both_wires() -> None:
    """Counted and dropped by the receiver (CodecError inside), never decoded."""
    body = bytearray((0x92, 0x5A, 5, 9, m.ImuTelemetry.TYPE, 7, 0, 0, 0x0B, 0x02, 0x0F, 0x00, 0x03))
    body += crc16(bytes(body)).to_bytes(2, "big")  # a good CRC over a 7-byte ImuTelemetry
    reader = FrameReader()
    assert reader.feed(cobs.encode(bytes(body)) + b"\x00") == []
    assert reader.stats.malformed == 1 and "ImuTelemetry" in str(reader.last_error)
    link = CanLink(can.Bus(interface="virtual", channel=f"quality-{next(_channels)}"))
    try:
        link.take(can.Message(arbitration_id=0x272, data=bytes(7), is_extended_id=False))
        assert link.stats.malformed == 1
    finally:
        link.close()
