"""The host killed at every phase of the fault matrix's flight
(:mod:`stairbot.fakes.fault_matrix`) and at several points inside each --
its first tick, its middle one and its last -- and a new host that resumes.

A phase's ticks are those of its first visit in a run with no fault (the
runs are deterministic in lockstep): :func:`phase_ticks`.  A kill at tick
``k`` stops the host right after the ``k``-th tick's journal line (as
``kill -9`` would: no end, no close); the boards hear nothing more, their
watchdogs trip and latch, the world runs on for a second, then a new host
reads the journal and resumes it with the operator's yes
(:func:`~stairbot.fakes.fault_rig.resume_watched`).  A kill is safe when
the resumed run completes, or the resume is refused, in one line, before any
Clear, the boards still latched.

``benchmarks/host_kills.py`` runs every phase and point on both wires;
tests/safety/test_host_kills.py runs a few, and checks the restore at every
tick of one journal.
"""

from __future__ import annotations

import contextlib
import json
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Mode
from stairbot.control.robot_config import load_config
from stairbot.errors import HardwareError
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.fault_rig import (
    HOST_DEAD_S,
    SCENARIO,
    BoardsOnWire,
    Cell,
    HostKilled,
    latched,
    resume_watched,
    run_on,
)
from stairbot.hardware import Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, parse_scenario
from stairbot.run.journal import mark_path
from stairbot.run.journaled import session_journal, start_journal
from stairbot.run.runner import RunResult, run

POINTS = ("first", "middle", "last")
"""Where in a phase's ticks the host is killed."""


class EndedBeforeKill(Exception):
    """The run to be killed ended first: the flight in lockstep is the same
    every time, so the wire (a reply later than the host's timeout on a
    machine past its cores) or the code changed it."""

    def __init__(self, ticks: int, tick: int, outcome: str, error: str | None,
                 fell: bool) -> None:
        self.fell = fell
        super().__init__(f"the run ended ({outcome}{': ' + error if error else ''}) after "
                         f"{ticks} ticks, before tick {tick}")


@dataclass
class Killed:
    """A host killed on fake boards: the boards (latched by now), its
    journal, the config it ran, and the tick it died after (0-based)."""

    boards: BoardsOnWire
    journal: Path
    config: RobotConfig
    tick: int

    def latched(self) -> bool:
        """Whether a board holds a latch."""
        return latched(self.boards)

    def last_phase(self) -> str:
        """The phase of the journal's last tick."""
        lines = self.journal.read_bytes().splitlines()
        ticks = [r for r in map(json.loads, lines) if r["kind"] == "tick"]
        return str(ticks[-1]["phase"]) if ticks else ""


@contextlib.contextmanager
def killed_host(wire: str, journal: Path | None, tick: int) -> Iterator[Killed]:
    """Fake boards on ``wire`` running the flight with a journal at
    ``journal`` (None: where a run on them keeps it by default,
    :func:`~stairbot.run.journaled.default_path`), the host killed after tick
    ``tick``, the world run on
    :data:`HOST_DEAD_S` and the boards listening again; closed when the
    block ends.  EndedBeforeKill when the run ends before that tick."""
    config = load_config()
    scenario = parse_scenario(SCENARIO, "<host kills>")
    world = make_world(config, scenario, lockstep=True)
    real = make_boards(world)
    boards = BoardsOnWire(wire, world, real, config)
    try:
        session = boards.open()
        journal = journal or session_journal(session)
        assert journal is not None
        writer = start_journal(journal, boards.url, session, config, scenario.name, Mode.FULL)
        assert writer is not None
        ticks = 0

        def kill(_ctl: Controller, _snap: Snapshot) -> None:
            nonlocal ticks
            ticks += 1
            if ticks > tick:
                boards.deaf(True)
                raise HostKilled

        try:
            result = run(session, config, on_tick=kill, journal=writer)
        except HostKilled:
            pass
        else:
            raise EndedBeforeKill(ticks, tick, result.outcome, result.error, result.fell)
        finally:
            writer.close()
            with contextlib.suppress(HardwareError):
                session.close()
        run_on(world, real, HOST_DEAD_S)
        boards.deaf(False)
        yield Killed(boards, journal, config, tick)
    finally:
        boards.close()


