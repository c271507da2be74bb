"""What the fault matrix (:mod:`stairbot.fakes.fault_matrix`) and the host
kills (:mod:`stairbot.fakes.host_kills`) stand on: the two-step flight
(:data:`SCENARIO`) on fake boards in lockstep on a wire
(:class:`BoardsOnWire`), a host that dies where it stands
(:class:`HostKilled`), the world going on with no host (:func:`run_on`),
and a new host resuming the journal (:func:`resume_watched`).  A run is
judged into a :class:`Cell`.
"""

from __future__ import annotations

import contextlib
import io
import threading
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

import can

from stairbot.drivers.can_link import CanLink
from stairbot.errors import HardwareError, InputError
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import Board
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.fakes.firmware_boards import FirmwareBoardServer, build_native
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.fakes.serial_boards import PtyPair, SerialBoardServer
from stairbot.fakes.sim import motor_limits
from stairbot.inputs.config import RobotConfig
from stairbot.run.journaled import resume
from stairbot.run.resume import ResumeRefused
from stairbot.run.robots import RobotOptions, RobotSession, open_robot
from stairbot.run.runner import run

SCENARIO = """
name = "fault_matrix"
description = "Two residential steps, then a landing, starting close"
[stairs]
count = 2
rise = 0.17
tread = 0.28
top = "landing"
width = 1.0
side_wall = "none"
[start]
distance = 0.2
[sensors]
noise = 0.001
seed = 3
"""

TIMEOUT_S = {"can": 0.0005, "serial": 0.02, "firmware": 0.05}
"""The host's reply timeout on each wire: a lost frame costs this much wall
time.  The CAN boards answer in the host's own thread (InlineBus), at once;
the serial boards answer from a thread of their own, which must win the GIL
from the host's threads first: four of Python's 5 ms switch intervals, so a
reply is not taken for lost because the host held the GIL.  The firmware's
reply crosses two more processes (the board's program, which asks its plant
here first)."""
GRACE_S = 0.5  # the URLs' default grace period
HOST_DEAD_S = 1.0  # world seconds between the host killed and the new host


@dataclass
class Cell:
    """One cell's run: ``verdict`` is "completed", "stopped", "resumed" (the
    host killed, the new host finished), "refused" (the host killed, the new
    host refused to resume before touching the boards), "untested" (the run
    ended safely before its fault began) or "UNSAFE"; ``reason`` the run's
    error, or what made it unsafe."""

    fault: str
    phase: str
    wire: str
    verdict: str
    reason: str = ""
    injected: bool = False
    wall_s: float = 0.0

    @property
    def safe(self) -> bool:
        return self.verdict != "UNSAFE"


class HostKilled(BaseException):
    """Raised in the tick callback: the host dies where it stands."""


class BoardsOnWire:
    """The fake boards on one wire, and sessions of hosts opening them.
    ``wire``: "can" or "serial" (the Python fake boards ``boards``), or
    "firmware" (the boards' C firmware on the serial wire, built natively
    into ``firmware_dir``; ``boards`` is then empty)."""

    def __init__(self, wire: str, world: BoardWorld, boards: dict[int, Board],
                 config: RobotConfig, firmware_dir: Path | None = None) -> None:
        self.wire, self.world, self.boards, self.config = wire, world, boards, config
        self._thread: threading.Thread | None = None
        self.firmware: FirmwareBoardServer | None = None
        if wire == "can":
            self.channel = f"fault-matrix-{uuid.uuid4().hex[:8]}"
            self.url = f"can://virtual/{self.channel}?lockstep=1"
            self.server: CanBoardServer | SerialBoardServer = CanBoardServer(
                can.Bus(interface="virtual", channel=self.channel), world, dict(boards))
            return
        self.pty = PtyPair()
        self.url = f"serial://{self.pty.path}?lockstep=1&timeout={TIMEOUT_S[wire]}"
        if wire == "firmware":
            self.firmware = FirmwareBoardServer(
                self.pty.master, world, firmware_dir or build_native(), motor_limits(config),
                (1, 2))
            self.server = self.firmware
        else:
            self.server = SerialBoardServer(self.pty.master, world, dict(boards))
        self._serve()

    def _serve(self) -> None:
        self._thread = threading.Thread(target=self.server.serve, daemon=True)
        self._thread.start()

    def open(self, allow_latched: bool = False) -> RobotSession:
        if isinstance(self.server, CanBoardServer):
            bus = InlineBus(can.Bus(interface="virtual", channel=self.channel), self.server)
            link = CanLink(cast(can.BusABC, bus), timeout_s=TIMEOUT_S["can"], grace_s=GRACE_S)
            robot = LockstepRobot(link, self.url, allow_latched=allow_latched)
            return RobotSession(robot, robot.clock, self.url, robot.simulated)
        return open_robot(self.url, self.config, RobotOptions(allow_latched=allow_latched))

    def deaf(self, on: bool) -> None:
        """The boards hear nothing from the host (it is dead), or again."""
        server: Any = self.server
        if on:
            server.receive = lambda *_: None
        else:
            vars(server).pop("receive", None)

    def run_on(self, seconds: float) -> None:
        """The world goes on with no host: the boards' watchdogs see time pass."""
        if self.firmware is None:
            run_on(self.world, self.boards, seconds)
            return
        self.firmware.stop()  # the firmware's plant links are served here meanwhile
        if self._thread is not None:
            self._thread.join(5)
        self.firmware.run_on(seconds)
        self.firmware.rearm()
        self._serve()

    def latched(self) -> bool:
        """Whether a board holds a latch (its e-stop or its tripped watchdog)."""
        if self.firmware is not None:
            return self.firmware.latched()
        return any(b.estop or b.watchdog_tripped for b in self.boards.values())

    def close(self) -> None:
        if isinstance(self.server, CanBoardServer):
            self.server.bus.shutdown()
            return
        self.server.stop()
        if self._thread is not None:
            self._thread.join(5)
        if self.firmware is not None:
            self.firmware.close()
        self.pty.close()


