"""Robot config: the seed's constants under their seed names, in SI units,
the mechanical parameters they come from, and what follows from them.

Loaded from TOML (``--config FILE``); the shipped default describes the
reference robot.  Turn counts that follow from geometry are computed, never
typed in.  Bad files raise :class:`~stairbot.errors.ConfigError` naming the
file, the field and what is allowed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from stairbot.errors import ConfigError
from stairbot.files import shown
from stairbot.inputs.schema import convert, load_toml, read_named, shipped
from stairbot.inputs.sections import (
    Algorithm,
    ConfigFile,
    Geometry,
    Masses,
    Motors,
    Safety,
    Sensors,
)


@dataclass(frozen=True)
class RobotConfig:
    """The resolved config: the file's values plus what follows from them
    alone (turn counts, lengths, speeds).  What the controller allows a robot
    (the shortest tread, the lowest riser, narrow steps) is worked out from it
    by :mod:`stairbot.control.algorithm.limits`."""

    source: str
    geometry: Geometry
    masses: Masses
    motors: Motors
    sensors: Sensors
    algorithm: Algorithm
    safety: Safety

    # -- seed constants that are lengths (metres) -------------------------------
    @property
    def LENGTH_OF_FIRST_MODULE(self) -> float:  # noqa: N802 - the seed's name
        return self.geometry.LENGTH_OF_FIRST_MODULE

    @property
    def LENGTH_OF_SECOND_MODULE(self) -> float:  # noqa: N802
        return self.geometry.LENGTH_OF_SECOND_MODULE

    @property
    def LENGTH_OF_THIRD_MODULE(self) -> float:  # noqa: N802
        return self.geometry.LENGTH_OF_THIRD_MODULE

    @property
    def LENGTH_OF_A_ROBOT(self) -> float:  # noqa: N802
        g = self.geometry
        return g.LENGTH_OF_FIRST_MODULE + g.LENGTH_OF_SECOND_MODULE + g.LENGTH_OF_THIRD_MODULE

    @property
    def SAFE_DISTANCE_IN_FRONT_OF_STEP(self) -> float:  # noqa: N802
        return self.algorithm.SAFE_DISTANCE_IN_FRONT_OF_STEP

    @property
    def SAFE_LENGTH(self) -> float:  # noqa: N802
        return self.algorithm.SAFE_LENGTH

    @property
    def LENGTH_OF_INFINITY(self) -> float:  # noqa: N802
        return self.algorithm.LENGTH_OF_INFINITY

    @property
    def BACK_CLEARANCE(self) -> float:  # noqa: N802
        """SBR/SBL reading when segment 3 stands on the floor."""
        return self.sensors.back_height

    # -- seed constants that are turn counts (computed) -------------------------
    @property
    def wheel_circumference(self) -> float:
        return 2.0 * math.pi * self.geometry.wheel_radius

    def wheel_turns(self, metres: float) -> float:
        return metres / self.wheel_circumference

    def lift_turns(self, metres: float) -> float:
        return metres / self.motors.lift_travel_per_turn

    @property
    def MAX_OF_VERTICAL_TURNS(self) -> float:  # noqa: N802
        return self.lift_turns(self.motors.lift_travel)

    @property
    def NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE(self) -> float:  # noqa: N802
        return self.lift_turns(self.algorithm.clearance_lift)

    @property
    def NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH(self) -> float:  # noqa: N802
        a = self.algorithm
        return self.wheel_turns(a.SAFE_DISTANCE_IN_FRONT_OF_STEP - a.approach_gap)

    @property
    def NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE(self) -> float:  # noqa: N802
        return self.wheel_turns(self.geometry.LENGTH_OF_FIRST_MODULE)

    @property
    def NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE(self) -> float:  # noqa: N802
        return self.wheel_turns(self.geometry.LENGTH_OF_SECOND_MODULE)

    @property
    def initial_number_of_vertical_turns(self) -> float:
        """MTF turns past the moment the front sensors see over the step: the beam
        height above the wheels plus the drive clearance."""
        return self.lift_turns(self.sensors.front_height + self.algorithm.drive_clearance)

    # -- what the robot can climb ------------------------------------------------
    @property
    def max_step_rise_m(self) -> float:
        """Highest rise the ascent accepts: the sensors must see over it before MTF
        has made MAX_OF_VERTICAL_TURNS - number_of_vertical_turns turns, so the
        beam (front_height above the wheels) may rise at most lift_travel -
        front_height - drive_clearance: the rise is at most lift_travel -
        drive_clearance.

        This is the limit of a rigid robot with a level beam.  A real one loses
        a little to the nose-down pitch that the cantilevered segment 1 puts on
        the wheels of segment 2: the beam must still clear the tread
        LENGTH_OF_A_ROBOT + SAFE_LENGTH ahead.  The simulated robot loses under
        1 mm (docs/algorithm.md, ascent 3).  What the robot publishes
        (:func:`stairbot.control.algorithm.limits.max_step_rise_m`) also takes
        off how high over the step the front pair's lowest ray must look to
        read past the riser (a cone looking down meets the step's own tread
        nearer than the sensor reads)."""
        lift_at_sight = self.motors.lift_travel - (
            self.sensors.front_height + self.algorithm.drive_clearance
        )
        return lift_at_sight + self.sensors.front_height

    @property
    def max_drop_m(self) -> float:
        """Deepest drop a continuous descent lowers segment 3 into: MTB's whole
        stroke down, MAX_OF_VERTICAL_TURNS.  Deeper ones are refused."""
        return self.MAX_OF_VERTICAL_TURNS * self.motors.lift_travel_per_turn

    @property
    def _front_fov_deg(self) -> float:
        """The front pair's cone: the config's ``front_fov_deg``, else its model's."""
        s = self.sensors
        return s.spec(back=False).fov_deg if s.front_fov_deg is None else s.front_fov_deg

    @property
    def front_cone_top_rad(self) -> float:
        """How far above level the front pair's highest ray looks: the mount's
        tilt plus half the cone (0 for one level ray)."""
        return math.radians(max(0.0, self.sensors.front_tilt_deg + self._front_fov_deg / 2.0))

    @property
    def front_cone_bottom_rad(self) -> float:
        """How far below level the front pair's lowest ray looks: half the
        cone less the mount's tilt (0 when none looks down)."""
        return math.radians(max(0.0, self._front_fov_deg / 2.0 - self.sensors.front_tilt_deg))

    def min_rise_for(self, tread_m: float) -> float:
        """Lowest next riser it can measure a tread of ``tread_m`` against:
        once the front sensors see over a riser, segment 1 rises
        number_of_vertical_turns more before the tread is measured, and the
        pair must not see past the next riser meanwhile (with 10 mm to spare)
        -- nor may the top of a cone, which climbs (tread + approach_gap) x
        tan(front_cone_top_rad) over that distance."""
        reach = (tread_m + self.algorithm.approach_gap) * math.tan(self.front_cone_top_rad)
        return self.sensors.front_height + self.algorithm.drive_clearance + 0.01 + reach

    @property
    def wheel_speed_m_s(self) -> float:
        return self.motors.wheel_speed * self.wheel_circumference

    @property
    def lift_speed_m_s(self) -> float:
        return self.motors.lift_speed * self.motors.lift_travel_per_turn



