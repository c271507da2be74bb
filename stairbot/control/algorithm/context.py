"""The controller's context: the seed's variables under their seed names, the
run's progress (where the program stands, and what spans phases: the start
position, the step being descended, a landing, the standing rule's watch and
wait), and the present phase's own state: its family's
(:mod:`~stairbot.control.algorithm.families`) and its work
(:mod:`~stairbot.control.algorithm.work`).

Everything a phase needs to carry on is here, and motion targets are absolute
counter values (not "N more turns"), so a controller restored from
:meth:`Context.to_dict` -- or resumed after the standing rule's wait -- picks up
exactly where it stopped.
"""

from __future__ import annotations

import math
import types
from dataclasses import dataclass, field, fields, is_dataclass
from enum import Enum
from typing import Any, TypeVar, Union, get_args, get_origin, get_type_hints

from stairbot.control.algorithm import families, work
from stairbot.control.algorithm.families import Family
from stairbot.control.algorithm.limp import Limp
from stairbot.control.algorithm.modes import AscentEnd, Outcome
from stairbot.control.algorithm.phases import BY_VALUE
from stairbot.control.algorithm.work import Work
from stairbot.errors import InputError

F = TypeVar("F", bound=Family)
W = TypeVar("W", bound=Work)

TAB_SIZE = 20
"""Length of tab_length_to_edge, as the seed declares it."""


def _empty_tab() -> list[float | None]:
    return [None] * TAB_SIZE


def _empty_flags() -> list[bool | None]:
    return [None] * TAB_SIZE


CONTEXT_VERSION = 2
"""The shape of :meth:`Context.to_dict`; a journal names the version of the
contexts it holds, and one of another version is refused, not misread.
Version 1 was one flat table of every phase's scratch state."""


@dataclass
class StartPosition:
    """Where the program began and where its first calibration squared up:
    what descent 7 comes back to."""

    reading: float | None = None
    """Mean SFR/SFL reading when the first calibration ended: the start position."""
    wheel: float | None = None
    """The drive's odometer (turns) there."""
    home_wheel: float | None = None
    """The drive's odometer where the program began: where descent 7 returns
    to (the first calibration may have closed in on the riser before it
    squared up; its start position is then nearer the stairs)."""
    home_twist: float | None = None
    """The heading by the odometer where the program began: half of MWR's
    counter less MWL's (:func:`~stairbot.control.algorithm.motion.twist`).
    Descent 7 turns back to it before it backs the distance the first
    calibration closed in."""


@dataclass
class DescentStep:
    """The step being descended, across descent 1's back-off, its calibration
    and its backing up to the edge (and the narrow tread below, from descent
    5 on)."""

    edge_wheel: float | None = None
    """The odometer where the back pair crossed the edge of the step it
    stands on (where it read the drop, less how far the robot backed while
    the reading came through:
    :func:`~stairbot.control.algorithm.edge_measure.edge_sight_m`)."""
    edge_squared: bool = False
    """Continuous descent: the robot turned square to this step's edge by
    its back pair (once a step)."""
    turned_back: bool = False
    """Descent 1 has turned back to the climb's heading on this step (once);
    descent 7 to the floor's."""
    narrow_edge_wheel: float | None = None
    """Narrow steps: the odometer where the back pair crossed the edge of the
    narrow tread the robot steps down onto (descent 5 and on): what bounds
    descent 1's backing there, whatever the front pair reads."""


@dataclass
class Landing:
    """A quarter-turn landing ([algorithm] landings), from its scan to the
    way back down the first flight."""

    seen: bool = False
    """Landing 1 has scanned a landing (one a climb)."""
    right_m: float | None = None
    left_m: float | None = None
    """How far what SSR (SSL) saw at the landing stands from the robot's
    centre line, m (None: nothing in range)."""
    side: int = 0
    """The side the robot turned to: +1 left, -1 right (0: not turned)."""
    twist: float | None = None
    """The heading (odometer twist) the robot came up the first flight with:
    the way down turns back to it."""
    riser_m: float | None = None
    """What SFR/SFL read on the next flight's first riser, squared up where
    the robot turned: landing 3 backs to it."""
    step: int | None = None
    """0-based index of the next flight's first step (number_of_steps when
    the robot turned onto it); None: no landing turned at."""


