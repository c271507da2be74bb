"""Issue 35, defect 8: "a summary event listed before an earlier info
event".  A console note ("run completed") was timed at the last reading
(326.08 s), after the run's summary (326.10 s) had been listed: the list
went back in time.  A note is timed at the robot's clock as last heard
from, reading or event; another robot starts that clock again."""

from __future__ import annotations

from stairbot.console.state import LiveState
from stairbot.events import Event, EventKind
from stairbot.hardware import MotorId, MotorState, SensorId, SensorReading, Snapshot


def snapshot(t: float) -> Snapshot:
    return Snapshot(t, {s: SensorReading(0.3) for s in SensorId},
                    {m: MotorState(0.0) for m in MotorId})


def test_a_note_after_the_summary_is_listed_at_or_after_it_console_defect_8() -> None:
    state = LiveState()
    state.on_read(snapshot(326.08))
    state.on_event(Event(326.08, EventKind.END, "program ended (completed)"))
    state.on_event(Event(326.10, EventKind.SUMMARY, "run completed; climbed 5, descended 5"))
    state.note("run completed")
    times = [event.time_s for _, event in state.view().events]
    assert times == sorted(times) and times[-1] == 326.10, times
    state.set_robot("sim://", "default", True)  # another robot: its clock from 0
    state.on_read(snapshot(0.5))
    state.note("opened")
    assert state.view().events[-1][1].time_s == 0.5
