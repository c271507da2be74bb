"""The distance filter's timings and the tolerances derived from the sensors'
stated noise (:mod:`stairbot.inputs.sensor_specs`, ``[sensors]`` in the robot
config): how long a pair takes to settle, how far its filtered reading may
stray, when two readings are "equal", how long calibration stands to square
up.  Decisions that compare two sensors ("equal", the standing rule) use
these, not a guess.  :mod:`stairbot.control.perception` filters by them.
"""

from __future__ import annotations

import math

from stairbot.inputs.config import RobotConfig
from stairbot.inputs.sensor_specs import SensorSpec

WINDOW = 5
"""Measurements a sensor's median spans, whatever its period.  Five, not
three: two stray measurements in a row pass a median of three -- for an
HC-SR04 pair (1 % outliers, a measurement every 60 ms) about three times a
run, for a VL53L1X pair often enough to pause the standing rule -- and set
reading drives' targets centimetres off."""
STALE_PERIODS = 3.0
"""A measurement older than latency + this many periods (+ a tick) is stale."""
SIGMAS = 4.0
"""A difference counts as real when it exceeds this many of its own sigmas."""
MEDIAN_EFFICIENCY = 1.25
"""The median of n normal samples has about 1.25 times the sigma of their mean."""

def measurement_period(cfg: RobotConfig, back: bool) -> float:
    """How often the pair gives a new measurement: its period, or every tick."""
    return _period(cfg, cfg.sensors.spec(back))


def window(cfg: RobotConfig, back: bool) -> int:
    """Measurements the pair's median spans (WINDOW, for every pair)."""
    return WINDOW


def max_age(cfg: RobotConfig, back: bool) -> float:
    """The oldest a measurement of the pair may be and still be used."""
    return spec_max_age(cfg, cfg.sensors.spec(back))


def settle_s(cfg: RobotConfig, back: bool = False) -> float:
    """How long the pair's filtered readings take to stand for where the robot
    stands now, once it stops: its latency and a full window of measurements.
    Measurements to average standing still start after it."""
    return _settle_s(cfg, cfg.sensors.spec(back))


def side_settle_s(cfg: RobotConfig) -> float:
    """:func:`settle_s` of the side pair (``[sensors] side_model``)."""
    return _settle_s(cfg, cfg.sensors.side_spec())


def _period(cfg: RobotConfig, spec: SensorSpec) -> float:
    return max(spec.period_s, cfg.algorithm.tick)


def spec_max_age(cfg: RobotConfig, spec: SensorSpec) -> float:
    """The oldest a measurement of a sensor of ``spec`` may be and still be used."""
    return spec.latency_s + STALE_PERIODS * _period(cfg, spec) + cfg.algorithm.tick


def _settle_s(cfg: RobotConfig, spec: SensorSpec) -> float:
    return spec.latency_s + WINDOW * _period(cfg, spec)


def median_sigma(cfg: RobotConfig, back: bool, distance_m: float) -> float:
    """Sigma of the pair's filtered reading at ``distance_m``."""
    k = _pair(cfg, back)
    return _median_sigma(k, k.sigma(distance_m))


def pair_tolerance(cfg: RobotConfig, distance_m: float, smoothing: float = 1.0,
                   back: bool = False) -> float:
    """How far two filtered readings of one surface ``distance_m`` away may
    differ and still be "equal": equal_tolerance, or SIGMAS sigmas of their
    difference if the sensors are noisier than that allows.  ``smoothing`` is
    the weight of an exponential smoothing applied each tick on top (1.0:
    none); it averages fewer independent values when the sensor is slower
    than the tick."""
    k = _pair(cfg, back)
    return _pair_tolerance(k, k.sigma(distance_m), smoothing)


def standing_tolerance(cfg: RobotConfig, distance_m: float, smoothing: float = 1.0,
                       back: bool = False) -> float:
    """How far the pair may differ while the robot drives or lifts before the
    standing rule stops it: what calibration may have left
    (:func:`square_tolerance`), plus SIGMAS sigmas of the (smoothed) difference."""
    k = _pair(cfg, back)
    sigma = k.sigma(distance_m)
    # the standing rule asks every tick; the answer depends on the sigma alone
    known = k.standing
    tolerance = known.get((sigma, smoothing))
    if tolerance is None:
        if len(known) >= _KNOWN_SIGMAS:
            known.clear()
        tolerance = known[sigma, smoothing] = (_square_tolerance(k, sigma)
                                               + _pair_tolerance(k, sigma, smoothing))
    return tolerance


MAX_STILL_S = 5.0
"""The longest calibration stands still to square up (a very noisy sensor
squares up as well as this allows, and the standing rule allows for it)."""


def still_samples(cfg: RobotConfig, distance_m: float, back: bool = False) -> int:
    """Ticks of standing still whose mean pair difference is known to within
    equal_tolerance (:func:`still_tolerance`), at most MAX_STILL_S of them:
    calibration squares up to that yaw."""
    k = _pair(cfg, back)
    return _still_samples(k, k.sigma(distance_m))


