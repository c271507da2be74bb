"""Requests and replies on CAN matched by the host's session and a sequence
number (protocol 4.0, docs/protocol.md section 8): late, duplicated and
foreign replies are never taken for a waiting request's and are counted; the
boards answer a repeated frame from their cache and execute a new session's;
a board of protocol 3.x is refused with one line; a captured run decodes with
cantools and the masked DBC."""

from __future__ import annotations

import itertools
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import can
import pytest

from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.can_wire import make_id, wire
from stairbot.drivers.handshake import open_board
from stairbot.errors import NoBoardError, ProtocolVersionError
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import Board, make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.hardware import MotorId
from stairbot.inputs.scenario import load_scenario

_names = itertools.count()
STATUS = m.Status(0x40, 0, 250, 1)
MOTOR = int(m.Board.MOTOR)


def telemetry(turns: int) -> list[m.Message]:
    """A motor board's ReadAll reply whose counters all read ``turns``."""
    return [STATUS, *(m.MotorTelemetry(c, 1, 0, 0, turns) for c in range(6))]


@dataclass
class Wire:
    """A host link and a bare "board" end on one virtual bus, on a clock the
    test moves."""

    link: CanLink
    boards: can.BusABC
    t: list[float]

    def answer(self, board: int, seq: int, msgs: list[m.Message], session: int | None = None
               ) -> None:
        for msg in msgs:
            self.boards.send(wire().to_can(board, msg, self.link.session
                                           if session is None else session, seq))


@pytest.fixture
def bus() -> Iterator[Wire]:
    channel = f"seq-{next(_names)}"
    t = [0.0]
    link = CanLink(can.Bus(interface="virtual", channel=channel), timeout_s=0.1, retries=0,
                   now=lambda: t[0])
    boards = can.Bus(interface="virtual", channel=channel)
    yield Wire(link, boards, t)
    link.close()
    boards.shutdown()


# -- the host ---------------------------------------------------------------------


def test_a_late_reply_of_a_request_given_up_is_not_taken_for_a_newer_ones(bus: Wire) -> None:
    """A ReadAll given up; a new ReadAll to the same board; the first one's
    Status and telemetry come now: counted late, and the new request waits
    for its own (it used to take them: the same kinds, the oldest request)."""
    old = bus.link.request(MOTOR, [m.ReadAll()])
    bus.t[0] = 1.0
    bus.link.poll()
    assert old.failed
    new = bus.link.request(MOTOR, [m.ReadAll()])
    assert new.seqs != old.seqs
    bus.answer(MOTOR, old.seqs[0], telemetry(111))  # the stale world
    bus.link.poll()
    assert new.reply is None and bus.link.stats.late == 7
    bus.answer(MOTOR, new.seqs[0], telemetry(222))
    (reply,) = bus.link.wait([new])
    assert [x.turns_mt for x in reply.messages[1:]] == [222] * 6  # type: ignore[union-attr]
    assert bus.link.stats.late == 7 and bus.link.stats.stray == 0


def test_a_late_status_is_not_taken_for_a_newer_get_status(bus: Wire) -> None:
    old = bus.link.request(MOTOR, [m.GetStatus()])
    bus.t[0] = 1.0
    bus.link.poll()
    new = bus.link.request(MOTOR, [m.GetStatus()])
    bus.answer(MOTOR, old.seqs[0], [m.Status(0x41, 1, 250, 1)])  # e-stop latched, then
    bus.link.poll()
    assert new.reply is None and bus.link.stats.late == 1
    bus.answer(MOTOR, new.seqs[0], [STATUS])
    assert bus.link.wait([new])[0].messages == (STATUS,)


def test_a_duplicated_reply_frame_is_ignored_and_counted(bus: Wire) -> None:
    req = bus.link.request(MOTOR, [m.ReadAll()])
    (seq,) = req.seqs
    status, *tel = telemetry(5)
    bus.answer(MOTOR, seq, [status, status, tel[0], tel[0], *tel[1:]])  # copies mid-reply
    (reply,) = bus.link.wait([req])
    assert reply.messages == (status, *tel)
    bus.answer(MOTOR, seq, [tel[5]])  # and after it was taken
    bus.link.poll()
    s = bus.link.stats
    assert (s.duplicates, s.stray, s.late, s.timeouts) == (3, 0, 0, 0)


