"""Both fake boards served on one serial link: a pseudo-terminal (or any fd).

:class:`SerialBoardServer` reads host frames from a file descriptor, hands
each valid one to the board it addresses (``fakes.boards``), writes the reply
frame back, and -- unless in lockstep -- advances the simulated world as wall
time passes.  A frame identical to the previous one to the same board (same
session, same seq, same messages: a retry or a duplicate) gets the previous
reply again without being executed twice, as docs/protocol.md requires of
firmware; a new host session reusing a sequence number is executed.

Fault injection (:class:`WireFaults`) acts on the wire: frames dropped,
corrupted (one byte flipped, so the CRC fails), duplicated, or delayed, in
either direction, drawn from a seeded generator; and a board that goes silent
from a given board time on (it still obeys what it hears; it just never
answers).
"""

from __future__ import annotations

import contextlib
import os
import random
import select
import threading
import time
import tty
from dataclasses import dataclass
from typing import Protocol

from stairbot.drivers.messages import Message
from stairbot.drivers.serial_wire import CodecError, Frame, FrameReader, encode_frame
from stairbot.fakes.board_world import BoardWorld, Pacer
from stairbot.fakes.boards import Board


@dataclass(frozen=True)
class WireFaults:
    """Probabilities per frame (0..1), the delay of a late frame, and when
    (board seconds) a board goes silent (None: never)."""

    drop: float = 0.0
    corrupt: float = 0.0
    duplicate: float = 0.0
    late: float = 0.0
    late_s: float = 0.1
    silent_board: int | None = None  # board address; None with silent_after_s: all boards
    silent_after_s: float | None = None
    seed: int = 0

    @property
    def any(self) -> bool:
        return bool(self.drop or self.corrupt or self.duplicate or self.late
                    or self.silent_after_s is not None)


class _Counts(Protocol):
    injected: int


class FaultDice:
    """Draws one server's wire faults from its seeded stream and counts each
    injected fault in ``stats.injected``; shared by the serial and CAN servers."""

    def __init__(self, faults: WireFaults, stats: _Counts) -> None:
        self.faults = faults
        self.stats = stats
        self.rng = random.Random(faults.seed)

    def chance(self, p: float) -> bool:
        """True with probability ``p`` (and then counted as injected)."""
        if p and self.rng.random() < p:
            self.stats.injected += 1
            return True
        return False

    def silent(self, board: int, now_s: float) -> bool:
        """Whether ``board`` has gone silent at board time ``now_s``."""
        f = self.faults
        return (f.silent_after_s is not None and now_s >= f.silent_after_s
                and f.silent_board in (None, board))


@dataclass
class ServerStats:
    frames_rx: int = 0
    frames_tx: int = 0
    crc_errors: int = 0
    malformed: int = 0
    duplicates: int = 0  # repeated frames answered from the cache
    stray: int = 0  # frames for no board here, or from a board
    injected: int = 0  # faults injected
    overflows: int = 0  # replies dropped because nobody read the line
    cut: int = 0  # reply frames that could not hold every reply (the rest left off)


