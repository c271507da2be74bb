"""Calibration: squaring up to the riser (cases 1, 2, 3A, 3B).

The same phases serve the start of the program (every case), ascent step 1 on
later steps and descent step 1 (case 2 only); ``Context.purpose`` says which.
Turning happens on segment 2's wheels with segments 1 and 3 lifted by
NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE, slowly, and stops when the smoothed
SFL − SFR reaches zero, so that sensor noise neither stops it early nor
leaves the robot askew.
"""

from __future__ import annotations

import math

from stairbot.algorithm import motion
from stairbot.algorithm.handler import Handler, PhaseIO, Speeds, lift, where
from stairbot.algorithm.phases import Mode, Phase
from stairbot.hardware import MotorId

PROBE_YAW_RAD = math.radians(10.0)
"""Case 3: the probe turn stops after this much yaw if the readings have not
changed by 2 × equal_tolerance before."""
MAX_TURN_YAW_RAD = math.radians(90.0)
"""A calibration that turns this far without SFR = SFL ends with an error."""
TURN_SLOW_FLOOR = 0.25
"""The squaring turn slows near SFR = SFL, down to this fraction of its speed."""


def _readings(io: PhaseIO) -> tuple[float, float]:
    sfr, sfl = motion.pair(io.snap)
    return sfr.distance_m, sfl.distance_m


def _where(io: PhaseIO) -> str:
    return where(io.ctx, io.phase)


def _after_calibration(io: PhaseIO) -> None:
    if io.ctx.purpose == "descent":
        io.go(Phase.DESCENT_BACK_TO_EDGE)
    else:
        io.go(Phase.ASCENT_APPROACH)


def _check(io: PhaseIO) -> Speeds:
    cfg, ctx = io.cfg, io.ctx
    sfr, sfl = motion.pair(io.snap)
    if motion.far(sfr, cfg) and motion.far(sfl, cfg):
        if ctx.purpose != "start":
            io.fail(f"nothing ahead at {_where(io)}: SFR {sfr.distance_m:.3f} m, "
                    f"SFL {sfl.distance_m:.3f} m where a riser should be")
            return {}
        ctx.calibration_case = "1"
        io.info("calibration case 1: nothing ahead (SFR and SFL read at least "
                f"LENGTH_OF_INFINITY = {cfg.LENGTH_OF_INFINITY} m)", case="1")
        io.end("stopped", "nothing ahead: SFR and SFL read at least LENGTH_OF_INFINITY")
        return {}
    diff = sfl.distance_m - sfr.distance_m
    equal = abs(diff) <= cfg.algorithm.equal_tolerance
    if equal and ctx.purpose != "start":
        ctx.calibration_case = None
        _after_calibration(io)
        return {}
    ctx.calibration_case = "3" if equal else "2"
    io.info(f"calibration ({_where(io)}): SFR {sfr.distance_m:.3f} m, SFL {sfl.distance_m:.3f} m: "
            + ("equal, case 3" if equal else "not equal, case 2"),
            case=ctx.calibration_case, SFR=sfr.distance_m, SFL=sfl.distance_m)
    io.go(Phase.CAL_LIFT)
    return {}


def _lift_enter_targets(io: PhaseIO) -> dict[MotorId, float]:
    ctx, cfg = io.ctx, io.cfg
    ctx.return_mtf, ctx.return_mtb = ctx.entry_mtf, ctx.entry_mtb
    up = cfg.NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE
    limit = cfg.MAX_OF_VERTICAL_TURNS
    return {MotorId.MTF: min(up, limit - ctx.entry_mtf),
            MotorId.MTB: min(up, limit - ctx.entry_mtb)}


def _lifted(io: PhaseIO) -> None:
    io.ctx.turn_origin = io.snap.turns(MotorId.MWR)
    io.go(Phase.CAL_TURN if io.ctx.calibration_case == "2" else Phase.CAL_PROBE)


def _turned_too_far(io: PhaseIO) -> bool:
    made = abs(io.snap.turns(MotorId.MWR) - io.ctx.turn_origin)
    if motion.turn_yaw_rad(io.cfg, made) <= MAX_TURN_YAW_RAD:
        return False
    io.fail(f"calibration ({_where(io)}) turned {math.degrees(MAX_TURN_YAW_RAD):.0f}° "
            "without finding SFR = SFL")
    return True


def _turn_enter(io: PhaseIO) -> None:
    sfr, sfl = _readings(io)
    # SFL < SFR: the left side is nearer, turn left (the seed's case 2 rule).
    io.ctx.turn_direction = 1 if sfl < sfr else -1
    io.ctx.turn_diff = sfl - sfr


