"""The motor board's firmware in C (firmware/board, run as
firmware/native's sb_motor_native on a pseudo-terminal with a trivial plant)
driven by the host's own serial driver (SerialLink, handshake.open_board),
beside the Python fake boards (``stairbot fake-boards --serial``) where the
assertions hold for both: identify and protocol version, one owner (a second
session refused NOT_OWNER), a retried frame answered from the duplicate cache
and not executed twice, the watchdog stopping the motors and latching, the
command hold, the e-stop latched until Clear, and speeds and counters in
the telemetry (exact and clamped on the C board's plant).

Nothing here waits for a time the protocol does not define: a wait for a
latch polls until it shows, giving up after a few seconds."""

from __future__ import annotations

import dataclasses
import os
import random
import select
import shutil
import signal
import socket
import subprocess
import sys
import time
import tty
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import pytest
from cobs import cobs

from stairbot.drivers import messages as m
from stairbot.drivers.handshake import check_version, open_board, release_board
from stairbot.drivers.serial_link import FdChannel, SerialLink
from stairbot.drivers.serial_wire import Frame, FrameReader, RawMessage, encode_frame, parse_body
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import MotorBoard
from stairbot.fakes.serial_boards import SerialBoardServer
from stairbot.hardware import MotorId, MotorState, Snapshot, Truth

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
MOTOR = m.Board.MOTOR
LEASE_MS = 5000  # long beside the watchdog: a test's host keeps its lease while it waits
NONCE = 0x5EED
GIVE_UP_S = 5.0  # a latch the protocol says must come that has not come by then never will
WHEEL_LIMIT, LIFT_LIMIT = 1000, 10000  # the native plant's limits, mturn/s (native/plant.h)


@dataclass
class Boards:
    kind: str  # "c" or "python"
    path: str  # the pty a host opens
    proc: subprocess.Popen[str]


def find_cc() -> str | None:
    names = [os.environ["CC"]] if os.environ.get("CC") else ["cc", "gcc", "clang"]
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    return None


def build_native(out: Path) -> Path:
    cc = find_cc()
    if cc is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    exe = out / "sb_motor_native"
    sources = [str(p) for d in ("core", "board", "native") for p in sorted(
        (FIRMWARE / d).glob("*.c"))]
    includes = [f"-I{FIRMWARE / d}" for d in ("core", "board", "native")]
    subprocess.run([cc, "-std=c11", "-O2", "-Wall", "-Wextra", "-Wpedantic", "-Wconversion",
                    "-Wshadow", "-Werror", *includes, *sources, "-o", str(exe)], check=True)
    return exe


@pytest.fixture(scope="module", params=["c", "python"])
def boards(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
           ) -> Iterator[Boards]:
    tmp = tmp_path_factory.mktemp(f"boards_{request.param}")
    if request.param == "c":
        proc = subprocess.Popen([str(build_native(tmp))], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, text=True)
    else:
        env = {**os.environ, "XDG_STATE_HOME": str(tmp), "XDG_RUNTIME_DIR": str(tmp)}
        proc = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", "--serial"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                stdin=subprocess.DEVNULL, text=True, env=env)
    assert proc.stdout is not None
    first = proc.stdout.readline().strip()
    assert first, proc.communicate(timeout=10)
    path = first.removeprefix("serial://").split("?")[0]
    try:
        yield Boards(request.param, path, proc)
    finally:
        proc.terminate()
        _, err = proc.communicate(timeout=10)
        if request.param == "c":
            assert "sb_motor_native:" in err and " frames" in err, err


