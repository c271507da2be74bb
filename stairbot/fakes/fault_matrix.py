"""The fault matrix: one fault, started as the run enters one phase, on a
two-step flight over the fake boards in lockstep -- and what the run must
end as.

Faults (:data:`FAULTS`):

* ``drop``, ``corrupt``, ``late``, ``duplicate`` at 1, 5 and 20 % of the frames,
  both ways, from the phase to the end of the run (a late frame comes
  :data:`LATE_S` after it was due, well past the host's timeout);
* a board **killed**: from the phase on it answers nothing and its motors
  stop (its power is gone; the lifts are self-locking and hold);
* a board **hung**: it answers nothing, and its motors run on as last told
  until its watchdog -- a timer of its own, not its firmware -- stops them;
* the **host killed**: from the phase on the host sends nothing (as after
  ``kill -9``); a second later a new host reads the journal, the operator
  says yes, and it carries the run on.

A cell is **safe** (:func:`run_cell`) when the run

* completed the flight up and back down and never fell; or
* stopped with a reason (the driver's words: "no reply from the motor board
  for 0.52 s ..."), never fell, every motor the host still reached stopped
  at once, and -- the host gone, the world run on for :data:`AFTER_S` --
  every motor stopped and the lifts holding (their turns unchanged), with a
  journal that ends resumable (a lost link) so ``--resume`` can carry on;
* for the host killed: the resumed run completed and never fell (a resume
  refused before any Clear, the boards still latched, is "refused": safe,
  but not what the matrix expects).

A run that ends before its phase comes (the host's timeouts are wall time:
a loaded machine can lose the link with no fault at all) tested nothing:
its stop is judged as any other, and if safe the cell is **untested**, for
``benchmarks/fault_matrix.py`` to run again.  When motors are left running,
the reason names the boards that did not confirm the host's emergency stop.

The flight, the boards on their wire and the resuming host are
:mod:`stairbot.fakes.fault_rig`'s, shared with :mod:`stairbot.fakes.host_kills`.
``benchmarks/fault_matrix.py`` runs every cell and prints the table of
docs/reliability.md; tests/safety/test_fault_matrix.py runs a subset in CI.
"""

from __future__ import annotations

import contextlib
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Mode
from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.errors import HardwareError
from stairbot.events import Event, EventKind
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import Board, make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.fault_rig import (
    HOST_DEAD_S,
    SCENARIO,
    BoardsOnWire,
    Cell,
    HostKilled,
    resume_watched,
)
from stairbot.fakes.serial_boards import WireFaults
from stairbot.hardware import Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.journal import read_journal
from stairbot.run.journaled import start_journal
from stairbot.run.runner import RunResult, run

LATE_S = {"can": 0.005, "serial": 0.12, "firmware": 0.3}  # ten, six and six timeouts late
AFTER_S = 2.0  # world seconds run on after a stopped run, no host
LIFT_HELD_TURNS = 1e-3  # a held lift's give under load is 1e-5 turns
MOTOR, SENSOR = int(m.Board.MOTOR), int(m.Board.SENSOR)

PHASES: tuple[str, ...] = (
    "cal_check", "cal_lift", "cal_probe", "cal_turn", "cal_lower",
    "ascent_approach", "ascent_approach_turns", "ascent_lift_first", "ascent_lift_first_more",
    "ascent_drive_first", "ascent_lift_second", "ascent_drive_second", "ascent_lift_third",
    "ascent_check", "ascent_drive_third",
    "descent_lower_third", "descent_drive_second", "descent_lower_second",
    "descent_drive_first", "descent_lower_first", "descent_back_off", "descent_back_to_edge",
    "descent_finish",
)
"""The phases a fault starts in (at the first time the run enters it): every
phase the two-step flight goes through -- calibration, each of the seed's
ascent and descent phases -- in that order."""