def _turn(io: PhaseIO) -> Speeds:
    ctx, cfg = io.ctx, io.cfg
    sfr, sfl = _readings(io)
    ctx.turn_diff = motion.smooth(ctx.turn_diff, sfl - sfr)
    # Turning left closes SFL - SFR from below, turning right from above: stop
    # when the smoothed difference has reached zero.
    remaining = -ctx.turn_direction * ctx.turn_diff
    if remaining <= 0.0:
        io.info(f"squared up: SFR {sfr:.3f} m, SFL {sfl:.3f} m", SFR=sfr, SFL=sfl)
        io.go(Phase.CAL_LOWER)
        return {}
    if _turned_too_far(io):
        return {}
    slow = min(1.0, max(TURN_SLOW_FLOOR, remaining / (2 * cfg.algorithm.equal_tolerance)))
    return motion.turn(ctx.turn_direction, cfg, slow)


def _probe_enter(io: PhaseIO) -> None:
    io.ctx.probe_sfr, io.ctx.probe_sfl = _readings(io)


def _probe(io: PhaseIO) -> Speeds:
    ctx, cfg = io.ctx, io.cfg
    sfr, sfl = _readings(io)
    d_sfr, d_sfl = sfr - ctx.probe_sfr, sfl - ctx.probe_sfl
    tol = cfg.algorithm.equal_tolerance
    made = abs(io.snap.turns(MotorId.MWR) - ctx.turn_origin)
    if abs(d_sfr) + abs(d_sfl) < 2 * tol and motion.turn_yaw_rad(cfg, made) < PROBE_YAW_RAD:
        return motion.turn(1, cfg)
    corner = d_sfr > 0 and d_sfl < 0 and d_sfr - d_sfl >= tol
    ctx.calibration_case = "3B" if corner else "3A"
    data = {"case": ctx.calibration_case, "dSFR": d_sfr, "dSFL": d_sfl}
    if corner:
        io.info(f"calibration case 3B: a corner (turning left, SFR grew {d_sfr * 1000:.1f} mm, "
                f"SFL shrank {-d_sfl * 1000:.1f} mm); turning on until both shrink", **data)
        ctx.probe_sfr = sfr
        io.go(Phase.CAL_CORNER)
    else:
        io.info(f"calibration case 3A: square to the riser (turning left, SFR changed "
                f"{d_sfr * 1000:+.1f} mm, SFL {d_sfl * 1000:+.1f} mm); turning back", **data)
        io.go(Phase.CAL_TURN)
    return {}


def _corner(io: PhaseIO) -> Speeds:
    ctx = io.ctx
    sfr, _sfl = _readings(io)
    ctx.probe_sfr = max(ctx.probe_sfr, sfr)  # the largest SFR seen while turning
    if sfr < ctx.probe_sfr - io.cfg.algorithm.equal_tolerance:
        io.info(f"case 3B: SFR shrinks again ({sfr:.3f} m): both see the riser")
        io.go(Phase.CAL_TURN)
        return {}
    if _turned_too_far(io):
        return {}
    return motion.turn(1, io.cfg)


def _lower_targets(io: PhaseIO) -> dict[MotorId, float]:
    ctx = io.ctx
    return {MotorId.MTF: ctx.return_mtf - ctx.entry_mtf,
            MotorId.MTB: ctx.return_mtb - ctx.entry_mtb}


def _lowered(io: PhaseIO) -> None:
    ctx, cfg = io.ctx, io.cfg
    if ctx.purpose == "start":
        if motion.measurable(io.snap, cfg):
            ctx.start_reading = motion.mean_distance(io.snap)
            io.info(f"start position: SFR/SFL read {ctx.start_reading:.3f} m",
                    start_reading=ctx.start_reading)
        if io.mode is Mode.CALIBRATE_ONLY:
            io.end("completed", "calibrate-only: calibration done")
            return
    _after_calibration(io)


HANDLERS: dict[Phase, Handler] = {
    Phase.CAL_CHECK: Handler(_check),
    Phase.CAL_LIFT: lift(_lift_enter_targets, _lifted),
    Phase.CAL_TURN: Handler(_turn, _turn_enter),
    Phase.CAL_PROBE: Handler(_probe, _probe_enter),
    Phase.CAL_CORNER: Handler(_corner),
    Phase.CAL_LOWER: lift(_lower_targets, _lowered),
}
