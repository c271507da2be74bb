"""A board's ReadAll reply as parts of a Snapshot, whatever the wire.

The motor board answers ReadAll with its Status and one MotorTelemetry per
motor; the sensor board with its Status, one SensorTelemetry per sensor (4,
or 6 with the side pair) and one ImuTelemetry per IMU axis
(``messages.read_all_reply``).  These functions turn the telemetry into
stairbot's types (``units.py``): every channel or a HardwareError, and the
IMU or None with the reason (``ImuRead``), never a made-up value.
``board_robot`` checks the Status and calls them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.errors import BoardMismatchError, HardwareError
from stairbot.hardware import Imu, MotorId, MotorState, SensorId, SensorReading

T = TypeVar("T", m.MotorTelemetry, m.SensorTelemetry)
K = TypeVar("K", MotorId, SensorId)
V = TypeVar("V", MotorState, SensorReading)
R = TypeVar("R")  # what sensors_of makes of each SensorTelemetry

BASE_NAMES = ", ".join(s.value for s in m.SENSOR_CHANNELS[:m.BASE_SENSOR_CHANNELS])
"""SFR, SFL, SBR, SBL: channels 0-3, for messages."""
SIDE_NAMES = ", ".join(m.SENSOR_CHANNELS[c].value for c in m.SIDE_SENSOR_CHANNELS)
"""SSR, SSL: channels 4-5, for messages."""

IMU_OK, IMU_ABSENT, IMU_ERROR = "ok", "absent", "error"
IMU_INVALID, IMU_MISSING = "invalid", "missing"  # the board broke the protocol


@dataclass(frozen=True, slots=True)
class ImuRead:
    """The IMU of one ReadAll reply: the Imu, or None and why.  ``state`` is
    ok, absent (no IMU fitted), error (the board says the IMU failed or an
    unknown status), invalid (a value the protocol does not allow) or missing
    (the reply lacks an axis); ``problem`` says what was wrong, for the last two."""

    imu: Imu | None
    state: str
    problem: str | None = None

    @property
    def broken(self) -> bool:
        """Whether the board broke the protocol (invalid, missing)."""
        return self.state in (IMU_INVALID, IMU_MISSING)


def channels(board: m.Board, msgs: Sequence[Any], kind: type[T], ids: Sequence[K],
             convert: Callable[[T], V]) -> dict[K, V]:
    """``{ids[channel]: convert(telemetry)}`` for the ``kind`` telemetry in a
    ReadAll reply (after its Status).  HardwareError when a channel lacks."""
    out = {ids[t.channel]: convert(t) for t in msgs
           if isinstance(t, kind) and t.channel < len(ids)}
    if len(out) != len(ids):
        raise HardwareError(f"the {board.name.lower()} board's ReadAll reply lacks "
                            f"channels: {tuple(msgs)!r}")
    return out


def sensors_of(msgs: Sequence[Any], convert: Callable[[m.SensorTelemetry], R],
               side_pair: str | None = None) -> dict[SensorId, R]:
    """``{sensor: convert(telemetry)}`` for the SensorTelemetry in the sensor
    board's ReadAll reply (after its Status): channels 0-3 always, the side
    pair (4 SSR, 5 SSL) when ``side_pair`` names where the robot config gives
    the robot one (None: it has none, and side channels a board sends are
    left out: nothing shows a reading of a sensor the robot does not have).
    HardwareError when a base channel lacks, or the reply has one side channel
    without the other; BoardMismatchError when ``side_pair`` wants them and the
    reply has neither.  Channels beyond 5 (a later minor version's) are left out."""
    got: dict[int, m.SensorTelemetry] = {}
    for t in msgs:
        if isinstance(t, m.SensorTelemetry):
            got.setdefault(t.channel, t)
    lacking = [f"{c} ({m.SENSOR_CHANNELS[c].value})"
               for c in range(m.BASE_SENSOR_CHANNELS) if c not in got]
    if lacking:
        raise HardwareError(f"the sensor board's ReadAll reply lacks channel(s) "
                            f"{', '.join(lacking)}: {tuple(msgs)!r}")
    side = [c for c in m.SIDE_SENSOR_CHANNELS if c in got]
    if side and len(side) != len(m.SIDE_SENSOR_CHANNELS):
        (has,) = side
        (lacks,) = (c for c in m.SIDE_SENSOR_CHANNELS if c not in got)
        raise HardwareError(
            f"the sensor board's ReadAll reply has {m.SENSOR_CHANNELS[has].value} (channel "
            f"{has}) but not {m.SENSOR_CHANNELS[lacks].value} (channel {lacks}): a sensor "
            "board sends both side channels or neither (docs/protocol.md, section 3)")
    if side_pair is not None and not side:
        raise BoardMismatchError(
            f"{side_pair} gives the robot the side pair ({SIDE_NAMES}), but the sensor board's "
            f"ReadAll reply has channels 0-3 alone ({BASE_NAMES}) and no side readings")
    wanted = m.BASE_SENSOR_CHANNELS + (len(side) if side_pair is not None else 0)
    return {m.SENSOR_CHANNELS[c]: convert(got[c]) for c in range(wanted)}


def imu_of(msgs: Sequence[Any], transit_s: float = 0.0) -> ImuRead:
    """The IMU in the sensor board's ReadAll reply (the first ImuTelemetry of
    each axis), its age ``transit_s`` older than the board says (see
    ``units.reading_from_wire``)."""
    axes: dict[int, m.ImuTelemetry] = {}
    for t in msgs:
        if isinstance(t, m.ImuTelemetry):
            axes.setdefault(t.axis, t)
    lacking = [a.name.lower() for a in m.IMU_AXES if a not in axes]
    if lacking:
        return ImuRead(None, IMU_MISSING, f"the sensor board's ReadAll reply has no "
                       f"ImuTelemetry for {' and '.join(lacking)}")
    pitch, roll = axes[m.ImuAxis.PITCH], axes[m.ImuAxis.ROLL]
    codes = {pitch.status, roll.status}
    if codes == {m.ImuCode.OK}:
        try:
            return ImuRead(u.imu_from_wire(pitch, roll, transit_s), IMU_OK)
        except m.TelemetryValueError as exc:
            return ImuRead(None, IMU_INVALID, str(exc))
    if codes <= {m.ImuCode.OK, m.ImuCode.ABSENT}:
        return ImuRead(None, IMU_ABSENT)
    return ImuRead(None, IMU_ERROR)