def new_link(path: str, avoid: int = 0) -> SerialLink:
    """A host's link on the pty, with a session other than ``avoid``."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    link = SerialLink(FdChannel(fd), timeout_s=0.2)
    if link.session == avoid:
        link.session = avoid % 255 + 1
    return link


@contextmanager
def host(path: str, avoid: int = 0) -> Iterator[SerialLink]:
    """A link that takes nothing (a host on another machine, a program of its own)."""
    link = new_link(path, avoid)
    try:
        yield link
    finally:
        release_board(link, MOTOR, NONCE)
        link.close()


@contextmanager
def owner(path: str) -> Iterator[SerialLink]:
    """A host that has opened the motor board the host's way (Identify,
    Claim, SetWatchdog 250 ms) and cleared what an earlier test latched."""
    with host(path) as link:
        open_board(link, f"serial://{path}", MOTOR, lockstep=False, watchdog_ms=250,
                   hold_ms=0, nonce=NONCE, lease_ms=LEASE_MS, wait_s=time.sleep,
                   allow_latched=True)
        assert flags(one(link, m.Clear(0x07))) & 0x07 == 0
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)
        yield link


def one(link: SerialLink, msg: m.Message) -> m.Message:
    (reply,) = link.exchange(MOTOR, [msg]).messages
    assert isinstance(reply, m.Message), reply
    return reply


def flags(reply: m.Message) -> int:
    """A Status reply's flags (any other reply fails the test)."""
    assert isinstance(reply, m.Status), reply
    return reply.flags


def ok(kind: type[m.Message], result: m.AckResult = m.AckResult.OK) -> m.Ack:
    return m.Ack(kind.TYPE, result)


def read_all(link: SerialLink) -> tuple[m.Status, list[m.MotorTelemetry]]:
    status, *tel = link.exchange(MOTOR, [m.ReadAll()]).messages
    assert isinstance(status, m.Status)
    assert [t.channel for t in tel if isinstance(t, m.MotorTelemetry)] == list(range(6))
    return status, [t for t in tel if isinstance(t, m.MotorTelemetry)]


def until(what: str, check: Callable[[], bool]) -> None:
    """Poll until ``check`` holds (a latch the protocol says comes)."""
    end = time.monotonic() + GIVE_UP_S
    while not check():
        assert time.monotonic() < end, f"never came: {what}"
        time.sleep(0.02)


def test_identify_and_protocol_version(boards: Boards) -> None:
    with host(boards.path) as link:
        ident, status = link.exchange(MOTOR, [m.Identify(), m.GetStatus()]).messages
        assert isinstance(ident, m.Ident) and isinstance(status, m.Status)
        assert (ident.board, ident.protocol_major, ident.protocol_minor, ident.channels) == (
            MOTOR, m.PROTOCOL_MAJOR, m.PROTOCOL_MINOR, 6)
        check_version(f"serial://{boards.path}", MOTOR, ident)
        assert status.flags & m.StatusFlag.SIMULATED and not status.flags & m.StatusFlag.LOCKSTEP
        # what a board does not have, or a board's own message, is not supported
        assert one(link, m.GetSensor(0)) == ok(m.GetSensor, m.AckResult.NOT_SUPPORTED)
        assert one(link, m.Status(0, 0, 0, 0)) == ok(m.Status, m.AckResult.NOT_SUPPORTED)
        assert one(link, m.GetMotor(6)) == ok(m.GetMotor, m.AckResult.BAD_CHANNEL)


