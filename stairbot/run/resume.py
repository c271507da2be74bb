"""Carrying on a run that a host left unfinished (``stairbot run --resume``).

The journal (:mod:`stairbot.run.journal`) has been read and checked whole
(:func:`~stairbot.run.journal_read.read_journal`); what it says of the run is
checked here against the boards as they are now and the robot's config,
before anything moves -- before the boards' latches are cleared:

* a run that ended (completed, refused, stopped or failed, with its end
  record) has nothing to resume;
* the simulation (``sim://``) cannot be resumed: its world ended with the
  host that ran it;
* the robot's URL must be the journal's (the same scheme and port, or
  interface and channel; its options may differ);
* the boards must be the journal's (the same boards by name and serial
  number), still running since: the same boot id where the boards give one
  (a journal with a boot id for boards that give none, or the other way
  round, is of another firmware or host version and is refused), and an
  uptime no lower than the journal's last -- a board that restarted began
  its turn counters again at 0, and the robot's position by them, what
  every phase's motion targets are, is lost;
* the context restores (:meth:`Context.from_dict`) and its steps climbed are
  within the config's ``max_steps``.

:func:`describe` says where the robot believes it is, for the operator to
compare with what they see; only after their confirmation does the run go
on (:func:`restored_context`), from the last context the journal holds, its
timers moved on by the time the host was away (so that the downtime does
not count against a phase's timeout).  Refusals are :class:`ResumeRefused`,
one line each.
"""

from __future__ import annotations

import copy
from typing import Any

from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.phases import BY_VALUE
from stairbot.errors import InputError, StairbotError
from stairbot.run.journal import JournalError, JournalState


class ResumeRefused(StairbotError):
    """The journal's run cannot be carried on (one line says why)."""


def same_robot_url(a: str, b: str) -> bool:
    """Whether two robot URLs name the same boards: the same scheme and port
    (``serial:///dev/ttyUSB0``) or interface and channel (``can://socketcan/can0``);
    their options (``?baud=...``) may differ."""
    return _where(a) == _where(b)


def _where(url: str) -> str:
    return url.split("?", 1)[0].split("#", 1)[0].rstrip("/")


def check(state: JournalState, url: str, boards: dict[str, dict[str, int]] | None) -> None:
    """ResumeRefused unless the journal's run can go on on the boards at ``url``
    (``boards``: their identity now, None for the simulation).  Checks, in
    order: the run did not end, it is not a simulation, the journal has a
    context, the boards are the journal's and did not restart, the URL."""
    where = state.path
    if state.end is not None and not state.end.get("resumable"):
        raise ResumeRefused(f"{where}: the last run ended ({state.end.get('outcome')}"
                            f"{': ' + str(state.end['error']) if state.end.get('error') else ''})"
                            ": nothing to resume")
    if boards is None:
        raise ResumeRefused(f"{url}: a simulation cannot be resumed: its world ended with "
                            "the host that ran it")
    if state.context is None:
        raise ResumeRefused(f"{where}: the run stopped before its first tick was written: "
                            "start a new run")
    was = state.boards if isinstance(state.boards, dict) else {}
    if set(was) != set(boards):
        raise ResumeRefused(f"{url}: the boards are {', '.join(sorted(boards)) or 'none'}, "
                            f"the journal's were {', '.join(sorted(was)) or 'none'}: not the "
                            f"robot of {where}")
    for name, now in sorted(boards.items()):
        _same_board(name, was[name], now, url, where)
    then_url = str(state.start.get("url"))
    if not same_robot_url(then_url, url):
        raise ResumeRefused(f"{url}: the journal's run was on {then_url}, not on "
                            f"{_where(url)}: resume it on {then_url} (or pass the journal "
                            "of this robot)")


