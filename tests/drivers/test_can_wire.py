"""The CAN wire: the DBC loads and agrees with the message model, the test
vectors, codec round trips, captured traffic decoded by cantools, the bus-load
arithmetic, and arbitrary frames never crashing a decoder."""

from __future__ import annotations

import itertools
import json
import random
import struct
from collections.abc import Iterator
from importlib import resources
from pathlib import Path
from typing import Any

import can
import cantools
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.can_wire import (
    FRAME_ID_MASK,
    SESSION_MAX,
    CanFrame,
    CanWire,
    frame_bits,
    load_dbc,
    make_id,
    split_id,
    wire,
)
from stairbot.fakes import sim_messages as sim
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.inputs.scenario import load_scenario

# The real boards' vectors, then the simulation's (their frames are in the
# fakes' DBC, which importing the fakes adds to the wire).
VECTORS: list[dict[str, Any]] = [
    *json.loads(resources.files("stairbot.drivers").joinpath("vectors_can.json")
                .read_text())["vectors"],
    *json.loads(resources.files("stairbot.fakes").joinpath("vectors_sim_can.json")
                .read_text())["vectors"]]
SIM_TYPES = {sim.StepTo.TYPE, sim.GetTruth.TYPE, sim.StepDone.TYPE, sim.Truth.TYPE}
DBC_PATH = str(resources.files("stairbot.drivers").joinpath("stairbot.dbc"))
SIM_DBC_PATH = str(resources.files("stairbot.fakes").joinpath(sim.DBC_NAME))


def message_of(v: dict[str, Any]) -> m.Message:
    cls = {c.__name__: c for c in m.MESSAGES.values()}[v["message"]]
    return cls(**v["fields"])


def test_the_dbc_loads_and_every_message_has_a_frame() -> None:
    db = cantools.database.load_file(DBC_PATH, strict=True)
    ids = [f.frame_id for f in db.messages]
    assert len(ids) == len(set(ids))
    assert all(f.is_extended_frame and f.frame_id & ~FRAME_ID_MASK == 0 and f.length <= 8
               for f in db.messages)
    w = CanWire(db)
    assert set(w.kinds) == set(m.MESSAGES) - SIM_TYPES  # the real boards' messages alone
    db.add_dbc_file(SIM_DBC_PATH)  # the fakes' frames: every message the codec knows
    assert set(CanWire(db).kinds) == set(m.MESSAGES)
    assert {f.name for f in cantools.database.load_file(SIM_DBC_PATH).messages} == {
        "StepTo_Motor", "GetTruth_Motor", "StepDone_Motor", "Truth_Motor"}
    assert set(wire().kinds) == set(m.MESSAGES)  # the shared wire has them added
    assert db.get_message_by_frame_id(0x00F << 18).name == "EStop_All"
    assert min(ids) == w.frame_id(m.Board.MOTOR, m.EStop)  # e-stop wins arbitration


def test_estop_has_the_lowest_id_of_every_frame_whatever_the_session_and_seq() -> None:
    """Arbitration favours the lowest id: the highest id an EStop can have
    (any board, session 1023, seq 255) is below the lowest any other frame
    can have (session 0, seq 0)."""
    w = wire()
    estop = [make_id(w.base(b, m.EStop), s, q) for b in (1, 2, 15)
             for s in (0, 1, SESSION_MAX) for q in (0, 255)]
    others = [f.frame_id for f in w.db.messages if not f.name.startswith("EStop_")]
    assert max(estop) < min(others)
    assert max(estop) == 0x003FFFFF and min(others) == 0x00440000


def test_the_id_carries_session_and_seq_below_the_base() -> None:
    w = wire()
    fid, data = w.encode(1, m.ReadAll(), session=0x15A, seq=5)
    assert (fid, data) == (0x0A1 << 18 | 0x15A << 8 | 5, b"") == (0x02855A05, b"")
    assert split_id(fid) == (0x0A1, 0x15A, 5)
    assert w.decode(fid, b"") == CanFrame(1, m.ReadAll(), 0x15A, 5)
    for session, seq in ((-1, 0), (SESSION_MAX + 1, 0), (1, 256), (1, -1)):
        with pytest.raises(m.CodecError, match="out of range"):
            w.encode(1, m.ReadAll(), session, seq)


def test_a_dbc_that_disagrees_with_the_model_is_refused(tmp_path: Path) -> None:
    text = resources.files("stairbot.drivers").joinpath("stairbot.dbc").read_text()
    lift = f"BO_ {0x80000000 | 0x051 << 18} SetLiftSpeeds_Motor:"
    bad = tmp_path / "bad.dbc"
    bad.write_text(text.replace(f"{lift} 4", f"{lift} 6"))
    with pytest.raises(ValueError, match="SetLiftSpeeds_Motor is 6 bytes"):
        CanWire(load_dbc(str(bad)))
    standard = tmp_path / "standard.dbc"  # a protocol 3.x frame: an 11-bit id
    standard.write_text(text.replace(lift, "BO_ 81 SetLiftSpeeds_Motor:"))
    with pytest.raises(ValueError, match="SetLiftSpeeds_Motor has id 0x00000051"):
        CanWire(load_dbc(str(standard)))