DEFAULT_CONFIG_NAME = "default_robot.toml"


def resolve_config(text: str, source: str) -> RobotConfig:
    """A config document (and the one it ``extends``) read into a
    RobotConfig, each field's type and bounds checked; how the values fit
    together is checked by :func:`check_consistency`, which
    :func:`stairbot.control.robot_config.parse_config` runs with the
    controller's limits.  Raises ConfigError naming the file, the field and
    what it allows."""
    raw = _extended(load_toml(text, source, ConfigError), source, ())
    data = convert(raw, ConfigFile, source, ConfigError)
    return RobotConfig(source, data.geometry, data.masses, data.motors, data.sensors,
                       data.algorithm, data.safety)


REFERENCE = "reference"
"""The shipped reference robot's name (``extends = "reference"``, ``--config reference``)."""


MAX_EXTENDS = 8
"""The most configs one config stands on through ``extends`` (the one it
names, the one that one names, and so on): a deeper chain is refused, and so
is a loop."""


def _extended(raw: dict[str, Any], source: str, chain: tuple[str, ...]) -> dict[str, Any]:
    """``raw`` laid over the config it names in ``extends`` (a shipped robot, or
    a file beside it), and that one over its own: tables key by key, anything
    else replaced.  ``chain`` holds the sources that extend this one, the
    first one loaded first.  Raises ConfigError on a loop (naming its files)
    or on a chain of more than :data:`MAX_EXTENDS`."""
    out: dict[str, Any] = {}
    for _, layer in _layers(raw, source, chain):
        out = _merged(out, layer)
    return out


