"""The algorithm's modes and verdicts, as enums: what a calibration is for, the
case it found, why the ascent ended, how the program ended.

Each value is the stable name logs, journals and results use.
"""

from __future__ import annotations

from enum import Enum


class Purpose(Enum):
    """What the calibration phases are doing."""

    START = "start"
    """The program's first calibration: every case."""
    ASCENT = "ascent"
    """Ascent 1 on a later step: case 2 only."""
    DESCENT = "descent"
    """Descent 1: case 2 only."""
    HOME = "home"
    """Descent 7 turns back to the heading the program began with."""
    FLOOR = "floor"
    """Descent 7 turns back to the heading it crossed the floor with."""
    EDGE = "edge"
    """A continuous descent turns square to the edge its back pair found."""
    LANDING = "landing"
    """A landing's 90° turn onto the next flight."""
    LANDING_BACK = "landing_back"
    """A landing's turn back to the first flight."""


LANDING_PURPOSES = (Purpose.LANDING, Purpose.LANDING_BACK)
"""A landing's 90° turn onto the next flight, and back."""


class CalibrationCase(Enum):
    """The seed's calibration cases (2W: the nearer beam sees a side wall)."""

    ONE = "1"
    TWO = "2"
    TWO_W = "2W"
    THREE = "3"
    THREE_A = "3A"
    THREE_B = "3B"


class AscentEnd(Enum):
    """Why the ascent ended."""

    TOP_REACHED = "top_reached"
    OBSTACLE = "obstacle"
    STEP_LIMIT = "step_limit"
    LANDING_CLOSED = "landing_closed"
    LANDING_TOO_SMALL = "landing_too_small"
    SENSOR_LOST = "sensor_lost"
    """A sensor was lost on the stairs and the operator let the robot limp
    home: the step in progress finished or undone, it goes down."""


class Outcome(Enum):
    """How the program ended."""

    COMPLETED = "completed"
    STOPPED = "stopped"
    ERROR = "error"
    CAME_HOME_DEGRADED = "came_home_degraded"
    """A sensor was lost on the stairs, and the robot came back down to where
    it began on the sensors that remained (limp home)."""
