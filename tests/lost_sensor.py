"""What the limp-home tests share: a scenario in which SFR errs from 42 s, in
ascent 7 of step 1 (segment 3 rising) of a two-step flight on the reference
robot -- a degraded stop the robot can limp home from on SFL -- the two-step
flight the faults are laid on, and how a test reads a run's degraded stops."""

from __future__ import annotations

from typing import Any

from stairbot.events import Event, EventKind
from stairbot.run.runner import RunResult

LOST_MID_CLIMB = """
[stairs]
count = 2
[[faults]]
at = 42.0
sensor = "SFR"
kind = "error"
"""

TWO_STEPS = """
[stairs]
count = 2
rise = 0.17
tread = 0.28
[sensors]
noise = 0.001
seed = 5
"""
"""The two-step flight the limp-home, stuck and serial tests fault."""


def degraded_stops(events: list[Event]) -> list[dict[str, Any]]:
    """What each degraded stop of a run said (its ``data["degraded"]``)."""
    return [e.data["degraded"] for e in events
            if e.kind is EventKind.WARNING and "degraded" in e.data]


def degraded(events: list[Event]) -> dict[str, Any]:
    """The run's one degraded stop."""
    stops = degraded_stops(events)
    assert len(stops) == 1, stops
    return stops[0]


def home(r: RunResult) -> bool:
    """Back on the floor where it began, every step climbed come down."""
    return (not r.fell and r.steps_climbed == r.steps_descended
            and r.final_offset_m is not None and r.final_offset_m <= 0.05)


def sweep_flight(seed: int, at: float, sensor: str, fault: str) -> str:
    """The two-step flight of sweeps/sensor_faults.toml, its sensor noise
    seeded, with ``fault`` (the TOML of its kind) on ``sensor`` from ``at``
    on."""
    return f"""
[stairs]
count = 2
rise = 0.17
tread = 0.28
top = "landing"
[start]
distance = 0.5
[sensors]
noise = 0.001
seed = {seed}
[[faults]]
at = {at}
sensor = "{sensor}"
{fault}
"""
