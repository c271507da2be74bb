"""The simulated robot's rigid bodies in a pymunk space: three box segments
(index 0 = segment 1, the front) with two wheels each, driven by a motor per
wheel, and the two lead-screw lifts that slide segments 1 and 3 vertically
against segment 2 (a groove keeps each in line, a gear joint keeps it
parallel, a pin joint whose length the world moves sets the offset).

Segments do not collide with each other, only with the stairs.  Bodies are
added to the space in a fixed order: the simulation is deterministic.
"""

from __future__ import annotations

from dataclasses import dataclass

import pymunk

from stairbot.fakes.world_params import WorldParams
from stairbot.inputs.config import RobotConfig

PIN_REACH = 1.0  # the lift pin's lower anchor sits this far below segment 2's axles

CAT_STAIRS = 0b01
CAT_ROBOT = 0b10
ROBOT_GROUP = 1


@dataclass(frozen=True)
class RobotBodies:
    """What :func:`build_robot` put in the space, front to back."""

    segments: list[pymunk.Body]
    boxes: list[pymunk.Poly]
    wheels: list[tuple[pymunk.Body, pymunk.Body]]  # (rear, front)
    motors: list[tuple[pymunk.SimpleMotor, pymunk.SimpleMotor]]
    wheel_x: list[float]  # axle x from the segment centre (+ = front)
    pins: list[pymunk.PinJoint]  # lift 0 (MTF: segment 1), lift 1 (MTB: segment 3)


def build_robot(space: pymunk.Space, config: RobotConfig, p: WorldParams,
                lengths: tuple[float, float, float], front: float, base: float
                ) -> RobotBodies:
    """Add the robot to ``space`` standing level, segment 1's front face at x
    = ``front``, its wheels on the surface at y = ``base``, the lifts at
    zero offset."""
    g = config.geometry
    height, r = g.segment_height, g.wheel_radius
    masses = (config.masses.first_module, config.masses.second_module,
              config.masses.third_module)
    robot_filter = pymunk.ShapeFilter(group=ROBOT_GROUP, categories=CAT_ROBOT,
                                      mask=CAT_STAIRS)
    out = RobotBodies([], [], [], [], [], [])
    left = front
    for length, mass in zip(lengths, masses, strict=True):
        body = pymunk.Body()
        # local frame: origin at the segment's centre on its axle line
        body.position = (left - length / 2, base + r)
        half, ch = length / 2, min(p.chamfer, length / 4, height / 4)
        # the chassis' bottom edges are chamfered, as a real one's would be
        box = pymunk.Poly(body, [(-half + ch, 0.0), (half - ch, 0.0), (half, ch),
                                 (half, height), (-half, height), (-half, ch)])
        box.mass = mass
        box.friction = p.body_friction
        box.filter = robot_filter
        space.add(body, box)
        ax = length / 2 - g.wheel_inset
        out.wheel_x.append(ax)
        pair: list[pymunk.Body] = []
        mots: list[pymunk.SimpleMotor] = []
        for sx in (-ax, ax):
            wheel = pymunk.Body()
            wheel.position = body.local_to_world((sx, 0.0))
            circle = pymunk.Circle(wheel, r)
            circle.mass = 2 * config.masses.wheel  # the left and right wheel
            circle.friction = p.wheel_friction
            circle.filter = robot_filter
            pivot = pymunk.PivotJoint(body, wheel, (sx, 0.0), (0.0, 0.0))
            pivot.collide_bodies = False
            # rate = body.w - wheel.w: positive rolls forward (clockwise)
            motor = pymunk.SimpleMotor(body, wheel, 0.0)
            motor.max_force = config.motors.wheel_torque
            space.add(wheel, circle, pivot, motor)
            pair.append(wheel)
            mots.append(motor)
        out.segments.append(body)
        out.boxes.append(box)
        out.wheels.append((pair[0], pair[1]))
        out.motors.append((mots[0], mots[1]))
        left -= length
    s1, s2, s3 = out.segments
    lift_x = ((lengths[0] + lengths[1]) / 2, -(lengths[1] + lengths[2]) / 2)
    travel = config.motors.lift_travel + 0.02
    for end, gx in ((s1, lift_x[0]), (s3, lift_x[1])):
        groove = pymunk.GrooveJoint(s2, end, (gx, -travel), (gx, travel), (0.0, 0.0))
        gear = pymunk.GearJoint(s2, end, 0.0, 1.0)
        pin = pymunk.PinJoint(s2, end, (gx, -PIN_REACH), (0.0, 0.0))
        pin.distance = PIN_REACH
        pin.max_force = config.motors.lift_force
        for c in (groove, gear, pin):
            c.error_bias = 0.5 ** (1.0 / p.dt)
            c.collide_bodies = False
            space.add(c)
        out.pins.append(pin)
    return out
