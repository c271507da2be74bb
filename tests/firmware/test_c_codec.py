"""The firmware's C codec (firmware/core) against the host's Python codec
(stairbot.drivers.serial_wire and messages, with the simulation's messages):
the test vectors both ways, random frames of the Python encoder decoded and
encoded by C field by field, mutated frames refused by both for the same
reason, the board checks of docs/protocol.md section 3 (by hand and against
the Python fake boards), and a short run of the sanitized fuzz harness
(benchmarks/fuzz_firmware.py).

The C side is firmware/test/sbtool.c, built here with the C compiler named
by $CC, else cc, gcc or clang from PATH; without one the tests skip."""

from __future__ import annotations

import dataclasses
import json
import random
import subprocess
import sys
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
from firmware_build import find_cc

from stairbot.drivers import messages as m
from stairbot.drivers.serial_wire import (
    MAX_MESSAGE_BYTES,
    CodecError,
    CrcError,
    Frame,
    FrameReader,
    OldFramingError,
    RawMessage,
    crc16,
    encode_frame,
    frame_body,
    parse_body,
)
from stairbot.fakes import sim_messages as sim
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import make_boards
from stairbot.hardware import BASE_SENSORS, MotorId, MotorState, SensorReading, Snapshot, Truth

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE = ROOT / "firmware"
VECTORS: dict[str, Any] = json.loads(
    resources.files("stairbot.drivers").joinpath("vectors_serial.json").read_text())
BY_NAME = {c.__name__: c for c in m.MESSAGES.values()}  # with the simulation's (sim)
assert sim.StepTo.__name__ in BY_NAME


@pytest.fixture(scope="module")
def sbtool(tmp_path_factory: pytest.TempPathFactory) -> Path:
    cc = find_cc()
    if cc is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    exe = tmp_path_factory.mktemp("firmware") / "sbtool"
    sources = sorted(str(p) for p in (FIRMWARE / "core").glob("*.c"))
    subprocess.run([cc, "-std=c11", "-O2", "-Wall", "-Wextra", "-Wpedantic", "-Wconversion",
                    "-Werror", f"-I{FIRMWARE / 'core'}", *sources,
                    str(FIRMWARE / "test" / "sbtool.c"), "-o", str(exe)], check=True)
    return exe


def ask(sbtool: Path, commands: list[str]) -> list[str]:
    """sbtool's one-line answers to ``commands``, in order."""
    done = subprocess.run([str(sbtool)], input="".join(c + "\n" for c in commands),
                          capture_output=True, text=True, check=True)
    answers = done.stdout.splitlines()
    assert len(answers) == len(commands)
    return answers


def values(msg: m.Message) -> list[int]:
    """A message's fields by name, in the dataclass's (records.py's) order."""
    return [int(getattr(msg, f.name)) for f in dataclasses.fields(msg)]


def fmt_msg(msg: m.Message | RawMessage) -> str:
    if isinstance(msg, RawMessage):
        return f"raw {msg.type_code} {msg.payload.hex() or '-'}"
    return " ".join(str(v) for v in (msg.TYPE, *values(msg)))


def fmt_frame(frame: Frame) -> str:
    head = f"{frame.board} {int(frame.from_board)} {frame.session} {frame.seq}"
    return " | ".join([head, *map(fmt_msg, frame.messages)])


def frame_of(spec: dict[str, Any]) -> Frame:
    msgs = tuple(BY_NAME[x["type"]](**x["fields"]) for x in spec["messages"])
    return Frame(spec["board"], spec["seq"], msgs, spec["from_board"], spec["session"])


def python_outcome(body: bytes) -> str:
    """What the Python codec makes of a body, in sbtool's terms (the error's class only)."""
    try:
        return "ok " + fmt_frame(parse_body(body))
    except CrcError:
        return "err crc"
    except OldFramingError:
        return "err old_framing"
    except CodecError:
        return "err codec"


