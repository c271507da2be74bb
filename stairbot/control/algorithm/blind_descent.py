"""Descent 1's calibration with the front pair distrusted
(:mod:`~stairbot.control.algorithm.blind`).  Not in the seed.

Seeing, descent 1 turns back by the odometer to the heading the step was
climbed with, then squares up to the riser with the front pair (case 2),
so that backing up to the edge by the tab goes straight back.  Blind, the
turn back by the odometer is all of it: the heading the step was climbed
with is the one calibration squared to the riser on the way up, and the
back pair's edge watch, which backs the robot up to the edge
(:func:`~stairbot.control.algorithm.back_off.edge_search_m`'s climbed-step
form), stops it if one back sensor reads the drop far before the other
(turned too far from the edge, MAX_EDGE_YAW_RAD).
"""

from __future__ import annotations

import math

from stairbot.control.algorithm import blind
from stairbot.control.algorithm.modes import Purpose
from stairbot.control.algorithm.phase import Step, Tick, go
from stairbot.control.algorithm.squaring import HEADING_TOLERANCE_RAD, heading_off_rad
from stairbot.control.algorithm.texts import calibration as say
from stairbot.control.algorithm.texts import limp as say_limp


def check(t: Tick) -> Step | None:
    """Descent 1's calibration check while the front pair is distrusted: turn
    back to the heading the step was climbed with (once a step, if the
    odometer says it is further off than HEADING_TOLERANCE_RAD), then on to
    back up to the edge, squared by the odometer.  None: not blind, or not
    descent 1 (the check reads the pair)."""
    ctx, cal = t.ctx, t.cal
    if cal.purpose is not Purpose.DESCENT or not blind.front_unusable(ctx):
        return None
    climbed = ctx.climb_twist[t.descent_index]
    assert climbed is not None  # blind.needs_no_front: known, or the robot stays stopped
    off = heading_off_rad(t, climbed)
    if not ctx.descent.turned_back and abs(off) > HEADING_TOLERANCE_RAD:
        cal.turn_to = climbed
        ctx.descent.turned_back = True  # once a step
        t.say(say.off_climb_heading(t.descent_index, off), off_deg=math.degrees(off))
        return go("off_climb_heading")
    cal.case = None
    t.say(say_limp.squared_by_odometer(t.descent_index, off), off_deg=math.degrees(off))
    return go("square_to_descend")
