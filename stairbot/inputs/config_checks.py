"""What the robot config's values must satisfy together: the segments add up,
the wheels fit, the sensors can see what the algorithm asks of them, the lifts
reach.  Each failure is one ConfigError naming the file, the field and what is
allowed."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from stairbot.errors import ConfigError

if TYPE_CHECKING:
    from stairbot.inputs.config import RobotConfig

BACK_RANGE_MARGIN = 0.005
"""The floor must read at least this far inside the back sensors' range."""

WHEEL_SPEED_M_S = (0.001, 5.0)
"""What the wheels' speed may make at the rim, m/s: slower, a run of a few
steps outlasts a day; faster, the simulation's wheels skip over a 1/600 s step."""
LIFT_SPEED_M_S = (0.0002, 1.0)
"""What the lifts' speed may make, m/s (a 0.21 m stroke in 18 min at the least)."""


def check_consistency(cfg: RobotConfig, min_step_rise_m: Callable[[RobotConfig], float]) -> None:
    """Raise ConfigError naming the field when the config's values do not fit
    together (the file's own types and ranges are checked as it is read).
    ``min_step_rise_m``: the lowest riser the controller climbs with this
    robot (:func:`stairbot.control.algorithm.limits.min_step_rise_m`)."""
    src = cfg.source
    g, s, m, a = cfg.geometry, cfg.sensors, cfg.motors, cfg.algorithm
    if g.LENGTH_OF_A_ROBOT is not None and abs(g.LENGTH_OF_A_ROBOT - cfg.LENGTH_OF_A_ROBOT) > 1e-3:
        raise ConfigError(
            src, "geometry.LENGTH_OF_A_ROBOT",
            f"{g.LENGTH_OF_A_ROBOT} m, but the segments add up to {cfg.LENGTH_OF_A_ROBOT:.4f} m; "
            "the robot is its three segments end to end (leave the key out to derive it)",
        )
    if a.landings and not s.has_side_pair:
        raise ConfigError(src, "algorithm.landings",
                          "quarter-turn landings look sideways with the side pair SSR/SSL, "
                          "and this robot has none; allowed: landings = false, or a "
                          "[sensors] side_model (one of the sensor models) for the pair")
    if s.has_side_pair and s.side_min_range >= s.side_max_range:
        raise ConfigError(src, "sensors.side_min_range", "must be below side_max_range")
    if s.has_side_pair and s.side_height >= (lowest := min_step_rise_m(cfg)):
        raise ConfigError(src, "sensors.side_height",
                          f"{s.side_height} m: the side pair's beams must start below the "
                          f"lowest riser the robot climbs (min_step_rise_m, "
                          f"{lowest:.3f} m), or they read past a landing's next "
                          "flight's first riser to the ones beyond; allowed: less than that")
    if s.has_side_pair and s.side_from_rear > g.LENGTH_OF_THIRD_MODULE:
        raise ConfigError(src, "sensors.side_from_rear",
                          f"{s.side_from_rear} m puts the side pair off segment 3 "
                          f"({g.LENGTH_OF_THIRD_MODULE} m long); allowed: up to its length")
    for name in ("LENGTH_OF_FIRST_MODULE", "LENGTH_OF_SECOND_MODULE", "LENGTH_OF_THIRD_MODULE"):
        length = getattr(g, name)
        if 2 * g.wheel_inset > length or g.wheel_inset < g.wheel_radius:
            raise ConfigError(
                src, "geometry.wheel_inset",
                f"{g.wheel_inset} m does not fit {name} = {length} m with wheel_radius "
                f"{g.wheel_radius} m; allowed: wheel_radius <= wheel_inset <= {length / 2} m",
            )
    for field, value, unit, (lo, hi) in (
            ("motors.wheel_speed", cfg.wheel_speed_m_s, "at the rim", WHEEL_SPEED_M_S),
            ("motors.lift_speed", cfg.lift_speed_m_s, "with lift_travel_per_turn",
             LIFT_SPEED_M_S)):
        if not lo <= value <= hi:
            raise ConfigError(src, field, f"{getattr(m, field.split('.')[1]):g} turns/s makes "
                              f"{value:.3g} m/s {unit}; allowed: {lo:g} to {hi:g} m/s")
    if s.front_min_range >= s.front_max_range:
        raise ConfigError(src, "sensors.front_min_range", "must be below front_max_range")
    if s.back_min_range >= s.back_max_range:
        raise ConfigError(src, "sensors.back_min_range", "must be below back_max_range")
    back_lo = s.range(back=True)[0]
    if s.back_height < back_lo + BACK_RANGE_MARGIN:
        raise ConfigError(src, "sensors.back_height",
                          f"{s.back_height} m, but SBR/SBL ({s.back_model}) read from "
                          f"{back_lo} m: the floor would be out of range; allowed: at "
                          f"least {back_lo + BACK_RANGE_MARGIN:.3f} m (mount them higher, "
                          "or choose a back_model that reads nearer)")
    front_hi = s.range(back=False)[1]
    if a.LENGTH_OF_INFINITY > front_hi:
        raise ConfigError(src, "algorithm.LENGTH_OF_INFINITY",
                          f"{a.LENGTH_OF_INFINITY} m, but SFR/SFL ({s.front_model}) read "
                          f"at most {front_hi} m (sensors.front_max_range, within the "
                          f"sensor's own range); allowed: at most {front_hi} m")
    for back, fov in ((False, s.front_fov_deg), (True, s.back_fov_deg)):
        full = s.spec(back).fov_deg
        pair = "back" if back else "front"
        if fov is not None and full > 0 and fov > full:
            raise ConfigError(src, f"sensors.{pair}_fov_deg",
                              f"{fov} degrees, wider than the {s.spec(back).name}'s "
                              f"{full}-degree cone; allowed: up to {full} (an ROI narrows it)")
        if fov is not None and full == 0 and fov > 0:
            raise ConfigError(src, f"sensors.{pair}_fov_deg",
                              f"{fov} degrees, but the {s.spec(back).name} model is one ray; "
                              "allowed: 0, one ray along the mount (say so when the config "
                              "it extends gives a cone)")
    check_zones(cfg)
    if a.SAFE_DISTANCE_IN_FRONT_OF_STEP <= a.approach_gap:
        raise ConfigError(src, "algorithm.SAFE_DISTANCE_IN_FRONT_OF_STEP",
                          f"must exceed approach_gap ({a.approach_gap} m)")
    if a.SAFE_DISTANCE_IN_FRONT_OF_STEP < s.front_min_range:
        raise ConfigError(src, "algorithm.SAFE_DISTANCE_IN_FRONT_OF_STEP",
                          f"must be at least sensors.front_min_range ({s.front_min_range} m)")
    if a.SAFE_LENGTH < s.front_min_range:
        raise ConfigError(src, "algorithm.SAFE_LENGTH",
                          f"must be at least sensors.front_min_range ({s.front_min_range} m): "
                          "the last drive of each step stops at that reading")
    if s.front_height + a.drive_clearance >= m.lift_travel:
        raise ConfigError(src, "motors.lift_travel",
                          "must exceed sensors.front_height + algorithm.drive_clearance")
    if a.clearance_lift >= m.lift_travel:
        raise ConfigError(src, "algorithm.clearance_lift", "must be below motors.lift_travel")
    half_base = g.LENGTH_OF_SECOND_MODULE / 2 - g.wheel_inset
    if cfg.safety.stability_margin >= half_base:
        raise ConfigError(
            src, "safety.stability_margin",
            f"{cfg.safety.stability_margin} m leaves no room: segment 2's wheels alone carry "
            "the robot while segments 1 and 3 are lifted (calibration); allowed: 0 <= "
            f"stability_margin < LENGTH_OF_SECOND_MODULE / 2 - wheel_inset = {half_base:.4f} m")
    if a.LENGTH_OF_INFINITY <= cfg.LENGTH_OF_A_ROBOT + a.SAFE_LENGTH:
        raise ConfigError(src, "algorithm.LENGTH_OF_INFINITY",
                          "must exceed LENGTH_OF_A_ROBOT + SAFE_LENGTH")


