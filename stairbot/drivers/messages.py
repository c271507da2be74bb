"""The boards' messages, independent of the wire that carries them.

Two boards sit on the robot: the motor board (MWF, MWB, MWR, MWL, MTF, MTB)
and the sensor board (SFR, SFL, SBR, SBL).  The host talks to each with small
messages: a one-byte type code and a fixed payload of at most 8 bytes, so the
same model maps onto a serial frame (``serial_wire``) and onto one CAN data
frame each (the CAN driver's DBC).  ``docs/protocol.md`` is the reference a
firmware author reads; this module is its executable twin.

Units on the wire are integers: speeds in milli-turns/s (int16), turn counters
in milli-turns (int32), distances in millimetres (uint16), times in ms or us.
Everything is little-endian.  ``units.py`` converts to and from stairbot's
units and types.

Messages are values (frozen dataclasses).  ``encode(msg)`` gives
``(type_code, payload)``; ``decode(type_code, payload)`` gives the message or
raises :class:`CodecError` -- the only exception a decoder raises, whatever
the bytes.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields
from enum import IntEnum, IntFlag
from typing import ClassVar, TypeVar

from stairbot.errors import StairbotError
from stairbot.hardware import MotorId, SensorId

PROTOCOL_MAJOR = 1
PROTOCOL_MINOR = 0
MAX_PAYLOAD = 8
INT16_MAX = 32767
INT32_MAX = 2**31 - 1


class CodecError(StairbotError):
    """Bytes that are not a valid message or frame.  Drivers and boards count
    these and drop the frame; they never stop on one."""


class Board(IntEnum):
    """Board addresses (4 bits).  0 is reserved; 15 is the broadcast address."""

    MOTOR = 1
    SENSOR = 2


BROADCAST = 0x0F

# Channel numbers: the index of a motor or sensor on its board.
MOTOR_CHANNELS: tuple[MotorId, ...] = (
    MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL, MotorId.MTF, MotorId.MTB,
)
SENSOR_CHANNELS: tuple[SensorId, ...] = (SensorId.SFR, SensorId.SFL, SensorId.SBR, SensorId.SBL)
LIFT_CHANNELS: frozenset[int] = frozenset({4, 5})
ALL_MOTORS_MASK = 0x3F


class MotorMode(IntEnum):
    """What a motor is doing (4 bits in MotorTelemetry)."""

    IDLE = 0  # speed 0: a wheel coasts to rest, a lift holds
    RUN = 1  # running at a commanded speed
    MOVE = 2  # moving a commanded number of turns
    BRAKE = 3  # wheel actively braked; a lift holds
    HOLD = 4  # stopped by e-stop, watchdog or fault; a lift holds


class MotorFault(IntEnum):
    NONE = 0
    ESTOP = 1  # emergency stop latched
    WATCHDOG = 2  # the board's watchdog tripped
    OVERCURRENT = 3
    STALL = 4
    ENCODER = 5
    LIMIT = 6  # a lift at the end of its stroke refused to go further
    DRIVER = 7  # motor driver chip fault
    SIMULATION = 8  # fake boards only: the simulated world failed (a fall); see Truth


class SensorCode(IntEnum):
    OK = 0
    OUT_OF_RANGE = 1
    ERROR = 2


class StatusFlag(IntFlag):
    """Board status bits (Status.flags)."""

    ESTOP = 0x01  # emergency stop latched
    WATCHDOG = 0x02  # watchdog tripped and latched
    FAULT = 0x04  # some motor or sensor fault latched
    SIMULATED = 0x40  # a fake board (simulation), not hardware
    LOCKSTEP = 0x80  # a fake board whose physics advances only on StepTo


class ClearMask(IntFlag):
    ESTOP = 0x01
    WATCHDOG = 0x02
    FAULTS = 0x04
    ALL = 0x07


class AckResult(IntEnum):
    OK = 0
    ESTOP = 1  # refused: emergency stop latched
    WATCHDOG = 2  # refused: watchdog fault latched
    BAD_CHANNEL = 3
    BAD_VALUE = 4
    UNKNOWN_TYPE = 5
    BAD_LENGTH = 6
    NOT_SUPPORTED = 7  # e.g. StepTo on a real board


M = TypeVar("M", bound="Message")
_NAMES: dict[type, tuple[str, ...]] = {}


@dataclass(frozen=True, slots=True)
class Message:
    """Base of every message.  Subclasses set TYPE, FORMAT (struct, little-
    endian, at most 8 bytes) and the flags below."""

    TYPE: ClassVar[int] = -1
    FORMAT: ClassVar[str] = "<"
    REPLY: ClassVar[bool] = False  # True for board -> host messages
    IDEMPOTENT: ClassVar[bool] = False  # may the host retry it on a timeout?

    def fields(self) -> tuple[int, ...]:
        """The integers packed into the payload, in FORMAT order."""
        names = _NAMES.get(type(self))
        if names is None:
            names = _NAMES[type(self)] = tuple(f.name for f in dataclass_fields(self))
        return tuple([int(getattr(self, name)) for name in names])

    @classmethod
    def from_fields(cls: type[M], values: tuple[int, ...]) -> M:
        return cls(*values)


# ---- host -> board ---------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Identify(Message):
    """Ask a board who it is.  Reply: Ident."""

    TYPE = 0x01
    IDEMPOTENT = True


@dataclass(frozen=True, slots=True)
class Heartbeat(Message):
    """Keep the watchdog fed when there is nothing else to send.  Reply: Status."""

    TYPE = 0x02
    FORMAT = "<B"
    IDEMPOTENT = True
    counter: int = 0


@dataclass(frozen=True, slots=True)
class GetStatus(Message):
    """Ask for the board's flags and latched fault.  Reply: Status."""

    TYPE = 0x03
    IDEMPOTENT = True