@dataclass
class Watch:
    """The standing rule's watch of the present phase: made afresh whenever
    a phase is entered (the wait's and a resume's too)."""

    ticks: int = 0
    """Ticks in a row the watched pair has disagreed."""
    diff: float | None = None
    """The watched pair's smoothed difference (left − right)."""


@dataclass
class Pause:
    """The standing rule's wait: made when it stops the robot, gone when it
    resumes."""

    resume_phase: str
    """The phase it stopped in, resumed when the readings agree."""
    started_s: float
    diffs: list[float] = field(default_factory=list)
    """The watched pair's difference (left − right) on the wait's last ticks
    that gave one (MEDIAN_S of them): their median decides at its end."""


@dataclass
class Context:
    """The state of one run of the algorithm: the seed's variables under their
    seed names, the run's progress, and the present phase's own state (its
    family's and its work).  Plain data; :meth:`to_dict` is JSON-serialisable."""

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

    # -- the run's progress ----------------------------------------------------------
    phase: str = "cal_check"
    """Value of the present :class:`~stairbot.control.algorithm.phases.Phase`."""
    phase_started_s: float | None = None
    """When the present phase began (controller clock: Snapshot.time_s)."""
    from_top: bool = False
    """Continuous descent (:attr:`~stairbot.control.algorithm.phases.Mode.DESCEND`): the
    program began on the top of a flight it did not climb.  Its steps are
    counted from the top (number_of_steps stays 0); each step's
    tab_length_to_edge is read where descent 1 leaves segment 3 over its
    edge."""
    steps_descended: int = 0
    pauses: int = 0
    ascent_end: AscentEnd | None = None
    outcome: Outcome | None = None
    error: str | None = None
    end_reason: str | None = None
    """Why the program ended, whatever the outcome."""
    tread_length: list[float | None] = field(default_factory=_empty_tab)
    """Per step (0-based, as tab_length_to_edge): its tread as ascent 3
    measured it (None: not measurable, the top).  One shorter than
    LENGTH_OF_A_ROBOT + SAFE_LENGTH is a narrow step
    (``[algorithm] narrow_steps``): the robot does not fit on it."""
    climb_twist: list[float | None] = field(default_factory=_empty_tab)
    """Per step (0-based, as tab_length_to_edge): the heading by the odometer
    the robot climbed it with (where ascent 1's calibration left it).
    Descent 1 turns back to it, so that the way down retraces the way up."""
    second_by_turns: list[bool | None] = field(default_factory=_empty_flags)
    """Per step (0-based): ascent 6 drove segment 2 onto it by turns (a
    tread past FAR_TREAD_M, the top, or a riser out of the front pair's
    sight).  Descent 3 and 5 go by turns off it too."""
    third_in_air: bool = False
    """Narrow steps: segment 3 hangs in the air over the step below (it did
    not fit on the tread): it carries nothing, and the static-stability
    check leaves it out."""
    riser_wheel: float | None = None
    """The next riser by dead reckoning: the drive's odometer (turns) at which
    the front sensors would touch it, from the last readings that measured it
    (ascent 9's, then ascent 2's).  Ascent 2 starts from it when the sensors
    read "too near" (a sensor whose minimum range is more than what ascent 9
    leaves)."""
    start: StartPosition = field(default_factory=StartPosition)
    descent: DescentStep = field(default_factory=DescentStep)
    landing: Landing = field(default_factory=Landing)
    limp: Limp | None = None
    """Present once a sensor was lost and the robot limps home."""

    # -- the standing rule -----------------------------------------------------------
    watch: Watch = field(default_factory=Watch)
    pause: Pause | None = None

    # -- the present phase's own state ----------------------------------------------
    family: Family | None = None
    """The state of the present phase's family (None: the phase has none)."""
    work: Work = field(default_factory=Work)
    """The present phase's work: made afresh when a phase is entered; no
    other phase reads it."""

    @property
    def resume_phase(self) -> str | None:
        """The phase the standing rule's wait resumes (None: not waiting)."""
        return None if self.pause is None else self.pause.resume_phase

    def family_of(self, kind: type[F]) -> F:
        """The present family's state, which must be a ``kind``."""
        family = self.family
        assert isinstance(family, kind), f"{self.phase}: {family!r} is not a {kind.__name__}"
        return family

    def work_of(self, kind: type[W]) -> W:
        """The present phase's work, which must be a ``kind``."""
        work = self.work
        assert isinstance(work, kind), f"{self.phase}: {work!r} is not a {kind.__name__}"
        return work

    def to_dict(self) -> dict[str, Any]:
        """Plain data (JSON-serialisable) that :meth:`from_dict` restores."""
        data = _plain(self)
        assert isinstance(data, dict)
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "<context>") -> Context:
        """Restore a context saved with :meth:`to_dict` (and sent through JSON):
        every value as its field declares it -- a tuple from the list JSON
        made of it, a float from an int, an enum from its value, a work or a
        family as the class its ``kind`` names -- so that
        ``from_dict(to_dict())`` equals the original.

        Raises InputError naming the key when a key is unknown, a value has
        the wrong type, a number is not finite or beyond :data:`MAX_ABS`, a
        per-step list is not :data:`TAB_SIZE` long, the steps climbed are
        beyond it, more steps were descended than climbed, or ``phase`` (or
        the pause's ``resume_phase``) names no phase.
        """
        if not isinstance(data, dict):
            raise InputError(source, None, "a context must be a table")
        ctx = cls(**_values(cls, data, source, ""))
        for key in _PER_STEP:
            if len(getattr(ctx, key)) != TAB_SIZE:
                raise InputError(source, key, f"must be a list of {TAB_SIZE} numbers or nulls")
        phases: tuple[tuple[str, str | None], ...] = (
            ("phase", ctx.phase), ("pause.resume_phase", ctx.resume_phase))
        for key, name in phases:
            if name is not None and name not in BY_VALUE:
                raise InputError(source, key, f"{name!r} is not a phase")
        counts: tuple[tuple[str, int | None], ...] = (
            ("number_of_steps", ctx.number_of_steps), ("landing.step", ctx.landing.step))
        for key, value in counts:
            if value is not None and not 0 <= value <= TAB_SIZE:
                raise InputError(source, key, f"{value} is out of range; allowed: 0 to "
                                 f"{TAB_SIZE} (the steps a context has room for)")
        most = MAX_ABS if ctx.from_top else ctx.number_of_steps  # from the top: not climbed
        if not 0 <= ctx.steps_descended <= most:
            raise InputError(source, "steps_descended", f"{ctx.steps_descended} is out of "
                             f"range; allowed: 0 to {most:g} (number_of_steps)")
        return ctx