@cache
def recorded(wire: str) -> tuple[tuple[str, ...], bytes, bytes]:
    """A run of the flight with no fault on ``wire`` (once a process): each
    tick's phase, and its journal's and its mark's bytes."""
    with tempfile.TemporaryDirectory() as tmp:
        journal = Path(tmp) / "journal.jsonl"
        phases = record_run(wire, journal)
        return tuple(phases), journal.read_bytes(), mark_path(journal).read_bytes()


def phase_ticks(wire: str) -> dict[str, tuple[int, int]]:
    """Each phase's first visit in a run of the flight with no fault on
    ``wire``: its first and last tick (0-based, counted from the run's
    start)."""
    return _spans(list(recorded(wire)[0]))


def journaled_run(wire: str, scenario: Scenario, journal: Path
                  ) -> tuple[RunResult, list[str]]:
    """The reference robot on fake boards in lockstep on ``wire`` running
    ``scenario`` with no fault, journaled at ``journal``: its result and each
    tick's phase, in order."""
    config = load_config()
    world = make_world(config, scenario, lockstep=True)
    boards = BoardsOnWire(wire, world, make_boards(world), config)
    phases: list[str] = []
    try:
        session = boards.open()
        writer = start_journal(journal, boards.url, session, config, scenario.name, Mode.FULL)
        assert writer is not None
        try:
            result = run(session, config, journal=writer,
                         on_tick=lambda ctl, _snap: phases.append(ctl.context.phase))
        finally:
            writer.close()
            with contextlib.suppress(HardwareError):
                session.close()
    finally:
        boards.close()
    return result, phases


def record_run(wire: str, journal: Path) -> list[str]:
    """Run the flight with no fault on ``wire``, journaled at ``journal``;
    each tick's phase, in order.  AssertionError when it does not complete."""
    result, phases = journaled_run(wire, parse_scenario(SCENARIO, "<host kills>"), journal)
    assert result.outcome == "completed" and not result.fell, result
    return phases


def _spans(phases: list[str]) -> dict[str, tuple[int, int]]:
    spans: dict[str, tuple[int, int]] = {}
    for k, phase in enumerate(phases):
        if phase not in spans:
            spans[phase] = (k, k)
        elif spans[phase][1] == k - 1:  # still the first visit
            spans[phase] = (spans[phase][0], k)
    return spans


def kill_tick(wire: str, phase: str, point: str) -> int:
    """The tick at ``point`` ("first", "middle", "last") of ``phase``'s first
    visit.  KeyError when the flight never enters the phase."""
    first, last = phase_ticks(wire)[phase]
    return {"first": first, "middle": (first + last) // 2, "last": last}[point]


def run_kill(wire: str, phase: str, point: str, workdir: Path | None = None) -> Cell:
    """The host killed at ``point`` of ``phase`` on ``wire``, then resumed:
    its cell (fault "host killed at POINT"), judged as the module says."""
    t0 = time.perf_counter()
    cell = Cell(f"host killed at {point}", phase, wire, "UNSAFE", injected=True)
    with contextlib.ExitStack() as stack:
        if workdir is None:
            workdir = Path(stack.enter_context(tempfile.TemporaryDirectory()))
        try:
            with killed_host(wire, workdir / "journal.jsonl",
                             kill_tick(wire, phase, point)) as k:
                if k.last_phase() != phase:
                    cell.reason = f"killed in {k.last_phase()}, not {phase}"
                else:
                    taken = resume_watched(k.boards, k.config, k.journal)
                    cell.verdict, cell.reason = taken.verdict, taken.reason
        except EndedBeforeKill as exc:
            # not a kill: safe unless the run fell
            cell.verdict = "UNSAFE" if exc.fell else "not killed"
            cell.reason = str(exc)
    cell.wall_s = time.perf_counter() - t0
    return cell
