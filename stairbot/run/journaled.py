"""A run's journal and its resume, as ``stairbot run``, the console and the
fake-board harnesses keep them (the journal's format:
:mod:`stairbot.run.journal`; what a resume checks: :mod:`stairbot.run.resume`).

A run on boards (``serial://``, ``can://``) keeps a journal by default, at
``$XDG_STATE_HOME/stairbot/journal-motor-<serial>.jsonl`` (``~/.local/state``
when unset; the motor board's serial number: the robot, whatever port or
bus it is on), or where ``--journal FILE`` says.  A simulated run keeps one only when asked: it
cannot be resumed (its world ends with the process).

A journal whose run on boards did not finish is never overwritten: a new
run sets it aside first (:func:`set_aside`: renamed beside, with its mark),
and ``stairbot run`` refuses to start one over it unless told
(:func:`unfinished`, ``--discard-journal``).
"""

from __future__ import annotations

import hashlib
import json
import os
import stat
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from stairbot.control.algorithm import limits
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.lost import awaits_consent
from stairbot.control.algorithm.phases import Mode
from stairbot.events import EventSink
from stairbot.hardware import HasAttitude, HoldsLatches, Imu, Robot
from stairbot.inputs.config import RobotConfig
from stairbot.run.journal import (
    MAX_LINE,
    JournalError,
    JournalState,
    JournalWriter,
    digest,
    mark_path,
    read_journal,
)
from stairbot.run.paths import unused_path
from stairbot.run.resume import ResumeRefused, check, describe, restored_context
from stairbot.run.robots import RobotSession
from stairbot.run.runner import board_identity
from stairbot.text import printable


class NotConfirmed(ResumeRefused):
    """The operator did not confirm the resume: nothing moved."""


def config_digest(config: RobotConfig) -> str:
    values = limits.config_dict(config)
    values.pop("source", None)
    return digest(values)


