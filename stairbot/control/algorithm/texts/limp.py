"""What a degraded stop and the limp home say
(:mod:`~stairbot.control.algorithm.limp`)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence


def _lifts(lifts: Mapping[str, float]) -> str:
    return ", ".join(f"{motor} {round(turns, 1) + 0.0:+.1f} turns"
                     for motor, turns in lifts.items())


def stopped_at(failed: str, label: str, where: str, lifts: Mapping[str, float],
               climbed: int, descended: int) -> str:
    """``failed``: what was lost and why ("SFR 3 measurements in a row report
    an error"); ``where``: the step (may be empty)."""
    at = f"{label} ({where})" if where else label
    return (f"degraded stop: {failed} in {at}; lifts {_lifts(lifts)}; {climbed} step(s) "
            f"climbed, {descended} descended: all motors stopped, lifts holding")


def limping(plan: str, survivors: Sequence[str], speed: float) -> str:
    """``plan``: what it does with the step in progress (:func:`plan`)."""
    stand_in = (", ".join(f"{s} for its pair" for s in survivors) + ", ") if survivors else ""
    return (f"limp home (consented): {plan}, on {stand_in}odometry and the IMU, at "
            f"{speed:.0%} speed")


def plan(kind: str, step: int, down: int) -> str:
    """What the limp home does from where the robot stands: ``kind`` "undo"
    (the step it lifts segment 1 onto), "finish" (the step it climbs),
    "turn_back" (before the step it approaches) or "down" (it was going
    down); ``step``: the step in progress (1-based); ``down``: the steps to
    go down after it."""
    head = {"undo": f"undoing step {step} (segment 1 lowered again), then ",
            "finish": f"finishing step {step}, then ",
            "turn_back": f"turning back before step {step}, then ",
            "down": "carrying on "}[kind]
    steps = (f"down the {down} step(s) climbed by the treads and tabs measured on the way "
             "up, then " if down else "")
    return f"{head}{steps}back to the start"


BY_THE_ODOMETER = ("back to the start by the odometer alone, turning by it to the floor's "
                   "and the start's headings, the front pair distrusted")
"""The plan where the front pair is distrusted (:mod:`~stairbot.control.algorithm.blind`)."""
DOWN_BLIND = ("down the steps climbed without the front pair (the back-off and descent 3 "
              "and 5 by the seed's turns, each step's heading as it was climbed by the "
              "odometer, the edges found by the back pair), then " + BY_THE_ODOMETER)
"""The plan where the front pair is distrusted on the stairs, going down."""
FINISH_BLIND = ("finishing the step by counts (the lifts by the step's height, ascent 6 by "
                "the seed's turns), then " + DOWN_BLIND)
"""The same plan from ascent 5 to 8."""


def squared_by_odometer(index: int, off_rad: float) -> str:
    return (f"descent 1, step {index + 1}: the front pair distrusted, squared by the "
            f"odometer to the heading it climbed this step with ({math.degrees(off_rad):+.2f}° "
            "off): backing up to the edge by the back pair alone")


def front_needed(why: str) -> str:
    """The standing rule's end where the front pair cannot be done without."""
    return (f"; neither front sensor can be named the wrong one, and the way home from "
            f"here needs the front pair ({why}): the remaining sensors cannot support a "
            "descent")


UNDO_FIRST = ("undoing step 1 by the odometer (segment 1 backed off the step to where ascent "
              "4 began and lowered again), then " + BY_THE_ODOMETER)
"""The same plan from ascent 4 of the first step."""
UNDO_BY_THE_ODOMETER = ("ascent 4, step 1: the front pair distrusted, backing segment 1 off "
                        "the step by the odometer to where ascent 4 began")

NO_CONSENT = ("it can come down on the sensors that remain, but only with the operator's "
              "consent; until then it stays stopped, lifts holding, or a person brings it "
              "down")

REOPENED = ("limp home (consented on resuming): the program stopped on a lost sensor goes "
            "on from where it stopped, on the sensors that remain")


def stranded(why: str) -> str:
    return f"it cannot come down on what remains ({why}): staying stopped, lifts holding"


def stand_ins(lost: Sequence[str]) -> str:
    """What a message says of the pair's readings while limping home."""
    pairs = {"SFR": "SFL", "SFL": "SFR", "SBR": "SBL", "SBL": "SBR"}
    said = [f"{s} reads {pairs[s]}'s value" for s in lost if pairs[s] not in lost]
    said += [f"{s} and {pairs[s]} distrusted" for s in ("SFR", "SBR") if s in lost
             and pairs[s] in lost]
    return " [limping: " + ", ".join(said) + "]"


def lost_sensor_end(failed: str, wait_s: float, label: str, then: str = "") -> str:
    """The reason the program ends with on a sensor error (lost for
    ``wait_s``; 0: judged biased, not waited for), or on a degraded stop it
    does not limp home from (``then``: what followed)."""
    held = f" for {wait_s:g} s" if wait_s > 0.0 else ""
    return f"sensor error: {failed}{held} in {label}" + (f"; {then}" if then else "")


def limp_down(steps: int) -> str:
    return (f"limp home: the ascent ends here; down the {steps} step(s) climbed"
            if steps else "limp home: the ascent ends here; back to the start")
