"""A back sensor whose "drop" holds flat, far short of the step's rise: judged
biased in descent 1 (not in the seed, which has no sensor faults).

Descent 1 backs segment 3 along the flat tread of a step the robot climbed,
whose rise each back sensor read at the end of its ascent 7
(:mod:`~stairbot.control.algorithm.bias_rise`: BACK_CLEARANCE + the rise).
A back sensor crossing the edge reads, within the backing its cone takes to
leave the edge (:func:`crossing_m`), about that rise: a cone that mixes its
returns by signal (a VL53L0X) reads the drop once nearly its whole footprint
has left the tread, and all of it past 2 x
:func:`~stairbot.control.algorithm.edge_measure.mixed_footprint_m`; a first
echo grows along the riser's face at 1 / sin(half the cone) per metre backed
(:func:`~stairbot.control.algorithm.edge_measure.edge_sight_m`'s model) until
it reads the rise.  A sensor biased long as it backs (sweeps/sensor_faults.toml,
SBR +5 cm from descent 1's back-off: no second of mount heights on the
tread before it) instead steps to a value past the edge watch's drop line
but far short of the rise, and holds there.

:class:`FlatDrop` watches, tick by tick while descent 1 steers by the back
pair, one sensor reading past the drop line while its partner reads the
floor: once the robot has backed :func:`hold_m` since it first did (the
crossing and two measurement periods' backing: the sensors' timing and the
median's), and all that while it read short of the rise
(:func:`short_of_m`), no edge explains it: it is judged biased.  The edge
watch would otherwise end the run ("turned too far from the edge") when
the partner has not followed within 25 degrees' worth of backing; the
judged sensor reads as ERROR, and the robot limps home on its partner.
"""

from __future__ import annotations

import math

from stairbot.control.algorithm.bias_rise import Rise
from stairbot.control.algorithm.edge_measure import (
    back_half_cone_rad,
    edge_doubt_m,
    edge_drop_m,
    mixed_footprint_m,
)
from stairbot.control.algorithm.texts import bias as say
from stairbot.control.tolerances import median_sigma
from stairbot.hardware import SensorId, Snapshot
from stairbot.inputs.config import RobotConfig

RISE_SIGMAS = 4.0
"""A crossed edge reads the step's rise within this many sigmas of the
filtered reading there (and a resolution step)."""


def crossing_m(cfg: RobotConfig, rise_m: float) -> float:
    """How far the robot backs from a back sensor's first reading past the
    drop line (:func:`~stairbot.control.algorithm.edge_measure.edge_drop_m`)
    until a real edge reads ``rise_m`` (BACK_CLEARANCE + the rise): a mixing
    cone's whole footprint; a first echo's climb along the riser's face
    from the drop line to the rise."""
    if cfg.sensors.spec(True).first_echo:
        return max(0.0, rise_m - edge_drop_m(cfg)) * math.sin(back_half_cone_rad(cfg))
    return 2 * mixed_footprint_m(cfg)


def hold_m(cfg: RobotConfig, rise_m: float) -> float:
    """The backing a reading short of the rise must hold over to be no edge:
    :func:`crossing_m` and two measurement periods' backing at full speed
    (:func:`~stairbot.control.algorithm.edge_measure.edge_doubt_m`: the
    crossing falls anywhere between two measurements, and the median's
    majority may take one more)."""
    return crossing_m(cfg, rise_m) + 2 * edge_doubt_m(cfg)


def short_of_m(cfg: RobotConfig, rise_m: float) -> float:
    """Readings below this are short of the rise: RISE_SIGMAS filtered sigmas
    and a resolution step below it, and at most half-way up from the drop
    line (on the lowest rise, under its noise, a real edge reads well above
    that)."""
    drop = edge_drop_m(cfg)
    noise = RISE_SIGMAS * median_sigma(cfg, True, rise_m) + cfg.sensors.resolution
    return min(rise_m - noise, (drop + rise_m) / 2)


class FlatDrop:
    """Tracks one back sensor reading past the drop line, short of the rise,
    while its partner reads the floor (module docstring).  Told every tick
    descent 1 steers by the back pair; a tick missed (another phase, a
    hold) starts it afresh."""

    __slots__ = ("_cfg", "_last_s", "_sensor", "_from_m", "_high_m")

    def __init__(self, cfg: RobotConfig) -> None:
        self._cfg = cfg
        self._last_s: float | None = None
        self._sensor: SensorId | None = None
        self._from_m = 0.0
        """The odometer (m) where the sensor first read past the drop line."""
        self._high_m = 0.0
        """The most it read since."""

    def see(self, snap: Snapshot, odometer: float,
            rise: Rise | None) -> tuple[SensorId, str] | None:
        """This tick's readings at ``odometer`` (m, backing counts down) on
        the step whose climbed rise is ``rise``: the sensor judged biased and
        the evidence in words, or None."""
        cfg = self._cfg
        last, self._last_s = self._last_s, snap.time_s
        if last is None or snap.time_s - last > 1.5 * cfg.algorithm.tick:
            self._sensor = None
        r, left = snap.sensors[SensorId.SBR], snap.sensors[SensorId.SBL]
        drop = edge_drop_m(cfg)
        if rise is None or not (r.ok and left.ok) \
                or (r.distance_m > drop) == (left.distance_m > drop):
            self._sensor = None
            return None
        sensor, partner = (SensorId.SBR, SensorId.SBL) if r.distance_m > drop \
            else (SensorId.SBL, SensorId.SBR)
        reading = snap.sensors[sensor].distance_m
        if sensor is not self._sensor:
            self._sensor, self._from_m, self._high_m = sensor, odometer, reading
        self._high_m = max(self._high_m, reading)
        rise_m = min(rise.right_m, rise.left_m)
        short = short_of_m(cfg, rise_m)
        if self._high_m >= short:
            return None  # it read the rise: an edge (or at least not this fault)
        backed = self._from_m - odometer
        if backed < hold_m(cfg, rise_m):
            return None
        return sensor, say.judged_flat_drop(sensor, partner, self._high_m, backed, short,
                                            rise_m, rise.step, drop)
