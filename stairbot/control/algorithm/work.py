"""A phase's private working state (:class:`Work`)."""

from __future__ import annotations

from dataclasses import dataclass, field

from stairbot.control.algorithm import motion
from stairbot.hardware import MotorId, Snapshot


@dataclass
class Work:
    """A phase's private working state: made afresh each time a phase is
    entered (not when the standing rule resumes it), seen by no other phase.
    Motion targets are absolute counter values, so a phase restored from a
    saved context carries on exactly."""

    entry_wheel: float = 0.0
    entry_mtf: float = 0.0
    entry_mtb: float = 0.0
    """Counters when the phase began."""
    target_wheel: float | None = None
    """Target for the mean of the four wheel counters (drives)."""
    target_reading: float | None = None
    """Mean SFR/SFL reading a drive ends at (None: a drive by turns only)."""
    target_mtf: float | None = None
    target_mtb: float | None = None
    turn_direction: int = 0
    """Calibration turns: +1 left (counter-clockwise), -1 right."""
    turn_diff: float = 0.0
    """Calibration turns: SFL − SFR, smoothed over a few ticks."""
    turn_flips: int = 0
    """The squaring turn: how often a check standing still turned it back."""
    turn_from: float = 0.0
    turn_limit_rad: float = 0.0
    """The squaring turn: MWR's counter at its start, and the most it may turn
    (what the readings at its start say, and a margin)."""
    probe_sfr: float = 0.0
    probe_sfl: float = 0.0
    """SFR/SFL when the case-3 probe began: their trimmed means standing still,
    lifted (in case 3B: the largest SFR seen)."""
    probe_recent: list[tuple[float, float]] = field(default_factory=list)
    """The case-3 probe turn: SFR/SFL on its last PROBE_TICKS ticks that gave both."""
    reading_key: float | None = None
    """A reading drive: the mean SFR/SFL reading plus the odometer (m) --
    constant while the sensors see the same surface: the median of its first
    KEY_TICKS values (``first_keys``), so one stray first reading does not set it."""
    first_keys: list[float] = field(default_factory=list)
    recent_keys: list[float] = field(default_factory=list)
    """A reading drive: its last KEY_TICKS keys; the target is set from their median."""
    reading_lost: bool = False
    """A reading drive: the reading jumped away from what the wheels explain;
    the rest is driven by turns."""
    sights: list[list[float]] = field(default_factory=lambda: [[], []])
    """Ascent 3's lift past the sight-over: SFR's and SFL's readings of the
    next riser over its second half (the tread is measured on their medians,
    not on one noisy reading)."""
    rise_rows: list[list[float]] = field(default_factory=lambda: [[], []])
    """Ascent 3's lift past the sight-over: SFR's and SFL's readings past the
    riser, in the order segment 1 rose (:mod:`stairbot.control.algorithm.long_tread`)."""
    start_reading: float | None = None
    """A reading the phase measures from (the approach's last, the sight-over)."""
    diffs: list[float] = field(default_factory=list)
    """A pair difference, each tick standing still that gave one."""
    standing: list[tuple[float, float]] = field(default_factory=list)
    """SFR and SFL on those ticks."""
    diff_skipped: int = 0
    """Ticks standing still on which a reading of the pair gave no figure
    for the difference (an error, a dropout, nothing ahead)."""
    checked: bool = False
    """The phase's entry condition has been checked (on its first step)."""
    still_since: float | None = None
    """When the robot stopped to measure standing still (calibration)."""
    finishing: bool = False
    """Descent 2: the back pair reads BACK_CLEARANCE within its noise; the
    rest of the lowering goes by turns to ``target_mtb``."""
    balanced: bool = False
    """The static-stability check has run (before a lift phase's first step)."""
    edge_watch_s: float | None = None
    """Descent 1's edge watch: the last tick it looked at the back pair."""
    edge_floor_s: float | None = None
    """The last tick the back pair read the floor while the watch looked (None:
    not in this phase, or not since it missed a stretch): a crossing is
    placed only after one."""
    edge_blind_until: float | None = None
    """After a stretch the watch missed (a tick that came late, a hold), what
    perception says of the pair until then still comes from measurements
    taken in it: a floor read before then does not count."""
    refind_from: float | None = None
    """Descent 1, backing up to the edge: the odometer where the robot began
    driving forward to find the floor again (None: not doing that)."""
    refind_floor: int = 0
    """Ticks in a row the back pair has read the floor on that drive."""
    edge_first_wheel: float | None = None
    edge_first: str | None = None
    """Descent 1's edge watch: the odometer where one back sensor (named)
    first read the drop while the other still read the floor."""
    edge_stop: str | None = None
    """Descent 1's edge watch found a reason to end the program (the step
    wrapper ends it with this error)."""
    square_yaw: float | None = None
    """Continuous descent: the yaw (radians, + = turn left) that squares the
    robot up to the edge, from how far it backed between its two back
    sensors reading the drop: the step wrapper turns by it."""

    side_base: list[list[float]] = field(default_factory=lambda: [[], []])
    """Landing 1: what SSR and SSL read over segment 3's first SCAN_BASE_M of lift."""
    side_open: list[float | None] = field(default_factory=lambda: [None, None])
    """Landing 1: how far segment 3 had lifted when SSR (SSL) began reading
    past what it saw (None: not, or not for long)."""
    side_run: list[int] = field(default_factory=lambda: [0, 0])
    """Landing 1: ticks in a row SSR (SSL) has read past what it saw."""
    side_top: list[int] = field(default_factory=lambda: [0, 0])
    """Landing 1: ticks standing at the top on which SSR (SSL) read past it."""
    side_ticks: int = 0
    """Landing 1: ticks read standing at the top."""

    @classmethod
    def at_entry(cls, snap: Snapshot) -> Work:
        """Fresh work for a phase entered at ``snap``."""
        return cls(entry_wheel=motion.wheel_position(snap), entry_mtf=snap.turns(MotorId.MTF),
                   entry_mtb=snap.turns(MotorId.MTB))

    def lift_targets(self) -> dict[MotorId, float]:
        """The lift targets that are set."""
        out: dict[MotorId, float] = {}
        if self.target_mtf is not None:
            out[MotorId.MTF] = self.target_mtf
        if self.target_mtb is not None:
            out[MotorId.MTB] = self.target_mtb
        return out
