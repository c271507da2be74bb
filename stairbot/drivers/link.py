"""What a wire is to :class:`~stairbot.drivers.board_robot.BoardRobot`: the
:class:`BoardLink` protocol (requests to a board and their replies), the
records of a request and its reply, the health counters, and the optional
capabilities a link may have.

:class:`~stairbot.drivers.request_link.RequestLink` implements the protocol
once -- matching replies to requests, retrying, expiring, counting -- and
states its rules; a wire subclasses it (``serial_link.py``, ``can_link.py``).
"""

from __future__ import annotations

import statistics
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

from stairbot.drivers.records import Ident, Message, RawMessage
from stairbot.errors import LinkLostError


class BusFaultError(LinkLostError):
    """The wire itself failed, not a board: a CAN bus that went bus-off, or a
    flood of frames from another node.  The robot latches its emergency stop
    before raising it on (``BoardRobot``)."""


@dataclass(frozen=True, slots=True)
class Reply:
    """A board's whole answer to one request, whatever the wire: the board
    and its messages in the order it sent them."""

    board: int
    messages: tuple[Message | RawMessage, ...]


@dataclass(eq=False)
class Request:
    """A request in flight, whatever the wire.  ``order`` numbers commands
    (non-idempotent requests) in sending order; -1 for queries."""

    board: int
    messages: tuple[Message, ...]
    idempotent: bool
    sent_at: float
    deadline: float
    order: int = -1
    attempts: int = 1  # since it was (re)vived: see RequestLink._revive
    revived: int = 0  # times sent again, as fresh, after every retry was used
    reply: Reply | None = None
    failed: bool = False
    urgent: bool = False  # sent by urgent(): resent and given up by its sender
    feed: bool = False  # a Heartbeat of a retry round (RequestLink._feed): nobody waits for it
    broken: str | None = None
    """Why the board's answers can never complete this request (it leaves the
    same replies out every time: a protocol error); never sent again."""

    @property
    def done(self) -> bool:
        return self.reply is not None or self.failed

    def progress(self) -> str:
        """What a wire adds to "did not answer" (the CAN link: replies that came)."""
        return ""

    def attempt_failed(self) -> str | None:
        """This attempt ended without the whole reply; why the board will never
        send one (a wire that can tell: the CAN link, from the same replies
        left out attempt after attempt), or None."""
        return None


@dataclass
class LinkStats:
    """What a link counts.  ``rtt_s`` keeps the latest round-trip times."""

    frames_tx: int = 0
    frames_rx: int = 0
    bytes_tx: int = 0
    bytes_rx: int = 0
    retries: int = 0
    timeouts: int = 0  # requests whose (last) attempt got no reply in time
    lost: int = 0  # requests given up: no reply after every allowed attempt
    revived: int = 0  # queries sent again beyond their retries, within the grace period
    feeds: int = 0  # Heartbeats to a board a retry round did not reach
    late: int = 0
    stray: int = 0
    duplicates: int = 0  # second copies of a reply already taken
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


class BoardLink(Protocol):
    """Requests and replies to both boards over one wire (a serial port, a
    CAN bus).  Every method raises LinkLostError when the wire fails."""

    @property
    def wire(self) -> str:
        """What the boards hang on, for messages: "serial port", "CAN bus"."""
        ...

    @property
    def timeout_s(self) -> float: ...

    @property
    def retries(self) -> int: ...

    @property
    def max_lost(self) -> int: ...

    @property
    def lost_streak(self) -> int:
        """Commands unanswered in a row, in sending order."""
        ...

    def commands_lost(self) -> str | None:
        """Why the unanswered commands mean the link is lost, or None."""
        ...

    @property
    def stats(self) -> LinkStats: ...

    def request(self, board: int, messages: Sequence[Message], send: bool = True) -> Request:
        """Send ``messages`` to ``board`` as one request; with ``send=False``
        it waits for :meth:`flush` or the next request that sends."""
        ...

    def broadcast(self, msg: Message) -> Sequence[Request]:
        """Send ``msg`` to every board at once, one request per board."""
        ...

    def urgent(self, msg: Message, copies: int = 1) -> Sequence[Request]:
        """Put ``msg`` on the wire to every board now, ``copies`` times, from
        any thread (one request per board and copy)."""
        ...

    def resend_urgent(self, requests: Sequence[Request]) -> None:
        """Send the still unanswered ``requests`` of :meth:`urgent` again, now."""
        ...

    def forget(self, requests: Sequence[Request], lost: bool = True) -> None:
        """Stop waiting for ``requests`` (a reply that still comes is late);
        ``lost``: count those unanswered as lost (not spare copies)."""
        ...

    def flush(self) -> None:
        """Send every request held back."""
        ...

    def poll(self) -> None:
        """Take in whatever has arrived and expire old requests; never waits."""
        ...

    def wait(self, requests: Sequence[Request]) -> list[Reply]:
        """The replies of ``requests``, in order (LinkLostError: see the rules)."""
        ...

    def exchange(self, board: int, messages: Sequence[Message]) -> Reply:
        """Send one request and wait for its reply."""
        ...

    def describe(self) -> dict[str, object]:
        """What the wire is, for diagnostics."""
        ...

    def bus_trouble(self) -> str | None:
        """What is wrong with the wire itself, for a lost link's message (a
        CAN bus error-passive, frames from other nodes); None if nothing."""
        ...

    def close(self) -> None: ...


@runtime_checkable
class ProbesOldBoards(Protocol):
    """A link that can ask a board that ignores it (one of an older protocol
    whose frames this host's do not match) who it is: the CAN link, whose
    frame layout changed in protocol 4.0."""

    def probe_old_ident(self, board: int) -> Ident | None:
        """The Ident an older board sends when asked the old way; None if none."""
        ...


@runtime_checkable
class CountsReplies(Protocol):
    """A link that counts a ReadAll reply's telemetry before it comes, and so
    must be told how many channels each board has (its Ident): the CAN link,
    where each telemetry message is a frame of its own and a reply is whole
    when every frame has come.  (On the serial link a reply is one frame.)"""

    def set_channels(self, board: int, channels: int) -> None:
        """``board`` answers ReadAll with ``channels`` telemetry messages."""
        ...

