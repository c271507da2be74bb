"""The request/response engine over a byte stream, and its health counters.

The host numbers every frame it sends (``seq``, mod 256); a board answers each
request frame with exactly one reply frame carrying the same ``seq``.  Several
requests may be in flight at once (one per board per control cycle), so a
cycle costs one round trip, not one per board.

Rules (docs/protocol.md, "Requests and replies"):

* A request waits at most ``timeout_s`` for its reply.
* Only requests made entirely of idempotent messages (queries, StepTo) are
  re-sent, byte for byte with the same ``seq``, up to ``retries`` times.
  Commands are never re-sent: the next control cycle sends fresh ones.
* A reply to a request that already timed out is counted ``late``; a reply
  matching nothing (a duplicate, an echo) is counted ``stray``.
* :meth:`Link.wait` raises LinkLostError when a waited-for request got no
  reply after its retries; commands that go unanswered ``max_lost`` times in
  a row also mean the link is lost.
"""

from __future__ import annotations

import os
import select
import statistics
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from stairbot.drivers.messages import Message
from stairbot.drivers.serial_wire import Frame, FrameReader, encode_frame
from stairbot.errors import LinkLostError


class ByteChannel(Protocol):
    def write(self, data: bytes) -> None: ...

    def read_some(self, timeout_s: float) -> bytes:
        """Whatever bytes arrive within ``timeout_s`` (maybe none)."""
        ...

    def close(self) -> None: ...


class FdChannel:
    """A channel on a POSIX file descriptor (a tty, a pty): select + os.read,
    which avoids reconfiguring the port for every read timeout."""

    def __init__(self, fd: int, owner: Any = None) -> None:
        self.fd = fd
        self._owner = owner  # the pyserial port that owns the fd, closed with us

    def write(self, data: bytes) -> None:
        view = memoryview(data)
        while view:
            try:
                n = os.write(self.fd, view)
            except BlockingIOError:
                select.select([], [self.fd], [], 0.1)
                continue
            view = view[n:]

    def read_some(self, timeout_s: float) -> bytes:
        ready, _, _ = select.select([self.fd], [], [], max(0.0, timeout_s))
        if not ready:
            return b""
        try:
            return os.read(self.fd, 4096)
        except (BlockingIOError, InterruptedError):
            return b""

    def close(self) -> None:
        if self._owner is not None:
            self._owner.close()
        else:
            os.close(self.fd)


class PortChannel:
    """A channel on any pyserial port (socket://, rfc2217://, loop://...):
    reads poll with a short fixed port timeout."""

    POLL_S = 0.002

    def __init__(self, port: Any) -> None:
        self.port = port
        port.timeout = self.POLL_S

    def write(self, data: bytes) -> None:
        self.port.write(data)

    def read_some(self, timeout_s: float) -> bytes:
        deadline = time.perf_counter() + timeout_s
        while True:
            data: bytes = self.port.read(max(1, self.port.in_waiting))
            if data or time.perf_counter() >= deadline:
                return data

    def close(self) -> None:
        self.port.close()


@dataclass
class LinkStats:
    """What the driver counts.  ``rtt_s`` keeps the latest round-trip times."""

    frames_tx: int = 0
    frames_rx: int = 0
    bytes_tx: int = 0
    bytes_rx: int = 0
    retries: int = 0
    timeouts: int = 0  # requests whose (last) attempt got no reply in time
    lost: int = 0  # requests given up: no reply after every allowed attempt
    late: int = 0
    stray: int = 0
    crc_errors: int = 0
    malformed: int = 0
    rtt_s: deque[float] = field(default_factory=lambda: deque(maxlen=2048))
    rtt_count: int = 0  # replies timed so far
    _rtt_cache: tuple[int, float, float] = (-1, 0.0, 0.0)

    def add_rtt(self, seconds: float) -> None:
        self.rtt_s.append(seconds)
        self.rtt_count += 1

    def _rtt(self) -> tuple[float, float]:
        # Sorting 2048 samples costs more than a whole control cycle: redo it
        # only every 64 new samples (and whenever few are kept).
        n, med, p99 = self._rtt_cache
        if self.rtt_s and (n < 0 or self.rtt_count - n >= 64 or len(self.rtt_s) < 64):
            ordered = sorted(self.rtt_s)
            med = statistics.median(ordered)
            p99 = ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))]
            self._rtt_cache = (self.rtt_count, med, p99)
        return med, p99

    def rtt_median_ms(self) -> float:
        return self._rtt()[0] * 1e3

    def rtt_p99_ms(self) -> float:
        return self._rtt()[1] * 1e3

    def as_dict(self) -> dict[str, float]:
        """Counters and RTT figures, flat, for Snapshot.health and events."""
        out: dict[str, float] = {
            k: float(v) for k, v in vars(self).items()
            if isinstance(v, int) and not k.startswith("_")
        }
        out["rtt_median_ms"] = round(self.rtt_median_ms(), 3)
        out["rtt_p99_ms"] = round(self.rtt_p99_ms(), 3)
        return out


@dataclass(eq=False)
class Request:
    """What every request in flight keeps, whatever the wire (serial or CAN)."""

    board: int
    seq: int
    idempotent: bool
    sent_at: float
    deadline: float
    attempts: int = 1
    reply: Frame | None = None
    failed: bool = False

    @property
    def done(self) -> bool:
        return self.reply is not None or self.failed


@dataclass
class Pending(Request):
    """A request in flight on a serial link: the frame as sent, for a resend."""

    wire: bytes = b""
    order: int = -1  # commands only: their place in the sending order


