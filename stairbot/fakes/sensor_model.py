"""Realistic distance sensors: a cone of rays, timing, noise and faults.

A :class:`SensorModel` is a record of what a sensor's datasheet says (presets
in :mod:`stairbot.fakes.sensor_presets`); a :class:`ModelSensor` is one
sensor of that kind on the robot, with its own seeded random stream.

What a reading goes through:

* geometry (:mod:`stairbot.fakes.beams` casts the rays): the cone's rays that
  meet a surface, each with its distance, the cosine of its incidence on the
  surface and its weight in the beam, are combined by :func:`combine` into
  one distance -- the nearest (an ultrasonic ranger's first echo) or the mean
  weighted by the returned signal (a time-of-flight sensor's mixed return) --
  or a cause for having none: nothing in the beam, the echo lost (every ray
  beyond ``max_incidence_deg``), or the signal too weak (less than a full
  beam square to a target ``weak_range`` away would return);
* timing: a measurement is taken every ``period_s`` (at whole multiples of it;
  0: at every read) from the world as it is then, and published
  ``latency_s`` later; between publications the last value is repeated.  The
  very first measurement is published at once (the sensor was running before
  the program started);
* per measurement, always the same random draws for a given model whatever
  the outcome: one Gaussian when there is noise (sigma = noise_a + noise_b *
  distance), two uniforms when there are outliers, two when there are
  dropouts -- so the same run gives the same readings bit for bit;
* scenario faults: an ``offset`` fault adds to the measurement taken while it
  is active; an ``error`` fault makes every reading ERROR while it is active;
  a ``freeze`` fault stops the measurements (the last one is published on,
  growing old); a ``stuck`` fault lets them go on, on time and fresh, but
  each is the last one taken before the fault began, as it was (the noise,
  outlier and dropout draws are still made, so the readings after the fault
  are those of the same run without it);
* a dropout makes one measurement ERROR or OUT_OF_RANGE (even odds); an
  outlier replaces it with a uniform value within range;
* no target, echo lost or too weak: OUT_OF_RANGE at the maximum; beyond the
  maximum likewise; nearer than the minimum: OUT_OF_RANGE at the minimum;
  otherwise OK, the true distance plus offset, bias and noise, rounded to the
  resolution.

With the ``ideal`` model (one ray, no timing, noise of the scenario, nothing
else) this gives exactly the readings of the sensor stairbot had before the
models (tests/fakes/reference_sensor.py keeps it as the test's oracle).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import Literal

from stairbot.fakes.sensors import active_faults, frozen, gauss, sensor_rng, stuck
from stairbot.hardware import SensorId, SensorReading, SensorStatus
from stairbot.inputs.scenario import Fault
from stairbot.readings import sensor_reading

Hit = tuple[float, float, float]  # distance m, cos(incidence), weight in the beam
ConeRay = tuple[float, float, float]  # angle along the side view, across it (rad), weight


class Cause(StrEnum):
    """Why a measurement came out as it did (for tests and diagnostics)."""

    OK = "ok"
    NOTHING = "nothing"  # no ray met anything
    ECHO_LOST = "echo_lost"  # every ray met its surface beyond max_incidence_deg
    WEAK = "weak"  # the returned signal is below what the sensor can range
    NEAR = "near"
    FAR = "far"
    DROPOUT = "dropout"
    OUTLIER = "outlier"
    FAULT = "fault"  # a scenario fault (error, stuck) is active


_OK, _NOTHING = Cause.OK, Cause.NOTHING  # bound once: an enum's member is a slow look-up


@dataclass(frozen=True)
class SensorModel:
    """What a kind of distance sensor does; None means "the robot config's"
    (ranges, resolution) or "the scenario's" (noise_a)."""

    name: str
    fov_deg: float = 0.0  # full angle of the cone (of a rectangle: up and down)
    fov_across_deg: float | None = None  # a rectangle's full angle across; None: a round cone
    rays: int = 1  # rays across the cone in the side view (vertical spread)
    rays_across: int = 1  # rays across it in the top view (front sensors only)
    aggregate: Literal["nearest", "weighted"] = "nearest"
    tilt_deg: float = 0.0  # mounting tilt: front + = up, back + = towards the front
    period_s: float = 0.0  # between measurements; 0: one at every read
    latency_s: float = 0.0  # from a measurement to its publication
    noise_a: float | None = None  # sigma = noise_a + noise_b * distance, m
    noise_b: float = 0.0
    bias: float = 0.0  # m, added to every measurement
    resolution: float | None = None
    outlier_rate: float = 0.0
    dropout_rate: float = 0.0
    min_range: float | None = None
    max_range: float | None = None
    weak_range: float | None = None  # full beam, square to the target: too weak beyond
    max_incidence_deg: float | None = None  # ultrasonic: a ray's echo is lost beyond

    # What casting needs, derived from the fields above once, when the model
    # is made (a compiled build runs a cached_property's body at every read).
    cone: tuple[ConeRay, ...] = field(init=False, repr=False, compare=False)
    """The rays of a forward sensor's cone: a grid of ``rays`` x
    ``rays_across`` angles within the circle of half-angle fov/2, each
    weighted 1 on the axis falling to 0.5 at the rim; or, with
    ``fov_across_deg``, a rectangle of them fov tall and fov_across wide,
    each weighted 1 (a multizone sensor's block of zones, every direction
    in it counted alike)."""
    fan: tuple[ConeRay, ...] = field(init=False, repr=False, compare=False)
    """The side-view rays only (a downward sensor's cone)."""
    cone_index: tuple[tuple[float, ...], tuple[float, ...], tuple[tuple[int, int, float], ...]] \
        = field(init=False, repr=False, compare=False)
    """The :attr:`cone` for casting: its distinct angles up and across, and
    its rays as the indexes of their two angles, with their weights (the
    rays at one angle share its cast or its trigonometry)."""
    cone_rows: tuple[tuple[int, tuple[tuple[int, float], ...]], ...] = field(
        init=False, repr=False, compare=False)
    """The rays of :attr:`cone_index` in their order, in runs at one angle
    up: (the angle's index, the rays' indexes across and weights), per run."""
    min_cos: float = field(init=False, repr=False, compare=False)
    """The cosine of ``max_incidence_deg`` (1: none given)."""
    tilt: float = field(init=False, repr=False, compare=False)
    """``tilt_deg`` in radians."""

    def __post_init__(self) -> None:
        cone = self._grid(self.rays_across)
        ups: dict[float, int] = {}
        acrosses: dict[float, int] = {}
        rays = tuple((ups.setdefault(up, len(ups)), acrosses.setdefault(across, len(acrosses)),
                      weight) for up, across, weight in cone)
        rows: list[tuple[int, list[tuple[int, float]]]] = []
        for i_up, i_across, weight in rays:
            if not rows or rows[-1][0] != i_up:
                rows.append((i_up, []))
            rows[-1][1].append((i_across, weight))
        derived = {
            "cone": cone, "fan": self._grid(1),
            "cone_index": (tuple(ups), tuple(acrosses), rays),
            "cone_rows": tuple((i_up, tuple(row)) for i_up, row in rows),
            "min_cos": 1.0 if self.max_incidence_deg is None
            else math.cos(math.radians(self.max_incidence_deg)),
            "tilt": math.radians(self.tilt_deg),
        }
        for name, value in derived.items():
            object.__setattr__(self, name, value)  # frozen: set once, here

    @property
    def single_ray(self) -> bool:
        """One ray straight along the mount: today's geometry, no cone."""
        return (self.rays == 1 and self.rays_across == 1 and self.tilt_deg == 0.0
                and self.max_incidence_deg is None and self.weak_range is None)

    def _grid(self, across: int) -> tuple[ConeRay, ...]:
        half = math.radians(self.fov_deg) / 2.0

        def spread(n: int, half: float = half) -> list[float]:
            return [0.0] if n <= 1 or half == 0.0 else [
                -half + 2.0 * half * i / (n - 1) for i in range(n)]

        if self.fov_across_deg is not None:
            wide = spread(across, math.radians(self.fov_across_deg) / 2.0)
            return tuple((a, b, 1.0) for a in spread(self.rays) for b in wide)
        out: list[ConeRay] = []
        for a in spread(self.rays):
            for b in spread(across):
                r2 = (a * a + b * b) / (half * half) if half > 0.0 else 0.0
                if r2 <= 1.0 + 1e-9:
                    out.append((a, b, 1.0 - 0.5 * r2))
        return tuple(out)


def combine(model: SensorModel, hits: Sequence[Hit], total_weight: float
            ) -> tuple[float | None, Cause]:
    """One distance from the rays that met a surface (see the module
    docstring); ``total_weight``: the weight of every ray of the cone, met or
    not."""
    if not hits:
        return None, _NOTHING
    if model.max_incidence_deg is not None:
        min_cos = model.min_cos
        hits = [h for h in hits if h[1] >= min_cos]
        if not hits:
            return None, Cause.ECHO_LOST
    weak_range = model.weak_range
    mixed = len(hits) > 1 and model.aggregate != "nearest"
    if weak_range is None and not mixed:
        return min([h[0] for h in hits]), _OK
    # each ray's returned signal, relative to a full beam square to a target 1 m
    # away (its weight in the mix; a ray at 0 m weighs its weight in the beam)
    signals: list[float] = []
    num = den = 0.0
    for d, c, g in hits:
        if d > 0.0:
            w = g * c / (d * d)
            signals.append(w)
        else:
            w = g
        num += w * d
        den += w
    if weak_range is not None and sum(signals) / total_weight * weak_range * weak_range < 1.0:
        return None, Cause.WEAK
    if not mixed:
        return min([h[0] for h in hits]), _OK
    return (num / den if den > 0.0 else min([h[0] for h in hits])), _OK


class ModelSensor:
    """One distance sensor of a given :class:`SensorModel` (see the module
    docstring).  ``min_range``, ``max_range``, ``resolution`` and ``noise`` are
    the config's and scenario's, used where the model leaves them None."""

    def __init__(self, sensor: SensorId, model: SensorModel, min_range: float,
                 max_range: float, resolution: float, noise: float, seed: int,
                 faults: Iterable[Fault] = (), outliers: float = 0.0) -> None:
        self.sensor = sensor
        if outliers > model.outlier_rate:  # the scenario's, on top of the model's
            model = replace(model, outlier_rate=outliers)
        self.model = model
        # the config's range, within the sensor's own (RobotConfig.sensors.range)
        self.min_range = min_range if model.min_range is None else max(min_range, model.min_range)
        self.max_range = max_range if model.max_range is None else min(max_range, model.max_range)
        self.resolution = resolution if model.resolution is None else model.resolution
        self.noise_a = noise if model.noise_a is None else model.noise_a
        self.noise_b = model.noise_b
        rng = self._rng = sensor_rng(seed, sensor)
        self._uniform = rng.random
        self.faults = tuple(f for f in faults if f.sensor == sensor.value)
        self._freezes = tuple(f for f in self.faults if f.kind == "freeze")
        self._stucks = tuple(f for f in self.faults if f.kind == "stuck")
        self._held: SensorReading | None = None
        """The last measurement taken while no stuck fault was active: what a
        stuck sensor repeats."""
        self._far = SensorReading(self.max_range, SensorStatus.OUT_OF_RANGE)
        self._near = SensorReading(self.min_range, SensorStatus.OUT_OF_RANGE)
        self._error = SensorReading(0.0, SensorStatus.ERROR)
        self._by_step: dict[int, SensorReading] = {}
        self._next = -math.inf  # time of the next measurement
        self._pending: deque[tuple[float, float, SensorReading, Cause]] = deque()
        self._current: tuple[float, SensorReading, Cause] | None = None
        self.measurements = 0
        # the model's figures each measurement needs, looked up once
        self._period, self._latency = model.period_s, model.latency_s
        self._noisy = self.noise_a > 0.0 or self.noise_b > 0.0
        self._outlier_rate, self._dropout_rate = model.outlier_rate, model.dropout_rate
        self._bias = model.bias
        # measured at every read and published at once, no scenario fault: each
        # read's reading is its own measurement (measure's short way)
        self._instant = self._period <= 0.0 and self._latency <= 0.0 and not self.faults

    # -- timing ---------------------------------------------------------------------
    def due(self, t: float) -> bool:
        """Whether a measurement is to be taken at time ``t`` (never while a
        freeze fault is active)."""
        return t >= self._next and not (self._freezes and frozen(self._freezes, t))

    def sample(self, seen: tuple[float | None, Cause], t: float) -> None:
        """Take a measurement now of what the beam sees (a distance, or None and
        why not); it is published ``latency_s`` later."""
        period = self._period
        if period > 0.0:  # the next whole multiple of the period (0: every read)
            self._next = (math.floor(t / period + 1e-9) + 1) * period
        reading, cause = self._measure(seen[0], seen[1], t)
        if self._stucks:
            if not stuck(self._stucks, t):
                self._held = reading
            else:  # stuck from before its first measurement: stuck on the first
                if self._held is None:
                    self._held = reading
                reading, cause = self._held, Cause.FAULT
        self.measurements += 1
        if self._current is None or self._latency <= 0.0:
            self._current = (t, reading, cause)
        else:
            self._pending.append((t + self._latency, t, reading, cause))

    def reading(self, t: float) -> SensorReading:
        """The reading published at time ``t``: the latest measurement whose
        latency has passed (ERROR while a scenario error fault is active)."""
        pending = self._pending
        while pending and pending[0][0] <= t + 1e-12:
            _, taken, reading, cause = pending.popleft()
            self._current = (taken, reading, cause)
        if self.faults and active_faults(self.faults, t)[1]:
            return self._error
        return self._current[1] if self._current is not None else self._far

    def published(self, t: float) -> SensorReading:
        """:meth:`reading` with its :meth:`age` in it (the same object when 0 s
        old): what the board publishes.  (:meth:`reading` written out: the
        board publishes every sensor at every read.)"""
        pending = self._pending
        while pending and pending[0][0] <= t + 1e-12:
            _, taken, reading, cause = pending.popleft()
            self._current = (taken, reading, cause)
        current = self._current
        if self.faults and active_faults(self.faults, t)[1]:
            reading = self._error
        elif current is not None:
            reading = current[1]
        else:
            reading = self._far
        age = math.inf if current is None else t - current[0]
        return reading if age == 0.0 else sensor_reading(reading.distance_m, reading.status, age)

    def age(self, t: float) -> float:
        """How old the published reading is at ``t`` (inf before the first)."""
        self.reading(t)
        return math.inf if self._current is None else t - self._current[0]

    @property
    def cause(self) -> Cause | None:
        """Why the published reading is what it is."""
        return None if self._current is None else self._current[2]

    def measure(self, true_distance: float | None, t: float) -> SensorReading:
        """One ray, square to its target: measure ``true_distance`` (None:
        nothing) if a measurement is due, and return the published reading."""
        if self._instant:  # what sample and reading come to for such a sensor
            reading, cause = self._measure(true_distance,
                                           _OK if true_distance is not None else _NOTHING, t)
            self.measurements += 1
            self._current = (t, reading, cause)
            return reading
        if t >= self._next and not (self._freezes and frozen(self._freezes, t)):
            self.sample((true_distance, _OK if true_distance is not None else _NOTHING), t)
        return self.reading(t)

    # -- one measurement --------------------------------------------------------------
    def _measure(self, true_distance: float | None, cause: Cause, t: float
                 ) -> tuple[SensorReading, Cause]:
        noise = 0.0
        if self._noisy:
            a = self.noise_a
            sigma = a + self.noise_b * true_distance if true_distance is not None else a
            noise = gauss(self._rng, sigma)
        outliers, dropouts = self._outlier_rate, self._dropout_rate
        outlier = False
        if outliers > 0.0:
            outlier = self._uniform() < outliers
            outlier_at = self._uniform()
        if dropouts > 0.0:
            dropout = self._uniform() < dropouts
            dropout_kind = self._uniform()
            if dropout:
                return (self._error if dropout_kind < 0.5 else self._far), Cause.DROPOUT
        if outlier:
            d = self.min_range + outlier_at * (self.max_range - self.min_range)
            return self._quantized(d), Cause.OUTLIER
        if true_distance is None:
            return self._far, cause
        offset = active_faults(self.faults, t)[0] if self.faults else 0.0
        d = true_distance + offset + self._bias + noise
        if d > self.max_range:
            return self._far, Cause.FAR
        if d < self.min_range:
            return self._near, Cause.NEAR
        return self._quantized(d), _OK

    def _quantized(self, d: float) -> SensorReading:
        if self.resolution <= 0.0:
            return sensor_reading(d)
        # readings are whole multiples of the resolution: share one object per value
        k = round(d / self.resolution)
        reading = self._by_step.get(k)
        if reading is None:
            value = min(max(round(k * self.resolution, 9), self.min_range), self.max_range)
            reading = self._by_step[k] = sensor_reading(value)
        return reading