@dataclass(frozen=True, slots=True)
class SetWatchdog(Message):
    """Set the watchdog timeout in ms (0 disables it).  Reply: Status."""

    TYPE = 0x04
    FORMAT = "<H"
    timeout_ms: int


@dataclass(frozen=True, slots=True)
class EStop(Message):
    """Latch the emergency stop: every motor stops, lifts hold.  Reply: Status."""

    TYPE = 0x05


@dataclass(frozen=True, slots=True)
class Clear(Message):
    """Clear the latches named by ``mask`` (ClearMask).  Reply: Status."""

    TYPE = 0x06
    FORMAT = "<B"
    mask: int = int(ClearMask.ALL)


@dataclass(frozen=True, slots=True)
class ReadAll(Message):
    """Ask for every channel at once.  Reply: Status, then one MotorTelemetry
    per motor (motor board) or one SensorTelemetry per sensor (sensor board)."""

    TYPE = 0x10
    IDEMPOTENT = True


@dataclass(frozen=True, slots=True)
class GetMotor(Message):
    TYPE = 0x11
    FORMAT = "<B"
    IDEMPOTENT = True
    channel: int


@dataclass(frozen=True, slots=True)
class GetSensor(Message):
    TYPE = 0x12
    FORMAT = "<B"
    IDEMPOTENT = True
    channel: int


@dataclass(frozen=True, slots=True)
class SetWheelSpeeds(Message):
    """Run the four wheel motors at these speeds (milli-turns/s).  Reply: Ack."""

    TYPE = 0x20
    FORMAT = "<hhhh"
    mwf: int
    mwb: int
    mwr: int
    mwl: int


@dataclass(frozen=True, slots=True)
class SetLiftSpeeds(Message):
    """Run the two lifts at these speeds (milli-turns/s; 0 holds).  Reply: Ack."""

    TYPE = 0x21
    FORMAT = "<hh"
    mtf: int
    mtb: int


@dataclass(frozen=True, slots=True)
class Run(Message):
    """Run one motor forward (>0) or back (<0) at a speed.  Reply: Ack."""

    TYPE = 0x22
    FORMAT = "<Bh"
    channel: int
    speed_mtps: int


@dataclass(frozen=True, slots=True)
class Move(Message):
    """Move one motor by ``turns_mt`` milli-turns (sign = direction) at
    ``speed_mtps`` (> 0), then stop (IDLE).  Not idempotent.  Reply: Ack."""

    TYPE = 0x23
    FORMAT = "<BiH"
    channel: int
    turns_mt: int
    speed_mtps: int


@dataclass(frozen=True, slots=True)
class Stop(Message):
    """Set the speed of the motors in ``mask`` (bit n = channel n) to 0:
    wheels coast to rest, lifts hold.  Reply: Ack."""

    TYPE = 0x24
    FORMAT = "<B"
    mask: int = ALL_MOTORS_MASK


@dataclass(frozen=True, slots=True)
class Brake(Message):
    """Brake the wheels in ``mask`` actively; lifts in it hold.  Reply: Ack."""

    TYPE = 0x25
    FORMAT = "<B"
    mask: int = ALL_MOTORS_MASK


@dataclass(frozen=True, slots=True)
class StepTo(Message):
    """Simulation only (LOCKSTEP fake boards): advance the simulated world to
    ``time_us`` microseconds since start; earlier times are a no-op, so the
    message is idempotent.  Sent to the motor board.  Reply: StepDone."""

    TYPE = 0x7E
    FORMAT = "<I"
    IDEMPOTENT = True
    time_us: int


