"""The run loop's operator controls and capabilities, on the simulated robot:
each e-stop press is one ``robot.estop()`` and each clear one ``robot.clear()``
on the run thread, in the order pressed; nothing is commanded while latched;
clearing alone never restarts motion; truth and events by ``isinstance``."""

from __future__ import annotations

import threading
from collections.abc import Callable

from stairbot.control.algorithm.controller import Controller
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind, EventSink
from stairbot.hardware import Robot, Snapshot, Speeds
from stairbot.run.robots import RobotOptions, RobotSession, open_robot
from stairbot.run.runner import RunControl, run

CONFIG = load_config()


class Recorder:
    """A Robot passing every call to the simulation and noting it (name,
    thread); it has no truth of its own (not HasTruth)."""

    def __init__(self, inner: Robot) -> None:
        self.inner = inner
        self.calls: list[tuple[str, int]] = []
        self.motion: list[int] = []  # call indices of commands that asked for motion

    def _note(self, name: str) -> None:
        self.calls.append((name, threading.get_ident()))

    def read(self) -> Snapshot:
        self._note("read")
        return self.inner.read()

    def command(self, speeds: Speeds) -> None:
        if any(v != 0 for v in speeds.values()):
            self.motion.append(len(self.calls))
        self._note("command")
        self.inner.command(speeds)

    def stop_all(self) -> None:
        self._note("stop_all")
        self.inner.stop_all()

    def estop(self) -> None:
        self._note("estop")
        self.inner.estop()

    def clear(self) -> None:
        self._note("clear")
        self.inner.clear()

    @property
    def estopped(self) -> bool:
        return self.inner.estopped

    def diagnostics(self) -> dict[str, object]:
        return self.inner.diagnostics()

    def close(self) -> None:
        self.inner.close()

    def names(self, since: int = 0) -> list[str]:
        return [name for name, _ in self.calls[since:]]


def recorded_sim() -> tuple[RobotSession, Recorder]:
    session = open_robot("sim://", CONFIG, RobotOptions())
    rec = Recorder(session.robot)
    return RobotSession(rec, session.clock, session.url, session.simulated, session.sim), rec


def script(steps: dict[int, Callable[[], None]]) -> Callable[[Controller, Snapshot], None]:
    """An on_tick that does ``steps[n]`` after the n-th tick (on the run thread)."""
    count = [0]

    def on_tick(_ctl: Controller, _snap: Snapshot) -> None:
        count[0] += 1
        step = steps.get(count[0])
        if step is not None:
            step()
    return on_tick


def test_estop_then_clear_then_resume() -> None:
    session, rec = recorded_sim()
    control = RunControl()
    marks: dict[str, int] = {}

    def mark(name: str, then: Callable[[], None]) -> Callable[[], None]:
        def go() -> None:
            marks[name] = len(rec.calls)
            then()
        return go

    on_tick = script({
        150: mark("estop", control.estop),
        200: mark("clear", control.clear_estop),
        250: mark("resume", control.resume),
        400: lambda: control.request_stop("enough"),
    })
    result = run(session, CONFIG, control=control, on_tick=on_tick)
    assert result.outcome == "stopped"
    assert rec.motion and rec.motion[0] < marks["estop"]  # it was moving before the stop
    latched = rec.names(marks["estop"])[:rec.names(marks["estop"]).index("clear")]
    assert latched.count("estop") == 1  # one press, one robot.estop()
    assert "command" not in latched  # nothing sent while latched
    assert rec.names().count("clear") == 1
    # Clearing alone moves nothing: no motion between the clear and the resume.
    assert not [i for i in rec.motion if marks["clear"] <= i < marks["resume"]]
    assert [i for i in rec.motion if i > marks["resume"]]  # the resume moves it again
    run_thread = {t for _, t in rec.calls}
    assert len(run_thread) == 1  # estop and clear reached the robot on the run thread


def test_presses_between_two_ticks_reach_the_robot_in_order() -> None:
    session, rec = recorded_sim()
    control = RunControl()

    def press_three() -> None:
        control.estop()
        control.clear_estop()
        control.estop()

    on_tick = script({50: press_three, 80: lambda: control.request_stop("enough")})
    run(session, CONFIG, control=control, on_tick=on_tick)
    assert [n for n in rec.names() if n in ("estop", "clear")] == ["estop", "clear", "estop"]
    assert rec.estopped  # the last press was a stop: the robot stays latched
    assert control.estopped


def test_a_clear_pressed_as_the_run_ends_still_reaches_the_robot() -> None:
    session, rec = recorded_sim()
    control = RunControl()

    def clear_and_stop() -> None:
        control.clear_estop()
        control.request_stop("enough")

    on_tick = script({20: control.estop, 40: clear_and_stop})
    run(session, CONFIG, control=control, on_tick=on_tick)
    assert [n for n in rec.names() if n in ("estop", "clear")] == ["estop", "clear"]
    assert not rec.estopped


def test_truth_only_from_a_robot_that_has_it() -> None:
    session = open_robot("sim://", CONFIG, RobotOptions())
    stop = RunControl()
    with_truth = run(session, CONFIG, control=stop,
                     on_tick=script({50: lambda: stop.request_stop("enough")}))
    assert with_truth.max_pitch_deg is not None and with_truth.final_offset_m is not None
    session, _rec = recorded_sim()  # the same simulation, behind a robot with no truth()
    stop = RunControl()
    without = run(session, CONFIG, control=stop,
                  on_tick=script({50: lambda: stop.request_stop("enough")}))
    assert without.max_pitch_deg is None and without.final_offset_m is None
    assert without.fell is False


class Reporting(Recorder):
    """A robot that reports its own events (ReportsEvents)."""

    sink: EventSink | None = None

    def attach_sink(self, sink: EventSink) -> None:
        self.sink = sink


def test_a_robot_that_reports_events_gets_the_runs_sink() -> None:
    session = open_robot("sim://", CONFIG, RobotOptions())
    robot = Reporting(session.robot)
    events: list[Event] = []
    stop = RunControl()
    run(RobotSession(robot, session.clock, session.url, True, session.sim), CONFIG,
        events.append, control=stop, on_tick=script({5: lambda: stop.request_stop("x")}))
    assert robot.sink is not None
    robot.sink(Event(0.0, EventKind.LINK, "link: +1 retries"))
    assert events[-1].message == "link: +1 retries"
