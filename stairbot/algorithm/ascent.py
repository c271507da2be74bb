"""Ascent steps 2–9 (step 1 is calibration: :mod:`stairbot.algorithm.calibration`).

h below is number_of_turns_for_step_height.  Ascent 3 lifts segment 1 until
the front sensors see over the step, then number_of_vertical_turns more; h is
the total.  Ascent 5 moves MTF and MTB by −h together (segment 2 rises), ascent
7 moves MTB by +h (segment 3 rises).  The drives of steps 4, 6 and 9 end at a
reading when the distance is measurable and by turns when it is not.
"""

from __future__ import annotations

from stairbot.algorithm import motion
from stairbot.algorithm.handler import Handler, PhaseIO, Speeds, lift, reading_drive
from stairbot.algorithm.phases import Phase
from stairbot.hardware import MotorId


def _approach(io: PhaseIO) -> Speeds:
    cfg, ctx = io.cfg, io.ctx
    sfr, sfl = motion.pair(io.snap)
    if motion.far(sfr, cfg) or motion.far(sfl, cfg):
        io.fail(f"riser lost during the approach (step {ctx.number_of_steps + 1}): "
                f"SFR {sfr.distance_m:.3f} m, SFL {sfl.distance_m:.3f} m, nothing ahead")
        return {}
    reading = motion.mean_distance(io.snap)
    safe = cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP
    here = motion.wheel_position(io.snap)
    if reading <= safe:
        # From SAFE_DISTANCE_IN_FRONT_OF_STEP on, NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
        # more.  A robot that starts nearer (after ascent 9) drives only the rest.
        ctx.target_wheel = (here + cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
                            - cfg.wheel_turns(safe - reading))
        io.go(Phase.ASCENT_APPROACH_TURNS)
        return {}
    remaining = cfg.wheel_turns(reading - safe) + cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH
    return motion.drive(cfg, 1, remaining)


def _approach_turns(io: PhaseIO) -> Speeds:
    assert io.ctx.target_wheel is not None  # set by ascent 2's first part
    remaining = io.ctx.target_wheel - motion.wheel_position(io.snap)
    if remaining <= motion.WHEEL_DONE:
        io.go(Phase.ASCENT_LIFT_FIRST)
        return {}
    return motion.drive(io.cfg, 1, remaining)


def _lift_first_enter(io: PhaseIO) -> None:
    ctx, cfg = io.ctx, io.cfg
    ctx.return_mtf = ctx.entry_mtf
    ctx.target_mtf = ctx.entry_mtf + cfg.MAX_OF_VERTICAL_TURNS - ctx.number_of_vertical_turns
    ctx.target_mtb = None


def _lift_first(io: PhaseIO) -> Speeds:
    ctx, cfg = io.ctx, io.cfg
    sight = cfg.LENGTH_OF_A_ROBOT + cfg.SAFE_LENGTH
    readings = motion.pair(io.snap)
    if all(motion.far(r, cfg) or (r.ok and r.distance_m >= sight) for r in readings):
        io.info(f"segment 1 sees over step {ctx.number_of_steps + 1}: SFR/SFL read "
                f"{readings[0].distance_m:.3f}/{readings[1].distance_m:.3f} m "
                f"(≥ {sight:.3f} m) after {io.snap.turns(MotorId.MTF) - ctx.return_mtf:.1f} "
                "MTF turns")
        io.go(Phase.ASCENT_LIFT_FIRST_MORE)
        return {}
    assert ctx.target_mtf is not None
    speed = motion.lift_to(cfg, io.snap, MotorId.MTF, ctx.target_mtf)
    if speed is None:
        ctx.ascent_end = "obstacle"
        allowed = cfg.MAX_OF_VERTICAL_TURNS - ctx.number_of_vertical_turns
        io.info(f"step {ctx.number_of_steps + 1} too high or its tread too short: no reading "
                f"≥ {sight:.3f} m within {allowed:.1f} MTF turns; the ascent ends (obstacle)",
                ascent_end="obstacle")
        io.go(Phase.ASCENT_LOWER_OBSTACLE)
        return {}
    return {MotorId.MTF: speed}


def _lifted_first(io: PhaseIO) -> None:
    ctx = io.ctx
    ctx.number_of_turns_for_step_height = io.snap.turns(MotorId.MTF) - ctx.return_mtf
    io.info(f"number_of_turns_for_step_height = {ctx.number_of_turns_for_step_height:.2f} "
            f"(step {ctx.number_of_steps + 1})",
            number_of_turns_for_step_height=ctx.number_of_turns_for_step_height)
    io.go(Phase.ASCENT_DRIVE_FIRST)


def _lowered_obstacle(io: PhaseIO) -> None:
    io.go(Phase.DESCENT_BACK_OFF if io.ctx.number_of_steps > 0 else Phase.DESCENT_FINISH)


