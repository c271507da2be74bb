"""Changing a runtime-safe parameter between runs (the parameters screen,
``i``): the value checked by the product's own checks, then a small TOML
file that ``extends`` the config the console started with and sets only the
values changed, written under a name not taken (never over a file), and
loaded for the next run.  Pure but for :func:`write`; no Textual here.

**Runtime-safe** (:data:`RUNTIME_SAFE`): values the controller reads when a
run starts, that change neither the robot's shape nor what its sensors see,
and that no change within the bounds below makes less safe than the config
the console started with:

* ``motors.wheel_speed``, ``motors.lift_speed``: the speeds the controller
  commands and the supervisor clamps to.  Lower only (at most the started
  config's), and down to half of it: the motors are the ones it was built
  with (the simulation's world keeps their limits), and every timing that
  follows from a speed (the phase timeout, how far the robot backs in one
  measurement) is worked out again from the new one, so a much slower robot
  would be found stalled that much later.
* ``algorithm.standing_wait``: how long the standing rule waits, motors
  stopped, before it measures again; from half to twice the started
  config's, within the schema's bounds.
* ``algorithm.max_steps``: how many steps the ascent climbs before it
  turns to the descent; within the schema's bounds.
* ``safety.max_pitch_deg``, ``safety.max_roll_deg``,
  ``safety.max_rate_dps``, ``safety.imu_max_age_s``: the supervisor's stop
  thresholds.  Tighter only (at most the started config's): a tighter one
  can only stop the robot sooner.  (The narrow steps' stability check works
  with the pitch the supervisor allows, so a tighter ``max_pitch_deg`` can
  let it pass: the check's own verdict, with the bound kept every tick.)
* ``safety.stability_margin``: how far inside its wheels the centre of mass
  must stay before a lift moves.  Larger only (at least the started
  config's), up to what the config checks allow.

Not runtime-safe: the geometry, masses, sensors and their placement, the
lifts' travel, the control tick and the algorithm's lengths (what the
robot is and what it sees; the simulation's world is built from them),
and the switches ``narrow_steps`` and ``landings`` (what the robot tries).
They change in the config file, for a console started on it.
"""

from __future__ import annotations

import errno
import json
import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import msgspec

from stairbot.console.params import SECTIONS, shown_value
from stairbot.control.robot_config import parse_config
from stairbot.errors import ConfigError, InputError
from stairbot.files import shown
from stairbot.inputs.config import RobotConfig, robot_shown, source_ref
from stairbot.inputs.schema import describe_at, unit_at
from stairbot.inputs.sections import ConfigFile
from stairbot.run.paths import unused_path

Way = Literal["any", "lower", "higher"]


@dataclass(frozen=True)
class Rule:
    """Which way a runtime-safe value may move from the started config's."""

    way: Way
    why: str
    share: tuple[float, float] | None = None
    """The least and most share of the started config's value it may take
    (None: the schema's bounds and ``way`` alone)."""


RUNTIME_SAFE: dict[str, Rule] = {
    # at most half as fast: a slower robot's phase timeouts stretch with it, and a
    # stalled robot is found that much later
    "motors.wheel_speed": Rule("lower", "the wheels' motors are the ones the robot has",
                               (0.5, 1.0)),
    "motors.lift_speed": Rule("lower", "the lifts' motors are the ones the robot has",
                              (0.5, 1.0)),
    "algorithm.standing_wait": Rule("any", "the robot waits standing still", (0.5, 2.0)),
    "algorithm.max_steps": Rule("any", "the ascent turns to the descent sooner or later"),
    "safety.max_pitch_deg": Rule("lower", "a tighter threshold stops the robot sooner"),
    "safety.max_roll_deg": Rule("lower", "a tighter threshold stops the robot sooner"),
    "safety.max_rate_dps": Rule("lower", "a tighter threshold stops the robot sooner"),
    "safety.imu_max_age_s": Rule("lower", "a tighter threshold stops the robot sooner"),
    "safety.stability_margin": Rule("higher", "a larger margin keeps the weight further in"),
}
"""The values the console may change between runs (the module's docstring
says why each)."""