def _same_board(name: str, then: dict[str, int], now: dict[str, int], url: str,
                where: str) -> None:
    """ResumeRefused unless the ``name`` board is the journal's, running since."""
    lost = ("its turn counters began again at 0, so the robot's position by them is "
            "lost; bring the robot to the floor by hand and start a new run")
    if then.get("serial") != now.get("serial"):
        raise ResumeRefused(
            f"{url}: the {name} board is serial {now.get('serial')}, the journal's was "
            f"{then.get('serial')}: not the robot of {where}")
    if ("boot" in then) != ("boot" in now):
        has, lacks = ("the journal", "the board") if "boot" in then else \
            ("the board", "the journal")
        raise ResumeRefused(
            f"{url}: {has} gives the {name} board's boot id and {lacks} does not: the "
            f"journal {where} is of another firmware or host version, and whether the board "
            "restarted since cannot be told; bring the robot to the floor by hand and "
            "start a new run")
    if "boot" in then and then["boot"] != now["boot"]:
        raise ResumeRefused(
            f"{url}: the {name} board restarted since the journal (boot id {then['boot']}, "
            f"then {now['boot']}): {lost}")
    if now["uptime_ms"] < int(then.get("uptime_ms", 0)):
        raise ResumeRefused(
            f"{url}: the {name} board restarted since the journal's last tick (up "
            f"{now['uptime_ms'] / 1000:.1f} s, then {int(then['uptime_ms']) / 1000:.1f} s): "
            f"{lost}")


def describe(state: JournalState) -> list[str]:
    """Where the robot believes it is, in lines for the operator."""
    ctx = state.context or {}
    phase = BY_VALUE.get(str(state.last.get("phase")))
    label = phase.label if phase is not None else str(state.last.get("phase"))
    resumed = f", resumed {state.resumes} time(s) before" if state.resumes else ""
    lines = [
        f"run {state.start.get('run_id', '?')[:8]} of {state.start.get('scenario')} on "
        f"{state.start.get('url')}{resumed}",
        f"the host stopped in: {label} (at {float(state.last.get('time_s', 0.0)):.2f} s)",
        f"steps climbed {ctx.get('number_of_steps', 0)}, descended "
        f"{ctx.get('steps_descended', 0)}"
        + (f"; the ascent ended: {ctx['ascent_end']}" if ctx.get("ascent_end") else ""),
    ]
    command = state.last.get("command")
    if isinstance(command, dict):
        moving = {k: v for k, v in command.items() if abs(float(v)) > 1e-9}
        lines.append("last command: " + (", ".join(f"{k} {float(v):+.2f} turn/s"
                                                   for k, v in sorted(moving.items()))
                                         if moving else "every motor stopped"))
    if state.last.get("estopped"):
        lines.append("the emergency stop was latched")
    if state.end is not None:
        lines.append(f"the run stopped: {state.end.get('error')}")
    return lines


_TIMES = ("phase_started_s", "pause_started_s")
_WORK_TIMES = ("still_since", "blocked_since")
"""A phase's own timers (its work's): standing since, blocked since."""


def moved_on(context: dict[str, Any], shift: float) -> dict[str, Any]:
    """A copy of a saved context (:meth:`Context.to_dict`) with its timers
    moved on by ``shift`` seconds: the time the program stood still, which
    must not count against a phase's timeout."""
    data: dict[str, Any] = copy.deepcopy(context)
    for key in _TIMES:
        if isinstance(data.get(key), int | float):
            data[key] = float(data[key]) + shift
    work = data.get("work")
    if isinstance(work, dict):
        for key in _WORK_TIMES:
            if isinstance(work.get(key), int | float):
                work[key] = float(work[key]) + shift
    return data


def restored_context(state: JournalState, now_s: float, max_steps: int | None = None
                     ) -> Context:
    """The journal's last context, its timers moved on by the time between the
    journal's last tick and ``now_s`` (the robot's clock now).  ResumeRefused
    when there is none; JournalError (naming the file and the field) when it
    does not restore, or its steps climbed are more than ``max_steps`` (the
    config's)."""
    if state.context is None:
        raise ResumeRefused(f"{state.path}: no context to resume from")
    data = moved_on(state.context, now_s - float(state.last.get("time_s", now_s)))
    try:
        ctx = Context.from_dict(data, "the context")
    except InputError as exc:
        raise JournalError(state.path, f"the last context: {exc.field}", exc.problem) from None
    if max_steps is not None and ctx.number_of_steps > max_steps:
        raise JournalError(state.path, "the last context: number_of_steps",
                           f"{ctx.number_of_steps} is out of range; allowed: 0 to the "
                           f"config's max_steps, {max_steps}")
    return ctx
