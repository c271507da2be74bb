"""The side view of the simulated robot on its stairs: a pymunk world that
steps the physics, moves the lifts, and watches for a fall.

x points forward (towards the stairs), y up, gravity -9.81 m/s^2, metres and
kilograms throughout.  Riser 1 stands at x = 0; the robot starts with its front
face ``scenario.start.distance`` before it.  The robot's bodies and joints
are built by :mod:`stairbot.fakes.robot_bodies`; the world moves each lift's
pin joint with the commanded speed (it holds the offset when stopped), and
:mod:`stairbot.fakes.fall_watch` says when the robot has fallen.

Python work per physics step is kept to the lift targets; everything else
(motor rates, stability checks) happens once per :meth:`World.advance` call,
which the simulated clock makes once per control tick.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from typing import Any

import pymunk

try:  # the C functions behind pymunk's Body properties, without the Python wrapper
    from pymunk._chipmunk import ffi as _ffi
    from pymunk._chipmunk import lib as _cp
except ImportError:  # pragma: no cover - another pymunk layout: the public API is used
    _cp = _ffi = None
from stairbot.fakes.fall_watch import FallWatch
from stairbot.fakes.margin_watch import MarginWatch
from stairbot.fakes.robot_bodies import CAT_STAIRS, PIN_REACH, build_robot
from stairbot.fakes.stairs import StairsProfile, stairs_outline
from stairbot.fakes.world_params import WorldParams
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario

TWO_PI = 2.0 * math.pi


def top_edge(scenario: Scenario) -> tuple[float, float]:
    """(x, y) of the top edge: where the last riser meets the last tread."""
    x = sum(step.tread for step in scenario.steps[:-1])
    return x, sum(step.rise for step in scenario.steps)


def start_pose(scenario: Scenario, length: float) -> tuple[float, float]:
    """Where the robot starts: x of its front face, and y of the surface it
    stands on.  On the floor (``start.on = "floor"``) its front face is
    ``start.distance`` before riser 1; on the top it faces away from the
    flight, its rear ``start.distance`` past the top edge."""
    start = scenario.start
    if start.on == "top":
        x, y = top_edge(scenario)
        return x + start.distance + length, y
    return -start.distance, 0.0


class World:
    """The pymunk world: static stairs, the robot's bodies, joints and motors."""

    def __init__(self, config: RobotConfig, scenario: Scenario,
                 params: WorldParams | None = None) -> None:
        self.config = config
        self.scenario = scenario
        self.params = p = params or WorldParams()
        g = config.geometry
        self.space = space = pymunk.Space()
        space.gravity = (0.0, -9.81)
        space.iterations = p.iterations
        space.collision_slop = p.collision_slop
        self.time = 0.0
        self._steps_done = 0
        self._stairs: list[pymunk.Segment] = []
        self.set_stairs(stairs_outline(scenario))

        self.lengths = (g.LENGTH_OF_FIRST_MODULE, g.LENGTH_OF_SECOND_MODULE,
                        g.LENGTH_OF_THIRD_MODULE)
        self.height = g.segment_height
        self.radius = g.wheel_radius
        front, base = start_pose(scenario, sum(self.lengths))
        bodies = build_robot(space, config, p, self.lengths, front, base)
        self.segments, self.boxes = bodies.segments, bodies.boxes
        self.wheels, self.motors = bodies.wheels, bodies.motors
        self.wheel_x, self.pins = bodies.wheel_x, bodies.pins
        self.lift_target = [0.0, 0.0]  # metres, + = end segment up
        self.lift_speed = [0.0, 0.0]  # metres per second (already clamped)
        self._wheel_zero = [w1.angle - b.angle
                            for b, (_w0, w1) in zip(self.segments, self.wheels, strict=True)]
        self.all_wheels = [w for pair in self.wheels for w in pair]
        self._rates = [0.0, 0.0, 0.0]
        self._bias = [-1.0, -1.0]
        self._moving = [False, False]
        self._pose_at = -1
        # each segment and its (rear, front) wheels: (x, y, angle) of each, in one call
        self._read_bodies = _batch_reader(space, [b for seg, (rear, front) in
                                                  zip(self.segments, self.wheels, strict=True)
                                                  for b in (seg, rear, front)])
        self._ptrs: list[tuple[object, object]] | None = None  # (segment, its front wheel)
        if _cp is not None and all(hasattr(b, "_body") for b in self.space.bodies):
            self._ptrs = [(b._body, w[1]._body)
                          for b, w in zip(self.segments, self.wheels, strict=True)]
        self._px, self._py, self._pa = [0.0] * 3, [0.0] * 3, [0.0] * 3
        self._bodies: list[float] = []  # the batch reader's last read, when it is at hand
        self._wheel_turns, self._lifts = [0.0] * 3, [0.0, 0.0]
        self._stroke, self._stall = config.motors.lift_travel, p.lift_stall
        self._cp_step: tuple[Callable[[Any, float], None], Any] | None = None
        # setting a pin's distance (each tick a lift moves) and a motor's rate,
        # without pymunk's Python properties where its C functions are at hand
        self._set_distance = [_setter(pin, "distance", "cpPinJointSetDist") for pin in self.pins]
        self._set_rate = [[_setter(m, "rate", "cpSimpleMotorSetRate") for m in pair]
                          for pair in self.motors]
        self._fetch()
        self.falls = FallWatch(p, self.all_wheels, self._py)
        self.margins = MarginWatch(self.segments, self.boxes, self.all_wheels, self.radius,
                                   p.stairs_radius, config.motors.lift_travel, p.contact_check_s)
        self.start_x = self._px[1]

    # -- the stairs, and a change of frame ---------------------------------------------
    def set_stairs(self, outline: list[tuple[float, float]]) -> None:
        """Make ``outline`` the stairs: the static segments the wheels roll on,
        ``outline`` and ``profile`` (the sensors' rays).  Between steps only."""
        p = self.params
        if self._stairs:
            self.space.remove(*self._stairs)
        self.outline = outline
        self.profile = StairsProfile(outline, p.stairs_radius)
        self._stairs = []
        for a, b in zip(outline, outline[1:], strict=False):
            seg = pymunk.Segment(self.space.static_body, a, b, p.stairs_radius)
            seg.friction = p.stairs_friction
            seg.filter = pymunk.ShapeFilter(categories=CAT_STAIRS)
            self._stairs.append(seg)
        self.space.add(*self._stairs)

    def shift(self, dx: float) -> None:
        """Move every body of the robot ``dx`` along x, velocities, angles and
        joints as they are (a change of frame: fakes/landing.py).  Between steps only."""
        for body in (*self.segments, *self.all_wheels):
            x, y = body.position
            body.position = (x + dx, y)
        self._pose_at = -1

    # -- actuators ------------------------------------------------------------------
    def set_wheel_speed(self, segment: int, turns_per_s: float) -> None:
        """Drive both wheels of a segment at ``turns_per_s`` (+ = forward)."""
        rate = turns_per_s * TWO_PI
        if rate != self._rates[segment]:  # setting a pymunk attribute is not free
            self._rates[segment] = rate
            for set_rate in self._set_rate[segment]:
                set_rate(rate)

    def set_lift_speed(self, lift: int, metres_per_s: float) -> None:
        """Move lift 0 (MTF) or 1 (MTB) at ``metres_per_s`` (+ = end segment up); 0 holds."""
        self.lift_speed[lift] = metres_per_s

    def _steps(self, n: int) -> None:
        """``n`` physics steps.  The first goes through pymunk's Space.step,
        which checks the bodies; after it, with no collision handlers,
        post-step callbacks or objects added while stepping (this world has
        none), cpSpaceStep alone is the whole of a step, without the
        wrapper's Python."""
        dt = self.params.dt
        if n <= 0:
            return
        if self._cp_step is None:
            self.space.step(dt)
            n -= 1
            if _cp is not None and hasattr(self.space, "_space"):
                self._cp_step = (_cp.cpSpaceStep, self.space._space)
            else:  # pragma: no cover - another pymunk layout
                for _ in range(n):
                    self.space.step(dt)
                return
        step, handle = self._cp_step
        for _ in range(n):
            step(handle, dt)

    # -- state (read once per physics state by _fetch, then from the cache) ---------
    def _fetch(self) -> None:
        if self._pose_at == self._steps_done:
            return
        px, py, pa = self._px, self._py, self._pa
        if self._read_bodies is not None:
            (px[0], py[0], pa[0], _x, _y, _a, _x, _y, front0,
             px[1], py[1], pa[1], _x, _y, _a, _x, _y, front1,
             px[2], py[2], pa[2], _x, _y, _a, _x, _y, front2) = self._bodies = self._read_bodies()
            wa = (front0, front1, front2)
        elif self._ptrs is not None:
            get_pos, get_angle = _cp.cpBodyGetPosition, _cp.cpBodyGetAngle
            (b0, w0), (b1, w1), (b2, w2) = self._ptrs
            p0, p1, p2 = get_pos(b0), get_pos(b1), get_pos(b2)
            px[0], py[0], pa[0] = p0.x, p0.y, get_angle(b0)
            px[1], py[1], pa[1] = p1.x, p1.y, get_angle(b1)
            px[2], py[2], pa[2] = p2.x, p2.y, get_angle(b2)
            wa = (get_angle(w0), get_angle(w1), get_angle(w2))
        else:
            for i, body in enumerate(self.segments):
                pos = body.position
                px[i], py[i], pa[i] = pos.x, pos.y, body.angle
            (_r0, f0), (_r1, f1), (_r2, f2) = self.wheels
            wa = (f0.angle, f1.angle, f2.angle)
        # the front wheels' encoders, and the lifts' offsets across segment 2's axle line
        turns, zero = self._wheel_turns, self._wheel_zero
        turns[0] = -(wa[0] - pa[0] - zero[0]) / TWO_PI
        turns[1] = -(wa[1] - pa[1] - zero[1]) / TWO_PI
        turns[2] = -(wa[2] - pa[2] - zero[2]) / TWO_PI
        sin_a, cos_a = math.sin(pa[1]), math.cos(pa[1])
        lifts = self._lifts
        lifts[0] = -sin_a * (px[0] - px[1]) + cos_a * (py[0] - py[1])
        lifts[1] = -sin_a * (px[2] - px[1]) + cos_a * (py[2] - py[1])
        self._pose_at = self._steps_done

    def lift_offset(self, lift: int) -> float:
        """Actual height of segment 1 (lift 0) or 3 (lift 1) over segment 2, m."""
        if self._pose_at != self._steps_done:
            self._fetch()
        return self._lifts[0 if lift == 0 else 1]

    def wheel_turns(self, segment: int) -> float:
        """Turns of a segment's front wheel relative to the segment (+ = forward):
        what the wheel motor's encoder counts."""
        if self._pose_at != self._steps_done:
            self._fetch()
        return self._wheel_turns[segment]

    def pitch_deg(self, segment: int = 1) -> float:
        """Nose-up pitch of a segment in degrees."""
        if self._pose_at != self._steps_done:
            self._fetch()
        return math.degrees(self._pa[segment])

    def pitch_rate_dps(self, segment: int = 1) -> float:
        """Nose-up pitch rate of a segment in degrees per second."""
        if self._ptrs is not None:
            return math.degrees(_cp.cpBodyGetAngularVelocity(self._ptrs[segment][0]))
        return math.degrees(self.segments[segment].angular_velocity)

    def pose(self, segment: int) -> tuple[float, float, float]:
        """(x, y, angle) of a segment's local origin: its centre on the axle line."""
        if self._pose_at != self._steps_done:
            self._fetch()
        return self._px[segment], self._py[segment], self._pa[segment]

    def centre_x(self) -> float:
        """x of segment 2's centre (its axle line)."""
        if self._pose_at != self._steps_done:
            self._fetch()
        return self._px[1]

    def clear_of_stairs_m(self) -> float:
        """How far segment 1's front face stands before riser 1 (x = 0), along
        the flight; negative once it is over the stairs."""
        if self._pose_at != self._steps_done:
            self._fetch()
        x, a = self._px[0], self._pa[0]
        return -(x + math.cos(a) * self.lengths[0] / 2)

    def state(self) -> tuple[list[float], list[float], list[float], list[float], list[float]]:
        """What pose, wheel_turns and lift_offset tell one at a time, in one call:
        the segments' x, y, angle, the wheels' turns, the lifts' offsets.  The
        world's own lists, refilled after each step: read now, never change or keep."""
        if self._pose_at != self._steps_done:
            self._fetch()
        return self._px, self._py, self._pa, self._wheel_turns, self._lifts

    @property
    def steps_done(self) -> int:
        """Physics steps taken so far: identifies the physics state."""
        return self._steps_done

    # -- stepping -------------------------------------------------------------------
    def _steps_for(self, seconds: float) -> int:
        target = round((self.time + seconds) / self.params.dt)
        return max(0, target - self._steps_done)

    def step_bare(self, seconds: float) -> None:
        """Step the physics ``seconds`` with nothing else: no lifts, no checks."""
        n = self._steps_for(seconds)
        dt = self.params.dt
        self._steps(n)
        self._steps_done += n
        self.time = self._steps_done * dt

    def advance(self, seconds: float) -> None:
        """Step the physics ``seconds`` (whole physics steps), moving the lifts at
        their set speeds within their stroke, then check stability and the margins."""
        dt = self.params.dt
        n = round((self.time + seconds) / dt) - self._steps_done  # as _steps_for
        if n <= 0:
            return
        self._set_lifts(n * dt)
        self._steps(n)
        done = self._steps_done = self._steps_done + n
        self.time = done * dt
        if not self.falls.fell:  # the stability check, on the new state
            self._fetch()
            self.falls.check(self.time, self._py, self._pa)
            if self.margins.due(n * dt, self._lifts):
                self._look_at_margins()

    def _look_at_margins(self) -> None:
        """Where the robot touches the stairs now (:class:`MarginWatch`); the
        edge margin of the wheels that stand: none while a wheel drives, and
        not those of the segment the lifts move (segment 1 or 3 when one
        lift moves, the middle one when both do)."""
        px, py, pa = self._px, self._py, self._pa
        b = self._bodies
        if b:  # each segment's (x, y, angle), then its rear and front wheels'
            wheels = [(b[3], b[4]), (b[6], b[7]), (b[12], b[13]), (b[15], b[16]),
                      (b[21], b[22]), (b[24], b[25])]
        else:
            wheels = [(w.position.x, w.position.y) for w in self.all_wheels]
        up0, up1 = self.lift_speed
        if self._rates[0] != 0.0 or self._rates[1] != 0.0 or self._rates[2] != 0.0:
            judged: tuple[int, ...] = ()
        elif up0 != 0.0:
            judged = (0, 2) if up1 != 0.0 else (1, 2)
        else:
            judged = (0, 1) if up1 != 0.0 else (0, 1, 2)
        self.margins.look(self.outline, [(px[0], py[0], pa[0]), (px[1], py[1], pa[1]),
                                         (px[2], py[2], pa[2])], wheels, judged)

    def _set_lifts(self, seconds: float) -> None:
        """Aim each moving lift's pin at where the screw will be in ``seconds``; the
        pin's max_bias makes it travel there at the lift's speed, so no Python runs
        between physics steps."""
        speed, moving = self.lift_speed, self._moving
        if (speed[0] == 0.0 and speed[1] == 0.0 and not moving[0] and not moving[1]
                and self._bias[0] == self._bias[1] == self.params.lift_hold_speed):
            return  # both held, as they were: nothing to set
        stroke, stall = self._stroke, self._stall
        hold = self.params.lift_hold_speed
        if self._pose_at != self._steps_done:
            self._fetch()
        offsets = self._lifts  # (lift_offset's)
        for i in (0, 1):
            v = speed[i]
            if v != 0.0:
                # a stalled lead screw does not run ahead of its nut
                actual = offsets[i]
                t = min(max(self.lift_target[i], actual - stall), actual + stall) + v * seconds
                t = stroke if t > stroke else (-stroke if t < -stroke else t)
                self.lift_target[i] = t
                self._set_distance[i](PIN_REACH + t)
            elif moving[i]:
                # just stopped: the screw stands where the nut is now, no coasting on
                t = offsets[i]
                self.lift_target[i] = t
                self._set_distance[i](PIN_REACH + t)
            moving[i] = v != 0.0
            bias = abs(v) if v != 0.0 else hold
            if bias != self._bias[i]:
                self._bias[i] = bias
                self.pins[i].max_bias = bias

    # -- falls ----------------------------------------------------------------------
    @property
    def fell(self) -> bool:
        """The robot has fallen (:class:`~stairbot.fakes.fall_watch.FallWatch`)."""
        return self.falls.fell

    @property
    def fall_reason(self) -> str | None:
        return self.falls.reason

    @property
    def max_pitch_deg(self) -> float:
        """The largest pitch of any segment so far, degrees."""
        return self.falls.max_pitch_deg

    # -- queries --------------------------------------------------------------------
    def ray(self, start: tuple[float, float], end: tuple[float, float]
            ) -> tuple[float, float] | None:
        """First point of the stairs' surface on the segment start -> end, or None."""
        return self.profile.ray(start[0], start[1], end[0], end[1])

    def ray_normal(self, start: tuple[float, float], end: tuple[float, float]
                   ) -> tuple[float, float, float, float] | None:
        """Like :meth:`ray`, with the unit normal of the surface met: (x, y, nx, ny)."""
        return self.profile.ray_normal(start[0], start[1], end[0], end[1])

    def clear_of_ground(self, segment: int, clearance: float) -> bool:
        """True when nothing of the stairs lies within ``clearance`` under the
        segment's wheels."""
        r = self.radius
        for w in self.wheels[segment]:
            c = w.position
            if self.ray((c.x, c.y), (c.x, c.y - r - clearance)) is not None:
                return False
            for dx in (-r, r):
                if self.ray((c.x + dx * 0.7, c.y), (c.x + dx * 0.7, c.y - r - clearance)):
                    return False
        return True

    def underside(self, segment: int) -> float:
        """Height of a segment's lowest point: the bottom of its lower wheel."""
        rear, front = self.wheels[segment]
        return min(rear.position.y, front.position.y) - self.radius

    def segment_corners(self, segment: int) -> list[tuple[float, float]]:
        """The segment chassis' outline in world metres (a closed polygon, CCW)."""
        return [(float(v.x), float(v.y))
                for v in (self.segments[segment].local_to_world(q)
                          for q in self.boxes[segment].get_vertices())]


