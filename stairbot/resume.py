"""Carrying on a run that a host left unfinished (``stairbot run --resume``).

What the journal (:mod:`stairbot.journal`) says of the last run is checked
against the boards as they are now, before anything moves:

* a run that ended (completed, refused, stopped or failed, with its end
  record) has nothing to resume;
* the boards must be the journal's (the same serial numbers) and must have
  run on since (uptime no lower than the journal's last): a board that
  restarted began its turn counters again at 0, and the robot's position by
  them -- what every phase's motion targets are -- is lost;
* the simulation (``sim://``) cannot be resumed: its world ended with the
  host that ran it.

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

from stairbot.algorithm.context import Context
from stairbot.algorithm.phases import BY_VALUE
from stairbot.errors import StairbotError
from stairbot.journal import JournalState


class ResumeRefused(StairbotError):
    """The journal's run cannot be carried on (one line says why)."""


def check(state: JournalState, url: str, boards: dict[str, dict[str, int]] | None) -> None:
    """ResumeRefused unless the journal's run can go on on the boards at ``url``
    (``boards``: their identity now, None for the simulation)."""
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
    for name, now in sorted(boards.items()):
        then = was.get(name)
        if not isinstance(then, dict):
            raise ResumeRefused(f"{where}: the journal does not know the {name} board")
        if then.get("serial") != now["serial"]:
            raise ResumeRefused(
                f"{url}: the {name} board is serial {now['serial']}, the journal's was "
                f"{then.get('serial')}: not the robot of {where}")
        if now["uptime_ms"] < int(then.get("uptime_ms", 0)):
            raise ResumeRefused(
                f"{url}: the {name} board restarted since the journal's last tick (up "
                f"{now['uptime_ms'] / 1000:.1f} s, then {int(then['uptime_ms']) / 1000:.1f} s): "
                "its turn counters began again at 0, so the robot's position by them is "
                "lost; bring the robot to the floor by hand and start a new run")


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


def restored_context(state: JournalState, now_s: float) -> Context:
    """The journal's last context, its timers moved on by the time between the
    journal's last tick and ``now_s`` (the robot's clock now)."""
    if state.context is None:
        raise ResumeRefused(f"{state.path}: no context to resume from")
    data: dict[str, Any] = copy.deepcopy(state.context)
    shift = now_s - float(state.last.get("time_s", now_s))
    for key in _TIMES:
        if isinstance(data.get(key), int | float):
            data[key] = float(data[key]) + shift
    work = data.get("work")
    if isinstance(work, dict) and isinstance(work.get("still_since"), int | float):
        work["still_since"] = float(work["still_since"]) + shift
    return Context.from_dict(data, state.path)