def _first_target(io: PhaseIO) -> float | None:
    ctx, cfg = io.ctx, io.cfg
    if motion.measurable(io.snap, cfg):
        ctx.length_of_next_step = motion.mean_distance(io.snap)
        io.info(f"length_of_next_step = {ctx.length_of_next_step:.3f} m",
                length_of_next_step=ctx.length_of_next_step)
        return ctx.length_of_next_step - cfg.LENGTH_OF_FIRST_MODULE
    ctx.length_of_next_step = None
    io.info("length_of_next_step not measurable (nothing ahead within LENGTH_OF_INFINITY): "
            "driving NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE turns",
            length_of_next_step=None)
    return None


def _second_target(io: PhaseIO) -> float | None:
    length = io.ctx.length_of_next_step
    if length is None:
        return None
    return length - io.cfg.LENGTH_OF_FIRST_MODULE - io.cfg.LENGTH_OF_SECOND_MODULE


def _third_target(io: PhaseIO) -> float | None:
    length = io.ctx.length_of_next_step
    return None if length is None else length - io.cfg.LENGTH_OF_A_ROBOT


def _h(io: PhaseIO) -> float:
    return io.ctx.number_of_turns_for_step_height


def _lifted_third(io: PhaseIO) -> None:
    ctx, cfg = io.ctx, io.cfg
    i = ctx.number_of_steps
    if motion.measurable(io.snap, cfg):
        ctx.tab_length_to_edge[i] = motion.mean_distance(io.snap)
        io.info(f"tab_length_to_edge[{i}] = {ctx.tab_length_to_edge[i]:.3f} m",
                index=i, tab_length_to_edge=ctx.tab_length_to_edge[i])
    else:
        ctx.tab_length_to_edge[i] = None
        io.info(f"tab_length_to_edge[{i}] not measurable (nothing ahead): the descent of this "
                "step drives by turns", index=i, tab_length_to_edge=None)
    ctx.number_of_steps += 1
    io.info(f"number_of_steps = {ctx.number_of_steps}", number_of_steps=ctx.number_of_steps)
    io.go(Phase.ASCENT_CHECK)


def _check(io: PhaseIO) -> Speeds:
    ctx, cfg = io.ctx, io.cfg
    sfr, sfl = motion.pair(io.snap)
    if motion.far(sfr, cfg) and motion.far(sfl, cfg):
        ctx.ascent_end = "top_reached"
        io.info(f"top reached after {ctx.number_of_steps} steps: SFR/SFL read at least "
                "LENGTH_OF_INFINITY; the descent begins", ascent_end="top_reached")
        io.go(Phase.DESCENT_LOWER_THIRD)
    elif ctx.number_of_steps >= cfg.algorithm.max_steps:
        ctx.ascent_end = "step_limit"
        io.info(f"number_of_steps reached {cfg.algorithm.max_steps}: the ascent ends; "
                "the descent begins", ascent_end="step_limit")
        io.go(Phase.DESCENT_LOWER_THIRD)
    else:
        io.go(Phase.ASCENT_DRIVE_THIRD)
    return {}


def _driven_third(io: PhaseIO) -> None:
    io.ctx.purpose = "ascent"
    io.go(Phase.CAL_CHECK)


HANDLERS: dict[Phase, Handler] = {
    Phase.ASCENT_APPROACH: Handler(_approach),
    Phase.ASCENT_APPROACH_TURNS: Handler(_approach_turns),
    Phase.ASCENT_LIFT_FIRST: Handler(_lift_first, _lift_first_enter),
    Phase.ASCENT_LIFT_FIRST_MORE: lift(lambda io: {MotorId.MTF: io.ctx.number_of_vertical_turns},
                                       _lifted_first),
    Phase.ASCENT_LOWER_OBSTACLE: lift(
        lambda io: {MotorId.MTF: io.ctx.return_mtf - io.ctx.entry_mtf}, _lowered_obstacle),
    Phase.ASCENT_DRIVE_FIRST: reading_drive(
        1, _first_target, lambda io: io.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE,
        lambda io: io.go(Phase.ASCENT_LIFT_SECOND)),
    Phase.ASCENT_LIFT_SECOND: lift(lambda io: {MotorId.MTF: -_h(io), MotorId.MTB: -_h(io)},
                                   lambda io: io.go(Phase.ASCENT_DRIVE_SECOND)),
    Phase.ASCENT_DRIVE_SECOND: reading_drive(
        1, _second_target, lambda io: io.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE,
        lambda io: io.go(Phase.ASCENT_LIFT_THIRD)),
    Phase.ASCENT_LIFT_THIRD: lift(lambda io: {MotorId.MTB: _h(io)}, _lifted_third),
    Phase.ASCENT_CHECK: Handler(_check),
    Phase.ASCENT_DRIVE_THIRD: reading_drive(
        1, _third_target, lambda io: io.cfg.wheel_turns(io.cfg.LENGTH_OF_THIRD_MODULE),
        _driven_third),
}