class Link:
    """Requests and replies over one byte channel (both boards share it)."""

    def __init__(
        self,
        channel: ByteChannel,
        timeout_s: float = 0.05,
        retries: int = 2,
        max_lost: int = 3,
        now: Callable[[], float] = time.perf_counter,
    ) -> None:
        self.channel = channel
        self.timeout_s = timeout_s
        self.retries = retries
        self.max_lost = max_lost
        self._now = now
        self._reader = FrameReader()
        self._pending: dict[tuple[int, int], Pending] = {}
        self._expired: deque[tuple[int, int]] = deque(maxlen=64)
        self._seq = 0
        self._out = bytearray()
        self.lost_streak = 0
        self._commands_sent = 0
        self._last_answered = -1  # order of the latest-sent command that was answered
        self._failed: deque[int] = deque(maxlen=256)  # orders of unanswered commands
        self.stats = LinkStats()

    # -- sending ---------------------------------------------------------------
    def _next_seq(self, board: int) -> int:
        for _ in range(256):
            self._seq = (self._seq + 1) & 0xFF
            if (board, self._seq) not in self._pending:
                return self._seq
        raise LinkLostError("256 requests in flight: the boards do not answer")

    def request(self, board: int, messages: Sequence[Message], send: bool = True) -> Pending:
        """Send one request frame to ``board``; its reply is collected by
        :meth:`wait` or :meth:`poll`.  With ``send=False`` the frame waits in
        the output buffer for :meth:`flush` (or the next request that sends),
        so that several frames go out in one write."""
        seq = self._next_seq(board)
        wire = encode_frame(Frame(board, seq, tuple(messages)))
        now = self._now()
        p = Pending(board, seq, all(m.IDEMPOTENT for m in messages), now,
                    now + self.timeout_s, wire=wire)
        if not p.idempotent:
            p.order = self._commands_sent
            self._commands_sent += 1
        self._pending[(board, seq)] = p
        self._send(wire, send)
        return p

    def _send(self, wire: bytes, flush: bool = True) -> None:
        self._out += wire
        self.stats.frames_tx += 1
        self.stats.bytes_tx += len(wire)
        if flush:
            self.flush()

    def flush(self) -> None:
        """Write every frame still in the output buffer (one write)."""
        if not self._out:
            return
        data, self._out = bytes(self._out), bytearray()
        try:
            self.channel.write(data)
        except OSError as exc:
            raise LinkLostError(f"cannot write to the port: {exc}") from exc

    # -- receiving -------------------------------------------------------------
    def _receive(self, timeout_s: float) -> None:
        try:
            data = self.channel.read_some(timeout_s)
        except OSError as exc:
            raise LinkLostError(f"cannot read from the port: {exc}") from exc
        if not data:
            return
        self.stats.bytes_rx += len(data)
        rs = self._reader.stats
        for frame in self._reader.feed(data):
            key = (frame.board, frame.seq)
            p = self._pending.get(key) if frame.from_board else None
            if p is None:
                if key in self._expired:
                    self.stats.late += 1
                else:
                    self.stats.stray += 1
                continue
            self.stats.frames_rx += 1
            self.stats.add_rtt(self._now() - p.sent_at)
            p.reply = frame
            del self._pending[key]
            if not p.idempotent and p.order > self._last_answered:
                self._last_answered = p.order
                self._count_streak()
        self.stats.crc_errors = rs.crc_errors
        self.stats.malformed = rs.malformed + rs.overruns

    def _expire(self) -> None:
        now = self._now()
        for key, p in list(self._pending.items()):
            if now < p.deadline:
                continue
            self.stats.timeouts += 1
            if p.idempotent and p.attempts <= self.retries:
                p.attempts += 1
                self.stats.retries += 1
                p.sent_at, p.deadline = now, now + self.timeout_s
                self._send(p.wire)
                continue
            p.failed = True
            self.stats.lost += 1
            del self._pending[key]
            self._expired.append(key)
            if not p.idempotent:
                self._failed.append(p.order)
                self._count_streak()

    def _count_streak(self) -> None:
        # "In a row" goes by sending order, not by when a timeout noticed the
        # loss: commands that failed after the latest one that was answered.
        self.lost_streak = sum(1 for o in self._failed if o > self._last_answered)

    def poll(self) -> None:
        """Take in whatever has arrived, without waiting; expire old requests.
        Frames held back with ``send=False`` stay held."""
        self._receive(0.0)
        self._expire()

    def wait(self, pendings: Sequence[Pending]) -> list[Frame]:
        """The replies of ``pendings``, in order.  Re-sends idempotent requests
        that time out; raises LinkLostError when one gets no reply at all, or
        when ``max_lost`` commands in a row went unanswered."""
        self.flush()
        while True:
            # Take in what has already arrived before judging deadlines: a host
            # descheduled past a timeout must not call a waiting reply late.
            self._receive(0.0)
            self._expire()
            failed = [p for p in pendings if p.failed]
            if failed:
                p = failed[0]
                raise LinkLostError(
                    f"board {p.board} did not answer (seq {p.seq}, {p.attempts} attempt(s) "
                    f"of {self.timeout_s * 1e3:.0f} ms)")
            if self.lost_streak >= self.max_lost:
                raise LinkLostError(f"{self.lost_streak} commands in a row went unanswered")
            waiting = [p for p in pendings if p.reply is None]
            if not waiting:
                return [p.reply for p in pendings if p.reply is not None]
            timeout = min(p.deadline for p in waiting) - self._now()
            self._receive(max(0.0, timeout))

    def exchange(self, board: int, messages: Sequence[Message]) -> Frame:
        """Send one request and wait for its reply."""
        return self.wait([self.request(board, messages)])[0]

    def close(self) -> None:
        self.channel.close()
