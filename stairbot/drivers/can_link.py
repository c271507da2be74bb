"""Requests and replies over a python-can bus, with the serial link's interface.

:class:`CanLink` offers what :class:`stairbot.drivers.link.Link` offers the
robot driver (``request``, ``wait``, ``poll``, ``exchange``, ``stats``,
``lost_streak``), so the same board logic drives both wires.  CAN frames carry
no sequence number (a message fills the 8 bytes), so replies are matched to
requests by what each message is answered with (docs/protocol.md, "CAN"):

* Identify -> Ident; Heartbeat, GetStatus, SetWatchdog, EStop, Clear -> Status;
  ReadAll -> Status + one telemetry frame per channel; GetMotor/GetSensor ->
  one telemetry frame; StepTo -> StepDone; GetTruth -> Truth; commands -> Ack.
  An Ack naming the message's type answers any of them (a refusal).
* A board sends its replies in order, and a CAN bus keeps the order of one
  sender's frames, so a board's replies fill its oldest waiting request first.
* A request waits ``timeout_s``; only idempotent ones are re-sent (up to
  ``retries`` times).  Replies still owed by a request given up are counted
  ``late`` when they come; a reply nobody waits for is ``stray``.  Frames a
  host sends (its own echo on ``udp_multicast``, another host's) are ignored.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import can

from stairbot.drivers import messages as m
from stairbot.drivers.can_wire import BROADCAST, CanWire, frame_bits, wire
from stairbot.drivers.link import LinkStats, Request
from stairbot.drivers.serial_wire import Frame
from stairbot.errors import LinkLostError

_CHANNELS = {int(m.Board.MOTOR): (len(m.MOTOR_CHANNELS), m.MotorTelemetry),
             int(m.Board.SENSOR): (len(m.SENSOR_CHANNELS), m.SensorTelemetry)}
_STATUS_ANSWERED = (m.Heartbeat, m.GetStatus, m.SetWatchdog, m.EStop, m.Clear)
_SINGLE: dict[type[m.Message], type[m.Message]] = {
    m.Identify: m.Ident, m.StepTo: m.StepDone, m.GetTruth: m.Truth,
    m.GetMotor: m.MotorTelemetry, m.GetSensor: m.SensorTelemetry,
}


def expected_replies(board: int, msg: m.Message) -> list[type[m.Message]]:
    """The reply messages, in order, a board sends for ``msg`` when it obeys."""
    if isinstance(msg, _STATUS_ANSWERED):
        return [m.Status]
    if isinstance(msg, m.ReadAll):
        count, kind = _CHANNELS.get(board, (0, m.MotorTelemetry))
        return [m.Status] + [kind] * count
    reply = _SINGLE.get(type(msg))
    return [reply] if reply is not None else [m.Ack]


@dataclass
class CanStats(LinkStats):
    """LinkStats plus the bus time used (worst-case stuffed bits) by the frames
    sent and by the boards' frames received."""

    bits_tx: int = 0
    bits_rx: int = 0
    ignored: int = 0  # frames from hosts (our own echo included)


@dataclass(eq=False)
class CanPending(Request):
    """A request in flight: its messages and the replies still to come."""

    messages: tuple[m.Message, ...] = ()
    got: list[m.Message] = field(default_factory=list)
    todo: deque[tuple[int, int, type[m.Message]]] = field(default_factory=deque)

    def expect(self) -> None:
        """(Re)start waiting for every reply."""
        self.got = []
        self.todo = deque((i, msg.TYPE, kind) for i, msg in enumerate(self.messages)
                          for kind in expected_replies(self.board, msg))

    def offer(self, msg: m.Message) -> bool:
        """Take ``msg`` if it is the next reply this request waits for."""
        if not self.todo:
            return False
        index, request_type, kind = self.todo[0]
        if isinstance(msg, m.Ack):
            if msg.request != request_type:
                return False
            # An Ack answers the message whole: nothing else comes for it.
            while self.todo and self.todo[0][0] == index:
                self.todo.popleft()
        elif isinstance(msg, kind):
            self.todo.popleft()
        else:
            return False
        self.got.append(msg)
        return True

    @property
    def owed(self) -> int:
        """Replies still to come."""
        return len(self.todo)


