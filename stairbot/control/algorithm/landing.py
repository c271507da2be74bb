"""Quarter-turn landings (the seed's extension 1): look sideways for the next
flight, turn 90° towards it, climb on; on the way down, turn back.

The seed turns one back sensor to look parallel to the floor; this robot
has a side pair, SSR and SSL, on segment 3, looking right and left.  A
landing shows itself as the seed's wall at the top: ascent 3 lifts segment
1 its whole stroke in front of the wall ahead and still sees it (an
obstacle).  With ``[algorithm] landings`` the robot then, before it turns
back down:

1. *scans* (landing 1): lifts segment 3 its whole stroke with the side pair
   looking out.  A side that, standing at the top, reads on past what it
   saw below by SIDE_JUMP_M, having first done so no lower than the lowest
   riser the robot climbs, is the next flight's first riser, if its reading
   moved past while the beam rose and, segment 3 lowered again, reads what it
   read there before the lift (a sensor whose reading moved, not the beam's
   view, would send the robot into a wall); any other is a wall.  The
   readings before the lift say how far the sides are.
2. *decides*: no side open, the ascent ends as at a wall (``landing_closed``);
   a landing too small for the robot to turn in (its turning circle,
   TURN_ROOM_MARGIN clear of the walls, the riser and the edge behind), it
   ends too (``landing_too_small``) -- both then descend home as from a wall.
3. *centres* (landing 2): backs from the wall ahead to the landing's middle,
   by the front pair, so that the turning circle clears the wall and the
   edge behind it;
4. *turns* 90° towards the open side by calibration's turn (segments 1 and 3
   lifted, segment 2's wheels, by the odometer), and calibrates on the next
   flight's first riser: the ascent goes on, counting steps on.

The descent mirrors it: having come down the second flight's first step, the
robot backs to where it turned (landing 3), turns back to the heading it
came up with, and descends the first flight (descent 1's calibration on the
wall ahead, then the edge its back pair finds).  One landing a climb.
"""

from __future__ import annotations

import math
from typing import Any

from stairbot.control.algorithm import motion
from stairbot.control.algorithm.families import LandingTurn
from stairbot.control.algorithm.landing_scan import LEFT, RIGHT, SCAN, recheck
from stairbot.control.algorithm.modes import AscentEnd, Purpose
from stairbot.control.algorithm.moves import lift, reading_drive
from stairbot.control.algorithm.phase import (
    FAILED,
    FAULT,
    Exit,
    PhaseDef,
    Step,
    Tick,
    calibrate,
    go,
)
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.texts import landing as say
from stairbot.control.algorithm.work import DriveWork, LiftWork, RecheckWork
from stairbot.hardware import MotorId
from stairbot.inputs.config import RobotConfig

P = Phase
FLOW = "landing"

TURN_ROOM_MARGIN = 0.03
"""The robot turns on a landing only if its turning circle stays this far
(m) from the walls, the next flight's riser and the edge behind it."""
WHEEL_WIDTH = 0.01
"""How far a wheel stands out past the track on each side, m: the robot's
width is track_width plus twice this."""
DEPTH_MARGIN = 0.01
"""The landing's depth is taken this much less than it was measured, m."""
TAB_PAST_EDGE_M = 0.02
"""Where ascent 7 read tab_length_to_edge, segment 1's front face stood
LENGTH_OF_FIRST_MODULE + LENGTH_OF_SECOND_MODULE less about this past the
edge (segment 2's rear wheels just onto the step: ascent 6 ends at
length_of_next_step less the two, and a 0.28 m tread read tabs of 0.145 to
0.150 m), m."""
def half_width(cfg: RobotConfig) -> float:
    """Half the robot's width, wheels included."""
    return cfg.geometry.track_width / 2.0 + WHEEL_WIDTH


def centre_to_front(cfg: RobotConfig) -> float:
    """From segment 2's centre (where the robot turns) to segment 1's front face."""
    g = cfg.geometry
    return g.LENGTH_OF_FIRST_MODULE + g.LENGTH_OF_SECOND_MODULE / 2.0


def turning_radius(cfg: RobotConfig) -> float:
    """The farthest corner of the robot from segment 2's centre."""
    g = cfg.geometry
    reach = max(centre_to_front(cfg), g.LENGTH_OF_SECOND_MODULE / 2.0 + g.LENGTH_OF_THIRD_MODULE)
    return math.hypot(reach, half_width(cfg))


def turn_room_m(cfg: RobotConfig) -> float:
    """How far every wall, riser and edge must be from the centre to turn."""
    return turning_radius(cfg) + TURN_ROOM_MARGIN


