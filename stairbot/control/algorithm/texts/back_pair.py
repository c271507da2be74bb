"""Descent 2's back-pair evidence in words: a back sensor judged by the rise
it read on the way up (:mod:`~stairbot.control.algorithm.bias_rise`), and
segment 3 found standing on the step below by touch
(:mod:`~stairbot.control.algorithm.touchdown`)."""

from __future__ import annotations

from stairbot.control.algorithm.texts.bias import _cm, _past
from stairbot.hardware import SensorId


def judged_by_rise(sensor: SensorId, off_m: float, partner_off_m: float, step: int,
                   said_m: float) -> str:
    """At the standing rule's wait's end in descent 2: the rise below."""
    partner = SensorId.SBR if sensor is SensorId.SBL else SensorId.SBL
    return (f"judged biased (or stuck: the rise does not tell which): lowering segment 3 "
            f"over step {step + 1}'s edge, {sensor} reads "
            f"{_cm(off_m)} {'more' if off_m > 0 else 'less'} than at the end of that step's "
            f"ascent 7 less MTB's travel since, {partner} within "
            f"{abs(partner_off_m) * 1000:.1f} mm of it; {_past(sensor, partner, said_m)}")


def stood_by_touch(right_m: float, left_m: float, clearance: float, pushed_m: float) -> str:
    """Descent 2: segment 3 met the step below before the pair read BACK_CLEARANCE."""
    return (f"segment 3 stands on the step below: SBR/SBL stopped falling with MTB's travel "
            f"(they read {right_m:.3f}/{left_m:.3f} m, BACK_CLEARANCE {clearance:.3f} m: one "
            f"or both read long); MTB back up {pushed_m * 1000:.1f} mm, what it lowered since")


def apart_goes_on(right_m: float, left_m: float, median_m: float, allowance_m: float,
                  label: str) -> str:
    """Descent 2: the standing rule's wait ends with the back pair apart,
    within what descent 2 allows (:mod:`~stairbot.control.algorithm.back_apart`)."""
    return (f"standing rule: SBR/SBL still disagree after the wait ({right_m:.3f} m / "
            f"{left_m:.3f} m, {abs(median_m) * 1000:.0f} mm apart) in {label}, and nothing "
            f"names either; within what descent 2 allows ({allowance_m * 1000:.0f} mm, a "
            f"quarter of the lowest rise: both read the step below, and either still tells "
            f"the next edge's drop from its tread): lowering on until the longer reading "
            f"reads BACK_CLEARANCE or segment 3 is found standing by touch")