def _layers(raw: dict[str, Any], source: str,
            chain: tuple[str, ...]) -> list[tuple[str, dict[str, Any]]]:
    """The configs :func:`_extended` lays one over the other, each with its
    source, the one at the bottom of the chain first and ``raw`` (without
    its ``extends``) last.  Raises ConfigError as :func:`_extended` does."""
    chain = (*chain, source)
    base = raw.pop("extends", None)
    if base is None:
        return [(source, raw)]
    if not isinstance(base, str) or not base:
        raise ConfigError(source, "extends", "must be a shipped robot's name ("
                          + ", ".join(shipped_configs()) + ") or a config file's path")
    text, base_source = config_text(base, Path(source).parent if Path(source).exists() else None)
    ids = [_identity(s) for s in chain]
    if _identity(base_source) in ids:
        loop = (*chain[ids.index(_identity(base_source)):], base_source)
        raise ConfigError(source, "extends", f"{base!r} makes a loop: "
                          + " -> ".join(shown(s) for s in loop)
                          + "; allowed: a chain without loops")
    if len(chain) > MAX_EXTENDS:
        raise ConfigError(source, "extends", f"{base!r}: the chain of extends from "
                          f"{shown(chain[0])} goes deeper than {MAX_EXTENDS} configs; "
                          f"allowed: a config stands on at most {MAX_EXTENDS} others")
    return [*_layers(load_toml(text, base_source, ConfigError), base_source, chain),
            (source, raw)]


def value_sources(text: str, source: str) -> dict[str, str]:
    """Which config of the ``extends`` chain set each value of a config
    document: ``"section.key"`` -> the source of the last one to set it (a
    file's path, ``<robot NAME>``, ``<default ...>``).  A key no config of
    the chain sets is left out: its value is the schema's default.  Raises
    ConfigError as :func:`resolve_config` does."""
    out: dict[str, str] = {}
    for layer_source, layer in _layers(load_toml(text, source, ConfigError), source, ()):
        for section, table in layer.items():
            if isinstance(table, dict):
                out.update({f"{section}.{key}": layer_source for key in table})
    return out


def _identity(source: str) -> str:
    """What tells two configs of a chain apart: a file's resolved path (one
    file by two spellings is one), else the source's name (``<robot ir>``)."""
    path = Path(source)
    return str(path.resolve()) if path.is_file() else source


def _merged(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for key, value in over.items():
        old = base.get(key)
        out[key] = _merged(old, value) if isinstance(value, dict) and isinstance(old, dict) \
            else value
    return out


def config_text(path: str | Path | None, beside: Path | None = None) -> tuple[str, str]:
    """The text and source name of a config: the reference robot (None or
    ``"reference"``), a shipped robot by name, or a file (relative to
    ``beside`` when given)."""
    if path is None or path == REFERENCE:
        text = resources.files("stairbot.inputs").joinpath(DEFAULT_CONFIG_NAME).read_text("utf-8")
        return text, f"<default {DEFAULT_CONFIG_NAME}>"
    if beside is not None and isinstance(path, str) and (beside / path).exists():
        path = beside / path
    return read_named(path, SHIPPED_DIR, "robot", ConfigError, also=(REFERENCE,))


def robot_shown(source: str) -> str:
    """A config's source as a person reads it: a shipped robot as its name
    ("reference (shipped)", "landings (shipped)"), a file as its path."""
    ref = source_ref(source)
    return source if ref == source else f"{ref} (shipped)"


SHIPPED_DIR = "configs"


def shipped_configs() -> list[str]:
    """Names of the robot configs shipped with stairbot (``--config NAME``)."""
    return sorted([REFERENCE, *shipped(SHIPPED_DIR)])


def source_ref(source: str) -> str:
    """What :func:`config_text` takes to read a config again from its source
    name: a shipped robot's name (``"reference"``, ``"ir"``), else the
    source itself (a file's path)."""
    if source == f"<default {DEFAULT_CONFIG_NAME}>":
        return REFERENCE
    if source.startswith("<robot ") and source.endswith(">"):
        return source[len("<robot "):-1]
    return source


def config_table(path: str | Path | None = None) -> dict[str, Any]:
    """A config's document as plain data with what it ``extends`` laid under
    it (no ``extends`` left): a sweep's base for its cases.  Raises ConfigError."""
    text, source = config_text(path)
    return _extended(load_toml(text, source, ConfigError), source, ())
