"""The messages of real boards, as values: what each carries, in what order.

A message is a one-byte type code and a fixed payload of at most 8 bytes
(docs/protocol.md, section 2), so the same record maps onto a serial frame
(``serial_wire``) and onto one CAN data frame (``can_wire``).  Each class says
its TYPE, its payload layout (FORMAT, struct, little-endian), whether a board
sends it (REPLY), whether a host may send it again (IDEMPOTENT) and, for a
host's message, the reply it is answered with (ANSWER).  ``messages.py`` is
the namespace everyone imports and the codec; the simulation's own messages
are the fakes' (``stairbot.fakes.sim_messages`` adds them to the codec).
"""

from __future__ import annotations

from dataclasses import dataclass
from dataclasses import fields as dataclass_fields
from typing import ClassVar, TypeVar

from stairbot.drivers.codes import ALL_MOTORS_MASK, ClearMask
from stairbot.errors import StairbotError

# The type codes of the replies a host's message is answered with (ANSWER).
IDENT, STATUS, OWNER, ACK = 0x81, 0x82, 0x83, 0xA0
MOTOR_TELEMETRY, SENSOR_TELEMETRY, IMU_TELEMETRY = 0x90, 0x91, 0x92


class CodecError(StairbotError):
    """Bytes that are not a valid message or frame.  Drivers and boards count
    these and drop the frame; they never stop on one."""


class TelemetryValueError(CodecError):
    """A message that decodes but holds a value the protocol does not allow
    (an IMU angle beyond +-180 degrees, the reserved -32768).  Its text names
    the message, the field, the value and what is allowed."""


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
    # The type of the one reply a board obeying a host's message sends (ReadAll:
    # the Status that comes before the telemetry); any message may instead be
    # answered with an Ack that refuses it.
    ANSWER: ClassVar[int] = ACK

    def fields(self) -> tuple[int, ...]:
        """The integers packed into the payload, in FORMAT order."""
        names = _NAMES.get(type(self))
        if names is None:
            names = _NAMES[type(self)] = tuple(f.name for f in dataclass_fields(self))
        return tuple([int(getattr(self, name)) for name in names])

    @classmethod
    def from_fields(cls: type[M], values: tuple[int, ...]) -> M:
        return cls(*values)


@dataclass(frozen=True, slots=True)
class RawMessage:
    """A message of a type this side does not know, kept whole (a board
    answers it with Ack(UNKNOWN_TYPE); a host passes it on in a reply)."""

    type_code: int
    payload: bytes


# ---- host -> board ---------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Identify(Message):
    """Ask a board who it is.  Reply: Ident."""

    TYPE = 0x01
    ANSWER = IDENT
    IDEMPOTENT = True


@dataclass(frozen=True, slots=True)
class Heartbeat(Message):
    """Keep the watchdog fed when there is nothing else to send.  Reply: Status."""

    TYPE = 0x02
    ANSWER = STATUS
    FORMAT = "<B"
    IDEMPOTENT = True
    counter: int = 0


@dataclass(frozen=True, slots=True)
class GetStatus(Message):
    """Ask for the board's flags and latched fault.  Reply: Status."""

    TYPE = 0x03
    ANSWER = STATUS
    IDEMPOTENT = True


@dataclass(frozen=True, slots=True)
class SetWatchdog(Message):
    """Set the watchdog timeout in ms (0 disables it) and the command hold:
    how long, in ms, a speed command keeps its motors running without a
    newer one (0: until changed).  Reply: Status."""

    TYPE = 0x04
    ANSWER = STATUS
    FORMAT = "<HH"
    timeout_ms: int
    hold_ms: int = 0


@dataclass(frozen=True, slots=True)
class EStop(Message):
    """Latch the emergency stop: every motor stops, lifts hold.  Reply: Status."""

    TYPE = 0x05
    ANSWER = STATUS


@dataclass(frozen=True, slots=True)
class Clear(Message):
    """Clear the latches named by ``mask`` (ClearMask).  Reply: Status."""

    TYPE = 0x06
    ANSWER = STATUS
    FORMAT = "<B"
    mask: int = int(ClearMask.ALL)