def run_on(world: BoardWorld, boards: dict[int, Board], seconds: float) -> None:
    """The world goes on with no host: the boards' watchdogs see time pass."""
    t_us = round(world.now() * 1e6)
    for _ in range(round(seconds / 0.01)):
        t_us += 10_000
        world.step_to(t_us)
        for board in boards.values():
            board.poll()



@dataclass
class Resumption:
    """What a new host made of a killed one's journal: ``verdict`` "resumed"
    (the run completed, never fell), "refused" (one line, ``reason``, before
    any Clear: the boards still hold their latches), "stopped" (the new
    host's link failed as it took over; the boards left standing, latched)
    or "UNSAFE" (refused after the latches were cleared, a resumed run that
    did not complete, or a failed link that left a board unlatched or
    moving); ``cleared``: whether the host sent the boards a Clear."""

    verdict: str
    reason: str
    cleared: bool
    latched: bool


def latched(boards: BoardsOnWire) -> bool:
    """Whether a board holds a latch (its e-stop or its tripped watchdog)."""
    return boards.latched()


def _link_failed(boards: BoardsOnWire, cleared: bool, exc: HardwareError) -> Resumption:
    """The new host's link failed as it took over (a reply later than its
    timeout: a machine too loaded for the wire's timeout).  That is a stop,
    not a resume: "stopped" when, the world run on with no host, every motor
    stands and a latch holds the boards, else "UNSAFE"."""
    return _held(boards, cleared, f"the resume's link failed: {exc}")


def _held(boards: BoardsOnWire, cleared: bool, why: str) -> Resumption:
    """A host that stopped on a failed link: the world run on with no host,
    "stopped" when every motor stands and a latch holds the boards, else
    "UNSAFE"."""
    boards.run_on(HOST_DEAD_S)
    held = latched(boards)
    if held and not any(boards.world.speeds().values()):
        return Resumption("stopped", why, cleared, held)
    return Resumption("UNSAFE", f"{why}, and the boards were left unlatched or moving",
                      cleared, held)


def resume_watched(boards: BoardsOnWire, config: RobotConfig, journal: Path,
                   url: str | None = None) -> Resumption:
    """``stairbot run --resume --yes`` on ``boards`` (at ``url``, default
    theirs) from ``journal``, in this process, watching for the Clear."""
    session = boards.open(allow_latched=True)
    cleared = False
    clear = session.robot.clear

    def watched(*args: Any) -> None:
        nonlocal cleared
        cleared = True
        clear(*args)

    session.robot.clear = watched  # type: ignore[method-assign]
    try:
        try:
            resumed = resume(journal, url or boards.url, session, config, lambda _e: None,
                             yes=True, out=io.StringIO())
        except (ResumeRefused, InputError) as exc:
            held = latched(boards)
            safe = not cleared and held and "\n" not in str(exc)
            return Resumption("refused" if safe else "UNSAFE",
                              str(exc) if safe else f"refused after a Clear, or not in one "
                              f"line, or the latches gone: {exc}", cleared, held)
        except HardwareError as exc:
            return _link_failed(boards, cleared, exc)
        try:
            result = run(session, config, controller=resumed.controller,
                         journal=resumed.journal)
        finally:
            resumed.journal.close()
    finally:
        with contextlib.suppress(HardwareError):
            session.close()
    if result.outcome == "completed" and not result.fell:
        return Resumption("resumed", "", cleared, latched(boards))
    if result.fault == "link" and not result.fell:
        return _held(boards, cleared, f"the resumed run lost its link: {result.error}")
    return Resumption("UNSAFE", f"the resumed run ended {result.outcome}: {result.error}",
                      cleared, latched(boards))
