"""The motor board's firmware in C (firmware/board, run as
firmware/native's sb_motor_native on a pseudo-terminal with a trivial plant)
driven by the host's own serial driver (SerialLink, handshake.open_board),
beside the Python fake boards (``stairbot fake-boards --serial``) where the
assertions hold for both: identify and protocol version, one owner (a second
session refused NOT_OWNER), a retried frame answered from the duplicate cache
and not executed twice, the watchdog stopping the motors and latching, the
command hold, the e-stop latched until Clear, and speeds and counters in
the telemetry (exact and clamped on the C board's plant).  The C board
against the Python fake step by step: test_motor_board_steps.py.
The host's helpers are board_host.py's."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from board_host import (
    GIVE_UP_S,
    LEASE_MS,
    MOTOR,
    NONCE,
    flags,
    host,
    ok,
    one,
    owner,
    read_all,
    until,
)
from firmware_build import LIFT_LIMIT, WHEEL_LIMIT, build

from stairbot.drivers import messages as m
from stairbot.drivers.handshake import check_version
from stairbot.drivers.serial_link import SerialLink
from stairbot.drivers.serial_wire import Frame, FrameReader, encode_frame


@dataclass
class Boards:
    kind: str  # "c" or "python"
    path: str  # the pty a host opens
    proc: subprocess.Popen[str]


def build_native(out: Path) -> Path:
    return build(out / "sb_motor_native", ("core", "board", "plant"),
                 ("native/plant.c", "native/sb_native.c", "native/sb_motor_native.c"), ["-O2"])


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
        if boards.kind == "c":  # the plant's measured speeds follow on its next millisecond
            until("every motor stopped",
                  lambda: all(t.speed_mtps == 0 for t in read_all(other)[1]))
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