@dataclass(frozen=True, slots=True)
class GetTruth(Message):
    """Simulation only: ask the fake boards for the simulated world's truth
    (not something a real robot knows).  Sent to the motor board.  Reply: Truth."""

    TYPE = 0x7D
    IDEMPOTENT = True


# ---- board -> host ---------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Ident(Message):
    TYPE = 0x81
    FORMAT = "<BBBBHH"
    REPLY = True
    board: int
    protocol_major: int
    protocol_minor: int
    channels: int
    firmware: int
    serial: int


@dataclass(frozen=True, slots=True)
class Status(Message):
    """Board flags (StatusFlag), the first latched fault (MotorFault), the
    watchdog timeout and the board's uptime (ms, wraps)."""

    TYPE = 0x82
    FORMAT = "<BBHI"
    REPLY = True
    flags: int
    fault: int
    watchdog_ms: int
    uptime_ms: int


@dataclass(frozen=True, slots=True)
class MotorTelemetry(Message):
    """One motor: channel (low nibble) and MotorMode (high nibble) in byte 0,
    MotorFault, speed in milli-turns/s, turn counter in milli-turns."""

    TYPE = 0x90
    FORMAT = "<BBhi"
    REPLY = True
    channel: int
    mode: int
    fault: int
    speed_mtps: int
    turns_mt: int

    def fields(self) -> tuple[int, ...]:
        return ((self.channel & 0x0F) | ((self.mode & 0x0F) << 4), self.fault,
                self.speed_mtps, self.turns_mt)

    @classmethod
    def from_fields(cls, values: tuple[int, ...]) -> MotorTelemetry:
        head, fault, speed, turns = values
        return cls(head & 0x0F, head >> 4, fault, speed, turns)


@dataclass(frozen=True, slots=True)
class SensorTelemetry(Message):
    """One sensor: channel, SensorCode, distance in mm, and a sample counter
    that advances with every new measurement (wraps at 65536)."""

    TYPE = 0x91
    FORMAT = "<BBHH"
    REPLY = True
    channel: int
    status: int
    distance_mm: int
    sample: int


@dataclass(frozen=True, slots=True)
class Ack(Message):
    """Answer to a command: which type it answers and an AckResult."""

    TYPE = 0xA0
    FORMAT = "<BB"
    REPLY = True
    request: int
    result: int


@dataclass(frozen=True, slots=True)
class StepDone(Message):
    TYPE = 0xFE
    FORMAT = "<I"
    REPLY = True
    time_us: int


@dataclass(frozen=True, slots=True)
class Truth(Message):
    """Simulation only: bit 0 of ``flags`` = the robot fell; the largest pitch
    so far in centi-degrees; the robot's offset from its start in mm."""

    TYPE = 0xFD
    FORMAT = "<Bxhi"
    REPLY = True
    flags: int
    max_pitch_cdeg: int
    offset_mm: int


MESSAGES: dict[int, type[Message]] = {
    cls.TYPE: cls
    for cls in (
        Identify, Heartbeat, GetStatus, SetWatchdog, EStop, Clear, ReadAll, GetMotor,
        GetSensor, SetWheelSpeeds, SetLiftSpeeds, Run, Move, Stop, Brake, StepTo, GetTruth,
        Ident, Status, MotorTelemetry, SensorTelemetry, Ack, StepDone, Truth,
    )
}
_STRUCTS: dict[int, struct.Struct] = {t: struct.Struct(c.FORMAT) for t, c in MESSAGES.items()}
assert all(s.size <= MAX_PAYLOAD for s in _STRUCTS.values())


def payload_size(type_code: int) -> int:
    """The payload length of a message type; CodecError for an unknown type."""
    s = _STRUCTS.get(type_code)
    if s is None:
        raise CodecError(f"unknown message type 0x{type_code:02X}")
    return s.size


def encode(msg: Message) -> tuple[int, bytes]:
    """``(type_code, payload)`` of a message.  Raises CodecError when a field
    does not fit its wire type."""
    try:
        return msg.TYPE, _STRUCTS[msg.TYPE].pack(*msg.fields())
    except struct.error as exc:
        raise CodecError(f"{type(msg).__name__}: {exc}") from None


def decode(type_code: int, payload: bytes) -> Message:
    """The message of this type and payload.  Raises CodecError (only) for an
    unknown type or a payload of the wrong length."""
    s = _STRUCTS.get(type_code)
    if s is None:
        raise CodecError(f"unknown message type 0x{type_code:02X}")
    if len(payload) != s.size:
        raise CodecError(
            f"{MESSAGES[type_code].__name__}: payload of {len(payload)} bytes, expected {s.size}")
    return MESSAGES[type_code].from_fields(s.unpack(payload))
