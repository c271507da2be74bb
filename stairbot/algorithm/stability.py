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

The centre of mass and the axles both move in a straight line as a lift
moves, so the check at the lift's start and at its target covers every
position in between.

Pure functions, and :func:`before_lift`, which the controller runs once
before a lift phase's first step (docs/algorithm.md, "Safety").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from stairbot.algorithm.phase import PhaseDef, Step, Tick, fail
from stairbot.algorithm.work import Work
from stairbot.config import RobotConfig
from stairbot.hardware import MotorId

UNSTABLE = "unstable lift"
"""How the reason of a refused lift begins (as "sensor error", "motor fault")."""
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
    per_turn = cfg.motors.lift_travel_per_turn
    lengths = (g.LENGTH_OF_FIRST_MODULE, g.LENGTH_OF_SECOND_MODULE, g.LENGTH_OF_THIRD_MODULE)
    centres = ((lengths[0] + lengths[1]) / 2, 0.0, -(lengths[1] + lengths[2]) / 2)
    heights = (mtf_turns * per_turn, 0.0, mtb_turns * per_turn)
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
    axles = [horizontal(centres[i - 1] + side * (lengths[i - 1] / 2 - g.wheel_inset),
                        heights[i - 1])
             for i in carried_by for side in (-1.0, 1.0)]
    return Balance(moment / total, min(axles), max(axles))


def worst(cfg: RobotConfig, carried_by: tuple[int, ...], start: tuple[float, float],
          end: tuple[float, float], pitch_deg: float = 0.0) -> Balance:
    """The less stable of the lift's two ends, (MTF, MTB) counters at ``start``
    and ``end``: the worse of every position in between (see the module
    docstring)."""
    return min((balance(cfg, carried_by, *at, pitch_deg) for at in (start, end)),
               key=lambda b: b.margin)


def before_lift(t: Tick, record: PhaseDef, w: Work) -> Step | None:
    """Once, before ``record``'s first step (a phase that moves a lift): the
    error that ends the program if the lift from the present counters to the
    work's targets would bring the centre of mass within
    ``[safety] stability_margin`` of the edge of the carrying wheels, or
    beyond; None when it is stable (or not a lift phase)."""
    w.balanced = True
    if not record.carried_by:
        return None
    cfg, snap = t.cfg, t.snap
    start = (snap.turns(MotorId.MTF), snap.turns(MotorId.MTB))
    targets = w.lift_targets()
    end = (targets.get(MotorId.MTF, start[0]), targets.get(MotorId.MTB, start[1]))
    imu = snap.imu
    pitch = imu.pitch_deg if cfg.safety.imu and imu is not None \
        and math.isfinite(imu.pitch_deg) else 0.0
    b = worst(cfg, record.carried_by, start, end, pitch)
    need = cfg.safety.stability_margin
    if b.margin >= need:
        return None
    who = " and ".join(str(i) for i in record.carried_by)
    plural = "s" if len(record.carried_by) > 1 else ""
    side = "outside" if b.margin < 0 else "inside"
    return fail(
        f"{UNSTABLE}: {record.label} would leave the centre of mass {abs(b.margin) * 1000:.1f} mm "
        f"{side} the wheels that carry the robot (segment{plural} {who}: {b.rear_x * 1000:+.1f} "
        f"to {b.front_x * 1000:+.1f} mm about segment 2's centre, the centre of mass at "
        f"{b.centre_x * 1000:+.1f} mm, pitch {pitch:+.1f}°), less than [safety] "
        f"stability_margin {need * 1000:g} mm: refused before moving, every motor stopped, "
        "lifts holding")
