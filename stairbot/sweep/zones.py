"""Which zone a case's stairs lie in for its robot: "inside" its limits
(the run must climb them), "outside" (it must refuse them, or stop short),
or the "band" between, within the spec's margins, where either is right.

The limits are the robot config's (rise, tread, what the front cone needs
to measure a tread, sight at the start), a quarter-turn landing's turning
room, and a descent's drops; :func:`zone` picks the rules for the stairs.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cache

import msgspec

from stairbot.control.algorithm import limits
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, Step, parse_scenario
from stairbot.sweep.spec import Rules

SIGHT_MARGIN_M = 0.02
"""The band either side of LENGTH_OF_INFINITY in which the start's nearer
front sensor may or may not read the first riser as nearer (the noise of one
reading, or three of the sensor's stated sigma there if that is more)."""

REST_S = 1.0
"""How long the simulated robot stands, every motor stopped, before
:func:`first_sight` reads its front pair: it is set down with its wheels
1 mm into the stairs' surface and rises 0.5 mm in its first second, to
within 10 um of rest by REST_S, and its calibration reads the pair standing
there (0.9 s after the start on the reference robot): a ray that grazes the
first riser's nosing from the pose it was set down in may pass over it by
then and meet the riser beyond."""


def first_sight(scenario: Scenario, config: RobotConfig) -> float:
    """The nearer front sensor's reading at the start, before noise (inf:
    nothing in range), as the robot stands when its calibration reads the
    pair: the simulated robot left standing :data:`REST_S` (see there), then
    what its beams meet (``SimSensors.front_seen``) -- one level ray each,
    or a cone as the sensor model combines it, so a cone tilted up that takes
    in the risers beyond the first reads long.  The calibration's case 1 stops
    the robot, rightly, when both read LENGTH_OF_INFINITY or more: stairs that
    far are not in sight, whatever their steps.

    A robot set down on the floor at least :data:`FLOOR_CLEAR_M` before the
    first riser touches nothing but the floor while it stands, so it comes
    to rest as it does on open floor: its pose there (:func:`_rest_on_floor`,
    once per robot config) is moved to where this robot was set down instead
    of stepping the physics again."""
    from stairbot.fakes.sim import SimRobot  # the sweep runs the sim anyway

    robot = SimRobot(config, scenario)
    if scenario.start.on == "floor" and scenario.start.distance >= FLOOR_CLEAR_M:
        world = robot.world
        bodies = (*world.segments, *world.all_wheels)
        for body, (dx, y, angle) in zip(bodies, _rest_on_floor(config), strict=True):
            body.position = (body.position.x + dx, y)
            body.angle = angle
        world.shift(0.0)  # the poses are read afresh
        robot.plan.move(_rest_on_floor(config)[1][0])  # segment 2's drift, as advance moves it
    else:
        robot.advance(REST_S)
    right, left = robot.board.front_seen()
    hi = config.sensors.range(back=False)[1]
    seen = [d for d in (right, left) if d is not None and d <= hi]
    return min(seen, default=math.inf)


FLOOR_CLEAR_M = 0.05
"""How far before the first riser a robot set down on the floor stands clear
of it while it comes to rest (it moves well under a millimetre)."""

_OPEN_FLOOR = "[stairs]\ncount = 1\n[start]\ndistance = 1.0\n"
"""Where :func:`_rest_on_floor` lets a robot come to rest: a metre before a
single step."""


@cache
def _rest_on_floor(config: RobotConfig) -> tuple[tuple[float, float, float], ...]:
    """Each body of ``config``'s simulated robot (segments, then wheels, in the
    world's order) after standing :data:`REST_S` on open floor: how far it
    moved along x from where it was set down, its height and its angle."""
    from stairbot.fakes.sim import SimRobot

    robot = SimRobot(config, parse_scenario(_OPEN_FLOOR, "<open floor>"))
    world = robot.world
    bodies = (*world.segments, *world.all_wheels)
    set_down = [body.position.x for body in bodies]
    robot.advance(REST_S)
    return tuple((body.position.x - x0, body.position.y, body.angle)
                 for body, x0 in zip(bodies, set_down, strict=True))


def sight_margin(config: RobotConfig) -> float:
    """How far either side of LENGTH_OF_INFINITY the sight rule leaves a band."""
    far = config.LENGTH_OF_INFINITY
    return max(SIGHT_MARGIN_M, 3.0 * config.sensors.sigma(False, far))


def zone(scenario: Scenario, config: RobotConfig, rules: Rules) -> tuple[str, float, float]:
    """("inside" | "band" | "outside", max rise, min tread) of the steps the robot
    attempts (the first max_steps) against its limits (rises between
    min_step_rise_m and max_step_rise_m, each at least min_rise_for the
    tread before it and, where that tread is measured (all but a landing's),
    min_rise_for the tread after it; treads of min_tread_m or more), give
    or take the margins; stairs out of sight at the start (see
    :func:`first_sight`) are outside.
    A tread counts where the robot must fit on it: every tread it climbs onto,
    but not the last one under a landing, which runs on into the landing.
    A tread so long that the next riser is out of the front pair's sight at
    ascent 8 ends the flight for the robot, as stairs out of sight at the
    start do (:func:`_riser_seen_m`)."""
    if scenario.start.on == "top":
        return descent_zone(scenario, config, rules)
    if scenario.landing is not None:
        return landing_zone(scenario, config, rules)
    steps = scenario.steps[:config.algorithm.max_steps]
    if not steps:
        return "inside", 0.0, math.inf
    max_rise = max(s.rise for s in steps)
    min_rise = min(s.rise for s in steps)
    last = len(scenario.steps) - 1
    treads = [s.tread for i, s in enumerate(steps) if not (i == last and scenario.top == "landing")]
    min_tread = min(treads, default=math.inf)
    lr, lo, lt = (limits.max_step_rise_m(config), limits.min_step_rise_m(config),
                  limits.min_tread_m(config))
    rm, tm = rules.rise_margin_m, rules.tread_margin_m
    # how far each riser clears what the front cone needs to measure the tread
    # before it, and each measured tread's own riser what the robot asks of it
    # (it takes the next riser to be as high: ascent 3)
    measured = [i for i in range(len(steps)) if not (i == last and scenario.top == "landing")]
    near_low, far_low = _cone_clearances(scenario, steps, measured, config, tm)
    low = min([min_rise - lo] + near_low)
    sight, margin = first_sight(scenario, config), sight_margin(config)
    sight = max([sight] + [_riser_seen_m(s.tread, config) for s in steps[:-1]])
    far = config.LENGTH_OF_INFINITY
    if (max_rise > lr + rm or low < -rm or min_tread < lt - tm
            or sight > far + margin):
        return "outside", max_rise, min_tread
    if (max_rise <= lr - rm and low >= rm and min(far_low, default=rm) >= rm
            and min_tread >= lt + tm and sight <= far - margin):
        return "inside", max_rise, min_tread
    return "band", max_rise, min_tread


def _riser_seen_m(tread: float, config: RobotConfig) -> float:
    """What the front pair reads of the next riser at ascent 8 on a tread
    ``tread`` long: from segment 1's front face, about LENGTH_OF_FIRST_MODULE
    + LENGTH_OF_SECOND_MODULE - TAB_PAST_EDGE_M past the edge.  Past
    LENGTH_OF_INFINITY (give or take the sight margin) the robot takes that
    step for the top: like stairs out of sight at the start, the rest is
    outside."""
    from stairbot.control.algorithm.landing import TAB_PAST_EDGE_M

    return tread - (config.LENGTH_OF_FIRST_MODULE + config.LENGTH_OF_SECOND_MODULE
                    - TAB_PAST_EDGE_M)


def _cone_clearances(scenario: Scenario, steps: tuple[Step, ...] | list[Step],
                     measured: list[int], config: RobotConfig, tm: float
                     ) -> tuple[list[float], list[float]]:
    """How far each riser clears what the front cone needs, split by the
    rule that holds it: ([the rule's own, which refuses], [the readings',
    for a tread past FAR_TREAD_M]).  A tread the robot measures up to
    FAR_TREAD_M (the reading, tread + approach_gap, give or take the tread
    margin) holds the riser it climbs, and the next, to min_rise_for it;
    past it the robot climbs a riser lower than that if its readings held
    as segment 1 rose (:mod:`stairbot.control.algorithm.long_tread`): the next
    riser lower than min_rise_for, climbing and refusing are both right (a
    wall is higher than any: no bound).  Within the margin of FAR_TREAD_M,
    either rule may hold: the readings'."""
    from stairbot.control.algorithm.long_tread import (
        FAR_TREAD_M,  # the sweep runs the controller anyway
    )

    near: list[float] = []
    far: list[float] = []
    gap = config.algorithm.approach_gap
    for i in range(len(steps)):
        tread = steps[i].tread
        need = config.min_rise_for(tread)
        ahead = [steps[i + 1].rise - need] if i + 1 < len(steps) else []
        own = [steps[i].rise - need] if i in measured else []
        if tread + gap <= FAR_TREAD_M - tm:
            near.extend(ahead + own)
        elif tread + gap <= FAR_TREAD_M + tm:
            far.extend(ahead + own)  # either rule
        else:
            far.extend(ahead)  # a wall ahead (the last step under top = "wall"): no bound
    return near, far


def landing_drift_m(scenario: Scenario, config: RobotConfig) -> float:
    """How far across the flight the climb may carry the robot from where it
    was set down, by the time it looks sideways from the landing's wall: the
    start's close-in drive at the yaw it was set down with, then the yaw the
    start's squaring may leave (the pair's difference within
    :func:`~stairbot.control.tolerances.square_tolerance` over its baseline,
    2 x front_lateral: 2.9 degrees on the reference robot's 5 mm over 0.1 m),
    which later steps keep (their calibration turns only past the tolerance),
    over the way from where it squared up to the wall ahead: 0.1 m over the
    2 m to a 1.02 m landing's wall behind two 0.28 m treads."""
    from stairbot.control.tolerances import square_tolerance  # the sweep runs the controller

    landing = scenario.landing
    assert landing is not None
    start = scenario.start
    squared = min(start.distance, limits.square_range_m(config))
    close_in = (start.distance - squared) * abs(math.sin(math.radians(start.yaw_deg)))
    yaw = math.atan(square_tolerance(config, squared)
                    / (2.0 * max(config.sensors.front_lateral, 1e-6)))
    way = (squared + sum(s.tread for s in scenario.steps[:-1]) + landing.depth
           - config.algorithm.approach_gap)
    return close_in + way * math.tan(yaw)


def landing_zone(scenario: Scenario, config: RobotConfig, rules: Rules
                 ) -> tuple[str, float, float]:
    """Quarter-turn stairs' zone: each flight's as a flight of its own
    (:func:`zone`: the first ends on the landing, the second on its top),
    and the landing's.  The robot turns on the landing only if it has the
    side pair and ``[algorithm] landings``, the second flight has steps, the
    landing is not so deep that the wall ahead reads as the top (the front
    pair's LENGTH_OF_INFINITY past the robot standing at the edge), and the
    robot's turning room (:func:`~stairbot.control.algorithm.landing.turn_room_m`)
    fits in half the landing's measured depth and on either side of where it
    climbed (half the width, less start.lateral and the drift the squaring's
    tolerance allows: :func:`landing_drift_m`), give or take the tread
    margin; where it fits centred but not so drifted, either is right (the
    band).  Where the landing refuses, the first flight's zone stands: the
    robot climbs it, refuses the landing, comes home, and that is right
    ("refused"); where it does not, both flights must be climbed."""
    from stairbot.control.algorithm.landing import DEPTH_MARGIN, turn_room_m

    landing = scenario.landing
    assert landing is not None
    first = _first_flight_zone(scenario, config, rules)
    if not landing.steps:
        return first  # a wall where the second flight should be: the flight ends there
    second = zone(replace(scenario, steps=landing.steps, landing=None,
                          start=msgspec.structs.replace(scenario.start, distance=0.3)),
                  config, rules)
    tm = rules.tread_margin_m
    room = turn_room_m(config)
    depth = landing.depth - DEPTH_MARGIN
    # where the robot stands across the landing: start.lateral, and what the
    # yaw the squaring leaves adds over the flight (either way: the nearer side)
    centred = scenario.width / 2.0 - room
    drifted = centred - abs(scenario.start.lateral) - landing_drift_m(scenario, config)
    # how far inside LENGTH_OF_INFINITY ascent 8 reads the wall ahead
    top = config.LENGTH_OF_INFINITY - _riser_seen_m(landing.depth, config)
    sight = sight_margin(config)
    turns = config.algorithm.landings and config.sensors.has_side_pair
    max_rise, min_tread = max(first[1], second[1]), min(first[2], second[2])
    steps = len(scenario.steps) + len(landing.steps)
    if not turns or min(depth / 2.0 - room, centred) < -tm or top < -sight:
        # the landing refuses (or reads as the top): the first flight decides
        return ("outside" if first[0] == "inside" else first[0]), max_rise, min_tread
    short = min(depth / 2.0 - room, drifted)
    zones = {first[0], second[0]}
    if "outside" in zones:
        return "outside", max_rise, min_tread
    if zones == {"inside"} and short >= tm and top >= sight \
            and steps <= config.algorithm.max_steps:
        return "inside", max_rise, min_tread
    return "band", max_rise, min_tread


def _first_flight_zone(scenario: Scenario, config: RobotConfig, rules: Rules
                       ) -> tuple[str, float, float]:
    """The first flight's zone under a quarter-turn landing: its last tread is
    the landing, which ascent 3 measures (and holds to min_rise_for, as any
    tread: the robot cannot tell the landing's wall from a low riser beyond
    a long tread) where the wall ahead is in the front pair's sight (nearer
    than LENGTH_OF_INFINITY, give or take the sight margin), and does not
    beyond it; between, either."""
    landing = scenario.landing
    assert landing is not None
    last = scenario.steps[-1]
    walled = replace(scenario, landing=None, top="wall",
                     steps=(*scenario.steps[:-1], type(last)(last.rise, landing.depth)))
    open_ = replace(scenario, landing=None)
    reading = landing.depth + config.algorithm.approach_gap
    sight, far = sight_margin(config), config.LENGTH_OF_INFINITY
    if reading < far - sight:
        return zone(walled, config, rules)
    if reading > far + sight:
        return zone(open_, config, rules)
    a, b = zone(walled, config, rules), zone(open_, config, rules)
    return a if a[0] == b[0] else ("band", a[1], min(a[2], b[2]))


def descent_zone(scenario: Scenario, config: RobotConfig, rules: Rules
                 ) -> tuple[str, float, float]:
    """A continuous descent's zone: every rise from the least drop the back
    pair reads as one (:func:`~stairbot.control.algorithm.edge_measure.edge_drop_m` less
    BACK_CLEARANCE) to max_step_rise_m, and every tread it steps down onto (all
    but the top one, which runs on into the landing it starts on) at least
    LENGTH_OF_A_ROBOT + SAFE_LENGTH (narrow steps or not), give or take the
    margins, is inside; a rise deeper than
    max_drop_m (what segment 3 can be lowered), a lower rise than the pair
    sees, or a tread shorter than LENGTH_OF_FIRST_MODULE +
    LENGTH_OF_SECOND_MODULE (segments 1 and 2 do not fit on it), is outside
    (refused); between, the band.  (The robot does not measure a tread
    before it steps down onto it: one shorter than min_tread_m it descends
    while its back pair still reads the tread after the step, and refuses
    once it reads past the next edge.)"""
    from stairbot.control.algorithm.edge_measure import (
        edge_drop_m,  # the sweep runs the controller anyway
    )

    steps = scenario.steps
    low = edge_drop_m(config, from_top=True) - config.BACK_CLEARANCE  # the least drop seen
    max_rise = max(s.rise for s in steps)
    min_rise = min(s.rise for s in steps)
    min_tread = min((s.tread for s in steps[:-1]), default=math.inf)
    rm, tm = rules.rise_margin_m, rules.tread_margin_m
    if (max_rise > config.max_drop_m + rm or min_rise < low - rm
            or min_tread < config.LENGTH_OF_FIRST_MODULE + config.LENGTH_OF_SECOND_MODULE - tm):
        return "outside", max_rise, min_tread
    # the whole robot's tread, narrow steps or not: a continuous descent does
    # not know a tread before it steps down onto it
    whole = config.LENGTH_OF_A_ROBOT + config.SAFE_LENGTH
    if (max_rise <= config.max_step_rise_m - rm and min_rise >= low + rm
            and min_tread >= whole + tm):
        return "inside", max_rise, min_tread
    return "band", max_rise, min_tread

