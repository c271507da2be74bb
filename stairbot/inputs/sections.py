"""The robot config file's sections as typed structs (``[geometry]``,
``[masses]``, ``[motors]``, ``[sensors]``, ``[algorithm]``, ``[safety]``),
each field with its bounds: what :mod:`stairbot.inputs.config` reads a file
into before it resolves it."""

from __future__ import annotations

from typing import Annotated, Literal

import msgspec

from stairbot.inputs.sensor_specs import SPECS, SensorSpec

# Physical bounds: generous around any robot of this kind (the reference robot
# is 0.225 m long and 2.4 kg), tight enough that the simulation's pymunk world
# stays sane and a run ends (docs/config.md, "Bounds of the inputs").  Each
# number carries its unit (``extra["unit"]``, read by
# :func:`stairbot.inputs.schema.unit_at`: the console's parameters screen).
Length = Annotated[float, msgspec.Meta(ge=0.001, le=10.0, extra={"unit": "m"})]
"""A length that must be there: 1 mm to 10 m."""
Gap = Annotated[float, msgspec.Meta(ge=0.0, le=10.0, extra={"unit": "m"})]
"""A length that may be zero: 0 to 10 m."""
Mass = Annotated[float, msgspec.Meta(ge=0.001, le=1000.0, extra={"unit": "kg"})]
"""A mass: 1 g to 1 t."""
Degrees90 = Annotated[float, msgspec.Meta(ge=0, le=90, extra={"unit": "°"})]
"""A sensor's full cone: 0 to 90 degrees."""
Tilt = Annotated[float, msgspec.Meta(ge=-45, le=45, extra={"unit": "°"})]
"""A sensor's mounting tilt: -45 to 45 degrees."""
TurnsPerSecond = Annotated[float, msgspec.Meta(ge=0.01, le=1000.0,
                                                 extra={"unit": "turns/s"})]

# The kinds of distance sensor (stairbot.inputs.sensor_specs; the names must agree)
SensorModelName = Literal["ideal", "vl53l1x", "vl53l0x", "hcsr04", "gp2y0a21", "vl53l5cx"]


