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
* this module        -- one namespace for them (``from stairbot.drivers import
  messages as m``) and the codec.

The codec knows the real boards' messages and nothing else.  The fake
boards' simulation-only messages (StepTo, GetTruth and their replies) travel
on the same wire, but only a process that imports the fakes knows them:
``stairbot.fakes.sim_messages`` adds them, with the DBC of their CAN frames,
by :func:`register`.  To a host that never imports the fakes a StepTo is an
unknown type, as it is to a real board.

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

MESSAGES: dict[int, type[Message]] = {
    cls.TYPE: cls
    for cls in (
        Identify, Heartbeat, GetStatus, SetWatchdog, EStop, Clear, ReadAll, GetMotor,
        GetSensor, GetImu, SetWheelSpeeds, SetLiftSpeeds, Run, Move, Stop, Brake, Ident,
        Status, MotorTelemetry, SensorTelemetry, ImuTelemetry, Ack, Claim, Owner,
    )
}
"""Every message the codec knows, by type code: the real boards', and those
added by :func:`register`."""
_STRUCTS: dict[int, struct.Struct] = {t: struct.Struct(c.FORMAT) for t, c in MESSAGES.items()}
assert all(s.size <= MAX_PAYLOAD for s in _STRUCTS.values())
_DBCS: list[str] = []  # the registered DBC texts, in order


def register(*classes: type[Message], dbc: str | None = None) -> None:
    """Add messages to the codec, and ``dbc`` (the text of a DBC naming
    their CAN frames, ``<Message>_<Motor|Sensor|All>``) to the CAN wire
    (``can_wire.wire``).  The fakes add their simulation-only messages so.
    Registering the same classes and DBC again changes nothing; a type code
    another class holds, or a payload longer than MAX_PAYLOAD, raises
    ValueError."""
    for cls in classes:
        held = MESSAGES.get(cls.TYPE)
        if held is not None and held is not cls:
            raise ValueError(f"type 0x{cls.TYPE:02X} is {held.__name__}'s, not {cls.__name__}'s")
        layout = struct.Struct(cls.FORMAT)
        if layout.size > MAX_PAYLOAD:
            raise ValueError(f"{cls.__name__}: payload of {layout.size} bytes, more than "
                             f"{MAX_PAYLOAD}")
    for cls in classes:
        MESSAGES[cls.TYPE], _STRUCTS[cls.TYPE] = cls, struct.Struct(cls.FORMAT)
    if dbc is not None and dbc not in _DBCS:
        _DBCS.append(dbc)


def registered_dbcs() -> tuple[str, ...]:
    """The DBC texts :func:`register` added, in order (the shipped DBC not among them)."""
    return tuple(_DBCS)


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
    "GetMotor", "GetSensor", "GetStatus", "Heartbeat", "Ident", "Identify",
    "ImuAxis", "ImuCode", "ImuTelemetry", "Message", "MotorFault", "MotorMode",
    "MotorTelemetry", "Move", "Owner", "RawMessage", "ReadAll", "Run", "SensorCode",
    "SensorTelemetry", "SetLiftSpeeds", "SetWatchdog", "SetWheelSpeeds", "Status", "StatusFlag",
    "Stop", "TelemetryValueError", "decode", "encode", "payload_size", "read_all_reply",
    "register", "registered_dbcs",
]
