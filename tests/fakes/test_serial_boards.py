"""The fake boards' serial server: arbitrary bytes and arbitrary well-framed
messages never crash it (they are counted), repeats are answered from the
cache, and the host's link survives whatever comes back."""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest
from cobs import cobs
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_boards import StubClock, StubRobot

from stairbot.drivers import messages as m
from stairbot.drivers.serial_link import FdChannel, SerialLink
from stairbot.drivers.serial_wire import FRAMING_3, Frame, FrameReader, crc16, encode_frame
from stairbot.fakes import sim_messages as sim
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import make_boards
from stairbot.fakes.serial_boards import SerialBoardServer


@pytest.fixture
def server() -> Iterator[tuple[SerialBoardServer, int]]:
    """A server writing into a pipe; yields it and the pipe's read end."""
    robot = StubRobot()
    world = BoardWorld(robot, StubClock(robot), lockstep=True)
    r, w = os.pipe()
    os.set_blocking(r, False)
    yield SerialBoardServer(w, world, make_boards(world)), r
    os.close(r)
    os.close(w)


def drain(fd: int) -> bytes:
    out = b""
    while True:
        try:
            chunk = os.read(fd, 65536)
        except BlockingIOError:
            return out
        if not chunk:
            return out
        out += chunk


@settings(max_examples=200, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.binary(max_size=600))
def test_arbitrary_bytes_never_crash_the_server(server: tuple, data: bytes) -> None:
    srv, r = server
    srv.receive(b"\x00")  # start from a clean receiver
    s = srv.stats
    before = s.crc_errors + s.malformed + s.frames_rx + s.stray
    overruns = srv._reader.stats.overruns
    srv.receive(data + b"\x00")
    drain(r)
    if srv._reader.stats.overruns == overruns:  # every chunk is handled or counted
        chunks = [c for c in (data + b"\x00").split(b"\x00")[:-1] if c]
        assert s.crc_errors + s.malformed + s.frames_rx + s.stray - before == len(chunks)
    # and it still answers a good frame afterwards
    srv.receive(b"\x00" + encode_frame(Frame(1, 77, (m.GetStatus(),))))
    replies = FrameReader().feed(drain(r))
    assert replies and replies[-1].seq == 77 and isinstance(replies[-1].messages[0], m.Status)


bodies = st.lists(st.tuples(st.integers(0, 255), st.binary(max_size=8)), min_size=1,
                  max_size=6)


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.integers(0, 15), st.integers(0, 255), bodies)
def test_arbitrary_messages_in_valid_frames_never_crash_a_board(
        server: tuple, board: int, seq: int, msgs: list[tuple[int, bytes]]) -> None:
    srv, r = server
    # keep the stub world's time small: a StepTo to an hour would be obeyed
    msgs = [(c, p) for c, p in msgs if c != sim.StepTo.TYPE]
    payload = b"".join(bytes((c, len(p))) + p for c, p in msgs)
    body = bytes((board | FRAMING_3, 0x5A, seq, len(payload))) + payload
    body += crc16(body).to_bytes(2, "big")
    srv.receive(cobs.encode(body) + b"\x00")
    out = FrameReader().feed(drain(r))
    for frame in out:  # whatever it answered is well-formed and from that board
        assert frame.from_board and frame.board == board and frame.seq == seq
        assert frame.session == 0x5A


def claim(srv: SerialBoardServer, r: int, session: int, lease_ms: int = m.LEASE_MS) -> None:
    """Take (or with ``lease_ms`` 0 give up) the motor board's lease for ``session``."""
    srv.receive(encode_frame(Frame(1, 200, (m.Claim(lease_ms, session),), session=session)))
    (reply,) = FrameReader().feed(drain(r))
    assert isinstance(reply.messages[0], m.Owner)


def test_a_repeated_frame_is_answered_again_but_executed_once(server: tuple) -> None:
    srv, r = server
    claim(srv, r, 0)  # the session of the frames below
    move = encode_frame(Frame(1, 5, (m.Move(0, 1000, 1000),)))
    srv.receive(move)
    first = drain(r)
    srv.receive(move)
    assert drain(r) == first and srv.stats.duplicates == 1
    robot = srv.world.robot
    assert isinstance(robot, StubRobot)
    assert robot.commands == 1


def test_the_same_seq_and_bytes_of_another_session_are_executed(server: tuple) -> None:
    """A new host (or the same one restarted) starts its sequence numbers over:
    its request is not a duplicate of the last host's, even byte for byte."""
    srv, r = server
    robot = srv.world.robot
    assert isinstance(robot, StubRobot)
    claim(srv, r, 1)
    for session in (1, 1, 2):
        if session == 2:  # the first host leaves; the next takes the boards
            claim(srv, r, 1, lease_ms=0)
            claim(srv, r, 2)
        srv.receive(encode_frame(Frame(1, 5, (m.Move(0, 1000, 1000),), session=session)))
        (reply,) = FrameReader().feed(drain(r))
        assert reply.session == session and reply.seq == 5
    assert robot.commands == 2 and srv.stats.duplicates == 1


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=600))
def test_arbitrary_bytes_from_the_boards_never_crash_the_host(data: bytes) -> None:
    r, w = os.pipe()
    try:
        link = SerialLink(FdChannel(r), timeout_s=0.001)
        os.write(w, data + b"\x00")
        link.poll()
        s = link.stats
        assert s.frames_rx == 0  # nothing was asked, so nothing is a reply
        chunks = [c for c in (data + b"\x00").split(b"\x00")[:-1] if c]
        if len(data) <= 254:  # no overrun possible: every chunk is counted
            assert s.stray + s.crc_errors + s.malformed == len(chunks)
    finally:
        os.close(r)
        os.close(w)


def test_a_request_whose_replies_cannot_fit_one_frame_gets_those_that_fit(
        server: tuple) -> None:
    """Forty ReadAlls in one frame ask for far more than 255 message bytes of
    replies (the fuzz script found the board raising here): the board answers
    with one frame of the replies that fit, in order, and counts the cut."""
    srv, r = server
    srv.receive(encode_frame(Frame(1, 9, (m.ReadAll(),) * 40)))
    (reply,) = FrameReader().feed(drain(r))
    assert reply.from_board and reply.seq == 9 and isinstance(reply.messages[0], m.Status)
    assert srv.stats.cut == 1
    assert sum(2 + len(p) for p in (m.encode(x)[1] for x in reply.messages)) <= 255


class _Silent:
    """A board that answers nothing (the fault matrix's killed or hung board)."""

    def handle(self, msgs: object, session: int) -> list[m.Message]:
        return []


def test_a_board_that_answers_nothing_leaves_the_server_serving_the_other(
        server: tuple) -> None:
    """The motor board killed: its frames get no reply, and the server goes on
    answering the sensor board (it raised on the empty reply before, and the
    thread that serves both boards died)."""
    srv, r = server
    srv.boards[m.Board.MOTOR] = _Silent()
    srv.receive(b"\x00" + encode_frame(Frame(m.Board.MOTOR, 5, (m.GetStatus(),))))
    assert drain(r) == b""
    srv.receive(encode_frame(Frame(m.Board.SENSOR, 6, (m.GetStatus(),))))
    (reply,) = FrameReader().feed(drain(r))
    assert reply.board == m.Board.SENSOR and reply.seq == 6