@dataclass(frozen=True)
class Fault:
    name: str
    kind: str  # "wire", "kill", "hang" or "host"
    wire: dict[str, float] = field(default_factory=dict)
    board: int | None = None


def _faults() -> dict[str, Fault]:
    out: list[Fault] = []
    for kind in ("drop", "corrupt", "late", "duplicate"):
        for pct in (1, 5, 20):
            out.append(Fault(f"{kind} {pct}%", "wire", {kind: pct / 100}))
    for kind in ("kill", "hang"):
        for name, board in (("motor", MOTOR), ("sensor", SENSOR)):
            out.append(Fault(f"{name} board {'killed' if kind == 'kill' else 'hung'}",
                             kind, board=board))
    out.append(Fault("host killed", "host"))
    return {f.name: f for f in out}


FAULTS: dict[str, Fault] = _faults()
WIRES = ("can", "serial")
"""The wires every cell runs on by default; "firmware" (the boards' C
firmware on the serial wire, ``fake-boards --firmware native``) on request."""
ALL_WIRES = (*WIRES, "firmware")


class _DeadBoard:
    """A board that answers nothing and executes nothing (killed or hung)."""

    def __init__(self, board: Board) -> None:
        self.board = board

    def handle(self, msgs: Any, session: int) -> list[m.Message]:
        return []

    def __getattr__(self, name: str) -> Any:
        return getattr(self.board, name)



def _lifts(world: BoardWorld) -> tuple[float, ...]:
    snap = world.snapshot()
    if snap is None:
        return ()
    return tuple(snap.motors[m.MOTOR_CHANNELS[ch]].turns for ch in sorted(m.LIFT_CHANNELS))



def _after_stop(cell: Cell, result: RunResult, boards: BoardsOnWire, journal: Path,
                alive: bool, links: list[str]) -> Cell:
    """Check a run that did not complete: see the module docstring.
    ``links``: the host's LINK events of the run."""
    world = boards.world
    problems: list[str] = []
    if result.fell:
        problems.append("fell")
    if not result.error:
        problems.append("stopped with no reason given")
    if alive and any(world.speeds().values()):
        unconfirmed = [t for t in links if t.startswith("emergency stop not confirmed")]
        problems.append(f"motors left running: {world.speeds()}"
                        + "".join(f" [{t}]" for t in unconfirmed))
    boards.run_on(0.5)  # every watchdog has tripped by now
    before = _lifts(world)
    boards.run_on(AFTER_S - 0.5)
    after = _lifts(world)
    if any(world.speeds().values()):
        problems.append(f"motors running {AFTER_S:.0f} s on: {world.speeds()}")
    if any(abs(a - b) > LIFT_HELD_TURNS for a, b in zip(before, after, strict=True)):
        problems.append(f"a lift moved with no host: {before} -> {after}")
    truth = world.truth()
    if truth.flags:
        problems.append("fell once left alone")
    if result.fault == "link":
        end = read_journal(journal).end or {}
        if not end.get("resumable"):
            problems.append("the journal does not offer --resume after a lost link")
    if problems:
        cell.verdict, cell.reason = "UNSAFE", "; ".join(problems) + f" ({result.error})"
    else:
        cell.verdict, cell.reason = "stopped", result.error or ""
    return cell


def run_cell(fault_name: str, phase: str, wire: str = "can", seed: int = 1,
             workdir: Path | None = None, firmware_dir: Path | None = None) -> Cell:
    """Run one cell of the matrix and judge it (see the module docstring);
    on the "firmware" wire, with the native programs in ``firmware_dir``
    (default: built into firmware/build)."""
    fault = FAULTS[fault_name]
    if phase not in PHASES or wire not in ALL_WIRES:
        raise ValueError(f"unknown phase {phase!r} or wire {wire!r}")
    t0 = time.perf_counter()
    with contextlib.ExitStack() as stack:
        if workdir is None:
            workdir = Path(stack.enter_context(tempfile.TemporaryDirectory()))
        cell = _run(fault, phase, wire, seed, workdir / "journal.jsonl", firmware_dir)
    cell.wall_s = time.perf_counter() - t0
    return cell