@pytest.mark.parametrize("v", VECTORS, ids=lambda v: f"{v['id']}-{v['message']}")
def test_vector(v: dict[str, Any]) -> None:
    w = wire()
    fid, data = int(v["id"], 16), bytes.fromhex(v["data"])
    msg = message_of(v)
    assert split_id(fid) == (int(v["base"], 16), v["session"], v["seq"])
    assert w.encode(v["board"], msg, v["session"], v["seq"]) == (fid, data)
    assert w.decode(fid, data) == CanFrame(v["board"], msg, v["session"], v["seq"])
    assert m.encode(msg)[1] == data  # the CAN payload is the protocol payload
    frame = w.db.get_message_by_frame_id(fid)  # the DBC, masked: any session and seq
    assert frame.name == v["frame"] and frame.frame_id == int(v["base"], 16) << 18
    decoded = {k: (str(x) if not isinstance(x, int | float) else x)
               for k, x in frame.decode(data).items()}
    assert decoded == pytest.approx(v["signals"])


def test_every_frame_round_trips_and_matches_the_struct_payload() -> None:
    w, rng = wire(), random.Random(7)
    for fid in sorted(f.frame_id for f in w.db.messages):
        first = w.decode(fid, bytes(w.db.get_message_by_frame_id(fid).length))
        board, cls = first.board, type(first.message)
        for _ in range(100):
            layout = struct.Struct(cls.FORMAT)
            raw = bytes(rng.randrange(256) for _ in range(layout.size))
            msg = m.decode(cls.TYPE, layout.pack(*layout.unpack(raw)))  # padding zeroed
            session, seq = rng.randrange(SESSION_MAX + 1), rng.randrange(256)
            sent = w.encode(board, msg, session, seq)
            assert sent == (fid | session << 8 | seq, m.encode(msg)[1])
            assert w.decode(*sent) == CanFrame(board, msg, session, seq)


def test_fields_that_do_not_fit_and_frames_that_do_not_exist_are_codec_errors() -> None:
    w = wire()
    with pytest.raises(m.CodecError, match="mtf"):
        w.encode(1, m.SetLiftSpeeds(40000, 0))
    with pytest.raises(m.CodecError, match="SetWheelSpeeds and board 2"):
        w.encode(2, m.SetWheelSpeeds(0, 0, 0, 0))
    with pytest.raises(m.CodecError, match="unknown CAN id"):
        w.decode(0x7FF << 18, b"")
    with pytest.raises(m.CodecError, match="expected 8"):
        w.decode(0x221 << 18 | 0x15A05, b"\x00" * 7)
    old = can.Message(arbitration_id=0x0A1, data=b"", is_extended_id=False)  # protocol 3.x
    with pytest.raises(m.CodecError, match="not a classic extended data frame"):
        w.from_can(old)


def test_frame_bits_worst_case_stuffing() -> None:
    assert frame_bits(8) == 160  # 135 with an 11-bit id
    assert frame_bits(0) == 80  # 55
    assert [frame_bits(n) for n in range(9)] == sorted(frame_bits(n) for n in range(9))


def test_captured_traffic_is_decoded_by_cantools(tmp_path: Path) -> None:
    """A session's frames logged by python-can to an ASC file, read back, and
    every one decoded from the DBCs alone (the real boards', with the
    simulation's added for its StepTo and StepDone)."""
    config, scenario = load_config(), load_scenario()
    world = make_world(config, scenario, True)
    server = CanBoardServer(can.Bus(interface="virtual", channel="capture"), world,
                            make_boards(world))
    spy = can.Bus(interface="virtual", channel="capture")
    host = InlineBus(can.Bus(interface="virtual", channel="capture"), server)
    link = CanLink(host, timeout_s=1.0)
    for board in m.Board:
        link.exchange(board, [m.Identify(), m.Claim(m.LEASE_MS, 1), m.ReadAll()])
    link.exchange(1, [m.SetWheelSpeeds(1000, 1000, 1000, 1000), sim.StepTo(20000)])
    log = tmp_path / "capture.asc"
    with can.ASCWriter(str(log)) as writer:
        frame = spy.recv(0)
        while frame is not None:
            writer.on_message_received(frame)
            frame = spy.recv(0)
    db = load_dbc()
    db.add_dbc_file(SIM_DBC_PATH)
    names = []
    for frame in can.LogReader(str(log)):
        # get_message_by_frame_id applies the mask (decode_message, in
        # cantools 45.1, does not)
        found = db.get_message_by_frame_id(frame.arbitration_id)
        names.append(found.name)
        found.decode(frame.data)  # raises if it cannot
    assert names.count("MotorTelemetry_Motor") == 6
    assert names.count("SensorTelemetry_Sensor") == 4
    assert {"Ident_Motor", "Ident_Sensor", "Claim_Motor", "Owner_Sensor", "StepTo_Motor",
            "StepDone_Motor", "SetWheelSpeeds_Motor", "Ack_Motor"} <= set(names)
    for bus in (spy, host):
        bus.shutdown()
    server.bus.shutdown()


