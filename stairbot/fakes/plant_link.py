"""The plant link: the simulated world behind a firmware board.

A board built from ``firmware/`` on a simulated plant (``firmware/plant``)
asks this end for its motors' counters and its sensors' readings over a
byte stream of its own, and sends its motors' commands there.  Frames are
COBS-stuffed and 0x00-delimited, as the host's wire (section 5 of
docs/protocol.md): a kind byte, the request's sequence number, little-endian
fields, then the CRC-16/CCITT-FALSE of all that, big-endian.
firmware/README.md ("The plant link") lists the frames.

:class:`PlantLink` answers one board from a
:class:`~stairbot.fakes.board_world.BoardWorld`: the world's time is the
board's clock, so in lockstep the board's watchdog and Moves see exactly
the time the host stepped to.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from dataclasses import dataclass

from cobs import cobs

from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.drivers.serial_wire import crc16
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.motor_faults import wire_fault
from stairbot.hardware import MotorId, Snapshot

# Frame kinds: the board's requests in capitals, the plant's answers in small letters.
HELLO, QUERY, MOTOR, STEP, TRUTH = b"HQMST"
INFO, MOTOR_STATE, SENSOR_STATE, STEPPED, TRUTH_IS = b"hmnst"

_INFO = struct.Struct("<BHBB6h")
_STATE_HEAD = struct.Struct("<QB")
_MOTOR = struct.Struct("<ihB")
_RANGE = struct.Struct("<BBHI")
_AXIS = struct.Struct("<BhhI")
_MOTOR_CMD = struct.Struct("<BhB")
_STEPPED = struct.Struct("<BI")
_TRUTH = struct.Struct("<BBhi")
_NEVER_US = 70_000_000  # a sample this old has an age beyond the wire's 65,535 ms


class Delimited:
    """A byte stream cut into 0x00-delimited frames, each kept with its
    delimiter; empty frames (a lone delimiter) are skipped."""

    def __init__(self) -> None:
        self.pending = bytearray()

    def frames(self, data: bytes) -> list[bytes]:
        """The frames ``data`` completes (a partial one waits for the rest)."""
        self.pending += data
        out = []
        while (end := self.pending.find(0)) >= 0:
            frame = bytes(self.pending[:end + 1])
            del self.pending[:end + 1]
            if len(frame) > 1:
                out.append(frame)
        return out


class PlantLinkError(ValueError):
    """A plant-link frame that cannot be read."""


def encode(kind: int, seq: int, fields: bytes = b"") -> bytes:
    """One frame on the wire: stuffed, CRC'd and delimited."""
    body = bytes((kind, seq & 0xFF)) + fields
    return cobs.encode(body + crc16(body).to_bytes(2, "big")) + b"\x00"


def decode(stuffed: bytes) -> tuple[int, int, bytes]:
    """(kind, seq, fields) of one frame's bytes (without the delimiter)."""
    try:
        body = cobs.decode(stuffed)
    except cobs.DecodeError as exc:
        raise PlantLinkError(f"not a COBS frame: {exc}") from exc
    if len(body) < 4:
        raise PlantLinkError(f"a frame of {len(body)} bytes: at least 4 (kind, seq, CRC)")
    if crc16(body[:-2]) != int.from_bytes(body[-2:], "big"):
        raise PlantLinkError("CRC mismatch")
    return body[0], body[1], body[2:-2]


@dataclass
class LinkStats:
    queries: int = 0
    commands: int = 0
    steps: int = 0
    bad: int = 0  # frames that could not be read or asked for nothing known


