"""A host that stalls: the world runs on with the last speeds sent for longer
than a tick, unwatched (a scheduler's time slice, a collection; fake boards
at ``--time-scale 20`` turn 5 ms of wall clock into 100 ms of robot time).

Descent 1 places the edge of the step from where the back pair was seen
crossing it.  A crossing nobody saw happen -- the pair past the edge when the
back-off ended, or across a stretch the host missed -- was placed at the
tick that first saw the drop, 0 mm behind the pair, and backing the whole
clearance from there tipped the robot back (``benchmarks/soak_host_stalls.py``,
seed 19: +15.8 deg, stopped by the tilt limit).  Now the robot first drives
forward until the pair reads the floor again, then backs up to the edge
watching it cross.  The whole runs are on the pymunk robot.
"""

from __future__ import annotations

from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Phase
from stairbot.control.robot_config import load_config
from stairbot.events import Event
from stairbot.hardware import Clock, Snapshot
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult, run

CFG = load_config()
NOT_SEEN = "they were not seen crossing it"


class SlowInPhase:
    """The session's clock, but each tick of ``phase`` (the first time the
    controller is in it) takes ``stall_s`` longer."""

    def __init__(self, inner: Clock, phase: Phase, stall_s: float) -> None:
        self.inner, self.phase, self.stall_s = inner, phase, stall_s
        self.in_phase = False
        self.done = False
        self.stalls = 0

    def watch(self, ctl: Controller, _snap: Snapshot) -> None:
        now = ctl.phase is self.phase
        self.done = self.done or (self.in_phase and not now)
        self.in_phase = now and not self.done

    def now(self) -> float:
        return self.inner.now()

    def advance(self, dt: float) -> None:
        if self.in_phase:
            self.stalls += 1
            dt += self.stall_s
        self.inner.advance(dt)


def stalled_run(phase: Phase, stall_s: float) -> tuple[RunResult, list[Event], SlowInPhase]:
    session = open_robot("sim://", CFG, RobotOptions())
    clock = SlowInPhase(session.clock, phase, stall_s)
    session.clock = clock
    events: list[Event] = []
    result = run(session, CFG, sink=events.append, on_tick=clock.watch)
    return result, events, clock


def test_a_host_slow_through_the_back_off_still_places_the_edge_and_comes_home() -> None:
    r, events, clock = stalled_run(Phase.DESCENT_BACK_OFF, 0.12)
    assert clock.stalls > 3  # the back-off did run slow
    assert (r.outcome, r.steps_climbed, r.steps_descended) == ("completed", 5, 5), r.to_dict()
    assert not r.fell and r.max_pitch_deg is not None and r.max_pitch_deg < 8.0, r.to_dict()
    said = [e.message for e in events]
    refound = [i for i, m in enumerate(said) if NOT_SEEN in m]
    assert refound, "the robot should have driven forward to find the floor again"
    after = said[refound[0]:]
    assert any(m.startswith("SBR/SBL read the floor again") for m in after)
    assert any(m.startswith("SBR/SBL see the edge") for m in after)


def test_an_unstalled_run_sees_every_crossing_as_it_happens() -> None:
    session = open_robot("sim://", CFG, RobotOptions())
    events: list[Event] = []
    r = run(session, CFG, sink=events.append)
    assert r.outcome == "completed"
    assert not any(NOT_SEEN in e.message for e in events)
