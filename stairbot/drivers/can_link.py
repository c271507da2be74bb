"""The link protocol over a python-can bus.

:class:`CanLink` is a :class:`~stairbot.drivers.link.RequestLink`, as the
serial link is: retries, expiry and the health counters are shared.  What is
CAN's own: each message is one frame, and frames carry no sequence number (a
message fills the 8 bytes), so replies are matched to requests by what each
message is answered with (docs/protocol.md, "CAN"):

* the reply a message declares (``ANSWER``: Identify -> Ident; Heartbeat,
  GetStatus, SetWatchdog, EStop, Clear -> Status; GetMotor/GetSensor/GetImu -> one
  telemetry frame; commands -> Ack); ReadAll -> Status + one telemetry frame
  per channel and per IMU axis (``messages.READ_ALL_REPLY``).  An Ack naming
  the message's type answers any of them (a refusal).
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
from stairbot.drivers.link import LinkStats, Request, RequestLink
from stairbot.errors import LinkLostError


def expected_replies(board: int, msg: m.Message) -> list[type[m.Message]]:
    """The reply messages, in order, a board sends for ``msg`` when it obeys."""
    if isinstance(msg, m.ReadAll):
        return list(m.READ_ALL_REPLY.get(board, (m.Status,)))
    return [m.MESSAGES.get(msg.ANSWER, m.Ack)]


@dataclass
class CanStats(LinkStats):
    """LinkStats plus the bus time used (worst-case stuffed bits) by the frames
    sent and by the boards' frames received."""

    bits_tx: int = 0
    bits_rx: int = 0
    ignored: int = 0  # frames from hosts (our own echo included)


def _key(msg: m.Message) -> int | None:
    """Which channel (or IMU axis) a telemetry reply is for; None for others."""
    if isinstance(msg, (m.MotorTelemetry, m.SensorTelemetry)):
        return msg.channel
    if isinstance(msg, m.ImuTelemetry):
        return msg.axis
    return None


@dataclass(eq=False)
class CanRequest(Request):
    """A request on the bus: the replies that came and those still to come.

    A reply is matched by kind and, for telemetry, by channel (or IMU axis):
    the n-th telemetry of a kind a ReadAll is answered with is channel n, so
    a duplicated frame is not taken as another channel's.  A board sends a
    request's replies back to back and CAN keeps their order, so a reply that
    matches a later expected one means the ones before it were lost
    (``gap``): the request cannot complete, and the link sends it again as
    soon as the last reply has come, without waiting for the timeout."""

    got: list[m.Message] = field(default_factory=list)
    # (message index, request type code, reply kind, channel or axis or None)
    todo: deque[tuple[int, int, type[m.Message], int | None]] = field(default_factory=deque)
    gap: bool = False

    def expect(self) -> None:
        """(Re)start waiting for every reply."""
        self.got = []
        self.gap = False
        self.todo = deque()
        for i, msg in enumerate(self.messages):
            seen: dict[type[m.Message], int] = {}
            for kind in expected_replies(self.board, msg):
                n = seen.get(kind, 0)
                seen[kind] = n + 1
                keyed = kind in (m.MotorTelemetry, m.SensorTelemetry, m.ImuTelemetry)
                self.todo.append((i, msg.TYPE, kind, n if keyed else None))

    def _fits(self, entry: tuple[int, int, type[m.Message], int | None],
              msg: m.Message) -> bool:
        _, request_type, kind, key = entry
        if isinstance(msg, m.Ack):
            return msg.request == request_type
        return isinstance(msg, kind) and (key is None or _key(msg) == key)

    def offer(self, msg: m.Message) -> bool:
        """Take ``msg`` if it is a reply this request still waits for: the
        next one, or a later one (then those before it were lost: ``gap``)."""
        pos = next((i for i, entry in enumerate(self.todo) if self._fits(entry, msg)), None)
        if pos is None:
            return False
        if pos:
            self.gap = True
            for _ in range(pos):
                self.todo.popleft()
        index = self.todo[0][0]
        if isinstance(msg, m.Ack):
            # An Ack answers the message whole: nothing else comes for it.
            while self.todo and self.todo[0][0] == index:
                self.todo.popleft()
        else:
            self.todo.popleft()
        self.got.append(msg)
        return True

    @property
    def owed(self) -> int:
        """Replies still to come."""
        return len(self.todo)

    def progress(self) -> str:
        return f"; {len(self.got)} of {len(self.got) + self.owed} replies came"