def c_class(answer: str) -> str:
    """sbtool's answer with its error named by the Python class it matches."""
    if answer.startswith("err ") and answer not in ("err crc", "err old_framing"):
        return "err codec"
    return answer


def test_crc_is_ccitt_false(sbtool: Path) -> None:
    data = [b"123456789", b"", b"\x00", bytes(range(256))]
    answers = ask(sbtool, [f"crc {d.hex() or '-'}" for d in data])
    assert answers[0] == "29b1"
    assert answers == [f"{crc16(d):04x}" for d in data]


@pytest.mark.parametrize("vec", VECTORS["vectors"], ids=lambda v: v["name"])
def test_vector(sbtool: Path, vec: dict[str, Any]) -> None:
    frame = frame_of(vec["frame"])
    body = bytes.fromhex(vec["body_hex"])
    wire = bytes.fromhex(vec["wire_hex"])
    enc = "enc " + " | ".join(
        [f"{frame.board} {int(frame.from_board)} {frame.session} {frame.seq}",
         *(fmt_msg(x) for x in frame.messages)])
    decoded_body, decoded_wire, encoded = ask(sbtool, [
        f"body {body.hex()}", f"wire {wire[:-1].hex()}", enc])
    assert decoded_body == "ok " + fmt_frame(frame)
    assert decoded_wire == decoded_body
    assert encoded == f"ok {body.hex()} {wire.hex()}"


@pytest.mark.parametrize("stream", VECTORS["streams"], ids=lambda v: v["name"])
def test_stream(sbtool: Path, stream: dict[str, Any]) -> None:
    by_name = {v["name"]: frame_of(v["frame"]) for v in VECTORS["vectors"]}
    (answer,) = ask(sbtool, [f"stream {stream['wire_hex'].replace(' ', '')}"])
    *frames, stats = answer.split(" || ")
    assert frames == [fmt_frame(by_name[n]) for n in stream["frames"]]
    assert stats == (f"frames {len(stream['frames'])} crc {stream['crc_errors']} "
                     f"malformed {stream['malformed']} overruns 0")


def random_message(rng: random.Random) -> m.Message | RawMessage:
    """A message of any type the Python codec knows, every field anywhere in
    its wire range (from its struct FORMAT), or of a type it does not know."""
    if rng.random() < 0.1:
        code = rng.choice([c for c in range(256) if c not in m.MESSAGES])
        return RawMessage(code, rng.randbytes(rng.randint(0, 8)))
    cls = rng.choice(list(m.MESSAGES.values()))
    ranges = {"B": (0, 255), "H": (0, 65535), "h": (-32768, 32767), "I": (0, 2**32 - 1),
              "i": (-2**31, 2**31 - 1)}
    codes = [c for c in cls.FORMAT.lstrip("<") if c != "x"]
    names = [f.name for f in dataclasses.fields(cls)]
    if cls is m.MotorTelemetry:  # channel and mode share byte 0: a nibble each
        return m.MotorTelemetry(rng.randint(0, 15), rng.randint(0, 15), rng.randint(0, 255),
                                rng.randint(-32768, 32767), rng.randint(-2**31, 2**31 - 1))
    assert len(codes) == len(names), cls
    return cls(*(rng.randint(*ranges[c]) for c in codes))


def random_frame(rng: random.Random) -> Frame:
    msgs: list[m.Message | RawMessage] = []
    size = 0
    for _ in range(rng.randint(1, 30)):
        msg = random_message(rng)
        n = 2 + len(msg.payload if isinstance(msg, RawMessage) else m.encode(msg)[1])
        if size + n > MAX_MESSAGE_BYTES:
            break
        msgs.append(msg)
        size += n
    return Frame(rng.randint(0, 15), rng.randint(0, 255), tuple(msgs), rng.random() < 0.5,
                 rng.randint(0, 255))


