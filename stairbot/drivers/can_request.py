"""One request on the CAN bus and the replies it takes (``can_link.py``
sends it and hands it the replies whose session and seq are its own).

A request is one frame per message, each with a seq of its own; a board
answers each frame with the replies its message declares (``ANSWER``;
ReadAll: Status + one telemetry frame per channel and IMU axis,
``messages.read_all_reply``: as many sensor channels as the board's Ident
said), back to back and in order.  Within one frame's
replies a reply is matched by kind and, for telemetry, by channel or axis.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, field
from enum import Enum
from typing import NamedTuple

from stairbot.drivers import messages as m
from stairbot.drivers.link import Request

SAME_SHORT_LIMIT = 8
"""Attempts in a row that each ended in the same gap, after which a request is
given up as a protocol error (``CanRequest.attempt_failed``): a board that
leaves those replies out (its Ident said 6 sensor channels, it sends 4), not
a lossy bus, which at 10 % of frames lost does that to fewer than one request
in 10**10."""


def expected_replies(board: int, msg: m.Message,
                     channels: int | None = None) -> list[type[m.Message]]:
    """The reply messages, in order, a board sends for ``msg`` when it obeys;
    ``channels``: how many the board's Ident says it has (None: its base)."""
    if isinstance(msg, m.ReadAll):
        return list(m.read_all_reply(board, channels))
    return [m.MESSAGES.get(msg.ANSWER, m.Ack)]


def _key(msg: m.Message) -> int | None:
    """Which channel (or IMU axis) a telemetry reply is for; None for others."""
    if isinstance(msg, (m.MotorTelemetry, m.SensorTelemetry)):
        return msg.channel
    if isinstance(msg, m.ImuTelemetry):
        return msg.axis
    return None


# What a telemetry reply's key is, for messages (else a channel).
_KEY_NAME: dict[type[m.Message], str] = {m.ImuTelemetry: "axis"}
_KEYED = (m.MotorTelemetry, m.SensorTelemetry, m.ImuTelemetry)

# (board, message class, channels, the class registered for its ANSWER) ->
# the (kind, key) of each reply: all that expected_replies reads
_REPLIES: dict[tuple[int, type[m.Message], int | None, type[m.Message] | None],
               tuple[tuple[type[m.Message], int | None], ...]] = {}


def replies_of(board: int, msg: m.Message,
               channels: int | None = None) -> tuple[tuple[type[m.Message], int | None], ...]:
    """The kind of each reply :func:`expected_replies` names, and its key:
    for telemetry the channel (or IMU axis) it is the n-th of, else None.
    Kept per board, message class, channels and the class the codec holds
    for the message's ANSWER, so a class registered later is seen."""
    cache_key = (board, type(msg), channels, m.MESSAGES.get(msg.ANSWER))
    out = _REPLIES.get(cache_key)
    if out is None:
        seen: dict[type[m.Message], int] = {}
        keyed: list[tuple[type[m.Message], int | None]] = []
        for kind in expected_replies(board, msg, channels):
            n = seen.get(kind, 0)
            seen[kind] = n + 1
            keyed.append((kind, n if kind in _KEYED else None))
        out = _REPLIES[cache_key] = tuple(keyed)
    return out


class Due(NamedTuple):
    """A reply a request waits for: of which of its messages, answering which
    type code, of which kind, for which channel or axis (None: any)."""

    part: int  # which of the request's messages
    request_type: int
    kind: type[m.Message]
    key: int | None

    def fits(self, msg: m.Message) -> bool:
        if isinstance(msg, m.Ack):
            return msg.request == self.request_type
        return isinstance(msg, self.kind) and (self.key is None or _key(msg) == self.key)


class Offer(Enum):
    """What a request made of a reply offered to it."""

    TAKEN = "taken"
    DUPLICATE = "duplicate"  # a second copy of a reply it has taken
    LATE = "late"  # a reply it stopped waiting for (one after it came first)
    STRAY = "stray"  # not a reply to this frame at all