def test_one_owner_a_second_session_is_refused(boards: Boards) -> None:
    with owner(boards.path) as first, host(boards.path, avoid=first.session) as second:
        (claimed,) = first.exchange(MOTOR, [m.Claim(LEASE_MS, NONCE)]).messages
        assert isinstance(claimed, m.Owner) and claimed.result == m.ClaimResult.GRANTED
        assert claimed.session == first.session
        held = one(second, m.Claim(LEASE_MS, NONCE + 1))
        assert isinstance(held, m.Owner) and held.result == m.ClaimResult.HELD
        assert (held.session, held.boot) == (first.session, claimed.boot) and held.lease_cs > 0
        for msg in [m.SetWatchdog(0, 0), m.Clear(0x07), m.SetWheelSpeeds(500, 500, 500, 500),
                    m.SetLiftSpeeds(100, 100), m.Run(0, 500), m.Move(0, 1000, 500)]:
            assert one(second, msg) == ok(type(msg), m.AckResult.NOT_OWNER), msg
        # not executed: the watchdog is the first host's, nothing runs
        status, tel = read_all(second)
        assert status.watchdog_ms == 250 and all(t.mode != m.MotorMode.RUN for t in tel)
        # the owner's own commands run; stopping is everyone's right
        assert one(first, m.Run(0, 500)) == ok(m.Run)
        assert read_all(second)[1][0].mode == m.MotorMode.RUN
        assert one(second, m.Stop(0x01)) == ok(m.Stop)
        assert read_all(first)[1][0].mode == m.MotorMode.IDLE
        # given up, the lease is the next host's
        released = one(first, m.Claim(0, NONCE))
        assert isinstance(released, m.Owner) and released.result == m.ClaimResult.RELEASED
        free = one(first, m.Claim(0, NONCE))
        assert isinstance(free, m.Owner) and free.result == m.ClaimResult.FREE
        taken = one(second, m.Claim(LEASE_MS, NONCE))
        assert isinstance(taken, m.Owner) and taken.result == m.ClaimResult.GRANTED
        assert taken.session == second.session
        assert one(first, m.Run(0, 500)) == ok(m.Run, m.AckResult.NOT_OWNER)


def raw_exchange(link: SerialLink, wire: bytes, seq: int) -> bytes:
    """Write ``wire`` on the link's channel and return the reply frame's
    bytes (the motor board's, of ``seq``), read past the link's own reader."""
    link.channel.write(wire)
    reader, got = FrameReader(), b""
    end = time.monotonic() + GIVE_UP_S
    while time.monotonic() < end:
        data = link.channel.read_some(0.05)
        got += data
        for frame in reader.feed(data):
            if frame.from_board and frame.seq == seq and frame.session == link.session:
                return encode_frame(frame)
    raise AssertionError(f"no reply to seq {seq}: {got.hex()}")


def test_a_retried_frame_is_answered_from_the_cache_and_not_executed_twice(
        boards: Boards) -> None:
    with owner(boards.path) as link:
        _, tel = read_all(link)
        start = tel[4].turns_mt
        seq = 77
        # Status.uptime_ms in the reply tells one execution from another
        move = encode_frame(Frame(MOTOR, seq, (m.Move(4, 300, 2000), m.GetStatus()),
                                  session=link.session))
        first = raw_exchange(link, move, seq)
        (reply,) = FrameReader().feed(first)
        assert reply.messages[0] == ok(m.Move) and isinstance(reply.messages[1], m.Status)
        time.sleep(0.05)  # the lift runs on (2000 mturn/s); board time passes
        # the same session, seq and bytes again, the very next frame: the kept reply
        assert raw_exchange(link, move, seq) == first
        until("the Move's stop point", lambda: read_all(link)[1][4].mode == m.MotorMode.IDLE)
        moved = read_all(link)[1][4].turns_mt
        # one Move of 300 from start; run again 50 ms on it would stop at start + 400 or more
        assert start + 300 <= moved < start + 400, (start, moved)
        # the same seq and bytes from another session are executed (a new host)
        other = encode_frame(Frame(MOTOR, seq, (m.Move(4, 300, 2000), m.GetStatus()),
                                   session=link.session % 255 + 1))
        link.channel.write(other)
        reader, replies = FrameReader(), list[Frame]()

        def heard() -> bool:
            replies.extend(f for f in reader.feed(link.channel.read_some(0.05)) if f.from_board)
            return bool(replies)

        until("the other session's reply", heard)
        assert replies[0].messages[0] == ok(m.Move, m.AckResult.NOT_OWNER)