class PlantLink:
    """One board's end of the plant link: feed it the bytes the board sent,
    send back what :meth:`feed` returns.  ``board``: 1 the motor board, 2
    the sensor board (it must greet as that board); ``serial``: the serial
    number the plant gives it; ``limits_tps``: each motor's speed limit;
    ``after_step``: called each time a StepTo moved the world.  A query
    carries the board's Status.flags (``board_flags``), which the fault
    matrix reads to see its latches without a host."""

    def __init__(self, world: BoardWorld, board: int, serial: int,
                 limits_tps: dict[MotorId, float],
                 after_step: Callable[[], None] | None = None) -> None:
        self.world = world
        self.after_step = after_step
        self.board_flags = 0  # the board's Status.flags, as its last query said
        self.board = board
        self.serial = serial
        self.limits_tps = limits_tps
        self.stats = LinkStats()
        self.greeted = False
        self._line = Delimited()
        self._state: tuple[float, bytes] | None = None  # (world time, the state's fields)

    def feed(self, data: bytes) -> bytes:
        """The answers to the complete frames in ``data`` (and those before it)."""
        out = bytearray()
        for wire in self._line.frames(data):
            try:
                kind, seq, fields = decode(wire[:-1])
                out += self._answer(kind, seq, fields)
            except (PlantLinkError, struct.error):
                self.stats.bad += 1
        return bytes(out)

    def _answer(self, kind: int, seq: int, fields: bytes) -> bytes:
        if kind == HELLO:
            (board,) = struct.unpack("<B", fields)
            if board != self.board:
                raise PlantLinkError(f"hello from board {board}, this link serves {self.board}")
            self.greeted = True
            return encode(INFO, seq, self._info())
        if kind == QUERY:
            (self.board_flags,) = struct.unpack("<B", fields)
            self.stats.queries += 1
            return encode(MOTOR_STATE if self.board == 1 else SENSOR_STATE, seq, self._fields())
        if kind == MOTOR:
            ch, mtps, _brake = _MOTOR_CMD.unpack(fields)
            if ch >= len(m.MOTOR_CHANNELS) or self.board != 1:
                raise PlantLinkError(f"a motor command for channel {ch}")
            self.stats.commands += 1
            self.world.set_speeds({m.MOTOR_CHANNELS[ch]: u.speed_from_wire(mtps)})
            self._state = None
            return b""
        if kind == STEP:
            (time_us,) = struct.unpack("<I", fields)
            if not self.world.lockstep:
                return encode(STEPPED, seq, _STEPPED.pack(0, 0))
            self.stats.steps += 1
            done = self.world.step_to(time_us)
            if self.after_step is not None:
                self.after_step()
            return encode(STEPPED, seq, _STEPPED.pack(1, done & 0xFFFFFFFF))
        if kind == TRUTH:
            t = self.world.truth()
            return encode(TRUTH_IS, seq, _TRUTH.pack(1, t.flags & 1, t.max_pitch_cdeg,
                                                     t.offset_mm))
        raise PlantLinkError(f"unknown kind {kind:#04x}")

    def _info(self) -> bytes:
        channels = len(m.MOTOR_CHANNELS) if self.board == 1 else self._sensor_channels()
        limits = [u.speed_to_wire(self.limits_tps[mid]) for mid in m.MOTOR_CHANNELS]
        return _INFO.pack(self.board, self.serial, int(self.world.lockstep), channels, *limits)

    def _sensor_channels(self) -> int:
        """The sensor board's range channels: 4, or 6 with the side pair."""
        return max(m.SIDE_SENSOR_CHANNELS) + 1 if self.world.side_pair \
            else m.BASE_SENSOR_CHANNELS

    def _fields(self) -> bytes:
        """The state's fields at the world's present time (kept while it stands)."""
        now = self.world.now()
        if self._state is not None and self._state[0] == now:
            return self._state[1]
        snap = self.world.snapshot()
        now_us = round(now * 1e6)
        head = _STATE_HEAD.pack(now_us, int(self.world.failure is not None))
        body = self._motors(snap) if self.board == 1 else self._sensors(snap, now_us)
        self._state = (now, head + body)
        return head + body

    def _motors(self, snap: Snapshot | None) -> bytes:
        out = bytearray()
        for mid in m.MOTOR_CHANNELS:
            state = snap.motors[mid] if snap else None
            fault = int(wire_fault(state.fault)) if state is not None else 0
            out += _MOTOR.pack(u.turns_to_wire(state.turns if state else 0.0),
                               u.speed_to_wire(state.speed_tps if state else 0.0), fault)
        return bytes(out)

    def _sensors(self, snap: Snapshot | None, now_us: int) -> bytes:
        channels = self._sensor_channels()
        out = bytearray((channels,))
        snap_us = round(snap.time_s * 1e6) if snap else now_us
        for ch in range(channels):
            r = snap.sensors.get(m.SENSOR_CHANNELS[ch]) if snap else None
            if r is None:  # never measured
                out += _RANGE.pack(0, int(m.SensorCode.ERROR), 0, 0)
                continue
            reading = u.reading_to_wire(ch, r, 0)
            out += _RANGE.pack(1, reading.status, reading.distance_mm,
                               _measured_us(snap_us, r.age_s))
        if snap is None:  # the world failed before its first reading
            out += bytes((1,)) + _AXIS.pack(int(m.ImuCode.ERROR), 0, 0,
                                            (now_us - _NEVER_US) & 0xFFFFFFFF) * 2
            return bytes(out)
        out += bytes((int(snap.imu is not None),))
        for axis in m.IMU_AXES:
            if snap.imu is None:
                out += _AXIS.pack(int(m.ImuCode.ABSENT), 0, 0, 0)
                continue
            sample = u.imu_to_wire(snap.imu, axis)
            out += _AXIS.pack(sample.status, sample.angle_cdeg, sample.rate_ddps,
                              _measured_us(snap_us, snap.imu.age_s))
        return bytes(out)


def _measured_us(snap_us: int, age_s: float) -> int:
    """When a sample ``age_s`` old at the snapshot's time ``snap_us`` was
    taken, on the board's 32-bit microsecond clock."""
    if not math.isfinite(age_s) or age_s * 1e6 >= _NEVER_US:
        return (snap_us - _NEVER_US) & 0xFFFFFFFF
    return (snap_us - round(age_s * 1e6)) & 0xFFFFFFFF


__all__ = ["Delimited", "LinkStats", "PlantLink", "PlantLinkError", "decode", "encode"]