@dataclass(eq=False)
class CanRequest(Request):
    """A request on the bus: the seq of the frame carrying each message (none
    until sent), the replies that came and those still to come.

    A reply names its frame by seq; within that frame's replies it is matched
    by kind and, for telemetry, by channel (or IMU axis): the n-th telemetry of
    a kind a ReadAll is answered with is channel n.  A board sends a request's
    replies back to back and CAN keeps their order, so a reply that matches a
    later expected one means the ones before it were lost (``gap``): the
    request cannot complete, and the link sends it again as soon as the last
    reply has come, without waiting for the timeout."""

    channels: int | None = None  # the board's, from its Ident (None: its base)
    seqs: tuple[int, ...] = ()
    got: list[m.Message] = field(default_factory=list)
    todo: deque[Due] = field(default_factory=deque)
    taken: list[Due] = field(default_factory=list)
    gap: bool = False
    skipped: list[Due] = field(default_factory=list)  # this attempt's, lost in a gap
    short: tuple[tuple[Due, ...], int] = ((), 0)  # replies lacked, attempts in a row

    def expect(self) -> None:
        """(Re)start waiting for every reply."""
        self.got = []
        self.taken = []
        self.gap = False
        self.skipped = []
        self.todo = deque(self._all_due())

    def attempt_failed(self) -> str | None:
        """This attempt ended without its whole reply.  After SAME_SHORT_LIMIT
        attempts in a row that each ended in the same gap -- the board's last
        reply came, the same ones before it never did -- why the board will
        never send them; else None.  Only a gap counts: CAN keeps a sender's
        order, so a reply skipped before a later one was not sent (or lost),
        never merely slow; an attempt that timed out with replies still to
        come may have met a slow board, and starts the count afresh."""
        lacked = tuple(self.skipped) if self.gap and not self.todo else ()
        before, count = self.short
        count = count + 1 if lacked and lacked == before else int(bool(lacked))
        self.short = (lacked, count)
        if count < SAME_SHORT_LIMIT:
            return None
        names = "+".join(type(x).__name__ for x in self.messages)
        what = ", ".join(due.kind.__name__ + ("" if due.key is None else
                                              f" {_KEY_NAME.get(due.kind, 'channel')} {due.key}")
                         for due in lacked)
        told = "" if self.channels is None else f" (its Ident said {self.channels} channels)"
        return (f"it answered {names} {count} times in a row without {what}{told}, though "
                "it answered each time")

    def _all_due(self) -> Iterator[Due]:
        for i, msg in enumerate(self.messages):
            for kind, key in replies_of(self.board, msg, self.channels):
                yield Due(i, msg.TYPE, kind, key)

    def index_of(self, seq: int) -> int | None:
        """Which message the frame ``seq`` carried; None if none of ours."""
        return self.seqs.index(seq) if seq in self.seqs else None

    def offer(self, msg: m.Message, index: int | None = None) -> Offer:
        """Take ``msg`` (a reply to message ``index``; None: to any) if this
        request still waits for it: the next reply, or a later one (then
        those before it were lost: ``gap``)."""
        def mine(due: Due) -> bool:
            return (index is None or due.part == index) and due.fits(msg)

        todo = self.todo
        # the next reply due is the one that comes, but after a loss
        pos = 0 if todo and mine(todo[0]) else next(
            (i for i, due in enumerate(todo) if mine(due)), None)
        if pos is None:
            if any(mine(due) for due in self.taken):
                return Offer.DUPLICATE
            return Offer.LATE if any(mine(due) for due in self._all_due()) else Offer.STRAY
        if pos:
            self.gap = True
            for _ in range(pos):
                self.skipped.append(self.todo.popleft())
        first = self.todo[0]
        if isinstance(msg, m.Ack):
            # An Ack answers the message whole: nothing else comes for it.
            while self.todo and self.todo[0].part == first.part:
                self.todo.popleft()
        else:
            self.todo.popleft()
        self.taken.append(first)
        self.got.append(msg)
        return Offer.TAKEN

    @property
    def owed(self) -> int:
        """Replies still to come."""
        return len(self.todo)

    def progress(self) -> str:
        seqs = ",".join(str(s) for s in self.seqs)
        return f"; {len(self.got)} of {len(self.got) + self.owed} replies came; seq {seqs}"
