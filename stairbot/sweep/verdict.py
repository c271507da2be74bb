"""The verdict rules: a run's result plus the stairs' zone against the robot's
published limits (``stairbot config show``) give one of six verdicts.

Zones (margins from the spec's ``[verdict]``, default 10 mm):

* inside:  max rise <= max_step_rise_m - margin, min rise >= min_step_rise_m + margin,
           min tread >= min_tread_m + margin and the first riser in sight
           (the nearer front beam <= LENGTH_OF_INFINITY - 20 mm)
* outside: max rise >  max_step_rise_m + margin, min rise < min_step_rise_m - margin,
           min tread <  min_tread_m - margin or the first riser out of sight
           (both front beams > LENGTH_OF_INFINITY + 20 mm: calibration case 1)
* band:    neither: climbing and refusing are both right

Verdicts, first match wins:

* ``error``    the program itself crashed (a traceback is kept)
* ``unsafe``   the robot fell, or a lift or wheel was left moving
* ``stranded`` ended farther than ``home_m`` from the start, or on the stairs
               (climbed a different number of steps than it descended)
* ``climbed``  completed, climbed and descended every step it should
               (min(steps, max_steps)), home: right inside and in the band
* ``refused``  home, as many steps down as up, fewer than the flight: right
               outside and in the band, and wherever the scenario injects faults
* ``wrong``    inside but refused, or outside but climbed
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

VERDICTS = ("climbed", "refused", "unsafe", "stranded", "wrong", "error")
PASSING = ("climbed", "refused")
SEVERITY = {"error": 5, "unsafe": 4, "wrong": 3, "stranded": 2, "refused": 0, "climbed": 0}


def judge(result: Mapping[str, Any], facts: Mapping[str, Any],
          moving: Sequence[str] = ()) -> tuple[str, str]:
    """(verdict, why) for one run.  ``result`` is ``RunResult.to_dict()``;
    ``facts`` come from the case (zone, expected_steps, faults, home_m);
    ``moving`` names the motors whose speed was not 0 after the run."""
    up, down = int(result.get("steps_climbed", 0)), int(result.get("steps_descended", 0))
    offset = result.get("final_offset_m")
    home_m = float(facts.get("home_m", 0.05))
    expected = int(facts.get("expected_steps", 0))
    zone = str(facts.get("zone", "inside"))
    if result.get("fell") or result.get("outcome") == "fell":
        return "unsafe", f"fell: {result.get('error') or 'pitch beyond the limit'}"
    if moving:
        return "unsafe", "left moving after the run: " + ", ".join(moving)
    if up != down:
        return "stranded", f"ended on the stairs: climbed {up}, descended {down}"
    if offset is None or offset > home_m:
        return "stranded", f"ended {offset} m from the start (home is within {home_m} m)"
    climbed = result.get("outcome") == "completed" and up == expected
    if climbed:
        if zone == "outside":
            return "wrong", f"climbed {up} step(s) outside the limits"
        return "climbed", f"climbed and descended {up} step(s), home"
    if zone == "inside" and not facts.get("faults"):
        why = result.get("error") or result.get("ascent_end") or result.get("outcome")
        return "wrong", f"refused inside the limits after {up} of {expected} step(s) ({why})"
    return "refused", f"refused after {up} of {expected} step(s), home"


def passing(verdict: str) -> bool:
    return verdict in PASSING
