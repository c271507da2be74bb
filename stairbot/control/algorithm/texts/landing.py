"""What a landing says: the scan for the next flight, the decision, the
turn and the way back (:mod:`~stairbot.control.algorithm.landing_scan`,
:mod:`~stairbot.control.algorithm.landing`)."""

from __future__ import annotations

import math


def _said(d: float | None) -> str:
    return "nothing in range" if d is None else f"{d:.3f} m"


# -- landing 1: scan, decide ------------------------------------------------------------
def side_sees_over(sensor: str, on_right: bool, base: float, seen_at: float) -> str:
    return (f"landing: {sensor} sees over what it saw on the {'right' if on_right else 'left'} "
            f"({base:.3f} m) with segment 3 lifted {seen_at:.3f} m, and "
            f"standing at the top: the next flight")


def side_not_back(sensor: str, on_right: bool, base: float, back: int, ticks: int) -> str:
    return (f"landing: {sensor} does not read again what it saw on the "
            f"{'right' if on_right else 'left'} ({base:.3f} m) with segment 3 lowered "
            f"where it read it ({back} of {ticks} readings): what it saw over was its "
            "reading moving, not the stairs (a sensor fault?); no flight on the "
            f"{'right' if on_right else 'left'}")


def no_next_flight(right: float | None, left: float | None) -> str:
    return ("landing: no next flight to either side (SSR "
            f"{_said(right)}, SSL {_said(left)}: walls, or nothing, that segment "
            "3's whole stroke does not see over)")


DEPTH_NOT_MEASURED = ("landing: its depth was not measured (neither the tread past the "
                      "last riser nor tab_length_to_edge read the wall ahead): no room to "
                      "turn is known")


def too_small(room: float, radius: float, margin: float,
              short: list[tuple[str, float | None]]) -> str:
    """``short``: each side (right, left, depth/2) with less than ``room``,
    and what it has."""
    return (f"landing too small to turn in: the robot's turning circle needs "
            f"{room:.3f} m from its centre on every side (radius "
            f"{radius:.3f} m + {margin} m), it has "
            + ", ".join(f"{name} {_said(have)}" for name, have in short))


def ascent_ends(why: str) -> str:
    return why + "; the ascent ends, the descent begins"


def next_flight(to_left: bool, depth: float, right: float, left: float) -> str:
    return (f"landing: the next flight is to the {'left' if to_left else 'right'}; "
            f"{depth:.3f} m deep, {right:.3f} m right and {left:.3f} m left of the centre: "
            "centring to turn")


# -- landing 2: centre, turn ------------------------------------------------------------
def centred(yaw_rad: float) -> str:
    return (f"centred on the landing: turning {math.degrees(yaw_rad):+.0f}° towards the "
            "next flight")


def onto_next_flight(steps: int) -> str:
    return f"turned onto the next flight: its steps count on from {steps + 1}"


def where_turned(riser_m: float) -> str:
    return (f"where it turned: SFR/SFL read {riser_m:.3f} m to the next flight's "
            "first riser")


# -- landing 3: back to where it turned -------------------------------------------------
BACK_WHERE_TURNED = "back where it turned: turning back to the first flight"
