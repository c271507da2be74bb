"""Sensor model presets, chosen per sensor pair in the robot config
(``[sensors] front_model``, ``back_model``).

The datasheet's timing, noise and range come from
:mod:`stairbot.inputs.sensor_specs` (the controller's perception uses the same
figures, cited there); here is what only a simulation needs, each figure
saying where it comes from: how many rays stand for the cone, how they
combine, outlier and dropout rates ("assumed": the datasheets do not give
them, and they are deliberately modest), weak-signal and incidence limits.
The robot config may narrow a cone (a ToF's ROI), choose a multizone
sensor's rows of zones, and tilt a mount: :func:`model_for`.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from stairbot.fakes.sensor_model import SensorModel
from stairbot.inputs import sensor_specs as specs
from stairbot.inputs.sections import Sensors
from stairbot.inputs.sensor_specs import SensorSpec


def _from(spec: SensorSpec, **sim_only: Any) -> SensorModel:
    return SensorModel(
        name=spec.name, fov_deg=spec.fov_deg, period_s=spec.period_s,
        latency_s=spec.latency_s, noise_a=spec.noise_a, noise_b=spec.noise_b,
        resolution=spec.resolution, min_range=spec.min_range, max_range=spec.max_range,
        **sim_only)


# Today's behaviour: one ray straight along the mount, no latency, measured at
# every read, Gaussian noise of the scenario's [sensors] noise, the config's
# ranges and resolution.
IDEAL = _from(specs.IDEAL)

# VL53L1X: the SPAD array returns a signal-weighted mix of the targets in the
# cone ("weighted"): 5 rays up the cone, 3 across it.  Maximum in long mode,
# dark, white target: 360 cm typical (DS12385 2.5, ranging performance): the
# weak-signal limit for a full, square beam.  Assumed: 0.2 % outliers (a stray
# return), 0.5 % dropouts (a range status other than "valid").
VL53L1X = _from(specs.VL53L1X, rays=5, rays_across=3, aggregate="weighted",
                outlier_rate=0.002, dropout_rate=0.005, weak_range=3.6)

# VL53L0X: default mode's 1.2 m is the weak-signal limit, 2 m the most reported.
# Assumed: 0.5 % outliers, 1 % dropouts; "weighted" mix of 5 x 3 rays.
VL53L0X = _from(specs.VL53L0X, rays=5, rays_across=3, aggregate="weighted",
                outlier_rate=0.005, dropout_rate=0.01, weak_range=1.2)

# HC-SR04: the first echo wins ("nearest"): 7 rays up the cone, 3 across.
# Incidence-angle loss as the spec states it (echo_incidence_deg, assumed): a
# ray meeting its surface more than 10 degrees off the normal returns no
# echo, so the 15-degree cone hears a surface turned up to about 17 degrees
# from its axis.  Assumed: 1 % outliers (cross-talk, multipath), 1 % dropouts
# (no echo).
HCSR04 = _from(specs.HCSR04, rays=7, rays_across=3, aggregate="nearest",
               outlier_rate=0.01, dropout_rate=0.01,
               max_incidence_deg=specs.HCSR04.echo_incidence_deg)

# GP2Y0A21: a narrow spot, 3 rays in the side view.  Assumed: 0.2 % outliers;
# no dropouts (an analog output has no status).
GP2Y0A21 = _from(specs.GP2Y0A21, rays=3, rays_across=1, aggregate="weighted",
                 outlier_rate=0.002)

# VL53L5CX, 8x8: the sensor board publishes, per sensor, one distance from a
# block of zones -- the robot config's rows (front_fov_deg tall, its axis
# front_tilt_deg up on a level mount; config_checks keeps them on the grid)
# by the two central columns, 11.25 degrees across.  Each zone is a rectangle
# of rays, two per zone and one more at the far edge each way (3 up a row,
# 5 across two columns), the rows' zones mixed as the VL53L1X's cone
# ("weighted"): pessimistic, since the sensor can tell targets apart within
# a zone.  Zones are taken with hard edges (AN5894: a zone's edge is a
# convention; their blur is not modelled).  Assumed: weak beyond 3 m (ST
# quotes 4 m for the sensor); 0.2 % outliers and 0.5 % dropouts (a target
# status other than valid), as the VL53L1X.
VL53L5CX_COLUMNS = 2
"""Central columns of zones the board publishes."""
RAYS_PER_ZONE = 2

VL53L5CX = _from(specs.VL53L5CX, fov_across_deg=VL53L5CX_COLUMNS * specs.VL53L5CX.zone_deg,
                 rays=RAYS_PER_ZONE * specs.VL53L5CX.zones + 1,
                 rays_across=RAYS_PER_ZONE * VL53L5CX_COLUMNS + 1, aggregate="weighted",
                 outlier_rate=0.002, dropout_rate=0.005, weak_range=3.0)

PRESETS: dict[str, SensorModel] = {m.name: m for m in (IDEAL, VL53L1X, VL53L0X, HCSR04, GP2Y0A21,
                                                       VL53L5CX)}


def preset(name: str) -> SensorModel:
    """The preset called ``name``.  Raises KeyError naming the allowed ones
    (the config validates the name first)."""
    try:
        return PRESETS[name]
    except KeyError:
        raise KeyError(f"no sensor model {name!r}; allowed: {', '.join(PRESETS)}") from None


def model_for(sensors: Sensors, back: bool) -> SensorModel:
    """The model of one pair as the robot config mounts it: its preset, with
    the config's cone (ROI) and tilt where it gives them."""
    name = sensors.back_model if back else sensors.front_model
    fov = sensors.back_fov_deg if back else sensors.front_fov_deg
    tilt = sensors.back_tilt_deg if back else sensors.front_tilt_deg
    model = preset(name)
    zone = specs.SPECS[name].zone_deg
    if fov is not None and zone > 0.0:  # rows of zones: the rays per zone the preset has
        model = replace(model, fov_deg=fov, rays=RAYS_PER_ZONE * round(fov / zone) + 1)
    elif fov is not None:
        model = replace(model, fov_deg=fov)
    if tilt:
        model = replace(model, tilt_deg=tilt)
    return model


def front_blocks(sensors: Sensors) -> tuple[SensorModel, ...]:
    """The front pair's model as mounted (:func:`model_for`), then, for a
    multizone sensor, the same block moved up 1, 2, ... rows while it stays
    within the sensor's field: what
    :func:`~stairbot.inputs.sensor_specs.rows_up` chooses from."""
    model = model_for(sensors, back=False)
    spec = specs.SPECS[sensors.front_model]
    if not spec.zones:
        return (model,)
    top = model.tilt_deg + model.fov_deg / 2.0
    return tuple(replace(model, tilt_deg=model.tilt_deg + k * spec.zone_deg)
                 for k in range(spec.zones)
                 if top + k * spec.zone_deg <= spec.fov_deg / 2.0 + 1e-6)
