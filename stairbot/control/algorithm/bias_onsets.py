"""Onsets: one pair's readings, compensated for the motion the host knows,
whose difference steps because one of them moved and its partner held
(:mod:`~stairbot.control.algorithm.bias` says what follows from them).

A front sensor looks along the drive: its reading plus the odometer stays
put while the robot drives at a riser, and turning left lengthens SFL and
shortens SFR by front_lateral per radian of the odometer's yaw.  Where a
beam meets the world depends on more than that, near an edge: turning, each
beam may meet another wall, and while MTF lifts or lowers segment 1 in the
air a cone may see over a riser's top or stop doing so (the VL53L1X pair
before a 0.10 m riser).  Neither can be compensated, so a front step taken
while the heading or segment 1's height changed is no onset.  A back cone
looks down at the ground it passes over: turning sweeps it sideways, and
backing takes it over ground the robot has not stood on, where an edge
may be; a back step taken while the heading changed is no onset, nor is
one that lengthens a reading while segment 3 backed.  A back
sensor looks down: driving on a floor does not move what it reads, and
while MTB lifts segment 3 in the air its reading less MTB's travel stays
put.  The compensated readings' means over two windows a settle time apart
are compared: the pair's difference *steps* when they differ by more than
STEP_SIGMAS pair tolerances, and the windows' medians do as well (a spike
perception's median let through moves a mean, not a median); the step is
an onset of the sensor that moved if its partner held, and counts once the
next window bears it out (its mean level held).  Healthy, the back pair
reads alike: a back step that takes its difference back towards what the
onsets say, from further than a step from it, ends a disagreement (a cone
on a nosing, then off it) and begins no offset."""

from __future__ import annotations

import math
from collections.abc import Collection

from stairbot.control.algorithm.bias_evidence import Onset, Onsets, Sample, Step, Unconfirmed
from stairbot.control.algorithm.texts import bias as say
from stairbot.control.tolerances import pair_tolerance, settle_s
from stairbot.hardware import SensorId, SensorReading, SensorStatus, Snapshot
from stairbot.inputs.config import RobotConfig

MIN_WINDOW_TICKS = 5
"""The gap between the two windows whose means are compared spans the pair's
settle time (:func:`~stairbot.control.tolerances.settle_s`: the filter's
median comes round to a new level within it), and at least this many
ticks."""
WINDOW_SETTLES = 2.0
"""Each of the two windows spans this many settle times: long enough that
its mean is quieter than a tick by about the square root of the
measurements it holds."""
STEP_SIGMAS = 1.0
"""A step counts when the pair's difference moves by more than this many of
its pair tolerance (itself four sigmas of one tick's difference, so more
sigmas of two windows' means): a fault-free run must not take its noise for
an onset, and the next window must bear an onset out before it counts."""
MAX_ONSET_M = 0.08
"""A one-sided step larger than this is one sensor crossing an edge before its
partner (the back pair askew over a drop, a front cone over a riser): not
an onset.  (A bias as large is judged by the other evidence, or not at all.)"""
ATTRIBUTE_SHARE = 0.4
"""A step is one sensor's onset when its partner's compensated reading moved
less than this share of the step (or half the threshold, if more)."""
WARM_SETTLES = 3.0
"""A pair is watched from this many of its settle times into the run on."""
LEVEL_M = 0.01
"""A back sensor reads its mount height on a surface when it reads no more
than this over BACK_CLEARANCE: no drop in sight."""
STILL_M = 0.001
DRIVING_M = 0.0001
STILL_RAD = math.radians(0.2)

_OK, _OUT = SensorStatus.OK, SensorStatus.OUT_OF_RANGE