class CanLink:
    """Requests and replies for both boards on one python-can bus."""

    def __init__(self, bus: can.BusABC, timeout_s: float = 0.1, retries: int = 2,
                 max_lost: int = 3, now: Callable[[], float] = time.perf_counter,
                 codec: CanWire | None = None) -> None:
        self.bus = bus
        self.timeout_s = timeout_s
        self.retries = retries
        self.max_lost = max_lost
        self.codec = codec or wire()
        self._now = now
        self._pending: dict[int, deque[CanPending]] = {}
        self._owed: dict[int, int] = {}  # replies still due to requests given up
        self._seq = 0
        self._held: list[CanPending] = []
        self.lost_streak = 0
        self.stats = CanStats()

    # -- sending ---------------------------------------------------------------
    def request(self, board: int, messages: Sequence[m.Message], send: bool = True
                ) -> CanPending:
        """Send ``messages`` to ``board``, one frame each; the replies are
        collected by :meth:`wait` or :meth:`poll`.  With ``send=False`` the
        frames wait for :meth:`flush` (or the next request that sends), as on
        the serial link; then one message asked of every board in a row goes
        out once, as a broadcast frame (board 15)."""
        self._seq = (self._seq + 1) & 0xFFFF
        now = self._now()
        p = CanPending(board, self._seq, all(x.IDEMPOTENT for x in messages),
                       now, now + self.timeout_s, messages=tuple(messages))
        p.expect()
        self._pending.setdefault(board, deque()).append(p)
        self._held.append(p)
        if send:
            self.flush()
        return p

    def flush(self) -> None:
        """Send every held request, in order; a single message held for every
        board in a row (ReadAll to both) becomes one broadcast frame."""
        held, self._held = self._held, []
        everyone = set(_CHANNELS)
        i = 0
        while i < len(held):
            p = held[i]
            group = held[i:i + len(everyone)]
            if (len(p.messages) == 1 and {q.board for q in group} == everyone
                    and all(q.messages == p.messages for q in group)):
                self.send(BROADCAST, p.messages[0])
                i += len(group)
            else:
                self._send(p)
                i += 1

    def _send(self, p: CanPending) -> None:
        for msg in p.messages:
            self.send(p.board, msg)

    def broadcast(self, msg: m.Message) -> list[CanPending]:
        """Send ``msg`` once to every board (one frame to board 15) and wait
        for each board's replies as for a request of its own."""
        self.flush()
        out = [self.request(board, [msg], send=False) for board in _CHANNELS]
        self.flush()
        return out

    def send(self, board: int, msg: m.Message) -> None:
        """One frame, no reply expected (e.g. a broadcast EStop)."""
        frame = self.codec.to_can(board, msg)
        try:
            self.bus.send(frame, timeout=self.timeout_s)
        except (can.CanError, OSError, ValueError) as exc:
            raise LinkLostError(f"cannot send on the CAN bus: {exc}") from exc
        self.stats.frames_tx += 1
        self.stats.bytes_tx += len(frame.data)
        self.stats.bits_tx += frame_bits(len(frame.data))

    # -- receiving -------------------------------------------------------------
    def _receive(self, timeout_s: float) -> bool:
        """Take in one frame (waiting up to ``timeout_s``); False if none came."""
        try:
            frame = self.bus.recv(timeout=max(0.0, timeout_s))
        except (can.CanError, OSError, ValueError) as exc:
            raise LinkLostError(f"cannot receive from the CAN bus: {exc}") from exc
        if frame is None:
            return False
        self.take(frame)
        return True

    def take(self, frame: can.Message) -> None:
        """Handle one received frame: a board's reply is matched to what waits
        for it; anything else is counted (error frames as ``crc_errors``,
        undecodable ones as ``malformed``, host frames as ``ignored``)."""
        if frame.is_error_frame:
            self.stats.crc_errors += 1
            return
        try:
            board, msg = self.codec.from_can(frame)
        except m.CodecError:
            self.stats.malformed += 1
            return
        if not msg.REPLY:
            self.stats.ignored += 1  # not counted in bits_rx: our own echo is in bits_tx
            return
        self.stats.bits_rx += frame_bits(len(frame.data))
        self.stats.bytes_rx += len(frame.data)
        self._match(board, msg)

    def _match(self, board: int, msg: m.Message) -> None:
        for p in self._pending.get(board, ()):
            if p.offer(msg):
                if not p.todo:
                    self._complete(p)
                return
        if self._owed.get(board, 0) > 0:
            self._owed[board] -= 1
            self.stats.late += 1
        else:
            self.stats.stray += 1

    def _complete(self, p: CanPending) -> None:
        self.stats.frames_rx += len(p.got)
        self.stats.add_rtt(self._now() - p.sent_at)
        p.reply = Frame(p.board, p.seq & 0xFF, tuple(p.got), from_board=True)
        self._pending[p.board].remove(p)
        if not p.idempotent:
            self.lost_streak = 0

    def _expire(self) -> None:
        now = self._now()
        for board, queue in self._pending.items():
            for p in list(queue):
                if now < p.deadline:
                    continue
                self.stats.timeouts += 1
                owed = p.owed
                if p.idempotent and p.attempts <= self.retries:
                    p.attempts += 1
                    self.stats.retries += 1
                    self._owed[board] = self._owed.get(board, 0) + owed
                    p.sent_at, p.deadline = now, now + self.timeout_s
                    p.expect()
                    self._send(p)
                    continue
                p.failed = True
                self.stats.lost += 1
                self._owed[board] = min(64, self._owed.get(board, 0) + owed)
                queue.remove(p)
                if not p.idempotent:
                    self.lost_streak += 1

    def poll(self) -> None:
        """Take in whatever has arrived, without waiting; expire old requests."""
        self.flush()
        while self._receive(0.0):
            pass
        self._expire()

    def wait(self, pendings: Sequence[CanPending]) -> list[Frame]:
        """The replies of ``pendings``, in order.  Re-sends idempotent requests
        that time out; raises LinkLostError when one gets no complete reply
        after its retries, or ``max_lost`` commands in a row went unanswered."""
        self.flush()
        while True:
            while self._receive(0.0):  # what has arrived counts before any timeout
                pass
            self._expire()
            failed = [p for p in pendings if p.failed]
            if failed:
                p = failed[0]
                names = "+".join(type(x).__name__ for x in p.messages)
                raise LinkLostError(
                    f"board {p.board} did not answer {names} ({p.attempts} attempt(s) of "
                    f"{self.timeout_s * 1e3:.0f} ms; {len(p.got)} of {len(p.got) + p.owed} "
                    "replies came)")
            if self.lost_streak >= self.max_lost:
                raise LinkLostError(f"{self.lost_streak} commands in a row went unanswered")
            waiting = [p for p in pendings if p.reply is None]
            if not waiting:
                return [p.reply for p in pendings if p.reply is not None]
            self._receive(min(p.deadline for p in waiting) - self._now())

    def exchange(self, board: int, messages: Sequence[m.Message]) -> Frame:
        """Send one request and wait for its reply."""
        return self.wait([self.request(board, messages)])[0]

    def close(self) -> None:
        self.bus.shutdown()