def can_scan(t: Tick, wall_ahead: bool) -> bool:
    """A wall ahead at the top of a step (``wall_ahead``: too high to see
    over; a tread too short to stand on is no landing to turn on), on a robot
    that turns on landings, with no landing scanned yet: look sideways before
    turning back down."""
    ctx, cfg = t.ctx, t.cfg
    return (cfg.algorithm.landings and cfg.sensors.has_side_pair and ctx.number_of_steps > 0
            and wall_ahead and not ctx.landing.seen and not ctx.from_top)


def _turn(t: Tick) -> LandingTurn:
    return t.ctx.family_of(LandingTurn)


# -- landing 1: lower, decide ------------------------------------------------------------------
def _lower_deltas(t: Tick, w: LiftWork) -> dict[MotorId, float]:
    return {MotorId.MTB: _turn(t).return_mtb - w.entry_mtb}


def _decide(t: Tick, _w: LiftWork) -> Step:
    landing, cfg, turn = t.ctx.landing, t.cfg, _turn(t)
    right, left = landing.right_m, landing.left_m
    opened = turn.open
    if not opened:
        return _refuse(t, AscentEnd.LANDING_CLOSED, say.no_next_flight(right, left))
    room = turn_room_m(cfg)
    depth = landing_depth(t)
    if depth is None:
        return _refuse(t, AscentEnd.LANDING_TOO_SMALL, say.DEPTH_NOT_MEASURED)
    turn.depth_m = depth
    short = [(name, have) for name, have in
             (("right", right), ("left", left), ("depth/2", depth / 2.0))
             if have is None or have < room]
    if short:
        return _refuse(t, AscentEnd.LANDING_TOO_SMALL,
                       say.too_small(room, turning_radius(cfg), TURN_ROOM_MARGIN, short))
    assert right is not None and left is not None  # unmeasured, a side is short
    side = LEFT if LEFT in opened else RIGHT
    if len(opened) == 2:
        # both open: the lower first riser (the side seen over first)
        side = LEFT if (turn.rise_m[1] or 0.0) <= (turn.rise_m[0] or 0.0) else RIGHT
    landing.side = side
    t.say(say.next_flight(side == LEFT, depth, right, left), side=side, depth=depth)
    return go("room_to_turn")


def landing_depth(t: Tick) -> float | None:
    """The landing's depth, from the edge behind to the wall ahead, less
    DEPTH_MARGIN: the smaller of what ascent 3 measured for the last step's
    tread (the reading past its riser: beyond LENGTH_OF_INFINITY not
    measured) and what ascent 7's tab_length_to_edge puts it at
    (TAB_PAST_EDGE_M); None if neither was measured."""
    ctx, cfg = t.ctx, t.cfg
    i = ctx.number_of_steps - 1
    seen: list[float] = []
    tread, tab = ctx.tread_length[i], ctx.tab_length_to_edge[i]
    if tread is not None and math.isfinite(tread):
        seen.append(tread)
    if tab is not None:
        seen.append(tab + cfg.LENGTH_OF_FIRST_MODULE + cfg.LENGTH_OF_SECOND_MODULE
                    - TAB_PAST_EDGE_M)
    return min(seen) - DEPTH_MARGIN if seen else None


def _refuse(t: Tick, why: AscentEnd, message: str) -> Step:
    t.ctx.ascent_end = why
    t.say(say.ascent_ends(message), ascent_end=why.value)
    return go("refused")


_scan_lower = lift(_lower_deltas, recheck(_decide))
SCAN_LOWER = PhaseDef(
    P.LANDING_SCAN_LOWER, "landing 1 — lower segment 3; which way is open?", FLOW,
    _scan_lower[1], RecheckWork, enter=_scan_lower[0], carried_by=(1, 2), family=LandingTurn,
    on={"room_to_turn": Exit(P.LANDING_CENTRE, "lowered, a side seen over reads again what it "
                                               "read there before the lift; room to turn"),
        "refused": Exit(P.DESCENT_BACK_OFF, "lowered; no side seen over that reads again what "
                                            "it read there before the lift (landing_closed), "
                                            "or too little room to turn (landing_too_small): "
                                            "the descent begins"),
        FAILED: Exit(P.ERROR, FAULT)})


# -- landing 2: centre, then turn --------------------------------------------------------------
def _centre_target(t: Tick) -> float | None:
    depth = _turn(t).depth_m
    assert depth is not None  # set by the decision
    return depth / 2.0 - centre_to_front(t.cfg)


def _centre_turns(t: Tick) -> float:
    """Backing by turns, if the front pair cannot read the wall ahead: from
    where ascent 2 left the front face (approach_gap from it)."""
    target = _centre_target(t)
    assert target is not None
    return t.cfg.wheel_turns(max(0.0, target - t.cfg.algorithm.approach_gap))


def _centred(t: Tick, _w: DriveWork) -> Step:
    landing = t.ctx.landing
    landing.twist = motion.twist(t.snap)
    yaw = landing.side * math.pi / 2.0
    return calibrate("centred", Purpose.LANDING, landing.twist + motion.yaw_turns(t.cfg, yaw),
                     say.centred(yaw))