class Geometry(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    LENGTH_OF_FIRST_MODULE: Length
    LENGTH_OF_SECOND_MODULE: Length
    LENGTH_OF_THIRD_MODULE: Length
    segment_height: Length
    track_width: Length
    wheel_radius: Length
    wheel_inset: Length
    LENGTH_OF_A_ROBOT: Annotated[float, msgspec.Meta(gt=0, le=30.0,
                                                     extra={"unit": "m"})] | None = None
    """Optional; must equal the sum of the segments."""


class Masses(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    first_module: Mass
    second_module: Mass
    third_module: Mass
    wheel: Mass


class Motors(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    """Speeds in turns per second; what they make in m/s is bounded too
    (config_checks: WHEEL_SPEED_M_S, LIFT_SPEED_M_S)."""

    wheel_speed: TurnsPerSecond
    wheel_torque: Annotated[float, msgspec.Meta(ge=0.001, le=10000.0, extra={"unit": "N·m"})]
    """N*m: 1 mN*m to 10 kN*m."""
    lift_travel_per_turn: Annotated[float, msgspec.Meta(ge=0.00001, le=1.0, extra={"unit": "m"})]
    """m: 10 um to 1 m."""
    lift_speed: TurnsPerSecond
    lift_travel: Length
    lift_force: Annotated[float, msgspec.Meta(ge=0.01, le=100000.0, extra={"unit": "N"})]
    """N: 10 mN to 100 kN."""


class Sensors(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    front_height: Length
    front_lateral: Gap
    front_min_range: Gap
    front_max_range: Length
    back_from_rear: Gap
    back_height: Length
    back_lateral: Gap
    back_min_range: Gap
    back_max_range: Length
    resolution: Annotated[float, msgspec.Meta(ge=0.0, le=1.0, extra={"unit": "m"})]
    noise: Annotated[float, msgspec.Meta(ge=0.0, le=1.0, extra={"unit": "m"})] = 0.005
    """Stated sigma of a distance reading of the ``ideal`` model: perception
    derives its tolerances from it.  A named model states its own
    (stairbot.inputs.sensor_specs)."""
    front_model: SensorModelName = "ideal"
    """The kind of sensor SFR/SFL are (stairbot.inputs.sensor_specs): its timing and
    noise set perception's staleness limit and tolerances, and the simulation
    models it (stairbot.fakes.sensor_presets)."""
    back_model: SensorModelName = "ideal"
    """... and SBR/SBL."""
    front_fov_deg: Degrees90 | None = None
    """Full cone of SFR/SFL as mounted (a ToF's ROI narrows it), at most the
    model's; 0: one ray along the mount (what the ``ideal`` model has, and
    how a config that extends one with a cone takes the cone back); None
    (the key left out): the model's."""
    front_tilt_deg: Tilt = 0.0
    """Mounting tilt of SFR/SFL, degrees up."""
    back_fov_deg: Degrees90 | None = None
    """... of SBR/SBL, the same way."""
    back_tilt_deg: Tilt = 0.0
    """Mounting tilt of SBR/SBL, degrees towards the front."""
    side_model: SensorModelName | Literal["none"] = "none"
    """The side pair SSR/SSL (quarter-turn landings, the seed's extension 1):
    "none", the robot has none; else the kind of sensor they are."""
    side_height: Length = 0.03
    """Beam height of SSR/SSL above the wheels' contact line (they ride on
    segment 3: lifting it raises them)."""
    side_from_rear: Gap = 0.0375
    """From the rear end of segment 3 to the side pair, along the robot."""
    side_lateral: Gap = 0.09
    """Each side sensor's face this far right/left of the centre line."""
    side_min_range: Gap = 0.03
    side_max_range: Length = 1.3

    @property
    def has_side_pair(self) -> bool:
        """Whether the robot has SSR/SSL."""
        return self.side_model != "none"

    def spec(self, back: bool) -> SensorSpec:
        """The datasheet of the front (or back) pair's kind of sensor."""
        return SPECS[self.back_model if back else self.front_model]

    def side_spec(self) -> SensorSpec:
        """The datasheet of the side pair's kind of sensor (``has_side_pair``)."""
        return SPECS["ideal" if self.side_model == "none" else self.side_model]

    def range(self, back: bool) -> tuple[float, float]:
        """The pair's working range: the config's, within the sensor's own."""
        lo, hi = ((self.back_min_range, self.back_max_range) if back
                  else (self.front_min_range, self.front_max_range))
        return _within(self.spec(back), lo, hi)

    def side_range(self) -> tuple[float, float]:
        """The side pair's working range, as :meth:`range`."""
        return _within(self.side_spec(), self.side_min_range, self.side_max_range)

    def sigma(self, back: bool, distance_m: float) -> float:
        """The stated sigma of one reading of the pair at ``distance_m``."""
        return self.spec(back).sigma(distance_m, self.noise)


def _within(spec: SensorSpec, lo: float, hi: float) -> tuple[float, float]:
    """The range ``lo`` to ``hi`` within the sensor's own."""
    return (lo if spec.min_range is None else max(lo, spec.min_range),
            hi if spec.max_range is None else min(hi, spec.max_range))


class Algorithm(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    SAFE_DISTANCE_IN_FRONT_OF_STEP: Length
    SAFE_LENGTH: Length
    LENGTH_OF_INFINITY: Length
    approach_gap: Gap
    clearance_lift: Length
    drive_clearance: Length
    equal_tolerance: Annotated[float, msgspec.Meta(ge=0.0001, le=1.0, extra={"unit": "m"})]
    standing_wait: Annotated[float, msgspec.Meta(gt=0, le=3600.0, extra={"unit": "s"})]
    """Controller seconds, at most an hour."""
    max_steps: Annotated[int, msgspec.Meta(ge=1, le=20, extra={"unit": "steps"})]
    # at most 1 kHz: what a host drives over a serial link or a CAN bus (and the
    # simulation's physics step, 1/600 s, must fit in a tick for time to move)
    tick: Annotated[float, msgspec.Meta(ge=0.001, le=0.5, extra={"unit": "s"})]
    narrow_steps: bool = False
    """The seed's extension 3: climb treads down to LENGTH_OF_FIRST_MODULE +
    LENGTH_OF_SECOND_MODULE (+ SAFE_LENGTH), segment 3 in the air over the
    step below while segment 1 is lifted onto the next -- if segment 2's
    wheels alone carry the robot then
    (:func:`stairbot.control.algorithm.limits.narrow_steps_margin_m`)."""
    landings: bool = False
    """The seed's extension 1: at the top of a flight that ends on a landing
    with a wall ahead, look sideways with the side pair for the next flight,
    turn 90 degrees towards it and climb on; the descent comes back the same
    way.  Needs the side pair (``[sensors] side_model``)."""


class Safety(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    """What the supervisor watches every tick (stairbot.control.tilt) and the margin
    the static-stability check keeps before every lift
    (stairbot.control.algorithm.stability).  The defaults' reasons are in
    default_robot.toml."""

    imu: bool
    """The sensor board has an IMU: without one in a snapshot the robot stops
    (with a stale one it stands until a fresh one comes, for at most the
    sensor wait).  False: tilt is not watched, and the run says so."""
    max_pitch_deg: Annotated[float, msgspec.Meta(gt=0, le=30, extra={"unit": "°"})]
    max_roll_deg: Annotated[float, msgspec.Meta(gt=0, le=30, extra={"unit": "°"})]
    """Tilt beyond which every motor stops and the lifts hold (either sign)."""
    max_rate_dps: Annotated[float, msgspec.Meta(gt=0, le=1000, extra={"unit": "°/s"})]
    """Pitch or roll rate beyond which every motor stops, degrees per second."""
    imu_max_age_s: Annotated[float, msgspec.Meta(gt=0, le=1, extra={"unit": "s"})]
    """An IMU reading older than this cannot watch tilt: every motor stops
    until a fresher one comes (stairbot/control/tilt.py)."""
    stability_margin: Gap
    """Metres the centre of mass must stay inside the wheels that carry the
    robot while a lift moves."""


class ConfigFile(msgspec.Struct, forbid_unknown_fields=True, frozen=True):
    geometry: Geometry
    masses: Masses
    motors: Motors
    sensors: Sensors
    algorithm: Algorithm
    safety: Safety
