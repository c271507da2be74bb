"""One host owns the robot, on real processes in real time: a second host is
refused in one line, cannot switch off the first one's watchdog or command
its motors, and when the first host is killed mid-run every motor stops and
latches within the watchdog, whoever else is talking to the boards."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from stairbot.drivers import messages as m
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.can_robot import open_bus, parse_can_url
from stairbot.drivers.link import BoardLink
from stairbot.drivers.serial_link import SerialLink
from stairbot.drivers.serial_robot import open_channel, parse_serial_url

OTHER_NONCE = 0xC0FFEE


def stairbot(*args: str, env: dict[str, str]) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "stairbot", *args], text=True, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL)


@contextmanager
def real_time_boards(wire: str, env: dict[str, str]) -> Iterator[str]:
    """Fake boards paced to the wall clock (not lockstep: their watchdog
    counts real time); the URL they print."""
    where = ["--serial"] if wire == "serial" else [
        "--can", f"udp_multicast/239.74.{random.randrange(1, 255)}.{random.randrange(1, 255)}"
                 f"?port={random.randrange(40000, 60000)}"]
    proc = stairbot("fake-boards", *where, env=env)
    assert proc.stdout is not None
    try:
        yield proc.stdout.readline().strip()
    finally:
        proc.terminate()
        proc.communicate(timeout=10)


@contextmanager
def raw_link(wire: str, url: str) -> Iterator[BoardLink]:
    """A link to the boards that takes no lock and claims nothing: what a
    host on another machine, or a program of its own, would be.

    Its session is not the lease holder's.  A link draws its session number
    at random (1-1023 on CAN, 1-255 on serial), and one that draws the
    holder's is the holder to a board, which knows a host by nothing else
    (docs/protocol.md, "One host owns the boards"): such a link is closed
    and another drawn.  Claim(0) with another host's nonce asks who holds
    the lease and never takes or gives it up."""
    while True:
        link: BoardLink
        if wire == "serial":
            port, opts = parse_serial_url(url)
            link = SerialLink(open_channel(port, int(opts["baud"]), url), timeout_s=0.2)
        else:
            link = CanLink(open_bus(parse_can_url(url)), timeout_s=0.2)
        (owner,) = link.exchange(m.Board.MOTOR, [m.Claim(0, OTHER_NONCE)]).messages
        assert isinstance(owner, m.Owner) and owner.result != m.ClaimResult.RELEASED, owner
        if owner.session == 0 or owner.session != link.session:
            break
        link.close()
    try:
        yield link
    finally:
        link.close()


def motors_of(link: BoardLink) -> tuple[m.Status, list[m.MotorTelemetry]]:
    reply = link.exchange(m.Board.MOTOR, [m.ReadAll()])
    status, *tel = reply.messages
    assert isinstance(status, m.Status)
    return status, [t for t in tel if isinstance(t, m.MotorTelemetry)]


def wait_for_motion(host: subprocess.Popen[str]) -> None:
    """Until the run's first phase line (it is moving then)."""
    assert host.stdout is not None
    for _ in range(2):  # "running ...", then the first phase
        line = host.stdout.readline()
        assert line, f"the run ended before it moved: {host.communicate(timeout=10)}"


@pytest.mark.parametrize("wire", ["serial", "can"])
def test_a_second_host_is_refused_and_a_killed_host_leaves_every_motor_stopped_and_latched(
        wire: str, tmp_path: Path) -> None:
    env = {**os.environ, "XDG_STATE_HOME": str(tmp_path), "XDG_RUNTIME_DIR": str(tmp_path)}
    with real_time_boards(wire, env) as url:
        host = stairbot("run", "--robot", url, env=env)
        try:
            wait_for_motion(host)
            time.sleep(1.0)
            # A second stairbot on this machine: refused at once, naming the first.
            spellings = [url] + ([url.replace("serial://", "serial://spy://", 1)]
                                 if wire == "serial" else [])
            for command, spelling in [("run", url), *(("clear", s) for s in spellings)]:
                second = stairbot(command, "--robot", spelling, "--yes", env=env)
                _, err = second.communicate(timeout=30)
                assert second.returncode == 1, err
                assert err.count("\n") == 1 and "in use by another stairbot (pid " \
                    f"{host.pid}" in err, err
            if wire == "can":
                # A host the lock cannot see (another machine): the boards refuse it.
                with raw_link(wire, url) as other:
                    for board in m.Board:
                        (owner,) = other.exchange(board, [m.Claim(m.LEASE_MS, OTHER_NONCE)]
                                                  ).messages
                        assert isinstance(owner, m.Owner)
                        assert owner.result == m.ClaimResult.HELD and owner.session != 0
                        assert other.exchange(board, [m.SetWatchdog(0)]).messages == (
                            m.Ack(m.SetWatchdog.TYPE, m.AckResult.NOT_OWNER),)
                        assert other.exchange(board, [m.Clear()]).messages == (
                            m.Ack(m.Clear.TYPE, m.AckResult.NOT_OWNER),)
                    assert other.exchange(m.Board.MOTOR, [m.SetWheelSpeeds(
                        5000, 5000, 5000, 5000)]).messages == (
                        m.Ack(m.SetWheelSpeeds.TYPE, m.AckResult.NOT_OWNER),)
                    status, _ = motors_of(other)
                    assert status.watchdog_ms == 250 and not status.flags & m.StatusFlag.WATCHDOG
            assert host.poll() is None, host.communicate(timeout=10)
        finally:
            host.send_signal(signal.SIGKILL)
            host.communicate(timeout=10)
        killed = time.monotonic()
        with raw_link(wire, url) as other:
            # Polled from the moment of the kill: the poller's frames feed nothing.
            while time.monotonic() - killed < 0.6:
                motors_of(other)
            status, motors = motors_of(other)
            assert status.flags & m.StatusFlag.WATCHDOG, status
            assert [t.mode for t in motors] == [m.MotorMode.HOLD] * 6
            turns = [t.turns_mt for t in motors]
            time.sleep(0.5)
            _, later = motors_of(other)
            assert [t.turns_mt for t in later] == turns  # nothing moves any more
            # Nor can it be cleared by whoever happens to talk to the boards first.
            for board in m.Board:
                assert other.exchange(board, [m.Clear()]).messages == (
                    m.Ack(m.Clear.TYPE, m.AckResult.NOT_OWNER),)
