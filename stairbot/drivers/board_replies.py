"""The boards' ReadAll replies as a Snapshot's parts, for one robot.

:class:`ReplyReader` checks that each reply starts with its board's Status
(the robot judges the Status: a tripped watchdog is a lost link, a failed
world behind fake boards ends the run), then turns the telemetry into
stairbot's types (``telemetry.py``): every motor, the base sensors and the
side pair on a robot whose config has one, and the IMU or None.  It keeps
the IMU as last read and counts the replies whose IMU broke the protocol.

A sensor's reading is repeated between its measurements, and the board
numbers each measurement (SensorTelemetry.sample).  The reader keeps when
each sensor's current sample was taken, so a repeated sample keeps its
first reading's measurement time: the reply's transit, which varies from
read to read on a real line, cannot make an old measurement look new (and
count again where perception counts measurements in a row).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import Any

from stairbot.drivers import messages as m
from stairbot.drivers import telemetry
from stairbot.drivers import units as u
from stairbot.errors import BoardMismatchError, HardwareError
from stairbot.events import Event, EventKind, EventSink
from stairbot.hardware import Imu, MotorId, MotorState, SensorId, SensorReading

StatusCheck = Callable[[m.Board, m.Status], None]


class ReplyReader:
    """Decodes one robot's ReadAll replies.  ``url`` names the robot in
    errors; ``side_pair`` says where its config gives it the side pair (None:
    it has none); ``check_status`` is called with each reply's Status before
    its telemetry is read, and may raise."""

    def __init__(self, url: str, side_pair: str | None, check_status: StatusCheck) -> None:
        self.url = url
        self.side_pair = side_pair
        self._check_status = check_status
        self.imu_read = telemetry.ImuRead(None, "unknown")  # the IMU as last read
        self.imu_rejected = 0  # replies whose IMU broke the protocol
        # per sensor: its current sample's number and when it was taken (robot clock)
        self._taken: dict[SensorId, tuple[int, float]] = {}

    def status(self, board: m.Board, msgs: Sequence[Any]) -> m.Status:
        """The Status a ReadAll reply starts with, checked (``check_status``).
        HardwareError when the reply does not start with one."""
        if not msgs or not isinstance(msgs[0], m.Status):
            raise HardwareError(f"the {board.name.lower()} board answered ReadAll with "
                                f"{tuple(msgs)!r}")
        self._check_status(board, msgs[0])
        return msgs[0]

    def motors(self, msgs: Sequence[Any]) -> dict[MotorId, MotorState]:
        """The motor board's ReadAll reply as every motor's state, after its
        Status.  HardwareError when a channel lacks."""
        self.status(m.Board.MOTOR, msgs)
        return telemetry.channels(m.Board.MOTOR, msgs[1:], m.MotorTelemetry,
                                  m.MOTOR_CHANNELS, u.state_from_wire)

    def sensors(self, msgs: Sequence[Any], transit_s: float,
                now: float | None = None) -> dict[SensorId, SensorReading]:
        """The sensor board's ReadAll reply as readings at ``now`` (robot
        clock), after its Status: the base four, and the side pair on a robot
        that has one (``telemetry.sensors_of``).  A sample read before keeps
        the measurement time it was first read with (the module docstring);
        ``now`` None: each reading's age as the board and ``transit_s`` say.
        HardwareError when the reply is not that; BoardMismatchError (naming
        the URL) when the side pair lacks."""
        self.status(m.Board.SENSOR, msgs)
        try:
            got = telemetry.sensors_of(msgs[1:], lambda t: (t.sample, u.reading_from_wire(
                t, transit_s)), self.side_pair)
        except BoardMismatchError as exc:
            raise BoardMismatchError(f"{self.url}: {exc}") from None
        if now is None:
            return {sid: reading for sid, (_, reading) in got.items()}
        return {sid: self._aged(sid, sample, reading, now)
                for sid, (sample, reading) in got.items()}

    def _aged(self, sid: SensorId, sample: int, reading: SensorReading,
              now: float) -> SensorReading:
        """``reading`` (sample number ``sample``) with the age of its sample's
        earliest measurement time yet: a repeat is never younger than before."""
        taken = now - reading.age_s
        kept = self._taken.get(sid)
        if kept is not None and kept[0] == sample and kept[1] <= taken:
            return replace(reading, age_s=now - kept[1])
        self._taken[sid] = (sample, taken)
        return reading

    def imu(self, msgs: Sequence[Any], transit_s: float, now: float,
            sink: EventSink) -> Imu | None:
        """The IMU of the sensor board's ReadAll reply (None unless it is
        there, OK and valid).  A board that breaks the protocol is counted
        (``imu_rejected``) and told once to ``sink``, as a WARNING, until it
        mends (a value that changes every tick is one trouble, not one a tick)."""
        got = telemetry.imu_of(msgs, transit_s)
        if got.broken:
            self.imu_rejected += 1
            if got.state != self.imu_read.state:
                sink(Event(now, EventKind.WARNING, f"sensor board IMU read as none: "
                           f"{got.problem}", None, {"imu": got.state}))
        self.imu_read = got
        return got.imu

    def diagnostics(self) -> dict[str, object]:
        """The IMU as last read: its state, the problem, the replies rejected."""
        return {"state": self.imu_read.state, "problem": self.imu_read.problem,
                "rejected": self.imu_rejected}


def vars_of(ident: m.Ident) -> dict[str, int]:
    """A board's Ident as diagnostics report it."""
    return {"protocol": ident.protocol_major * 256 + ident.protocol_minor,
            "firmware": ident.firmware, "serial": ident.serial, "channels": ident.channels}


def identity(idents: Mapping[int, m.Ident], status: Mapping[int, m.Status],
             boots: Mapping[int, int]) -> dict[str, dict[str, int]]:
    """Each board's serial number, uptime (ms, from its last Status; -1
    without one) and boot id (drawn by the board at power-up): what a
    journal keeps, and what tells a resumed run whether these are the same
    boards, still running since (their counters still valid)."""
    return {m.Board(b).name.lower(): {
                "serial": ident.serial,
                "uptime_ms": status[b].uptime_ms if b in status else -1,
                "boot": boots.get(b, 0)}
            for b, ident in idents.items()}
