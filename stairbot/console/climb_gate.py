"""Whether the robot may stand part way up the stairs, and so must not start
a new run from where it stands: a new run squares up to the first riser and
drives at it, and with a segment on a step the wheels then grind against
the riser until a phase times out.

The robot is *mid-climb* after a run that did not complete and had got past
calibration (its last phase was in the ascent or the descent).  The console
knows it from its own last run, and -- for boards on a wire -- from the run
journal (:mod:`stairbot.run.journal`), which outlives the console: a console
that crashed, or was killed, mid-run leaves the journal behind, and the next
one reads it when it opens the same boards.  From there only two ways lead
on: resuming the journal's run (boards only, with the checks of ``stairbot
run --resume``), or the operator's word that the robot is back at the start.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from stairbot.control.algorithm.phases import BY_VALUE
from stairbot.errors import StairbotError
from stairbot.run.journal import read_journal
from stairbot.run.resume import describe
from stairbot.run.runner import RunResult

CLIMB_FLOWS = ("ascent", "descent", "landing")


HOME = ("completed", "came_home_degraded")
"""The outcomes that end a run where it began (a limp home's too)."""


@dataclass(frozen=True)
class MidClimb:
    """Why the robot is believed to stand part way up: ``lines`` for the
    operator (where it stopped, the steps, the last command)."""

    lines: tuple[str, ...]


def after_run(result: RunResult, last_flow: str, last_label: str) -> MidClimb | None:
    """Mid-climb after a run that ended with ``result`` whose last phase
    before the end was ``last_label`` in ``last_flow``; None when it completed
    or never left calibration."""
    if result.outcome in HOME or last_flow not in CLIMB_FLOWS:
        return None
    why = f": {result.error}" if result.error else ""
    return MidClimb((f"the last run ended ({result.outcome}{why})",
                     f"in: {last_label}",
                     f"steps climbed {result.steps_climbed}, descended "
                     f"{result.steps_descended}"))


def from_journal(path: Path | None, boards: dict[str, dict[str, int]] | None) -> MidClimb | None:
    """Mid-climb by the journal at ``path`` for these ``boards`` (their
    identity now): its last run did not complete and its last tick was not
    in calibration (a tick that ended the run in an error or a wait says
    "error" or "paused", which could be anywhere: it counts, on the safe
    side).  A journal of other boards (other serial numbers) says nothing of
    these; boards that restarted since are still where they were, so they
    count."""
    if path is None or boards is None or not path.exists():
        return None
    try:
        state = read_journal(path)
    except StairbotError:
        return None  # unreadable: nothing to go by (resuming would say why)
    was = state.boards if isinstance(state.boards, dict) else {}
    for name, now in boards.items():
        then = was.get(name)
        if isinstance(then, dict) and then.get("serial") != now.get("serial"):
            return None
    if state.end is not None and state.end.get("outcome") in HOME:
        return None
    phase = BY_VALUE.get(str(state.last.get("phase")))
    if phase is None or phase.flow == "calibration":
        return None
    return MidClimb(tuple(describe(state)))