frames = st.builds(
    lambda fid, data, ext, remote, err, fd: can.Message(
        arbitration_id=fid if ext else fid & 0x7FF, data=data, is_extended_id=ext,
        is_remote_frame=remote and not fd, is_error_frame=err, is_fd=fd, check=False),
    st.integers(0, 0x1FFFFFFF), st.binary(max_size=64), st.booleans(),
    st.booleans(), st.booleans(), st.booleans())


_DBC_FRAMES = [(f.frame_id, f.length) for f in load_dbc().messages]
valid_frames = st.sampled_from(_DBC_FRAMES).flatmap(lambda spec: st.builds(
    lambda data, session, seq: can.Message(arbitration_id=spec[0] | session << 8 | seq,
                                           data=data, is_extended_id=True, check=False),
    st.binary(min_size=spec[1], max_size=spec[1]), st.integers(0, SESSION_MAX),
    st.integers(0, 255)))


@pytest.fixture(scope="module")
def fuzz_targets() -> Iterator[tuple[CanBoardServer, CanLink]]:
    """One fake-boards server (world not in lockstep: StepTo is refused, so a
    random time cannot run the physics for an hour) and one host link."""
    world = make_world(load_config(), load_scenario(), False)
    server = CanBoardServer(can.Bus(interface="virtual", channel="fuzz-boards"), world,
                            make_boards(world))
    # a clock that moves a second a look: the frames fuzzed here, however
    # many, never make a flood (bus_health: 500 foreign frames in 250 ms)
    seconds = itertools.count()
    link = CanLink(can.Bus(interface="virtual", channel="fuzz-host"),
                   now=lambda: float(next(seconds)))
    yield server, link
    server.bus.shutdown()
    link.close()


@settings(max_examples=300, deadline=None)
@given(st.lists(st.one_of(frames, valid_frames), max_size=20))
def test_arbitrary_frames_never_crash_the_decoders_and_are_counted(
        fuzz_targets: tuple[CanBoardServer, CanLink], batch: list[can.Message]) -> None:
    """Any id, flags and bytes -- and every DBC frame with arbitrary data, so
    every message with arbitrary field values reaches the boards: no decoder,
    board or link fails, and each frame is counted somewhere."""
    w = wire()
    bad = 0
    for frame in batch:
        try:
            w.from_can(frame)
        except m.CodecError:
            bad += 1
    server, link = fuzz_targets
    s0, l0 = vars(server.stats).copy(), link.stats.as_dict()
    for frame in batch:
        server.receive(frame)
        link.take(frame)
    s = {k: v - s0[k] for k, v in vars(server.stats).items()}
    ls = {k: v - l0[k] for k, v in link.stats.as_dict().items()}
    assert s["error_frames"] + s["malformed"] == bad
    assert ls["error_frames"] + ls["malformed"] == bad and ls["crc_errors"] == 0
    assert ls["ignored"] + ls["stray"] + ls["late"] + ls["duplicates"] == len(batch) - bad
    assert s["ignored"] + s["frames_rx"] + s["stray"] >= len(batch) - bad


def test_link_matches_interleaved_replies_and_counts_late_and_stray() -> None:
    """Replies of two boards interleaved on the bus reach their own requests;
    a reply after its request was given up is late, one nobody asked for stray."""
    t = [0.0]
    host = can.Bus(interface="virtual", channel="link-unit")
    boards = can.Bus(interface="virtual", channel="link-unit")
    link = CanLink(host, timeout_s=0.1, retries=0, now=lambda: t[0])
    w = wire()
    status = m.Status(0x40, 0, 250, 1)
    pm = link.request(1, [m.ReadAll()])
    ps = link.request(2, [m.GetStatus()])
    (sm,), (ss,) = pm.seqs, ps.seqs
    replies = [(1, sm, status), (2, ss, status)] + [
        (1, sm, m.MotorTelemetry(c, 0, 0, 0, c)) for c in range(6)]
    for board, seq, msg in replies:
        boards.send(w.to_can(board, msg, link.session, seq))
    motor, sensor = link.wait([pm, ps])
    assert motor.messages[0] == status and len(motor.messages) == 7
    assert [x.turns_mt for x in motor.messages[1:]] == list(range(6))  # type: ignore[attr-defined]
    assert sensor.messages == (status,)
    late = link.request(2, [m.GetStatus()])
    t[0] = 1.0  # its time is up: given up (no retries)
    link.poll()
    assert late.failed and link.stats.lost == 1
    boards.send(w.to_can(2, status, link.session, late.seqs[0]))  # the reply it was owed
    boards.send(w.to_can(1, m.Ack(0x20, 0), link.session, (late.seqs[0] + 1) % 256))  # unasked
    link.poll()
    assert (link.stats.late, link.stats.stray) == (1, 1)
    for bus in (host, boards):
        bus.shutdown()