@dataclass(frozen=True, slots=True)
class Claim(Message):
    """Take, renew or (``lease_ms`` 0) give up this host's lease of the
    board.  ``nonce`` is drawn by the host when it opens the link, so that a
    host whose session number happens to equal the holder's cannot take its
    lease.  Sending it again has the same effect.  Reply: Owner."""

    TYPE = 0x07
    ANSWER = OWNER
    FORMAT = "<HI"
    IDEMPOTENT = True
    lease_ms: int
    nonce: int


@dataclass(frozen=True, slots=True)
class ReadAll(Message):
    """Ask for every channel at once.  Reply: Status, then one MotorTelemetry
    per motor (motor board), or one SensorTelemetry per sensor (4, or 6 with
    the side pair) and one ImuTelemetry per IMU axis (sensor board):
    ``messages.read_all_reply``."""

    TYPE = 0x10
    ANSWER = STATUS
    IDEMPOTENT = True


@dataclass(frozen=True, slots=True)
class GetMotor(Message):
    TYPE = 0x11
    ANSWER = MOTOR_TELEMETRY
    FORMAT = "<B"
    IDEMPOTENT = True
    channel: int


@dataclass(frozen=True, slots=True)
class GetSensor(Message):
    TYPE = 0x12
    ANSWER = SENSOR_TELEMETRY
    FORMAT = "<B"
    IDEMPOTENT = True
    channel: int


@dataclass(frozen=True, slots=True)
class GetImu(Message):
    """Ask the sensor board for one axis (ImuAxis) of its IMU.  Reply: ImuTelemetry."""

    TYPE = 0x13
    ANSWER = IMU_TELEMETRY
    FORMAT = "<B"
    IDEMPOTENT = True
    axis: int


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


# ---- board -> host ---------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Ident(Message):
    """Who a board is: its address, the protocol it speaks, how many channels
    it has (the motor board 6; the sensor board 4, or 6 with the side pair
    SSR/SSL: that many SensorTelemetry in its ReadAll reply), its firmware
    and serial number.  Its layout is the same in every protocol version."""

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
class Owner(Message):
    """Answer to Claim: what became of it (ClaimResult), the session that
    holds the lease now (0: none), how long it lasts from now without another
    frame from its holder (in 10 ms, saturating at 2.55 s), and the board's
    boot id: a number the board draws at power-up, so that a host can tell
    a board that restarted (its counters begun again) from one that ran on."""

    TYPE = 0x83
    FORMAT = "<BHBI"
    REPLY = True
    result: int
    session: int
    lease_cs: int
    boot: int


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
        if not (0 <= self.channel <= 0x0F and 0 <= self.mode <= 0x0F):
            raise CodecError(f"MotorTelemetry: channel {self.channel} and mode {self.mode} "
                             "must each fit a nibble (0-15)")
        return (self.channel | (self.mode << 4), self.fault, self.speed_mtps, self.turns_mt)

    @classmethod
    def from_fields(cls, values: tuple[int, ...]) -> MotorTelemetry:
        head, fault, speed, turns = values
        return cls(head & 0x0F, head >> 4, fault, speed, turns)


@dataclass(frozen=True, slots=True)
class SensorTelemetry(Message):
    """One sensor: channel, SensorCode, distance in mm, a sample counter that
    advances with every new measurement (wraps at 65536), and the reading's
    age: ms from the measurement to this reply (saturating at AGE_MAX_MS)."""

    TYPE = 0x91
    FORMAT = "<BBHHH"
    REPLY = True
    channel: int
    status: int
    distance_mm: int
    sample: int
    age_ms: int


@dataclass(frozen=True, slots=True)
class ImuTelemetry(Message):
    """One axis (ImuAxis) of the sensor board's IMU: ImuCode, the angle in
    0.01 degree, the rate in 0.1 degree/s, and the measurement's age in ms
    (saturating at AGE_MAX_MS).  Both axes of one reply come from one sample."""

    TYPE = 0x92
    FORMAT = "<BBhhH"
    REPLY = True
    axis: int
    status: int
    angle_cdeg: int
    rate_ddps: int
    age_ms: int


@dataclass(frozen=True, slots=True)
class Ack(Message):
    """Answer to a command: which type it answers and an AckResult."""

    TYPE = 0xA0
    FORMAT = "<BB"
    REPLY = True
    request: int
    result: int