class PairWatch:
    """Finds one pair's onsets (:class:`Onsets` keeps them)."""

    def __init__(self, cfg: RobotConfig, right: SensorId, left: SensorId, back: bool) -> None:
        self._cfg = cfg
        ticks = max(MIN_WINDOW_TICKS, round(settle_s(cfg, back) / cfg.algorithm.tick))
        self.track = Onsets(right, left, back, round(WINDOW_SETTLES * ticks), ticks)
        self._warm = WARM_SETTLES * settle_s(cfg, back)
        """Robot time from which the pair is watched."""
        self._near = cfg.sensors.range(back)[0]
        self._infinity = cfg.LENGTH_OF_INFINITY
        self._lateral = cfg.sensors.front_lateral
        self._level_m = cfg.BACK_CLEARANCE + LEVEL_M
        self._least_step = STEP_SIGMAS * cfg.algorithm.equal_tolerance
        """No pair tolerance is less than equal_tolerance: a step below this is none."""

    def tick(self, snap: Snapshot, odometer: float, yaw: float, lifted_m: float,
             surface: bool, judged: Collection[SensorId]) -> None:
        """One tick (``surface``: for the back pair, segment 3 stands on a
        surface; ``lifted_m``: what the pair's lift moved its segment in the
        air, summed: MTB segment 3's, MTF segment 1's; the pair is not
        watched once one of it is ``judged``).  A back onset while the drive
        moved counts only if the sensor read its mount height before it, and
        its partner throughout."""
        track = self.track
        sensors, back = snap.sensors, track.back
        r, left = sensors[track.right], sensors[track.left]
        dr, dl = distance(r, self._near), distance(left, self._near)
        if dr is None or dl is None or track.right in judged or track.left in judged \
                or (not back and max(dr, dl) >= self._infinity):
            if track.pending is not None:  # a step seen before one of them stopped reading
                self._decide(track.pending)
            if track.unconfirmed is not None:
                self._confirm(True)
            track.clear()
            return
        if snap.time_s < self._warm:
            return  # the filter's first medians are of its first few measurements
        if not back:  # looking along the drive: plus the odometer, less the turn
            turn = self._lateral * yaw
            dr, dl = dr + odometer + turn, dl + odometer - turn
        else:  # looking down from segment 3: less what MTB lifted it
            dr, dl = dr - lifted_m, dl - lifted_m
        if back:  # each reads its mount height on a surface (no drop in sight)
            level_r = surface and r.distance_m <= self._level_m
            level_l = surface and left.distance_m <= self._level_m
        else:
            level_r = level_l = True
        moved = track.add((snap.time_s, dr, dl, odometer, yaw, r.status is not _OK,
                           left.status is not _OK, level_r, level_l, lifted_m))
        waiting = track.unconfirmed
        if waiting is not None and len(track.buf) == track.window:
            level = sum(x[2] - x[1] for x in track.buf) / track.window
            self._confirm(abs(level - waiting.level) <= waiting.share)
        if moved is None:
            return
        moved_r, moved_l = moved
        step = moved_l - moved_r
        pending = track.pending
        if pending is None and abs(step) <= self._least_step:
            return  # the common case, kept short
        near = min(r.distance_m, left.distance_m)
        threshold = STEP_SIGMAS * pair_tolerance(self._cfg, near, back=back)
        if abs(step) > threshold and (pending is None or abs(step) >= pending.size):
            # a step the windows' medians bear out: a spike perception's median
            # let through moves a window's mean, not its median
            right_m, left_m = track.moved_medians()
            if abs(left_m - right_m) > threshold:
                at = track.buf[track.window + track.gap // 2][0]
                track.pending = Step(abs(step), moved_r, moved_l, threshold, at)
            return
        if pending is not None:
            self._decide(pending)
            track.clear()  # the pair's new level is the next windows' first

    def _decide(self, step: Step) -> None:
        """Attribute a step to the sensor that moved, if its partner held; the
        onset counts once the next window bears it out (:meth:`_confirm`)."""
        track = self.track
        if step.size > MAX_ONSET_M:
            return  # one sensor crossed an edge before its partner: not a bias
        share = max(ATTRIBUTE_SHARE * step.size, step.threshold / 2)
        before, after = track.windows()
        if _turned(before + after) or not track.back and _lifted(track.across()):
            return  # the cones met the world elsewhere: the module docstring
        what = _motion(before, after)
        if abs(step.moved_right) <= share:
            near = any(s[6] for s in before) or any(s[6] for s in after)
            onset = Onset(track.left, step.moved_left, step.moved_right, step.at_s, what, near)
        elif abs(step.moved_left) <= share:
            near = any(s[5] for s in before) or any(s[5] for s in after)
            onset = Onset(track.right, step.moved_right, step.moved_left, step.at_s, what, near)
        else:
            return  # both moved: the world changed, or nobody can tell
        if track.back and onset.step_m > 0 and _backed(before + after):
            # backing, the cones pass over ground the robot has not stood on:
            # the one meeting an edge first reads longer, a bias or not
            return
        level = sum(s[2] - s[1] for s in before) / len(before)
        if track.back and _ended(level, level + step.moved_left - step.moved_right,
                                 track.offsets[track.left] - track.offsets[track.right],
                                 step.threshold):
            return
        mine, partner = (8, 7) if onset.sensor is track.left else (7, 8)
        if track.back and not (all(x[mine] for x in _driving(before))
                               and all(x[partner] for x in _driving(before) + _driving(after))):
            # segment 3 driven where a cone sees part of a drop: it crosses an
            # edge a little at a time, and the sensor nearer it moves first
            return
        track.unconfirmed = Unconfirmed(onset, level + step.moved_left - step.moved_right, share,
                                        step.threshold)

    def _confirm(self, held: bool) -> None:
        """Count the onset waiting for the next window if the pair's
        difference held at its new level there (``held``; or the pair stopped
        reading first: it may have)."""
        track = self.track
        waiting, track.unconfirmed = track.unconfirmed, None
        assert waiting is not None
        if held:
            track.record(waiting.onset, waiting.threshold)


def _ended(before: float, after: float, said: float, threshold: float) -> bool:
    """Whether the back pair's difference (left − right) stepped from
    ``before``, more than ``threshold`` from what its onsets say (``said``),
    back towards it (``after``): a disagreement the onsets do not explain
    ended -- one cone on a nosing or over part of an edge, then off it -- and
    no offset began.  Both look down at the surface segment 3 is over, so
    healthy they read alike."""
    return abs(before - said) > threshold and abs(after - said) < abs(before - said)


def _turned(samples: list[Sample]) -> bool:
    """Whether the heading changed over ``samples``: a front beam switching
    walls at a corner looks like a jump; the back cones sweep sideways over
    the ground, and near an edge one of them crosses it first."""
    yaws = [x[4] for x in samples]
    return max(yaws) - min(yaws) > STILL_RAD


def _lifted(samples: list[Sample]) -> bool:
    """Whether MTF moved segment 1, and the front cones, up or down in the air
    over ``samples`` (:meth:`Onsets.across`: where the step formed, and a
    settle time before it, the filter's lag): lifted a centimetre for the
    squaring turn a cone sees over a low riser, and lowered it meets it
    again (tests/test_vl53l1x_front.py).  A lift that ended a settle time
    before the step, or began after it, moved nothing the step saw."""
    lifts = [x[9] for x in samples]
    return max(lifts) - min(lifts) > STILL_M


def _backed(samples: list[Sample]) -> bool:
    """Whether the drive backed segment 3 (by more than STILL_M) over
    ``samples``: its cones passed over ground the robot has not stood on.
    Driving forward, they pass where segment 3's own wheels, and the rest of
    the robot, have been."""
    backed = sum(min(x[3] - y[3], 0.0) for x, y in zip(samples[1:], samples[:-1], strict=False))
    return backed < -STILL_M


def _driving(samples: list[Sample]) -> list[Sample]:
    """The ticks of ``samples`` on which the drive moved (by more than STILL_M
    over a second at 20 ms: DRIVING_M a tick)."""
    return [x for x, y in zip(samples[1:], samples[:-1], strict=False)
            if abs(x[3] - y[3]) > DRIVING_M]


def distance(r: SensorReading, near_m: float) -> float | None:
    """A reading's distance: OK, or too near to measure (its clamp, the
    nearest it can tell, ``near_m``); None for an error or nothing in range."""
    status = r.status
    if status is _OK:
        return r.distance_m
    if status is _OUT and r.distance_m <= near_m + 1e-9:
        return r.distance_m
    return None


def _motion(before: list[Sample], after: list[Sample]) -> str:
    """What the robot did between two windows, by the odometer, in words."""
    drove = sum(s[3] for s in after) / len(after) - sum(s[3] for s in before) / len(before)
    turned = sum(s[4] for s in after) / len(after) - sum(s[4] for s in before) / len(before)
    return say.motion(drove, turned, abs(drove) < STILL_M and abs(turned) < STILL_RAD)
