"""The link protocol over a byte stream: serial frames on a port.

The host numbers every frame it sends (``seq``, mod 256, per board); a board
answers each request frame with exactly one reply frame carrying the same
``seq``, which is how :class:`SerialLink` matches a reply to its request.
Several requests may be in flight at once (one per board per control cycle),
so a cycle costs one round trip, not one per board.  A request sent again
after a timeout is the same frame, byte for byte, with the same ``seq``: a
board answers a repeated frame from its cache without acting twice.
Retries, expiry and the health counters are
:class:`~stairbot.drivers.request_link.RequestLink`'s.
"""

from __future__ import annotations

import os
import secrets
import select
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from stairbot.drivers.frame_log import SerialFrameLog
from stairbot.drivers.link import LinkStats, Request
from stairbot.drivers.records import Message
from stairbot.drivers.request_link import RequestLink
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

    def __init__(self, port: Any, on_close: Callable[[], None] | None = None) -> None:
        self.port = port
        self._on_close = on_close  # after the port closes (a port lock's release)
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
        try:
            self.port.close()
        finally:
            if self._on_close is not None:
                self._on_close()


@dataclass(eq=False)
class SerialRequest(Request):
    """A request on the serial wire: its sequence number and its frame as
    sent, for a retry."""

    seq: int = 0
    frame: bytes = b""
    on_wire: bool = False  # written (not only held in the output buffer)

    def progress(self) -> str:
        return f"; seq {self.seq}"


class SerialLink(RequestLink[SerialRequest]):
    """Requests and replies for both boards over one byte channel."""

    wire = "serial port"

    def __init__(self, channel: ByteChannel, timeout_s: float = 0.05, retries: int = 2,
                 max_lost: int = 3, now: Callable[[], float] = time.perf_counter,
                 grace_s: float = 0.0, log: SerialFrameLog | None = None) -> None:
        super().__init__(LinkStats(), timeout_s, retries, max_lost, now, grace_s)
        self.channel = channel
        self.log = log  # every byte written and read, a line per frame
        self._reader = FrameReader()
        self._expired: deque[tuple[int, int]] = deque(maxlen=64)
        self._answered: deque[tuple[int, int]] = deque(maxlen=64)
        # This link's session: a reply of another (an earlier host's, a
        # previous run's still on the line) is never taken for one of ours.
        self.session = secrets.randbelow(255) + 1
        self.other_session = 0  # replies of another session seen (counted stray too)
        # Where the sequence numbers start: random too, so that a new session
        # that drew an earlier one's number still seldom repeats a request.
        self._seq = secrets.randbelow(256)
        self._out = bytearray()
        self._unsent: list[SerialRequest] = []  # their frames are in _out

    # -- sending ---------------------------------------------------------------
    def _new(self, board: int, messages: tuple[Message, ...], idempotent: bool,
             now: float) -> SerialRequest:
        seq = self._next_seq(board)
        frame = encode_frame(Frame(board, seq, messages, session=self.session))
        return SerialRequest(board, messages, idempotent, now, now + self.timeout_s,
                             seq=seq, frame=frame)

    def _next_seq(self, board: int) -> int:
        used = {r.seq for r in self.in_flight(board)}
        for _ in range(256):
            self._seq = (self._seq + 1) & 0xFF
            if self._seq not in used:
                return self._seq
        raise LinkLostError("256 requests in flight: the boards do not answer")

    def _transmit(self, req: SerialRequest, send: bool) -> None:
        self._out += req.frame
        self._unsent.append(req)
        self.stats.frames_tx += 1
        self.stats.bytes_tx += len(req.frame)
        if send:
            self.flush()

    def _resend(self, req: SerialRequest) -> None:
        self._transmit(req, True)

    def flush(self) -> None:
        """Write every frame still in the output buffer (one write)."""
        with self._mutex:
            if not self._out:
                return
            data, self._out = bytes(self._out), bytearray()
            self._write(data)
            # their timeouts (and round trips) run from now, not from when
            # they were held back
            now = self._now()
            for req in self._unsent:
                req.on_wire, req.sent_at, req.deadline = True, now, now + self.timeout_s
            self._unsent = []

    def _on_wire(self, req: SerialRequest) -> bool:
        # A request held back cannot time out before it is written.
        return req.on_wire

    def _send_now(self, requests: Sequence[SerialRequest]) -> None:
        for req in requests:
            req.on_wire = True
        data = b"".join(r.frame for r in requests)
        self.stats.frames_tx += len(requests)
        self.stats.bytes_tx += len(data)
        self._write(data)

    def _write(self, data: bytes) -> None:
        try:
            self.channel.write(data)
        except OSError as exc:
            raise LinkLostError(f"cannot write to the serial port: {exc}") from exc
        if self.log is not None:
            self.log.tx(data)

    # -- receiving -------------------------------------------------------------
    def _receive(self, timeout_s: float) -> bool:
        try:
            data = self.channel.read_some(timeout_s)
        except OSError as exc:
            raise LinkLostError(f"cannot read from the serial port: {exc}") from exc
        if not data:
            return False
        if self.log is not None:
            self.log.rx(data)
        with self._mutex:
            self.stats.bytes_rx += len(data)
            rs = self._reader.stats
            for frame in self._reader.feed(data):
                req = self._match(frame) if frame.from_board else None
                if frame.from_board:
                    self._hear(frame.board, feed=req is not None and req.feed)
                mine = frame.session == self.session
                if req is not None:
                    self._complete(req, frame.messages)
                    self._answered.append((req.board, req.seq))
                elif mine and (frame.board, frame.seq) in self._expired:
                    self.stats.late += 1
                elif mine and frame.from_board and (frame.board, frame.seq) in self._answered:
                    self.stats.duplicates += 1  # a second copy of a reply taken
                else:
                    self.stats.stray += 1
            self.stats.crc_errors = rs.crc_errors
            self.stats.malformed = rs.malformed + rs.overruns
        return True

    def _match(self, frame: Frame) -> SerialRequest | None:
        if frame.session != self.session:
            self.other_session += 1
            return None
        for req in self.in_flight(frame.board):
            if req.seq == frame.seq:
                return req
        return None

    def _given_up(self, req: SerialRequest) -> None:
        self._expired.append((req.board, req.seq))

    def describe(self) -> dict[str, object]:
        out: dict[str, object] = {"wire": self.wire}
        if self.log is not None:
            out["frame_log"] = self.log.describe()
        return out

    def close(self) -> None:
        try:
            self.channel.close()
        finally:
            if self.log is not None:
                self.log.close()
