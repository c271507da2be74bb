"""Limp home: what the robot does when a distance sensor is lost on the stairs
(not in the seed, which has no sensor faults).

A sensor the phase needs that reads as ERROR (errors, or stale) for
SENSOR_WAIT_S, or that is judged biased (it reads, but wrong:
:mod:`~stairbot.control.algorithm.bias`), is *lost*, and with it every other
distance sensor that reads as ERROR then, needed by the phase or not
(:func:`~stairbot.control.algorithm.lost.every_error`): what remains is judged
by all of them.  On the floor where the program began that ends
the run as it always has: the robot is home.  Anywhere else it is a
*degraded stop* (:class:`DegradedStop`): every motor stopped, the lifts
holding, and the robot says what failed, where it stands, and whether it
can come down on what remains.  It can while each pair keeps one sensor
(the survivor then stands for both: :func:`mirrored`; or the front pair is
lost where the way home reads nothing of it:
:mod:`~stairbot.control.algorithm.blind`), the IMU watches the tilt, and it
is not on a landing; with the operator's consent
(``stairbot run --yes``) it then finishes or undoes the step in progress and
goes down by the geometry it measured on the way up, at LIMP_SPEED of
every motor's speed, and the program ends ``came_home_degraded``.  Without
the consent, or where too little remains, it stays stopped.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from stairbot.control.algorithm.modes import LANDING_PURPOSES, Purpose
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.hardware import MotorId, SensorId, SensorReading, SensorStatus, Snapshot

LIMP_SPEED = 0.5
"""While limping home every motor runs at most this share of its maximum
speed (and a phase may last 1 / LIMP_SPEED times as long)."""

PARTNER = {SensorId.SFR: SensorId.SFL, SensorId.SFL: SensorId.SFR,
           SensorId.SBR: SensorId.SBL, SensorId.SBL: SensorId.SBR}
"""Each distance sensor's partner in its pair."""

PAIR_NAMES = {SensorId.SFR: "front", SensorId.SFL: "front",
              SensorId.SBR: "back", SensorId.SBL: "back"}


@dataclass
class Limp:
    """The run's progress once a sensor is lost off the floor and the robot
    could come down on the rest: the sensors lost (each the survivor of its
    pair stands in for), when and where, and whether the operator consented
    (not yet: the program ended there, and a resume with consent carries it
    on from ``stopped_in``)."""

    lost: list[str] = field(default_factory=list)
    """The lost sensors' names (SensorId values)."""
    since_s: float = 0.0
    where: str = ""
    """The phase (and step) the first was lost in, as the operator was told."""
    consented: bool = True
    stopped_in: str = ""
    """Not consented: the phase the program stopped in (a Phase value)."""


def mirrored(snap: Snapshot, lost: Sequence[str]) -> Snapshot:
    """``snap`` with each lost sensor reading what its partner reads: a pair
    of which one survives steers as one sensor (its mean is the survivor's,
    it never disagrees with itself, and it crosses an edge where the
    survivor does).  A pair both of whose sensors are lost reads as ERROR
    (:mod:`~stairbot.control.algorithm.blind`: only what needs no reading of
    it goes on)."""
    sensors = dict(snap.sensors)
    for name in lost:
        sid = SensorId(name)
        if PARTNER[sid].value in lost:
            r = snap.sensors[sid]
            sensors[sid] = SensorReading(r.distance_m, SensorStatus.ERROR, r.age_s)
        else:
            sensors[sid] = snap.sensors[PARTNER[sid]]
    return replace(snap, sensors=sensors)


def on_the_floor(phase: Phase, purpose: Purpose | None, steps_climbed: int,
                 mode: Mode, began: bool = True) -> bool:
    """Whether the robot still stands where it started, on the floor: a
    calibration-only run, or the start's calibration before it measured
    where the program began (``began`` false).  A sensor lost there ends the
    run where the robot stands, as it always has.  Once the start is
    measured, descent 7 knows the way back to it."""
    if mode is Mode.CALIBRATE_ONLY:
        return True
    if mode is Mode.DESCEND or steps_climbed > 0:
        return False
    return phase.flow == "calibration" and purpose is Purpose.START and not began


def cannot_limp(lost: Iterable[SensorId], phase: Phase, purpose: Purpose | None,
                tilt_watched: bool, turned_at_landing: bool = False,
                needs_no_front: bool = False) -> str | None:
    """Why the robot cannot come down on what remains (None: it can).
    ``needs_no_front``: the way home from ``phase`` reads no front sensor
    (:func:`~stairbot.control.algorithm.blind.needs_no_front`)."""
    gone = set(lost)
    for right, left, pair, what in (
            (SensorId.SFR, SensorId.SFL, "front", "nothing reads the risers and treads the "
                                                  "way down is measured against"),
            (SensorId.SBR, SensorId.SBL, "back", "nothing finds the edges and the floor "
                                                 "below a step")):
        if right in gone and left in gone and not (needs_no_front and pair == "front"):
            return f"both {pair} sensors lost: {what}"
    if not tilt_watched:
        return "no IMU watches the tilt: the robot does not move blind on its remaining sensors"
    if phase.flow == "landing" or purpose in LANDING_PURPOSES or turned_at_landing:
        return "on a landing: limping home across a landing's turn is not supported"
    return None


@dataclass(frozen=True)
class DegradedStop:
    """What the operator is told when a sensor is lost off the floor: what
    failed, where the robot stands, and what it does about it (``then``:
    "limp_home", "no_consent" or "stranded", with ``why``)."""

    lost: tuple[str, ...]
    failed: str
    phase: str
    where: str
    steps_climbed: int
    steps_descended: int
    lifts: dict[str, float]
    then: str
    why: str
    survivors: tuple[str, ...] = ()
    biased: tuple[str, ...] = ()
    """Those of ``lost`` judged biased: they read, but wrong (``failed`` says
    on what evidence); the others report errors or went stale."""
    plan: str = ""
    """What limping home would do from here, in words ("": it cannot)."""

    def to_dict(self) -> dict[str, Any]:
        return {"lost": list(self.lost), "failed": self.failed, "phase": self.phase,
                "where": self.where, "steps_climbed": self.steps_climbed,
                "steps_descended": self.steps_descended, "lifts": dict(self.lifts),
                "then": self.then, "why": self.why, "survivors": list(self.survivors),
                "biased": list(self.biased), "plan": self.plan}


def lifts(snap: Snapshot) -> dict[str, float]:
    """MTF's and MTB's counters (turns), as a degraded stop reports them."""
    return {m.value: round(snap.turns(m), 2) for m in (MotorId.MTF, MotorId.MTB)}


def survivors(lost: Iterable[SensorId]) -> tuple[str, ...]:
    """The partners that stand in for the lost sensors."""
    gone = set(lost)
    return tuple(sorted(PARTNER[s].value for s in gone if PARTNER[s] not in gone))
