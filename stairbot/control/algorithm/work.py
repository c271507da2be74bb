"""A phase's own working state: one small dataclass per kind of phase, made
afresh when the phase is entered (not when the standing rule resumes it) and
gone when it ends.  Each :class:`~stairbot.control.algorithm.phase.PhaseDef`
names the class of its work.

Motion targets are absolute counter values, so a phase restored from a saved
context carries on exactly.  A saved work names its class (``kind``):
:data:`KINDS` restores it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, TypeVar

from stairbot.control.algorithm import motion
from stairbot.hardware import MotorId, SensorId, Snapshot

W = TypeVar("W", bound="Work")

_MTF, _MTB = MotorId.MTF, MotorId.MTB  # bound once: an enum's member is a slow look-up

KINDS: dict[str, type[Work]] = {}
"""Every class of work by its name (``kind`` in a saved context)."""


@dataclass
class Work:
    """What every phase keeps: the counters when it began, and the checks run
    once before its first step."""

    KIND: ClassVar[str] = "Work"

    entry_wheel: float = 0.0
    entry_mtf: float = 0.0
    entry_mtb: float = 0.0
    """Counters when the phase began."""
    balanced: bool = False
    """The static-stability check has run (before a lift phase's first step)."""
    checked: bool = False
    """The phase's entry condition has been checked (on its first step:
    :func:`~stairbot.control.algorithm.moves.checked_first`)."""

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        cls.KIND = cls.__name__
        KINDS[cls.__name__] = cls

    @classmethod
    def at_entry(cls: type[W], snap: Snapshot) -> W:
        """Fresh work for a phase entered at ``snap``."""
        return cls(entry_wheel=motion.wheel_position(snap), entry_mtf=snap.turns(MotorId.MTF),
                   entry_mtb=snap.turns(MotorId.MTB))


KINDS[Work.KIND] = Work


@dataclass
class LiftWork(Work):
    """A lift to absolute counters."""

    target_mtf: float | None = None
    target_mtb: float | None = None

    def lift_targets(self) -> dict[MotorId, float]:
        """The lift targets that are set."""
        out: dict[MotorId, float] = {}
        if self.target_mtf is not None:
            out[_MTF] = self.target_mtf
        if self.target_mtb is not None:
            out[_MTB] = self.target_mtb
        return out


@dataclass
class DriveWork(Work):
    """A drive that ends at a reading, or by turns
    (:func:`~stairbot.control.algorithm.moves.reading_drive`)."""

    target_wheel: float | None = None
    """Target for the mean of the four wheel counters."""
    target_reading: float | None = None
    """Mean SFR/SFL reading the drive ends at (None: a drive by turns only)."""
    reading_key: float | None = None
    """The mean SFR/SFL reading plus the odometer (m) -- constant while the
    sensors see the same surface: the median of its first KEY_TICKS values
    (``first_keys``), so one stray first reading does not set it."""
    first_keys: list[float] = field(default_factory=list)
    recent_keys: list[float] = field(default_factory=list)
    """Its last KEY_TICKS keys; the target is set from their median."""
    reading_lost: bool = False
    """The reading jumped away from what the wheels explain; the rest is
    driven by turns."""


@dataclass
class EdgeWork(DriveWork):
    """Descent 1's backing, and descent 5 onto a narrow tread: the drive, and
    the back pair's edge watch (:mod:`~stairbot.control.algorithm.edge`)."""

    edge_watch_s: float | None = None
    edge_watch_wheel: float | None = None
    """The last tick the watch looked at the back pair, and the odometer then."""
    edge_floor_s: float | None = None
    """The last tick the back pair read the floor while the watch looked (None:
    not yet, or not since it missed a stretch the robot moved through): a
    crossing is placed only after one."""
    edge_floor_at: float | None = None
    """Where the pair was, on the odometer, when its measurements last put it
    on the floor (:func:`~stairbot.control.algorithm.edge.floor_known_s`
    before that tick).  The crossing came after (backing: at a lower count)."""
    edge_recent: list[tuple[float, float]] = field(default_factory=list)
    """(time, odometer) on the watch's ticks, back as far as a floor reading
    can stand for."""
    edge_floor_held: bool = False
    """The watch missed a stretch since that floor reading, the robot standing
    through it (a hold stops every motor): the crossing lies between there
    and here."""
    edge_blind_until: float | None = None
    """After a stretch the watch missed (a tick that came late, a hold), what
    perception says of the pair until then still comes from measurements
    taken in it: a floor read before then does not count."""
    refind_from: float | None = None
    """Backing up to the edge: the odometer where the robot began driving
    forward to find the floor again (None: not doing that)."""
    refind_floor: int = 0
    edge_slow: bool = False
    """Found the floor again: backing up to the edge goes on at
    :func:`~stairbot.control.algorithm.edge_measure.slow_backing`."""
    """Ticks in a row the back pair has read the floor on that drive."""
    edge_first_wheel: float | None = None
    edge_first: SensorId | None = None
    """The odometer where one back sensor (named) first read the drop while
    the other still read the floor."""
    edge_stop: str | None = None
    """The watch found a reason to end the program (the step ends it with
    this error) ..."""
    edge_wrong: SensorId | None = None
    """... or, with this, a back sensor reading wrong (the step distrusts it
    for that reason: :func:`~stairbot.control.algorithm.edge.edge_stopped`)."""
    edge_distrusted: bool = False
    """The watch has judged one back sensor wrong in this phase (once)."""
    square_yaw: float | None = None
    """Continuous descent: the yaw (radians, + = turn left) that squares the
    robot up to the edge, from how far it backed between its two back
    sensors reading the drop: the step turns by it."""


@dataclass
class ApproachWork(Work):
    """Ascent 2's approach to SAFE_DISTANCE_IN_FRONT_OF_STEP."""

    still_since: float | None = None
    """When a beam began reading "nothing ahead" (the approach stands); once
    blocked, when the robot stood backed off the step."""
    riser_keys: list[float] = field(default_factory=list)
    """The mean reading plus the odometer, on its last RISER_KEYS ticks."""
    nearest_riser: float | None = None
    """The nearest the riser was placed on the odometer (turns): where it
    stands while the wheels carry the robot."""
    placings: list[float] = field(default_factory=list)
    """Where the riser was placed while it held (turns), one a place: each
    one more than HELD_M from the one before (the pair reads another surface)."""
    held_wheel: float | None = None
    """The odometer on the last tick the riser was placed near its nearest."""
    blocked_since: float | None = None
    """When the placed riser went away (the approach stands, then places the
    robot: :mod:`~stairbot.control.algorithm.blocked`)."""
    blocked_wheel: float | None = None
    """The odometer then."""
    went_m: float = 0.0
    """How far on the riser was placed then."""
    back_target: float | None = None
    """Where backing off the step ends, on the odometer."""
    level_keys: list[float] = field(default_factory=list)
    """Backed off and standing: the mean reading plus the odometer, a tick each."""


@dataclass
class ApproachTurnsWork(Work):
    """Ascent 2's last NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH."""

    target_wheel: float | None = None
    start_reading: float | None = None
    """How far the riser was when the phase began."""


@dataclass
class LiftFirstWork(LiftWork):
    """Ascent 3's lift of segment 1 until its sensors see over the riser."""

    still_since: float | None = None
    """When the lift stood at the top of its travel, not seeing over yet."""


@dataclass
class SightWork(LiftWork):
    """Ascent 3's lift past the sight-over."""

    sights: list[list[float]] = field(default_factory=lambda: [[], []])
    """SFR's and SFL's readings of the next riser over its second half (the
    tread is measured on their medians, not on one noisy reading)."""
    rise_rows: list[list[float]] = field(default_factory=lambda: [[], []])
    """SFR's and SFL's readings past the riser, in the order segment 1 rose
    (:mod:`stairbot.control.algorithm.long_tread`)."""


@dataclass
class WaitWork(Work):
    """A phase that may stand and wait (ascent 8)."""

    still_since: float | None = None


@dataclass
class StandingWork(Work):
    """Calibration's check: the pair measured standing still."""

    still_since: float | None = None
    """When the robot stopped to measure standing still."""
    diffs: list[float] = field(default_factory=list)
    """SFL − SFR, each tick standing still that gave one."""
    standing: list[tuple[float, float]] = field(default_factory=list)
    """SFR and SFL on those ticks."""
    diff_skipped: int = 0
    """Ticks standing still on which a reading of the pair gave no figure
    for the difference (an error, a dropout, nothing ahead)."""


@dataclass
class TurnWork(StandingWork):
    """The squaring turn (case 2): turning, then checking standing still."""

    measuring: bool = False
    """Stopped at SFR = SFL: measuring standing still."""
    turn_direction: int = 0
    """+1 left (counter-clockwise), -1 right."""
    turn_diff: float = 0.0
    """SFL − SFR, smoothed over a few ticks."""
    turn_flips: int = 0
    """How often a check standing still turned it back."""
    turn_from: float = 0.0
    turn_limit_rad: float = 0.0
    """MWR's counter at its start, and the most it may turn (what the
    readings at its start say, and a margin)."""
    turn_first: tuple[float, float] = (0.0, 0.0)
    """SFR's and SFL's readings at its start ..."""
    turn_held: tuple[bool, bool] = (True, True)
    """... whether each has read just that on every tick since ..."""
    turn_moved: tuple[float, float] = (0.0, 0.0)
    """... the most each has moved from it reading a distance ..."""
    turn_seen: tuple[float, float] = (0.0, 0.0)
    """... and the last distance each read."""
    distrusted: bool = False
    """A sensor that held its value through the turn was judged stuck."""


@dataclass
class AwayWork(Work):
    """Case 2W's turn away from the side wall."""

    flipped: bool = False
    """The pair has flipped (the other sensor is the nearer) at least once."""
    turn_direction: int = 0
    turn_diff: float = 0.0
    turn_from: float = 0.0


@dataclass
class ProbeWork(StandingWork):
    """Case 3's probe turn."""

    measured: bool = False
    """The start has been measured standing still."""
    probe_sfr: float = 0.0
    probe_sfl: float = 0.0
    """SFR/SFL when the probe began: their trimmed means standing still, lifted."""
    probe_recent: list[tuple[float, float]] = field(default_factory=list)
    """SFR/SFL on its last PROBE_TICKS ticks that gave both."""


@dataclass
class CornerWork(Work):
    """Case 3B's turn left until both readings shrink."""

    largest_sfr: float = 0.0
    """The largest SFR seen while turning."""


@dataclass
class LowerThirdWork(LiftWork):
    """Descent 2."""

    finishing: bool = False
    """The back pair reads BACK_CLEARANCE within its noise; the rest of the
    lowering goes by turns to ``target_mtb``."""
    mtb_recent: list[tuple[float, float]] = field(default_factory=list)
    """(time, MTB's counter) on the phase's ticks, back to the back pair's lag:
    how far segment 3 was lowered since what its filtered reading stands for."""
    touch_sums: list[tuple[float, float]] = field(default_factory=list)
    touch_lowest: tuple[float, float] | None = None
    touch_pitch: float | None = None
    """SBR's and SBL's readings plus MTB's travel over the last ticks, their
    lowest smoothed, and segment 2's pitch when the pair came near
    BACK_CLEARANCE: whether segment 3 stands on the step below though
    the pair reads it above BACK_CLEARANCE
    (:mod:`~stairbot.control.algorithm.touchdown`)."""
    apart: float | None = None
    """The back pair's disagreement the standing rule's wait ended on, within
    what descent 2 allows: it lowers on by the longer reading and by touch
    (:mod:`~stairbot.control.algorithm.back_apart`); None: by the mean."""


@dataclass
class RefuseWork(LiftWork):
    """Descent 2 refused: segment 3 up, then forward onto the step."""

    target_wheel: float | None = None


@dataclass
class ScanWork(LiftWork):
    """Landing 1's scan: segment 3 lifted, the side pair looking out."""

    lifted: bool = False
    """The lift is over: reading standing at the top."""
    still_since: float | None = None
    side_base: list[list[float]] = field(default_factory=lambda: [[], []])
    """What SSR and SSL read over segment 3's first SCAN_BASE_M of lift."""
    side_open: list[float | None] = field(default_factory=lambda: [None, None])
    """How far segment 3 had lifted when SSR (SSL) began reading past what
    it saw (None: not, or not for long)."""
    side_run: list[int] = field(default_factory=lambda: [0, 0])
    """Ticks in a row SSR (SSL) has read past what it saw."""
    side_top: list[int] = field(default_factory=lambda: [0, 0])
    """Ticks standing at the top on which SSR (SSL) read past it."""
    side_ticks: int = 0
    """Ticks read standing at the top."""


@dataclass
class RecheckWork(LiftWork):
    """Landing 1's lowering: segment 3 back down, the sides it saw over read
    again where they read before the lift."""

    still_since: float | None = None
    side_back: list[int] = field(default_factory=lambda: [0, 0])
    """Ticks standing lowered on which SSR (SSL) read what it read before the
    lift."""
    side_ticks: int = 0
    """Ticks read standing lowered."""
