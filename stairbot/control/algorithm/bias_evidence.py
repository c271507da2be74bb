"""The evidence :class:`~stairbot.control.algorithm.bias.BiasWatch` judges a
biased sensor on, each kind kept as it comes, tick by tick:

* :class:`Onsets`: a pair's readings, compensated for the motion the host
  knows, whose difference *steps* because one of them moved and its partner
  held (the module docstring of :mod:`~stairbot.control.algorithm.bias`);
* :class:`MountHeights`: what each back sensor reads while segment 3 stands
  on a surface (BACK_CLEARANCE, the mount height, when it reads right);
* :class:`Reference`: where a riser stands by the drive's odometer, from
  the start position, or the tab_length_to_edge the ascent measured.
"""

from __future__ import annotations

import statistics
from collections import deque
from dataclasses import dataclass

from stairbot.hardware import SensorId

Sample = tuple[float, float, float, float, float, bool, bool, bool, bool, float]
"""(time, right, left, odometer m, yaw rad, right too near, left too near,
right level, left level, lifted m): one tick of a pair, its readings
compensated for the motion, whether each read too near to measure (its
clamp stands for it: a step it makes is at least what it says), (the back
pair) whether each read its mount height on a surface (no drop in sight),
and how far its lift has moved the pair's segment in the air, summed over
the run."""


@dataclass(frozen=True, slots=True)
class Onset:
    """One sensor's reading moved, by ``step_m`` (+ longer), more than the
    motion explains, while its partner's moved by ``partner_m``; ``motion``
    says what the robot did meanwhile, in words; ``at_least``: it read too
    near to measure on some of those ticks, and moved at least ``step_m``."""

    sensor: SensorId
    step_m: float
    partner_m: float
    at_s: float
    motion: str
    at_least: bool = False


@dataclass(frozen=True, slots=True)
class Step:
    """The largest step of a pair's difference seen since its last decision."""

    size: float
    moved_right: float
    moved_left: float
    threshold: float
    at_s: float


@dataclass(frozen=True, slots=True)
class Unconfirmed:
    """An onset found, waiting for the next window to bear it out: the pair's
    difference should hold at ``level``, within ``share``."""

    onset: Onset
    level: float
    share: float
    threshold: float


class Onsets:
    """One pair's compensated readings over two windows and the gap between
    them (running sums: a tick costs the same whatever the windows' length),
    and the onsets found, not cancelled."""

    __slots__ = ("right", "left", "back", "window", "gap", "size", "buf", "sums", "pending",
                 "unconfirmed", "found", "offsets", "at_least")

    def __init__(self, right: SensorId, left: SensorId, back: bool, window: int,
                 gap: int) -> None:
        self.right, self.left, self.back = right, left, back
        self.window, self.gap = window, gap
        self.size = 2 * window + gap
        self.buf: deque[Sample] = deque()
        self.sums = [0.0, 0.0, 0.0, 0.0]
        """The windows' sums: before right, before left, after right, after left."""
        self.pending: Step | None = None
        self.unconfirmed: Unconfirmed | None = None
        self.found: list[Onset] = []
        self.offsets = {right: 0.0, left: 0.0}
        """How far each sensor has moved by the onsets not cancelled, m."""
        self.at_least = {right: False, left: False}
        """Whether an onset of the sensor's was at least what it says."""

    def clear(self) -> None:
        self.buf.clear()
        self.pending = None

    def add(self, sample: Sample) -> tuple[float, float] | None:
        """Take one tick; once both windows are full, how far the right and
        the left sensor moved between their means."""
        buf, w, sums = self.buf, self.window, self.sums
        if len(buf) == self.size:
            old = buf.popleft()
            enters = buf[w - 1]  # from the gap into the first window
            leaves = buf[self.size - w - 1]  # from the second window into the gap
            sums[0] += enters[1] - old[1]
            sums[1] += enters[2] - old[2]
            sums[2] += sample[1] - leaves[1]
            sums[3] += sample[2] - leaves[2]
            buf.append(sample)
        else:
            buf.append(sample)
            if len(buf) < self.size:
                return None
            items = list(buf)
            sums[0] = sum(s[1] for s in items[:w])
            sums[1] = sum(s[2] for s in items[:w])
            sums[2] = sum(s[1] for s in items[-w:])
            sums[3] = sum(s[2] for s in items[-w:])
        return (sums[2] - sums[0]) / w, (sums[3] - sums[1]) / w

    def moved_medians(self) -> tuple[float, float]:
        """How far the right and the left sensor moved between the medians of
        the two windows: what :meth:`add`'s means say of a step that holds,
        but not of a spike that got through perception's median (three
        outliers among its five measurements stand for one measurement: in a
        window's mean a 0.5 m one moves it by 8 cm, in its median not at
        all).  Sorted on the ticks a step shows, not every tick."""
        before, after = self.windows()
        med = statistics.median
        return (med([s[1] for s in after]) - med([s[1] for s in before]),
                med([s[2] for s in after]) - med([s[2] for s in before]))

    def across(self) -> list[Sample]:
        """The ticks across which the step formed: the gap between the
        windows, the last settle time (``gap`` ticks) of the first window
        before it (the filtered readings lag the world by up to that), and
        one tick either side."""
        w, g = self.window, self.gap
        return list(self.buf)[max(0, w - g - 1):w + g + 1]

    def windows(self) -> tuple[list[Sample], list[Sample]]:
        items = list(self.buf)
        return items[:self.window], items[-self.window:]

    def record(self, onset: Onset, threshold: float) -> bool:
        """Keep ``onset``; False when it cancels what the pair's onsets said
        (its partner moved the same way: both saw the world change)."""
        self.found.append(onset)
        self.offsets[onset.sensor] += onset.step_m
        self.at_least[onset.sensor] |= onset.at_least
        if abs(self.offsets[self.left] - self.offsets[self.right]) < threshold:
            self.offsets = dict.fromkeys(self.offsets, 0.0)
            self.at_least = dict.fromkeys(self.at_least, False)
            self.found.clear()
            return False
        return True


