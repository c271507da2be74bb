"""Both fake boards served on a python-can bus.

    stairbot fake-boards --can INTERFACE/CHANNEL [--scenario FILE] [--config FILE]
                         [--time-scale X | --lockstep] [fault options]

serves the emulated motor and sensor boards (``fakes.boards``, backed by the
same physics world as ``sim://``) on any python-can bus, e.g.
``udp_multicast/239.74.163.2`` (other processes on this host join it with
``can://udp_multicast/239.74.163.2``); ``INTERFACE/CHANNEL`` may carry the
URL's bus options (``udp_multicast/239.74.163.2?port=43200``).  It prints the
``can://`` URL a host opens, then serves until interrupted.

On ``udp_multicast`` the boards listen on this machine's loopback interface
only, as every ``can://udp_multicast`` bus stairbot opens
(``drivers.udp_loopback``: bound to ``GROUP:PORT``, the group joined on
``127.0.0.1``, sent with TTL 0): no other host can send them frames.  The
URL option ``lan=1`` opens them to the network instead (python-can's socket
on ``0.0.0.0:PORT``); the line on stderr says which.

:class:`CanBoardServer` decodes each frame with the DBC (``drivers.can_wire``),
hands a host frame to the board it is for (both boards for board 15), and
sends each reply as one frame from that board, with the session and seq of
the host frame it answers.  A host frame identical to the previous one to
the same board (same session, seq, kind and data -- a retry, or a copy the
bus made; sent to that board or to every board) gets the previous replies
again without being executed twice, as docs/protocol.md requires of
firmware; a frame of a new session is executed.  Frames from boards (its
own echo on ``udp_multicast``) are ignored; unknown ids, wrong lengths and
11-bit ids (a protocol 3.x host) are counted as malformed and ignored, as
CAN firmware ignores frames it does not understand.
Fault injection (``WireFaults``, as on the serial wire) acts on whole frames:
dropped, corrupted (the receiver's CAN controller rejects it: modelled as an
error frame), duplicated, late, and a board that goes silent.
"""

from __future__ import annotations

import sys
import threading
import time
from dataclasses import dataclass

import can
from can.interfaces.udp_multicast import UdpMulticastBus

from stairbot.control.robot_config import config_for
from stairbot.drivers import messages as m
from stairbot.drivers.can_robot import open_bus, parse_can_url
from stairbot.drivers.can_wire import BROADCAST, CanFrame, CanWire, wire
from stairbot.drivers.udp_loopback import LoopbackUdpMulticastBus
from stairbot.errors import RobotUrlError
from stairbot.fakes.board_world import BoardWorld, Pacer
from stairbot.fakes.boards import Board, launch_serials, make_boards, serials_words
from stairbot.fakes.registry import registered
from stairbot.fakes.serial_boards import FaultDice, WireFaults
from stairbot.inputs.scenario import load_scenario


@dataclass
class CanServerStats:
    frames_rx: int = 0  # host frames handled
    frames_tx: int = 0
    error_frames: int = 0
    malformed: int = 0  # unknown ids, wrong lengths, 11-bit ids (protocol 3.x)
    duplicates: int = 0  # repeated host frames answered from the cache
    ignored: int = 0  # frames from boards (our own echo included)
    stray: int = 0  # host frames for a board not served here
    injected: int = 0  # faults injected
    send_errors: int = 0  # replies the bus refused to send