class SerialBoardServer:
    """Serve ``boards`` (address -> Board) on file descriptor ``fd``."""

    def __init__(self, fd: int, world: BoardWorld, boards: dict[int, Board],
                 faults: WireFaults | None = None, time_scale: float = 1.0,
                 step_s: float = 0.005) -> None:
        self.fd = fd
        os.set_blocking(fd, False)
        self.world = world
        self.boards = boards
        self.faults = faults or WireFaults()
        self.time_scale = time_scale
        self.step_s = step_s
        self.stats = ServerStats()
        self._dice = FaultDice(self.faults, self.stats)
        self._rng = self._dice.rng
        self._reader = FrameReader()
        self._last: dict[int, tuple[Frame, bytes]] = {}
        self._late: list[tuple[float, bytes]] = []
        self._stop = threading.Event()
        self.pacer = Pacer(world, boards.values(), time_scale, step_s)
        self._crc_seen = 0
        self._out = bytearray()

    # -- faults ------------------------------------------------------------------
    def set_faults(self, faults: WireFaults) -> None:
        """From now on, these faults (a fault matrix starts them mid-run)."""
        self.faults = faults
        self._dice = FaultDice(faults, self.stats)
        self._rng = self._dice.rng

    def _chance(self, p: float) -> bool:
        return self._dice.chance(p)

    def _silent(self, board: int) -> bool:
        return self._dice.silent(board, self.world.now())

    def _corrupt(self, wire: bytes) -> bytes:
        i = self._rng.randrange(len(wire) - 1)  # never the delimiter
        flipped = wire[i] ^ (1 << self._rng.randrange(8))
        return wire[:i] + bytes((flipped or 0x55,)) + wire[i + 1:]

    # -- wire ----------------------------------------------------------------------
    def _write(self, wire: bytes) -> None:
        if self._chance(self.faults.drop):
            return
        if self._chance(self.faults.corrupt):
            wire = self._corrupt(wire)
        if self._chance(self.faults.late):
            self._late.append((time.monotonic() + self.faults.late_s, wire))
            return
        copies = 2 if self._chance(self.faults.duplicate) else 1
        self._out += wire * copies
        self.stats.frames_tx += copies

    def _write_all(self, data: bytes) -> None:
        """Write, or drop what the line will not take: with no host reading
        the pty its buffer fills, and a UART would send into the void too.
        Never blocks for long, so the server always stays stoppable."""
        view = memoryview(data)
        while view:
            try:
                view = view[os.write(self.fd, view):]
            except BlockingIOError:
                _, ready, _ = select.select([], [self.fd], [], 0.05)
                if not ready:
                    self.stats.overflows += 1
                    return

    def _flush_late(self) -> None:
        now = time.monotonic()
        due = [w for t, w in self._late if t <= now]
        self._late = [(t, w) for t, w in self._late if t > now]
        for wire in due:
            self._write_all(wire)
            self.stats.frames_tx += 1

    def receive(self, data: bytes) -> None:
        """Handle the bytes the host sent.  Faults on the way in act on whole
        frames: a dropped one is ignored, a corrupted one is ignored as its
        CRC would fail, a duplicated one is handled twice."""
        f = self.faults
        for frame in self._reader.feed(data):
            if self._chance(f.drop):
                continue
            if self._chance(f.corrupt):
                self.stats.crc_errors += 1
                continue
            self._handle(frame)
            if self._chance(f.duplicate):
                self._handle(frame)
        if self._out:
            out, self._out = bytes(self._out), bytearray()
            self._write_all(out)  # every reply to this read in one write
        rs = self._reader.stats
        self.stats.malformed = rs.malformed + rs.overruns
        self._crc_seen, new = rs.crc_errors, rs.crc_errors - self._crc_seen
        self.stats.crc_errors += new

    def _handle(self, frame: Frame) -> None:
        board = self.boards.get(frame.board)
        if board is None or frame.from_board:
            self.stats.stray += 1
            return
        self.stats.frames_rx += 1
        last = self._last.get(frame.board)
        if last is not None and last[0] == frame:
            self.stats.duplicates += 1
            board.handle([], frame.session)  # feeds the watchdog, executes nothing
            wire = last[1]
        else:
            replies: list[Message] = board.handle(frame.messages, frame.session)
            if not replies:  # a board that answers nothing (killed or hung) sends nothing
                return
            wire = self._reply_frame(frame, replies)
            self._last[frame.board] = (frame, wire)
        if not self._silent(frame.board):
            self._write(wire)

    def _reply_frame(self, frame: Frame, replies: list[Message]) -> bytes:
        """The reply frame: the replies that fit in one frame (247 message
        bytes, MAX_MESSAGE_BYTES), in order; a request asking for more has the rest left off
        (counted as ``cut``), as a board's fixed reply buffer would."""
        kept = list(replies)
        while True:
            try:
                wire = encode_frame(Frame(frame.board, frame.seq, tuple(kept),
                                          from_board=True, session=frame.session))
            except CodecError:
                if len(kept) <= 1:
                    raise
                kept.pop()
                continue
            self.stats.cut += len(kept) < len(replies)
            return wire

    # -- serving -------------------------------------------------------------------
    def _side_fds(self) -> list[int]:
        """Descriptors besides the line that :meth:`serve` waits on (none here)."""
        return []

    def _side_ready(self, fd: int) -> None:
        """One of :meth:`_side_fds` is readable."""

    def _idle(self) -> None:
        """Called once each time round :meth:`serve`'s loop."""

    def stop(self) -> None:
        self._stop.set()

    def serve(self) -> None:
        """Serve until :meth:`stop` (or the fd closes).  In real time the world
        advances in ``step_s`` steps to keep up with the wall clock times
        ``time_scale`` (a :class:`Pacer`); in lockstep only StepTo advances it."""
        pacer = self.pacer
        while not self._stop.is_set():
            timeout = pacer.step()
            if self._late:
                timeout = min(timeout, max(0.0, min(t for t, _ in self._late) - time.monotonic()))
            ready, _, _ = select.select([self.fd, *self._side_fds()], [], [], max(0.0, timeout))
            for fd in ready:
                if fd != self.fd:
                    self._side_ready(fd)
            self._idle()
            if self.fd in ready:
                try:
                    data = os.read(self.fd, 4096)
                except OSError:
                    data = b""  # EIO while no host has the pty open
                    time.sleep(0.01)
                if data:
                    self.receive(data)
            self._flush_late()


class PtyPair:
    """A pseudo-terminal: the server keeps the master; ``path`` is what a host
    opens (``serial://<path>``).  The slave stays open here too, so the pty
    outlives a host that closes and reopens it."""

    def __init__(self) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        tty.setraw(self.master)
        self.path = os.ttyname(self.slave)

    def close(self) -> None:
        for fd in (self.master, self.slave):
            with contextlib.suppress(OSError):
                os.close(fd)


class InlineChannel:
    """A host's byte channel with the fake boards served in the same thread:
    every read first lets the server handle what the host wrote.  ``fd`` is
    the host's end of a socket pair whose other end the server holds (a
    socket pair, unlike a pty, hands bytes across at once).  No thread and no
    pacing: the world moves only when its owner advances it -- for tests that
    drive the boards' clock and the host's together.  Closing it closes ``fd``."""

    def __init__(self, fd: int, server: SerialBoardServer) -> None:
        self.fd = fd
        self.server = server

    def write(self, data: bytes) -> None:
        os.write(self.fd, data)

    def read_some(self, timeout_s: float) -> bytes:
        while select.select([self.server.fd], [], [], 0.0)[0]:
            data = os.read(self.server.fd, 4096)
            if not data:
                break
            self.server.receive(data)
        ready, _, _ = select.select([self.fd], [], [], max(0.0, timeout_s))
        return os.read(self.fd, 4096) if ready else b""

    def close(self) -> None:
        os.close(self.fd)
