"""The controller's context: the seed's variables under their seed names,
where the program stands, and the present phase's own working state
(:class:`~stairbot.control.algorithm.work.Work`).

Everything a phase needs to carry on is here, and motion targets are absolute
counter values (not "N more turns"), so a controller restored from
:meth:`Context.to_dict` — or resumed after the standing rule's wait — picks up
exactly where it stopped.
"""

from __future__ import annotations

import math
import types
from dataclasses import asdict, dataclass, field, fields, is_dataclass
from typing import Any, Union, get_args, get_origin, get_type_hints

from stairbot.control.algorithm.phases import BY_VALUE
from stairbot.control.algorithm.work import Work
from stairbot.errors import InputError

TAB_SIZE = 20
"""Length of tab_length_to_edge, as the seed declares it."""


def _empty_tab() -> list[float | None]:
    return [None] * TAB_SIZE


@dataclass
class Context:
    """The state of one run of the algorithm.  Plain data; JSON-serialisable."""

    # -- the seed's variables ----------------------------------------------------
    length_of_next_step: float | None = None
    """Total length of the next step, metres (None: not measurable, e.g. the top)."""
    number_of_vertical_turns: float = 0.0
    """Extra MTF turns past the point where the sensors see over the step."""
    number_of_turns_for_step_height: float = 0.0
    """Lift turns for the height of the present step (ascent 3, descent 2)."""
    number_of_steps: int = 0
    """Steps climbed."""
    tab_length_to_edge: list[float | None] = field(default_factory=_empty_tab)
    """Per step (0-based: the step's number before it was counted): the SFR/SFL
    reading at which segment 3 hangs over the edge; None when not measurable."""

    # -- where the program stands ---------------------------------------------------
    phase: str = "cal_check"
    """Value of the present :class:`~stairbot.control.algorithm.phases.Phase`."""
    purpose: str = "start"
    """What the calibration phases are doing: "start", "ascent", "descent", or
    "home" or "floor" (descent 7 lifts and lowers segments 1 and 3 to turn
    back to the heading the program began with, or crossed the floor with),
    or "edge" (a continuous descent turns square to the edge its back pair
    found)."""
    calibration_case: str | None = None
    """The first calibration's case: "1", "2", "3A" or "3B"."""
    start_reading: float | None = None
    """Mean SFR/SFL reading when the first calibration ended: the start position."""
    start_wheel: float | None = None
    """The drive's odometer (turns) there."""
    home_wheel: float | None = None
    """The drive's odometer where the program began: where descent 7 returns
    to (the first calibration may have closed in on the riser before it
    squared up, its start position is then nearer the stairs)."""
    home_twist: float | None = None
    """The heading by the odometer where the program began: half of MWR's
    counter less MWL's (:func:`~stairbot.control.algorithm.motion.twist`).  Descent 7
    turns back to it before it backs the distance the first calibration
    closed in."""
    tread_length: list[float | None] = field(default_factory=_empty_tab)
    """Per step (0-based, as tab_length_to_edge): its tread as ascent 3
    measured it (None: not measurable, the top).  One shorter than
    LENGTH_OF_A_ROBOT + SAFE_LENGTH is a narrow step
    (``[algorithm] narrow_steps``): the robot does not fit on it."""
    narrow_edge_wheel: float | None = None
    """Narrow steps: the odometer where the back pair crossed the edge of the
    narrow tread the robot steps down onto (descent 5 and on): what bounds
    descent 1's backing there, whatever the front pair reads."""
    third_in_air: bool = False
    """Narrow steps: segment 3 hangs in the air over the step below (it did
    not fit on the tread): it carries nothing, and the static-stability
    check leaves it out."""
    climb_twist: list[float | None] = field(default_factory=_empty_tab)
    """Per step (0-based, as tab_length_to_edge): the heading by the odometer
    the robot climbed it with (where ascent 1's calibration left it).
    Descent 1 turns back to it, so that the way down retraces the way up."""
    case_diff: float | None = None
    """SFL − SFR, the standing mean the last calibration check chose its case
    on: the squaring turn's bound starts from it."""
    turn_to: float | None = None
    """The heading (twist) the calibration's odometer turn is turning to."""
    squaring_turns: int = 0
    """Turns this calibration has made to square up (by the readings, then
    by the odometer to correct what the check standing on all wheels found);
    while above 0, the calibration's check verifies the last one."""
    steps_descended: int = 0
    from_top: bool = False
    """Continuous descent (:attr:`~stairbot.control.algorithm.phases.Mode.DESCEND`): the
    program began on the top of a flight it did not climb.  Its steps are
    counted from the top (number_of_steps stays 0); each step's
    tab_length_to_edge is read where descent 1 leaves segment 3 over its
    edge."""
    pauses: int = 0
    ascent_end: str | None = None
    """"top_reached" | "obstacle" | "step_limit" once the ascent has ended."""
    outcome: str | None = None
    error: str | None = None
    end_reason: str | None = None
    """Why the program ended, whatever the outcome."""

    # -- timers (controller clock: Snapshot.time_s) ---------------------------------
    phase_started_s: float | None = None
    pause_started_s: float | None = None
    resume_phase: str | None = None
    """The phase the standing rule stopped in, resumed when readings agree."""
    pause_diffs: list[float] = field(default_factory=list)
    """The watched pair's difference (left − right) on the standing rule's
    wait's last ticks that gave one (MEDIAN_S of them): their median decides
    at its end."""
    disagree_ticks: int = 0
    standing_diff: float | None = None
    """The standing rule's smoothed difference of the watched pair (left − right)."""

    # -- bookkeeping that spans phases ---------------------------------------------
    return_mtf: float = 0.0
    return_mtb: float = 0.0
    """Lift counters to come back to: before the calibration lift, before ascent 3
    (and where descent 2 began lowering MTB)."""
    turn_origin: float = 0.0
    """MWR counter when calibration began turning: bounds the total turn."""
    edge_wheel: float | None = None
    """Descent 1: the odometer where the back pair crossed the edge of the
    step it stands on (where it read the drop, less how far the robot
    backed while the reading came through:
    :func:`~stairbot.control.algorithm.edge.edge_sight_m`), backing
    off or backing up to it."""
    edge_squared: bool = False
    """Continuous descent: the robot turned square to this step's edge by
    its back pair (once a step)."""
    turned_back: bool = False
    """Descent 1 has turned back to the climb's heading on this step (once)."""
    riser_wheel: float | None = None
    """Ascent 9's estimate of the next riser: the drive's odometer (turns) at
    which the front sensors would touch it, dead reckoned from the last
    readings that measured it.  Ascent 2 starts from it when the sensors read
    "too near" (a sensor whose minimum range is more than what ascent 9
    leaves)."""
    riser_gap: float | None = None
    """How far the front sensors stand from the riser when ascent 3 begins:
    the approach's last reading less what it drove after it (the sensors read
    "too near" there).  The tread is what they see past the riser less this."""

    # -- quarter-turn landings ([algorithm] landings) -----------------------------
    wall_ahead: bool = False
    """Ascent 3 lifted segment 1 its whole stroke and still saw what is ahead:
    a wall (or a riser too high), not a tread too short or a rise too low.
    Only a wall may be a landing's."""
    landing_seen: bool = False
    """Landing 1 has scanned a landing (one a climb)."""
    landing_right_m: float | None = None
    landing_left_m: float | None = None
    """How far what SSR (SSL) saw at the landing stands from the robot's centre
    line, m (None: nothing in range)."""
    landing_rise_m: list[float | None] = field(default_factory=lambda: [None, None])
    """The height at which SSR (SSL) saw over it: the next flight's first
    riser on the right (left), m; None: not seen over (a wall)."""
    landing_open: list[int] = field(default_factory=list)
    """The sides that open onto a flight: +1 left, -1 right."""
    landing_depth_m: float | None = None
    """The landing's depth, from the edge behind to the wall ahead, m."""
    landing_side: int = 0
    """The side the robot turned to: +1 left, -1 right (0: not turned)."""
    landing_twist: float | None = None
    """The heading (odometer twist) the robot came up the first flight with:
    the way down turns back to it."""
    landing_riser_m: float | None = None
    """What SFR/SFL read on the next flight's first riser, squared up where the
    robot turned: landing 3 backs to it."""
    landing_step: int | None = None
    """0-based index of the next flight's first step (number_of_steps when the
    robot turned onto it); None: no landing turned at."""
    # -- the present phase's own working state ----------------------------------------
    work: Work = field(default_factory=Work)
    """Made afresh when a phase is entered; no other phase reads it."""

    def to_dict(self) -> dict[str, Any]:
        """Plain data (JSON-serialisable) that :meth:`from_dict` restores."""
        data = asdict(self)
        data["tab_length_to_edge"] = list(self.tab_length_to_edge)
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "<context>") -> Context:
        """Restore a context saved with :meth:`to_dict` (and sent through JSON):
        every value as its field declares it -- a tuple from the list JSON
        made of it, a float from an int -- so that ``from_dict(to_dict())``
        equals the original.

        Raises InputError naming the key when a key is unknown, a value has
        the wrong type, a number is not finite or beyond :data:`MAX_ABS`, a
        per-step list is not :data:`TAB_SIZE` long, the steps climbed are
        beyond it, more steps were descended than climbed, or ``phase`` (or
        ``resume_phase``) names no phase.
        """
        if not isinstance(data, dict):
            raise InputError(source, None, "a context must be a table")
        ctx = cls(**_values(cls, data, source, ""))
        for key in _PER_STEP:
            if len(getattr(ctx, key)) != TAB_SIZE:
                raise InputError(source, key, f"must be a list of {TAB_SIZE} numbers or nulls")
        for key in ("phase", "resume_phase"):
            value = getattr(ctx, key)
            if value is not None and value not in BY_VALUE:
                raise InputError(source, key, f"{value!r} is not a phase")
        for key in _STEP_COUNTS:
            value = getattr(ctx, key)
            if value is not None and not 0 <= value <= TAB_SIZE:
                raise InputError(source, key, f"{value} is out of range; allowed: 0 to "
                                 f"{TAB_SIZE} (the steps a context has room for)")
        most = MAX_ABS if ctx.from_top else ctx.number_of_steps  # from the top: not climbed
        if not 0 <= ctx.steps_descended <= most:
            raise InputError(source, "steps_descended", f"{ctx.steps_descended} is out of "
                             f"range; allowed: 0 to {most:g} (number_of_steps)")
        return ctx


