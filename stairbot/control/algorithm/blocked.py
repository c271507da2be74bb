"""Ascent 2, blocked: a step lower than the front sensors stand.

The approach places the riser it reads on the odometer (``ctx.riser_wheel``:
the reading plus the turns driven, the median of many ticks).  Driving, the
place may come nearer (a cone that mixed in what lies beyond the riser sees
the riser alone) but a riser does not go away.  It does when the wheels turn
without carrying the robot, against a step below the beams (wheels 16 mm in
radius cannot mount a riser the front pair, 30 mm up, looks over), or when
the pair sees over the riser it read.  Either way the step is lower than the
pair stands (``sensors.front_height``), below every robot's
``min_step_rise_m``: the ascent ends there (an obstacle) and the robot goes
back down, or home.

Slipping wheels turn the odometer on without the robot, and descent 7 backs
to the start position by the odometer on the floor.  So on the floor the
robot first backs BACK_OFF_M off the step (level again: pressed against it
the pair pitches and reads past the riser), stands until its filtered
readings stand for where it is, and places the riser again: the slip is how
much further on it stands now than a place it held while the wheels carried
the robot (:func:`_slip` says which), and the start position moves on by
that.  No such place (the pair saw over the riser, or reads another surface
now): the odometer is kept.
"""

from __future__ import annotations

import statistics

from stairbot.control.algorithm import landing, motion
from stairbot.control.algorithm.modes import AscentEnd
from stairbot.control.algorithm.moves import KEY_TICKS, RISER_KEYS
from stairbot.control.algorithm.phase import NO_MOTION, Step, Tick, go, stay
from stairbot.control.algorithm.texts import ascent as say
from stairbot.control.algorithm.work import ApproachWork
from stairbot.control.tolerances import settle_s

BLOCKED_M = 0.04
"""How much further on than its nearest place the riser stands when it has
gone away: eight times the placing's noise on the noisiest shipped pair (an
HC-SR04's median, 5 mm)."""
HELD_M = 0.01
"""Within this of its nearest place the riser holds still (the wheels carry
the robot)."""
STOP_S = 0.5
"""Blocked: standing this long before backing off (the wheels stop)."""
BACK_OFF_M = 0.05
"""On the floor, how far the robot backs off the step before it places the
riser again."""


def went_away(t: Tick, w: ApproachWork) -> bool:
    """The riser placed on the odometer stands BLOCKED_M further on than the
    nearest it was placed in this approach (then the approach stands:
    :func:`step` from the next tick on)."""
    cfg, riser = t.cfg, t.ctx.riser_wheel
    if riser is None or len(w.riser_keys) < KEY_TICKS:
        return False
    here = motion.wheel_position(t.snap)
    if w.nearest_riser is None or riser < w.nearest_riser:
        w.nearest_riser = riser
    went = (riser - w.nearest_riser) * cfg.wheel_circumference
    if went <= HELD_M:
        w.held_wheel = here
        if not w.placings or abs(riser - w.placings[-1]) > cfg.wheel_turns(HELD_M):
            w.placings.append(riser)
    if went <= BLOCKED_M:
        return False
    w.blocked_since, w.blocked_wheel, w.went_m = t.snap.time_s, here, went
    return True


def step(t: Tick, w: ApproachWork) -> Step:
    """Stand STOP_S; on the floor back BACK_OFF_M and place the robot; then
    end the ascent: home from the floor, down the steps climbed, or back to
    a landing's turn."""
    cfg, ctx = t.cfg, t.ctx
    assert w.blocked_since is not None
    if t.snap.time_s - w.blocked_since < STOP_S:
        return stay(NO_MOTION)
    turned = landing.turned_here(t)
    on_the_floor = ctx.number_of_steps == 0 and not turned
    slip = 0.0
    if on_the_floor:
        here = motion.wheel_position(t.snap)
        if w.back_target is None:
            w.back_target = here - cfg.wheel_turns(BACK_OFF_M)
        remaining = here - w.back_target
        if remaining > motion.WHEEL_DONE:
            return stay(motion.drive(cfg, -1, remaining))
        placed = _placed(t, w)
        if placed is None:
            return stay(NO_MOTION)
        slip = _slip(t, w, placed)
        start = ctx.start
        if start.wheel is not None:
            start.wheel += slip
        if start.home_wheel is not None:
            start.home_wheel += slip
    ctx.ascent_end = AscentEnd.OBSTACLE
    slip_m = slip * cfg.wheel_circumference
    t.say(say.below_the_sensors(ctx.number_of_steps, cfg.sensors.front_height, w.went_m,
                                slip_m if on_the_floor else None),
          ascent_end="obstacle", slip_m=slip_m)
    if turned:
        return go("blocked_after_turn")
    return go("blocked_steps_climbed" if ctx.number_of_steps > 0 else "blocked_on_the_floor")


def _placed(t: Tick, w: ApproachWork) -> float | None:
    """Backed off: the riser placed on the odometer by the median of KEY_TICKS
    ticks' readings once the filtered readings stand for where the robot
    stands (settle_s); None until then, and NaN when the pair cannot measure
    it (then the odometer is kept)."""
    cfg = t.cfg
    if w.still_since is None:
        w.still_since = t.snap.time_s
    if t.snap.time_s - w.still_since < settle_s(cfg):
        return None
    if motion.measurable(t.snap, cfg):
        w.level_keys.append(motion.wheel_position(t.snap)
                            + cfg.wheel_turns(motion.mean_distance(t.snap)))
    if len(w.level_keys) >= KEY_TICKS:
        return statistics.median(w.level_keys)
    if t.snap.time_s - w.still_since >= settle_s(cfg) + 2 * KEY_TICKS * cfg.algorithm.tick:
        return float("nan")
    return None


def _slip(t: Tick, w: ApproachWork, placed: float) -> float:
    """Turns the wheels made without the robot: how much further on the
    riser is placed now than a place it held at, at least as far as it
    went before it was found gone (BLOCKED_M, less HELD_M) and at most the
    turns driven since it last held and over the placing's lag (the filtered readings'
    settle_s and RISER_KEYS ticks: it is seen to go that late); the least
    such, or none.  Places, not the nearest alone: the pair may have read
    a riser beyond before it read this one, and pressed against the step it
    pitches and reads nearer than this one stands."""
    cfg = t.cfg
    assert w.blocked_wheel is not None
    held = w.held_wheel if w.held_wheel is not None else w.entry_wheel
    lag_s = settle_s(cfg) + RISER_KEYS * cfg.algorithm.tick
    most = w.blocked_wheel - held + cfg.motors.wheel_speed * lag_s + cfg.wheel_turns(HELD_M)
    least = cfg.wheel_turns(BLOCKED_M - HELD_M)
    slips = [placed - place for place in w.placings if least <= placed - place <= most]
    return min(slips, default=0.0)  # (placed NaN, not measured: none)
