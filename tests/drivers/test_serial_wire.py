"""The serial wire: CRC, COBS framing, the test vectors, resynchronisation,
and arbitrary bytes never crashing a decoder."""

from __future__ import annotations

import contextlib
import json
from importlib import resources
from typing import Any

import pytest
from cobs import cobs
from crc import Calculator, Crc16
from hypothesis import given, settings
from hypothesis import strategies as st

from stairbot.drivers import messages as m
from stairbot.drivers.serial_wire import (
    MAX_FRAME,
    MAX_MESSAGE_BYTES,
    CodecError,
    CrcError,
    Frame,
    FrameReader,
    OldFramingError,
    RawMessage,
    crc16,
    decode_frame,
    encode_frame,
    frame_body,
    parse_body,
)
from stairbot.fakes import sim_messages as sim

VECTORS: dict[str, Any] = json.loads(
    resources.files("stairbot.drivers").joinpath("vectors_serial.json").read_text())
REFERENCE_CRC = Calculator(Crc16.IBM_3740)  # = CRC-16/CCITT-FALSE


def frame_of(spec: dict[str, Any]) -> Frame:
    by_name = {c.__name__: c for c in m.MESSAGES.values()}  # the fakes' messages too (sim)
    msgs = tuple(by_name[x["type"]](**x["fields"]) for x in spec["messages"])
    return Frame(spec["board"], spec["seq"], msgs, spec["from_board"], spec["session"])


def test_crc_is_ccitt_false() -> None:
    assert crc16(b"123456789") == 0x29B1
    assert REFERENCE_CRC.checksum(b"123456789") == 0x29B1


@given(st.binary(max_size=300))
def test_crc_matches_the_crc_package(data: bytes) -> None:
    assert crc16(data) == REFERENCE_CRC.checksum(data)


@pytest.mark.parametrize("vec", VECTORS["vectors"], ids=lambda v: v["name"])
def test_vector(vec: dict[str, Any]) -> None:
    frame = frame_of(vec["frame"])
    assert frame_body(frame).hex(" ") == vec["body_hex"]
    assert encode_frame(frame).hex(" ") == vec["wire_hex"]
    wire = bytes.fromhex(vec["wire_hex"])
    assert wire.count(0) == 1 and wire.endswith(b"\x00")
    assert decode_frame(wire[:-1]) == frame


@pytest.mark.parametrize("stream", VECTORS["streams"], ids=lambda v: v["name"])
@pytest.mark.parametrize("chunk", [None, 1, 3])
def test_stream_resynchronises(stream: dict[str, Any], chunk: int | None) -> None:
    by_name = {v["name"]: frame_of(v["frame"]) for v in VECTORS["vectors"]}
    wire = bytes.fromhex(stream["wire_hex"])
    reader = FrameReader()
    got: list[Frame] = []
    step = chunk or len(wire)
    for i in range(0, len(wire), step):
        got += reader.feed(wire[i:i + step])
    assert got == [by_name[n] for n in stream["frames"]]
    assert reader.stats.crc_errors == stream["crc_errors"]
    assert reader.stats.malformed == stream["malformed"]


def test_bad_crc_is_a_crc_error() -> None:
    body = bytearray(frame_body(Frame(1, 7, (m.ReadAll(),))))
    body[-1] ^= 0x80
    with pytest.raises(CrcError):
        parse_body(bytes(body))


def test_unknown_type_is_kept_raw_and_bad_length_rejected() -> None:
    frame = Frame(2, 5, (RawMessage(0x33, b"\x01\x02"), m.GetStatus()))
    assert decode_frame(encode_frame(frame)[:-1]) == frame
    body = bytearray(frame_body(Frame(1, 1, (m.Heartbeat(3),))))
    body[5] = 9  # a message length beyond the frame
    body[-2:] = crc16(bytes(body[:-2])).to_bytes(2, "big")
    with pytest.raises(CodecError, match="bad length"):
        parse_body(bytes(body))


def test_bytes_inserted_before_the_delimiter_are_never_a_frame() -> None:
    """Protocol 2's blind spot: a CRC without a final xor is 0 over a body and
    its own CRC, so ``01 01`` before the delimiter of a frame whose CRC ended
    in 0x00 unstuffed to body + 00 00 and passed.  The length byte refuses it
    (and every other insertion after the header)."""
    hits = 0
    for seq in range(256):
        for frame in (Frame(1, seq, (m.ReadAll(),)), Frame(2, seq, (m.GetStatus(),), True),
                      Frame(1, seq, (m.SetWheelSpeeds(1000, 1000, 0, 0),))):
            wire = encode_frame(frame)
            if frame_body(frame)[-1] != 0:
                continue
            hits += 1
            assert crc16(cobs.decode(wire[:-1] + b"\x01\x01")) == 0  # the CRC alone passes it
            with pytest.raises(CodecError, match="length byte says"):
                decode_frame(wire[:-1] + b"\x01\x01")
    assert hits > 0