class CanLink(RequestLink[CanRequest]):
    """Requests and replies for both boards on one python-can bus."""

    wire = "CAN bus"
    stats: CanStats

    def __init__(self, bus: can.BusABC, timeout_s: float = 0.1, retries: int = 2,
                 max_lost: int = 3, now: Callable[[], float] = time.perf_counter,
                 codec: CanWire | None = None, grace_s: float = 0.0) -> None:
        super().__init__(CanStats(), timeout_s, retries, max_lost, now, grace_s)
        self.bus = bus
        self.codec = codec or wire()
        self._owed: dict[int, int] = {}  # replies still due to requests given up
        self._held: list[CanRequest] = []

    # -- sending ---------------------------------------------------------------
    def _new(self, board: int, messages: tuple[m.Message, ...], idempotent: bool,
             now: float) -> CanRequest:
        req = CanRequest(board, messages, idempotent, now, now + self.timeout_s)
        req.expect()
        return req

    def _transmit(self, req: CanRequest, send: bool) -> None:
        self._held.append(req)
        if send:
            self.flush()

    def _resend(self, req: CanRequest) -> None:
        self._owed[req.board] = self._owed.get(req.board, 0) + req.owed
        req.expect()
        self._send(req)

    def flush(self) -> None:
        """Send every held request, in order; a single message held for every
        board in a row (ReadAll to both) becomes one broadcast frame."""
        with self._mutex:
            self._flush()

    def _flush(self) -> None:
        held, self._held = self._held, []
        everyone = set(m.READ_ALL_REPLY)
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

    def _send_now(self, requests: Sequence[CanRequest]) -> None:
        """One broadcast frame for each copy to every board (a request per
        board), else a frame per request."""
        boards = set(m.READ_ALL_REPLY)
        i = 0
        while i < len(requests):
            group = requests[i:i + len(boards)]
            if len(group) == len(boards) and {q.board for q in group} == boards and all(
                    len(q.messages) == 1 and q.messages == group[0].messages for q in group):
                self.send(BROADCAST, group[0].messages[0])
                i += len(group)
            else:
                self._send(requests[i])
                i += 1

    def _send(self, p: CanRequest) -> None:
        for msg in p.messages:
            self.send(p.board, msg)

    def send(self, board: int, msg: m.Message) -> None:
        """One frame, no reply expected."""
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
        with self._mutex:
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
        self._hear(board)
        for p in self.in_flight(board):
            if p.offer(msg):
                if p.todo:
                    pass
                elif p.gap:  # every reply that will come came, some were lost
                    self.stats.frames_rx += len(p.got)
                    p.deadline = self._now()  # sent again (or given up) at once
                else:
                    self._complete(p, tuple(p.got), frames=len(p.got))
                return
        if self._owed.get(board, 0) > 0:
            self._owed[board] -= 1
            self.stats.late += 1
        else:
            self.stats.stray += 1

    def _given_up(self, req: CanRequest) -> None:
        self._owed[req.board] = min(64, self._owed.get(req.board, 0) + req.owed)

    def describe(self) -> dict[str, object]:
        return {"wire": self.wire, "bus": {"interface": type(self.bus).__name__,
                                           "channel": str(self.bus.channel_info)}}

    def close(self) -> None:
        self.bus.shutdown()
