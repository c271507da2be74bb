"""How far and how late the back pair tells descent 1 about an edge: where
segment 3 stands on the floor (:func:`floor_tolerance`), how far past the
edge the robot backs (:func:`edge_clearance_m`) and with what doubt, what
the pair reads past it (:func:`edge_drop_m`), how long perception takes to
say so (:func:`edge_lag_s`) and how far the robot has backed by then
(:func:`edge_sight_m`); how slowly it backs after finding the floor again
(:func:`slow_backing`).  Pure functions of the robot's config; the watch
that uses them is :mod:`~stairbot.control.algorithm.edge`.
"""

from __future__ import annotations

import math

from stairbot.control.algorithm import limits
from stairbot.control.algorithm.per_config import per_config
from stairbot.control.tolerances import max_age, measurement_period, median_sigma, window
from stairbot.inputs.config import RobotConfig

FLOOR_SIGMAS = 2.0
"""Descent 2: SBR/SBL "read BACK_CLEARANCE" within this many sigmas of their
filtered mean (and half a resolution step)."""


@per_config
def floor_tolerance(cfg: RobotConfig) -> float:
    """How far above BACK_CLEARANCE the pair's mean may read and segment 3
    stand on the floor: half a resolution step, and FLOOR_SIGMAS sigmas of
    the mean of two filtered readings there.  Without the sigmas, a noisy
    pair (or a cone, whose slanted rays read a little long) that reads above
    BACK_CLEARANCE standing keeps the lift pushing segment 3 down, and
    segment 2 tips nose down."""
    sigma = median_sigma(cfg, True, cfg.BACK_CLEARANCE) / math.sqrt(2.0)
    return cfg.sensors.resolution / 2 + FLOOR_SIGMAS * sigma


EDGE_MARGIN_M = 0.006
"""Segment 3's front wheels stop this far clear of the edge's corner."""


def edge_clearance_m(cfg: RobotConfig) -> float:
    """How far the robot backs after its back pair (``back_from_rear`` from
    segment 3's rear) crossed the edge until segment 3's front wheels are
    clear of it, their front EDGE_MARGIN_M past its corner: over the step
    below, and not yet so far that the robot tips back off segment 2's rear
    wheels.  The wheels' front, not their centre, is what must clear the
    corner: wheels whose centre is only a wheel radius past it stand on it,
    segment 3 stays up when lowered, and the lift pitches segment 2 nose
    down."""
    g = cfg.geometry
    return (g.LENGTH_OF_THIRD_MODULE - cfg.sensors.back_from_rear - g.wheel_inset
            + g.wheel_radius + EDGE_MARGIN_M + edge_doubt_m(cfg))


def edge_doubt_m(cfg: RobotConfig) -> float:
    """How far off :func:`edge_sight_m` may place the crossing: the distance
    backed at full speed in one of the back pair's measurement periods (the
    crossing falls anywhere between two measurements, and the median's
    majority may take one more).  Added to the clearance, so that a slow
    pair (an HC-SR04 measures every 60 ms, about 10 mm of backing) still
    stops segment 3's front wheels past the corner, not on it, where
    lowering segment 3 would pitch the robot nose down."""
    return cfg.wheel_speed_m_s * measurement_period(cfg, True)


LOW_DROP_M = 0.015
"""A continuous descent takes a drop this much past BACK_CLEARANCE (and its
noise) for an edge: it has not climbed the flight, so any rise may come,
and one lower than half min_step_rise_m, unseen, would be backed off wheels
first and tip the robot back.  0.015 m is under a 32 mm wheel's radius, a
drop the wheels roll down."""


def edge_drop_m(cfg: RobotConfig, from_top: bool = False) -> float:
    """The back pair reads "past the edge" beyond this: more than half the
    lowest rise below BACK_CLEARANCE (and its noise); in a continuous
    descent, LOW_DROP_M more than BACK_CLEARANCE (and its noise)."""
    low = LOW_DROP_M if from_top else limits.min_step_rise_m(cfg) / 2
    return cfg.BACK_CLEARANCE + floor_tolerance(cfg) + low