def test_a_protocol_2_frame_is_named_for_what_it_is() -> None:
    old = bytes((0x01, 2, 0x10, 0x00))
    old += crc16(old).to_bytes(2, "big")
    with pytest.raises(OldFramingError, match="protocol 2.x framing"):
        parse_body(old)
    with pytest.raises(OldFramingError, match="protocol 2.x framing"):
        parse_body(old[:2] + b"\x00" + old[2:4] + crc16(old[:2] + b"\x00" + old[2:4]).to_bytes(
            2, "big"))


def test_overrun_is_dropped_and_the_reader_resyncs() -> None:
    reader = FrameReader()
    good = encode_frame(Frame(1, 9, (m.ReadAll(),)))
    assert reader.feed(b"\x55" * (MAX_FRAME + 10)) == []
    assert reader.feed(b"\x55" * 5 + b"\x00" + good) == [Frame(1, 9, (m.ReadAll(),))]
    assert reader.stats.overruns == 1 and reader.stats.malformed == 0


messages_st = st.sampled_from([
    m.ReadAll(), m.Identify(), m.GetStatus(), m.Heartbeat(7), m.Stop(0x3F),
    m.SetWheelSpeeds(1000, -1000, 0, 5), m.SetLiftSpeeds(10000, -10000),
    m.MotorTelemetry(3, 1, 0, -250, -123456), m.SensorTelemetry(2, 1, 1300, 65535, 65535),
    m.ImuTelemetry(1, 0, -18000, -32767, 7), m.GetImu(0),
    m.Status(0xC0, 0, 250, 2**32 - 1), m.Ack(0x20, 1), sim.StepTo(20000), m.Move(5, -19000, 10000),
])


@given(st.integers(0, 15), st.integers(0, 255), st.booleans(),
       st.lists(messages_st, min_size=1, max_size=8))
def test_frame_round_trip(board: int, seq: int, from_board: bool, msgs: list[m.Message]) -> None:
    frame = Frame(board, seq, tuple(msgs), from_board)
    wire = encode_frame(frame)
    assert wire.count(0) == 1
    assert FrameReader().feed(wire) == [frame]


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=400))
def test_arbitrary_bytes_never_crash_the_decoders(data: bytes) -> None:
    with contextlib.suppress(CodecError):
        decode_frame(data)
    with contextlib.suppress(CodecError):
        parse_body(data)
    reader = FrameReader()
    frames = reader.feed(data)
    s = reader.stats
    if s.overruns == 0:  # every complete chunk is either a frame or counted as an error
        chunks = [c for c in data.split(b"\x00")[:-1] if c]
        assert len(frames) + s.crc_errors + s.malformed == len(chunks)
    assert s.frames == len(frames)
    assert reader.feed(encode_frame(Frame(1, 1, (m.ReadAll(),))) * 2)[-1:] == [
        Frame(1, 1, (m.ReadAll(),))]


@given(st.lists(messages_st, min_size=1, max_size=6), st.data())
def test_a_byte_added_or_lost_after_the_header_is_never_a_frame(
        msgs: list[m.Message], data: st.DataObject) -> None:
    body = frame_body(Frame(1, 9, tuple(msgs)))
    at = data.draw(st.integers(3, len(body)), label="at")
    if data.draw(st.booleans(), label="insert"):
        extra = data.draw(st.binary(min_size=1, max_size=4), label="extra")
        bad = body[:at] + extra + body[at:]
    else:
        n = data.draw(st.integers(1, min(4, len(body) - at) or 1), label="n")
        bad = body[:at] + body[at + n:]
    if bad == body:
        return
    bad = bad[:-2] + crc16(bad[:-2]).to_bytes(2, "big") if data.draw(
        st.booleans(), label="fix crc") else bad
    with pytest.raises(CodecError):
        parse_body(bad)


def test_a_frame_too_long_to_stuff_into_max_frame_is_never_made() -> None:
    """247 message bytes stuff into MAX_FRAME (254); one more would make a
    frame the receiver drops as an overrun when its bytes come one at a
    time (the C core's cross-check found the sender allowing 255)."""
    def raw(total: int) -> Frame:
        msgs, left = [], total
        while left:
            n = min(8, left - 2)
            msgs.append(RawMessage(0x60, bytes(n)))  # a type no table names
            left -= 2 + n
        return Frame(1, 1, tuple(msgs), session=9)

    assert MAX_MESSAGE_BYTES == 247
    wire = encode_frame(raw(247))
    assert len(wire) - 1 <= MAX_FRAME
    reader = FrameReader()
    got = [f for b in wire for f in reader.feed(bytes([b]))]
    assert len(got) == 1 and reader.stats.overruns == 0, reader.stats
    with pytest.raises(CodecError, match="at most 247"):
        encode_frame(raw(257))


@pytest.mark.parametrize(("channel", "mode"), [(17, 0), (0, 16), (-1, 0)])
def test_motor_telemetry_refuses_a_channel_or_mode_its_nibble_cannot_hold(channel: int,
                                                                           mode: int) -> None:
    """Channel 17 went out as channel 1 (the C encoder's cross-check)."""
    with pytest.raises(CodecError, match="nibble"):
        encode_frame(Frame(1, 1, (m.MotorTelemetry(channel, mode, 0, 0, 0),), from_board=True,
                           session=9))