def test_random_frames_agree(sbtool: Path) -> None:
    """400 frames of the Python encoder: C decodes each to the same fields,
    from the body and from the wire, and encodes those fields to the same bytes."""
    rng = random.Random(37)
    frames = [random_frame(rng) for _ in range(400)]
    commands = []
    for frame in frames:
        commands += [f"body {frame_body(frame).hex()}", f"wire {encode_frame(frame)[:-1].hex()}",
                     "enc " + fmt_frame(frame)]
    answers = ask(sbtool, commands)
    for i, frame in enumerate(frames):
        body_answer, wire_answer, enc_answer = answers[3 * i:3 * i + 3]
        assert body_answer == "ok " + fmt_frame(frame)
        assert wire_answer == body_answer
        assert enc_answer == f"ok {frame_body(frame).hex()} {encode_frame(frame).hex()}"


def mutate(rng: random.Random, body: bytes) -> bytes:
    """One mutation of a body: flipped bits, a cut, bytes inserted or lost,
    a lying length byte or message length, another type code; the CRC made
    good again half the time (always for the lies), so the checks behind it run."""
    b = bytearray(body)
    kind = rng.randrange(6)
    if kind == 0:
        for _ in range(rng.randint(1, 3)):
            b[rng.randrange(len(b))] ^= 1 << rng.randrange(8)
    elif kind == 1:
        del b[rng.randrange(len(b)):]
    elif kind == 2:
        at = rng.randint(0, len(b))
        b[at:at] = rng.randbytes(rng.randint(1, 4))
    elif kind == 3:
        at = rng.randrange(len(b))
        del b[at:at + rng.randint(1, 4)]
    elif kind == 4:
        b[3] = rng.randrange(256)
    else:
        b[rng.choice([4, 5])] = rng.randrange(256)  # the first message's type or length
    if kind >= 4 or rng.random() < 0.5:
        b[-2:] = crc16(bytes(b[:-2])).to_bytes(2, "big") if len(b) >= 2 else b[-2:]
    return bytes(b)


def test_mutated_frames_are_judged_alike(sbtool: Path) -> None:
    """600 mutated bodies: where Python accepts, C reads the same frame; where
    Python refuses, C refuses for the same class of reason (a CRC error, a
    protocol 2.x frame, anything else malformed)."""
    rng = random.Random(2026)
    bodies = [mutate(rng, frame_body(random_frame(rng))) for _ in range(600)]
    bodies += [rng.randbytes(rng.randint(0, 12)) for _ in range(100)]
    answers = ask(sbtool, [f"body {b.hex() or '-'}" for b in bodies])
    outcomes = [python_outcome(b) for b in bodies]
    assert [c_class(a) for a in answers] == outcomes
    assert sum(o.startswith("ok") for o in outcomes) > 50  # the CRC-fixed lies get through often
    assert {a for a in answers if a.startswith("err")} >= {
        "err crc", "err length", "err msg_length", "err payload_size", "err short"}


def test_known_refusals_are_named(sbtool: Path) -> None:
    """Each check of section 5 refuses by its own name."""
    def fixed(body: bytes) -> str:
        return (body + crc16(body).to_bytes(2, "big")).hex()

    cases = {
        "old_framing": fixed(bytes((0x01, 0x5A, 1, 2, 0x10, 0))),
        "reserved_addr": fixed(bytes((0x31, 0x5A, 1, 2, 0x10, 0))),  # bit 5
        "reserved_addr ": fixed(bytes((0x51, 0x5A, 1, 2, 0x10, 0))),  # bit 6
        "length": fixed(bytes((0x11, 0x5A, 1, 3, 0x10, 0))),
        "msg_header": fixed(bytes((0x11, 0x5A, 1, 3, 0x10, 0, 0x10))),
        "msg_length": fixed(bytes((0x11, 0x5A, 1, 11, 0x33, 9)) + bytes(9)),
        "payload_size": fixed(bytes((0x11, 0x5A, 1, 3, 0x10, 1, 0))),
        "padding": fixed(bytes((0x91, 0x5A, 1, 10, 0xFD, 8, 0, 1, 0, 0, 0, 0, 0, 0))),
        "no_message": fixed(bytes((0x11, 0x5A, 1, 0))),
    }
    answers = ask(sbtool, [f"body {h}" for h in cases.values()])
    assert answers == [f"err {name.strip()}" for name in cases]
    for h in cases.values():  # and Python refuses every one
        assert python_outcome(bytes.fromhex(h)).startswith("err")