_PER_STEP = ("tab_length_to_edge", "climb_twist", "tread_length", "second_by_turns")
"""The context's lists with one entry per step (TAB_SIZE long)."""

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
        kinds = _KINDS.get(tp)
        if kinds is not None:  # a work or a family: the class its kind names
            value = dict(value)
            kind = value.pop("kind", None)
            if kind not in kinds:
                raise InputError(source, key + ".kind", f"{kind!r} is not a kind of "
                                 f"{tp.__name__}; allowed: " + ", ".join(kinds))
            tp = kinds[kind]
        return tp(**_values(tp, value, source, key + "."))
    if isinstance(tp, type) and issubclass(tp, Enum):
        try:
            return tp(value)
        except ValueError:
            raise wrong(f"{value!r} is not a {tp.__name__}; allowed: "
                        + ", ".join(repr(m.value) for m in tp)) from None
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


_KINDS: dict[type, dict[str, Any]] = {Work: work.KINDS, Family: families.KINDS}
"""The classes whose saved values name their kind: each one's registry."""


def _plain(value: Any) -> Any:
    """``value`` as plain data: a dataclass as a table of its fields (a work or
    a family with its ``kind``), an enum as its value, a list copied."""
    if is_dataclass(value) and not isinstance(value, type):
        out: dict[str, Any] = {}
        kind = getattr(value, "KIND", None)
        if kind is not None:
            out["kind"] = kind
        for f in fields(value):
            out[f.name] = _plain(getattr(value, f.name))
        return out
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, tuple):
        return tuple(_plain(v) for v in value)
    return value
