"""What the ascent says: its approach, lifting segment 1 over the riser and
measuring the tread, the tab and the top
(:mod:`~stairbot.control.algorithm.ascent`,
:mod:`~stairbot.control.algorithm.lift_first`).  ``steps`` is
number_of_steps, the steps climbed so far: the one being climbed is
``steps + 1``."""

from __future__ import annotations

import math


# -- ascent 2: the approach -------------------------------------------------------------
def riser_lost(steps: int, sfr: float, sfl: float, wait_s: float) -> str:
    return (f"riser lost during the approach (step {steps + 1}): "
            f"SFR {sfr:.3f} m, SFL {sfl:.3f} m, nothing ahead "
            f"for {wait_s:g} s")


def below_the_sensors(steps: int, front_height: float, went_m: float,
                      slip_m: float | None) -> str:
    slipped = "" if slip_m is None else (
        f"; the wheels slipped {slip_m:.3f} m" if slip_m > 0 else "; the wheels did not slip")
    return (f"step {steps + 1} is below the front sensors ({front_height:.3f} m up): "
            f"driving on, the riser they read went {went_m:.3f} m further away{slipped}; "
            "the ascent ends (obstacle)")


def at_riser(gap: float) -> str:
    return f"at the riser: {gap:.3f} m from it"


# -- ascent 3: lift segment 1 -----------------------------------------------------------
def sees_over(steps: int, lifted: float, rise: float, sfr: float, sfl: float) -> str:
    return (f"segment 1 sees over step {steps + 1} after {lifted:.1f} MTF turns "
            f"(rise about {rise:.3f} m): SFR/SFL read {sfr:.3f}/{sfl:.3f} m")


def too_low_to_climb(steps: int, rise: float, min_rise: float) -> str:
    return (f"step {steps + 1} is too low to climb: rise about {rise:.3f} m < "
            f"{min_rise:.3f} m (lifting on, the sensors could see past "
            "the next riser); the ascent ends (obstacle)")


RISE_TOO_LOW = "rise lower than the robot measures"


def too_high(steps: int, allowed: float) -> str:
    return (f"step {steps + 1} too high: the front sensors did not see over "
            f"it within {allowed:.1f} MTF turns; the ascent ends (obstacle)")


def tread_ahead(steps: int, tread: float | None, gap: float) -> str:
    ahead = "nothing ahead" if tread is None or tread == float("inf") \
        else f"tread {tread:.3f} m"
    return f"step {steps + 1}: {ahead} (the reading less {gap:.3f} m to the riser)"


def tread_too_short(steps: int, tread: float, need: float) -> str:
    return (f"the tread of step {steps + 1} is too short: {tread:.3f} m < "
            f"min_tread_m = {need:.3f} m; the ascent ends (obstacle)")


TREAD_TOO_SHORT = "tread shorter than min_tread_m"


def too_low_for_tread(steps: int, rise: float, min_rise: float, cone_top_rad: float,
                      tread: float) -> str:
    return (f"step {steps + 1} is too low for its tread: rise about {rise:.3f} "
            f"m < {min_rise:.3f} m (the front cone's top, "
            f"{math.degrees(cone_top_rad):.1f}° up, would see over the next riser "
            f"{tread:.3f} m away); the ascent ends (obstacle)")


TOO_LOW_FOR_TREAD = "rise too low for the tread the front cone measures"


def narrow_step(steps: int, tread: float) -> str:
    return (f"step {steps + 1} is narrow: tread {tread:.3f} m < "
            f"LENGTH_OF_A_ROBOT + SAFE_LENGTH: segment 3 stays in the air over the step "
            "below until segment 1 is on the next (narrow_steps)")


def step_height(turns: float, steps: int) -> str:
    return f"number_of_turns_for_step_height = {turns:.2f} (step {steps + 1})"


def too_few_readings(steps: int, lift_m: float) -> str:
    return (f"step {steps + 1}: too few readings past the riser over the "
            f"last {lift_m * 1000:.0f} mm of lift to tell whether they held")