def _run(fault: Fault, phase: str, wire: str, seed: int, journal: Path,
         firmware_dir: Path | None) -> Cell:
    config = load_config()
    scenario = parse_scenario(SCENARIO, "<fault matrix>")
    world = make_world(config, scenario, lockstep=True)
    real = {} if wire == "firmware" else make_boards(world)
    boards = BoardsOnWire(wire, world, real, config, firmware_dir)
    cell = Cell(fault.name, phase, wire, "UNSAFE")
    try:
        session = boards.open()
        writer = start_journal(journal, boards.url, session, config, scenario.name, Mode.FULL)
        assert writer is not None

        def inject(ctl: Controller, snap: Snapshot) -> None:
            if cell.injected or ctl.context.phase != phase:
                return
            cell.injected = True
            if fault.kind == "wire":
                boards.server.set_faults(WireFaults(seed=seed, late_s=LATE_S[wire],
                                                    **fault.wire))  # type: ignore[arg-type]
            elif fault.kind in ("kill", "hang") and boards.firmware is not None:
                assert fault.board is not None
                if fault.kind == "kill":
                    boards.firmware.kill(fault.board)
                else:
                    boards.firmware.hang(fault.board)
            elif fault.kind in ("kill", "hang"):
                assert fault.board is not None
                if fault.kind == "kill":
                    real[fault.board].halt()
                boards.server.boards[fault.board] = _DeadBoard(real[fault.board])  # type: ignore[assignment]
                boards.server.set_faults(WireFaults(silent_board=fault.board,
                                                    silent_after_s=0.0))
            else:
                boards.deaf(True)
                raise HostKilled

        links: list[str] = []

        def sink(event: Event) -> None:
            if event.kind is EventKind.LINK:
                links.append(event.message)

        try:
            result = run(session, config, sink, on_tick=inject, journal=writer)
        except HostKilled:
            result = None
        finally:
            writer.close()
            with contextlib.suppress(HardwareError):
                session.close()
        if not cell.injected:
            return _untested(cell, result, boards, journal, links)
        if result is None:
            return _resumed(cell, boards, config, journal)
        if result.outcome == "completed" and not result.fell:
            cell.verdict, cell.reason = "completed", ""
            return cell
        alive = fault.kind == "wire" or fault.board != MOTOR
        return _after_stop(cell, result, boards, journal, alive, links)
    finally:
        boards.close()


def _untested(cell: Cell, result: RunResult | None, boards: BoardsOnWire, journal: Path,
              links: list[str]) -> Cell:
    """A run that never entered the cell's phase: UNSAFE if its own end was
    (a stop judged as any other), else untested."""
    assert result is not None  # the host is killed only in the phase
    ended = f"the run never entered {cell.phase} (it ended {result.outcome}: {result.error})"
    if result.outcome != "completed" or result.fell:
        _after_stop(cell, result, boards, journal, True, links)
        if not cell.safe:
            cell.reason = f"{ended}; {cell.reason}"
            return cell
    cell.verdict, cell.reason = "untested", ended
    return cell


def _resumed(cell: Cell, boards: BoardsOnWire, config: RobotConfig, journal: Path) -> Cell:
    """The host was killed: the world runs on, then a new host resumes."""
    boards.run_on(HOST_DEAD_S)
    boards.deaf(False)
    taken = resume_watched(boards, config, journal)
    cell.verdict, cell.reason = taken.verdict, taken.reason
    return cell



def cells(wires: tuple[str, ...] = WIRES) -> Iterator[tuple[str, str, str]]:
    """Every (fault, phase, wire) of the matrix."""
    for wire in wires:
        for fault in FAULTS:
            for phase in PHASES:
                yield fault, phase, wire