class CanBoardServer:
    """Serve ``boards`` (address -> Board) on ``bus``."""

    def __init__(self, bus: can.BusABC, world: BoardWorld, boards: dict[int, Board],
                 faults: WireFaults | None = None, time_scale: float = 1.0,
                 step_s: float = 0.005, codec: CanWire | None = None) -> None:
        self.bus = bus
        self.world = world
        self.boards = boards
        self.faults = faults or WireFaults()
        self.time_scale = time_scale
        self.step_s = step_s
        self.codec = codec or wire()
        self.stats = CanServerStats()
        self._dice = FaultDice(self.faults, self.stats)
        self._late: list[tuple[float, can.Message]] = []
        # per board: the last host frame it executed (session, seq, type, data)
        # and its replies
        self._last: dict[int, tuple[tuple[int, int, int, bytes], list[m.Message]]] = {}
        self._stop = threading.Event()
        self.pacer = Pacer(world, boards.values(), time_scale, step_s)
        self.last_send_error: str | None = None

    # -- faults ------------------------------------------------------------------
    def set_faults(self, faults: WireFaults) -> None:
        """From now on, these faults (a fault matrix starts them mid-run)."""
        self.faults = faults
        self._dice = FaultDice(faults, self.stats)

    def _chance(self, p: float) -> bool:
        return self._dice.chance(p)

    def _silent(self, board: int) -> bool:
        return self._dice.silent(board, self.world.now())

    # -- frames --------------------------------------------------------------------
    def _send(self, frame: can.Message) -> None:
        f = self.faults
        if self._chance(f.drop):
            return
        if self._chance(f.corrupt):
            frame = can.Message(arbitration_id=frame.arbitration_id, is_error_frame=True,
                                is_extended_id=True, data=b"")
        if self._chance(f.late):
            self._late.append((time.monotonic() + f.late_s, frame))
            return
        for _ in range(2 if self._chance(f.duplicate) else 1):
            self._put(frame)

    def _put(self, frame: can.Message) -> None:
        """Send one frame; a bus that refuses it (buffer full, interface
        down) costs that frame, counted, never the server."""
        try:
            self.bus.send(frame, timeout=0.05)
        except (can.CanError, OSError) as exc:
            self.stats.send_errors += 1
            self.last_send_error = str(exc)
            return
        self.stats.frames_tx += 1

    def _flush_late(self) -> None:
        now = time.monotonic()
        due = [fr for t, fr in self._late if t <= now]
        self._late = [(t, fr) for t, fr in self._late if t > now]
        for frame in due:
            self._put(frame)

    def receive(self, frame: can.Message) -> None:
        """Handle one frame from the bus."""
        if frame.is_error_frame:
            self.stats.error_frames += 1
            return
        try:
            decoded = self.codec.from_can(frame)
        except m.CodecError:
            self.stats.malformed += 1
            return
        if decoded.message.REPLY:
            self.stats.ignored += 1
            return
        f = self.faults
        if self._chance(f.drop):
            return
        if self._chance(f.corrupt):
            self.stats.error_frames += 1
            return
        targets = list(self.boards) if decoded.board == BROADCAST else [decoded.board]
        for _ in range(2 if self._chance(f.duplicate) else 1):
            for address in targets:
                self._handle(address, decoded, bytes(frame.data))

    def _handle(self, address: int, frame: CanFrame, data: bytes) -> None:
        board = self.boards.get(address)
        if board is None:
            self.stats.stray += 1
            return
        self.stats.frames_rx += 1
        # The board field is left out: a retry to one board of a frame first
        # broadcast to both is the same frame to this board.
        key = (frame.session, frame.seq, frame.message.TYPE, data)
        last = self._last.get(address)
        if last is not None and last[0] == key:
            self.stats.duplicates += 1
            board.handle([], frame.session)  # feeds the watchdog, executes nothing
            replies = last[1]
        else:
            replies = board.handle([frame.message], frame.session)
            self._last[address] = (key, replies)
        if self._silent(address):
            return
        for reply in replies:
            self._send(self.codec.to_can(address, reply, frame.session, frame.seq))

    # -- serving -------------------------------------------------------------------
    def pump(self) -> None:
        """Handle every frame that has already arrived; never waits."""
        frame = self.bus.recv(timeout=0.0)
        while frame is not None:
            self.receive(frame)
            frame = self.bus.recv(timeout=0.0)
        if self._late:
            self._flush_late()

    def stop(self) -> None:
        self._stop.set()

    def serve(self) -> None:
        """Serve until :meth:`stop`.  In real time the world advances in
        ``step_s`` steps to keep up with the wall clock times ``time_scale``
        (a :class:`Pacer`: the bus is looked at between steps, as on the serial
        server); in lockstep only StepTo advances it."""
        pacer = self.pacer
        while not self._stop.is_set():
            timeout = pacer.step()
            if self._late:
                timeout = min(timeout, max(0.0, min(t for t, _ in self._late) - time.monotonic()))
            frame = self.bus.recv(timeout=max(0.0, timeout))
            while frame is not None:
                self.receive(frame)
                frame = self.bus.recv(timeout=0.0)
            self._flush_late()