def test_the_watchdog_stops_the_motors_and_latches_until_clear(boards: Boards) -> None:
    with owner(boards.path) as link, host(boards.path, avoid=link.session) as other:
        assert one(link, m.SetWheelSpeeds(300, 300, 300, 300)) == ok(m.SetWheelSpeeds)
        # SetWatchdog(0) is refused while a motor runs
        assert one(link, m.SetWatchdog(0, 0)) == ok(m.SetWatchdog, m.AckResult.BAD_VALUE)
        # the owner falls silent; another host's polling does not feed its watchdog
        until("the watchdog", lambda: bool(read_all(other)[0].flags & m.StatusFlag.WATCHDOG))
        status, tel = read_all(link)
        assert status.fault == m.MotorFault.WATCHDOG and status.flags & m.StatusFlag.WATCHDOG
        assert all(t.mode == m.MotorMode.HOLD for t in tel), tel
        if boards.kind == "c":
            assert all(t.speed_mtps == 0 for t in tel), tel
        # a frame after the timeout does not un-trip it; motion is refused
        assert one(link, m.Run(0, 300)) == ok(m.Run, m.AckResult.WATCHDOG)
        assert one(link, m.Move(0, 100, 300)) == ok(m.Move, m.AckResult.WATCHDOG)
        assert one(other, m.Clear(0x02)) == ok(m.Clear, m.AckResult.NOT_OWNER)
        cleared = one(link, m.Clear(0x02))
        assert isinstance(cleared, m.Status) and not cleared.flags & m.StatusFlag.WATCHDOG
        # clearing restarts nothing; the next command runs
        assert all(t.mode == m.MotorMode.HOLD for t in read_all(link)[1])
        assert one(link, m.Run(0, 300)) == ok(m.Run)
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)
        off = one(link, m.SetWatchdog(0, 0))
        assert isinstance(off, m.Status) and off.watchdog_ms == 0


def test_the_command_hold_stops_a_silent_speed_without_a_latch(boards: Boards) -> None:
    with owner(boards.path) as link:
        assert isinstance(one(link, m.SetWatchdog(2000, 100)), m.Status)
        assert one(link, m.Run(1, 300)) == ok(m.Run)
        # ReadAll feeds the watchdog but is no motion command
        until("the hold", lambda: read_all(link)[1][1].mode == m.MotorMode.IDLE)
        status, _ = read_all(link)
        assert status.flags & 0x07 == 0 and status.fault == m.MotorFault.NONE
        assert one(link, m.Run(1, 300)) == ok(m.Run)
        assert read_all(link)[1][1].mode == m.MotorMode.RUN
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)


def test_the_estop_latches_until_clear(boards: Boards) -> None:
    with owner(boards.path) as link, host(boards.path, avoid=link.session) as other:
        assert one(link, m.SetWheelSpeeds(300, 300, 300, 300)) == ok(m.SetWheelSpeeds)
        stopped = one(other, m.EStop())  # anyone may stop the robot
        assert isinstance(stopped, m.Status) and stopped.flags & m.StatusFlag.ESTOP
        assert stopped.fault == m.MotorFault.ESTOP
        assert all(t.mode == m.MotorMode.HOLD for t in read_all(link)[1])
        for msg in [m.SetWheelSpeeds(300, 300, 300, 300), m.SetLiftSpeeds(100, 100),
                    m.Run(0, 300), m.Move(0, 100, 300)]:
            assert one(link, msg) == ok(type(msg), m.AckResult.ESTOP), msg
        # Stop and Brake are obeyed, latched or not
        assert one(link, m.Brake(0x30 | 0x01)) == ok(m.Brake)
        modes = [t.mode for t in read_all(link)[1]]
        assert modes[0] == m.MotorMode.BRAKE and modes[4] == modes[5] == m.MotorMode.IDLE
        assert one(link, m.Stop(0x40)) == ok(m.Stop, m.AckResult.BAD_CHANNEL)
        # only bit 0x01 clears it, and only the owner may
        assert flags(one(link, m.Clear(0x06))) & m.StatusFlag.ESTOP
        assert one(other, m.Clear(0x01)) == ok(m.Clear, m.AckResult.NOT_OWNER)
        cleared = one(link, m.Clear(0x01))
        assert isinstance(cleared, m.Status) and cleared.flags & 0x07 == 0
        _, tel = read_all(link)
        assert all(t.mode != m.MotorMode.RUN for t in tel)  # clearing never restarts a motor
        assert one(link, m.Run(0, 300)) == ok(m.Run)
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)