MAX_NAMES = 9999
"""The most numbered names (``NAME-params-N.toml``) a write tries."""

WRITTEN_BY = ("# Written by the stairbot console (parameters, key i): the config it\n"
              "# extends, with the values the operator changed between runs.\n")


def value_of(cfg: RobotConfig, key: str) -> Any:
    section, name = key.split(".", 1)
    return getattr(getattr(cfg, section), name)


def allowed(key: str, started: RobotConfig) -> str:
    """What ``key`` may be set to, in words: the schema's bounds and the rule's."""
    rule = RUNTIME_SAFE[key]
    unit = unit_at(ConfigFile, key) or ""
    bounds = describe_at(ConfigFile, key)
    base = value_of(started, key)
    if rule.share is not None:
        lo, hi = (shown_value(base * f) for f in rule.share)
        return (f"{bounds} {unit}, and from {lo} to {hi} {unit} (the config the console "
                f"started with: {shown_value(base)})")
    if rule.way == "any":
        return f"{bounds} {unit}".strip()
    side = "at most" if rule.way == "lower" else "at least"
    return (f"{bounds} {unit}, and {side} {shown_value(base)} {unit} (the config the "
            "console started with)")


@dataclass(frozen=True)
class Edit:
    """A change checked and ready to be written: nothing is written yet."""

    key: str
    old: Any
    new: Any
    path: Path
    """Where it will be written (a name not taken when it was checked)."""
    text: str
    """The whole file."""
    config: RobotConfig
    """What the file resolves to (checked by the product's config checks)."""
    overrides: dict[str, Any]