ZONE_GRID_TOLERANCE_DEG = 1e-6
"""How near a block of zones' edges must lie to the grid's lines."""


def check_zones(cfg: RobotConfig) -> None:
    """Raise ConfigError unless a multizone sensor (one whose datasheet gives
    ``zones``) is on the front pair only, mounted level, with the rows it
    publishes on its grid: ``front_fov_deg`` a whole number of rows tall,
    ``front_tilt_deg`` the block's axis, its lowest ray level or above
    (lower, it meets the floor ahead, which reads as a riser)."""
    src, s = cfg.source, cfg.sensors
    for field, model, spec in (("back_model", s.back_model, s.spec(back=True)),
                               ("side_model", s.side_model, s.side_spec())):
        if spec.zones:
            raise ConfigError(src, f"sensors.{field}",
                              f"{model!r}: a multizone sensor is modelled on the front pair "
                              "only (a block of its zones looking forward); allowed: a "
                              "single-zone model here")
    spec = s.spec(back=False)
    if not spec.zones:
        return
    zone, full = spec.zone_deg, spec.fov_deg
    fov = full if s.front_fov_deg is None else s.front_fov_deg
    rows = fov / zone
    if round(rows) < 1 or abs(rows - round(rows)) * zone > ZONE_GRID_TOLERANCE_DEG:
        allowed = ", ".join(f"{k * zone:g}" for k in range(1, spec.zones + 1))
        raise ConfigError(src, "sensors.front_fov_deg",
                          f"{fov:g} degrees is not a whole number of the {spec.name}'s "
                          f"{zone:g}-degree rows of zones; allowed: {allowed}")
    bottom, top = s.front_tilt_deg - fov / 2.0, s.front_tilt_deg + fov / 2.0
    lines = (bottom + full / 2.0) / zone  # the block's lowest edge, in rows from the grid's
    if (abs(lines - round(lines)) * zone > ZONE_GRID_TOLERANCE_DEG
            or bottom < -full / 2.0 - ZONE_GRID_TOLERANCE_DEG
            or top > full / 2.0 + ZONE_GRID_TOLERANCE_DEG):
        first = -full / 2.0 + fov / 2.0
        raise ConfigError(src, "sensors.front_tilt_deg",
                          f"{s.front_tilt_deg:g} degrees puts the {fov:g}-degree block off the "
                          f"{spec.name}'s grid of {zone:g}-degree rows (mounted level, from "
                          f"{-full / 2.0:g} to {full / 2.0:g} degrees); allowed: {first:g} "
                          f"plus a whole number of {zone:g} up to {-first:g} (the block's "
                          "axis)")
    if bottom < -ZONE_GRID_TOLERANCE_DEG:
        floor = s.front_height / math.tan(math.radians(-bottom))
        raise ConfigError(src, "sensors.front_tilt_deg",
                          f"{s.front_tilt_deg:g} degrees: the block's lowest rays look "
                          f"{-bottom:g} degrees down and meet the floor {floor:.3f} m ahead "
                          f"of a sensor {s.front_height:g} m above it (front_height), which "
                          f"reads as a riser; allowed: at least {fov / 2.0:g} (half of "
                          "front_fov_deg: the lowest ray level)")
