"""The state a family of phases shares: made when the program enters the
family, gone when it leaves it.  A family is a run of phases that hand each
other what they measured (calibration's lift, turns and lowering; ascent 3's
lift and its lowering; descent 2 and its refusal; a landing's scan, decision
and centring).  Each :class:`~stairbot.control.algorithm.phase.PhaseDef` names
its family's class (None: none).

The phase that enters a family may hand it its first state (a calibration's
purpose and the heading it turns to: ``Step.begin``); otherwise the family
begins with its defaults.  A saved family names its class (``kind``):
:data:`KINDS` restores it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from stairbot.control.algorithm.modes import CalibrationCase, Purpose

KINDS: dict[str, type[Family]] = {}
"""Every family's class by its name (``kind`` in a saved context)."""


@dataclass
class Family:
    """Base of the families' states."""

    KIND: ClassVar[str] = "Family"

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        cls.KIND = cls.__name__
        KINDS[cls.__name__] = cls


@dataclass
class Calibration(Family):
    """The calibration phases (squaring up, and every turn on segment 2's wheels)."""

    purpose: Purpose = Purpose.START
    """What this calibration is for."""
    turn_to: float | None = None
    """The heading (odometer twist) the calibration's odometer turn turns to;
    None: square up by the readings."""
    case: CalibrationCase | None = None
    """The case the check chose."""
    case_diff: float | None = None
    """SFL − SFR, the standing mean the check chose its case on: the
    squaring turn's bound starts from it."""
    squaring_turns: int = 0
    """Turns made to square up (by the readings, then by the odometer to
    correct what the check standing on all wheels found); while above 0, the
    check verifies the last one."""
    turn_origin: float = 0.0
    """MWR's counter when the calibration began turning: bounds the total turn."""
    return_mtf: float = 0.0
    return_mtb: float = 0.0
    """Lift counters before the clearance lift: where the lowering returns to."""
    chased: str | None = None
    """Descent 1: why the squaring turn was found chasing a front sensor's
    offset and turned back to the climbed heading
    (:mod:`~stairbot.control.algorithm.squaring_bias`); None: it was not."""
    checked: tuple[float, float, float] | None = None
    """SFR's and SFL's trimmed means standing, and the heading (odometer
    twist), at the check that chose the squaring turn's case."""
    verdict: tuple[str, str] | None = None
    """After :attr:`chased`, back on that heading: the front sensor whose
    reading there changed ("SFR", "SFL"), or "both" (neither can be named),
    with why in words; None: not judged yet."""
    beams_lost_rad: float | None = None
    """How far the last squaring turn had turned when it stopped with both
    beams reading nothing ahead (not one tick of its check standing still
    read both); None: it did not."""


@dataclass
class LiftFirst(Family):
    """Ascent 3: lift segment 1, number_of_vertical_turns more, or lower it
    again at an obstacle."""

    riser_gap: float | None = None
    """How far the front sensors stand from the riser when ascent 3 begins:
    the approach's last reading less what it drove after it (the sensors read
    "too near" there).  The tread is what they see past the riser less this."""
    return_mtf: float = 0.0
    """MTF's counter before ascent 3."""
    wall_ahead: bool = False
    """Segment 1 lifted its whole stroke and still saw what is ahead: a wall
    (or a riser too high), not a tread too short or a rise too low.  Only a
    wall may be a landing's."""


@dataclass
class LowerThird(Family):
    """Descent 2, and its refusal."""

    return_mtb: float = 0.0
    """MTB's counter where descent 2 began lowering."""
    refused: str | None = None
    """Why the drop below was refused."""


@dataclass
class LandingTurn(Family):
    """A landing's scan, its decision and the centring before the turn."""

    return_mtb: float = 0.0
    """MTB's counter before the scan's lift."""
    rise_m: list[float | None] = field(default_factory=lambda: [None, None])
    """The height at which SSR (SSL) saw over it: the next flight's first
    riser on the right (left), m; None: not seen over (a wall)."""
    open: list[int] = field(default_factory=list)
    """The sides that open onto a flight: +1 left, -1 right."""
    base_m: list[float | None] = field(default_factory=lambda: [None, None])
    """What SSR (SSL) read before the scan's lift (the median of its first
    SCAN_BASE_M), m; None: nothing."""
    depth_m: float | None = None
    """The landing's depth, from the edge behind to the wall ahead, m."""