def host_url(spec: str) -> str:
    """The ``can://`` URL for a ``--can INTERFACE/CHANNEL[?options]`` argument."""
    return spec if spec.startswith("can://") else f"can://{spec}"


def reach(bus: can.BusABC) -> str:
    """Who can send ``bus`` frames, for the serving line: said for
    ``udp_multicast``, where it is a choice (``lan=1``)."""
    if isinstance(bus, LoopbackUdpMulticastBus):
        return ", this machine only: loopback 127.0.0.1, TTL 0"
    if isinstance(bus, UdpMulticastBus):
        return ", OPEN TO THE NETWORK (lan=1): any host on it can send these boards frames"
    return ""


def main(argv: list[str]) -> int:
    """``stairbot fake-boards --can ...`` (the serial engineer's parser hands
    over here).  Bad input raises InputError: the CLI prints one line, exits 2."""
    from stairbot.fakes.boards_cli import build_parser, faults_from, make_world, stop_on_signals

    args = build_parser().parse_args(argv)
    url = host_url(args.can)
    spec = parse_can_url(url)
    if spec.interface == "virtual":
        raise RobotUrlError(url, "interface", "a virtual bus lives inside one process; "
                            "serve other processes with udp_multicast/GROUP")
    scenario = load_scenario(args.scenario)
    config, note = config_for(args.config, scenario)
    if note is not None:
        print(f"stairbot fake-boards: {note}", file=sys.stderr, flush=True)
    world = make_world(config, scenario, args.lockstep)
    bus = open_bus(spec)
    boards = make_boards(world, launch_serials())
    server = CanBoardServer(bus, world, boards, faults_from(args), time_scale=args.time_scale)
    stop_on_signals(server.stop)  # before the URL is printed

    sep = "&" if "?" in url else "?"
    suffix = f"{sep}lockstep=1" if args.lockstep else (
        f"{sep}time_scale={args.time_scale:g}" if args.time_scale != 1.0 else "")
    print(f"{url}{suffix}", flush=True)
    print(f"fake boards ({serials_words(boards)}) serving on CAN {spec.label}{reach(bus)} "
          "(Ctrl-C to stop)", file=sys.stderr, flush=True)

    try:
        with registered(f"{url}{suffix}", wire="can", scenario=scenario.name,
                        config=args.config or scenario.robot or "reference",
                        serials=serials_words(boards)):
            server.serve()
    except KeyboardInterrupt:
        pass
    finally:
        bus.shutdown()
        s = server.stats
        print(f"fake boards: {s.frames_rx} frames in, {s.frames_tx} out, {s.error_frames} "
              f"error frames, {s.malformed} malformed, {s.duplicates} repeated frames "
              f"answered from the cache, {s.injected} faults injected, "
              f"{s.send_errors} replies the bus refused{server.pacer.report()}",
              file=sys.stderr)
    return 0


class InlineBus:
    """A host's bus with the fake boards served in the same thread: a
    ``recv`` that finds no frame waiting first lets the server handle what
    reached it.  Deterministic and free of thread hand-offs, for tests and
    benchmarks on ``virtual``; the frames still go through python-can and the
    DBC both ways.  The frames the host reads, and their order, are those of
    a server run before every ``recv``: the server handles the host's frames
    in the order they were sent whenever it runs, and its replies queue
    behind those already waiting; it only runs less often (once a burst of
    replies is read, not once a frame)."""

    def __init__(self, bus: can.BusABC, server: CanBoardServer) -> None:
        self.bus = bus
        self.server = server
        self.channel_info = f"{bus.channel_info} (boards inline)"

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        self.bus.send(msg, timeout)

    def recv(self, timeout: float | None = None) -> can.Message | None:
        waiting = self.bus.recv(0.0)
        if waiting is not None:
            return waiting
        self.server.pump()
        return self.bus.recv(timeout)

    def shutdown(self) -> None:
        self.bus.shutdown()