def square_tolerance(cfg: RobotConfig, distance_m: float, back: bool = False) -> float:
    """The pair difference calibration leaves at most when it squares up:
    equal_tolerance, or more for a sensor too noisy to get there in MAX_STILL_S."""
    k = _pair(cfg, back)
    return _square_tolerance(k, k.sigma(distance_m))


def quiet_range_m(cfg: RobotConfig) -> float:
    """Farthest reading from which the front pair squares up to
    equal_tolerance (:func:`square_tolerance`): farther, its stated noise
    allows only a looser square in MAX_STILL_S (a Sharp's sigma is 1 mm + 2 %
    of the distance).  Infinite when the pair does it anywhere short of
    LENGTH_OF_INFINITY."""
    k = _pair(cfg, False)
    if k.quiet is None:
        equal = cfg.algorithm.equal_tolerance + 1e-12
        lo, hi = cfg.sensors.range(False)[0], cfg.LENGTH_OF_INFINITY
        if _square_tolerance(k, k.sigma(hi)) <= equal:
            k.quiet = math.inf
        elif _square_tolerance(k, k.sigma(lo)) > equal:
            k.quiet = lo
        else:
            for _ in range(40):  # the sigma grows with the distance: bisect to 0.1 mm
                mid = (lo + hi) / 2.0
                lo, hi = (mid, hi) if _square_tolerance(k, k.sigma(mid)) <= equal else (lo, mid)
                if hi - lo < 1e-4:
                    break
            k.quiet = lo
    return k.quiet


def still_tolerance(cfg: RobotConfig, samples: int, distance_m: float,
                    back: bool = False) -> float:
    """Like :func:`pair_tolerance`, for the mean of ``samples`` ticks' filtered
    differences taken standing still."""
    k = _pair(cfg, back)
    return _still_tolerance(k, samples, k.sigma(distance_m))


# -- the same, from a pair's figures and the stated sigma at the distance ---------------
class _Pair:
    """What the tolerances of one pair need of the config, looked up once."""

    __slots__ = ("spec", "noise", "equal", "repeats", "sqrt_window", "max_still", "standing",
                 "quiet")

    def __init__(self, cfg: RobotConfig, back: bool) -> None:
        self.spec = cfg.sensors.spec(back)
        self.noise = cfg.sensors.noise
        self.equal = cfg.algorithm.equal_tolerance
        self.repeats = measurement_period(cfg, back) / cfg.algorithm.tick
        """Ticks per measurement (at least 1)."""
        self.sqrt_window = math.sqrt(window(cfg, back))
        self.max_still = round(MAX_STILL_S / cfg.algorithm.tick)
        self.standing: dict[tuple[float, float], float] = {}
        """standing_tolerance by (sigma, smoothing)."""
        self.quiet: float | None = None
        """quiet_range_m, once asked."""

    def sigma(self, distance_m: float) -> float:
        """The stated sigma of one reading at ``distance_m`` (Sensors.sigma)."""
        return self.spec.sigma(distance_m, self.noise)


_KNOWN_SIGMAS = 256
"""standing_tolerance remembers at most this many answers per pair (a sensor
whose noise grows with the distance gives a new sigma at most ticks)."""

_derived: tuple[RobotConfig, tuple[_Pair, _Pair]] | None = None
"""The last config asked about and its pairs (front, back): a run asks about
one config, every tick.  A config is frozen, so its pairs never change."""


def _pair(cfg: RobotConfig, back: bool) -> _Pair:
    global _derived
    derived = _derived
    if derived is None or derived[0] is not cfg:
        derived = _derived = (cfg, (_Pair(cfg, False), _Pair(cfg, True)))
    return derived[1][1 if back else 0]


def _median_sigma(k: _Pair, sigma: float) -> float:
    return MEDIAN_EFFICIENCY * sigma / k.sqrt_window


def _pair_tolerance(k: _Pair, sigma: float, smoothing: float) -> float:
    sigma_diff = math.sqrt(2.0) * _median_sigma(k, sigma)
    sigma_diff *= math.sqrt(min(1.0, k.repeats * smoothing / (2.0 - smoothing)))
    return max(k.equal, SIGMAS * sigma_diff)


def _still_samples(k: _Pair, sigma: float) -> int:
    one = SIGMAS * _still_sigma(sigma, 1.0)
    independent = (one / k.equal) ** 2
    return max(1, min(k.max_still, math.ceil(independent * k.repeats)))


def _square_tolerance(k: _Pair, sigma: float) -> float:
    return _still_tolerance(k, _still_samples(k, sigma), sigma)


def _still_tolerance(k: _Pair, samples: int, sigma: float) -> float:
    sigma_diff = _still_sigma(sigma, max(1.0, samples / k.repeats))
    return max(k.equal, SIGMAS * sigma_diff)


def _still_sigma(sigma: float, independent: float) -> float:
    """Sigma of the mean of ``independent`` filtered pair differences."""
    return math.sqrt(2.0) * MEDIAN_EFFICIENCY * sigma / math.sqrt(independent)
