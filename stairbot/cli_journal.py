"""``stairbot run``'s journal and ``--resume`` (the journal's format:
:mod:`stairbot.journal`; what a resume checks: :mod:`stairbot.resume`).

A run on boards (``serial://``, ``can://``) keeps a journal by default, at
``$XDG_STATE_HOME/stairbot/journal-<robot>.jsonl`` (``~/.local/state`` when
unset; ``<robot>`` names the port or bus, not the URL's options), or where
``--journal FILE`` says.  A simulated run keeps one only when asked: it
cannot be resumed (its world ends with the process).
"""

from __future__ import annotations

import hashlib
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from stairbot.algorithm.controller import Controller
from stairbot.algorithm.phases import Mode
from stairbot.config import RobotConfig
from stairbot.events import EventSink
from stairbot.journal import JournalState, JournalWriter, digest, read_journal
from stairbot.resume import ResumeRefused, check, describe, restored_context
from stairbot.robots import RobotSession
from stairbot.runner import board_identity
from stairbot.text import printable


class NotConfirmed(ResumeRefused):
    """The operator did not confirm the resume: nothing moved."""


def config_digest(config: RobotConfig) -> str:
    values = config.to_dict()
    values.pop("source", None)
    return digest(values)


def default_path(url: str) -> Path | None:
    """The default journal of a robot on a wire (None: the simulation)."""
    if not url.startswith(("serial://", "can://")):
        return None
    where = url.split("?", 1)[0]
    slug = hashlib.sha256(where.encode()).hexdigest()[:12]
    state = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    return Path(state) / "stairbot" / f"journal-{slug}.jsonl"


def journal_path(url: str, given: str | None) -> Path | None:
    return Path(given) if given else default_path(url)


def start_journal(path: Path | None, url: str, session: RobotSession, config: RobotConfig,
                  scenario: str, mode: Mode) -> JournalWriter | None:
    """A fresh journal for a new run (None: none kept).  JournalError when it
    cannot be written."""
    if path is None:
        return None
    writer = JournalWriter(path, fresh=True)
    writer.start(url=url, config=config.source, config_sha256=config_digest(config),
                 scenario=scenario, mode=mode.value, boards=board_identity(session.robot),
                 time_s=session.clock.now())
    return writer


@dataclass
class Resumed:
    controller: Controller
    journal: JournalWriter
    state: JournalState


def ask(prompt: str) -> bool:
    """The operator's answer on the terminal (no terminal: no)."""
    if not sys.stdin.isatty():
        return False
    try:
        return input(prompt).strip().lower() in ("y", "yes")
    except EOFError:
        return False


@dataclass
class ResumePlan:
    """A run the journal says can go on, checked against the boards; nothing
    has moved yet.  ``lines``: where the robot believes it is."""

    path: Path
    state: JournalState
    lines: list[str]


def plan_resume(path: Path | None, url: str, session: RobotSession,
                config: RobotConfig) -> ResumePlan:
    """Check the journal's run against the boards and say where the robot
    believes it is (the checks of ``stairbot run --resume``: the run did not
    end, the boards are the journal's and did not restart, the same config).
    ResumeRefused (one line) otherwise.  Moves nothing."""
    if path is None:
        raise ResumeRefused(f"{url}: a simulation cannot be resumed: its world ended with "
                            "the host that ran it")
    state = read_journal(path)
    robot = session.robot
    check(state, url, board_identity(robot))
    if state.start.get("config_sha256") != config_digest(config):
        raise ResumeRefused(f"{path}: the run began with config {state.start.get('config')}, "
                            f"which differs from {config.source}: pass --config "
                            f"{state.start.get('config')}")
    lines = describe(state)
    latched = getattr(robot, "latched", {})
    if latched:
        lines.append(f"the boards hold latches ({len(latched)} board(s)); resuming "
                     "clears them")
    return ResumePlan(path, state, lines)


def carry_on(plan: ResumePlan, session: RobotSession, config: RobotConfig,
             sink: EventSink) -> Resumed:
    """Once the operator has confirmed ``plan``: clear the boards' latches and
    hand back the restored controller and the journal, appended to."""
    robot = session.robot
    if getattr(robot, "latched", {}) or robot.estopped:
        robot.clear()
    now = session.clock.now()
    state = plan.state
    ctx = restored_context(state, now)
    mode = Mode(state.start.get("mode", Mode.FULL.value))
    controller = Controller(config, sink, mode, context=ctx)
    writer = JournalWriter(plan.path, fresh=False)
    writer.resume(str(state.start["run_id"]), board_identity(robot), now)
    return Resumed(controller, writer, state)


def resume(path: Path | None, url: str, session: RobotSession, config: RobotConfig,
           sink: EventSink, *, yes: bool, out: TextIO,
           confirm: Callable[[str], bool] = ask) -> Resumed:
    """Check the journal's run against the boards, say where the robot
    believes it is, and -- once the operator confirms -- clear the boards'
    latches and hand back the restored controller.  ResumeRefused (one line)
    otherwise; nothing has moved then."""
    plan = plan_resume(path, url, session, config)
    for line in plan.lines:
        print(f"resume: {printable(line)}", file=out)
    out.flush()
    question = ("Look at the robot: does it stand where the lines above say?  Resume and "
                "let it move? [y/N] ")
    if not yes and not confirm(question):
        raise NotConfirmed("not resumed: no confirmation (answer y on a terminal, or add "
                           "--yes); nothing moved")
    return carry_on(plan, session, config, sink)
