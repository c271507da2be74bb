"""Descent steps 1–7, one step at a time from the top, back to the start.

i is the step being descended (0-based, into tab_length_to_edge); h is
number_of_turns_for_step_height as descent 2 measures it.  Descent 2 lowers
segment 3 (MTB down) until SBR/SBL read BACK_CLEARANCE; descent 4 moves MTF and
MTB by +h (segment 2 goes down); descent 6 moves MTF by −h.  The drives end at
a reading measured against tab_length_to_edge[i]; where that is not
measurable (the top step reads "nothing ahead") they go by the seed's turn
counts.
"""

from __future__ import annotations

from stairbot.algorithm import motion
from stairbot.algorithm.handler import Handler, PhaseIO, Speeds, lift, reading_drive, turns_drive
from stairbot.algorithm.phases import Phase
from stairbot.hardware import BACK_SENSORS, MotorId


def _tab(io: PhaseIO) -> float | None:
    return io.ctx.tab_length_to_edge[io.descent_index]


def _backed_off(io: PhaseIO) -> None:
    io.ctx.purpose = "descent"
    io.go(Phase.CAL_CHECK)


def _edge_target(io: PhaseIO) -> float | None:
    tab = _tab(io)
    if tab is None:
        io.fail(f"descent 1: tab_length_to_edge[{io.descent_index}] was not measured; "
                "the edge of the step cannot be found")
    return tab


def _edge_fallback(io: PhaseIO) -> float:
    # Descent 1 backed off to SAFE_DISTANCE_IN_FRONT_OF_STEP before calibrating.
    tab = _tab(io) or io.cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP
    return io.cfg.wheel_turns(max(0.0, tab - io.cfg.SAFE_DISTANCE_IN_FRONT_OF_STEP))


def _lower_third_enter(io: PhaseIO) -> None:
    ctx, cfg = io.ctx, io.cfg
    ctx.return_mtb = ctx.entry_mtb
    ctx.target_mtb = -cfg.MAX_OF_VERTICAL_TURNS
    ctx.target_mtf = None
    reading = motion.mean_distance(io.snap, back=True)
    if reading <= cfg.BACK_CLEARANCE + cfg.sensors.resolution / 2:
        io.fail(f"floor not found: SBR/SBL read {reading:.3f} m, at or below BACK_CLEARANCE "
                f"({cfg.BACK_CLEARANCE} m), before segment 3 was lowered (step "
                f"{io.descent_index + 1}): segment 3 is not over an edge")


def _lower_third(io: PhaseIO) -> Speeds:
    ctx, cfg = io.ctx, io.cfg
    reading = motion.mean_distance(io.snap, back=True)
    to_go = reading - cfg.BACK_CLEARANCE
    if to_go <= cfg.sensors.resolution / 2:
        ctx.number_of_turns_for_step_height = ctx.return_mtb - io.snap.turns(MotorId.MTB)
        io.info(f"segment 3 on the step below: number_of_turns_for_step_height = "
                f"{ctx.number_of_turns_for_step_height:.2f} (step {io.descent_index + 1})",
                number_of_turns_for_step_height=ctx.number_of_turns_for_step_height)
        io.go(Phase.DESCENT_DRIVE_SECOND)
        return {}
    assert ctx.target_mtb is not None
    limit = motion.lift_to(cfg, io.snap, MotorId.MTB, ctx.target_mtb)
    if limit is None:
        io.fail(f"floor not found when descending step {io.descent_index + 1}: MTB reached "
                f"-MAX_OF_VERTICAL_TURNS ({-cfg.MAX_OF_VERTICAL_TURNS:.0f}) and SBR/SBL still "
                f"read {reading:.3f} m")
        return {}
    backs = [io.snap.sensors[s] for s in BACK_SENSORS]
    if all(r.ok for r in backs):
        speed = motion.approach(cfg.motors.lift_speed, cfg.lift_turns(to_go),
                                motion.LIFT_SLOW_ZONE, cfg.algorithm.tick)
        return {MotorId.MTB: -min(speed, abs(limit))}
    return {MotorId.MTB: limit}  # out of range far: nothing below yet, keep lowering


def _second_target(io: PhaseIO) -> float | None:
    tab = _tab(io)
    return None if tab is None else io.cfg.LENGTH_OF_SECOND_MODULE + tab


def _first_target(io: PhaseIO) -> float | None:
    tab = _tab(io)
    if tab is None:
        return None
    return io.cfg.LENGTH_OF_FIRST_MODULE + io.cfg.LENGTH_OF_SECOND_MODULE + tab


def _h(io: PhaseIO) -> float:
    return io.ctx.number_of_turns_for_step_height


def _lowered_first(io: PhaseIO) -> None:
    ctx = io.ctx
    ctx.steps_descended += 1
    io.info(f"step {ctx.number_of_steps - ctx.steps_descended + 1} descended "
            f"({ctx.steps_descended} of {ctx.number_of_steps})",
            steps_descended=ctx.steps_descended)
    if ctx.steps_descended < ctx.number_of_steps:
        io.go(Phase.DESCENT_BACK_OFF)
    else:
        io.go(Phase.DESCENT_FINISH)


def _finish_target(io: PhaseIO) -> float | None:
    return io.ctx.start_reading


HANDLERS: dict[Phase, Handler] = {
    Phase.DESCENT_BACK_OFF: turns_drive(
        -1, lambda io: io.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH, _backed_off),
    Phase.DESCENT_BACK_TO_EDGE: reading_drive(
        -1, _edge_target, _edge_fallback, lambda io: io.go(Phase.DESCENT_LOWER_THIRD)),
    Phase.DESCENT_LOWER_THIRD: Handler(_lower_third, _lower_third_enter),
    Phase.DESCENT_DRIVE_SECOND: reading_drive(
        -1, _second_target, lambda io: io.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE,
        lambda io: io.go(Phase.DESCENT_LOWER_SECOND)),
    Phase.DESCENT_LOWER_SECOND: lift(lambda io: {MotorId.MTF: _h(io), MotorId.MTB: _h(io)},
                                     lambda io: io.go(Phase.DESCENT_DRIVE_FIRST)),
    Phase.DESCENT_DRIVE_FIRST: reading_drive(
        -1, _first_target, lambda io: io.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE,
        lambda io: io.go(Phase.DESCENT_LOWER_FIRST)),
    Phase.DESCENT_LOWER_FIRST: lift(lambda io: {MotorId.MTF: -_h(io)}, _lowered_first),
    Phase.DESCENT_FINISH: reading_drive(
        -1, _finish_target, lambda io: io.cfg.NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH,
        lambda io: io.end("completed", "back at the start position")),
}
