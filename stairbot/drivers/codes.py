"""The numbers and codes of the boards' protocol (docs/protocol.md, sections
1 and 2, "Codes"): the protocol version, board addresses, channel order, and
the code tables the messages carry.  Pure data: no message, no wire.
"""

from __future__ import annotations

from enum import IntEnum, IntFlag

from stairbot.hardware import MotorId, SensorId

# 2.0: SensorTelemetry carries its reading's age (8 bytes, was 6); the sensor
# board's IMU (ImuTelemetry, GetImu).  A host refuses a board of another major
# version; Ident keeps its layout in every version so that it can tell.
# 3.0: the serial frame header has a length byte, flagged by address bit 4
# (serial_wire.py); CAN frames are unchanged.
# 4.0: CAN ids are 29 bits and carry the host's session and a seq (can_wire.py).
# 4.1: sensor channels 4 and 5, the side pair SSR and SSL (quarter-turn
# landings).  A sensor board with them says 6 channels in its Ident and sends
# 6 SensorTelemetry in its ReadAll reply; one without says 4 and sends 4, as
# before.  A 4.0 host reads channels 0-3 of either (on CAN it counts the two
# side frames it did not expect as stray); a 4.1 host reads a 4.0 board as one
# without the side pair.
# 5.0: one host owns the boards.  A host takes a board with Claim (a lease of
# its session, renewed by every frame it sends); while the lease is live the
# board refuses another session's motion commands, SetWatchdog, Clear and
# StepTo (Ack NOT_OWNER), and only the owner's frames feed the watchdog.
# Claim's reply, Owner, names the holder and carries the board's boot id.
# SetWatchdog(0) is refused while a motor may move.
PROTOCOL_MAJOR = 5
PROTOCOL_MINOR = 0
MAX_PAYLOAD = 8
INT16_MAX = 32767
INT16_NONE = -32768  # never sent in an IMU field: a board's "no number" (NaN)
INT32_MAX = 2**31 - 1
AGE_MAX_MS = 65535  # a telemetry age saturates here: "this old or older"
ANGLE_MAX_CDEG = 18000  # an IMU angle lies within +-180.00 degrees


class Board(IntEnum):
    """Board addresses (4 bits).  0 is reserved; 15 is the broadcast address."""

    MOTOR = 1
    SENSOR = 2


BROADCAST = 0x0F

# Channel numbers: the index of a motor or sensor on its board.
MOTOR_CHANNELS: tuple[MotorId, ...] = (
    MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL, MotorId.MTF, MotorId.MTB,
)
SENSOR_CHANNELS: tuple[SensorId, ...] = (
    SensorId.SFR, SensorId.SFL, SensorId.SBR, SensorId.SBL, SensorId.SSR, SensorId.SSL,
)
"""Every sensor channel a sensor board may have, in channel order."""
BASE_SENSOR_CHANNELS = 4
"""Channels 0-3 (SFR, SFL, SBR, SBL): every sensor board has them."""
SIDE_SENSOR_CHANNELS: tuple[int, ...] = (4, 5)
"""SSR and SSL, the side pair: a sensor board has both or neither (4.1)."""
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


class ImuAxis(IntEnum):
    """Which axis an ImuTelemetry is about (the sensor board's IMU "channels")."""

    PITCH = 0  # positive nose up (the front higher than the back)
    ROLL = 1  # positive right side down


IMU_AXES: tuple[ImuAxis, ...] = (ImuAxis.PITCH, ImuAxis.ROLL)


class ImuCode(IntEnum):
    """ImuTelemetry.status.  Anything but OK (an unknown code too) means the
    angle and rate carry nothing: the host reads no IMU."""

    OK = 0
    ABSENT = 1  # no IMU fitted on this board
    ERROR = 2  # the IMU reports a fault, or has no valid measurement yet


class StatusFlag(IntFlag):
    """Board status bits (Status.flags)."""

    ESTOP = 0x01  # emergency stop latched
    WATCHDOG = 0x02  # watchdog tripped and latched
    FAULT = 0x04  # some motor or sensor fault latched
    SIMULATED = 0x40  # a fake board (simulation), not hardware
    LOCKSTEP = 0x80  # a fake board whose physics advances only on StepTo


class ClaimResult(IntEnum):
    """Owner.result: what became of a Claim."""

    GRANTED = 0  # the lease is the claiming host's (taken or renewed)
    HELD = 1  # another host's lease is live: nothing changed
    RELEASED = 2  # the claiming host gave its lease up (lease_ms 0)
    FREE = 3  # lease_ms 0 from a host that held none: nothing changed


LEASE_MS = 1000
"""The lease a host claims unless told otherwise (ms of the board's clock);
a board keeps a lease at least as long as its watchdog timeout."""


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
    NOT_OWNER = 8  # refused: another host's lease is live, or this host holds none
