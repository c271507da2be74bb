"""The link protocol over a python-can bus.

:class:`CanLink` is a :class:`~stairbot.drivers.request_link.RequestLink`, as the
serial link is: retries, expiry and the health counters are shared.  What is
CAN's own (docs/protocol.md, "CAN"):

* Each message is one frame, whose 29-bit id carries the link's ``session``
  (drawn at random when the link opens, 1-1023) and a ``seq`` (mod 256) of
  its own: one per frame the host sends.  A request of two messages takes two
  seqs; a message asked of both boards in a row goes out once, as the
  broadcast frame of board 15, whose one seq both boards' requests await.
* A board's replies repeat the session and seq of the frame they answer.  A
  reply is taken only when its session is ours and its (board, seq) names a
  frame of a request still waiting; then by what the message is answered with
  (``ANSWER``: Identify -> Ident; Heartbeat, GetStatus, SetWatchdog, EStop,
  Clear -> Status; GetMotor/GetSensor/GetImu -> one telemetry frame; commands
  -> Ack; ReadAll -> Status + one telemetry frame per channel and per IMU axis,
  ``messages.read_all_reply``: as many sensor channels as the board's Ident
  said, ``set_channels``), telemetry by its channel.  An Ack naming the
  message's type answers any of them (a refusal).
* A retry of an idempotent request is the same frame again (same seq): a
  board answers it from its cache without acting twice.  A second copy of a
  reply already taken is counted ``duplicates``; a reply to a request given
  up ``late``; a reply of another session, or of a seq nobody sent, ``stray``.
  Frames a host sends (its own echo on ``udp_multicast``, another host's) are
  ``ignored``; 11-bit frames (protocol 3.x) are ``malformed``.
* The bus's own health -- its state, error frames, floods of frames from
  other nodes -- is ``bus_health.BusWatch``'s: bus-off or a flood raises
  BusFaultError.

How one request takes its replies is :class:`~stairbot.drivers.can_request.CanRequest`.
"""

from __future__ import annotations

import secrets
import time
from collections import OrderedDict
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

import can

from stairbot.drivers import messages as m
from stairbot.drivers.bus_health import BusWatch, socketcan_errors
from stairbot.drivers.can_request import CanRequest, Offer
from stairbot.drivers.can_wire import BROADCAST, SESSION_MAX, CanFrame, CanWire, frame_bits, wire
from stairbot.drivers.frame_log import CanFrameLog
from stairbot.drivers.link import LinkStats
from stairbot.drivers.request_link import RequestLink
from stairbot.errors import LinkLostError

PAST_SEQS = 512
"""How many (board, seq) of requests answered or given up are remembered, to
tell a duplicate or a late reply from a stray one."""


@dataclass
class CanStats(LinkStats):
    """LinkStats plus the bus time used (worst-case stuffed bits) by the frames
    sent and by the boards' frames received."""

    bits_tx: int = 0
    bits_rx: int = 0
    ignored: int = 0  # frames from hosts (our own echo included)
    error_frames: int = 0  # python-can's is_error_frame
    foreign: int = 0  # frames from other nodes: undecodable, other sessions'
    bus_state: int = 0  # bus_health.BusState: 0 active, 1 error-passive, 2 bus-off
    bus_passive: int = 0  # times the bus went error-passive
    flood_id: int = -1  # the id that flooded the bus, -1 none
    flood_per_s: int = 0  # its window's foreign frames a second