def test_a_frame_stuffs_into_254_bytes(sbtool: Path) -> None:
    """The writer fills a frame up to 247 message bytes, which stuff into 254
    with the delimiter after them; the decoder refuses a longer run."""
    big = Frame(1, 1, (m.Status(1, 1, 1, 1),) * 24 + (m.Heartbeat(1), m.Ack(1, 2)), True)
    assert len(frame_body(big)) - 6 == MAX_MESSAGE_BYTES
    over = Frame(1, 1, big.messages + (m.Identify(),), True)
    long_wire = bytes.fromhex("ff") + b"\x01" * 254  # 255 stuffed bytes, no 0x00 in them
    stream_bytes = long_wire + b"\x00" + encode_frame(big)  # an overrun, then a frame
    enc_big, enc_over, wire_big, too_long, stream = ask(sbtool, [
        "enc " + fmt_frame(big), "enc " + fmt_frame(over), f"wire {encode_frame(big)[:-1].hex()}",
        f"wire {long_wire.hex()}", f"stream {stream_bytes.hex()}"])
    assert enc_big == f"ok {frame_body(big).hex()} {encode_frame(big).hex()}"
    assert len(encode_frame(big)) - 1 <= 254
    assert enc_over == "err full"
    assert wire_big == "ok " + fmt_frame(big)
    assert too_long == "err too_long"
    assert stream == f"{fmt_frame(big)} || frames 1 crc 0 malformed 0 overruns 1"
    reader = FrameReader()  # the host's reader, fed byte by byte as a UART would
    assert [f for b in stream_bytes for f in reader.feed(bytes((b,)))] == [big]
    assert reader.stats.overruns == 1


def test_board_checks(sbtool: Path) -> None:
    """docs/protocol.md section 3, "Unknown input": the Ack result each board
    gives a message before its state is asked (0 OK, 3 BAD_CHANNEL, 4
    BAD_VALUE, 5 UNKNOWN_TYPE, 7 NOT_SUPPORTED)."""
    msgs: list[m.Message | RawMessage] = [
        m.GetMotor(5), m.GetMotor(6), m.Run(6, 100), m.Move(5, -19000, 10000), m.Move(2, 10, 0),
        m.Move(2, 10, 32768), m.Move(6, 10, 100), m.Stop(0x3F), m.Brake(0x40), m.SetWheelSpeeds(
            1, 2, 3, 4), m.GetSensor(3), m.GetSensor(4), m.GetSensor(5), m.GetSensor(6),
        m.GetImu(1), m.GetImu(2), m.Status(0, 0, 0, 0), RawMessage(0x33, b""), sim.StepTo(1),
        sim.GetTruth(), m.ReadAll(), m.Claim(1000, 7)]
    expected = {
        "motor": [0, 3, 3, 0, 4, 4, 3, 0, 3, 0, 7, 7, 7, 7, 7, 7, 7, 5, 7, 7, 0, 0],
        "motor_sim": [0, 3, 3, 0, 4, 4, 3, 0, 3, 0, 7, 7, 7, 7, 7, 7, 7, 5, 0, 0, 0, 0],
        "sensor": [7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 0, 3, 3, 3, 0, 3, 7, 5, 7, 7, 0, 0],
        "sensor6": [7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 0, 0, 0, 3, 0, 3, 7, 5, 7, 7, 0, 0],
    }
    body = frame_body(Frame(1, 3, tuple(msgs), False, 90)).hex()
    answers = ask(sbtool, [f"check {board} {body}" for board in expected])
    assert answers == ["ok " + " ".join(map(str, e)) for e in expected.values()]


