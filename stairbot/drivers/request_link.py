"""The one implementation of :class:`~stairbot.drivers.link.BoardLink` both
wires share: requests to a board, their replies, retries, expiry and the
health counters.

:class:`RequestLink` implements it once -- matching replies to requests,
retrying, expiring, counting -- and a wire subclasses it with what only that
wire knows: how a request is encoded and sent, how bytes or frames come in
and which request a reply belongs to (both by the host's session and a
sequence number: the serial link one per frame of messages,
``serial_link.py``; the CAN link one per frame, a message each, then by what
the message is answered with, ``can_link.py``).

Rules (docs/protocol.md, "Requests and replies"):

* A request waits at most ``timeout_s`` for its whole reply.
* Only requests made entirely of idempotent messages (queries, StepTo) are
  sent again, up to ``retries`` times.  Commands are never sent again: the
  next control cycle sends fresh ones.
* A reply to a request given up is counted ``late``; a second copy of a
  reply already taken ``duplicates``; a reply matching nothing (another
  session's, an echo) ``stray``.
* :meth:`RequestLink.wait` raises LinkLostError when a waited-for request got
  no reply after its retries and its board has answered nothing but retry
  rounds' Heartbeats for ``grace_s``; until then the request is sent again (a query) -- ordinary
  line noise, a lost frame here and there, is ridden out.  A board that
  answers every attempt but never wholly (``Request.attempt_failed``: on CAN
  the same replies left out, attempt after attempt) is alive but will never
  complete it: HardwareError, at once, rather than retries without end.  ``max_lost``
  commands in a row (in the order they were sent) that went unanswered mean
  the link is lost too, again once the board has been silent for ``grace_s``.
* A retry round feeds every board: each board is sent a Heartbeat
  (``feeds``) beside whatever request goes to it again, so that while the
  host waits for one board the other's watchdog does not starve, and the
  board being asked again hears two frames a round: its watchdog starves
  only if both are lost, round after round (``timing.py`` has the
  arithmetic).  A Heartbeat costs its board one reply; the same ReadAll
  again (on CAN the broadcast frame) would cost a whole ReadAll reply.
* :meth:`RequestLink.urgent` (the emergency stop) may be called from any
  thread while another waits for replies: its frames go on the wire at once,
  ahead of anything held back and between a waiting read's retries.  The
  link's state is guarded by a mutex that is never held while a read blocks;
  an urgent request never expires by itself (its sender resends it and gives
  it up with :meth:`RequestLink.forget`).
"""

from __future__ import annotations

import threading
import time
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable, Sequence
from typing import Generic, TypeVar, cast

from stairbot.drivers.codes import Board
from stairbot.drivers.link import LinkStats, Reply, Request
from stairbot.drivers.records import Heartbeat, Message, RawMessage
from stairbot.errors import HardwareError, LinkLostError

R = TypeVar("R", bound=Request)