class CanLink(RequestLink[CanRequest]):
    """Requests and replies for both boards on one python-can bus."""

    wire = "CAN bus"
    stats: CanStats

    def __init__(self, bus: can.BusABC, timeout_s: float = 0.1, retries: int = 2,
                 max_lost: int = 3, now: Callable[[], float] = time.perf_counter,
                 codec: CanWire | None = None, grace_s: float = 0.0,
                 session: int | None = None, log: CanFrameLog | None = None,
                 on_close: Callable[[], None] | None = None) -> None:
        super().__init__(CanStats(), timeout_s, retries, max_lost, now, grace_s)
        self.bus = bus
        self.log = log  # every frame sent and received
        self._on_close = on_close  # after the bus shut down: the machine's lock on it
        self.codec = codec or wire()
        # This link's session: a reply of another (an earlier host's, still on
        # the bus) is never taken for one of ours, and a board executes a
        # frame of a new session even if its seq repeats the last one it saw.
        self.session = session if session is not None else secrets.randbelow(SESSION_MAX) + 1
        if not 1 <= self.session <= SESSION_MAX:
            raise ValueError(f"session {self.session}: allowed 1 to {SESSION_MAX}")
        self.other_session = 0  # replies of another session seen (counted stray too)
        # Random too, so that a new session that drew an earlier one's number
        # still seldom repeats a frame.
        self._seq = secrets.randbelow(256)
        self._past: OrderedDict[tuple[int, int], bool] = OrderedDict()  # -> answered?
        self._held: list[CanRequest] = []
        self.old_idents: dict[int, m.Ident] = {}  # boards heard speaking protocol 3.x
        self.channels: dict[int, int] = {}  # board -> its channels, from its Ident
        self.watch = BusWatch(self.stats, socketcan_errors(bus))

    # -- sending ---------------------------------------------------------------
    def _new(self, board: int, messages: tuple[m.Message, ...], idempotent: bool,
             now: float) -> CanRequest:
        req = CanRequest(board, messages, idempotent, now, now + self.timeout_s,
                         channels=self.channels.get(board))
        req.expect()
        return req

    def set_channels(self, board: int, channels: int) -> None:
        """``board`` answers ReadAll with ``channels`` telemetry frames (its
        Ident says; the handshake tells): a sensor board with the side pair
        sends 6 SensorTelemetry, one without 4."""
        with self._mutex:
            self.channels[board] = channels

    def _next_seq(self) -> int:
        """A seq no waiting request's frame has; its past is forgotten."""
        used = {s for queue in self._in_flight.values() for r in queue for s in r.seqs}
        for _ in range(256):
            self._seq = (self._seq + 1) & 0xFF
            if self._seq not in used:
                for board in m.Board:
                    self._past.pop((int(board), self._seq), None)
                return self._seq
        raise LinkLostError("256 frames await replies: the boards do not answer")

    def _transmit(self, req: CanRequest, send: bool) -> None:
        self._held.append(req)
        if send:
            self.flush()

    def _resend(self, req: CanRequest) -> None:
        req.expect()
        self._send(req)

    def flush(self) -> None:
        """Send every held request, in order; a single message held for every
        board in a row (ReadAll to both) becomes one broadcast frame."""
        with self._mutex:
            held, self._held = self._held, []
            self._send_now(held)

    def _send_now(self, requests: Sequence[CanRequest]) -> None:
        """One broadcast frame for each copy to every board (a request per
        board, with one seq or none yet), else a frame per message."""
        for board, msg, seq in self._frames(requests):
            self.send(board, msg, seq)

    def _frames(self, requests: Sequence[CanRequest]) -> Iterator[tuple[int, m.Message, int]]:
        boards = {int(b) for b in m.Board}
        i = 0
        while i < len(requests):
            group = requests[i:i + len(boards)]
            first = group[0]
            if (len(group) == len(boards) and {q.board for q in group} == boards
                    and all(len(q.messages) == 1 and q.messages == first.messages
                            and q.seqs == first.seqs for q in group)):
                seqs = first.seqs or (self._next_seq(),)
                for q in group:
                    if not q.seqs:
                        self._going_out(q)
                    q.seqs = seqs
                yield BROADCAST, first.messages[0], seqs[0]
                i += len(group)
            else:
                yield from self._frames_of(first)
                i += 1

    def _frames_of(self, req: CanRequest) -> Iterator[tuple[int, m.Message, int]]:
        if not req.seqs:
            self._going_out(req)
            req.seqs = tuple(self._next_seq() for _ in req.messages)
        for msg, seq in zip(req.messages, req.seqs, strict=True):
            yield req.board, msg, seq

    def _going_out(self, req: CanRequest) -> None:
        """``req`` goes on the bus for the first time: its timeout (and its
        round trip) starts now, not when it was held back."""
        req.sent_at = self._now()
        req.deadline = req.sent_at + self.timeout_s

    def _on_wire(self, req: CanRequest) -> bool:
        # A request held back (send=False) has no seq yet: it cannot time out
        # before it is sent -- given up then, its replies would be nobody's.
        return bool(req.seqs)

    def _send(self, req: CanRequest) -> None:
        for board, msg, seq in self._frames_of(req):
            self.send(board, msg, seq)

    def send(self, board: int, msg: m.Message, seq: int = 0) -> None:
        """One frame of this session, no reply expected (a request's frames
        go through :meth:`request`)."""
        self._put(self.codec.to_can(board, msg, self.session, seq))

    def _put(self, frame: can.Message) -> None:
        try:
            self.bus.send(frame, timeout=self.timeout_s)
        except (can.CanError, OSError, ValueError) as exc:
            raise LinkLostError(f"cannot send on the CAN bus: {exc}") from exc
        if self.log is not None:
            self.log.write(frame, rx=False)
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
        if self.log is not None:
            self.log.write(frame, rx=True)
        with self._mutex:
            self.take(frame)
        return True

    def take(self, frame: can.Message) -> None:
        """Handle one received frame: a board's reply is matched to what waits
        for it; anything else is counted (error frames as ``error_frames``,
        undecodable ones as ``malformed``, host frames as ``ignored``;
        undecodable frames and another session's as ``foreign`` too).  BusFaultError when
        the bus is off or flooded (``bus_health``)."""
        if frame.is_error_frame:
            self.watch.error_frame(frame)
            return
        try:
            f = self.codec.from_can(frame)
        except m.CodecError:
            self.stats.malformed += 1
            old = self.codec.old_ident(frame)
            if old is not None:
                self.old_idents[old[0]] = old[1]
            else:
                self.watch.foreign(frame, "malformed", self._now())
            return
        if not f.message.REPLY:
            self.stats.ignored += 1  # not counted in bits_rx: our own echo is in bits_tx
            if f.session != self.session:
                self.watch.foreign(frame, "another host's", self._now())
            return
        self.stats.bits_rx += frame_bits(len(frame.data))
        self.stats.bytes_rx += len(frame.data)
        if f.session != self.session:
            self.watch.foreign(frame, "another session's reply", self._now())
        self._match(f)

    def _match(self, f: CanFrame) -> None:
        if f.session != self.session:
            self._hear(f.board)
            self.other_session += 1
            self.stats.stray += 1
            return
        for p in self.in_flight(f.board):
            index = p.index_of(f.seq)
            if index is None:
                continue
            self._hear(f.board, feed=p.feed)
            verdict = p.offer(f.message, index)
            if verdict is Offer.TAKEN:
                if p.todo:
                    pass
                elif p.gap:  # every reply that will come came, some were lost
                    self.stats.frames_rx += len(p.got)
                    p.deadline = self._now()  # sent again (or given up) at once
                else:
                    self._complete(p, tuple(p.got), frames=len(p.got))
                    self._remember(p, answered=True)
            elif verdict is Offer.DUPLICATE:
                self.stats.duplicates += 1
            elif verdict is Offer.LATE:
                self.stats.late += 1
            else:
                self.stats.stray += 1
            return
        self._hear(f.board)
        past = self._past.get((f.board, f.seq))
        if past is None:
            self.stats.stray += 1
        elif past:
            self.stats.duplicates += 1
        else:
            self.stats.late += 1

    def _remember(self, req: CanRequest, answered: bool) -> None:
        for seq in req.seqs:
            self._past[(req.board, seq)] = answered
            self._past.move_to_end((req.board, seq))
        while len(self._past) > PAST_SEQS:
            self._past.popitem(last=False)

    def _given_up(self, req: CanRequest) -> None:
        self._remember(req, answered=False)

    # -- protocol 3.x boards -------------------------------------------------------
    def probe_old_ident(self, board: int) -> m.Ident | None:
        """Send ``board`` the Identify of protocol 3.x (an 11-bit id) and wait,
        as long as a request's every attempt would, for a 3.x Ident; None if
        none came.  For a board that ignores this host's frames, to say why."""
        with self._mutex:
            self.old_idents.pop(board, None)
            self._put(self.codec.old_identify(board))
        deadline = self._now() + self.timeout_s * (self.retries + 1)
        while board not in self.old_idents:
            remaining = deadline - self._now()
            if remaining <= 0 or not self._receive(remaining):
                break
        return self.old_idents.get(board)

    def _check_bus(self) -> None:
        self.watch.read_state(self.bus)

    def bus_trouble(self) -> str | None:
        return self.watch.trouble()

    def describe(self) -> dict[str, object]:
        out: dict[str, object] = {
            "wire": self.wire, "session": self.session,
            "bus": {"interface": type(self.bus).__name__, "channel": str(self.bus.channel_info)}}
        if self.log is not None:
            out["frame_log"] = self.log.describe()
        return out

    def close(self) -> None:
        """Shut the bus down, close the frame log, then run ``on_close``
        (each even if the one before failed)."""
        try:
            self.bus.shutdown()
        finally:
            try:
                if self.log is not None:
                    self.log.close()
            finally:
                if self._on_close is not None:
                    self._on_close()