def test_fuzz_harness_short_run(tmp_path: Path) -> None:
    """20,000 frames through the decoder under ASan and UBSan: no finding."""
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "fuzz_firmware.py"),
                           "--frames", "20000", "--build-dir", str(tmp_path)],
                          capture_output=True, text=True, check=False)
    if done.returncode in (2, 3) and ("no C compiler" in done.stderr
                                      or "sanitiz" in done.stderr):
        pytest.skip(done.stderr.strip().splitlines()[-1])
    assert done.returncode == 0, done.stdout + done.stderr
    lines = dict(line.split(": ", 1) for line in done.stdout.splitlines() if ": " in line)
    assert lines["findings"] == "0"
    assert lines["frames"].startswith("20000")
    assert int(lines["accepted"]) > 1000 and int(lines["rejected"]) > 1000


class StandingRobot:
    """A robot that stands still at time 0: enough for the fake boards to answer."""

    def read(self) -> Snapshot:
        return Snapshot(0.0, {s: SensorReading(0.5) for s in BASE_SENSORS},
                        {mid: MotorState(0.0, 0.0) for mid in MotorId})

    def command(self, speeds: Mapping[MotorId, float]) -> None:
        pass

    def stop_all(self) -> None:
        pass

    def truth(self) -> Truth:
        return Truth(False, None, 0.0, 0.0, 0.0)

    def diagnostics(self) -> dict[str, object]:
        return {}

    def close(self) -> None:
        pass


class StillClock:
    def now(self) -> float:
        return 0.0

    def advance(self, dt: float) -> None:
        pass


def fake_board_result(board: int, msg: m.Message | RawMessage) -> int:
    """What the Python fake board (a fresh one, leased to the sender, nothing
    latched, no motor moving) answers ``msg`` with: the Ack's result, or 0
    (OK) for any other reply."""
    world = BoardWorld(StandingRobot(), StillClock(), lockstep=True)  # type: ignore[arg-type]
    fake = make_boards(world)[board]
    (owner,) = fake.handle([m.Claim(m.LEASE_MS, 7)], 0x2A)
    assert isinstance(owner, m.Owner) and owner.result == m.ClaimResult.GRANTED
    (reply, *_) = fake.handle([msg], 0x2A)
    return reply.result if isinstance(reply, m.Ack) else 0


def test_board_checks_match_the_fake_boards(sbtool: Path) -> None:
    """The C checks against the Python fake boards (an implementation of
    section 3 of their own; the fake motor board runs the simulation, so it is
    held against the caps "motor_sim"), over 300 random requests of every
    type, replies and unknown types among them."""
    rng = random.Random(3)
    requests = [c for c in m.MESSAGES.values() if not c.REPLY]
    msgs: list[m.Message | RawMessage] = []
    for _ in range(300):
        if rng.random() < 0.15:
            msg = random_message(rng)
        else:
            cls = rng.choice(requests)
            names = [f.name for f in dataclasses.fields(cls)]
            codes = [c for c in cls.FORMAT.lstrip("<") if c != "x"]
            near = {"channel": (0, 8), "axis": (0, 3), "mask": (0, 255), "timeout_ms": (0, 2)}
            wide = {"B": (0, 255), "H": (0, 65535), "h": (-32768, 32767), "I": (0, 2**32 - 1),
                    "i": (-2**31, 2**31 - 1)}
            msg = cls(*(rng.randint(*near.get(n, wide[c])) for n, c in zip(names, codes,
                                                                            strict=True)))
        msgs.append(msg)
    bodies = [frame_body(Frame(1, 1, (x,), False, 0x2A)).hex() for x in msgs]
    answers = ask(sbtool, [f"check {caps} {b}" for caps in ("motor_sim", "sensor")
                           for b in bodies])
    expected = [f"ok {fake_board_result(board, x)}" for board in (1, 2) for x in msgs]
    assert answers == expected