def test_a_reply_of_another_session_is_not_taken(bus: Wire) -> None:
    req = bus.link.request(MOTOR, [m.GetStatus()])
    other = bus.link.session % 1023 + 1
    bus.answer(MOTOR, req.seqs[0], [m.Status(0x41, 1, 250, 1)], session=other)
    bus.link.poll()
    assert req.reply is None
    assert bus.link.stats.stray == 1 and bus.link.other_session == 1
    bus.answer(MOTOR, req.seqs[0], [STATUS])
    assert bus.link.wait([req])[0].messages == (STATUS,)


def test_a_broadcast_is_one_frame_whose_seq_both_boards_requests_await(bus: Wire) -> None:
    motor, sensor = bus.link.broadcast(m.GetStatus())
    assert motor.seqs == sensor.seqs and bus.link.stats.frames_tx == 1
    sent = bus.boards.recv(0)
    assert sent is not None and sent.arbitration_id == make_id(0x0DF, bus.link.session,
                                                              motor.seqs[0])
    bus.answer(2, motor.seqs[0], [STATUS])
    bus.answer(1, motor.seqs[0], [STATUS])
    assert [r.board for r in bus.link.wait([motor, sensor])] == [1, 2]


def test_each_message_of_a_request_is_a_frame_of_its_own_seq(bus: Wire) -> None:
    req = bus.link.request(MOTOR, [m.SetWheelSpeeds(0, 0, 0, 0), m.SetLiftSpeeds(0, 0)])
    first, second = req.seqs
    assert second == (first + 1) % 256
    bus.answer(MOTOR, second, [m.Ack(0x21, 0)])  # the first Ack lost: a gap
    bus.answer(MOTOR, first, [m.Ack(0x20, 0)])  # ...or late, after the second
    bus.link.poll()
    assert req.reply is None and bus.link.stats.late == 1


def test_a_request_held_back_does_not_time_out_before_it_is_sent(bus: Wire) -> None:
    """Lockstep holds commands back until the tick's StepTo goes: a poll in
    between must not give them up unsent (counted lost, and their Acks, when
    they came, nobody's)."""
    held = bus.link.request(MOTOR, [m.SetWheelSpeeds(0, 0, 0, 0)], send=False)
    bus.t[0] = 1.0  # ten timeouts later, still held
    bus.link.poll()
    assert not held.failed and bus.link.stats.timeouts == bus.link.stats.lost == 0
    bus.link.flush()
    assert held.sent_at == 1.0 and held.seqs
    bus.answer(MOTOR, held.seqs[0], [m.Ack(0x20, 0)])
    assert bus.link.wait([held])[0].messages == (m.Ack(0x20, 0),)
    assert bus.link.stats.stray == 0


# -- the boards ---------------------------------------------------------------------


@dataclass
class Rig:
    link: CanLink
    server: CanBoardServer
    boards: dict[int, Board]
    world: BoardWorld


@pytest.fixture
def rig() -> Iterator[Rig]:
    channel = f"seq-rig-{next(_names)}"
    world = make_world(load_config(), load_scenario(), True)
    boards = make_boards(world)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world, boards)
    link = CanLink(InlineBus(can.Bus(interface="virtual", channel=channel), server),
                   timeout_s=0.01, retries=1)
    yield Rig(link, server, boards, world)
    link.close()
    server.bus.shutdown()


