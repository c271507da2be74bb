"""Static stability before a lift: is the centre of mass over the wheels that
carry the robot while the lift moves, with ``[safety] stability_margin`` to
spare?

The side view: x forward along the robot from segment 2's centre on its axle
line, y up from that line; the robot pitched by the IMU's pitch (level
without one).  Each segment is its body (``masses.*_module``, its centre
``segment_height / 2`` above its axles) and four wheels (``masses.wheel``
each: two axles, left and right, ``wheel_inset`` from the segment's ends);
segments 1 and 3 stand at their lifts' heights above segment 2 (MTF and MTB
turns times ``lift_travel_per_turn``).  A wheel on a support touches it
under its axle, so the support is the span between the outermost axles of
the segments that carry the robot -- which the phase knows: lifting segment 1
leaves segments 2 and 3 carrying it, lifting segment 2 segments 1 and 3,
lifting segments 1 and 3 (calibration) segment 2 alone.

The centre of mass and each axle move in a straight line as a lift moves,
so the margin is least at the lift's start, at its target, or where two
carrying axles pass each other (the outermost one changes, which only a
steep pitch makes happen): :func:`worst` looks at each.

Pure functions, and :func:`before_lift`, which the controller runs once
before a lift phase's first step (docs/algorithm.md, "Safety").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations
from typing import Any

from stairbot.control.algorithm.phase import PhaseDef, Step, Tick, fail
from stairbot.control.algorithm.texts import shared as say
from stairbot.control.algorithm.work import LiftWork, Work
from stairbot.hardware import MotorId
from stairbot.inputs.config import RobotConfig

UNSTABLE_EDGE = "the lift would put the centre of mass outside the carrying wheels"
"""The condition on a lift phase's edge to the error, in the flowcharts."""


@dataclass(frozen=True, slots=True)
class Balance:
    """Horizontal positions (m, + forward) about segment 2's centre: the
    centre of mass and the rearmost and frontmost carrying contacts."""

    centre_x: float
    rear_x: float
    front_x: float

    @property
    def margin(self) -> float:
        """How far inside the support the centre of mass is (negative: outside)."""
        return min(self.centre_x - self.rear_x, self.front_x - self.centre_x)


def balance(cfg: RobotConfig, carried_by: tuple[int, ...], mtf_turns: float,
            mtb_turns: float, pitch_deg: float = 0.0) -> Balance:
    """Where the centre of mass stands against the wheels of the segments
    ``carried_by`` (1, 2, 3: front to back), with MTF and MTB at these
    counters and the robot pitched ``pitch_deg`` (+ nose up).  Raises
    ValueError when no segment carries it."""
    if not carried_by or not set(carried_by) <= {1, 2, 3}:
        raise ValueError(f"carried_by {carried_by!r}: name one or more of segments 1, 2, 3")
    g, m = cfg.geometry, cfg.masses
    _lengths, centres = _layout(cfg)
    heights = _heights(cfg, (mtf_turns, mtb_turns))
    bodies = (m.first_module, m.second_module, m.third_module)
    wheels = 4 * m.wheel
    theta = math.radians(pitch_deg)
    c, s = math.cos(theta), math.sin(theta)

    def horizontal(x: float, y: float) -> float:
        return x * c - y * s

    total = moment = 0.0
    for body, x, y in zip(bodies, centres, heights, strict=True):
        # the body's centre above its axles; the wheels' centre on them
        moment += body * horizontal(x, y + g.segment_height / 2) + wheels * horizontal(x, y)
        total += body + wheels
    axles = _axles(cfg, carried_by, heights, c, s)
    return Balance(moment / total, min(axles), max(axles))


Triple = tuple[float, float, float]