def _batch_reader(space: pymunk.Space, bodies: list[pymunk.Body]
                  ) -> Callable[[], list[float]] | None:
    """A function that reads (x, y, angle) of each of ``bodies``, flat, in their
    order, in one C call through pymunk's batch API: what Body.position and
    Body.angle tell, without a call for each.  None where the API is not at hand,
    or the space does not go through its bodies in that order (it goes through
    them in the order they were added, while none is removed or sleeps: this
    world removes none and lets none sleep)."""
    try:
        from pymunk.batch import Buffer  # (pymunk 6.6 on)

        buffer = Buffer()
        data = _ffi.new("pmBatchedData *")
        data.floatArray, data.intArray = buffer._float_arr, buffer._int_arr
        each, visit = _cp.cpSpaceEachBody, _ffi.addressof(_cp, "pmSpaceBodyGetIteratorFuncBatched")
        handle = space._space
        data.fields = _cp.BODY_ID
        each(handle, visit, data)
        ids = buffer._int_arr
        if _ffi.unpack(ids.arr, ids.num)[:len(bodies)] != [b.id for b in bodies]:
            return None
        data.fields = _cp.POSITION | _cp.ANGLE
    except (AttributeError, ImportError, TypeError):  # pragma: no cover - another pymunk
        return None
    floats, unpack, count = buffer._float_arr, _ffi.unpack, 3 * len(bodies)

    def read() -> list[float]:
        floats.num = 0  # (the buffer, kept by this closure, is refilled from the start)
        each(handle, visit, data)
        return unpack(floats.arr, count)

    return read


def _setter(obj: pymunk.Constraint, name: str, c_function: str) -> Callable[[float], None]:
    """A function setting ``obj.name``: pymunk's C function ``c_function`` on it
    when at hand (what the property does, without its Python), else the
    property."""
    handle = getattr(obj, "_constraint", None)
    if _cp is not None and handle is not None and hasattr(_cp, c_function):
        return partial(getattr(_cp, c_function), handle)
    return partial(setattr, obj, name)
