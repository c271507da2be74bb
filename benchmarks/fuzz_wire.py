"""Fuzz the wire: seeded random and mutated frames through the serial and CAN
decoders and into the fake boards; prints counts.

    python benchmarks/fuzz_wire.py [--frames N] [--seed S] [--only serial|can|boards]

Each part sends ``--frames`` frames (default 1,000,000):

* **serial**: valid frames (random board, seq, direction and 1-6 messages of
  random type and bytes), each passed through one mutation -- none, 1-3
  flipped bits, 1-4 bytes inserted or deleted, truncated, ``01 01`` before
  the delimiter (protocol 2's blind spot), garbage, or spliced with another
  frame -- then decoded alone (``decode_frame``) and as one endless stream
  (``FrameReader``).  A mutated frame that decodes to a frame other than its
  original (spliced: than either of its two) is "undetected": a CRC-16 lets
  about 1 in 65,536 random corruptions through, but none may come from the
  blind spot.
* **can**: data frames of the DBC's ids (any session and seq) with random
  data, mutated -- flipped bits, a DLC one off, a random 29-bit id, an 11-bit
  id (protocol 3.x), remote, FD or error flags -- through ``CanWire.from_can``.
* **boards**: the fake boards (the pymunk robot behind them, never stepped)
  take the serial part's mutated bytes on their serial server and the CAN
  part's frames on their CAN server; every reply they send must decode.

"Unexpected" counts any exception but the decoders' CodecError; a call
slower than 1 s counts as a hang (and a stall of 60 s kills the script with
a traceback).  Exit status 1 when any unexpected exception, hang, blind-spot
frame or undecodable reply was seen.
"""

from __future__ import annotations

import argparse
import faulthandler
import os
import random
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator
from functools import partial
from itertools import count

import can

from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers import serial_wire
from stairbot.drivers.can_wire import SESSION_MAX, CanWire, make_id, wire
from stairbot.drivers.serial_wire import Frame, FrameReader, decode_frame, encode_frame
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer
from stairbot.fakes.serial_boards import SerialBoardServer
from stairbot.inputs.scenario import load_scenario

HANG_S = 1.0
STALL_S = 60
CODES = sorted(m.MESSAGES)
_channels = count()


