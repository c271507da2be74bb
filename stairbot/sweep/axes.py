"""A sweep spec's axes: the paths an axis may vary (a scenario's fields, a
robot config's as ``config.SECTION.KEY``, and the virtual jitters), how an
``[axes]`` entry is read (a value, a list, a range, a distribution), and the
generator each sampled draw comes from.  Everything wrong with an axis
raises :class:`SpecError` naming ``axes.PATH``."""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Any

import msgspec.inspect as mi

from stairbot.errors import InputError
from stairbot.inputs.scenario import ScenarioFile
from stairbot.inputs.schema import _tokens, _type_at
from stairbot.inputs.sections import ConfigFile


class SpecError(InputError):
    """A sweep spec is malformed: the CLI exits 2 before any case runs."""


GRID_KINDS = ("list", "range")
SAMPLED_KINDS = ("uniform", "normal", "choice", "randint")
DISTRIBUTIONS = ("range", *SAMPLED_KINDS)
VIRTUAL = {
    "stairs.rise_jitter": "each step's rise varies uniformly by up to this much, m",
    "stairs.tread_jitter": "each step's tread varies uniformly by up to this much, m",
}
NORMAL_SIGMAS = 4.0  # a normal axis must be valid this many deviations either side
MAX_CASES = 100_000
"""The most cases a spec may make (grid points times samples), counted from
its axes before any case is built: more would take days to run even on a
cluster, and hours only to build and check (docs/envelope.md)."""


@dataclass(frozen=True)
class Axis:
    """One axis: a grid (``list``/``range``: every value, a product with the other
    grids) or a distribution drawn once per case."""

    path: str
    kind: str
    values: tuple[Any, ...] = ()
    params: tuple[float, ...] = ()

    @property
    def sampled(self) -> bool:
        return self.kind in SAMPLED_KINDS

    def draw(self, rng: random.Random) -> Any:
        if self.kind == "uniform":
            return rng.uniform(self.params[0], self.params[1])
        if self.kind == "normal":
            return rng.gauss(self.params[0], self.params[1])
        if self.kind == "randint":
            return rng.randint(int(self.params[0]), int(self.params[1]))
        return self.values[rng.randrange(len(self.values))]

    def extremes(self) -> list[Any]:
        """The values a distribution can reach at its edges (checked up front)."""
        if self.kind == "randint":
            return [int(p) for p in self.params]
        if self.kind == "uniform":
            return list(self.params)
        if self.kind == "normal":
            mu, sd = self.params
            return [mu - NORMAL_SIGMAS * sd, mu + NORMAL_SIGMAS * sd]
        return list(self.values)

    def describe(self) -> str:
        if self.kind in ("list", "range", "choice"):
            return f"{self.kind} of {len(self.values)}"
        return f"{self.kind}({', '.join(f'{p:g}' for p in self.params)})"


def case_rng(seed: int, index: int, what: str) -> random.Random:
    """The generator for one draw: the same (seed, case, axis) gives the same value
    on every machine and Python version (string seeds hash with SHA-512)."""
    return random.Random(f"{seed}/{index}/{what}")


# -- parsing ---------------------------------------------------------------------


def _known_type(path: str) -> Any:
    """The schema type at a dotted axis path, or None when there is no such field."""
    if path in VIRTUAL:
        return "virtual"
    if path.startswith("config."):
        return _type_at(ConfigFile, _tokens("." + path.removeprefix("config.")))
    # the robot is the spec's (sweep.config, or the base scenario's robot), not an axis
    if path.split(".")[0].split("[")[0] in ("expect", "name", "description", "robot"):
        return None
    return _type_at(ScenarioFile, _tokens("." + path))


def _allowed_paths() -> str:
    paths = []
    for name in ("stairs", "start", "sensors", "faults"):
        sub = _type_at(ScenarioFile, [name])
        if isinstance(sub, mi.StructType):
            paths += [f"{name}.{g.encode_name}" for g in sub.fields]
        else:
            paths.append(name)
    paths += list(VIRTUAL)
    return ", ".join(paths) + ", faults[N].KEY, config.SECTION.KEY (see `stairbot config show`)"


def flatten(table: dict[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    out: list[tuple[str, Any]] = []
    for key, value in table.items():
        path = f"{prefix}.{key}" if prefix else key
        is_dist = isinstance(value, dict) and (
            bool(set(value) & set(DISTRIBUTIONS)) or _known_type(path) is not None)
        if isinstance(value, dict) and not is_dist:
            out += flatten(value, path)
        else:
            out.append((path, value))
    return out


def _numbers(src: str, where: str, value: Any, count: int, what: str) -> list[float]:
    ok = (isinstance(value, list) and len(value) == count
          and all(isinstance(v, int | float) and not isinstance(v, bool)
                  and math.isfinite(v) for v in value))
    if not ok:
        raise SpecError(src, where, f"{value!r} is not allowed; allowed: {what}")
    return [float(v) for v in value]


def parse_axis(src: str, path: str, value: Any) -> Axis:
    """One ``[axes]`` entry.  Raises SpecError naming ``axes.PATH``."""
    where = f"axes.{path}"
    if _known_type(path) is None:
        raise SpecError(src, where, f"unknown axis; allowed: {_allowed_paths()}")
    if isinstance(value, list):
        if not value:
            raise SpecError(src, where, "an empty list gives no cases; allowed: one or more values")
        return Axis(path, "list", tuple(value))
    if not isinstance(value, dict):
        return Axis(path, "list", (value,))
    if len(value) != 1 or next(iter(value)) not in DISTRIBUTIONS:
        raise SpecError(src, where, f"{value!r} is not an axis; allowed: a value, a list, or "
                        "one of {range = [start, stop, step]}, {uniform = [low, high]}, "
                        "{normal = [mean, sd]}, {choice = [...]}, {randint = [low, high]}")
    kind, arg = next(iter(value.items()))
    if kind == "range":
        start, stop, step = _numbers(src, f"{where}.range", arg, 3,
                                     "[start, stop, step] with step > 0 and stop >= start")
        if step <= 0 or stop < start:
            raise SpecError(src, f"{where}.range", f"{arg!r} is an empty range; allowed: "
                            "[start, stop, step] with step > 0 and stop >= start")
        span = (stop - start) / step  # inf when the step is tiny beside the range
        if not span < MAX_CASES:
            raise SpecError(src, f"{where}.range", f"{arg!r} gives more than {MAX_CASES} "
                            f"values; allowed: at most {MAX_CASES}")
        n = int(math.floor(span + 1e-9)) + 1
        ints = all(isinstance(v, int) for v in arg)
        vals = [int(start + k * step) if ints else round(start + k * step, 10) for k in range(n)]
        return Axis(path, "range", tuple(vals))
    if kind == "choice":
        if not isinstance(arg, list) or not arg:
            raise SpecError(src, f"{where}.choice", "allowed: a non-empty list of values")
        return Axis(path, "choice", tuple(arg))
    shape = "[mean, sd]" if kind == "normal" else "[low, high]"
    lo, hi = _numbers(src, f"{where}.{kind}", arg, 2, shape)
    if kind == "normal" and hi < 0:
        raise SpecError(src, f"{where}.normal", f"sd {hi:g} is not allowed; allowed: sd >= 0")
    if kind != "normal" and hi < lo:
        raise SpecError(src, f"{where}.{kind}", f"{arg!r} is empty; allowed: [low, high] "
                        "with high >= low")
    if kind == "randint" and not all(isinstance(v, int) for v in arg):
        raise SpecError(src, f"{where}.randint", f"{arg!r}: allowed: two whole numbers")
    return Axis(path, kind, (), (lo, hi))