MOUNT_TICKS = 50
"""What the back pair reads on a surface is the mean of its last this many
ticks there (1 s at the 20 ms tick), once it has as many."""

TAIL_TICKS = 10
"""A back sensor that read too near to measure for at least this many ticks
(0.2 s: six VL53L1X measurements, three HC-SR04 ones) at the end of its
stretch on a surface, its partner measuring throughout, went short there
though the second's mean says little of it (:attr:`MountHeights.tails`)."""

Tail = tuple[float, float]
"""(offset m, the partner's largest offset m): a sensor's trailing run of too
near readings on a surface, and how far its partner's readings strayed from
the mount height meanwhile."""


class MountHeights:
    """What SBR and SBL read, less BACK_CLEARANCE, over the last MOUNT_TICKS
    ticks segment 3 stood on a surface: their means, and whether the sensor
    read too near to measure on most of them (its mean is then at most what
    it says); and each sensor's trailing run of too near readings there.  A
    tick off a surface ends the stretch; what the last stretch long enough
    said is kept."""

    __slots__ = ("clearance", "ticks", "sums", "runs", "last", "tails")

    def __init__(self, clearance: float) -> None:
        self.clearance = clearance
        self.ticks: deque[tuple[float, float, bool, bool]] = deque()
        self.sums: list[float] = [0.0, 0.0, 0.0, 0.0]
        self.runs: list[list[float]] = [[0, 0.0, 0.0], [0, 0.0, 0.0]]
        """SBR's and SBL's current run of too near ticks, while the partner
        measured: (ticks, summed offset m, the partner's largest |offset| m)."""
        self.last: tuple[tuple[float, bool], tuple[float, bool]] | None = None
        """(offset m, read too near) of SBR and SBL."""
        self.tails: tuple[Tail | None, Tail | None] = (None, None)
        """SBR's and SBL's run of too near readings that ended the stretch
        :attr:`last` describes, if TAIL_TICKS long or more: its mean offset
        (what the clamp says: at least that short), and its partner's largest
        offset meanwhile."""

    def add(self, right: float, left: float, right_near: bool, left_near: bool) -> None:
        """One tick on a surface."""
        ticks, sums = self.ticks, self.sums
        sample = (right - self.clearance, left - self.clearance, right_near, left_near)
        ticks.append(sample)
        sums[0] += sample[0]
        sums[1] += sample[1]
        sums[2] += right_near
        sums[3] += left_near
        if len(ticks) > MOUNT_TICKS:
            old = ticks.popleft()
            sums[0] -= old[0]
            sums[1] -= old[1]
            sums[2] -= old[2]
            sums[3] -= old[3]
        for k, run in enumerate(self.runs):
            if sample[2 + k] and not sample[3 - k]:
                run[0] += 1
                run[1] += sample[k]
                run[2] = max(run[2], abs(sample[1 - k]))
            elif run[0]:
                run[:] = [0, 0.0, 0.0]
        n = len(ticks)
        if n >= MOUNT_TICKS:
            self.last = ((sums[0] / n, 2 * sums[2] > n), (sums[1] / n, 2 * sums[3] > n))
            right_tail, left_tail = ((run[1] / run[0], run[2]) if run[0] >= TAIL_TICKS else None
                                     for run in self.runs)
            self.tails = (right_tail, left_tail)

    def end(self) -> None:
        if self.ticks:  # none since the last end: nothing to reset
            self.ticks.clear()
            self.sums = [0.0, 0.0, 0.0, 0.0]
            self.runs = [[0, 0.0, 0.0], [0, 0.0, 0.0]]


@dataclass(frozen=True, slots=True)
class Reference:
    """Where the riser ahead of ``tread`` (0: the floor) stood: what the pair
    read there plus the drive's odometer, m, and the heading, rad."""

    position_m: float
    yaw_rad: float
    tread: int