def default_path(url: str, boards: Mapping[str, Mapping[str, int]] | None = None) -> Path | None:
    """The default journal of a robot on a wire (None: the simulation), kept
    by its motor board's serial number when ``boards`` (their identity, as
    :func:`~stairbot.run.runner.board_identity` gives it) names it: the
    robot's journal follows it to another port, and another robot on a port
    this one used never finds it.  By the port or bus when the motor board's
    serial is not known, or where the journal kept by the port (as stairbot
    did before) is of the same motor board and none is kept by its serial."""
    if not url.startswith(("serial://", "can://")):
        return None
    state = Path(os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state"))
    where = url.split("?", 1)[0]
    slug = hashlib.sha256(where.encode()).hexdigest()[:12]
    by_port = state / "stairbot" / f"journal-{slug}.jsonl"
    serial = (boards or {}).get("motor", {}).get("serial")
    if not isinstance(serial, int):
        return by_port
    path = state / "stairbot" / f"journal-motor-{serial}.jsonl"
    if not path.exists() and _motor_serial(by_port) == serial:
        return by_port  # kept by the port, as stairbot did before: still this robot's
    return path


def _motor_serial(path: Path) -> object:
    """The motor board's serial number in the start record of the journal at
    ``path`` (None: no journal there, or none it names)."""
    try:
        if not path.is_file():  # nothing there, or no journal (a FIFO would block)
            return None
        with open(path, "rb") as f:
            first = json.loads(f.readline(MAX_LINE))
        return first["boards"]["motor"]["serial"]
    except (OSError, ValueError, RecursionError, KeyError, TypeError):
        return None


def journal_path(url: str, given: str | None,
                 boards: Mapping[str, Mapping[str, int]] | None = None) -> Path | None:
    return Path(given) if given else default_path(url, boards)


def session_journal(session: RobotSession) -> Path | None:
    """The default journal of the robot ``session`` opened."""
    return default_path(session.url, board_identity(session.robot))


def start_journal(path: Path | None, url: str, session: RobotSession, config: RobotConfig,
                  scenario: str, mode: Mode) -> JournalWriter | None:
    """A fresh journal for a new run (None: none kept); a journal at ``path``
    whose run on boards did not finish is set aside first, not overwritten.
    JournalError when it cannot be written."""
    if path is None:
        return None
    if unfinished(path) is not None:
        set_aside(path)
    writer = JournalWriter(path, fresh=True)
    writer.start(url=url, config=config.source, config_sha256=config_digest(config),
                 scenario=scenario, mode=mode.value, boards=board_identity(session.robot),
                 time_s=session.clock.now())
    return writer


def _last_record(path: Path) -> dict[str, object] | None:
    """The journal's last whole line as a record (None: none, or not one)."""
    try:
        with open(path, "rb") as f:
            size = f.seek(0, os.SEEK_END)
            f.seek(max(0, size - MAX_LINE))
            tail = f.read(MAX_LINE)
    except OSError:
        return None
    whole = tail.rpartition(b"\n")[0].rpartition(b"\n")[2]
    try:
        rec = json.loads(whole)
    except (ValueError, RecursionError):
        return None
    return rec if isinstance(rec, dict) else None


def unfinished(path: Path) -> str | None:
    """What a new run at ``path`` would lose: None when there is no journal
    there (or no regular file: it is not read), or its run ended (its last
    line an end that is not resumable), or ran in the simulation; else a few
    words on the run (where it stopped, or why its journal cannot be read)."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return None  # nothing there, or not a journal (the writer says why)
    except (OSError, ValueError):
        return None
    last = _last_record(path)
    if last is not None and last.get("kind") == "end" and not last.get("resumable"):
        return None
    try:
        state = read_journal(path)
    except JournalError as exc:
        return f"a run that did not finish, whose journal cannot be resumed ({exc.problem})"
    if not str(state.start.get("url")).startswith(("serial://", "can://")):
        return None
    where = describe(state)[1].removeprefix("the host stopped in: ")
    return f"run {str(state.start.get('run_id'))[:8]}, stopped in {where}"


def set_aside(path: Path) -> Path:
    """Rename the journal at ``path`` (and its mark) beside it, under a name
    not taken (``journal.discarded.jsonl``, ``journal.discarded-1.jsonl``,
    ...); the new name.  JournalError when it cannot be renamed."""
    aside = Path(unused_path(str(path.with_name(f"{path.stem}.discarded{path.suffix}"))))
    try:
        os.rename(path, aside)
        if mark_path(path).exists():
            os.rename(mark_path(path), mark_path(aside))
    except OSError as exc:
        raise JournalError(str(path), None, f"cannot set the journal aside as {aside}: "
                           f"{exc.strerror or exc}") from None
    return aside


@dataclass
class Resumed:
    controller: Controller
    journal: JournalWriter
    state: JournalState


@dataclass
class ResumePlan:
    """A run the journal says can go on, checked against the boards; nothing
    has moved yet.  ``lines``: where the robot believes it is;
    ``context``: the journal's last context, restored and checked."""

    path: Path
    state: JournalState
    lines: list[str]
    context: Context


def plan_resume(path: Path | None, url: str, session: RobotSession,
                config: RobotConfig) -> ResumePlan:
    """Check the journal's run against the boards and say where the robot
    believes it is (the checks of ``stairbot run --resume``: the journal
    whole and well formed, the run did not end, the boards are the
    journal's and did not restart, the same URL, the same config, a context
    that restores within the config's bounds).  JournalError or
    ResumeRefused (one line) otherwise.  Moves nothing, clears nothing."""
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
    context = restored_context(state, float(state.last["time_s"]),
                               config.algorithm.max_steps)
    if isinstance(robot, HasAttitude):
        check_attitude(url, robot.attitude(), config)
    lines = describe(state)
    if awaits_consent(context) and context.limp is not None:
        lines.append(f"a sensor was lost ({', '.join(context.limp.lost)}) in "
                     f"{context.limp.where}: resuming lets the robot limp home on the "
                     "sensors that remain")
    latched = _latches(robot)
    if latched:
        lines.append(f"the boards hold latches ({len(latched)} board(s)); resuming "
                     "clears them")
    return ResumePlan(path, state, lines, context)


def _latches(robot: Robot) -> Mapping[int, int]:
    """The latches the robot's boards held when the host opened them (none
    for a robot without boards)."""
    return robot.latched if isinstance(robot, HoldsLatches) else {}


def check_attitude(url: str, imu: Imu | None, config: RobotConfig) -> None:
    """ResumeRefused when the IMU reads the robot pitched or rolled beyond the
    config's limits ([safety] max_pitch_deg, max_roll_deg): it tipped, or
    fell, while no host watched it, and where the journal left it no longer
    says where it is; or when its reading is older than the tilt watch
    allows ([safety] imu_max_age_s): what it says is not the robot now.  No
    IMU at all: nothing to check."""
    if imu is None:
        return
    s = config.safety
    if imu.age_s > s.imu_max_age_s:
        raise ResumeRefused(
            f"{url}: the IMU's reading is {imu.age_s:.2f} s old (limit {s.imu_max_age_s:g} "
            "s): whether the robot tipped since the host stopped cannot be told; look at "
            "the robot, bring it to the floor by hand and start a new run")
    for name, value, limit in (("pitch", imu.pitch_deg, s.max_pitch_deg),
                               ("roll", imu.roll_deg, s.max_roll_deg)):
        if abs(value) > limit:
            raise ResumeRefused(
                f"{url}: the IMU reads {name} {value:+.1f}° (limit ±{limit:g}°): the robot "
                "tipped since the host stopped; bring it to the floor by hand and start a "
                "new run")


def carry_on(plan: ResumePlan, session: RobotSession, config: RobotConfig,
             sink: EventSink, limp_home: bool = False) -> Resumed:
    """Once the operator has confirmed ``plan``: the restored controller
    (``limp_home``: consent to limp home if a sensor is lost) and the
    journal, appended to (its resume record written), and only then the
    boards' latches cleared."""
    robot = session.robot
    now = session.clock.now()
    state = plan.state
    ctx = restored_context(state, now, config.algorithm.max_steps)
    mode = Mode(state.start.get("mode", Mode.FULL.value))
    controller = Controller(config, sink, mode, context=ctx, limp_home=limp_home)
    writer = JournalWriter(plan.path, fresh=False, tail=state.tail)
    try:
        writer.resume(str(state.start["run_id"]), board_identity(robot), now)
        if _latches(robot) or robot.estopped:
            robot.clear()
    except BaseException:
        writer.close()
        raise
    return Resumed(controller, writer, state)


def resume(path: Path | None, url: str, session: RobotSession, config: RobotConfig,
           sink: EventSink, *, yes: bool, out: TextIO,
           confirm: Callable[[str], bool] = lambda _question: False) -> Resumed:
    """Check the journal's run against the boards, say where the robot
    believes it is, and -- once the operator confirms (``yes``, or
    ``confirm`` answers the question true; ``stairbot run`` asks on the
    terminal) -- clear the boards' latches and hand back the restored
    controller (``yes`` also consents to limp home if a sensor is lost).
    ResumeRefused (one line) otherwise; nothing has moved then."""
    plan = plan_resume(path, url, session, config)
    for line in plan.lines:
        print(f"resume: {printable(line)}", file=out)
    out.flush()
    home = awaits_consent(plan.context)
    question = ("Look at the robot: does it stand where the lines above say?  Resume and "
                + ("let it limp home? [y/N] " if home else "let it move? [y/N] "))
    if not yes and not confirm(question):
        raise NotConfirmed("not resumed: no confirmation (answer y on a terminal, or add "
                           "--yes); nothing moved")
    # confirming the resume of a degraded stop is consenting to limp home
    return carry_on(plan, session, config, sink, limp_home=yes or home)
