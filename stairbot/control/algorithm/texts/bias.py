"""What a sensor judged biased is said to have done
(:mod:`~stairbot.control.algorithm.bias`): the evidence, as far as the host
can know it (a reading that moved more than the motion explains, and the
pair's disagreement), never a cause."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from stairbot.hardware import SensorId

if TYPE_CHECKING:
    from stairbot.control.algorithm.bias_evidence import Onset


def _cm(m: float) -> str:
    return f"{abs(m) * 100:.1f} cm"


def motion(drove_m: float, turned_rad: float, still: bool) -> str:
    if still:
        return "the robot stood still"
    parts = []
    if abs(drove_m) >= 0.001:
        parts.append(f"drove {drove_m * 1000:+.0f} mm")
    if abs(math.degrees(turned_rad)) >= 0.2:
        parts.append(f"turned {math.degrees(turned_rad):+.1f}°")
    return "the robot " + (" and ".join(parts) if parts else "hardly moved") + " by the odometer"


def _onset(o: Onset) -> str:
    longer = "longer" if o.step_m > 0 else "shorter"
    size = f"at least {_cm(o.step_m)}" if o.at_least else _cm(o.step_m)  # read too near, clamped
    return (f"{o.sensor} read {size} {longer} from {o.at_s:.2f} s on, more than the "
            f"motion explains ({o.motion}), while its partner moved {o.partner_m * 1000:+.1f} mm")


def judged_at_once(onsets: Sequence[Onset], back: bool) -> str:
    """Where the robot steers by the pair: its onsets name the sensor."""
    steer = ("steering segment 3 by it would find the edge or the floor below where they are not"
             if back else "squaring up to the riser on it would leave the robot askew")
    return f"judged biased: {'; '.join(_onset(o) for o in onsets)}; {steer}"


def _past(sensor: SensorId, partner: SensorId, said_m: float) -> str:
    return (f"standing still, {sensor} reads {_cm(said_m)} {'more' if said_m > 0 else 'less'} "
            f"than {partner}")


def judged_by_onsets(onsets: Sequence[Onset], partner: SensorId, said_m: float) -> str:
    """At the standing rule's wait's end: the onsets that name the sensor."""
    sensor = onsets[0].sensor
    return (f"judged biased: {'; '.join(_onset(o) for o in onsets)}; "
            f"{_past(sensor, partner, said_m)}, as that says")


def judged_by_mount(sensor: SensorId, partner: SensorId, off_m: float, partner_off_m: float,
                    near: bool, said_m: float, clearance: float, tail: bool = False) -> str:
    """At the standing rule's wait's end: what the back pair read on a surface
    (``tail``: too near over the last ticks there, not most of its second)."""
    read = (f"read too near to measure ({_cm(off_m)} or more short of its mount height "
            f"{clearance:.3f} m){' as it left the surface' if tail else ''}" if near else
            f"read {_cm(off_m)} {'more' if off_m > 0 else 'less'} than its mount height "
            f"{clearance:.3f} m")
    return (f"judged biased: where segment 3 last stood on a surface, {sensor} {read} while "
            f"{partner} read it within {abs(partner_off_m) * 1000:.1f} mm; "
            f"{_past(sensor, partner, said_m)}, as that says")


def judged_mount_backing(sensor: SensorId, partner: SensorId, off_m: float,
                         partner_off_m: float, said_m: float, clearance: float,
                         drop: float) -> str:
    """Descent 1 backing off: a back sensor reading past where the edge watch
    reads the drop, as it read over the tread for the last second."""
    return (f"judged biased: over the last second segment 3 stood on the tread, {sensor} "
            f"read {_cm(off_m)} more than its mount height {clearance:.3f} m while {partner} "
            f"read it within {abs(partner_off_m) * 1000:.1f} mm; backing off, {sensor} reads "
            f"{_cm(said_m)} more than {partner}, past {drop:.3f} m, where the edge watch "
            f"reads a drop: backing to the edge by it would take the tread for the drop "
            f"(the step's drop, climbed, is a whole rise)")


def judged_flat_drop(sensor: SensorId, partner: SensorId, high_m: float, backed_m: float,
                     short_m: float, rise_m: float, step: int, drop: float) -> str:
    """Descent 1 backing off: a back sensor past the drop line, short of the
    step's climbed rise, over backing an edge's crossing would have ended."""
    return (f"judged biased: backing off, {sensor} read past {drop:.3f} m, where the edge "
            f"watch reads a drop, while {partner} read the floor, and held at most "
            f"{high_m:.3f} m over {backed_m * 1000:.0f} mm of backing; crossing an edge it "
            f"would read this step's rise, {rise_m:.3f} m as the pair read it climbing step "
            f"{step + 1} (above {short_m:.3f} m), within that backing: no edge explains it")


def judged_by_riser(sensor: SensorId, partner: SensorId, off_m: float, partner_off_m: float,
                    tread: int, said_m: float) -> str:
    """At the standing rule's wait's end: where the odometer puts the riser."""
    where = "the start position's reading" if tread == 0 else \
        f"tab_length_to_edge of step {tread}"
    return (f"judged biased: {sensor} reads {_cm(off_m)} {'more' if off_m > 0 else 'less'} "
            f"than the drive says ({where} and the odometer since), {partner} within "
            f"{abs(partner_off_m) * 1000:.1f} mm of it; {_past(sensor, partner, said_m)}")


def distrusted(disagree_m: float) -> tuple[str, str]:
    """At the standing rule's wait's end, nothing naming either sensor of the
    front pair (``disagree_m``: SFL less SFR): why SFR and why SFL are
    distrusted."""
    more = "SFL" if disagree_m > 0 else "SFR"
    return (f"distrusted: standing still, SFR and SFL still disagree by {_cm(disagree_m)} "
            f"({more} reads more) after the standing rule's wait, and no evidence names "
            "which of the two reads wrong",
            "distrusted with SFR: the front pair")
