"""Descent 2: segment 3 met the step below although the back pair reads it a
little above BACK_CLEARANCE (not in the seed, which lowers until the pair's
mean reads BACK_CLEARANCE, or MAX_OF_VERTICAL_TURNS).

One sensor reading 1 cm long (a bias within what the standing rule allows)
moves the pair's mean 5 mm, beyond
:func:`~stairbot.control.algorithm.edge_measure.floor_tolerance`: the pair
never read BACK_CLEARANCE, and MTB pushed segment 3 on down to
MAX_OF_VERTICAL_TURNS, pitching segment 2 13 degrees nose down
(sweeps/sensor_faults.toml, the +1 cm cases).

Two witnesses say segment 3 stands, both needed:

* *its sensors stop falling*: while MTB lowers segment 3 in the air, each
  reading plus MTB's travel (counted at the time the filtered reading
  stands for, :func:`~stairbot.control.algorithm.edge_measure.edge_lag_s`
  ago) stays put; once its wheels stand, the sensors on it stop falling and
  that sum grows with the travel.  Each sum is smoothed over the pair's
  settle time; both must have risen above their lowest by :func:`margin_m`.
  Alone this is not enough: limping at half speed, a healthy pair's
  medians held one value for half a second while segment 3 still hung a
  centimetre up (case 7 of the sweep, SFR lost), and raised back there it
  was set down short;
* *segment 2 pitches nose down*: hanging, segment 3 is carried by segments 1
  and 2 and their pitch holds (to 0.001 degrees in the simulation); pushed
  on a surface, segment 3 lifts segment 2's back end about segment 1's
  wheels.  The IMU must read segment 2 pitched nose down by at least
  :func:`pitch_deg` (half the sums' margin over LENGTH_OF_FIRST_MODULE +
  LENGTH_OF_SECOND_MODULE) since the pair came near BACK_CLEARANCE.

Only while the pair's mean reads within the standing tolerance of
BACK_CLEARANCE (a pair that still reads a drop below it has not met the
step), and only with the IMU watched (without it the lowering ends as the
seed says).  How far the sums rose is how far MTB pushed since segment 3
stood, and the pitch says it too: MTB goes back up by the smaller.  The
state is kept in descent 2's work (``touch_sums``, ``touch_lowest``,
``touch_pitch``): a resumed run carries on with it.
"""

from __future__ import annotations

import math

from stairbot.control.algorithm.edge_measure import edge_lag_s
from stairbot.control.algorithm.per_config import per_config
from stairbot.control.algorithm.work import LowerThirdWork
from stairbot.control.timeline import value_at
from stairbot.control.tolerances import (
    SIGMAS,
    measurement_period,
    median_sigma,
    settle_s,
    standing_tolerance,
)
from stairbot.hardware import BACK_SENSORS, MotorId, Snapshot
from stairbot.inputs.config import RobotConfig


@per_config
def smoothing_ticks(cfg: RobotConfig) -> int:
    """Each sum is smoothed over the back pair's settle time, in ticks: the
    filtered readings' own memory."""
    return max(1, round(settle_s(cfg, True) / cfg.algorithm.tick))


@per_config
def margin_m(cfg: RobotConfig) -> float:
    """How far a smoothed sum must rise above its lowest to say segment 3
    stands: SIGMAS sigmas of the difference of two such means at
    BACK_CLEARANCE (each of ``smoothing_ticks`` ticks, as many independent
    measurements as the sensor gives in that time), and half a resolution
    step."""
    ticks = smoothing_ticks(cfg)
    independent = max(1.0, ticks * cfg.algorithm.tick / measurement_period(cfg, True))
    sigma = median_sigma(cfg, True, cfg.BACK_CLEARANCE) / math.sqrt(independent)
    return SIGMAS * math.sqrt(2.0) * sigma + cfg.sensors.resolution / 2


@per_config
def pitch_deg(cfg: RobotConfig) -> float:
    """How far segment 2 must have pitched nose down, degrees: what pushing
    segment 3 half :func:`margin_m` onto a surface tilts it about segment
    1's wheels (LENGTH_OF_FIRST_MODULE + LENGTH_OF_SECOND_MODULE away)."""
    return math.degrees(math.atan2(margin_m(cfg) / 2,
                                   cfg.LENGTH_OF_FIRST_MODULE + cfg.LENGTH_OF_SECOND_MODULE))


def stood(cfg: RobotConfig, snap: Snapshot, w: LowerThirdWork) -> tuple[float, float] | None:
    """This tick of the lowering (``w.mtb_recent`` already holds it, back to
    the back pair's lag): None, or (the MTB counter segment 3 stood at, how
    far MTB has lowered it since, m) -- the push the sums and the pitch say,
    the smallest (segment 3 is raised back no further than all bear out,
    and stays on the step)."""
    lift_m = cfg.motors.lift_travel_per_turn
    was = value_at(w.mtb_recent, snap.time_s - edge_lag_s(cfg))
    readings = [snap.sensors[s] for s in BACK_SENSORS]
    if not cfg.safety.imu or snap.imu is None:
        return None
    if not all(r.ok for r in readings):
        w.touch_sums.clear()
        return None
    # each reading plus MTB's travel down (its counter falls lowering)
    w.touch_sums.append((readings[0].distance_m - was * lift_m,
                         readings[1].distance_m - was * lift_m))
    n = smoothing_ticks(cfg)
    del w.touch_sums[:-n]
    mean = (readings[0].distance_m + readings[1].distance_m) / 2
    if w.apart is not None:  # the pair apart (back_apart): the nearer one reads the surface
        mean = min(readings[0].distance_m, readings[1].distance_m)
    near = cfg.BACK_CLEARANCE + standing_tolerance(cfg, cfg.BACK_CLEARANCE, back=True)
    if mean > near:  # still over a drop: no surface to stand on yet
        w.touch_lowest = w.touch_pitch = None
        return None
    if w.touch_pitch is None:
        w.touch_pitch = snap.imu.pitch_deg
    if len(w.touch_sums) < n:
        return None
    smooth = (sum(a[0] for a in w.touch_sums) / n, sum(a[1] for a in w.touch_sums) / n)
    low = w.touch_lowest or smooth
    w.touch_lowest = low = (min(low[0], smooth[0]), min(low[1], smooth[1]))
    risen = min(smooth[0] - low[0], smooth[1] - low[1])
    if risen < margin_m(cfg) or w.touch_pitch - snap.imu.pitch_deg < pitch_deg(cfg):
        return None
    # the sums rose with the push since it stood, as of the readings' time
    # (MTB has lowered on since then); the pitch says it now: the smaller
    mtb = snap.turns(MotorId.MTB)
    lever = cfg.LENGTH_OF_FIRST_MODULE + cfg.LENGTH_OF_SECOND_MODULE
    pushed = min(risen + max(0.0, was - mtb) * lift_m,
                 lever * math.tan(math.radians(w.touch_pitch - snap.imu.pitch_deg)))
    return mtb + pushed / lift_m, pushed
