"""What the controller knows of each kind of distance sensor: its datasheet's
timing, noise and range.

The robot config names the kind fitted on each pair (``[sensors]
front_model``, ``back_model``).  Perception takes its tolerances from the
stated noise and its staleness limit from the timing here; the simulation's
sensor models (:mod:`stairbot.fakes.sensor_presets`) are built on the same
figures, plus what only a simulation needs (the cone's rays, outlier and
dropout rates).  Pure data: the core may import it.

"Datasheet" figures are the maker's; "assumed" ones are ours.  The names must
match :data:`stairbot.inputs.config.SensorModelName` (a test checks).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class SensorSpec:
    """One kind of distance sensor, as its datasheet states it.  None: the
    robot config's value (ranges, resolution) or its ``[sensors] noise``."""

    name: str
    period_s: float = 0.0
    """Between measurements; 0: a new one at every read."""
    latency_s: float = 0.0
    """From a measurement to its publication."""
    noise_a: float | None = None
    """Stated sigma = noise_a + noise_b * distance (m)."""
    noise_b: float = 0.0
    resolution: float | None = None
    min_range: float | None = None
    max_range: float | None = None
    fov_deg: float = 0.0
    """Full angle of the cone as shipped (a ToF's ROI may narrow it: the robot
    config's ``front_fov_deg`` / ``back_fov_deg``)."""
    first_echo: bool = False
    """It reports the nearest surface anywhere in its cone (an ultrasonic
    ranger's first echo), not a mean over the cone."""
    zones: int = 0
    """A multizone sensor's zones along each side of its square field (8: an
    8x8 grid, each zone ``fov_deg / zones`` square); 0: one zone, the cone."""
    echo_incidence_deg: float | None = None
    """A ranger that hears a surface only where its ray meets it within this
    many degrees of the surface's normal (an ultrasonic ranger: a smooth
    floor at a graze returns no echo); None: any surface in the cone counts."""

    @property
    def zone_deg(self) -> float:
        """The angle of one zone (0: not a multizone sensor)."""
        return self.fov_deg / self.zones if self.zones else 0.0

    def sigma(self, distance_m: float, stated_noise: float) -> float:
        """The stated sigma of a reading at ``distance_m``."""
        a = stated_noise if self.noise_a is None else self.noise_a
        return a + self.noise_b * max(0.0, distance_m)


# Today's simulated sensor: one ray, measured at every read, the config's noise.
IDEAL = SensorSpec(name="ideal")

# ST VL53L1X time-of-flight ranger, long-distance mode.
# - Datasheet DS12385, "Features": full field of view 27 degrees (the ROI on the
#   receiving array narrows it); 4 cm to 4 m; up to 50 Hz.
# - UM2356 (VL53L1X API) 2.5.2 "Timing budget and inter-measurement period":
#   budget 33 ms minimum for all modes.  Here 50 ms budget = period, the result
#   ready at its end (latency 50 ms); reported in mm.
# - Noise: the datasheet's ranging error is about +-20 mm; assumed sigma =
#   3 mm + 0.5 % of the distance (5 mm at 0.4 m, 18 mm at 3 m).
VL53L1X = SensorSpec(name="vl53l1x", period_s=0.050, latency_s=0.050, noise_a=0.003,
                     noise_b=0.005, resolution=0.001, min_range=0.04, max_range=4.0,
                     fov_deg=27.0)

# ST VL53L0X time-of-flight ranger, default mode.
# - Datasheet DocID029104: up to 2 m; field of view 25 degrees; ranging
#   profiles table: default mode 30 ms budget, 1.2 m.
# - Accuracy about +-4 % indoors in default mode (read as 2 sigma): assumed
#   sigma = 3 mm + 2 % of the distance.  Range in mm.  Minimum 3 cm (assumed:
#   the accuracy tables start there).
VL53L0X = SensorSpec(name="vl53l0x", period_s=0.030, latency_s=0.030, noise_a=0.003,
                     noise_b=0.02, resolution=0.001, min_range=0.03, max_range=2.0,
                     fov_deg=25.0)