def test_a_retried_read_all_whose_reply_was_lost_is_answered_from_the_cache(
        rig: Rig, monkeypatch: pytest.MonkeyPatch) -> None:
    """The ReadAll's replies all lost; the host sends the same frame again (same
    seq); the board answers it from its cache, not by reading the world again."""
    reads: list[m.Message] = []
    answer = rig.boards[MOTOR].answer

    def counting(msg: m.Message) -> list[m.Message]:
        reads.append(msg)
        return answer(msg)

    monkeypatch.setattr(rig.boards[MOTOR], "answer", counting)
    send = rig.server._send
    lost = [True]

    def lose_first_reply(frame: can.Message) -> None:
        if not lost[0]:
            send(frame)

    monkeypatch.setattr(rig.server, "_send", lose_first_reply)
    req = rig.link.request(MOTOR, [m.ReadAll()])
    rig.link.poll()  # the board has it, its reply is gone
    lost[0] = False
    (reply,) = rig.link.wait([req])
    assert len(reply.messages) == 7 and rig.link.stats.retries == 1
    assert rig.server.stats.duplicates == 1
    # the world was read once (the retry round's Heartbeat reads no world)
    assert [x for x in reads if not isinstance(x, m.Heartbeat)] == [m.ReadAll()]


def test_a_new_session_reusing_a_seq_is_executed_and_the_same_session_is_not(rig: Rig) -> None:
    """A Clear is never skipped because a new host happens to reuse the last
    host's seq; the same frame again in one session is a copy, not executed."""
    motor = rig.boards[MOTOR]
    motor.estop = True
    rig.link.exchange(MOTOR, [m.Claim(m.LEASE_MS, 1)])
    rig.link._seq = 41  # the next frame's seq: 42
    rig.link.exchange(MOTOR, [m.Clear(m.ClearMask.ESTOP)])
    assert not motor.estop
    motor.estop = True  # its own button, say
    # the same frame again (a copy the bus made): answered, not executed
    rig.link.send(MOTOR, m.Clear(m.ClearMask.ESTOP), 42)
    rig.link.poll()
    assert motor.estop and rig.server.stats.duplicates == 1
    # a new host (another session) whose seq is 42 too: executed
    newcomer = CanLink(rig.link.bus, timeout_s=0.01, retries=1,
                       session=rig.link.session % 1023 + 1)
    rig.link.exchange(MOTOR, [m.Claim(0, 1)])  # the first host leaves
    newcomer.exchange(MOTOR, [m.Claim(m.LEASE_MS, 2)])
    newcomer._seq = 41
    newcomer.exchange(MOTOR, [m.Clear(m.ClearMask.ESTOP)])
    assert not motor.estop and rig.server.stats.duplicates == 1


def test_host_frames_with_11_bit_ids_are_malformed_to_the_boards(rig: Rig) -> None:
    handled = rig.boards[MOTOR].handled
    rig.server.receive(can.Message(arbitration_id=0x0E1, data=b"", is_extended_id=False))
    assert rig.server.stats.malformed == 1 and rig.server.stats.frames_tx == 0
    assert rig.boards[MOTOR].handled == handled


# -- a board of protocol 3.x ---------------------------------------------------------


class OldBoardBus:
    """A host's bus on which a motor board of protocol 3.0 answers: it takes
    11-bit frames only, and answers Identify with its 11-bit Ident."""

    def __init__(self, channel: str) -> None:
        self.bus = can.Bus(interface="virtual", channel=channel)
        self.board = can.Bus(interface="virtual", channel=channel)
        self.channel_info = channel

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        self.bus.send(msg, timeout)

    def recv(self, timeout: float | None = None) -> can.Message | None:
        while (heard := self.board.recv(0)) is not None:
            if not heard.is_extended_id and heard.arbitration_id in (0x0E1, 0x0EF):
                _, data = m.encode(m.Ident(1, 3, 0, 6, 0x0100, 1))
                self.board.send(can.Message(arbitration_id=0x241, data=data,
                                            is_extended_id=False))
        return self.bus.recv(timeout)

    def shutdown(self) -> None:
        self.bus.shutdown()
        self.board.shutdown()


