"""What a replay plays: a recording's ticks (what the host read and
commanded, and where the segments were) and its events, in time order on
the replay's timeline, for ``stairbot replay`` (:mod:`stairbot.console.replay`),
and the side view at a tick (:func:`scene_of`).
:func:`stairbot.recording.replay_load.load_replay` reads a file into one.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from stairbot.events import Event
from stairbot.hardware import MotorId, Point, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.views.side_view import SceneView

PART_GAP_S = 0.001
"""On the replay's timeline a robot's part starts this long after the one
before ends (the time that passed between them is not recorded; the gap
keeps the two apart: no time holds a tick of each)."""


@dataclass(frozen=True, slots=True)
class SegmentFrame:
    """One segment's frame in the side view: its origin (centre of the axle
    line, m) and its nose-up pitch (rad)."""

    x: float
    z: float
    pitch: float


@dataclass(frozen=True)
class Tick:
    """One control cycle as recorded.  ``snapshot`` None: its sensor and
    motor messages were lost (a file cut short inside the cycle)."""

    time_s: float
    """On the replay's timeline (the robot's clock, shifted for a later part)."""
    snapshot: Snapshot | None
    commanded: dict[MotorId, float] | None
    """The speeds commanded (None: nothing was sent, or not recorded)."""
    frames: tuple[SegmentFrame, ...] = ()
    """Segments 1..3, front to back (empty: no pose recorded)."""
    part: int = 0
    """The robot it came from (:attr:`ReplaySource.parts`)."""


@dataclass
class Part:
    """One robot of a recording.  A console records across robots (a reset,
    another URL: each a ``/scene`` of its own), and each robot's clock is its
    own: a reset simulation starts at 0 again.  The replay's timeline plays
    the parts one after another (:data:`PART_GAP_S` apart): a part's robot
    time ``t`` is at ``start_s + t - first_t`` on it (the first part: at
    ``t`` itself)."""

    url: str = ""
    scenario: str = ""
    pose_topic: str = ""
    stairs: tuple[Point, ...] = ()
    start_s: float = 0.0
    first_t: float | None = None
    """The robot time of its first message (None: none yet)."""
    last_t: float = 0.0

    def timeline(self, robot_s: float) -> float:
        """Where robot time ``robot_s`` of this part is on the replay's timeline."""
        return self.start_s + robot_s - (robot_s if self.first_t is None else self.first_t)

    @property
    def end_s(self) -> float:
        return self.timeline(self.last_t)


@dataclass
class ReplaySource:
    """Everything a replay plays, in time order on the replay's timeline."""

    path: str
    kind: str
    """"mcap" or "jsonl"."""
    ticks: list[Tick]
    events: list[Event]
    complete: bool
    """False: the file was cut short (read up to where it ends)."""
    config: RobotConfig | None
    """The robot config the recording was made with (None: not in it)."""
    parts: list[Part] = field(default_factory=lambda: [Part()])
    notes: list[str] = field(default_factory=list)
    """What could not be read, said once to the operator."""

    @property
    def start_s(self) -> float:
        times = [t for t in (self.ticks[0].time_s if self.ticks else None,
                             self.events[0].time_s if self.events else None) if t is not None]
        return min(times) if times else 0.0

    @property
    def end_s(self) -> float:
        times = [t for t in (self.ticks[-1].time_s if self.ticks else None,
                             self.events[-1].time_s if self.events else None) if t is not None]
        return max(times) if times else 0.0

    def tick_index(self, time_s: float) -> int:
        """How many ticks are at or before ``time_s``."""
        return bisect_right(_Times(self.ticks), time_s)

    def event_index(self, time_s: float) -> int:
        """How many events are at or before ``time_s``."""
        return bisect_right(_Times(self.events), time_s)

    def part_at(self, time_s: float) -> int:
        """The part playing at ``time_s`` on the timeline."""
        return max(0, bisect_right([p.start_s for p in self.parts[1:]], time_s))


class _Times(Sequence[float]):
    """The times of a list of ticks or events, for bisect (no copy)."""

    def __init__(self, items: Sequence[Tick] | Sequence[Event]) -> None:
        self._items = items

    def __len__(self) -> int:
        return len(self._items)

    def __getitem__(self, i: Any) -> Any:
        return self._items[i].time_s



def scene_of(tick: Tick, stairs: tuple[Point, ...], config: RobotConfig) -> SceneView | None:
    """The side view at ``tick``: each segment a box of the config's size on
    its recorded frame, its wheels on the axle line (None: no pose)."""
    if len(tick.frames) != 3:
        return None
    g = config.geometry
    lengths = (g.LENGTH_OF_FIRST_MODULE, g.LENGTH_OF_SECOND_MODULE, g.LENGTH_OF_THIRD_MODULE)
    segments: list[tuple[Point, ...]] = []
    wheels: list[tuple[float, float, float]] = []
    for frame, length in zip(tick.frames, lengths, strict=True):
        c, s = math.cos(frame.pitch), math.sin(frame.pitch)

        def at(u: float, v: float, f: SegmentFrame = frame, c: float = c,
               s: float = s) -> Point:
            return (f.x + u * c - v * s, f.z + u * s + v * c)

        half = length / 2
        segments.append((at(-half, 0.0), at(half, 0.0), at(half, g.segment_height),
                         at(-half, g.segment_height)))
        ax = half - g.wheel_inset
        wheels.extend((*at(u, 0.0), g.wheel_radius) for u in (ax, -ax))
    return SceneView(stairs=stairs, segments=tuple(segments), wheels=tuple(wheels),
                     time_s=tick.time_s)