def test_speeds_and_counters_in_the_telemetry(boards: Boards) -> None:
    with owner(boards.path) as link:
        _, before = read_all(link)
        assert one(link, m.SetLiftSpeeds(2000, -2000)) == ok(m.SetLiftSpeeds)
        until("the lifts to move", lambda: all(
            abs(a.turns_mt - b.turns_mt) > 50 for a, b in zip(
                read_all(link)[1][4:], before[4:], strict=True)))
        status, tel = read_all(link)
        assert [t.mode for t in tel[4:]] == [m.MotorMode.RUN] * 2
        assert tel[4].turns_mt > before[4].turns_mt and tel[5].turns_mt < before[5].turns_mt
        if boards.kind == "c":  # the trivial plant turns at exactly the commanded speed
            assert (tel[4].speed_mtps, tel[5].speed_mtps) == (2000, -2000)
            assert one(link, m.SetWheelSpeeds(500, -500, 5000, -32767)) == ok(
                m.SetWheelSpeeds)
            assert one(link, m.SetLiftSpeeds(20000, 0)) == ok(m.SetLiftSpeeds)
            clamped = [500, -500, WHEEL_LIMIT, -WHEEL_LIMIT, LIFT_LIMIT, 0]  # each motor's limit
            until("the measured speeds", lambda: [
                t.speed_mtps for t in read_all(link)[1]] == clamped)
            _, tel = read_all(link)
            assert [t.mode for t in tel] == [m.MotorMode.RUN] * 5 + [m.MotorMode.IDLE]
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)


def test_the_estop_button_latches_the_board(boards: Boards) -> None:
    if boards.kind != "c":
        pytest.skip("the Python fake boards have no e-stop button")
    with owner(boards.path) as link:
        assert one(link, m.Run(0, 300)) == ok(m.Run)
        boards.proc.send_signal(signal.SIGUSR1)  # pressed
        until("the button's e-stop", lambda: bool(read_all(link)[0].flags & m.StatusFlag.ESTOP))
        assert all(t.mode == m.MotorMode.HOLD for t in read_all(link)[1])
        boards.proc.send_signal(signal.SIGUSR2)  # released
        until("the release", lambda: not flags(one(link, m.Clear(0x01))) & m.StatusFlag.ESTOP)


# -- the C board against the Python fake motor board, step by step ------------------


