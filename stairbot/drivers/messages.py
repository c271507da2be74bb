"""The boards' messages, independent of the wire that carries them, and their codec.

Two boards sit on the robot: the motor board (MWF, MWB, MWR, MWL, MTF, MTB)
and the sensor board (SFR, SFL, SBR, SBL, and on a robot with the side pair
SSR, SSL).  The host talks to each with small
messages: a one-byte type code and a fixed payload of at most 8 bytes, so the
same model maps onto a serial frame (``serial_wire``) and onto one CAN data
frame each (the CAN driver's DBC).  ``docs/protocol.md`` is the reference a
firmware author reads; this package is its executable twin:

* ``codes.py``        -- protocol version, boards, channels, code tables;
* ``records.py``      -- the real boards' messages (host -> board, board -> host);
* ``sim_messages.py`` -- the fake boards' simulation-only messages (StepTo,
  GetTruth and their replies), on the same wire;
* this module        -- one namespace for all of them (``from stairbot.drivers
  import messages as m``) and the codec.

Units on the wire are integers: speeds in milli-turns/s (int16), turn counters
in milli-turns (int32), distances in millimetres (uint16), times and ages in ms
or us, IMU angles in 0.01 degree and rates in 0.1 degree/s (int16).
Everything is little-endian.  ``units.py`` converts to and from stairbot's
units and types.

Messages are values (frozen dataclasses).  ``encode(msg)`` gives
``(type_code, payload)``; ``decode(type_code, payload)`` gives the message or
raises :class:`CodecError` -- the only exception a decoder raises, whatever
the bytes.
"""

from __future__ import annotations

import struct

from stairbot.drivers.codes import (
    AGE_MAX_MS,
    ALL_MOTORS_MASK,
    ANGLE_MAX_CDEG,
    BASE_SENSOR_CHANNELS,
    BROADCAST,
    IMU_AXES,
    INT16_MAX,
    INT16_NONE,
    INT32_MAX,
    LEASE_MS,
    LIFT_CHANNELS,
    MAX_PAYLOAD,
    MOTOR_CHANNELS,
    PROTOCOL_MAJOR,
    PROTOCOL_MINOR,
    SENSOR_CHANNELS,
    SIDE_SENSOR_CHANNELS,
    AckResult,
    Board,
    ClaimResult,
    ClearMask,
    ImuAxis,
    ImuCode,
    MotorFault,
    MotorMode,
    SensorCode,
    StatusFlag,
)
from stairbot.drivers.records import (
    Ack,
    Brake,
    Claim,
    Clear,
    CodecError,
    EStop,
    GetImu,
    GetMotor,
    GetSensor,
    GetStatus,
    Heartbeat,
    Ident,
    Identify,
    ImuTelemetry,
    Message,
    MotorTelemetry,
    Move,
    Owner,
    RawMessage,
    ReadAll,
    Run,
    SensorTelemetry,
    SetLiftSpeeds,
    SetWatchdog,
    SetWheelSpeeds,
    Status,
    Stop,
    TelemetryValueError,
)
from stairbot.drivers.sim_messages import GetTruth, StepDone, StepTo, Truth

MESSAGES: dict[int, type[Message]] = {
    cls.TYPE: cls
    for cls in (
        Identify, Heartbeat, GetStatus, SetWatchdog, EStop, Clear, ReadAll, GetMotor,
        GetSensor, GetImu, SetWheelSpeeds, SetLiftSpeeds, Run, Move, Stop, Brake, StepTo,
        GetTruth, Ident, Status, MotorTelemetry, SensorTelemetry, ImuTelemetry, Ack, StepDone,
        Truth, Claim, Owner,
    )
}
_STRUCTS: dict[int, struct.Struct] = {t: struct.Struct(c.FORMAT) for t, c in MESSAGES.items()}
assert all(s.size <= MAX_PAYLOAD for s in _STRUCTS.values())


def read_all_reply(board: int, channels: int | None = None) -> tuple[type[Message], ...]:
    """What a board obeying ReadAll sends, in order (docs/protocol.md, section
    3): its Status, one telemetry message per channel, and on the sensor board
    one ImuTelemetry per IMU axis.  ``channels``: how many its Ident says it
    has (a sensor board 4, or 6 with the side pair); None: the board's base
    (6 motors, 4 sensors).  A board of no known address answers with its Status."""
    if board == Board.MOTOR:
        return (Status, *(MotorTelemetry,) * (channels or len(MOTOR_CHANNELS)))
    if board == Board.SENSOR:
        return (Status, *(SensorTelemetry,) * (channels or BASE_SENSOR_CHANNELS),
                *(ImuTelemetry,) * len(IMU_AXES))
    return (Status,)


READ_ALL_REPLY: dict[int, tuple[type[Message], ...]] = {
    int(b): read_all_reply(b) for b in Board}
"""Each board's ReadAll reply without the side pair (``read_all_reply``)."""


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
    unknown type, a payload of the wrong length, or padding that is not zero."""
    s = _STRUCTS.get(type_code)
    if s is None:
        raise CodecError(f"unknown message type 0x{type_code:02X}")
    name = MESSAGES[type_code].__name__
    if len(payload) != s.size:
        raise CodecError(f"{name}: payload of {len(payload)} bytes, expected {s.size}")
    fields = s.unpack(payload)
    if "x" in s.format and s.pack(*fields) != payload:
        raise CodecError(f"{name}: padding bytes must be zero (payload {payload.hex()})")
    return MESSAGES[type_code].from_fields(fields)


__all__ = [
    "AGE_MAX_MS", "ALL_MOTORS_MASK", "ANGLE_MAX_CDEG", "BASE_SENSOR_CHANNELS", "BROADCAST",
    "IMU_AXES", "INT16_MAX", "INT16_NONE", "INT32_MAX", "LEASE_MS", "LIFT_CHANNELS",
    "MAX_PAYLOAD", "MESSAGES", "MOTOR_CHANNELS", "PROTOCOL_MAJOR", "PROTOCOL_MINOR",
    "READ_ALL_REPLY", "SENSOR_CHANNELS", "SIDE_SENSOR_CHANNELS", "Ack", "AckResult", "Board",
    "Brake", "Claim", "ClaimResult", "Clear", "ClearMask", "CodecError", "EStop", "GetImu",
    "GetMotor", "GetSensor", "GetStatus", "GetTruth", "Heartbeat", "Ident", "Identify",
    "ImuAxis", "ImuCode", "ImuTelemetry", "Message", "MotorFault", "MotorMode",
    "MotorTelemetry", "Move", "Owner", "RawMessage", "ReadAll", "Run", "SensorCode",
    "SensorTelemetry", "SetLiftSpeeds", "SetWatchdog", "SetWheelSpeeds", "Status", "StatusFlag",
    "StepDone", "StepTo", "Stop", "TelemetryValueError", "Truth", "decode", "encode",
    "payload_size", "read_all_reply",
]
