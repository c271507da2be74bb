"""Clocks for the run loop.  The algorithm itself only ever sees snapshot times;
a clock decides how those times pass.  :class:`WallClock` is for real robots;
the simulation brings its own clock (stairbot.fakes.sim.SimClock)."""

from __future__ import annotations

import time
from collections.abc import Callable


class WallClock:
    """Real time: ``advance(dt)`` waits until ``dt`` after the previous deadline,
    so a control loop keeps its period however long each cycle took."""

    def __init__(
        self,
        monotonic: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self._monotonic = monotonic
        self._sleep = sleep
        self._start = monotonic()
        self._deadline = 0.0

    def now(self) -> float:
        return self._monotonic() - self._start

    def advance(self, dt: float) -> None:
        self._deadline = max(self._deadline + dt, self.now() - dt)
        delay = self._deadline - self.now()
        if delay > 0:
            self._sleep(delay)
