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

A case that starts on the top of the flight (``start.on = "top"``: continuous
descent) is judged against the deepest drop the robot can lower instead:
inside it descends, outside it refuses (see :func:`judge_descent`).

Verdicts, first match wins:

* ``error``    the program itself crashed (a traceback is kept)
* ``unsafe``   the robot fell (during the run, or in the 2 s the simulation
               runs on after it), touched a wall it turned or drove into (a
               landing's: the simulation's top view), or a lift or wheel was
               left moving
* ``stranded`` ended farther than ``home_m`` from the start, or on the stairs
               (climbed a different number of steps than it descended)
* ``climbed``  completed, climbed and descended every step it should
               (min(steps, max_steps)), home: right inside and in the band
* ``refused``  home, as many steps down as up, fewer than the flight: right
               outside and in the band, and wherever the scenario injects faults
* ``came_home`` home, as many steps down as up, outcome ``came_home_degraded``:
               a sensor was lost on the stairs and the robot came down on the
               ones that remained (only where the scenario injects faults)
* ``wrong``    inside but refused, or outside but climbed
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

VERDICTS = ("climbed", "descended", "refused", "came_home", "unsafe", "stranded", "wrong",
            "error")
PASSING = ("climbed", "descended", "refused", "came_home")
SEVERITY = {"error": 5, "unsafe": 4, "wrong": 3, "stranded": 2, "refused": 0, "climbed": 0,
            "descended": 0, "came_home": 0}
FLOOR_CLEAR_M = 0.0
"""A continuous descent has reached the floor when the robot's front face
stands at least this far before the first riser (the whole robot off the
stairs)."""


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
    if result.get("fell_after"):
        return "unsafe", (f"fell after the run ended ({result.get('fell_after')}), which "
                          f"ended {result.get('outcome')}: {result.get('error') or ''}")
    if result.get("fell") or result.get("outcome") == "fell":
        return "unsafe", f"fell: {result.get('error') or 'pitch beyond the limit'}"
    if moving:
        return "unsafe", "left moving after the run: " + ", ".join(moving)
    if result.get("wall_contact"):
        return "unsafe", f"touched a wall: {result.get('wall_contact')}"
    if facts.get("from_top"):
        return judge_descent(result, facts)
    if up != down:
        return "stranded", f"ended on the stairs: climbed {up}, descended {down}"
    if offset is None or offset > home_m:
        return "stranded", f"ended {offset} m from the start (home is within {home_m} m)"
    if result.get("outcome") == "came_home_degraded":
        if not facts.get("faults"):
            return "wrong", f"limped home after {up} step(s) with no fault injected"
        return "came_home", f"a sensor lost: came home on the rest after {up} step(s)"
    climbed = result.get("outcome") == "completed" and up == expected
    if climbed:
        if zone == "outside":
            return "wrong", f"climbed {up} step(s) outside the limits"
        return "climbed", f"climbed and descended {up} step(s), home"
    if zone == "inside" and not facts.get("faults"):
        why = result.get("error") or result.get("ascent_end") or result.get("outcome")
        return "wrong", f"refused inside the limits after {up} of {expected} step(s) ({why})"
    return "refused", f"refused after {up} of {expected} step(s), home"


def judge_descent(result: Mapping[str, Any], facts: Mapping[str, Any]) -> tuple[str, str]:
    """A continuous descent that did not fall and left nothing moving:

    * ``descended`` completed, every step down, the whole robot on the floor:
                    right inside and in the band
    * ``refused``   stopped on the stairs (a drop deeper than it can lower):
                    right outside and in the band; and, wherever faults are
                    injected, stopped or ended with an error on the stairs
    * ``wrong``     outside but descended, or inside but refused
    * ``stranded``  any other end: an error on the stairs, or "the floor" found
                    before the flight's end
    """
    down, count = int(result.get("steps_descended", 0)), int(facts.get("count", 0))
    zone = str(facts.get("zone", "inside"))
    clear = result.get("clear_of_stairs_m")
    outcome = result.get("outcome")
    if outcome == "came_home_degraded" and down == count and clear is not None \
            and clear >= FLOOR_CLEAR_M and facts.get("faults"):
        return "came_home", f"a sensor lost: descended {down} step(s) on the rest"
    if outcome == "completed" and down == count and clear is not None \
            and clear >= FLOOR_CLEAR_M:
        if zone == "outside":
            return "wrong", f"descended {down} step(s) outside the limits"
        return "descended", f"descended {down} step(s), {clear:.2f} m clear of the stairs"
    why = result.get("error") or result.get("reason") or result.get("outcome")
    if facts.get("faults") and outcome in ("stopped", "error"):
        # a sensor that fails part way down: the robot stops where it stands
        return "refused", f"stopped after {down} of {count} step(s) on a sensor fault ({why})"
    if outcome == "stopped":
        if zone == "inside" and not facts.get("faults"):
            return "wrong", f"refused inside the limits after {down} of {count} step(s) ({why})"
        return "refused", f"refused after {down} of {count} step(s), stopped on the stairs"
    return "stranded", (f"ended after {down} of {count} step(s) down, "
                        f"{clear if clear is None else round(clear, 3)} m clear of the "
                        f"stairs ({why})")


def passing(verdict: str) -> bool:
    return verdict in PASSING
