"""The stairwell seen from above, and quarter-turn landings: flight 1's and
flight 2's frames and the switch between them.

The pymunk world is a side view along one axis (:mod:`stairbot.fakes.world`);
the top view (:mod:`stairbot.fakes.plan`) adds yaw and the side walls the
front beams see.  This module holds what neither can: the whole stairwell as
vertical faces in flight 1's frame (top view x forward up flight 1, y left,
heights z), for what only looks or reaches sideways -- the side pair SSR/SSL
(:meth:`Stairwell.side_hit`) and the footprint check (:meth:`Stairwell.contact`).

Flight 1 runs along +x, ``width`` wide about y = 0, its last riser at x = X1
(``world.top_edge``), its top at H1.  With a quarter-turn landing
(``scenario.landing``) the top is the landing x in [X1, X1 + depth], y in
[-width/2, width/2] at H1: a full-height wall at x = X1 + depth (the far
wall, in flight 1's side view), a full-height wall on the side opposite the
turn, and on the turn side the second flight: riser k (from 0) of it is the
plane y = +-(width/2 + k tread2) over x in [X1, X1 + depth], from
H1 + k rise2 to H1 + (k + 1) rise2, between walls at x = X1 and the far wall
(flight 2 is ``depth`` wide), up to a 3 m top.  No second flight: that side is
a full-height wall too.

Frames.  Flight 2's frame has x' up flight 2 and y' to its left, turned a
quarter from flight 1's: for a left turn (s = 1) or a right one (s = -1)

    x' = s y,   y' = -s (x - (X1 + depth / 2)),   yaw' = yaw - s 90 deg,

so the landing spans x' in [-width/2, width/2] with the opposite wall behind at
x' = -width/2, flight 2's first riser at x' = width/2, and y' in
[-depth/2, depth/2].  The side view in flight 2's frame is that: the wall,
the landing, flight 2's risers and its top (:meth:`Stairwell.outline`).

The switch (:meth:`Stairwell.switch`, once per advance): a robot whose
segment 2's centre stands on the landing and that has turned more than 45
degrees towards the second flight is moved to flight 2's frame -- the static
segments and the rays' profile rebuilt from flight 2's outline, the robot's
bodies shifted along x so that segment 2's centre lands on its x' (heights,
angles, velocities, joints and so every turn counter as they were), and the
top view's x, y, yaw, width and walls set for the new frame.  At 45 degrees
the share of travel along the side view's axis (cos yaw) is the same in both
frames.  Turning back past 45 degrees on the landing (a descent coming back
down flight 2) switches back.  A landing without a second flight never
switches.

The footprint check (:meth:`Stairwell.contact`) watches every wall and
flight 2's risers (but see below): a segment of the footprint seen from
above reaching more than ``CONTACT_DEPTH`` into one that stands higher than
the segment's underside (its wheels' lowest point) is a contact.  The side
view stops the robot's centre line at the faces it holds, not its corners
(a robot turned on the landing sweeps its corners into the far wall) and
not at the faces it does not hold (side walls, flight 2 in flight 1's
frame); nothing stops the robot there -- the sweeps judge it by
``Truth.wall_contact``.  Flight 1's risers are not watched: the robot climbs
them; nor are flight 2's in flight 2's frame while the robot stands within
CLIMB_YAW of its axis (climbing them, not turning).

Limits: in a frame's side view the stairs reach sideways without end (a robot
driven sideways off the landing over flight 1's top edge, in flight 2's
frame, does not fall; nor off an open side of a flight, as in any side view); the front
beams meet flight 2's first riser in flight 1's frame as a full-height wall
(Plan's walls); the side view lays the robot along its axis, so near a riser
at 45 degrees a switch may put an end segment into it (only where the
footprint check has already reported a contact).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from stairbot.fakes.plan import WHOLE_LENGTH, Plan, Range, Walls
from stairbot.fakes.stairs import FLOOR_BEHIND, LANDING, OPEN_FLOOR, WALL_HEIGHT, stairs_outline
from stairbot.fakes.world import World, top_edge
from stairbot.inputs.scenario import Scenario

Point = tuple[float, float]

SWITCH_YAW = math.pi / 4
"""The frame switches when the robot turns past this towards the other flight."""
CONTACT_DEPTH = 0.003
"""The footprint must reach this far into a face for a contact, m: the side
view lets a wheel or a chassis rest against a riser or a wall (its contact
slop and the stairs' rounding: 1.5 mm), and a robot a degree or two off square
reaches that much further at its corners."""
CLIMB_YAW = math.radians(20.0)
"""In flight 2's frame, its risers are the side view's, as flight 1's are in
flight 1's: the robot climbs them, resting against each (a corner a degree
or two off square reaches past CONTACT_DEPTH).  The footprint check watches
them there only while the robot is turned more than this from flight 2's
axis: turning on the landing."""
CONTACT_TOLERANCE = 0.002
"""A riser's top must stand this far above a segment's underside for a
contact (a wheel resting on the tread beside it is not one), m."""
FOOTPRINT_MARGIN = 0.02
"""The footprint is ``track_width`` plus this wide (the wheels' own width)."""

_INF = math.inf


@dataclass(frozen=True)
class Face:
    """A vertical face of the stairwell in flight 1's frame: the plane x = ``at``
    from y = ``lo`` to ``hi`` (``across = "x"``), or y = ``at`` from x = ``lo``
    to ``hi`` (``"y"``), from height ``bottom`` to ``top``; ``kind``: "wall",
    "riser" (flight 1's) or "riser2" (flight 2's)."""

    across: str
    at: float
    lo: float
    hi: float
    bottom: float
    top: float
    name: str
    kind: str


class Stairwell:
    """The stairwell of a scenario (see the module docstring), and the frame the
    simulation is in (``flight``: 1, or 2 on a quarter-turn landing's second
    flight)."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.half = scenario.width / 2
        self.landing = landing = scenario.landing
        self.flight = 1
        self.x1, self.h1 = top_edge(scenario) if scenario.steps else (0.0, 0.0)
        self.sign = 1 if landing is None or landing.turn == "left" else -1
        self.turns = landing is not None and bool(landing.steps)
        """Whether there is a second flight to switch to."""
        self.x_mid = self.x1 + (landing.depth / 2 if landing is not None else 0.0)
        self.faces: tuple[Face, ...] = tuple(_faces(scenario, self.x1, self.h1))
        # for the casts: (at, lo, hi, bottom, top) per face, each kind apart
        self._x_faces = [(f.at, f.lo, f.hi, f.bottom, f.top) for f in self.faces
                         if f.across == "x"]
        self._y_faces = [(f.at, f.lo, f.hi, f.bottom, f.top) for f in self.faces
                         if f.across == "y"]
        # the faces the footprint check watches, with their extent seen from above
        self._watched = tuple((f, *_box(f)) for f in self.faces if f.kind != "riser")
        self._footprint = (0.0, 0.0, 0.0, 0.0, 0.0)  # see footprint()
        self._near: tuple[tuple[float, float, float, float], ...] = ()

    # -- frames -----------------------------------------------------------------------
    def in_flight1(self, x: float, y: float, yaw: float) -> tuple[float, float, float]:
        """A top-view pose (x, y, yaw in radians) in the current frame, in flight 1's."""
        if self.flight == 1:
            return x, y, yaw
        s = self.sign
        return self.x_mid - s * y, s * x, yaw + s * math.pi / 2

    def from_flight1(self, x: float, y: float, yaw: float, flight: int
                     ) -> tuple[float, float, float]:
        """A top-view pose in flight 1's frame, in ``flight``'s."""
        if flight == 1:
            return x, y, yaw
        s = self.sign
        return s * y, -s * (x - self.x_mid), yaw - s * math.pi / 2

    def outline(self, flight: int) -> list[Point]:
        """The side view of ``flight``'s frame: the stairs' surface as one polyline."""
        if flight == 1 or self.landing is None:
            return stairs_outline(self.scenario)
        second = stairs_outline(replace(self.scenario, steps=self.landing.steps,
                                        top="landing", landing=None))
        # the landing from the opposite wall (behind) to flight 2's first riser,
        # then flight 2 (its floor behind left out)
        half, h1 = self.half, self.h1
        return [(-half, h1 + WALL_HEIGHT), (-half, h1),
                *[(x + half, y + h1) for x, y in second[1:]]]

    def width(self, flight: int) -> float:
        """The width of ``flight`` (and of the landing across it)."""
        if flight == 1 or self.landing is None:
            return self.scenario.width
        return self.landing.depth

    def walls(self, flight: int) -> Walls | None:
        """Where the top view's walls stand along x in ``flight``'s frame, left and
        right (None: without a landing, as ``side_wall`` says).  On the landing the
        front beams meet flight 2's first riser as a wall."""
        landing = self.landing
        if landing is None:
            return None
        if flight == 2:
            near: tuple[Range, ...] = ((self.half, _INF),)  # flight 2's wall at x = X1
            return (near, WHOLE_LENGTH) if self.sign > 0 else (WHOLE_LENGTH, near)
        side = self.scenario.side_wall
        left = WHOLE_LENGTH if side in ("left", "both") else ((self.x1, _INF),)
        right = WHOLE_LENGTH if side in ("right", "both") else ((self.x1, _INF),)
        return left, right

    # -- the switch -------------------------------------------------------------------
    def switch(self, world: World, plan: Plan) -> bool:
        """Switch frames if the robot, segment 2's centre on the landing, has turned
        past 45 degrees towards the other flight (see the module docstring);
        whether it did."""
        if not self.turns:
            return False
        s, x = self.sign, world.centre_x()
        if self.flight == 1:
            if s * plan.yaw <= SWITCH_YAW or x < self.x1:
                return False
            self.enter(2, world, plan)
        else:
            if s * plan.yaw >= -SWITCH_YAW or x > self.half:
                return False
            self.enter(1, world, plan)
        return True

    def enter(self, flight: int, world: World, plan: Plan) -> None:
        """Put the world and the top view in ``flight``'s frame, the robot where it is."""
        if flight == self.flight:
            return
        x = world.centre_x()
        pose = self.in_flight1(x, plan.y, plan.yaw)
        nx, ny, nyaw = self.from_flight1(*pose, flight)
        self.flight = flight
        world.set_stairs(self.outline(flight))
        world.shift(nx - x)
        plan.width = self.width(flight)
        plan.x, plan.y, plan.yaw = nx, ny, nyaw
        plan.set_walls(self.walls(flight))

    # -- what looks or reaches sideways --------------------------------------------------
    def side_hit(self, x: float, y: float, z: float, ux: float, uy: float, reach: float
                 ) -> tuple[float, float] | None:
        """The first face a level beam from (x, y) at height ``z`` along the unit
        vector (ux, uy) meets within ``reach`` (flight 1's frame): its distance and
        the cosine of the beam's incidence on it; None: nothing.  A face is met
        where its bottom is below the beam and its top above it."""
        best, incidence = reach, 0.0
        if ux > 1e-12 or ux < -1e-12:
            for at, lo, hi, bottom, top in self._x_faces:
                t = (at - x) / ux
                if 0.0 < t < best and bottom < z < top and lo <= y + t * uy <= hi:
                    best, incidence = t, abs(ux)
        if uy > 1e-12 or uy < -1e-12:
            for at, lo, hi, bottom, top in self._y_faces:
                t = (at - y) / uy
                if 0.0 < t < best and bottom < z < top and lo <= x + t * ux <= hi:
                    best, incidence = t, abs(uy)
        return None if incidence == 0.0 else (best, incidence)

    def watches(self) -> bool:
        """Whether there is anything for the footprint check to watch."""
        return bool(self._watched)

    def footprint(self, lengths: tuple[float, float, float], width: float) -> None:
        """Set the robot's footprint for :meth:`contact`: its segments' lengths
        (front to back) end to end, ``width`` wide."""
        l1, l2, l3 = lengths
        d = CONTACT_DEPTH  # the footprint less this all round: reaching in further
        front, rear, hw = l2 / 2 + l1 - d, -(l2 / 2 + l3) + d, width / 2 - d
        self._footprint = (front, rear, hw, l2 / 2, -l2 / 2)
        reach = max(front, -rear) + hw  # no face further than this from segment 2's centre
        self._near = tuple((ax - reach, bx + reach, ay - reach, by + reach)
                           for _f, ax, bx, ay, by in self._watched)

    def contact(self, world: World, x: float, y: float, yaw: float) -> tuple[int, str] | None:
        """The first segment (index, front to back) whose footprint
        (:meth:`footprint`) reaches more than ``CONTACT_DEPTH`` into a wall or a
        riser of flight 2 standing higher than the segment's underside, and that
        face's name; None: none.  ``x``, ``y``, ``yaw``: segment 2's centre and
        the heading in flight 1's frame."""
        for x_lo, x_hi, y_lo, y_hi in self._near:  # every tick: the short way out first
            if x_lo <= x <= x_hi and y_lo <= y <= y_hi:
                break
        else:
            return None
        front, rear, hw, mid_front, mid_rear = self._footprint
        c, s = math.cos(yaw), math.sin(yaw)
        # the footprint's box seen from above: a face outside it is not met
        fc, rc, fs, rs = front * c, rear * c, front * s, rear * s
        wx, wy = hw * abs(s), hw * abs(c)
        x_lo, x_hi = x + min(fc, rc) - wx, x + max(fc, rc) + wx
        y_lo, y_hi = y + min(fs, rs) - wy, y + max(fs, rs) + wy
        # each segment's stretch along the robot, front to back
        stretches = ((mid_front, front), (mid_rear, mid_front), (rear, mid_rear))
        undersides: list[float | None] = [None, None, None]
        # flight 2's risers are the side view's while the robot climbs them
        climbing = self.flight == 2 and abs(yaw - self.sign * math.pi / 2) < CLIMB_YAW
        for face, ax, bx, ay, by in self._watched:
            if bx < x_lo or ax > x_hi or by < y_lo or ay > y_hi:
                continue
            if climbing and face.kind == "riser2":
                continue
            # the face's ends in the robot's frame (u along it, v to its left)
            u0, v0 = (ax - x) * c + (ay - y) * s, -(ax - x) * s + (ay - y) * c
            u1, v1 = (bx - x) * c + (by - y) * s, -(bx - x) * s + (by - y) * c
            met = _clip(u0, v0, u1, v1, rear, front, -hw, hw)
            if met is None:
                continue
            ua, ub = u0 + (u1 - u0) * met[0], u0 + (u1 - u0) * met[1]
            u_lo, u_hi = min(ua, ub), max(ua, ub)
            for i, (lo, hi) in enumerate(stretches):
                if u_hi < lo or u_lo > hi:
                    continue
                under = undersides[i]
                if under is None:
                    under = undersides[i] = world.underside(i)
                if face.top > under + CONTACT_TOLERANCE:
                    return i, face.name
        return None


def _box(face: Face) -> tuple[float, float, float, float]:
    """x from, x to, y from, y to of a face seen from above."""
    if face.across == "x":
        return face.at, face.at, face.lo, face.hi
    return face.lo, face.hi, face.at, face.at


def _clip(u0: float, v0: float, u1: float, v1: float, u_lo: float, u_hi: float,
          v_lo: float, v_hi: float) -> tuple[float, float] | None:
    """The part of the segment (u0, v0) -> (u1, v1) inside the box, as its
    parameters from and to (0..1); None: it misses the box (Liang-Barsky)."""
    t0, t1 = 0.0, 1.0
    du, dv = u1 - u0, v1 - v0
    for p, q in ((-du, u0 - u_lo), (du, u_hi - u0), (-dv, v0 - v_lo), (dv, v_hi - v0)):
        if p == 0.0:
            if q < 0.0:
                return None
            continue
        r = q / p
        if p < 0.0:
            t0 = max(t0, r)
        else:
            t1 = min(t1, r)
        if t0 > t1:
            return None
    return t0, t1


def _faces(scenario: Scenario, x1: float, h1: float) -> list[Face]:
    """The stairwell's faces in flight 1's frame (see the module docstring)."""
    half, steps, landing = scenario.width / 2, scenario.steps, scenario.landing
    faces: list[Face] = []
    x = h = 0.0
    for k, step in enumerate(steps):
        if k:
            x += steps[k - 1].tread
        faces.append(Face("x", x, -half, half, h, h + step.rise, f"riser {k + 1}", "riser"))
        h += step.rise
    if not steps:
        end = OPEN_FLOOR
    elif landing is not None:
        end = x1  # flight 1's side walls end at its top edge; the landing has its own
    elif scenario.top == "wall":
        end = x1 + steps[-1].tread
        faces.append(Face("x", end, -half, half, h1, h1 + WALL_HEIGHT, "the wall at the top",
                          "wall"))
    else:
        end = x1 + steps[-1].tread + LANDING
    for side, s in (("left", 1), ("right", -1)):
        if scenario.side_wall in (side, "both"):
            faces.append(Face("y", s * half, -FLOOR_BEHIND, end, -_INF, _INF,
                              f"flight 1's {side} wall", "wall"))
    if landing is None:
        return faces
    s = 1 if landing.turn == "left" else -1
    other = "right" if s > 0 else "left"
    far = x1 + landing.depth
    second = landing.steps
    length2 = sum(step.tread for step in second) + LANDING if second else 0.0
    ends = sorted((-s * half, s * (half + length2)))
    faces.append(Face("x", far, ends[0], ends[1], -_INF, _INF, "the landing's far wall",
                      "wall"))
    faces.append(Face("y", -s * half, x1, far, -_INF, _INF, f"the landing's {other} wall",
                      "wall"))
    if not second:
        faces.append(Face("y", s * half, x1, far, -_INF, _INF,
                          f"the landing's {landing.turn} wall (no second flight)", "wall"))
        return faces
    y, h = half, h1
    for k, step in enumerate(second):
        faces.append(Face("y", s * y, x1, far, h, h + step.rise, f"riser {k + 1} of flight 2",
                          "riser2"))
        y += step.tread
        h += step.rise
    lo, hi = sorted((s * half, s * (half + length2)))
    faces.append(Face("x", x1, lo, hi, -_INF, _INF, f"flight 2's {landing.turn} wall", "wall"))
    return faces
