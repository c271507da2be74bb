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
from pathlib import Path
from typing import IO, Any

from stairbot.console.scene import SceneView, scene_from_sim, stairs_from_scenario
from stairbot.console.state import LiveState

from stairbot.config import RobotConfig
from stairbot.errors import InputError, StairbotError
from stairbot.events import Event, EventKind
from stairbot.hardware import Clock, MotorId, Robot, Snapshot, Speeds
from stairbot.robots import RobotOptions, RobotSession
from stairbot.scenario import Scenario, load_scenario

SPEEDS: dict[str, float | None] = {"1x": 1.0, "10x": 10.0, "max": None}
"""Simulation speeds the operator can pick: sim seconds per wall second."""

SCENE_PERIOD_S = 0.04  # wall seconds between pictures taken from the simulation
PHASE_PERIOD_S = 0.2  # wall seconds between copies of the controller's context
ZERO: dict[MotorId, float] = {m: 0.0 for m in MotorId}


class WatchedRobot:
    """A Robot that passes every call on under a lock, tells the live state what
    it read and sent, and obeys a latched emergency stop: while it is set every
    command becomes a stop of every motor."""

    def __init__(self, inner: Robot, state: LiveState, lock: threading.RLock,
                 scene: Callable[[], SceneView | None] | None = None,
                 wall: Callable[[], float] = time.monotonic) -> None:
        self.inner = inner
        self._state = state
        self._lock = lock
        self._scene = scene
        self._wall = wall
        self._last_scene = -1.0
        self._estop = threading.Event()
        self.estop_tick: int | None = None  # the tick count when the stop reached the robot
        self.ticks = 0

    @property
    def estopped(self) -> bool:
        return self._estop.is_set()

    def read(self) -> Snapshot:
        with self._lock:
            snap = self.inner.read()
            self.ticks += 1
            self._state.on_read(snap)
            self._maybe_scene()
        return snap

    def _maybe_scene(self, force: bool = False) -> None:
        now = self._wall()
        if self._scene is None or (not force and now - self._last_scene < SCENE_PERIOD_S):
            return
        self._last_scene = now
        scene = self._scene()
        if scene is not None:
            self._state.on_scene(scene)

    def refresh_scene(self) -> None:
        """Take a picture now (under the lock)."""
        with self._lock:
            self._maybe_scene(force=True)

    def command(self, speeds: Speeds) -> None:
        with self._lock:
            if self._estop.is_set():
                self.inner.stop_all()
                self._state.on_command(dict(ZERO))
            else:
                self.inner.command(speeds)
                self._state.on_command(dict(speeds))

    def stop_all(self) -> None:
        with self._lock:
            self.inner.stop_all()
            self._state.on_command(dict(ZERO))

    def estop(self) -> None:
        """Latch the stop and stop every motor now.  Safe from any thread: the
        flag alone makes the run thread's next command a stop, so even if the
        lock is busy for a moment no further motion is commanded."""
        self._estop.set()
        if self._lock.acquire(timeout=0.5):
            try:
                self.inner.stop_all()
                self.estop_tick = self.ticks
                self._state.on_command(dict(ZERO))
            finally:
                self._lock.release()

    def clear_estop(self) -> None:
        self._estop.clear()
        self.estop_tick = None

    def diagnostics(self) -> dict[str, object]:
        with self._lock:
            return self.inner.diagnostics()

    def close(self) -> None:
        with self._lock:
            self.inner.close()


class PacedClock:
    """The session's clock, advanced under the robot lock and, for a simulation,
    paced to ``scale`` simulated seconds per wall second (None: as fast as it goes)."""

    def __init__(self, inner: Clock, lock: threading.RLock,
                 wall: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.inner = inner
        self._lock = lock
        self._wall = wall
        self._sleep = sleep
        self._scale: float | None = None
        self._anchor: tuple[float, float] | None = None

    def set_scale(self, scale: float | None) -> None:
        self._scale = scale
        self._anchor = None

    def now(self) -> float:
        with self._lock:
            return self.inner.now()

    def advance(self, dt: float) -> None:
        with self._lock:
            self.inner.advance(dt)
            sim_now = self.inner.now()
        scale = self._scale
        if scale is None:
            return
        wall_now = self._wall()
        if self._anchor is None:
            self._anchor = (sim_now, wall_now)
            return
        due = self._anchor[1] + (sim_now - self._anchor[0]) / scale
        if due - wall_now > 0:
            self._sleep(due - wall_now)
        elif wall_now - due > 0.5:  # fell behind (a slow machine): do not race to catch up
            self._anchor = (sim_now, wall_now)


class Recorder:
    """Writes events as JSON lines (the format of ``stairbot run --record``)."""

    def __init__(self, path: str) -> None:
        self.path = path
        try:
            self._file: IO[str] = Path(path).open("w", encoding="utf-8")  # noqa: SIM115 - closed by close()
        except OSError as exc:
            raise InputError(path, None, f"cannot write: {exc.strerror or exc}") from None
        self._lock = threading.Lock()

    def write(self, event: Event) -> None:
        with self._lock:
            if not self._file.closed:
                self._file.write(event.to_json() + "\n")
                self._file.flush()

    def close(self) -> None:
        with self._lock:
            self._file.close()


def _default_open(url: str, config: RobotConfig, scenario: Scenario,
                  options: RobotOptions) -> RobotSession:
    from stairbot.robots import open_robot

    return open_robot(url, config, scenario, options)


def _default_run(session: RobotSession, config: RobotConfig, sink: Callable[[Event], None],
                 mode: str, control: Any, on_tick: Callable[[Any, Any], None]) -> Any:
    from stairbot.phases import Mode
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
    if result.get("ascent_end"):
        parts.append(str(result["ascent_end"]).replace("_", " "))
    parts.append(f"climbed {result.get('steps_climbed', 0)}, "
                 f"descended {result.get('steps_descended', 0)}")
    if result.get("error"):
        parts.append(str(result["error"]))
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
    def simulated(self) -> bool:
        return self.session is not None and self.session.simulated

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
        self.clock.set_scale(SPEEDS[self._speed] if session.simulated else None)
        stairs = stairs_from_scenario(scenario, self.config.LENGTH_OF_A_ROBOT)
        self.state.set_robot(url, scenario.name, session.simulated, stairs)
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

    def _on_tick(self, ctl: Any, _snap: Any) -> None:
        phase = getattr(ctl, "phase", None)
        now = self._wall()
        if phase is self._last_phase and now - self._last_ctx < PHASE_PERIOD_S:
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
        """Clear the latched stop; motion resumes only with :meth:`resume`."""
        if self.robot is None or not self.robot.estopped:
            return False
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
        if self.clock is not None and self.simulated:
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
