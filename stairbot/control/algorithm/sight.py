"""Whether the front pair reads the next riser or the tread before it: the
drives onto a step (ascent 4, 6 and 9) end at a reading only where the
front pair's view meets the riser before the tread it looks along.

The pair's sensors stand ``front_height`` above the wheels' contact line,
their view ``front_fov_deg`` tall with its axis ``front_tilt_deg`` up; a
multizone pair's board moves its block of zones up while the robot pitches
nose down (:func:`~stairbot.inputs.sensor_specs.rows_up`); a ranger that
hears a surface only near its normal (``echo_incidence_deg``, an
ultrasonic one) hears no level tread at a graze.  Pitched nose down, the
lowest ray that hears the tread meets it :func:`floor_sight_m` ahead, and
a riser farther than that is read short: a weighted cone mixes the tread
into its reading, a narrow spot reads the tread alone -- and the tread it
reads rides along with the robot, so the drive ends short by however much
the reading is.  (The ir robot's level 4-degree Sharp spot, 30 mm up,
pitched -4.5 degrees by ascent 5, met the tread it stood on 0.35 m ahead:
ascent 6 ended 18 mm short on a 0.48 m tread, segment 2's rear axle behind
the nosing, and lifting segment 3 levered the robot over it to the tilt
stop: docs/envelope.md, "Reach".)  Such a drive goes by the seed's turn
counts instead, as onto a tread past FAR_TREAD_M.

The pitch is the IMU's at the drive's start (a drive onto a step pitches
little: the robot stands on segments 1 and 3, or 2 and 3, throughout), and
PITCH_MARGIN_DEG more nose down; without an IMU, the pitch the phase is
expected to have (:func:`expected_pitch_deg`).

Pure functions.
"""

from __future__ import annotations

import math

from stairbot.hardware import Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.sensor_specs import ROW_SWITCH_PITCH_DEG, rows_up

PITCH_MARGIN_DEG = 1.0
"""The pitch is taken this much further nose down than measured: the IMU's
error and what the pitch moves within a drive."""


def _lowest_ray_deg(cfg: RobotConfig, pitch_deg: float) -> float:
    """The angle to level (+ up) of the lowest ray of the view the front
    pair publishes, the robot pitched ``pitch_deg`` (+ nose up): a
    multizone pair's block moved up as the board moves it, as far as the
    sensor's field goes."""
    s = cfg.sensors
    spec = s.spec(back=False)
    fov = spec.fov_deg if s.front_fov_deg is None else s.front_fov_deg
    lowest = s.front_tilt_deg - fov / 2.0 + pitch_deg
    if spec.zones:
        top = s.front_tilt_deg + fov / 2.0
        spare = max(0, math.floor((spec.fov_deg / 2.0 - top) / spec.zone_deg + 1e-9))
        lowest += min(rows_up(pitch_deg, spec.zone_deg), spare) * spec.zone_deg
    return lowest


def lowest_heard_deg(cfg: RobotConfig, pitch_deg: float,
                     margin_deg: float = PITCH_MARGIN_DEG) -> float | None:
    """The angle to level (+ up) of the lowest ray of the front pair that a
    level tread below returns, the robot pitched anywhere from ``pitch_deg``
    (+ nose up) to ``margin_deg`` further nose down: the lowest of either
    end and, for a multizone pair, of the pitches just before its board
    moves the block up a row (ROW_SWITCH_PITCH_DEG and a zone more each
    time).  None when no ray points down, or none that does is heard off a
    level tread."""
    spec = cfg.sensors.spec(back=False)
    low = pitch_deg - margin_deg
    pitches = [low, pitch_deg]
    if spec.zones:
        switch = -ROW_SWITCH_PITCH_DEG
        while switch >= low:
            if switch <= pitch_deg:
                pitches.append(switch)
            switch -= spec.zone_deg
    lowest = min(_lowest_ray_deg(cfg, p) for p in pitches)
    if lowest >= 0.0:
        return None
    if spec.echo_incidence_deg is not None and -lowest < 90.0 - spec.echo_incidence_deg:
        # a ray `d` degrees down meets a level tread 90 - d off its normal
        return None
    return lowest


def floor_sight_m(cfg: RobotConfig, pitch_deg: float,
                  margin_deg: float = PITCH_MARGIN_DEG) -> float:
    """How far ahead of the front pair its lowest heard ray meets the level
    tread its wheels stand on (``front_height`` below it), the robot
    pitched ``pitch_deg`` to ``margin_deg`` further nose down
    (:func:`lowest_heard_deg`); infinite where none does."""
    lowest = lowest_heard_deg(cfg, pitch_deg, margin_deg)
    if lowest is None:
        return math.inf
    # the sensors stand wheel_inset ahead of segment 1's front axle: pitched
    # nose down, that much lower
    low = math.radians(min(0.0, pitch_deg - margin_deg))
    height = cfg.sensors.front_height + cfg.geometry.wheel_inset * math.sin(low)
    return height / math.tan(math.radians(-lowest))


def expected_pitch_deg(cfg: RobotConfig, segment_2_lifted: bool) -> float:
    """The pitch a drive onto a step is expected to start at, for a robot
    without an IMU: level, or, with segment 2 lifted (ascent 6), segment 1 on
    the step and segment 3 below it, nose down by what ascent 3 lifts past
    the riser (drive_clearance) over the length between them."""
    if not segment_2_lifted:
        return 0.0
    g = cfg.geometry
    span = (g.LENGTH_OF_FIRST_MODULE + g.LENGTH_OF_THIRD_MODULE) / 2.0 \
        + g.LENGTH_OF_SECOND_MODULE
    return -math.degrees(math.atan2(cfg.algorithm.drive_clearance, span))


def pitch_now(cfg: RobotConfig, snap: Snapshot, segment_2_lifted: bool) -> float:
    """The pitch to judge the sight by: the IMU's, else
    :func:`expected_pitch_deg`."""
    imu = snap.imu
    if cfg.safety.imu and imu is not None and math.isfinite(imu.pitch_deg):
        return imu.pitch_deg
    return expected_pitch_deg(cfg, segment_2_lifted)


def riser_in_sight(cfg: RobotConfig, distance_m: float, pitch_deg: float) -> bool:
    """Whether a riser ``distance_m`` ahead is met by the front pair's view
    before the tread, the robot pitched ``pitch_deg`` (PITCH_MARGIN_DEG
    more nose down)."""
    return distance_m <= floor_sight_m(cfg, pitch_deg)