class PlantRobot:
    """firmware/native/plant.c in Python, on the Python fake board's side:
    each counter integrates its commanded speed (clamped to the plant's
    limits) in micro-turns; a lift stops at the end of its stroke and says
    "limit".  Time is whole milliseconds; the counters go to the fake as
    floats of turns, as the simulation's do."""

    LIFTS = (m.MOTOR_CHANNELS[4], m.MOTOR_CHANNELS[5])
    STROKE_UMT = 105_000_000

    def __init__(self, lift_mt: int) -> None:
        self.now_ms = 0
        self.cmd = {mid: 0 for mid in m.MOTOR_CHANNELS}
        self.umt = {mid: 0 for mid in m.MOTOR_CHANNELS}
        self.umt[self.LIFTS[0]], self.umt[self.LIFTS[1]] = lift_mt * 1000, -lift_mt * 1000
        self.measured = {mid: 0 for mid in m.MOTOR_CHANNELS}
        self.at_limit = {mid: False for mid in m.MOTOR_CHANNELS}

    def clamped(self, mid: MotorId) -> int:
        """The motor's commanded speed within its limit (mturn/s)."""
        limit = LIFT_LIMIT if mid in self.LIFTS else WHEEL_LIMIT
        return max(-limit, min(limit, self.cmd[mid]))

    def advance_to(self, t_ms: int) -> None:
        dt, self.now_ms = t_ms - self.now_ms, t_ms
        if dt == 0:
            return
        for mid in m.MOTOR_CHANNELS:
            v = self.clamped(mid)
            pos = self.umt[mid] + v * dt
            self.at_limit[mid] = mid in self.LIFTS and abs(pos) > self.STROKE_UMT
            if self.at_limit[mid]:
                pos, v = max(-self.STROKE_UMT, min(self.STROKE_UMT, pos)), 0
            self.umt[mid], self.measured[mid] = pos, v

    def read(self) -> Snapshot:
        def mt(umt: int) -> int:  # plant.c's rounding: a half away from zero
            return (umt + 500) // 1000 if umt >= 0 else -((-umt + 500) // 1000)
        return Snapshot(Fraction(self.now_ms, 1000), {}, {  # type: ignore[arg-type]
            mid: MotorState(mt(self.umt[mid]) / 1000, self.measured[mid] / 1000,
                            "lift limit" if self.at_limit[mid] else None)
            for mid in m.MOTOR_CHANNELS})

    def command(self, speeds: Mapping[MotorId, float]) -> None:
        for mid, tps in speeds.items():
            self.cmd[mid] = round(tps * 1000)

    def stop_all(self) -> None:
        self.cmd = {mid: 0 for mid in m.MOTOR_CHANNELS}

    def truth(self) -> Truth:
        return Truth(False, None, 0.0, 0.0, 0.0)


class PlantClock:
    """The scripted clock: exact (a Fraction of seconds), so the fake's
    watchdog, hold and lease compare whole milliseconds as the C board does."""

    def __init__(self, robot: PlantRobot) -> None:
        self.robot = robot

    def now(self) -> Fraction:
        return Fraction(self.robot.now_ms, 1000)


def random_request(rng: random.Random) -> m.Message | RawMessage:
    """One request of the kinds a host sends, with values near the edges
    that matter (channels and masks past the last, speeds past the limits,
    Moves of speed 0, watchdogs and holds short enough to trip)."""
    kinds: list[Callable[[], m.Message | RawMessage]] = [
        lambda: m.Identify(), lambda: m.GetStatus(), lambda: m.Heartbeat(rng.randrange(256)),
        lambda: m.ReadAll(), lambda: m.ReadAll(), lambda: m.ReadAll(),
        lambda: m.GetMotor(rng.randrange(8)), lambda: m.Clear(rng.choice([1, 2, 4, 7, 7])),
        lambda: m.Claim(rng.choice([0, 200, 1000, 1000]), rng.choice([1, 1, 2])),
        lambda: m.SetWatchdog(rng.choice([0, 0, 100, 250]), rng.choice([0, 0, 60])),
        lambda: m.SetWheelSpeeds(*(rng.randint(-1500, 1500) for _ in range(4))),
        lambda: m.SetLiftSpeeds(rng.randint(-2000, 12000), rng.randint(-12000, 2000)),
        lambda: m.SetLiftSpeeds(rng.randint(-2000, 12000), rng.randint(-12000, 2000)),
        lambda: m.Run(rng.randrange(7), rng.randint(-1500, 1500)),
        lambda: m.Move(rng.randrange(7), rng.randint(-400, 400), rng.choice([0, 300, 997, 5000])),
        lambda: m.Move(rng.randrange(6), rng.randint(-400, 400), rng.choice([300, 997, 5000])),
        lambda: m.Stop(rng.choice([0x01, 0x0F, 0x30, 0x3F, 0x40])),
        lambda: m.Brake(rng.choice([0x01, 0x0F, 0x30, 0x3F, 0x80])),
        lambda: m.EStop() if rng.random() < 0.3 else m.GetStatus(),
        lambda: m.GetSensor(0), lambda: RawMessage(0x55, b"\x01"),
    ]
    return rng.choice(kinds)()


FRAMES = 4000
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]


