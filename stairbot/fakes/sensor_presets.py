"""Sensor model presets, chosen per sensor pair in the robot config
(``[sensors] front_model``, ``back_model``).

Each figure says where it comes from.  "Datasheet" figures are the maker's;
"assumed" ones are ours (the datasheets do not give them: outlier and dropout
rates, how many rays stand for the cone) and are deliberately modest.  The
names must match :data:`stairbot.config.SensorModelName` (a test checks).
"""

from __future__ import annotations

from stairbot.fakes.sensor_model import SensorModel

# Today's behaviour: one ray straight along the mount, no latency, measured at
# every read, Gaussian noise of the scenario's [sensors] noise, the config's
# ranges and resolution.
IDEAL = SensorModel(name="ideal")

# ST VL53L1X time-of-flight ranger, long-distance mode.
# - Datasheet DS12385 (VL53L1X), "Features": typical full field of view 27
#   degrees; a programmable ROI on the receiving array reduces it (not
#   modelled: set fov_deg lower for a narrowed ROI); up to 400 cm; up to 50 Hz.
# - User manual UM2356 (VL53L1X API), section 2.2 "Timing considerations" and
#   2.5.2 "Timing budget and inter-measurement period": timing budget 20 ms
#   (short mode only) / 33 ms minimum for all modes, up to 1000 ms; the result
#   is ready at the end of the budget.  Here: 50 ms budget = inter-measurement
#   period, published at the end of it (latency 50 ms).
# - Range reported in millimetres (UM2356, VL53L1X_GetDistance): resolution 1 mm.
# - Minimum distance 4 cm (DS12385, "Features"/ranging section).
# - Maximum in long mode, dark, white target: 360 cm typical (DS12385 section
#   2.5 ranging performance table; not re-checked against the PDF here): the
#   weak-signal limit for a full, square beam.
# - Noise: the datasheet states a ranging error of about +-20 mm in the
#   ranging-performance section; assumed sigma = 3 mm + 0.5 % of the distance
#   (5 mm at 0.4 m, 18 mm at 3 m).
# - Assumed: 0.2 % outliers (a stray return), 0.5 % dropouts (a range status
#   other than "valid" for one measurement).
# - Multiple targets in the cone: the SPAD array returns a signal-weighted mix
#   ("weighted"): 5 rays up the cone, 3 across it.
VL53L1X = SensorModel(
    name="vl53l1x", fov_deg=27.0, rays=5, rays_across=3, aggregate="weighted",
    period_s=0.050, latency_s=0.050, noise_a=0.003, noise_b=0.005, resolution=0.001,
    outlier_rate=0.002, dropout_rate=0.005, min_range=0.04, max_range=4.0,
    weak_range=3.6,
)

# ST VL53L0X time-of-flight ranger, default mode.
# - Datasheet DocID029104 (VL53L0X), "Features": measures absolute range up to
#   2 m; section 1 / technical specification: field of view 25 degrees.
# - Same datasheet, ranging profiles table (section 2.4): default mode 30 ms
#   timing budget, 1.2 m; long range mode 33 ms, 2 m.  Here: default mode,
#   30 ms period and latency, 1.2 m weak-signal limit, 2 m the most reported.
# - Ranging accuracy table: about +-4 % indoors in default mode (read as 2
#   sigma): assumed sigma = 3 mm + 2 % of the distance.  Range in mm: 1 mm.
# - Minimum 3 cm: assumed (the datasheet's accuracy tables start there).
# - Assumed: 0.5 % outliers, 1 % dropouts; "weighted" mix of 5 x 3 rays.
VL53L0X = SensorModel(
    name="vl53l0x", fov_deg=25.0, rays=5, rays_across=3, aggregate="weighted",
    period_s=0.030, latency_s=0.030, noise_a=0.003, noise_b=0.02, resolution=0.001,
    outlier_rate=0.005, dropout_rate=0.01, min_range=0.03, max_range=2.0,
    weak_range=1.2,
)

# HC-SR04 ultrasonic ranger.
# - Datasheet "Ultrasonic Ranging Module HC-SR04" (Elecfreaks/SparkFun),
#   "Electric Parameter" table: max range 4 m, min range 2 cm, measuring angle
#   15 degrees; "Timing diagram": "we suggest to use over 60ms measurement
#   cycle"; the product text: "ranging accuracy can reach to 3mm" (resolution
#   3 mm here).  Its "Attention" notes: a target of at least 0.5 m^2, as
#   smooth as possible.
# - Latency: the echo pulse lasts up to ~23 ms at 4 m (distance = time * 340
#   m/s / 2, datasheet formula); assumed 25 ms.
# - Incidence-angle loss (assumed, not in the datasheet): a smooth surface
#   reflects the ping away; a ray meeting its surface more than 10 degrees off
#   the normal returns no echo, so the 15-degree cone hears a surface turned
#   up to about 17 degrees from its axis, and nothing beyond (OUT_OF_RANGE).
# - The first echo wins ("nearest"): 7 rays up the cone, 3 across.
# - Assumed noise: sigma = 2 mm + 0.3 % of the distance; 1 % outliers
#   (cross-talk, multipath), 1 % dropouts (no echo pulse).
HCSR04 = SensorModel(
    name="hcsr04", fov_deg=15.0, rays=7, rays_across=3, aggregate="nearest",
    period_s=0.060, latency_s=0.025, noise_a=0.002, noise_b=0.003, resolution=0.003,
    outlier_rate=0.01, dropout_rate=0.01, min_range=0.02, max_range=4.0,
    max_incidence_deg=10.0,
)

# Sharp GP2Y0A21YK0F infrared triangulation ranger (analog output).
# - Datasheet "GP2Y0A21YK / GP2Y0D21YK" (Sharp), "Electro-optical
#   Characteristics": distance measuring range 10 to 80 cm; "Timing chart":
#   one measurement every 38.3 ms +- 9.6 ms, its output held until the next
#   (latency: one period).
# - The output voltage goes roughly as 1/distance (datasheet "Example of
#   distance measuring characteristics"), so a fixed voltage noise grows in
#   distance with the distance: assumed sigma = 1 mm + 2 % of the distance
#   (3 mm at 0.1 m, 17 mm at 0.8 m); read through an ADC to 1 mm.
# - A narrow spot: assumed a 4-degree cone of 3 rays in the side view.
# - Assumed: 0.2 % outliers; no dropouts (an analog output has no status).
GP2Y0A21 = SensorModel(
    name="gp2y0a21", fov_deg=4.0, rays=3, rays_across=1, aggregate="weighted",
    period_s=0.0383, latency_s=0.0383, noise_a=0.001, noise_b=0.02, resolution=0.001,
    outlier_rate=0.002, min_range=0.10, max_range=0.80,
)

PRESETS: dict[str, SensorModel] = {m.name: m for m in (IDEAL, VL53L1X, VL53L0X, HCSR04, GP2Y0A21)}


def preset(name: str) -> SensorModel:
    """The preset called ``name``.  Raises KeyError naming the allowed ones
    (the config validates the name first)."""
    try:
        return PRESETS[name]
    except KeyError:
        raise KeyError(f"no sensor model {name!r}; allowed: {', '.join(PRESETS)}") from None
