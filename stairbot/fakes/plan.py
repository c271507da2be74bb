"""The top view of the simulated robot: lateral position, yaw, side walls.

The pymunk world is a side view along x (towards the risers).  The top view
adds what calibration needs: the robot's yaw (+ = turned left, counter-clockwise
seen from above) and the lateral position ``y`` of segment 2's centre (+ = left
of the flight's centre line).  Risers are planes x = const across the flight's
width; side walls, where the scenario puts them, are planes y = +-width/2 that
run the whole length of the stairwell.  A front beam that leaves the flight's
width before it reaches what the side view says it hits meets that side wall,
or nothing where there is no wall.

A wall may also stand over part of the length only (``walls``: ranges of x
per side; a quarter-turn landing's, :mod:`stairbot.fakes.landing`): a beam
meets it only where it crosses the wall's plane within one of them, which
needs the top-view x of segment 2's centre (``x``, the side view's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

Range = tuple[float, float]
"""From x to x (lo <= hi): where along the flight a wall stands."""
WHOLE_LENGTH: tuple[Range, ...] = ((-math.inf, math.inf),)
Walls = tuple[tuple[Range, ...], tuple[Range, ...]]
"""Where the left wall stands along x, and where the right one does (empty: none)."""


@dataclass
class Plan:
    """Top-view state: lateral offset and yaw of segment 2's centre."""

    width: float
    side_wall: str  # "none" | "left" | "right" | "both"
    y: float = 0.0
    yaw: float = 0.0  # radians, + = left
    x: float = 0.0
    """Top-view x of segment 2's centre (the side view's); only walls over part
    of the length need it."""
    walls: Walls | None = None
    """Where the walls stand along x, left and right; None: as ``side_wall``
    says, the whole length."""
    _left: tuple[Range, ...] = field(init=False, repr=False)  # set_walls sets these four
    _right: tuple[Range, ...] = field(init=False, repr=False)
    _left_all: bool = field(init=False, repr=False)
    _right_all: bool = field(init=False, repr=False)
    # the trigonometry of the yaw, kept while the yaw stays the same (see yaw_trig)
    _trig_of: float = field(init=False, repr=False, compare=False)
    _trig: tuple[float, float] = field(init=False, repr=False, compare=False)
    _turned_of: tuple[float, tuple[float, ...]] = field(init=False, repr=False, compare=False)
    _turned: list[tuple[float, float]] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # the fields that are not the constructor's are set here: the __init__
        # mypyc compiles for this module leaves their defaults unset
        self._trig_of, self._trig = math.nan, (1.0, 0.0)
        self._turned_of, self._turned = (math.nan, ()), []
        self.set_walls(self.walls)

    def set_walls(self, walls: Walls | None) -> None:
        """Put the walls where ``walls`` says (None: as ``side_wall`` says)."""
        self.walls = walls
        if walls is None:
            walls = (WHOLE_LENGTH if self.side_wall in ("left", "both") else (),
                     WHOLE_LENGTH if self.side_wall in ("right", "both") else ())
        self._left, self._right = walls
        self._left_all = walls[0] == WHOLE_LENGTH
        self._right_all = walls[1] == WHOLE_LENGTH

    @property
    def left_wall(self) -> bool:
        """Whether a left wall stands anywhere."""
        return bool(self._left)

    @property
    def right_wall(self) -> bool:
        """Whether a right wall stands anywhere."""
        return bool(self._right)

    def whole_length(self) -> tuple[bool, bool]:
        """Whether the left wall, and the right one, stand the whole length."""
        return self._left_all, self._right_all

    def wall_at(self, left: bool, x: float) -> bool:
        """Whether the left (or right) wall stands at ``x``."""
        if self._left_all if left else self._right_all:
            return True
        return any(lo <= x <= hi for lo, hi in (self._left if left else self._right))

    def yaw_trig(self) -> tuple[float, float]:
        """The cosine and sine of the yaw.  Worked out again only when the yaw
        has changed (the robot turns now and then; every sensor asks every
        tick); a yaw of 0 is worked out each time, as its sign counts."""
        yaw = self.yaw
        if yaw != self._trig_of or yaw == 0.0:
            self._trig_of, self._trig = yaw, (math.cos(yaw), math.sin(yaw))
        return self._trig

    def turned(self, angles: tuple[float, ...]) -> list[tuple[float, float]]:
        """The cosine and sine of the yaw plus each of ``angles`` (a cone's
        angles across it), worked out again only when the yaw or the angles
        have changed (see :meth:`yaw_trig`).  Read, never change or keep."""
        yaw = self.yaw
        if (yaw, angles) != self._turned_of or yaw == 0.0:
            self._turned_of = (yaw, angles)
            self._turned = [(math.cos(psi), math.sin(psi))
                            for psi in [yaw + across for across in angles]]
        return self._turned

    def move(self, dx: float) -> None:
        """The robot advanced ``dx`` along x (towards the risers) on its heading."""
        self.x += dx
        self.y += dx * math.tan(self.yaw)

    def turn(self, dyaw: float) -> None:
        """The robot turned ``dyaw`` radians about segment 2's centre (+ = left)."""
        self.yaw += dyaw

    def front_distance(self, forward: float, lateral: float, hit_dx: float | None,
                       slant: float) -> float | None:
        """Distance along a forward-looking beam to what it hits, or None.

        ``forward``: the mount's distance ahead of segment 2's centre along the
        robot's axis; ``lateral``: the mount's offset (+ = left); ``hit_dx``: how
        far ahead in x the side view's ray from the same mount hits the stairs
        (None: nothing); ``slant``: beam length per metre of x travelled in the
        side view (1 / cos(pitch)).  Valid for |yaw| < 90 degrees.
        """
        yaw = self.yaw
        hit = self.front_hit_at(forward, lateral, hit_dx, slant, math.cos(yaw), math.sin(yaw))
        return None if hit is None else hit[0]

    def front_hit(self, forward: float, lateral: float, hit_dx: float | None,
                  slant: float, yaw: float, mount_yaw: float | None = None
                  ) -> tuple[float, bool] | None:
        """:meth:`front_distance` for a beam turned ``yaw`` (the robot's yaw plus
        a ray's angle across a sensor's cone) from a mount placed by the
        robot's yaw ``mount_yaw`` (default: ``yaw``), and whether it meets a
        side wall (True) or the stairs (False); None: nothing."""
        c, s = math.cos(yaw), math.sin(yaw)
        if mount_yaw is None:
            return self.front_hit_at(forward, lateral, hit_dx, slant, c, s)
        return self.front_hit_at(forward, lateral, hit_dx, slant, c, s,
                                 math.cos(mount_yaw), math.sin(mount_yaw))

    def front_hit_at(self, forward: float, lateral: float, hit_dx: float | None,
                     slant: float, c: float, s: float, mc: float | None = None,
                     ms: float | None = None) -> tuple[float, bool] | None:
        """:meth:`front_hit` for a beam turned by the angle whose cosine is ``c``
        and sine ``s`` (beams at the same angle share them), from a mount placed
        by the robot's yaw, whose cosine and sine are ``mc`` and ``ms``
        (default: ``c`` and ``s``: a beam along the robot's axis)."""
        if mc is None or ms is None:
            mc, ms = c, s
        # the side view puts the mount at `forward` straight ahead; in the top view it
        # sits forward*cos - lateral*sin ahead of the centre and y_m to the side
        y_m = self.y + forward * ms + lateral * mc
        best: float | None = None
        if hit_dx is not None and c > 1e-9:
            dx = hit_dx + forward * (1.0 - mc) + lateral * ms
            if dx > 0.0:
                y_hit = y_m + dx * s / c
                if abs(y_hit) <= self.width / 2:
                    best = dx / c * slant
        # the side wall the beam turns towards, if there is one where it crosses its plane
        wall: float | None = None
        if s > 1e-9:
            if self._left:
                wall = max(0.0, (self.width / 2 - y_m) / s)
                if not self._left_all and not self.wall_at(
                        True, self.x + forward * mc - lateral * ms + wall * c):
                    wall = None
        elif s < -1e-9 and self._right:
            wall = max(0.0, (-(self.width / 2) - y_m) / s)
            if not self._right_all and not self.wall_at(
                    False, self.x + forward * mc - lateral * ms + wall * c):
                wall = None
        if wall is not None and (best is None or wall * slant < best):
            return wall * slant, True
        return None if best is None else (best, False)
