"""What a search minimises: one margin of a run, or the smallest normalised one.

Each margin (``result.margins``, docs/envelope.md "Margins") is divided by a
length or angle of the robot that ran the case, so that margins of different
units compare:

* ``stability_m`` by half the middle segment's wheelbase
  (``LENGTH_OF_SECOND_MODULE / 2 - wheel_inset``): 1.0 is the robot balanced
  on its middle wheels with its centre of mass between them;
* ``edge_m`` by the wheel radius: 1.0 is a standing wheel's centre a radius
  past the nosing;
* ``stroke_m`` by the lift travel (``[motors] lift_travel``);
* ``pitch_deg`` by the supervisor's limit (``[safety] max_pitch_deg``).

The objective ``margin`` is the smallest of the normalised margins that are
not None; a named objective is that margin in its own unit.  A case whose
verdict does not pass (error, unsafe, wrong, stranded) scores
``FAILED - severity``, below every passing case whatever its margins: a
failure is what a search looks for.  A passing case with no value for the
objective (``edge_m`` on a run that never stood on a tread; every margin None
for ``margin``) scores None, "no information": the optimiser is told the
trial failed, so it learns neither to seek nor to avoid that region (calling
it the worst passing case would send the search into the stairs the robot
refuses, which hold no edge margin at all).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from stairbot.inputs.config import RobotConfig
from stairbot.sweep.spec import SpecError
from stairbot.sweep.verdict import SEVERITY, passing

MARGINS = ("stability_m", "edge_m", "stroke_m", "pitch_deg")
DEFAULT = "margin"
OBJECTIVES = (DEFAULT, *MARGINS)
FAILED = -1000.0
"""A failing case's score (less its verdict's severity): below any margin a
passing run can have, in any unit (no robot's stability margin is -1 km)."""


def check_objective(name: str) -> str:
    """``name`` if it is an objective, else a SpecError naming the allowed ones."""
    if name not in OBJECTIVES:
        raise SpecError("--objective", None, f"{name!r} is not an objective; allowed: "
                        f"{', '.join(OBJECTIVES)}")
    return name


def scales(config: RobotConfig) -> dict[str, float]:
    """What each margin is divided by for ``config``'s robot."""
    g = config.geometry
    return {
        "stability_m": g.LENGTH_OF_SECOND_MODULE / 2 - g.wheel_inset,
        "edge_m": g.wheel_radius,
        "stroke_m": config.motors.lift_travel,
        "pitch_deg": config.safety.max_pitch_deg,
    }


def normalised(margins: Mapping[str, Any], scale: Mapping[str, float]) -> float | None:
    """The smallest normalised margin that is not None (None: none is known)."""
    vals = [float(margins[k]) / scale[k] for k in MARGINS
            if margins.get(k) is not None and scale.get(k)]
    return min(vals) if vals else None


def score(record: Mapping[str, Any], objective: str,
          scale: Mapping[str, float]) -> float | None:
    """The value a search minimises for one finished case (module docstring)."""
    verdict = str(record.get("verdict"))
    if not passing(verdict):
        return FAILED - SEVERITY.get(verdict, 5)
    margins = (record.get("result") or {}).get("margins") or {}
    if objective == DEFAULT:
        return normalised(margins, scale)
    value = margins.get(objective)
    return None if value is None else float(value)