# HC-SR04 ultrasonic ranger.
# - Datasheet (Elecfreaks/SparkFun), "Electric Parameter": 2 cm to 4 m,
#   measuring angle 15 degrees; "we suggest to use over 60ms measurement
#   cycle"; "ranging accuracy can reach to 3mm".
# - Latency: the echo pulse lasts up to ~23 ms at 4 m: assumed 25 ms.
# - Assumed sigma = 2 mm + 0.3 % of the distance.
# - The first echo back ends the measurement: the nearest surface in the cone.
# - Incidence (assumed, not in the datasheet; its "Attention" notes ask for a
#   target of at least 0.5 m^2, as smooth as possible): a ray meeting its
#   surface more than 10 degrees off the normal returns no echo.
HCSR04 = SensorSpec(name="hcsr04", period_s=0.060, latency_s=0.025, noise_a=0.002,
                    noise_b=0.003, resolution=0.003, min_range=0.02, max_range=4.0,
                    fov_deg=15.0, first_echo=True, echo_incidence_deg=10.0)

# Sharp GP2Y0A21YK0F infrared triangulation ranger (analog output).
# - Datasheet "Electro-optical Characteristics": 10 to 80 cm; "Timing chart":
#   one measurement every 38.3 ms +- 9.6 ms, held until the next.
# - Output roughly as 1/distance: assumed sigma = 1 mm + 2 % of the distance,
#   read through an ADC to 1 mm.  A narrow spot: assumed a 4-degree cone.
GP2Y0A21 = SensorSpec(name="gp2y0a21", period_s=0.0383, latency_s=0.0383, noise_a=0.001,
                      noise_b=0.02, resolution=0.001, min_range=0.10, max_range=0.80,
                      fov_deg=4.0)

# ST VL53L5CX multizone time-of-flight ranger, 8x8 zones.
# - ST product text (the VL53L5CX page, quoted in the SparkFun and
#   ironsheep driver repositories): 8x8 zones, a 63-degree diagonal square
#   field of view, ranging up to 400 cm, several targets per zone.  Taken as
#   45 x 45 degrees, zones of 5.625 (derived: ST's diagonal is the side times
#   sqrt 2, 63.6; the VL53L8CX, whose user manual UM3109 states a 45 x 45
#   square, is quoted at 65 diagonal in DS14161).
# - ST ULD API (STSW-IMG023) example 1: "Using 8x8, min frequency is 1Hz and
#   max is 15Hz": a frame every 1/15 s, published at the frame's end
#   (latency one period, as the VL53L1X here).
# - Assumed (the datasheet DS13754's accuracy table and minimum distance
#   were not retrieved): sigma = 3 mm + 0.5 % of the distance, as the
#   VL53L1X; from 2 cm; reported in mm.
VL53L5CX = SensorSpec(name="vl53l5cx", period_s=1.0 / 15.0, latency_s=1.0 / 15.0,
                      noise_a=0.003, noise_b=0.005, resolution=0.001, min_range=0.02,
                      max_range=4.0, fov_deg=45.0, zones=8)

SPECS: dict[str, SensorSpec] = {s.name: s for s in (IDEAL, VL53L1X, VL53L0X, HCSR04, GP2Y0A21,
                                                   VL53L5CX)}


ROW_SWITCH_PITCH_DEG = 2.0
"""Pitched nose down by more than this (segment 2, as the sensor board's IMU
reads it), the board publishes a multizone pair's block of zones moved up
by whole rows (:func:`rows_up`): a level row pitched down looks at the
tread or floor ahead (5 degrees down from 3 cm: 0.34 m), as happens from
ascent 5 to 7.  Within it, the lowest rays meet the floor beyond 0.86 m at
a grazing angle: too weak a return to read.  The simulation's board does
this (:mod:`stairbot.fakes.sensor_presets`), and the controller reckons
with it (:mod:`stairbot.control.algorithm.sight`)."""


def rows_up(pitch_deg: float, zone_deg: float) -> int:
    """Rows the board moves a block of zones up at ``pitch_deg`` (+ nose
    up): none within :data:`ROW_SWITCH_PITCH_DEG` of level, else one per
    ``zone_deg`` of nose-down pitch beyond it, rounded up."""
    if pitch_deg >= -ROW_SWITCH_PITCH_DEG:
        return 0
    return math.ceil((-pitch_deg - ROW_SWITCH_PITCH_DEG) / zone_deg)
