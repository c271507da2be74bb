"""Clocks for the run loop.  The algorithm itself only ever sees snapshot times;
a clock decides how those times pass.  :class:`WallClock` is for real robots;
the simulation brings its own clock (stairbot.fakes.sim.SimClock)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable


@dataclass(frozen=True, slots=True)
class HostBehind:
    """How far a control loop fell behind its period: ``ticks`` that began
    more than one tick late (the clock gave up catching up on each), and the
    longest of those latenesses, in seconds of the clock."""

    ticks: int = 0
    longest_s: float = 0.0

    def to_dict(self) -> dict[str, float]:
        return {"ticks": self.ticks, "longest_s": round(self.longest_s, 4)}


@runtime_checkable
class CountsLateTicks(Protocol):
    """A clock that waits for real time and counts the ticks that began late
    (a loaded machine, a stalled host).  A simulated clock has nothing to
    count: its time passes when the loop says so."""

    def begin_loop(self) -> None:
        """A control loop starts: the next ``advance`` sets its period
        afresh (however long ago the clock last advanced), and the count
        starts from zero."""

    def host_behind(self) -> HostBehind:
        """The late ticks since ``begin_loop`` (or since the clock was made)."""


class WallClock:
    """Real time: ``advance(dt)`` waits until ``dt`` after the previous deadline,
    so a control loop keeps its period however long each cycle took.  A
    cycle that ends more than ``dt`` past its deadline is not caught up: the
    next tick begins at once, late, and is counted (:meth:`host_behind`).
    The first ``advance`` of a loop only sets the period."""

    def __init__(
        self,
        monotonic: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self._monotonic = monotonic
        self._sleep = sleep
        self._start = monotonic()
        self._deadline = 0.0
        self._looping = False  # an advance has set the period
        self._behind = HostBehind()

    def now(self) -> float:
        return self._monotonic() - self._start

    def begin_loop(self) -> None:
        self._looping = False
        self._behind = HostBehind()

    def host_behind(self) -> HostBehind:
        return self._behind

    def advance(self, dt: float) -> None:
        now = self.now()
        due = self._deadline + dt  # when the next tick should begin
        late = now - due
        if self._looping and late > dt:
            self._behind = HostBehind(self._behind.ticks + 1,
                                      max(self._behind.longest_s, late))
        self._looping = True
        self._deadline = max(due, now - dt)
        delay = self._deadline - self.now()
        if delay > 0:
            self._sleep(delay)