class Parameters:
    """The changes the console made to the config it started with: each
    new file extends that config (not the last file written), so a chain of
    changes never grows deeper than one file."""

    def __init__(self, started: RobotConfig, config_home: Path | None = None) -> None:
        self.started = started
        ref = source_ref(started.source)
        self.shipped = ref != started.source
        self.base = ref if self.shipped else str(Path(ref).resolve())
        """What a new file extends: a shipped robot's name, or the started file's
        whole path (the file then reads the same from any directory)."""
        self.folder = (config_home or _config_home()) if self.shipped else Path(self.base).parent
        self.overrides: dict[str, Any] = {}
        self.written: Path | None = None
        """The last file written (the one the console's runs use)."""

    def propose(self, current: RobotConfig, key: str, typed: str) -> Edit:
        """``key`` set to the value ``typed`` (as TOML spells it), checked:
        a runtime-safe key, the schema's type and bounds, the rule's way,
        then the whole config through the product's config checks.  Raises
        InputError naming the key, what is wrong and what is allowed."""
        if key not in RUNTIME_SAFE:
            raise InputError(key, None, "not runtime-safe: it changes in the config file, "
                             "for a console started on it; runtime-safe: "
                             + ", ".join(RUNTIME_SAFE))
        if not self.shipped and not Path(self.base).is_file():
            raise InputError(key, None, f"the config came from {shown(self.base)}, no "
                             "file a new one can extend; allowed: a console started on a "
                             "config file or a shipped robot")
        what = allowed(key, self.started)
        new = _parsed(typed, what, whole=isinstance(value_of(self.started, key), int))
        if new is None:
            raise InputError(key, None, f"{typed.strip()!r} is not allowed; allowed: {what}")
        old = value_of(current, key)
        if new == old:
            raise InputError(key, None, f"{shown_value(new)} is its value already; "
                             f"allowed: {what}")
        rule, base = RUNTIME_SAFE[key], value_of(self.started, key)
        if isinstance(new, int | float) and (
                rule.way == "lower" and new > base or rule.way == "higher" and new < base
                or rule.share is not None and not base * rule.share[0] <= new
                <= base * rule.share[1]):
            raise InputError(key, None, f"{shown_value(new)} is not allowed ({rule.why}); "
                             f"allowed: {what}")
        overrides = dict(self.overrides)
        overrides[key] = new
        overrides = {k: v for k, v in overrides.items() if v != value_of(self.started, k)}
        path = Path(unused_path(str(self.folder / self._name())))
        text = self.text(overrides)
        try:
            config = parse_config(text, str(path))
        except ConfigError as exc:
            where = exc.field or key
            raise InputError(where, None, exc.problem) from None
        self.check_rest(config, overrides)
        return Edit(key, old, new, path, text, config, overrides)

    def check_rest(self, config: RobotConfig, overrides: dict[str, Any]) -> None:
        """InputError unless ``config`` (a file written here, as read back
        now) holds the started config's values but for ``overrides``: the
        file it extends is read again at each load, and a value changed there
        since the console started (a geometry, a looser threshold) would
        reach the next run unchecked and unshown."""
        moved = [f"{key} {shown_value(value_of(self.started, key))} → "
                 f"{shown_value(value_of(config, key))}"
                 for key in _keys(self.started)
                 if key not in overrides and value_of(config, key) != value_of(self.started, key)]
        if moved:
            raise InputError(shown(self.base), None,
                             "changed since the console started (" + ", ".join(moved[:3])
                             + (", ..." if len(moved) > 3 else "") + "); allowed: values as "
                             "the console started with, but for those changed here (start "
                             "the console again to use the file's new values)")

    def text(self, overrides: dict[str, Any]) -> str:
        """The file that extends :attr:`base` and sets ``overrides``."""
        lines = [WRITTEN_BY, f"extends = {json.dumps(self.base)}\n"]
        sections: dict[str, list[str]] = {}
        for key, value in sorted(overrides.items()):
            section, name = key.split(".", 1)
            sections.setdefault(section, []).append(f"{name} = {_toml(value)}")
        for section, entries in sections.items():
            lines.append(f"\n[{section}]\n" + "".join(e + "\n" for e in entries))
        return "".join(lines)

    def _name(self) -> str:
        stem = Path(self.base).stem if not self.shipped else self.base
        return re.sub(r"-params(-\d+)?$", "", stem) + "-params.toml"

    def write(self, edit: Edit) -> Path:
        """Write ``edit``'s file under a name no file has (``edit.path``, else
        the next free one beside it: a file is never overwritten) and take
        its values as the console's changes.  Returns the path written.
        Raises OSError when the folder or the disk refuses it (nothing is
        taken then)."""
        self.folder.mkdir(parents=True, exist_ok=True)
        path, stem = edit.path, Path(self._name()).stem
        for n in range(1, MAX_NAMES + 1):
            try:
                with open(path, "x", encoding="utf-8") as out:
                    out.write(edit.text)
                    out.flush()
                    os.fsync(out.fileno())
                break
            except FileExistsError:  # taken (since it was checked, or by a directory,
                # a FIFO, a dangling link, which unused_path lets keep their name)
                path = self.folder / f"{stem}-{n}.toml"
        else:
            raise FileExistsError(errno.EEXIST, f"every name up to {stem}-{MAX_NAMES}.toml "
                                  "is taken", str(self.folder))
        self.overrides, self.written = dict(edit.overrides), path
        return path

    def describe_source(self) -> str:
        """What the runs' config is, as the screen's title says it."""
        if self.written is None:
            return robot_shown(self.started.source)
        return f"{shown(self.written)} (extends {robot_shown(self.started.source)})"


def _keys(cfg: RobotConfig) -> list[str]:
    """Every ``section.name`` of a config."""
    return [f"{section}.{name}" for section in SECTIONS
            for name in msgspec.structs.asdict(getattr(cfg, section))]


def _config_home() -> Path:
    """``$XDG_CONFIG_HOME/stairbot`` (``~/.config/stairbot``): where the
    changes to a shipped robot are written."""
    home = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(home) / "stairbot"


def _parsed(typed: str, what: str, whole: bool) -> int | float | None:
    """The number typed, as TOML reads it: a whole number where ``whole``,
    else any number (as a float); None when it is not one."""
    try:
        value = tomllib.loads(f"v = {typed.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or (whole and not isinstance(value, int)):
        return None
    return value if whole else float(value)


def _toml(value: Any) -> str:
    """A number as TOML writes it."""
    return repr(value) if isinstance(value, float) else str(value)

