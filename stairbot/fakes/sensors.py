"""What every simulated distance sensor shares: its own seeded noise
generator, and the scenario's faults active at a time.

The sensor itself is :class:`~stairbot.fakes.sensor_model.ModelSensor`; its
``ideal`` preset reads as the reference robot's sensors always have: scenario
faults first (an ``offset`` fault adds its offset, an ``error`` fault makes the
sensor report ERROR, a ``freeze`` fault stops it measuring -- its last reading
repeats and grows old --, a ``stuck`` fault makes every measurement the one
taken last before it -- fresh, but the same value --, each for ``at <= t < at +
duration``), one Gaussian draw per reading, OUT_OF_RANGE at the limits,
otherwise OK rounded to the resolution.
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterable
from typing import Final

from stairbot.hardware import SensorId
from stairbot.inputs.scenario import Fault


def sensor_rng(seed: int, sensor: SensorId) -> random.Random:
    """The noise generator of one sensor: independent per sensor, fixed per seed."""
    return random.Random(f"stairbot-sensor:{seed}:{sensor.value}")


_TWO_PI: Final = 2.0 * math.pi


def gauss(rng: random.Random, sigma: float) -> float:
    """``rng.gauss(0.0, sigma)``: the same number, drawn the same way, and
    ``rng`` left in the same state.  CPython's ``Random.gauss``
    (Lib/random.py) is Python; written out here it is compiled with the
    sensor models, which draw it for every measurement.
    tests/fakes/test_sensor_noise.py holds the two to each other."""
    z = rng.gauss_next  # type: ignore[attr-defined]
    rng.gauss_next = None  # type: ignore[attr-defined]
    if z is None:
        x2pi = rng.random() * _TWO_PI
        g2rad = math.sqrt(-2.0 * math.log(1.0 - rng.random()))
        z = math.cos(x2pi) * g2rad
        rng.gauss_next = math.sin(x2pi) * g2rad  # type: ignore[attr-defined]
    return 0.0 + z * sigma


def active_faults(faults: Iterable[Fault], t: float) -> tuple[float, bool]:
    """The summed offset of the offset faults active at ``t``, and whether an
    error fault is active."""
    offset, error = 0.0, False
    for f in faults:
        if t >= f.at and (f.duration is None or t < f.at + f.duration):
            if f.kind == "error":
                error = True
            elif f.kind == "offset":
                offset += f.offset
    return offset, error


def frozen(faults: Iterable[Fault], t: float) -> bool:
    """Whether a freeze fault is active at ``t``: the sensor takes no new
    measurement (the board repeats the last one, and knows its age)."""
    return any(f.kind == "freeze" and t >= f.at and (f.duration is None or t < f.at + f.duration)
               for f in faults)


def stuck(faults: Iterable[Fault], t: float) -> bool:
    """Whether a stuck fault is active at ``t``: the sensor measures on, fresh,
    but every measurement is the one it took last before the fault (a frozen
    ADC, firmware that repeats its last value as new)."""
    return any(f.kind == "stuck" and t >= f.at and (f.duration is None or t < f.at + f.duration)
               for f in faults)