class Tally:
    """Counts, the slowest call, and what went wrong (the first few)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.counts: Counter[str] = Counter()
        self.slowest_s = 0.0
        self.problems: list[str] = []
        self._calls = 0

    def timed(self, fn: Callable[[], object]) -> object:
        self._calls += 1
        if self._calls % 4096 == 1:  # a stall of STALL_S kills the script, with a traceback
            faulthandler.dump_traceback_later(STALL_S, exit=True, file=2)
        t0 = time.perf_counter()
        try:
            return fn()
        finally:
            dt = time.perf_counter() - t0
            self.slowest_s = max(self.slowest_s, dt)
            if dt > HANG_S:
                self.counts["hangs"] += 1

    def unexpected(self, what: str, exc: BaseException) -> None:
        self.counts["unexpected"] += 1
        if len(self.problems) < 5:
            self.problems.append(f"{what}: {type(exc).__name__}: {exc}")

    def report(self, seconds: float) -> None:
        print(f"{self.name}: {seconds:.1f} s, slowest call {self.slowest_s * 1e3:.2f} ms")
        for key, n in sorted(self.counts.items()):
            print(f"  {key:40s} {n:>10,}")
        for p in self.problems:
            print(f"  ! {p}")


# -- serial ------------------------------------------------------------------------


def random_message(rng: random.Random) -> m.RawMessage:
    """Mostly a message that decodes (random fields of a known type), else
    random bytes: an unknown type, or a known one whose fields do not decode
    or whose length is wrong."""
    code = rng.choice(CODES)
    size = m.payload_size(code)
    roll = rng.random()
    if roll < 0.8:
        for _ in range(20):
            payload = rng.randbytes(size)
            try:
                m.decode(code, payload)
                return m.RawMessage(code, payload)
            except m.CodecError:
                continue
    if roll < 0.9:
        return m.RawMessage(rng.randrange(256), rng.randbytes(rng.randint(0, 8)))
    return m.RawMessage(code, rng.randbytes(rng.randint(0, 8)))


def random_frame(rng: random.Random) -> Frame:
    """Mostly a host frame to a board that exists; any address and direction
    now and then."""
    msgs = tuple(random_message(rng) for _ in range(rng.randint(1, 6)))
    if rng.random() < 0.8:
        return Frame(rng.choice((1, 2)), rng.randrange(256), msgs, False)
    return Frame(rng.randrange(16), rng.randrange(256), msgs, rng.random() < 0.5)


MUTATIONS = ("none", "bit flips", "inserted bytes", "deleted bytes", "truncated",
             "01 01 before the delimiter", "garbage", "spliced")


def mutate(rng: random.Random, wire_: bytes, other: bytes) -> tuple[str, bytes]:
    """One mutation of a frame on the wire (delimiter included)."""
    kind = rng.choice(MUTATIONS)
    body = bytearray(wire_[:-1])
    if kind == "bit flips":
        for _ in range(rng.randint(1, 3)):
            i = rng.randrange(len(body))
            body[i] ^= 1 << rng.randrange(8)
    elif kind == "inserted bytes":
        i = rng.randrange(len(body) + 1)
        body[i:i] = rng.randbytes(rng.randint(1, 4))
    elif kind == "deleted bytes":
        i = rng.randrange(len(body))
        del body[i:i + rng.randint(1, 4)]
    elif kind == "truncated":
        del body[rng.randrange(len(body)):]
    elif kind == "01 01 before the delimiter":
        body += b"\x01\x01"
    elif kind == "garbage":
        body = bytearray(rng.randbytes(rng.randint(0, 300)))
    elif kind == "spliced":
        body = body[:rng.randrange(len(body) + 1)] + other[rng.randrange(len(other)):-1]
    return kind, bytes(body) + b"\x00"


def decoded(stuffed: bytes) -> Frame | None:
    """The frame a sender meant (decoded by the wire module itself)."""
    try:
        return serial_wire.decode_frame(stuffed)
    except m.CodecError:
        return None


def serial_cases(rng: random.Random, n: int
                 ) -> Iterator[tuple[str, tuple[Frame | None, ...], bytes]]:
    """(mutation, the frames it was made of as decoded (None: not valid), the
    mutated bytes)."""
    prev = encode_frame(random_frame(rng))
    for _ in range(n):
        wire_ = encode_frame(random_frame(rng))
        kind, bad = mutate(rng, wire_, prev)
        sources = (wire_, prev) if kind == "spliced" else (wire_,)
        prev = wire_
        yield kind, tuple(decoded(w[:-1]) for w in sources), bad


def fuzz_serial(rng: random.Random, n: int) -> Tally:
    t = Tally("serial decoders")
    reader = FrameReader()
    for kind, originals, bad in serial_cases(rng, n):
        t.counts["frames"] += 1
        if originals[0] is not None:
            t.counts["frames valid before mutation"] += 1
        stuffed = bad[:-1]
        try:
            got = t.timed(partial(decode_frame, stuffed))
        except m.CodecError:
            t.counts["refused (CRC, COBS, length, payload)"] += 1
        except Exception as exc:  # what the fuzz is for
            t.unexpected(f"decode_frame({stuffed.hex()})", exc)
        else:
            if kind == "none" or got in originals:
                t.counts["decoded as sent"] += 1
            else:
                t.counts[f"undetected: {kind}"] += 1
                if kind == "01 01 before the delimiter":
                    t.counts["blind spot"] += 1
        try:
            frames = t.timed(partial(reader.feed, bad))
        except Exception as exc:
            t.unexpected(f"FrameReader.feed({bad.hex()})", exc)
        else:  # resynchronising may find a frame decode_frame could not: one that was sent
            assert isinstance(frames, list)
            t.counts["stream: undetected"] += sum(f not in originals for f in frames)
    s = reader.stats
    t.counts["stream: frames"] = s.frames
    t.counts["stream: crc errors"] = s.crc_errors
    t.counts["stream: malformed"] = s.malformed
    t.counts["stream: overruns"] = s.overruns
    return t


# -- CAN ---------------------------------------------------------------------------


def can_cases(rng: random.Random, codec: CanWire, n: int) -> Iterator[can.Message]:
    bases = sorted(codec._by_id)  # every frame of the DBC, by base
    for _ in range(n):
        base = rng.choice(bases)
        size = codec._by_id[base][2].length
        fid = make_id(base, rng.randrange(SESSION_MAX + 1), rng.randrange(256))
        data = bytearray(rng.randbytes(size))
        extended, remote, fd, error = True, False, False, False
        kind = rng.randrange(8)
        if kind == 1 and data:
            data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        elif kind == 2:
            data = data + rng.randbytes(1) if size < 8 and rng.random() < 0.5 else data[:-1]
        elif kind == 3:
            fid = rng.randrange(1 << 29)
        elif kind == 4:
            remote = True
        elif kind == 5:
            extended, fid = False, rng.randrange(0x800)  # a protocol 3.x frame
        elif kind == 6:
            fd, data = True, bytearray(rng.randbytes(rng.choice((12, 16, 24, 32, 48, 64))))
        elif kind == 7:
            error = True
        yield can.Message(arbitration_id=fid, data=bytes(data), is_extended_id=extended,
                          is_remote_frame=remote, is_fd=fd, is_error_frame=error, check=False)


def fuzz_can(rng: random.Random, n: int) -> Tally:
    t = Tally("CAN decoder")
    codec = wire()
    for frame in can_cases(rng, codec, n):
        t.counts["frames"] += 1
        try:
            t.timed(partial(codec.from_can, frame))
            t.counts["decoded"] += 1
        except m.CodecError:
            t.counts["refused"] += 1
        except Exception as exc:
            t.unexpected(f"from_can({frame})", exc)
    return t


# -- the fake boards ---------------------------------------------------------------


def fuzz_boards(rng: random.Random, n: int) -> Tally:
    t = Tally("fake boards")
    config, scenario = load_config(), load_scenario()
    world = make_world(config, scenario, lockstep=False)
    r, w = os.pipe()
    os.set_blocking(r, False)
    serial = SerialBoardServer(w, world, make_boards(world))
    replies = FrameReader()
    for _, _, bad in serial_cases(rng, n):
        t.counts["serial frames in"] += 1
        try:
            t.timed(partial(serial.receive, bad))
        except Exception as exc:
            t.unexpected(f"serial receive({bad.hex()})", exc)
        try:
            while chunk := os.read(r, 65536):
                for frame in replies.feed(chunk):
                    t.counts["serial replies"] += 1
                    if not frame.from_board:
                        t.counts["serial replies not from a board"] += 1
        except BlockingIOError:
            pass
    t.counts["serial replies undecodable"] = replies.stats.errors
    os.close(r)
    os.close(w)

    channel = f"fuzz-{os.getpid()}-{next(_channels)}"
    board_bus = can.Bus(interface="virtual", channel=channel)
    host_bus = can.Bus(interface="virtual", channel=channel)
    world = make_world(config, scenario, lockstep=False)
    server = CanBoardServer(board_bus, world, make_boards(world))
    codec = wire()
    try:
        for can_frame in can_cases(rng, codec, n):
            t.counts["CAN frames in"] += 1
            try:
                t.timed(partial(server.receive, can_frame))
            except Exception as exc:
                t.unexpected(f"CAN receive({can_frame})", exc)
            while (reply := host_bus.recv(timeout=0.0)) is not None:
                t.counts["CAN replies"] += 1
                try:
                    if not codec.from_can(reply).message.REPLY:
                        t.counts["CAN replies not a reply type"] += 1
                except m.CodecError:
                    t.counts["CAN replies undecodable"] += 1
    finally:
        board_bus.shutdown()
        host_bus.shutdown()
    return t


PARTS: dict[str, Callable[[random.Random, int], Tally]] = {
    "serial": fuzz_serial, "can": fuzz_can, "boards": fuzz_boards}
FAILING = ("unexpected", "hangs", "blind spot", "serial replies undecodable",
           "serial replies not from a board", "CAN replies undecodable",
           "CAN replies not a reply type")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--frames", type=int, default=1_000_000, help="frames per part")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--only", choices=sorted(PARTS), action="append",
                   help="run only this part (may be repeated)")
    args = p.parse_args(argv)
    if args.frames < 1:
        p.error("--frames must be at least 1")
    bad = 0
    print(f"fuzz_wire: seed {args.seed}, {args.frames:,} frames per part")
    for name in args.only or list(PARTS):
        rng = random.Random(f"{args.seed}-{name}")
        t0 = time.perf_counter()
        tally = PARTS[name](rng, args.frames)
        faulthandler.cancel_dump_traceback_later()
        tally.report(time.perf_counter() - t0)
        bad += sum(tally.counts[k] for k in FAILING)
    print(f"failures: {bad}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
