"""The message model: every type round-trips, payloads fit a CAN frame, units
convert as documented, and no byte string makes a decoder raise anything but
CodecError."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.fakes import sim_messages as sim
from stairbot.hardware import Imu, MotorId, SensorReading, SensorStatus

RANGES = {"B": (0, 255), "H": (0, 65535), "h": (-32768, 32767), "I": (0, 2**32 - 1),
          "i": (-(2**31), 2**31 - 1)}


def field_values(cls: type[m.Message]) -> st.SearchStrategy[tuple[int, ...]]:
    chars = [c for c in cls.FORMAT[1:] if c != "x"]
    if cls is m.MotorTelemetry:  # channel and mode share one byte
        return st.tuples(st.integers(0, 15), st.integers(0, 15), st.integers(0, 255),
                         st.integers(*RANGES["h"]), st.integers(*RANGES["i"]))
    return st.tuples(*(st.integers(*RANGES[c]) for c in chars))


@pytest.mark.parametrize("cls", list(m.MESSAGES.values()), ids=lambda c: c.__name__)
def test_payload_fits_a_can_frame(cls: type[m.Message]) -> None:
    assert struct.calcsize(cls.FORMAT) <= 8
    assert m.payload_size(cls.TYPE) == struct.calcsize(cls.FORMAT)


def test_type_codes_are_unique_and_replies_have_the_high_bit() -> None:
    assert len(m.MESSAGES) == len({c.TYPE for c in m.MESSAGES.values()})
    for code, cls in m.MESSAGES.items():
        assert bool(code & 0x80) == cls.REPLY, cls.__name__


@pytest.mark.parametrize("cls", list(m.MESSAGES.values()), ids=lambda c: c.__name__)
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_every_message_round_trips(cls: type[m.Message], data: st.DataObject) -> None:
    msg = cls(*data.draw(field_values(cls)))
    code, payload = m.encode(msg)
    assert code == cls.TYPE
    assert len(payload) == m.payload_size(code)
    assert m.decode(code, payload) == msg


def test_out_of_range_field_is_a_codec_error() -> None:
    with pytest.raises(m.CodecError, match="SetLiftSpeeds"):
        m.encode(m.SetLiftSpeeds(40000, 0))


def test_wrong_length_and_unknown_type_are_codec_errors() -> None:
    with pytest.raises(m.CodecError, match="expected 8"):
        m.decode(m.SetWheelSpeeds.TYPE, b"\x00" * 7)
    with pytest.raises(m.CodecError, match="unknown message type 0x33"):
        m.decode(0x33, b"")


def test_padding_that_is_not_zero_is_refused() -> None:
    # Truth has a pad byte; hypothesis once found that decoding dropped it
    # silently, so a frame's bytes and the message it became disagreed
    with pytest.raises(m.CodecError, match="Truth: padding bytes must be zero"):
        m.decode(sim.Truth.TYPE, b"\x00\x01" + b"\x00" * 6)
    assert m.decode(sim.Truth.TYPE, b"\x01\x00" + b"\x00" * 6) == sim.Truth(1, 0, 0)


@given(st.integers(0, 255), st.binary(max_size=12))
def test_decode_raises_only_codec_error(code: int, payload: bytes) -> None:
    try:
        msg = m.decode(code, payload)
    except m.CodecError:
        return
    assert m.encode(msg) == (code, payload)


def test_units() -> None:
    assert u.speed_to_wire(1.0) == 1000
    assert u.speed_to_wire(-10.0) == -10000
    assert u.speed_to_wire(1e9) == 32767 and u.speed_to_wire(-1e9) == -32767
    assert u.turns_to_wire(-19.0004) == -19000
    assert u.distance_to_wire(0.4975) in (497, 498)
    assert u.distance_to_wire(-1.0) == 0 and u.distance_to_wire(100.0) == 65535
    state = u.state_from_wire(m.MotorTelemetry(4, 1, 2, -1500, 105000))
    assert (state.turns, state.speed_tps, state.fault) == (105.0, -1.5, "watchdog")
    reading = u.reading_from_wire(m.SensorTelemetry(0, 1, 1300, 3, 25))
    assert (reading.distance_m, reading.status) == (1.3, SensorStatus.OUT_OF_RANGE)
    assert reading.age_s == 0.025
    assert u.reading_from_wire(m.SensorTelemetry(0, 9, 0, 0, 0)).status is SensorStatus.ERROR


def test_ages_round_to_the_millisecond_and_saturate() -> None:
    assert [u.age_to_wire(x) for x in (0.0, 0.0004, 0.0126, 1.5, 65.5349)] == [
        0, 0, 13, 1500, 65535]
    # "this old or older": too old, unknown (NaN) or endless all saturate; never negative
    assert [u.age_to_wire(x) for x in (65.6, 1e9, float("inf"), float("nan"))] == [65535] * 4
    assert u.age_to_wire(-0.5) == 0 and u.age_to_wire(float("-inf")) == 0
    t = u.reading_to_wire(2, SensorReading(1.3, SensorStatus.OUT_OF_RANGE, 0.031), 7, 0.002)
    assert t == m.SensorTelemetry(2, 1, 1300, 7, 33)  # the reply is 2 ms after the snapshot
    assert u.reading_from_wire(t, transit_s=0.004).age_s == pytest.approx(0.037)
    assert u.reading_to_wire(0, SensorReading(float("nan")), 1) == m.SensorTelemetry(
        0, m.SensorCode.ERROR, 0, 1, 0)


def test_the_imu_round_trips_to_the_wires_resolution() -> None:
    imu = Imu(5.234, -0.756, 1.52, -0.24, 0.0031)
    pitch, roll = (u.imu_to_wire(imu, axis, since_s=0.001) for axis in m.IMU_AXES)
    assert (pitch, roll) == (m.ImuTelemetry(0, 0, 523, 15, 4), m.ImuTelemetry(1, 0, -76, -2, 4))
    got = u.imu_from_wire(pitch, roll, transit_s=0.0005)
    assert got is not None and got.age_s == pytest.approx(0.0045)
    assert (got.pitch_deg, got.roll_deg, got.pitch_rate_dps, got.roll_rate_dps) == (
        5.23, -0.76, 1.5, -0.2)
    assert u.imu_to_wire(None, m.ImuAxis.ROLL) == m.ImuTelemetry(1, m.ImuCode.ABSENT, 0, 0, 0)
    # the older axis's age is the IMU's
    assert u.imu_from_wire(pitch, m.ImuTelemetry(1, 0, 0, 0, 9)) == Imu(5.23, 0.0, 1.5, 0.0, 0.009)


@pytest.mark.parametrize("status", [m.ImuCode.ABSENT, m.ImuCode.ERROR, 3, 255])
def test_an_imu_axis_that_is_not_ok_means_no_imu(status: int) -> None:
    ok = m.ImuTelemetry(0, m.ImuCode.OK, 100, 10, 1)
    other = m.ImuTelemetry(1, status, 20000, -32768, 1)  # its numbers mean nothing
    assert u.imu_from_wire(ok, other) is None
    assert u.imu_from_wire(m.ImuTelemetry(0, status, 0, 0, 0), ok) is None


@pytest.mark.parametrize(("angle", "rate", "match"), [
    (18001, 0, r"\(pitch\) angle_cdeg = 18001: allowed -18000..18000"),
    (-32768, 0, r"\(pitch\) angle_cdeg = -32768"),
    (0, -32768, r"\(pitch\) rate_ddps = -32768: allowed -32767..32767"),
])
def test_an_ok_imu_value_the_protocol_forbids_is_a_typed_error(
        angle: int, rate: int, match: str) -> None:
    ok = m.ImuTelemetry(1, m.ImuCode.OK, 0, 0, 0)
    with pytest.raises(m.TelemetryValueError, match=match):
        u.imu_from_wire(m.ImuTelemetry(0, m.ImuCode.OK, angle, rate, 0), ok)
    assert issubclass(m.TelemetryValueError, m.CodecError)


def test_speeds_to_wire_sends_zero_for_motors_left_out() -> None:
    wheels, lifts = u.speeds_to_wire({MotorId.MWL: -0.5, MotorId.MTB: 10.0})
    assert wheels == m.SetWheelSpeeds(0, 0, 0, -500)
    assert lifts == m.SetLiftSpeeds(0, 10000)


def test_a_speed_that_is_not_a_number_is_sent_as_stop() -> None:
    wheels, lifts = u.speeds_to_wire({MotorId.MWF: float("nan"), MotorId.MWB: float("inf"),
                                      MotorId.MWR: 0.5, MotorId.MTF: float("-inf")})
    assert wheels == m.SetWheelSpeeds(0, 0, 500, 0)
    assert lifts == m.SetLiftSpeeds(0, 0)


def test_only_queries_step_to_and_claim_are_idempotent() -> None:
    idempotent = {c.__name__ for c in m.MESSAGES.values() if c.IDEMPOTENT}
    assert idempotent == {"Identify", "Heartbeat", "GetStatus", "ReadAll", "GetMotor",
                          "GetSensor", "GetImu", "StepTo", "GetTruth", "Claim"}


def test_every_host_message_declares_a_reply_a_board_sends() -> None:
    for cls in m.MESSAGES.values():
        if not cls.REPLY:
            answer = m.MESSAGES[cls.ANSWER]
            assert answer.REPLY, cls.__name__
    assert m.MESSAGES[sim.StepTo.ANSWER] is sim.StepDone
    assert m.MESSAGES[sim.GetTruth.ANSWER] is sim.Truth
    assert m.MESSAGES[m.ReadAll.ANSWER] is m.Status  # then the telemetry
    assert m.MESSAGES[m.SetWheelSpeeds.ANSWER] is m.Ack
