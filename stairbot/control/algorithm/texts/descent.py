"""What the descent says: backing off and up to the edge, the back pair's
edge watch, lowering segment 3 onto the step below (or refusing the drop),
the steps descended and the way home
(:mod:`~stairbot.control.algorithm.back_off`,
:mod:`~stairbot.control.algorithm.edge`,
:mod:`~stairbot.control.algorithm.descent`,
:mod:`~stairbot.control.algorithm.homing`).  ``index`` is the step being
descended (0-based, into tab_length_to_edge); ``descended`` is
steps_descended, the steps from the top behind the robot so far."""

from __future__ import annotations

import math


# -- descent 1: back off, back up to the edge -------------------------------------------
def narrow_tab_unknown(index: int) -> str:
    return (f"descent 1: tab_length_to_edge[{index}] was not measured on "
            "a narrow step: the robot cannot be placed on a tread it does not fit on")


def edge_not_found(index: int, searched: float) -> str:
    return (f"descent 1: tab_length_to_edge[{index}] was not measured, and "
            f"SBR/SBL saw no edge backing {searched:.2f} m (the tread measured, or "
            "LENGTH_OF_INFINITY): the edge of the step cannot be found")


def not_on_top(searched: float, infinity: float) -> str:
    return (f"no edge behind: SBR/SBL read the floor for {searched:.2f} m "
            f"backing from the start (at most LENGTH_OF_INFINITY = "
            f"{infinity} m): not on the top of a flight")


def on_the_floor(searched: float, descended: int) -> str:
    return (f"on the floor, or a landing: no edge within {searched:.2f} m "
            f"behind step {descended} from the top, the last "
            "descended")


def turning_square_to_edge(yaw_rad: float) -> str:
    return f"turning {math.degrees(yaw_rad):+.1f}° square to the edge"


# -- descent 1: the edge watch ----------------------------------------------------------
def edge_askew(first: str, other: str, lag: float, most: float, max_yaw_rad: float) -> str:
    return (f"descent 1: {first} reads the drop, {other} still the floor "
            f"after backing {lag * 1000:.0f} mm more (at most {most * 1000:.0f} mm: "
            f"{math.degrees(max_yaw_rad):.0f}° from square to the edge): "
            "turned too far from the edge, the edge not straight, or a back "
            "sensor reading wrong")


def missed_crossing(first: str, lag: float, most: float, max_yaw_rad: float,
                    off_rad: float) -> str:
    return (f"stuck: still reads the floor {lag * 1000:.0f} mm after {first} read the "
            f"drop (more than {most * 1000:.0f} mm: {math.degrees(max_yaw_rad):.0f}° from "
            f"square), the robot square to the edge ({math.degrees(off_rad):+.1f}° from "
            "the heading the step was climbed with, by the odometer)")


def drop_read_first(first: str | None, lag: float, yaw_rad: float, square_yaw: float) -> str:
    return (f"{first} read the drop {lag * 1000:.0f} mm before the other: "
            f"{math.degrees(yaw_rad):.1f}° from square to the edge; turning "
            f"{'left' if square_yaw > 0 else 'right'} to square up")


NOT_SEEN_CROSSING = ("SBR/SBL read past the edge, but they were not seen crossing it: "
                     "driving forward until they read the floor again")


def sees_edge(reading: float, sight: float, more: float) -> str:
    return (f"SBR/SBL see the edge (read {reading:.3f} m, "
            f"about {sight * 1000:.0f} mm past it): backing at most {more:.3f} m more")


def floor_again(driven_m: float) -> str:
    return (f"SBR/SBL read the floor again {driven_m * 1000:.0f} mm forward: backing up "
            "to the edge")


def tread_shorter_than_robot(descended: int, driven_m: float) -> str:
    return (f"refused: SBR/SBL read past an edge from the start of step "
            f"{descended + 1} from the top, and still after "
            f"driving {driven_m * 1000:.0f} mm forward: the tread is shorter "
            "than the robot")


def floor_not_refound(driven_m: float, most: float) -> str:
    return (f"descent 1: SBR/SBL still read past the edge after driving "
            f"{driven_m * 1000:.0f} mm forward to find the floor again (at most "
            f"{most * 1000:.0f} mm): the edge of the step cannot be found")


# -- descent 2: lower segment 3 ---------------------------------------------------------
def not_over_an_edge(reading: float, back_clearance: float, index: int) -> str:
    return (f"floor not found: SBR/SBL read {reading:.3f} m, at or below BACK_CLEARANCE "
            f"({back_clearance} m), before segment 3 was lowered (step "
            f"{index + 1}): segment 3 is not over an edge")


def drop_too_deep(descended: int, depth: float, most: float) -> str:
    return (f"the drop below step {descended + 1} from "
            f"the top is {depth:.3f} m (SBR/SBL), deeper than segment "
            f"3 can be lowered ({most:.3f} m): refused")


def nothing_in_range_below(descended: int, reach: float, most: float) -> str:
    return (f"nothing within SBR/SBL's range below step "
            f"{descended + 1} from the top: the drop is "
            f"deeper than {reach:.3f} m, more than segment 3 can be "
            f"lowered ({most:.3f} m): refused")


def floor_beyond_stroke(descended: int, reading: float) -> str:
    return (f"floor not found below step {descended + 1} "
            f"from the top within MTB's stroke (-MAX_OF_VERTICAL_TURNS): "
            f"SBR/SBL read {reading:.3f} m: refused")


def floor_not_found(index: int, max_turns: float, reading: float) -> str:
    return (f"floor not found when descending step {index + 1}: MTB reached "
            f"-MAX_OF_VERTICAL_TURNS ({-max_turns:.0f}) and SBR/SBL "
            f"still read {reading:.3f} m")


def on_step_below(turns: float, where: str) -> str:
    return (f"segment 3 on the step below: number_of_turns_for_step_height = "
            f"{turns:.2f} ({where})")


def refused_drop(descended: int) -> str:
    return f"refused the drop below step {descended + 1}"


def back_on_the_step(why: str) -> str:
    return f"{why}; segment 3 raised again, the robot back on the step"


# -- descent 6-7: steps descended, the way home -----------------------------------------
def descended_from_top(descended: int) -> str:
    return f"step {descended} from the top descended"


def step_descended(steps: int, descended: int) -> str:
    return f"step {steps - descended + 1} descended ({descended} of {steps})"


BACK_AT_START = "back at the start position"


def off_floor_heading(off_rad: float) -> str:
    return (f"descent 7: turned {math.degrees(off_rad):+.2f}° from the heading it crossed the "
            "floor with (by the odometer); turning back to it")


BACK_WHERE_BEGAN = "back where the program began"

BY_THE_ODOMETER = ("descent 7: the front pair distrusted, back to the start position by the "
                   "odometer alone")