def test_a_protocol_3_can_board_is_refused_with_one_line() -> None:
    bus = OldBoardBus(f"old-{next(_names)}")
    link = CanLink(bus, timeout_s=0.01, retries=0)  # type: ignore[arg-type]
    try:
        with pytest.raises(ProtocolVersionError) as info:
            open_board(link, "can://virtual/old", m.Board.MOTOR, lockstep=False,
                       watchdog_ms=250, hold_ms=100, nonce=1, lease_ms=m.LEASE_MS,
                       wait_s=time.sleep)
        assert str(info.value) == (
            "can://virtual/old: the motor board speaks protocol 3.0; this host speaks "
            f"{m.PROTOCOL_MAJOR}.x (docs/protocol.md): update the board's firmware or the host")
        assert link.stats.malformed == 1  # its Ident, an 11-bit frame
        # a board that answers neither way is still "no board"
        with pytest.raises(NoBoardError, match="no sensor board answered"):
            open_board(link, "can://virtual/old", m.Board.SENSOR, lockstep=False,
                       watchdog_ms=250, hold_ms=100, nonce=1, lease_ms=m.LEASE_MS,
                       wait_s=time.sleep)
    finally:
        link.close()


# -- a captured run, decoded by cantools -------------------------------------------


def test_a_captured_run_decodes_with_the_masked_dbc_and_no_unknown_frame(
        tmp_path: Path) -> None:
    """Every frame of a short lockstep run (open, ticks, an e-stop, a clear,
    close) in a candump log: ``cantools decode -m 0x1FFC0000`` with the real
    boards' DBC and the simulation's concatenated (as docs/protocol.md says)
    knows each one; with the real DBC alone only the simulation's frames are
    unknown; without the mask it knows none."""
    channel = f"seq-capture-{next(_names)}"
    world = make_world(load_config(), load_scenario(), True)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            make_boards(world))
    spy = can.Bus(interface="virtual", channel=channel)
    link = CanLink(InlineBus(can.Bus(interface="virtual", channel=channel), server),
                   timeout_s=1.0)
    robot = LockstepRobot(link, f"can://virtual/{channel}?lockstep=1")
    for _ in range(5):
        robot.read()
        robot.command({MotorId.MWF: 0.5})
        robot.clock.advance(0.02)
    robot.estop()
    robot.clear()
    robot.close()
    log = tmp_path / "run.log"
    writer = can.CanutilsLogWriter(str(log))
    while (frame := spy.recv(0)) is not None:
        writer.on_message_received(frame)
    writer.stop()
    spy.shutdown()
    server.bus.shutdown()
    real = resources.files("stairbot.drivers").joinpath("stairbot.dbc").read_text()
    sim = resources.files("stairbot.fakes").joinpath("stairbot_sim.dbc").read_text()
    (tmp_path / "stairbot.dbc").write_text(real)
    (tmp_path / "lockstep.dbc").write_text(real + sim)  # cat stairbot.dbc stairbot_sim.dbc
    lines = log.read_text().splitlines()
    assert len(lines) > 100

    def decode(*mask: str, dbc: str = "lockstep.dbc") -> list[str]:
        out = subprocess.run([sys.executable, "-m", "cantools", "decode", "--single-line",
                              *mask, str(tmp_path / dbc)], input=log.read_text(),
                             capture_output=True, text=True, check=True).stdout.splitlines()
        assert len(out) == len(lines)
        return out

    sim_bases = {0x0F1, 0x101, 0x251, 0x261}  # StepTo, GetTruth, StepDone, Truth
    unknown = [x for x in decode("-m", "0x1FFC0000", dbc="stairbot.dbc")
               if "Unknown frame id" in x]
    assert unknown and {int(x.split()[2].split("#")[0], 16) >> 18 for x in unknown} <= sim_bases
    masked = decode("-m", "0x1FFC0000")
    assert not [x for x in masked if "Unknown frame id" in x]
    names = {x.split(" :: ")[1].split("(")[0] for x in masked}
    assert {"ReadAll_All", "Status_Motor", "MotorTelemetry_Motor", "ImuTelemetry_Sensor",
            "EStop_All", "Clear_All", "StepTo_Motor", "StepDone_Motor", "Ack_Motor",
            "SetWatchdog_All"} <= names
    assert all("Unknown frame id" in x for x in decode())  # the mask is what finds them