def test_the_c_board_answers_as_the_python_fake_board_step_by_step(
        tmp_path: Path) -> None:
    """The C board built with AddressSanitizer and UBSan (no report), and
    4,000 frames of two hosts (sessions 7 and 9, each with its own
    sequence numbers, a frame now and then sent again as a retry is), with
    the clock moving 0 to 400 ms between them: every reply frame the same,
    field by field, but Owner.lease_cs (the fake rounds a float: within 1);
    and the script reaches what it is meant to (retries answered from the
    cache, every Ack result, every Claim result, both latches, Moves that
    reach their stop points, a lift at its limit, a reply frame cut at 247
    message bytes); after every frame the two plants stand in the same
    place with their motors commanded alike.  (The fake sums a Move's stop
    point in float turns, so a counter landing exactly on it may run on to
    the next poll there, where the C board stops: firmware/README.md.  This
    script's seed lands on none; seed 2 with 20,000 frames does, at frame
    11,068.)"""
    cc = find_cc()
    if cc is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    exe = tmp_path / "sbboard"
    sources = [str(p) for d in ("core", "board") for p in sorted((FIRMWARE / d).glob("*.c"))]
    built = subprocess.run([cc, "-std=c11", "-O1", "-g", *SANITIZE, "-Wall", "-Wextra",
                            "-Wpedantic", "-Wconversion", "-Wshadow", "-Werror",
                            *(f"-I{FIRMWARE / d}" for d in ("core", "board", "native")),
                            *sources, str(FIRMWARE / "native" / "plant.c"),
                            str(FIRMWARE / "test" / "sbboard.c"), "-o", str(exe)],
                           capture_output=True, text=True, check=False)
    if built.returncode != 0 and "sanitize" in built.stderr:
        pytest.skip(f"{cc} cannot build with {' '.join(SANITIZE)}: {built.stderr.strip()}")
    assert built.returncode == 0, built.stderr
    boot, lift_mt = 0xB007, 103_000  # the lifts start 2 turns from the ends of their stroke
    robot = PlantRobot(lift_mt)
    world = BoardWorld(robot, PlantClock(robot))  # type: ignore[arg-type]
    fake = MotorBoard(world, serial=1)
    fake.boot = fake.lease.boot = boot
    ours, theirs = socket.socketpair()
    server = SerialBoardServer(ours.fileno(), world, {int(MOTOR): fake})
    theirs.setblocking(False)
    rng = random.Random(37)
    t_ms, seqs, last = 0, {7: 0, 9: 0}, {7: b"", 9: b""}
    commands, frames = [], []
    for _ in range(FRAMES):
        t_ms += rng.choice([0, 1, 3, 10, 30, 60, 100, 120, 250, 400])  # 100, 250: on a watchdog
        session = rng.choice([7, 7, 7, 9])
        if last[session] and rng.random() < 0.1:
            wire = last[session]  # a retry: the same bytes
        else:
            seqs[session] = (seqs[session] + 1) & 0xFF
            msgs = tuple(random_request(rng) for _ in range(rng.choice([1, 1, 2, 3])))
            wire = encode_frame(Frame(MOTOR, seqs[session], msgs, session=session))
        last[session] = wire
        commands += [f"t {t_ms}", f"w {wire.hex()}", "s"]
        frames.append((t_ms, wire))
    for seq in (200, 201):  # more replies than a frame holds: the rest left off, alike
        wire = encode_frame(Frame(MOTOR, seq, (m.ReadAll(),) * 4 + (m.Identify(),), session=7))
        commands += [f"t {t_ms}", f"w {wire.hex()}", "s"]
        frames.append((t_ms, wire))
    with subprocess.Popen([str(exe), str(boot), str(lift_mt)], stdin=subprocess.PIPE,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
        out, err = proc.communicate("".join(c + "\n" for c in commands), timeout=60)
    assert proc.returncode == 0 and not err, err  # no sanitizer report
    answers, plants = out.splitlines()[1::3], out.splitlines()[2::3]
    assert len(answers) == len(plants) == len(frames)
    seen: set[str] = set()
    try:
        for i, ((t, wire), c_hex, c_plant) in enumerate(zip(frames, answers, plants,
                                                             strict=True)):
            robot.advance_to(t)
            fake.poll()
            server.receive(wire)
            py = theirs.recv(4096) if select.select([theirs], [], [], 0)[0] else b""
            # the plant in the same place, its motors commanded alike (the C board clamps
            # a speed to the motor's limit; behind the Python fake the plant does)
            py_plant = [robot.umt[mid] for mid in m.MOTOR_CHANNELS] + [
                robot.clamped(mid) for mid in m.MOTOR_CHANNELS]
            assert [int(x) for x in c_plant.split()] == py_plant, (
                i, t, parse_body(cobs_body(wire)))
            c = b"" if c_hex == "-" else bytes.fromhex(c_hex)
            py_frames, c_frames = FrameReader().feed(py), FrameReader().feed(c)
            c_same, py_same = [same_lease(f) for f in c_frames], [same_lease(f) for f in py_frames]
            assert c_same == py_same, (i, t, parse_body(cobs_body(wire)), first_difference(
                c_same, py_same))
            for cf, pf in zip(c_frames, py_frames, strict=True):
                for cm, pm in zip(cf.messages, pf.messages, strict=True):
                    if isinstance(cm, m.Owner) and isinstance(pm, m.Owner):
                        assert abs(cm.lease_cs - pm.lease_cs) <= 1, (i, cm, pm)
                    seen.update(reached(cm))
                if len(cf.messages) < sum(7 if isinstance(x, m.ReadAll) else 1
                                          for x in parse_body(cobs_body(wire)).messages):
                    seen.add("cut")
    finally:
        ours.close()
        theirs.close()
    assert server.stats.duplicates > 50
    wanted = {f"ack {r.name}" for r in m.AckResult if r != m.AckResult.BAD_LENGTH}
    wanted |= {f"claim {r.name}" for r in m.ClaimResult}
    wanted |= {"estop", "watchdog", "mode MOVE", "mode BRAKE", "mode HOLD", "fault LIMIT", "cut"}
    assert wanted <= seen, wanted - seen


def reached(msg: m.Message | RawMessage) -> set[str]:
    """What a reply shows the script reached."""
    if isinstance(msg, m.Ack):
        return {f"ack {m.AckResult(msg.result).name}"}
    if isinstance(msg, m.Owner):
        return {f"claim {m.ClaimResult(msg.result).name}"}
    if isinstance(msg, m.Status):
        return ({"estop"} if msg.flags & m.StatusFlag.ESTOP else set()) | (
            {"watchdog"} if msg.flags & m.StatusFlag.WATCHDOG else set())
    if isinstance(msg, m.MotorTelemetry):
        return {f"mode {m.MotorMode(msg.mode).name}"} | (
            {"fault LIMIT"} if msg.fault == m.MotorFault.LIMIT else set())
    return set()


def first_difference(c: list[Frame], py: list[Frame]) -> str:
    """Where two lists of reply frames first differ, in words."""
    if len(c) != len(py):
        return f"C sent {len(c)} frame(s), Python {len(py)}"
    for cf, pf in zip(c, py, strict=True):
        for j, (cm, pm) in enumerate(zip(cf.messages, pf.messages, strict=False)):
            if cm != pm:
                return f"reply {j}: C {cm}, Python {pm}"
        if cf != pf:
            return f"C {cf}, Python {pf}"
    return "none"


def same_lease(frame: Frame) -> Frame:
    """``frame`` with Owner.lease_cs left out (compared apart, within 1)."""
    return dataclasses.replace(frame, messages=tuple(
        dataclasses.replace(x, lease_cs=0) if isinstance(x, m.Owner) else x
        for x in frame.messages))


def cobs_body(wire: bytes) -> bytes:
    return cobs.decode(wire[:-1])