@per_config
def edge_lag_s(cfg: RobotConfig) -> float:
    """How long after the back pair's distance changes (it crosses an edge,
    or segment 3 is lowered) perception reports it: the sensor's latency,
    then the median's majority of the window, one period each, the first of
    them half a period after the change on average."""
    return cfg.sensors.spec(True).latency_s \
        + (window(cfg, True) // 2 + 0.5) * measurement_period(cfg, True)


def back_half_cone_rad(cfg: RobotConfig) -> float:
    """Half the back pair's cone (the config's back_fov_deg, else its model's)."""
    fov = cfg.sensors.back_fov_deg
    return math.radians(cfg.sensors.spec(True).fov_deg if fov is None else fov) / 2


def mixed_footprint_m(cfg: RobotConfig) -> float:
    """How far past an edge a back sensor that mixes its cone's returns by
    their signal (a time-of-flight cone; not a first echo, whose riser face
    :func:`edge_sight_m` counts instead) may still read the tread: the tread
    BACK_CLEARANCE below returns (BACK_CLEARANCE + rise)^2 / BACK_CLEARANCE^2
    times the drop's signal per ray, so the mix reads past the edge only
    once nearly the whole footprint has left it, BACK_CLEARANCE x tan(half
    the cone) past the edge (a VL53L0X pair: 8.9 mm).  From the top, the
    drop read LOW_DROP_M past the floor, sooner: counted in full there, it
    stops segment 3's front wheels up to half the footprint short of where
    edge_clearance_m puts them, within its EDGE_MARGIN_M.  0 for one ray."""
    if cfg.sensors.spec(True).first_echo:
        return 0.0
    return cfg.BACK_CLEARANCE * math.tan(back_half_cone_rad(cfg))


def edge_sight_m(cfg: RobotConfig, speed_mps: float, from_top: bool = False) -> float:
    """How far past an edge the back pair's sensors are when perception first
    reports the drop, backing at ``speed_mps``: the distance backed while
    the measurements came through (the sensor's latency, then the median's
    majority of the window, one period each, the first of them half a
    period after the crossing on average), and where the cone lets the
    sensor see the drop at all: for a sensor that reports the first echo in
    its cone, the riser's face below the edge that the cone's back half
    keeps seeing, nearer than the drop, until the sensor is ``edge_drop_m``
    x sin(half the cone) past it (an HC-SR04 pair: about 2.4 cm); for one
    that mixes its cone by signal, the footprint still on the tread
    (:func:`mixed_footprint_m`).  The backing that follows subtracts it
    from edge_clearance_m: counted from the sighting instead, it backs that
    much too far, and segment 2's rear wheels go over the edge."""
    sight = abs(speed_mps) * edge_lag_s(cfg)
    if cfg.sensors.spec(True).first_echo:
        return sight + edge_drop_m(cfg, from_top) * math.sin(back_half_cone_rad(cfg))
    return sight + mixed_footprint_m(cfg)



def slow_backing(cfg: RobotConfig) -> float:
    """The fraction of full wheel speed descent 1 backs up to the edge at
    after finding the floor again: slow enough that what the robot backs
    while a floor reading can stand for measurements taken earlier
    (:func:`~stairbot.control.algorithm.edge.floor_known_s`, up to the stale
    limit) is half the crossing's doubt, so that a crossing read after a
    hold (every motor stopped) is known
    (:func:`~stairbot.control.algorithm.edge.held_crossing_known`).  Holds
    come often when the link loses many frames; at full speed each one in
    the crossing sends the robot forward to find the floor again."""
    lagged = max_age(cfg, True) + (window(cfg, True) // 2) * measurement_period(cfg, True)
    return min(1.0, edge_doubt_m(cfg) / 2 / (cfg.wheel_speed_m_s * lagged))
