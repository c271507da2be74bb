"""Ascent 4 of the first step with the front pair distrusted
(:mod:`~stairbot.control.algorithm.blind`): the step in progress undone by the
odometer, with no front reading.  Not in the seed.

The whole robot stands on the floor, segment 1 lifted over the first tread
(ascent 3 lifted it there in front of the riser, and ascent 4 drove it on).
Finishing the step would go by length_of_next_step, which the front pair
measured, and the way down from it by the tab it would read: neither is
trusted.  So the robot backs by the odometer to where ascent 4 began
(segment 1 clear of the riser again, where it rose), lowers segment 1 by
the turns ascent 3 lifted it (ascent 3's obstacle phase), and goes back to
the start by the odometer (descent 7, as when no step was climbed).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from stairbot.control.algorithm import blind, lost, motion
from stairbot.control.algorithm.families import LiftFirst
from stairbot.control.algorithm.phase import Exit, PhaseDef, Step, Tick, go, stay
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.texts import limp as say
from stairbot.control.algorithm.work import DriveWork
from stairbot.hardware import MotorId

UNDO = "limp_undo"
"""Ascent 4's outcome once it has backed segment 1 off the first step."""
EXITS = {UNDO: Exit(Phase.ASCENT_LOWER_OBSTACLE,
                    lost.LIMP + ", the front pair distrusted on the first step: backed by "
                                "the odometer to where ascent 4 began, lower segment 1")}


def undoing(t: Tick) -> bool:
    """Whether ascent 4 undoes the step: the first, the front pair distrusted."""
    return t.ctx.number_of_steps == 0 and blind.front_unusable(t.ctx)


def undo(t: Tick, w: DriveWork) -> Step:
    """Ascent 4's step while :func:`undoing`: back to the drive's entry by the
    odometer, then on to lower segment 1 by what ascent 3 lifted it
    (``number_of_turns_for_step_height``: ascent 4 moves no lift)."""
    if t.ctx.ascent_end is None:
        lost.limping(t)  # the ascent ends here, and says so
        t.say(say.UNDO_BY_THE_ODOMETER)
    remaining = motion.wheel_position(t.snap) - w.entry_wheel
    if remaining <= motion.WHEEL_DONE:
        floor = t.snap.turns(MotorId.MTF) - t.ctx.number_of_turns_for_step_height
        return go(UNDO, begin=LiftFirst(return_mtf=floor))
    return stay(motion.drive(t.cfg, -1, remaining))


def with_undo(drive_first: PhaseDef[Any]) -> PhaseDef[Any]:
    """Ascent 4's record, its step undoing the first step while
    :func:`undoing` (and the outcome that leads on from it)."""
    step = drive_first.step
    assert step is not None

    def first(t: Tick, w: Any) -> Step:
        return undo(t, w) if undoing(t) else step(t, w)

    return replace(drive_first, step=first, on={**drive_first.on, **EXITS})
