"""The back pair judged by its mount heights
(:class:`~stairbot.control.algorithm.bias_evidence.MountHeights`: what SBR and
SBL read, less BACK_CLEARANCE, over the last second segment 3 stood on a
surface).  Not in the seed, which has no sensor faults.

* :func:`by_mount`: at the end of the standing rule's wait, one sensor off
  its mount height (or too near to measure) as the disagreement says, its
  partner on it.  Too near to measure counts over most of the last second
  on a surface, or over the last TAIL_TICKS of it while its partner held
  its mount height: a bias that set in just before segment 3 left the
  surface shows only there (the second's mean averages it away);
* :func:`at_once`: descent 1 backing off, a sensor reading past
  :func:`~stairbot.control.algorithm.edge_measure.edge_drop_m` -- what the
  edge watch takes for the drop -- while its partner reads the floor, and
  both read so for the whole last second segment 3 stood on the tread (no
  reading beyond DROP_M over BACK_CLEARANCE in it: a drop of the lowest
  rise reads more).  A back sensor crossing an edge reads the drop within
  a footprint's backing and ends the stretch; one reading a steady 5 cm
  long over the tread it has stood on since the step's descent 2 is biased
  (sweeps/sensor_faults.toml, +5 cm from descent 3 of the top step: the
  edge watch took it for the drop, its partner "still the floor" after 48
  mm, and ended the run).  The robot climbed this step: its drop is a
  whole rise, far beyond what that sensor reads.
"""

from __future__ import annotations

from stairbot.control.algorithm.bias_evidence import MOUNT_TICKS, MountHeights
from stairbot.control.algorithm.edge_measure import edge_drop_m
from stairbot.control.algorithm.texts import bias as say
from stairbot.control.tolerances import pair_tolerance, standing_tolerance
from stairbot.hardware import SensorId, Snapshot
from stairbot.inputs.config import RobotConfig

MATCH_SHARE = 0.35
"""Evidence matches the standing rule's disagreement within the standing
tolerance, or this share of the disagreement if more (the onsets', the
mount heights', the rises')."""


def signed(disagree: float, sensor: SensorId) -> float:
    """The disagreement (left − right) as how far ``sensor`` reads past its partner."""
    return disagree if sensor in (SensorId.SFL, SensorId.SBL) else -disagree


def _named(mount: MountHeights, disagree: float, match: float,
           threshold: float) -> tuple[SensorId, SensorId, float, float, bool, float, bool] | None:
    """The back sensor whose mount height says what the disagreement (left −
    right) says, within ``match``: off by ``threshold`` or more, or read too
    near to measure (at least as short) over most of the last second or
    over its last TAIL_TICKS ticks or more, its partner measuring
    throughout; its partner within half of ``threshold`` (a sensor read too
    near: within ``threshold`` and a quarter of that sensor's shortfall).
    (sensor, partner, its offset, the partner's, read too near, how far it
    reads past its partner now, judged by its tail), or None."""
    last = mount.last
    if last is None:
        return None
    for sensor, partner, (off, near), (p_off, p_near), tail in (
            (SensorId.SBL, SensorId.SBR, last[1], last[0], mount.tails[1]),
            (SensorId.SBR, SensorId.SBL, last[0], last[1], mount.tails[0])):
        said = signed(disagree, sensor)
        by_tail = False
        if not near and tail is not None and tail[1] <= threshold / 2:
            off, near, by_tail = tail[0], True, True
        # a clamp says the sensor read at least that short: a partner a few
        # millimetres off its mount height (a sonar's 3 mm steps) still held
        held = abs(p_off) <= threshold / 2 or (near and abs(p_off) <= min(threshold, -off / 4))
        if p_near or not held:
            continue
        if (near and said <= off) or (not near and abs(off) >= threshold
                                      and abs(off - p_off - said) <= match):
            return sensor, partner, off, p_off, near, said, by_tail
    return None


def by_mount(mount: MountHeights, clearance: float, disagree: float, match: float,
             threshold: float) -> tuple[SensorId, str] | None:
    """At the end of the standing rule's wait: the back sensor whose mount
    height says what the disagreement (left − right) says, within
    ``match`` (off by ``threshold`` or more, or read too near to measure,
    its partner within half of it), and the evidence in words; or None."""
    found = _named(mount, disagree, match, threshold)
    if found is None:
        return None
    sensor, partner, off, p_off, near, said, by_tail = found
    return sensor, say.judged_by_mount(sensor, partner, off, p_off, near, said, clearance,
                                       by_tail)


def at_once(cfg: RobotConfig, mount: MountHeights, snap: Snapshot) -> tuple[SensorId, str] | None:
    """Descent 1 backing off a climbed step (the module docstring): the back
    sensor that reads what the edge watch takes for the drop, as it has
    for the whole of the last second on the tread (its mount height off by
    more than the standing tolerance and a pair tolerance, the pair as far
    apart now), while its partner reads the floor and read its mount
    height.  Returns the sensor and the evidence in words, or None."""
    if len(mount.ticks) < MOUNT_TICKS:
        return None  # the stretch on the tread ended (an edge read) or is younger than that
    r, left = snap.sensors[SensorId.SBR], snap.sensors[SensorId.SBL]
    if not (r.ok and left.ok):
        return None
    drop = edge_drop_m(cfg)
    if (r.distance_m > drop) == (left.distance_m > drop):
        return None  # both on the floor, or both past an edge
    clearance = cfg.BACK_CLEARANCE
    pair = pair_tolerance(cfg, clearance, back=True)
    threshold = max(standing_tolerance(cfg, clearance, back=True), pair)
    disagree = left.distance_m - r.distance_m
    found = _named(mount, disagree, max(pair, MATCH_SHARE * abs(disagree)), threshold)
    if found is None or found[4]:
        return None
    sensor, partner, off, p_off, _near, said, _tail = found
    if snap.sensors[sensor].distance_m <= drop:
        return None  # the floor-reading one: not what the edge watch is misled by
    return sensor, say.judged_mount_backing(sensor, partner, off, p_off, said, clearance, drop)
