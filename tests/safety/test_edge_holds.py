"""Descent 1 with the back pair's measurements held up again and again (a
lossy link: each reply lost leaves the pair's newest measurement older, and
past its limit every motor stops until a fresh one comes).  A hold is a
stretch the edge watch does not see, but the robot stands through it: the
floor the pair read before it still bounds where it can have crossed.

Before, every hold in the crossing sent the robot forward to find the floor
again, and the next hold came in the next crossing: 80-odd rounds and the
phase timeout (the 20 % serial real-time soak: 26 rounds on one step).  Now,
after finding the floor again, the robot backs slowly enough that a crossing
read after a hold is known within the clearance's doubt.  The whole runs are
on the pymunk robot, in lockstep."""

from __future__ import annotations

import dataclasses

import pytest

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Phase
from stairbot.control.robot_config import load_config
from stairbot.events import Event
from stairbot.hardware import BACK_SENSORS, Robot, Snapshot
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult, run

NOT_SEEN = "they were not seen crossing it"
WATCHED = (Phase.DESCENT_BACK_OFF, Phase.CAL_CHECK, Phase.DESCENT_BACK_TO_EDGE, Phase.PAUSED)


class BackPairHeldUp:
    """The simulated robot, but once descent has begun, while the controller
    backs to an edge (or stands in a hold there), its back pair's
    measurements come ``stale_s`` late in every ``every_s``: the board
    repeats an old one, as over a link that lost the replies between."""

    def __init__(self, inner: Robot, stale_s: float, every_s: float) -> None:
        self.inner, self.stale_s, self.every_s = inner, stale_s, every_s
        self.descending = self.active = False

    def __getattr__(self, name: str) -> object:
        return getattr(self.inner, name)

    def watch(self, ctl: Controller, _snap: Snapshot) -> None:
        self.descending = self.descending or ctl.phase is Phase.DESCENT_BACK_OFF
        self.active = self.descending and ctl.phase in WATCHED

    def read(self) -> Snapshot:
        snap = self.inner.read()
        if not self.active or snap.time_s % self.every_s >= self.stale_s:
            return snap
        sensors = dict(snap.sensors)
        for s in BACK_SENSORS:
            sensors[s] = dataclasses.replace(sensors[s], age_s=1.0)
        return dataclasses.replace(snap, sensors=sensors)


def held_up_run(config: str, stale_s: float, every_s: float) -> tuple[RunResult, list[str]]:
    cfg = load_config(config)
    session = open_robot("sim://", cfg, RobotOptions())
    robot = BackPairHeldUp(session.robot, stale_s, every_s)
    session.robot = robot  # type: ignore[assignment]
    events: list[Event] = []
    result = run(session, cfg, sink=events.append, on_tick=robot.watch)
    return result, [e.message for e in events]


@pytest.mark.parametrize(("config", "stale_s", "every_s"), [
    ("reference", 0.2, 0.35), ("reference", 0.15, 0.25), ("sonar", 0.2, 0.35),
])
def test_holds_in_every_crossing_still_bring_the_robot_down_each_edge_once_refound(
        config: str, stale_s: float, every_s: float) -> None:
    r, said = held_up_run(config, stale_s, every_s)
    assert sum(m.startswith("sensor hold") for m in said) > 50  # held up, again and again
    assert (r.outcome, r.steps_descended) == ("completed", r.steps_climbed), r.to_dict()
    assert r.steps_climbed == 5 and not r.fell, r.to_dict()
    assert r.max_pitch_deg is not None and r.max_pitch_deg < 8.0, r.to_dict()
    # found the floor again at most once an edge: after it the robot backs
    # slowly, and a crossing read after a hold is placed
    assert sum(NOT_SEEN in m for m in said) <= r.steps_descended


@pytest.mark.parametrize(("stale_s", "every_s"), [(0.15, 0.25), (0.16, 0.27)])
def test_a_drop_read_as_the_backing_brakes_is_placed_by_what_the_wheels_backed(
        stale_s: float, every_s: float) -> None:
    """The sonar robot, its back pair's replies lost part of the time: the
    pair read the drop as a backing braked (into a hold, or at its end),
    and the wheels' speed then, times the pair's lag, placed the crossing
    millimetres too far back -- the robot had backed faster while the
    measurements came through.  Backing the clearance from there, it
    pitched 17-18 deg nose up on the way down.  What the odometer recorded
    over the lag places it."""
    r, said = held_up_run("sonar", stale_s, every_s)
    assert any(m.startswith("sensor hold") for m in said)
    assert (r.outcome, r.steps_descended) == ("completed", r.steps_climbed), r.to_dict()
    assert r.steps_climbed == 5 and not r.fell, r.to_dict()
    assert r.max_pitch_deg is not None and r.max_pitch_deg < 8.0, r.to_dict()
