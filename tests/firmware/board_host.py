"""A host on a motor board's serial line, for the tests that drive a board
with the host's own serial driver (SerialLink, handshake.open_board): the
native board and the Python fakes (test_motor_board.py), the board in QEMU
(test_qemu_board.py).

Nothing here waits for a time the protocol does not define: a wait for a
latch polls until it shows, giving up after a few seconds."""

from __future__ import annotations

import os
import time
import tty
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from stairbot.drivers import messages as m
from stairbot.drivers.handshake import open_board, release_board
from stairbot.drivers.serial_link import FdChannel, SerialLink

MOTOR = m.Board.MOTOR
LEASE_MS = 5000  # long beside the watchdog: a test's host keeps its lease while it waits
NONCE = 0x5EED
GIVE_UP_S = 5.0  # a latch the protocol says must come that has not come by then never will


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


def reached_by_any_board(msg: m.Message | m.RawMessage) -> set[str]:
    """What a reply every board gives shows a step-by-step script reached:
    each Ack result, each Claim result, the latches in a Status."""
    if isinstance(msg, m.Ack):
        return {f"ack {m.AckResult(msg.result).name}"}
    if isinstance(msg, m.Owner):
        return {f"claim {m.ClaimResult(msg.result).name}"}
    if isinstance(msg, m.Status):
        return ({"estop"} if msg.flags & m.StatusFlag.ESTOP else set()) | (
            {"watchdog"} if msg.flags & m.StatusFlag.WATCHDOG else set()) | (
            {"status FAULT"} if msg.flags & m.StatusFlag.FAULT else set())
    return set()