_PER_STEP = ("tab_length_to_edge", "climb_twist", "tread_length")
"""The context's lists with one entry per step (TAB_SIZE long)."""

_STEP_COUNTS = ("number_of_steps", "landing_step")
"""Counts (or indices) of steps climbed: each indexes the per-step lists."""

MAX_ABS = 1e9
"""The largest magnitude a number in a context may have (counters in turns,
times in seconds, lengths in metres: an hour at a motor's top speed is a few
million turns)."""


def _values(cls: type, data: dict[str, Any], source: str, prefix: str) -> dict[str, Any]:
    """``data``'s values for the dataclass ``cls``, each restored to its
    field's declared type (InputError naming ``prefix`` + the key)."""
    hints = _hints(cls)
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key not in hints:
            raise InputError(source, prefix + key,
                             "unknown key; allowed: " + ", ".join(hints))
        out[key] = _restore(value, hints[key], source, prefix + key)
    return out


_HINTS: dict[type, dict[str, Any]] = {}


def _hints(cls: type) -> dict[str, Any]:
    if cls not in _HINTS:
        names = {f.name for f in fields(cls)}
        _HINTS[cls] = {k: v for k, v in get_type_hints(cls).items() if k in names}
    return _HINTS[cls]


def _restore(value: object, tp: Any, source: str, key: str, shown: str = "") -> Any:
    """``value`` (as JSON gave it) as a value of the type ``tp`` (named
    ``shown`` in messages, default its own name); InputError when it is not
    one."""
    def wrong(why: str = "") -> InputError:
        return InputError(source, key, why or f"{value!r} is not of type {shown or _name(tp)}")

    args = get_args(tp)
    if isinstance(tp, types.UnionType) or get_origin(tp) is Union:
        if value is None and type(None) in args:
            return None
        others = [a for a in args if a is not type(None)]
        if len(others) != 1:
            raise wrong()
        return _restore(value, others[0], source, key, shown or _name(tp))
    origin = get_origin(tp)
    if origin is list:
        if not isinstance(value, list):
            raise wrong()
        return [_restore(v, args[0], source, f"{key}[{i}]") for i, v in enumerate(value)]
    if origin is tuple:
        if not isinstance(value, list | tuple) or len(value) != len(args):
            raise wrong()
        return tuple(_restore(v, a, source, f"{key}[{i}]")
                     for i, (v, a) in enumerate(zip(value, args, strict=True)))
    if isinstance(tp, type) and is_dataclass(tp):
        if not isinstance(value, dict):
            raise wrong(f"must be a table of {tp.__name__}'s fields")
        return tp(**_values(tp, value, source, key + "."))
    if tp is bool:
        if not isinstance(value, bool):
            raise wrong()
        return value
    if tp is str:
        if not isinstance(value, str):
            raise wrong()
        return value
    if tp in (int, float):
        if isinstance(value, bool) or not isinstance(value, int | float) or (
                tp is int and not isinstance(value, int)):
            raise wrong()
        if not math.isfinite(value) or abs(value) > MAX_ABS:
            raise wrong(f"{value!r} is out of range; allowed: a finite number of at most "
                        f"{MAX_ABS:g} in magnitude")
        return tp(value)
    raise wrong()  # a field of a type this function does not know


def _name(tp: Any) -> str:
    return tp.__name__ if isinstance(tp, type) and not get_args(tp) else str(tp).replace(
        "NoneType", "None")