class RequestLink(ABC, Generic[R]):
    """The one implementation of matching, retry, expiry and health counting;
    a wire subclasses it (see the module docstring)."""

    wire = "link"

    def __init__(self, stats: LinkStats, timeout_s: float, retries: int, max_lost: int,
                 now: Callable[[], float] = time.perf_counter, grace_s: float = 0.0) -> None:
        self.stats = stats
        self.timeout_s = timeout_s
        self.retries = retries
        self.max_lost = max_lost
        self.grace_s = grace_s
        self._now = now
        self._heard: dict[int, float] = {}  # board -> when its latest reply came
        self._replied: dict[int, float] = {}  # the same, not counting feeds' replies
        self._in_flight: dict[int, list[R]] = {}  # per board, in sending order
        self._commands_sent = 0
        self._last_answered = -1  # order of the latest-sent command that was answered
        self._failed: deque[int] = deque(maxlen=256)  # orders of unanswered commands
        self.lost_streak = 0
        self._opened = now()
        # Guards everything above and the writes; never held while a read blocks.
        self._mutex = threading.RLock()

    # -- what a wire provides ----------------------------------------------------
    @abstractmethod
    def _new(self, board: int, messages: tuple[Message, ...], idempotent: bool,
             now: float) -> R:
        """The wire's record of a new request (its sequence number, its bytes)."""

    @abstractmethod
    def _transmit(self, req: R, send: bool) -> None:
        """Put ``req`` on the wire, or hold it back for :meth:`flush`."""

    @abstractmethod
    def _resend(self, req: R) -> None:
        """Send ``req`` again after a timeout (an idempotent request)."""

    @abstractmethod
    def _send_now(self, requests: Sequence[R]) -> None:
        """Write ``requests`` (of :meth:`urgent`) at once, ahead of anything held."""

    @abstractmethod
    def _receive(self, timeout_s: float) -> bool:
        """Take in what arrives within ``timeout_s``, handing each complete
        reply to :meth:`_complete` (under ``_mutex``, taken only once the
        bytes are in); False when nothing came."""

    def _given_up(self, req: R) -> None:
        """``req`` failed: remember what a late reply to it would look like."""

    def _check_bus(self) -> None:
        """Raise BusFaultError if the wire says it has failed (the CAN link
        reads its bus's state); called by every wait and poll."""

    def bus_trouble(self) -> str | None:
        return None

    def _on_wire(self, req: R) -> bool:
        """Whether ``req`` has gone out (a wire that holds requests back until
        :meth:`flush` says; its timeout runs from then)."""
        return True

    @abstractmethod
    def flush(self) -> None: ...

    @abstractmethod
    def describe(self) -> dict[str, object]: ...

    @abstractmethod
    def close(self) -> None: ...

    # -- requests --------------------------------------------------------------
    def request(self, board: int, messages: Sequence[Message], send: bool = True) -> R:
        """Send ``messages`` to ``board`` as one request; its reply is collected
        by :meth:`wait` or :meth:`poll`.  With ``send=False`` the request waits
        for :meth:`flush` (or the next request that sends), so that several go
        out together."""
        msgs = tuple(messages)
        with self._mutex:
            req = self._new(board, msgs, all(x.IDEMPOTENT for x in msgs), self._now())
            if not req.idempotent:
                req.order = self._commands_sent
                self._commands_sent += 1
            self._in_flight.setdefault(board, []).append(req)
            self._transmit(req, send)
        return req

    def broadcast(self, msg: Message) -> list[R]:
        """``msg`` to every board, sent together (on CAN as one frame to board 15)."""
        with self._mutex:
            out = [self.request(board, [msg], send=False) for board in Board]
            self.flush()
        return out

    def urgent(self, msg: Message, copies: int = 1) -> list[R]:
        """``msg`` to every board, ``copies`` times, written at once from any
        thread: it does not wait for a read in progress, nor go behind
        requests held back.  The requests never expire on their own: resend
        them with :meth:`resend_urgent`, give them up with :meth:`forget`."""
        with self._mutex:
            now = self._now()
            out = []
            for _ in range(copies):
                for board in Board:
                    req = self._new(board, (msg,), msg.IDEMPOTENT, now)
                    req.urgent = True
                    self._in_flight.setdefault(board, []).append(req)
                    out.append(req)
            self._send_now(out)
        return out

    def resend_urgent(self, requests: Sequence[Request]) -> None:
        with self._mutex:
            waiting = [cast(R, r) for r in requests if r.reply is None and not r.failed]
            for req in waiting:
                req.attempts += 1
                self.stats.retries += 1
            if waiting:
                self._send_now(waiting)

    def forget(self, requests: Sequence[Request], lost: bool = True) -> None:
        with self._mutex:
            for r in requests:
                req = cast(R, r)
                if req.reply is None and not req.failed:
                    req.failed = True
                    self.stats.lost += lost
                    queue = self._in_flight.get(req.board, [])
                    if req in queue:
                        queue.remove(req)
                    self._given_up(req)

    def in_flight(self, board: int) -> list[R]:
        """The requests to ``board`` still waiting for their reply, oldest first."""
        return self._in_flight.get(board, [])

    def _complete(self, req: R, messages: tuple[Message | RawMessage, ...],
                  frames: int = 1) -> None:
        """``req`` has its whole reply, ``frames`` frames of it."""
        self.stats.frames_rx += frames
        now = self._hear(req.board, req.feed)
        self.stats.add_rtt(now - req.sent_at)
        req.reply = Reply(req.board, messages)
        self._in_flight[req.board].remove(req)
        if not req.idempotent and req.order > self._last_answered:
            self._last_answered = req.order
            self._count_streak()

    def _expire(self) -> None:
        now = self._now()
        again: list[R] = []
        for queue in self._in_flight.values():
            for req in list(queue):
                if now < req.deadline or req.urgent or not self._on_wire(req):
                    continue
                if req.feed:  # it has fed the watchdog or not; nobody waits
                    req.failed = True
                    queue.remove(req)
                    self._given_up(req)
                    continue
                self.stats.timeouts += 1
                req.broken = req.broken or req.attempt_failed()
                if req.idempotent and req.attempts <= self.retries and req.broken is None:
                    req.attempts += 1
                    self.stats.retries += 1
                    req.sent_at, req.deadline = now, now + self.timeout_s
                    again.append(req)
                    continue
                req.failed = True
                self.stats.lost += 1
                queue.remove(req)
                self._given_up(req)
                if not req.idempotent:
                    self._failed.append(req.order)
                    self._count_streak()
        if again:
            self._send_again(again)

    def _send_again(self, requests: list[R]) -> None:
        """One retry round: ``requests`` go out again, and every board is fed a
        Heartbeat -- a second frame to a board asked again, the only one to a
        board that is not."""
        self._retry(requests)
        for board in Board:
            self._feed(board)

    def _retry(self, requests: list[R]) -> None:
        """Send ``requests`` again."""
        for req in requests:
            self._resend(req)

    def _feed(self, board: int) -> None:
        """A Heartbeat to ``board``, for its watchdog: written at once, never
        behind requests held back, given up silently at its deadline."""
        req = self._new(board, (Heartbeat(),), True, self._now())
        req.feed = True
        self.stats.feeds += 1
        self._in_flight.setdefault(board, []).append(req)
        self._send_now([req])

    def _count_streak(self) -> None:
        # "In a row" goes by sending order, not by when a timeout noticed the
        # loss: commands that failed after the latest one that was answered.
        self.lost_streak = sum(1 for o in self._failed if o > self._last_answered)

    def _drain(self) -> None:
        while self._receive(0.0):
            pass

    def poll(self) -> None:
        """Take in whatever has arrived, without waiting; expire old requests.
        Requests held back with ``send=False`` stay held."""
        self._check_bus()
        self._drain()
        with self._mutex:
            self._expire()

    def _hear(self, board: int, feed: bool = False) -> float:
        """``board`` said something (any valid frame, late or stray too): it is
        alive.  ``feed``: the reply to a Heartbeat of a retry round, which
        shows the board alive but not that anything else gets through.
        Returns the time."""
        now = self._now()
        self._heard[board] = now
        if not feed:
            self._replied[board] = now
        return now

    def silent_s(self, board: int) -> float:
        """How long ``board`` has not answered (since the link opened, if never)."""
        return self._now() - self._heard.get(board, self._opened)

    def unanswered_s(self, board: int) -> float:
        """How long ``board`` has sent nothing but the replies to retry rounds'
        Heartbeats (since the link opened, if never): what the grace period
        counts, so that a board whose Heartbeats get through but nothing
        else still runs out of it."""
        return self._now() - self._replied.get(board, self._opened)

    def commands_lost(self) -> str | None:
        """Why the commands say the link is lost, or None: ``max_lost`` in a row
        went unanswered, and the motor board has said nothing for ``grace_s``."""
        if self.lost_streak >= self.max_lost and self.silent_s(Board.MOTOR) >= self.grace_s:
            return (f"{self.lost_streak} commands in a row went unanswered, nothing from the "
                    f"motor board for {self.silent_s(Board.MOTOR):.2f} s")
        return None

    def _revive(self, req: R) -> bool:
        """Send a query that got no reply again, as a fresh request, while its
        board is within its grace period; False once it is beyond it."""
        if (not req.idempotent or req.broken is not None
                or self.unanswered_s(req.board) >= self.grace_s):
            return False
        with self._mutex:
            self.stats.revived += 1
            req.revived += 1
            req.failed = False
            req.attempts = 1
            now = self._now()
            req.sent_at, req.deadline = now, now + self.timeout_s
            self._in_flight.setdefault(req.board, []).append(req)
            self._send_again([req])
        return True

    def wait(self, requests: Sequence[Request]) -> list[Reply]:
        """The replies of ``requests``, in order.  Sends idempotent requests
        that time out again -- beyond their retries too while their board is
        within ``grace_s`` -- and raises LinkLostError once one gets no reply
        and its board has been silent for ``grace_s``, or when ``max_lost``
        commands in a row went unanswered and the motor board has been
        silent as long."""
        with self._mutex:
            self.flush()
        self._check_bus()
        while True:
            # Take in what has already arrived before judging deadlines: a host
            # descheduled past a timeout must not call a waiting reply late.
            self._drain()
            with self._mutex:
                self._expire()
            for req in requests:
                if req.failed and not self._revive(cast(R, req)):
                    names = "+".join(type(x).__name__ for x in req.messages)
                    who = (f"the {Board(req.board).name.lower()} board"
                           if req.board in Board._value2member_map_ else f"board {req.board}")
                    if req.broken is not None:
                        raise HardwareError(f"{who} broke the protocol: {req.broken}")
                    attempts = req.attempts + req.revived * (self.retries + 1)
                    silent = max(self.unanswered_s(req.board), attempts * self.timeout_s)
                    raise LinkLostError(
                        f"no reply from {who} for {silent:.2f} s "
                        f"({names}: {attempts} attempt(s) of "
                        f"{self.timeout_s * 1e3:.0f} ms{req.progress()})")
            reason = self.commands_lost()
            if reason is not None:
                raise LinkLostError(reason)
            waiting = [req for req in requests if req.reply is None]
            if not waiting:
                return [req.reply for req in requests if req.reply is not None]
            self._receive(max(0.0, min(req.deadline for req in waiting) - self._now()))

    def exchange(self, board: int, messages: Sequence[Message]) -> Reply:
        """Send one request and wait for its reply."""
        return self.wait([self.request(board, messages)])[0]
