"""What calibration says: its check, its turns and where it squared up
(:mod:`~stairbot.control.algorithm.calibration`,
:mod:`~stairbot.control.algorithm.turns`)."""

from __future__ import annotations

import math


# -- the check --------------------------------------------------------------------------
def off_climb_heading(index: int, off_rad: float) -> str:
    return (f"descent 1, step {index + 1}: turned {math.degrees(off_rad):+.2f}° "
            "from the heading it climbed this step with (by the odometer); turning "
            "back to it")


def nothing_ahead_where_riser(where: str, sfr: float, sfl: float) -> str:
    return (f"nothing ahead at {where}: SFR {sfr:.3f} m, "
            f"SFL {sfl:.3f} m where a riser should be")


def case_one(infinity: float) -> str:
    return ("calibration case 1: nothing ahead (SFR and SFL read at least "
            f"LENGTH_OF_INFINITY = {infinity} m)")


CASE_ONE_END = "nothing ahead: SFR and SFL read at least LENGTH_OF_INFINITY"


def closing_in(sfr: float, sfl: float, square_m: float) -> str:
    return (f"calibration (start): SFR {sfr:.3f} m, SFL {sfl:.3f} m: "
            f"farther than square_range_m ({square_m:.3f} m), where the "
            "front cones see over the first riser or the pair's noise allows only a loose "
            "square; closing in before squaring up")


def case_chosen(where: str, sfr: float, sfl: float, equal: bool, wall: bool,
                max_yaw_rad: float) -> str:
    said = ("equal, case 3" if equal else
            "too far apart for one riser within "
            f"{math.degrees(max_yaw_rad):.0f}°: the nearer sees a side wall, case 2W"
            if wall else "not equal, case 2")
    return f"calibration ({where}): SFR {sfr:.3f} m, SFL {sfl:.3f} m: {said}"


def nothing_ahead_squared(where: str, sfr: float, sfl: float) -> str:
    return (f"calibration ({where}): squared up, but standing on "
            f"all wheels SFR reads {sfr:.3f} m and SFL {sfl:.3f} m: at least one sees "
            "nothing ahead where the riser should be")


def square_on_all_wheels(diff: float, n: int, sfr: float, sfl: float) -> str:
    return (f"square on all wheels: SFL − SFR = {diff * 1000:+.1f} mm over {n} "
            f"readings standing still (SFR {sfr:.3f} m, SFL {sfl:.3f} m)")


def cannot_square(where: str, turns: int, diff: float, sfr: float, sfl: float) -> str:
    return (f"calibration ({where}) cannot square up: after "
            f"{turns} turns SFL − SFR still reads {diff * 1000:+.1f} mm "
            f"standing (SFR {sfr:.3f} m, SFL {sfl:.3f} m): the beams do not see one "
            "flat riser alike (a riser too low for them, or its edge)")


def not_square_on_all_wheels(diff: float, n: int, sfr: float, sfl: float,
                             yaw_rad: float) -> str:
    return (f"not square on all wheels: SFL − SFR = {diff * 1000:+.1f} mm over {n} "
            f"readings standing still (SFR {sfr:.3f} m, SFL {sfl:.3f} m): turning "
            f"{math.degrees(yaw_rad):+.1f}° by the odometer")


def start_position_standing(reading: float, ticks: int) -> str:
    return (f"start position: SFR/SFL read {reading:.3f} m (their means "
            f"over {ticks} ticks standing still)")


def start_position(reading: float) -> str:
    return f"start position: SFR/SFL read {reading:.3f} m"


CALIBRATE_ONLY_END = "calibrate-only: calibration done"


def closed_in(near: float | None) -> str:
    return f"closed in: SFR/SFL nearer reads {'nothing' if near is None else f'{near:.3f} m'}"


# -- the turns ----------------------------------------------------------------------------
def turned_too_far(where: str, limit_rad: float) -> str:
    return f"calibration ({where}) turned {math.degrees(limit_rad):.0f}° without finding SFR = SFL"


def turned_past_first_readings(where: str, made_rad: float, limit_rad: float) -> str:
    return (f"calibration ({where}) turned {math.degrees(made_rad):.0f}° "
            f"without finding SFR = SFL, more than the "
            f"{math.degrees(limit_rad):.0f}° its first readings allow: "
            "not squaring up to something other than the riser")


def held_through_turn(sensor: str, value: float, partner: str, first: float, now: float,
                      made_rad: float, gone: bool = False) -> str:
    went = f"went from {first:.3f} m to {now:.3f} m"
    if gone:
        went += " and then to nothing ahead (its beam turned off the riser)"
    return (f"stuck: read {value:.3f} m through a turn of {math.degrees(made_rad):.0f}° "
            f"on the spot while {partner} {went}")


def limp_turn_back(off_rad: float) -> str:
    return (f"limping home on one front sensor: turning {math.degrees(-off_rad):+.1f}° back "
            "to the heading the step was climbed with (by the odometer)")


def squared_up(diff: float, n: int, sfr: float, sfl: float) -> str:
    return (f"squared up: SFL − SFR = {diff * 1000:+.1f} mm over {n} readings "
            f"standing still (SFR {sfr:.3f} m, SFL {sfl:.3f} m)")


def turned_back_and_forth(where: str, flips: int, diff: float, sfr: float, sfl: float) -> str:
    return (f"calibration ({where}) turned back and forth "
            f"{flips} times without finding SFR = SFL: standing, "
            f"SFL − SFR reads {diff * 1000:+.1f} mm (SFR {sfr:.3f} m, SFL "
            f"{sfl:.3f} m); a beam may be off the flight's side, or one "
            "sensor reading long or short")


def case_3b(d_sfr: float, d_sfl: float) -> str:
    return (f"calibration case 3B: a corner (turning left, SFR grew {d_sfr * 1000:.1f} mm, "
            f"SFL shrank {-d_sfl * 1000:.1f} mm); turning on until both shrink")


def case_3a(d_sfr: float, d_sfl: float) -> str:
    return (f"calibration case 3A: square to the riser (turning left, SFR changed "
            f"{d_sfr * 1000:+.1f} mm, SFL {d_sfl * 1000:+.1f} mm); turning back")


def corner_shrinks(sfr: float) -> str:
    return f"case 3B: SFR shrinks again ({sfr:.3f} m): both see the riser"


def off_side_wall(sfr: float, sfl: float) -> str:
    return (f"case 2W: off the side wall, SFR {sfr:.3f} m and SFL {sfl:.3f} m see the "
            "riser; squaring up")


def away_too_far(where: str, max_rad: float, sfr: float, sfl: float) -> str:
    return (f"calibration ({where}) turned "
            f"{math.degrees(max_rad):.0f}° away from the side wall and the "
            f"readings still do not fit one riser (SFR {sfr:.3f} m, SFL {sfl:.3f} m)")


CASE_ONE_CLOSED_IN = ("nothing ahead after closing in: the riser closed in on is below the "
                      "beams; back to where the program began")