def readings_held(steps: int, reading: float, moved: float, lift_m: float, held: bool,
                  limit: float) -> str:
    return (f"step {steps + 1}: the front pair's readings of the riser "
            f"{reading:.3f} m ahead moved {moved * 1000:.0f} mm as segment 1 rose "
            f"{lift_m * 1000:.0f} mm ({'within' if held else 'more than'} "
            f"{limit * 1000:.0f} mm): "
            + ("a wall, or a riser the whole cone sees" if held
               else "the cone sees over it"))


def length_of_next_step(length: float, far: bool, far_tread_m: float) -> str:
    return (f"length_of_next_step = {length:.3f} m"
            + (f" (past FAR_TREAD_M = {far_tread_m} m: the drives onto the step "
               "go by turns)" if far else ""))


def riser_out_of_sight(steps: int, riser: float, pitch_deg: float, sight_m: float) -> str:
    return (f"step {steps + 1}: the next riser, {riser:.3f} m ahead, is beyond where the "
            f"front pair meets the tread at pitch {pitch_deg:+.1f}° ({sight_m:.3f} m): the "
            "pair would read the tread; the drive goes by turns")


LENGTH_NOT_MEASURABLE = ("length_of_next_step not measurable (nothing ahead within "
                         "LENGTH_OF_INFINITY): driving "
                         "NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE turns")


# -- ascent 7-8: the tab, the top -------------------------------------------------------
TIPPING_BACK = "tipping back off the step"
"""How the reason of ascent 7's pitch stop begins (as "unstable lift", "tilt")."""
TIPPING_BACK_EDGE = "segment 2 pitches nose up past LIFT_THIRD_MAX_PITCH_DEG"
"""Its condition on ascent 7's edge to the error, in the flowcharts."""


def tipping_back(steps: int, pitch_deg: float, limit_deg: float) -> str:
    return (f"{TIPPING_BACK}: segment 2 pitches {pitch_deg:+.1f}° nose up while segment 3 "
            f"rises (ascent 7, step {steps + 1}), more than the {limit_deg:+g}° a robot on "
            "the step levels to: segment 2 is not on the step, its rear over the nosing, and "
            "lifting segment 3 on would tip the robot back over the edge; every motor "
            "stopped, lifts holding")


def tab_length(i: int, tab: float) -> str:
    return f"tab_length_to_edge[{i}] = {tab:.3f} m"


def tab_not_measurable(i: int, distrusted: bool = False) -> str:
    """``distrusted``: the front pair (:mod:`~stairbot.control.algorithm.blind`)."""
    why = "the front pair distrusted" if distrusted else "nothing ahead"
    return (f"tab_length_to_edge[{i}] not measurable ({why}): the descent of this "
            "step drives by turns")


def number_of_steps(steps: int) -> str:
    return f"number_of_steps = {steps}"


def top_reached(steps: int) -> str:
    return (f"top reached after {steps} steps: SFR/SFL read at least "
            "LENGTH_OF_INFINITY; the descent begins")


def top_beside(steps: int, near: str, sfr: float, sfl: float, one_riser: float,
               wait_s: float) -> str:
    far = "SFL" if near == "SFR" else "SFR"
    return (f"top reached after {steps} steps: SFR/SFL read {sfr:.3f}/{sfl:.3f} m for "
            f"{wait_s:g} s, {far} nothing ahead; {near} reads more than both beams on one "
            f"riser can differ ({one_riser * 1000:.0f} mm) short of LENGTH_OF_INFINITY, and "
            f"ascent 3 measured no riser ahead: {near} sees no riser (a side wall at a graze); "
            "the descent begins")


def step_limit(max_steps: int) -> str:
    return f"number_of_steps reached {max_steps}: the ascent ends; the descent begins"


def tab_read_standing(i: int, tab: float) -> str:
    return (f"tab_length_to_edge[{i}] = {tab:.3f} m (read standing at "
            "ascent 8: ascent 7 read nothing ahead)")


def tab_not_measured(i: int, sfr: float, sfl: float, wait_s: float) -> str:
    return (f"tab_length_to_edge[{i}] not measured: SFR/SFL read {sfr:.3f}/"
            f"{sfl:.3f} m for {wait_s:g} s, not both a riser nor both nothing "
            "ahead; going on (the descent of this step finds its edge by the back pair alone)")