_centre = reading_drive(-1, _centre_target, _centre_turns, _centred)
CENTRE = PhaseDef(
    P.LANDING_CENTRE, "landing 2 — back to the landing's middle", FLOW, _centre[1],
    DriveWork, enter=_centre[0], watches="front", family=LandingTurn,
    on={"centred": Exit(P.CAL_LIFT, "reads half the landing's depth less the front face's "
                                    "reach: lift to turn 90° towards the next flight"),
        FAILED: Exit(P.ERROR, FAULT)})


def turned(t: Tick) -> Step:
    """Calibration's lowering after a landing's turn: on up the next flight
    (calibrate on its first riser), or down the first (calibrate on the wall
    ahead, descent 1)."""
    ctx = t.ctx
    if t.cal.purpose is Purpose.LANDING:
        ctx.landing.step = ctx.number_of_steps
        t.say(say.onto_next_flight(ctx.number_of_steps), landing_step=ctx.landing.step)
        return calibrate("onto_next_flight", Purpose.ASCENT)
    # descent 1 of the first flight's top step, as its back-off would begin it:
    # that step's edge not seen yet (the edge watch's mark is the last step's)
    ctx.descent.edge_wheel = None
    ctx.descent.turned_back = ctx.descent.edge_squared = False
    return calibrate("back_to_first_flight", Purpose.DESCENT)


TURNED: dict[str, Exit] = {
    "onto_next_flight": Exit(P.CAL_CHECK, "lowered after a landing's turn: calibrate on the "
                                          "next flight's first riser"),
    "back_to_first_flight": Exit(P.CAL_CHECK, "lowered, turned back on a landing: calibrate on "
                                              "the wall ahead (descent 1)"),
}
"""The outcomes of :func:`turned`, in calibration's lowering's record."""


def after_calibration(t: Tick) -> None:
    """Squared up on the next flight's first riser, standing where it turned:
    what the front pair reads there is where the way down turns back
    (``Landing.riser_m``)."""
    ctx = t.ctx
    landing = ctx.landing
    if landing.step is None or ctx.number_of_steps != landing.step \
            or landing.riser_m is not None or not motion.measurable(t.snap, t.cfg):
        return
    landing.riser_m = motion.mean_distance(t.snap)
    t.say(say.where_turned(landing.riser_m), landing_riser_m=landing.riser_m)


# -- landing 3: back to where it turned, turn back ------------------------------------------
def turned_here(t: Tick) -> bool:
    """Turned onto the next flight, and refusing its first step: the way down
    begins with the turn back."""
    ctx = t.ctx
    return ctx.landing.step is not None and ctx.number_of_steps == ctx.landing.step


def returns_here(t: Tick) -> bool:
    """Just down the next flight's first step: back to the landing's turn."""
    ctx = t.ctx
    return (ctx.landing.step is not None and not ctx.from_top
            and ctx.steps_descended < ctx.number_of_steps
            and t.descent_index == ctx.landing.step - 1)


def _return_target(t: Tick) -> float | None:
    """What the front pair read on the next flight's first riser where the
    robot turned (squared up there); if it could not read it, what the side
    pair said of that side, less the front face's reach.  The front pair
    first: a side sensor reading long, alone, would send the robot back to
    the wrong place on the landing, and it would turn back into a wall."""
    if t.ctx.landing.riser_m is not None:
        return t.ctx.landing.riser_m
    open_m = _open_m(t)
    return None if open_m is None else open_m - centre_to_front(t.cfg)


def _open_m(t: Tick) -> float | None:
    landing = t.ctx.landing
    return landing.left_m if landing.side == LEFT else landing.right_m


def _return_turns(t: Tick) -> float:
    target = _return_target(t)
    return t.cfg.wheel_turns(max(0.0, (target or 0.0) - t.cfg.algorithm.approach_gap))


def _returned(t: Tick, _w: DriveWork) -> Step:
    twist = t.ctx.landing.twist
    assert twist is not None  # set before the turn
    return calibrate("returned", Purpose.LANDING_BACK, twist,
                     say.BACK_WHERE_TURNED)


_return = reading_drive(-1, _return_target, _return_turns, _returned)
RETURN = PhaseDef(
    P.LANDING_RETURN, "landing 3 — back to where it turned", FLOW, _return[1],
    DriveWork, enter=_return[0], watches="front",
    on={"returned": Exit(P.CAL_LIFT, "reads where it turned (down the next flight's first "
                                     "step, or having refused it): lift to turn back to the "
                                     "heading it came up the first flight with"),
        FAILED: Exit(P.ERROR, FAULT)})


PHASES: tuple[PhaseDef[Any], ...] = (SCAN, SCAN_LOWER, CENTRE, RETURN)
