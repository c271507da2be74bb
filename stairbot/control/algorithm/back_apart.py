"""Descent 2 with the back pair a little apart (not in the seed, which has no
sensor faults): the standing rule's wait ends with SBR and SBL still
disagreeing, nothing names either (:mod:`~stairbot.control.algorithm.bias`),
and the disagreement is within :func:`allowance_m`.  Descent 2 goes on with
the pair instead of ending the program.

What descent 2 needs of the pair is where the step below is, not that the
two agree to their noise.  The standing tolerance is what the pair's noise
says two readings of one surface may differ by; it is no bound on what the
descent can bear, and it differs by a factor of two between the shipped
robots: the reference robot's VL53L0X pair lowers on with 2.6 cm between
its sensors at 0.18 m, the quieter HC-SR04 pair stops at 1.3 cm, where
its 3 mm resolution and noise are too coarse for the rise read on the way
up to name a sensor reading 1 cm long.  A disagreement of a
quarter of the lowest rise the robot climbs:

* cannot be the two sensors over two surfaces of the flight: the nearest
  other surface below segment 3 is another tread, a whole rise away;
* leaves the next edge watch its margin: a sensor that far off reads the
  tread a quarter of the lowest rise from BACK_CLEARANCE, and the drop is
  read half the lowest rise past it
  (:func:`~stairbot.control.algorithm.edge_measure.edge_drop_m`).

Where the two differ, one of them reads the step below too near or too far,
and which is not known, so the rest of descent 2 trusts neither to say
segment 3 has arrived before it has: it lowers until the *longer* reading
reads BACK_CLEARANCE (segment 3 is never left hanging above the step by a
sensor reading short), or until segment 3 is found standing by touch
(:mod:`~stairbot.control.algorithm.touchdown`: the sums stop falling and
the IMU reads segment 2 pitched, which sets it down on the step whatever
a sensor reading long says).  Touch needs the IMU: without it, the standing
rule ends the program as before.  So it does in a continuous descent: from
the top, the edge watch takes LOW_DROP_M (1.5 cm) past the floor for a drop
(any rise may come), less than the allowance.  The standing rule stays armed in this
descent 2 for a disagreement beyond the allowance.  The allowance is kept
in descent 2's work (``apart``): a resumed run carries it.
"""

from __future__ import annotations

import statistics

from stairbot.control.algorithm import limits, motion
from stairbot.control.algorithm.phase import Step, Tick, go
from stairbot.control.algorithm.phases import Phase
from stairbot.control.algorithm.texts import back_pair as say
from stairbot.control.algorithm.work import LowerThirdWork, Work
from stairbot.hardware import Snapshot
from stairbot.inputs.config import RobotConfig

SHARE_OF_LOWEST_RISE = 0.25
"""The allowance is this share of the lowest rise the robot climbs (module
docstring)."""


def allowance_m(cfg: RobotConfig) -> float:
    """How far SBR and SBL may differ for descent 2 to go on with them: a
    quarter of the lowest rise the robot climbs (2.1 cm on the sonar robot,
    1.9 cm on the reference robot)."""
    return SHARE_OF_LOWEST_RISE * limits.min_step_rise_m(cfg)


def _work(t: Tick) -> LowerThirdWork | None:
    w: Work = t.ctx.work
    return w if isinstance(w, LowerThirdWork) else None


def goes_on(t: Tick, resume: Phase, diffs: list[float], resumed: str) -> Step | None:
    """At the tick the standing rule would end the program after its wait on
    the back pair in descent 2 (``resume``): the resume (outcome
    ``resumed``), lowering on by the longer reading and by touch, if the
    median of the wait's last second (``diffs``, left − right) is within
    :func:`allowance_m` and the IMU is watched, on a flight the robot climbed;
    else None."""
    cfg, w = t.cfg, _work(t)
    if resume is not Phase.DESCENT_LOWER_THIRD or w is None or not diffs or t.ctx.from_top \
            or not cfg.safety.imu or t.snap.imu is None:
        return None
    median = statistics.median(diffs)
    allowance = allowance_m(cfg)
    if abs(median) > allowance:
        return None
    w.apart = abs(median)
    r, left = motion.pair(t.snap, back=True)
    return go(resumed, say.apart_goes_on(r.distance_m, left.distance_m, median, allowance,
                                         resume.record.label))


def within(t: Tick, smoothed: float, diff: float | None) -> bool:
    """Descent 2 going on with the pair apart: whether the back pair's
    smoothed difference, or its newest (``diff``; None: not asked), is
    within the allowance (no disagreement, for the standing rule)."""
    w = _work(t)
    if w is None or w.apart is None:
        return False
    allowance = allowance_m(t.cfg)
    return abs(smoothed) <= allowance or (diff is not None and abs(diff) <= allowance)


def reading(snap: Snapshot, w: LowerThirdWork) -> float:
    """What descent 2 lowers by: the pair's mean, or, going on with the pair
    apart, its longer reading."""
    if w.apart is None:
        return motion.mean_distance(snap, back=True)
    r, left = motion.pair(snap, back=True)
    return max(r.distance_m, left.distance_m)
