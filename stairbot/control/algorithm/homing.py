"""Descent 7: back to the start position, turning back first to the headings
the robot crossed the floor and began the program with.
"""

from __future__ import annotations

import math

from stairbot.control.algorithm import blind, motion
from stairbot.control.algorithm.modes import Outcome, Purpose
from stairbot.control.algorithm.moves import (
    checked_first,
    reading_drive,
    turns_drive,
)
from stairbot.control.algorithm.phase import (
    ENDED,
    FAILED,
    FAULT,
    Exit,
    PhaseDef,
    Step,
    Tick,
    calibrate,
    end,
    go,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.squaring import HEADING_TOLERANCE_RAD, heading_off_rad
from stairbot.control.algorithm.texts import descent as say
from stairbot.control.algorithm.work import (
    DriveWork,
)

P = Phase
FLOW = "descent"


# -- descent 7: back to the start ----------------------------------------------------------------
def _on_the_floor_all_along(t: Tick) -> bool:
    """No step was climbed: the wheels drove only on the floor, and their
    odometer knows the way back better than a reading of stairs it refused
    (a cone may see over low risers there)."""
    return t.ctx.number_of_steps == 0 and t.ctx.start.wheel is not None


def _by_the_odometer(t: Tick) -> bool:
    """Descent 7 goes by the odometer alone: no step was climbed
    (:func:`_on_the_floor_all_along`), or the front pair is distrusted
    (:mod:`~stairbot.control.algorithm.blind`: its two sensors disagree and
    nothing names which reads wrong; on the floor, all wheels down, the
    odometer's drift of a centimetre or so a step climbed and descended is
    all it costs)."""
    return _on_the_floor_all_along(t) or (blind.front_unusable(t.ctx)
                                          and t.ctx.start.wheel is not None)


def _finish_turns(t: Tick) -> float:
    """How far descent 7 backs while the front pair cannot measure: by the
    odometer if no step was climbed, or the front pair is distrusted; else
    from the riser (approach_gap away) to the start reading -- not the seed's
    NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH, within which a pair that reads
    only from 10 cm (a Sharp) may not yet measure, which would stop the
    robot 0.4 m short."""
    start, cfg = t.ctx.start, t.cfg
    if _by_the_odometer(t):
        assert start.wheel is not None
        return max(0.0, motion.wheel_position(t.snap) - start.wheel)
    if start.reading is None:
        return cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
    return cfg.wheel_turns(max(0.0, start.reading - cfg.algorithm.approach_gap))


def _closed_in_turns(t: Tick) -> float:
    """How far the first calibration closed in before it squared up (turns)."""
    start = t.ctx.start
    if start.wheel is None or start.home_wheel is None:
        return 0.0
    return max(0.0, start.wheel - start.home_wheel)


def _at_start_position(t: Tick, _w: DriveWork) -> Step:
    """At the start position (where the first calibration squared up).  If it
    closed in first, the way home retraces it: turn back to the heading the
    program began with (segments 1 and 3 lifted, as calibration turns), then
    back the distance."""
    home_twist = t.ctx.start.home_twist
    if _closed_in_turns(t) <= motion.WHEEL_DONE:
        return end(Outcome.COMPLETED, say.BACK_AT_START)
    if home_twist is None or abs(heading_off_rad(t, home_twist)) <= HEADING_TOLERANCE_RAD:
        return go("closed_in")
    return calibrate("off_start_heading", Purpose.HOME, home_twist)


def _floor_heading(t: Tick, _w: DriveWork) -> Step | None:
    """Before backing to the start position: turn back (once) to the heading
    the robot crossed the floor with, where the first calibration left it
    (climb_twist[0]), if the odometer says it is further off than
    HEADING_TOLERANCE_RAD.  Descent 1 squared up to the first riser again, and
    a start squared up far away within a noisy pair's tolerance may differ
    from that by degrees: backing the whole way to the start on the squarer
    heading would put the robot centimetres to the side of it."""
    ctx = t.ctx
    floor = ctx.climb_twist[0]
    if ctx.descent.turned_back or floor is None:
        return None
    ctx.descent.turned_back = True
    off = heading_off_rad(t, floor)
    if abs(off) <= HEADING_TOLERANCE_RAD:
        return None
    t.say(say.off_floor_heading(off), off_deg=math.degrees(off))
    return calibrate("off_floor_heading", Purpose.FLOOR, floor)


_finish = reading_drive(-1, lambda t: None if _by_the_odometer(t) else t.ctx.start.reading,
                        _finish_turns, _at_start_position)


def _finishing(t: Tick, w: DriveWork) -> Step:
    """Descent 7's drive; from the tick the front pair is distrusted on, to
    the start position by the odometer (the target its readings gave is
    dropped)."""
    if w.target_reading is not None and _by_the_odometer(t):
        assert t.ctx.start.wheel is not None
        w.target_reading, w.target_wheel = None, t.ctx.start.wheel
        t.say(say.BY_THE_ODOMETER)
    return _finish[1](t, w)
FINISH = PhaseDef(
    P.DESCENT_FINISH, "descent 7 — finish: back off to the start position", FLOW,
    checked_first(_floor_heading, _finishing), DriveWork, enter=_finish[0], watches="front",
    on={ENDED: Exit(P.DONE, "reads the start reading (or turns made; with no step climbed, or "
                            "the front pair distrusted: "
                            "back by the odometer to the start position)"),
        "off_floor_heading": Exit(P.CAL_LIFT, "turned from the heading it crossed the floor "
                                              "with: lift to turn back to it"),
        "off_start_heading": Exit(P.CAL_LIFT, "the first calibration closed in, turned from "
                                              "the heading the program began with: lift to "
                                              "turn back"),
        "closed_in": Exit(P.DESCENT_FINISH_FLOOR, "the first calibration closed in; turned "
                                                  "within HEADING_TOLERANCE_RAD of the heading "
                                                  "it began with"),
        FAILED: Exit(P.ERROR, FAULT)})


_floor = turns_drive(-1, _closed_in_turns,
                     lambda _t, _w: end(Outcome.COMPLETED, say.BACK_WHERE_BEGAN))
FINISH_FLOOR = PhaseDef(
    P.DESCENT_FINISH_FLOOR, "descent 7 — finish: back the distance calibration closed in",
    FLOW, _floor[1], DriveWork, enter=_floor[0],
    on={ENDED: Exit(P.DONE, "turns made: where the program began"),
        FAILED: Exit(P.ERROR, FAULT)})
