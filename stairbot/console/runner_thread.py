"""The console's side of a run: the robot opened by URL, the run loop on a
worker thread, and the operator's controls reaching it safely.

The run thread owns the robot; the UI thread only ever calls
:meth:`ConsoleEngine.estop`, :meth:`pause` and friends, which set flags (and,
for the emergency stop, stop every motor directly, under the same lock the run
thread holds for each robot call, so the two never talk to the robot at once).
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from stairbot.config import RobotConfig
from stairbot.console.scene import SceneView, scene_from_sim, stairs_from_scenario
from stairbot.console.state import LiveState
from stairbot.console.watch import PacedClock, Recorder, WatchedRobot
from stairbot.errors import InputError, StairbotError
from stairbot.events import Event, EventKind
from stairbot.robots import RobotOptions, RobotSession
from stairbot.scenario import Scenario, load_scenario

SPEEDS: dict[str, float | None] = {"1x": 1.0, "10x": 10.0, "max": None}
"""Simulation speeds the operator can pick: sim seconds per wall second."""

PHASE_PERIOD_S = 0.2  # wall seconds between copies of the controller's context


def _default_open(url: str, config: RobotConfig, scenario: Scenario,
                  options: RobotOptions) -> RobotSession:
    from stairbot.robots import open_robot

    return open_robot(url, config, replace(options, world=scenario))


def _default_run(session: RobotSession, config: RobotConfig, sink: Callable[[Event], None],
                 mode: str, control: Any, on_tick: Callable[[Any, Any], None]) -> Any:
    from stairbot.algorithm.phases import Mode
    from stairbot.runner import run

    return run(session, config, sink, Mode.CALIBRATE_ONLY if mode == "calibrate" else Mode.FULL,
               control, on_tick=on_tick)


def _default_control() -> Any:
    from stairbot.runner import RunControl

    return RunControl()


def describe_result(result: dict[str, Any]) -> tuple[str, str]:
    """One line saying how a run ended, and its severity (good/warning/error)."""
    outcome = result.get("outcome", "?")
    parts = [f"run {outcome}"]
    if result.get("error"):  # first: on a narrow screen the end of the line is cut
        parts.append(str(result["error"]))
    if result.get("ascent_end"):
        parts.append(str(result["ascent_end"]).replace("_", " "))
    parts.append(f"climbed {result.get('steps_climbed', 0)}, "
                 f"descended {result.get('steps_descended', 0)}")
    severity = {"completed": "good", "stopped": "warning"}.get(str(outcome), "error")
    return " · ".join(parts), severity


class ConsoleEngine:
    """Opens robots, runs the program on the calling (worker) thread, and takes
    the operator's controls from the UI thread."""

    def __init__(self, state: LiveState, config: RobotConfig, *,
                 open_fn: Callable[..., RobotSession] = _default_open,
                 run_fn: Callable[..., Any] = _default_run,
                 control_fn: Callable[[], Any] = _default_control,
                 wall: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.state = state
        self.config = config
        self._open_fn, self._run_fn, self._control_fn = open_fn, run_fn, control_fn
        self._wall, self._sleep = wall, sleep
        self._lock = threading.RLock()
        self.session: RobotSession | None = None
        self.robot: WatchedRobot | None = None
        self.clock: PacedClock | None = None
        self.scenario: Scenario | None = None
        self.control: Any = None
        self.recorder: Recorder | None = None
        self._running = threading.Event()
        self._speed = "max"
        self._last_phase: object = None
        self._controller: Any = None  # the run's controller, as the last tick saw it
        self._last_ctx = -1.0

    # -- robot -----------------------------------------------------------------
    @property
    def robot_lock(self) -> threading.RLock:
        """Held around every call to the robot and the clock (take it to look at
        the simulation from another thread)."""
        return self._lock

    @property
    def running(self) -> bool:
        return self._running.is_set()

    @property
    def in_process(self) -> bool:
        """The simulation runs here (sim://): the console draws it and sets its speed."""
        return self.session is not None and self.session.sim is not None

    def open(self, url: str, scenario_path: str | None) -> None:
        """Open the robot at ``url`` on the scenario (None: the default stairs),
        closing the previous one.  Raises InputError (bad URL or scenario) or
        StairbotError (the robot cannot be opened); the old robot stays closed."""
        if self.running:
            raise InputError(url, None, "a run is going on; stop it first")
        scenario = load_scenario(scenario_path)
        self.close()
        self.state.set_status(robot="connecting", message=f"opening {url}", severity="info")
        session = self._open_fn(url, self.config, scenario, RobotOptions())
        self.session, self.scenario = session, scenario
        sim = session.sim
        scene_fn = None
        if session.simulated and sim is not None and hasattr(sim, "scene"):
            def scene_fn() -> SceneView | None:
                return scene_from_sim(sim.scene())
        attach = getattr(session.robot, "attach_sink", None)
        if callable(attach):  # a driver's LINK events go to the log and the record
            attach(self._sink)
        self.robot = WatchedRobot(session.robot, self.state, self._lock, scene_fn, self._wall)
        self.clock = PacedClock(session.clock, self._lock, self._wall, self._sleep)
        self.clock.set_scale(SPEEDS[self._speed] if sim is not None else None)
        stairs = stairs_from_scenario(scenario, self.config.LENGTH_OF_A_ROBOT)
        self.state.set_robot(url, scenario.name, session.simulated, stairs, wired=sim is None)
        try:
            self.robot.read()  # first readings and picture, before any motion
        except StairbotError as exc:
            self.state.set_status(robot="fault", message=f"cannot read the robot: {exc}",
                                  severity="error")
            return
        self.robot.refresh_scene()
        self.state.set_status(robot="ready", estopped=False, paused=False,
                              message="", severity="info")

    def close(self) -> None:
        """Stop and release the robot (never raises)."""
        if self.robot is not None:
            with contextlib.suppress(Exception):  # closing must not fail the console
                self.robot.close()
        self.session = self.robot = self.clock = None

    # -- the run (worker thread) -----------------------------------------------
    def run(self, mode: str = "full") -> dict[str, Any] | None:
        """Run the program until it ends; returns the result as a dict, or None
        when it could not run.  Never raises: failures end up in the live state."""
        if self.session is None or self.robot is None or self.clock is None:
            self.state.set_status(message="no robot open: choose a robot first (u)",
                                  severity="warning")
            return None
        if self.robot.estopped:
            self.state.set_status(message="emergency stop is set: clear it (c) first",
                                  severity="warning")
            return None
        if self._running.is_set():
            return None
        self._running.set()
        session = RobotSession(self.robot, self.clock, self.session.url,
                               self.session.simulated, self.session.sim)
        self.state.on_result({})
        self.state.set_status(robot="running", paused=False, severity="info",
                              message="calibrating only" if mode == "calibrate" else "full run")
        self._controller = None
        try:
            self.control = self._control_fn()
            result = self._run_fn(session, self.config, self._sink, mode, self.control,
                                  self._on_tick)
        except Exception as exc:  # noqa: BLE001 - a fault shows as a banner, not a traceback
            with contextlib.suppress(Exception):
                self.robot.stop_all()
            self.state.set_status(robot="fault", severity="error",
                                  message=f"the run failed: {type(exc).__name__}: {exc}")
            return None
        finally:
            self._running.clear()
        if self._controller is not None:  # a stop or a fault ends the run between ticks
            self._on_tick(self._controller, None, final=True)
        out: dict[str, Any] = result.to_dict() if hasattr(result, "to_dict") else dict(result)
        self.robot.refresh_scene()
        self.state.on_result(out)
        line, severity = describe_result(out)
        if self.robot.estopped:
            line += " · EMERGENCY STOP still set: c clears it"
        self.state.set_status(robot="ended", paused=False, message=line, severity=severity)
        return out

    def _sink(self, event: Event) -> None:
        self.state.on_event(event)
        if self.recorder is not None:
            self.recorder.write(event)

    def _on_tick(self, ctl: Any, snap: Any, final: bool = False) -> None:
        self._controller = ctl
        try:
            self._copy_phase(ctl, final)
        except Exception:  # noqa: BLE001 - watching must never stop the run
            self.state.on_phase("(phase not readable)", "", None)

    def _copy_phase(self, ctl: Any, force: bool = False) -> None:
        phase = getattr(ctl, "phase", None)
        now = self._wall()
        if not force and phase is self._last_phase and now - self._last_ctx < PHASE_PERIOD_S:
            return
        self._last_phase, self._last_ctx = phase, now
        label = str(getattr(phase, "label", phase))
        flow = str(getattr(phase, "flow", ""))
        context = getattr(ctl, "context", None)
        ctx = context.to_dict() if context is not None and hasattr(context, "to_dict") else None
        self.state.on_phase(label, flow, ctx)

    # -- operator controls (UI thread) -------------------------------------------
    def estop(self) -> None:
        """Stop every motor now and latch it until :meth:`clear_estop`."""
        if self.control is not None and self.running:
            self.control.estop()
        if self.robot is not None:
            self.robot.estop()
        self.state.set_status(estopped=True, paused=self.running, severity="error",
                              message="EMERGENCY STOP — every motor stopped; c clears it")
        self._sink(Event(self._now(), EventKind.WARNING, "emergency stop by the operator"))

    def clear_estop(self) -> bool:
        """Clear the latched stop; motion resumes only with :meth:`resume`.
        False when no stop was set (on the robot, or, with no robot open, on the
        banner)."""
        latched = self.robot is not None and self.robot.estopped
        if not latched and not self.state.view().status.estopped:
            return False
        if self.robot is not None:
            self.robot.clear_estop()
        if self.control is not None:
            self.control.clear_estop()
        msg = "emergency stop cleared; p resumes the run" if self.running else \
            "emergency stop cleared"
        self.state.set_status(estopped=False, severity="warning", message=msg)
        self._sink(Event(self._now(), EventKind.INFO, "emergency stop cleared by the operator"))
        return True

    def pause(self) -> None:
        if self.control is not None and self.running:
            self.control.pause()
            self.state.set_status(paused=True, message="paused by the operator",
                                  severity="warning")

    def resume(self) -> bool:
        """Resume a paused run; refused while the emergency stop is set."""
        if self.control is None or not self.running:
            return False
        if self.robot is not None and self.robot.estopped:
            self.state.set_status(message="clear the emergency stop (c) before resuming",
                                  severity="error")
            return False
        self.control.resume()
        self.state.set_status(paused=False, message="running", severity="info")
        return True

    def stop(self, reason: str = "stopped by the operator") -> None:
        if self.control is not None and self.running:
            self.control.request_stop(reason)

    def set_speed(self, speed: str) -> None:
        self._speed = speed
        if self.clock is not None and self.in_process:
            self.clock.set_scale(SPEEDS[speed])
        self.state.set_speed(speed)

    def start_recording(self, path: str) -> None:
        """Append every event from now on to ``path``.  Raises InputError."""
        self.stop_recording()
        self.recorder = Recorder(path)
        self.state.set_recording(path)

    def stop_recording(self) -> None:
        if self.recorder is not None:
            self.recorder.close()
            self.recorder = None
        self.state.set_recording(None)

    def shutdown(self, wait_s: float = 2.0) -> None:
        """Stop any run, wait a little for it to end, stop recording, release the robot."""
        self.stop("the console closed")
        deadline = self._wall() + wait_s
        while self.running and self._wall() < deadline:
            self._sleep(0.01)
        if self.robot is not None:
            self.robot.stop_all()
        self.stop_recording()
        self.close()

    def _now(self) -> float:
        snap = self.state.view().snapshot
        return snap.time_s if snap is not None else 0.0