def _layout(cfg: RobotConfig) -> tuple[Triple, Triple]:
    """The segments' lengths, and their centres' x about segment 2's (front to back)."""
    g = cfg.geometry
    lengths = (g.LENGTH_OF_FIRST_MODULE, g.LENGTH_OF_SECOND_MODULE, g.LENGTH_OF_THIRD_MODULE)
    return lengths, ((lengths[0] + lengths[1]) / 2, 0.0, -(lengths[1] + lengths[2]) / 2)


def _heights(cfg: RobotConfig, counters: tuple[float, float]) -> Triple:
    """Each segment's axles above segment 2's, from the (MTF, MTB) counters."""
    per_turn = cfg.motors.lift_travel_per_turn
    return counters[0] * per_turn, 0.0, counters[1] * per_turn


def _axles(cfg: RobotConfig, carried_by: tuple[int, ...], heights: Triple,
           c: float, s: float) -> list[float]:
    """Horizontal positions of the carrying segments' axles (cos and sin of the pitch)."""
    lengths, centres = _layout(cfg)
    out = []
    for i in carried_by:
        half = lengths[i - 1] / 2 - cfg.geometry.wheel_inset
        for x in (centres[i - 1] - half, centres[i - 1] + half):
            out.append(x * c - heights[i - 1] * s)
    return out


def worst(cfg: RobotConfig, carried_by: tuple[int, ...], start: tuple[float, float],
          end: tuple[float, float], pitch_deg: float = 0.0) -> Balance:
    """The least stable position of a lift from (MTF, MTB) counters ``start``
    to ``end``: at one of its ends or where two carrying axles pass each
    other (see the module docstring)."""
    theta = math.radians(pitch_deg)
    c, s = math.cos(theta), math.sin(theta)
    a0 = _axles(cfg, carried_by, _heights(cfg, start), c, s)
    a1 = _axles(cfg, carried_by, _heights(cfg, end), c, s)
    where = {0.0, 1.0}
    for i, j in combinations(range(len(a0)), 2):
        d0, d1 = a0[i] - a0[j], a1[i] - a1[j]
        if d0 * d1 < 0.0:
            where.add(d0 / (d0 - d1))
    return min((balance(cfg, carried_by, start[0] + f * (end[0] - start[0]),
                        start[1] + f * (end[1] - start[1]), pitch_deg) for f in sorted(where)),
               key=lambda b: b.margin)


def carried_now(t: Tick, record: PhaseDef[Any]) -> tuple[int, ...]:
    """The segments that carry the robot while ``record``'s lift moves: its
    ``carried_by``, less segment 3 while it hangs in the air over the step
    below (narrow steps: ``Context.third_in_air``)."""
    carried = record.carried_by
    if t.ctx.third_in_air and 3 in carried and len(carried) > 1:
        return tuple(i for i in carried if i != 3)
    return carried


def before_lift(t: Tick, record: PhaseDef[Any], w: Work) -> Step | None:
    """Once, before ``record``'s first step (a phase that moves a lift): the
    error that ends the program if the lift from the present counters to the
    work's targets would bring the centre of mass within
    ``[safety] stability_margin`` of the edge of the carrying wheels, or
    beyond; None when it is stable (or not a lift phase)."""
    w.balanced = True
    if not record.carried_by:
        return None
    assert isinstance(w, LiftWork)  # a phase that moves a lift
    cfg, snap = t.cfg, t.snap
    carried = carried_now(t, record)
    start = (snap.turns(MotorId.MTF), snap.turns(MotorId.MTB))
    targets = w.lift_targets()
    end = (targets.get(MotorId.MTF, start[0]), targets.get(MotorId.MTB, start[1]))
    imu = snap.imu
    pitch = imu.pitch_deg if cfg.safety.imu and imu is not None \
        and math.isfinite(imu.pitch_deg) else 0.0
    b = worst(cfg, carried, start, end, pitch)
    need = cfg.safety.stability_margin
    if b.margin >= need:
        return None
    return fail(say.unstable_lift(record.label, b.margin, carried, b.rear_x, b.front_x,
                                  b.centre_x, pitch, need))
