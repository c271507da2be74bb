"""A board robot's link health: the figures in every snapshot, and the LINK
events a sink hears when a trouble counter moves (at most one a second of
robot time)."""

from __future__ import annotations

import time
from collections.abc import Callable

from stairbot.drivers.link import LinkStats
from stairbot.events import Event, EventKind, EventSink

EVENT_EVERY_S = 1.0  # at most one link-trouble event per second of robot time
TROUBLE = ("retries", "revived", "timeouts", "lost", "late", "stray", "duplicates", "crc_errors",
           "malformed", "refused", "error_frames", "foreign", "bus_passive")
"""Counters whose move is a LINK event (the last three only a CAN link has)."""


class HealthReport:
    """Link health as figures and events, for one robot."""

    def __init__(self, stats: LinkStats, monotonic: Callable[[], float] = time.monotonic
                 ) -> None:
        self.stats = stats
        self.refused = 0  # commands a board refused (Ack other than OK)
        self._monotonic = monotonic
        self._rate_mark = (monotonic(), 0)
        self._fps = 0.0
        self._reported: dict[str, float] = {}
        self._last_event = float("-inf")

    def figures(self) -> dict[str, float]:
        """The link's counters, RTT figures, ``refused``, ``rtt_ms`` (the latest
        round trip) and ``frames_per_s`` (frames both ways, over the last
        second or so of wall time)."""
        stats = self.stats
        h = stats.as_dict()
        h["refused"] = float(self.refused)
        h["rtt_ms"] = round(stats.rtt_s[-1] * 1e3, 3) if stats.rtt_s else 0.0
        now, frames = self._monotonic(), stats.frames_tx + stats.frames_rx
        t0, f0 = self._rate_mark
        if now - t0 >= 1.0:
            self._fps = (frames - f0) / (now - t0)
            self._rate_mark = (now, frames)
        h["frames_per_s"] = round(self._fps, 1)
        return h

    def maybe_event(self, health: dict[str, float], now: float, sink: EventSink) -> None:
        """One LINK event naming the trouble counters that moved since the last
        one, if a second of robot time has passed since."""
        changed = {k: health[k] - self._reported.get(k, 0.0) for k in TROUBLE
                   if k in health and health[k] != self._reported.get(k, 0.0)}
        if changed and now - self._last_event >= EVENT_EVERY_S:
            self._last_event = now
            self._reported = dict(health)
            what = ", ".join(f"+{v:g} {k}" for k, v in changed.items())
            sink(Event(now, EventKind.LINK, f"link: {what} (rtt median "
                       f"{health['rtt_median_ms']:.2f} ms)", None, dict(health)))
