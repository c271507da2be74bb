"""The console's side of a run: the robot opened by URL, the run loop on a
worker thread, and the operator's controls reaching it safely.

The run thread owns the robot; the UI thread only ever calls
:meth:`ConsoleEngine.estop`, :meth:`pause` and friends, which set flags (and,
for the emergency stop, call the robot's own ``estop()`` directly, under the
same lock the run thread holds for each robot call, so the two never talk to
the robot at once).
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, TypedDict

from stairbot.console.climb_gate import MidClimb, after_run, from_journal
from stairbot.console.freshness import POLL_PERIOD_S
from stairbot.console.state import LiveState
from stairbot.console.watch import PacedClock, WatchedRobot, watch
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Mode
from stairbot.errors import InputError, LatchedError, OutputError, StairbotError
from stairbot.events import Event, EventKind, EventSink
from stairbot.hardware import HasScene, HasTruth, ReportsEvents, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario
from stairbot.recording.record import JsonLinesRecord, RecordsTicks, is_mcap
from stairbot.run.journal import JournalWriter
from stairbot.run.journaled import ResumePlan, carry_on, default_path, plan_resume, start_journal
from stairbot.run.paths import unused_path
from stairbot.run.resume import ResumeRefused
from stairbot.run.robots import RobotOptions, RobotSession
from stairbot.run.runner import RunControl, RunResult
from stairbot.views.side_view import SceneView, scene_view, stairs_from_scenario
from stairbot.views.top_view import TopPlan, TopPose, plan_of, top_pose

if TYPE_CHECKING:  # the Foxglove SDK loads only when an MCAP record starts
    from stairbot.recording.mcap_sink import McapRecord

LATCH_HINT = "EMERGENCY STOP latched — c clears it (after you look at the robot)"
MID_CLIMB_HINT = ("the robot may stand part way up the stairs: a new run would drive it at "
                  "the riser; s offers resume (boards) or your word it is back at the start")

SPEEDS: dict[str, float | None] = {"1x": 1.0, "10x": 10.0, "max": None}
"""Simulation speeds the operator can pick: sim seconds per wall second."""

PHASE_PERIOD_S = 0.2  # wall seconds between copies of the controller's context

OnTick = Callable[[Controller, Snapshot], None]
OpenFn = Callable[[str, RobotConfig, Scenario, RobotOptions], RobotSession]


@dataclass(frozen=True)
class RunPlan:
    """What a run starts from: the journal it writes (boards on a wire), and
    the controller of a resumed run (None: a fresh one)."""

    journal: JournalWriter | None = None
    controller: Controller | None = None


RunFn = Callable[[RobotSession, RobotConfig, EventSink, str, RunControl, OnTick, RunPlan],
                 RunResult]
"""(session, config, sink, mode, control, on_tick, plan) -> result: the run
loop, ``mode`` "full", "calibrate" or "descend" (a scenario that starts on
the top)."""


class EngineHooks(TypedDict, total=False):
    """What a test (or another front end) may put in place of the engine's
    defaults: how robots open, the run loop, its controls, the wall clock."""

    open_fn: OpenFn
    run_fn: RunFn
    control_fn: Callable[[], RunControl]
    wall: Callable[[], float]
    sleep: Callable[[float], None]


def _default_open(url: str, config: RobotConfig, scenario: Scenario,
                  options: RobotOptions) -> RobotSession:
    from stairbot.run.robots import open_robot

    return open_robot(url, config, replace(options, world=scenario))


def _default_run(session: RobotSession, config: RobotConfig, sink: EventSink,
                 mode: str, control: RunControl, on_tick: OnTick, plan: RunPlan) -> RunResult:
    from stairbot.run.runner import run

    return run(session, config, sink, _mode(mode), control, on_tick=on_tick,
               controller=plan.controller, journal=plan.journal)


def _mode(mode: str) -> Mode:
    return {"calibrate": Mode.CALIBRATE_ONLY, "descend": Mode.DESCEND}.get(mode, Mode.FULL)


def describe_result(result: RunResult) -> tuple[str, str]:
    """One line saying how a run ended, and its severity (good/warning/error)."""
    parts = [f"run {result.outcome}"]
    if result.error:  # first: on a narrow screen the end of the line is cut
        parts.append(result.error)
    if result.ascent_end:
        parts.append(result.ascent_end.replace("_", " "))
    parts.append(f"climbed {result.steps_climbed}, descended {result.steps_descended}")
    severity = {"completed": "good", "stopped": "warning"}.get(result.outcome, "error")
    return " · ".join(parts), severity


class ConsoleEngine:
    """Opens robots, runs the program on the calling (worker) thread, and takes
    the operator's controls from the UI thread."""

    def __init__(self, state: LiveState, config: RobotConfig, *,
                 open_fn: OpenFn = _default_open,
                 run_fn: RunFn = _default_run,
                 control_fn: Callable[[], RunControl] = RunControl,
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
        self.control: RunControl | None = None
        self.recorder: JsonLinesRecord | McapRecord | None = None
        self._running = threading.Event()
        self._speed = "max"
        self._last_phase: object = None
        self._controller: Controller | None = None  # the run's, as the last tick saw it
        self._last_ctx = -1.0
        self._poller: threading.Thread | None = None
        self._closing = threading.Event()
        self._poll_fault: str | None = None  # why the last idle read failed
        self._opening = False
        self.mid_climb: MidClimb | None = None
        """The robot may stand part way up (stairbot.console.climb_gate): no
        fresh start until the operator resumes or says it is back at the start."""
        self._last_flow, self._last_label = "", ""  # the run's last phase before its end
        self.latched_boards: tuple[str, str | None, str] | None = None
        """(url, scenario, why) of boards refused for the latch they hold."""

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

    @property
    def latched(self) -> bool:
        """The console's emergency stop latch: set by the operator or by a run
        that ended on an error; it outlives the robot (a reset, another URL)
        and only :meth:`clear_estop` clears it."""
        return self.state.view().status.estopped

    def open(self, url: str, scenario_path: str | None, *, clear_latches: bool = False) -> None:
        """Open the robot at ``url`` on the scenario (None: the default stairs),
        closing the previous one.  Opening never clears a latch: the
        console's own carries over to the new robot (its ``estop()`` is
        called at once), and boards that hold one are refused (LatchedError,
        naming ``c`` and ``stairbot clear``; :attr:`latched_boards` remembers
        them) -- unless ``clear_latches``: the operator pressed ``c`` and
        confirmed, and the boards' latches and the console's are cleared.
        Raises InputError (bad URL or scenario) or StairbotError (the robot
        cannot be opened); the old robot stays closed."""
        if self.running:
            raise InputError(url, None, "a run is going on; stop it first")
        scenario = load_scenario(scenario_path)
        self._opening = True
        try:
            self._open(url, scenario, scenario_path, clear_latches)
        finally:
            self._opening = False

    def _open(self, url: str, scenario: Scenario, scenario_path: str | None,
              clear_latches: bool) -> None:
        self.close()
        self._poll_fault = None
        self.state.set_status(robot="connecting", message=f"opening {url}", severity="info")
        try:
            session = self._open_fn(url, self.config, scenario,
                                    RobotOptions(allow_latched=clear_latches))
        except LatchedError as exc:
            message = f"{exc}; or press c here once you have looked at the robot"
            self.latched_boards = (url, scenario_path, message)
            raise LatchedError(message) from None
        self.latched_boards = None
        if clear_latches:
            try:
                session.robot.clear()  # the boards' latches, as `stairbot clear` does
            except BaseException:
                with contextlib.suppress(Exception):
                    session.close()
                raise
            self.state.set_status(estopped=False, latch="")
            self._sink(Event(self._now(), EventKind.INFO,
                             "latches cleared by the operator (confirmed)"))
        self.session, self.scenario = session, scenario
        sim = session.sim
        scene_fn: Callable[[], SceneView] | None = None
        if isinstance(sim, HasScene):
            def scene_fn() -> SceneView:
                return scene_view(sim.scene())
        # the top view: a simulation that tells its truth tells its pose seen from above
        top_fn: Callable[[], TopPose | None] | None = None
        plan: TopPlan | None = None
        if isinstance(sim, HasTruth):
            truthful = sim  # bound for the closure, narrowed

            def top_fn() -> TopPose | None:
                return top_pose(truthful.truth())
            plan = plan_of(scenario)
        if isinstance(session.robot, ReportsEvents):  # LINK events: the log and the record
            session.robot.attach_sink(self._sink)
        self.robot = watch(session.robot, self.state, self._lock, scene_fn, self._wall, top_fn)
        if self.latched:  # the latch outlives the robot it was pressed on
            self.robot.estop()
        self.clock = PacedClock(session.clock, self._lock, self._wall, self._sleep)
        self.clock.set_scale(SPEEDS[self._speed] if sim is not None else None)
        stairs = stairs_from_scenario(scenario, self.config.LENGTH_OF_A_ROBOT)
        self.state.set_robot(url, scenario.name, session.simulated, stairs, wired=sim is None,
                             plan=plan)
        self._recording_safely(self._watch_recording)
        try:
            self.robot.read()  # first readings and picture, before any motion
        except StairbotError as exc:
            self.state.set_status(robot="fault", message=f"cannot read the robot: {exc}",
                                  severity="error")
            return
        self.robot.refresh_scene()
        # boards: their journal says whether an earlier host left them mid-climb
        self.mid_climb = None if sim is not None else from_journal(
            default_path(url), self.robot.identity())
        latched = self.latched
        self.state.set_status(robot="ready", paused=False,
                              message=LATCH_HINT if latched else "",
                              severity="error" if latched else "info")

    # -- idle polling --------------------------------------------------------------
    def start_polling(self, period_s: float = POLL_PERIOD_S) -> None:
        """Read the robot every ``period_s`` while no run goes on (a daemon
        thread, until :meth:`shutdown`): its sensors and link stay live on
        the screen, and a link that dies while idle shows as a FAULT."""
        if self._poller is not None:
            return
        self._poller = threading.Thread(target=self._poll_loop, args=(period_s,),
                                        name="console idle poll", daemon=True)
        self._poller.start()

    def _poll_loop(self, period_s: float) -> None:
        while not self._closing.wait(period_s):
            self.poll()

    def poll(self) -> None:
        """One idle read (nothing while a run goes on: the run reads every
        tick).  A read that fails makes the state FAULT with the driver's
        reason, once; one that works again after that makes it READY."""
        robot = self.robot
        if robot is None or self.running or self._opening:
            return
        try:
            robot.read()
        except Exception as exc:  # noqa: BLE001 - a failing read is news, not a crash
            if self.running or robot is not self.robot:
                return  # a run or another robot took over meanwhile
            why = f"no reading from {self.state.view().url}: {exc}"
            if why != self._poll_fault:
                self._poll_fault = why
                self.state.set_status(robot="fault", severity="error", message=why)
                self.state.note(why, "error")
            return
        if self._poll_fault is not None and robot is self.robot and not self.running:
            self._poll_fault = None
            self.state.set_status(robot="ready", severity="warning",
                                  message="the robot answers again")
            self.state.note("the robot answers again", "warning")

    def close(self) -> None:
        """Stop and release the robot (never raises)."""
        if self.robot is not None:
            with contextlib.suppress(Exception):  # closing must not fail the console
                self.robot.close()
        self.session = self.robot = self.clock = None

    # -- the run (worker thread) -----------------------------------------------
    def run(self, mode: str = "full", resume: ResumePlan | None = None) -> RunResult | None:
        """Run the program until it ends; returns its result, or None when it
        could not run.  ``resume``: carry on the journal's run (checked by
        :meth:`plan_resume` and confirmed by the operator).  Refused while
        the robot may stand mid-climb (:attr:`mid_climb`) unless resuming.
        Never raises: failures end up in the live state."""
        if self.session is None or self.robot is None or self.clock is None:
            self.state.set_status(message="no robot open: choose a robot first (u)",
                                  severity="warning")
            return None
        if self.robot.estopped or self.latched:
            self.state.set_status(message=LATCH_HINT, severity="error")
            return None
        if self.mid_climb is not None and resume is None:
            self.state.set_status(message=MID_CLIMB_HINT, severity="error")
            return None
        if self._running.is_set():
            return None
        if self.scenario is not None and self.scenario.start.on == "top":
            if mode == "calibrate":
                self.state.set_status(message="not started: calibration squares up to a riser "
                                      "ahead; on the top of a flight there is none (s runs "
                                      "the descent)", severity="warning")
                return None
            mode = "descend"
        try:
            plan = self._plan(mode, resume)
        except StairbotError as exc:
            self.state.set_status(message=f"not started: {exc}", severity="error")
            return None
        self._running.set()
        session = RobotSession(self.robot, self.clock, self.session.url,
                               self.session.simulated, self.session.sim)
        self.state.on_result(None)
        what = "resumed from the journal" if resume is not None else (
            "calibrating only" if mode == "calibrate" else
            "descending from the top" if mode == "descend" else "full run")
        self.state.set_status(robot="running", paused=False, severity="info", message=what)
        self._controller = None
        self._last_flow, self._last_label = "", ""
        try:
            self.control = control = self._control_fn()
            result = self._run_fn(session, self.config, self._sink, mode, control,
                                  self._on_tick, plan)
        except Exception as exc:  # noqa: BLE001 - a fault shows as a banner, not a traceback
            with contextlib.suppress(Exception):
                self.robot.stop_all()
            self.state.set_status(robot="fault", severity="error",
                                  message=f"the run failed: {type(exc).__name__}: {exc}")
            self.mid_climb = MidClimb((f"the run failed: {exc}",))  # where it is, unknown
            return None
        finally:
            self._running.clear()
            if plan.journal is not None:
                plan.journal.close()
        if self._controller is not None:  # a stop or a fault ends the run between ticks
            self._watch_phase(self._controller, final=True)
        self.mid_climb = after_run(result, self._last_flow, self._last_label)
        self.robot.refresh_scene()
        self.state.on_result(result)
        line, severity = describe_result(result)
        if self.robot.estopped:
            line += " · EMERGENCY STOP latched: c clears it"
            if not self.latched:  # the run latched it (an error): the console holds it too
                why = result.error or line
                self.state.set_status(estopped=True, latch=f"automatic: {why}")
                # the record has the run's own ERROR event; the list says who latched
                self.state.note(f"emergency stop latched automatically: {why}", "warning")
        # A lost link or a failing board is a fault of the robot, not an ending:
        # its values stop being live, and the operator must look before a rerun.
        self.state.set_status(robot="fault" if result.fault else "ended", paused=False,
                              message=line, severity=severity)
        return result

    def _plan(self, mode: str, resume: ResumePlan | None) -> RunPlan:
        """The journal (boards on a wire: a fresh one, or the resumed run's)
        and the controller.  StairbotError when the journal cannot be written."""
        session, scenario = self.session, self.scenario
        if session is None or self.in_process or scenario is None:
            return RunPlan()
        if resume is not None:
            resumed = carry_on(resume, session, self.config, self._sink)
            return RunPlan(resumed.journal, resumed.controller)
        return RunPlan(start_journal(default_path(session.url), session.url, session,
                                     self.config, scenario.name, _mode(mode)))

    def plan_resume(self) -> ResumePlan:
        """The journal's run, checked against the boards as ``stairbot run
        --resume`` checks it; its ``lines`` say where the robot believes it
        is.  Moves nothing.  ResumeRefused (or JournalError) says why not."""
        if self.session is None:
            raise ResumeRefused("no robot open")
        return plan_resume(default_path(self.session.url), self.session.url, self.session,
                           self.config)

    def back_at_start(self) -> None:
        """The operator says the robot stands at the start again: a fresh run may go."""
        self.mid_climb = None
        self.state.note("the operator says the robot is back at the start", "warning")

    def _sink(self, event: Event) -> None:
        """The run's events (and the engine's own): the live state, the record.
        A record the disk refuses raises OutputError, which ends a run as it
        does ``stairbot run``'s."""
        self.state.on_event(event)
        if self.recorder is not None:
            self.recorder.write(event)

    def _say(self, event: Event) -> None:
        """An event from the UI thread: a refused record write stops the
        recording (and says so) rather than reach the key that pressed it."""
        self._recording_safely(lambda: self._sink(event))

    def _recording_safely(self, write: Callable[[], None]) -> None:
        try:
            write()
        except (OutputError, OSError) as exc:
            self.state.set_status(severity="error", message=f"recording stopped: {exc}")
            self.stop_recording()

    def _on_tick(self, ctl: Controller, snap: Snapshot) -> None:
        self._controller = ctl
        self._watch_phase(ctl)
        recorder = self.recorder
        if isinstance(recorder, RecordsTicks) and self.robot is not None:
            recorder.tick(snap, self.robot.sent)

    def _watch_recording(self) -> None:
        """Tell an MCAP record which robot its ticks come from (and where it
        stands: the simulation's pose, or a dead-reckoned one)."""
        recorder, session, scenario = self.recorder, self.session, self.scenario
        if isinstance(recorder, RecordsTicks) and session is not None and scenario is not None:
            from stairbot.recording.pose import pose_source

            recorder.watch(pose_source(session.sim, self.config, scenario), scenario,
                           session.url)

    def _watch_phase(self, ctl: Controller, final: bool = False) -> None:
        try:
            self._copy_phase(ctl, final)
        except Exception:  # noqa: BLE001 - watching must never stop the run
            self.state.on_phase("(phase not readable)", "", None)

    def _copy_phase(self, ctl: Controller, force: bool = False) -> None:
        phase = ctl.phase
        if ctl.flow != "end":  # where the run was before it ended: mid-climb or not
            self._last_flow, self._last_label = ctl.flow, phase.label
        now = self._wall()
        if not force and phase is self._last_phase and now - self._last_ctx < PHASE_PERIOD_S:
            return
        self._last_phase, self._last_ctx = phase, now
        self.state.on_phase(phase.label, ctl.flow, ctl.context.to_dict(), phase.value)

    # -- operator controls (UI thread) -------------------------------------------
    def estop(self, why: str = "") -> None:
        """Stop every motor now and latch it until :meth:`clear_estop`: the
        robot's own ``estop()``, from this thread at once (the run loop, told
        too, holds the program and does not repeat it).  ``why``: what the
        operator did (the key, "quit pressed mid-run"), for the event list.
        Safe from any thread."""
        self.state.set_status(estopped=True, paused=self.running, severity="error",
                              message=LATCH_HINT, latch="operator")
        if self.robot is not None:
            # The boards' estop() puts the stop on the wire at once, then waits
            # for their confirmation (a few ms; at most half a second, after
            # which a LINK event names the board that did not confirm).
            self.robot.estop()
        if self.control is not None and self.running:
            self.control.estop()
        self._say(Event(self._now(), EventKind.WARNING, "emergency stop by the operator"
                         + (f" ({why})" if why else "")))

    @property
    def estop_set(self) -> bool:
        """The console's latch or the robot's (what :meth:`clear_estop` clears)."""
        return self.latched or (self.robot is not None and self.robot.estopped)

    def clear_estop(self) -> bool:
        """Clear the latched stop (the robot's ``clear()``: on the run thread
        during a run); motion resumes only with :meth:`resume`.  False when no
        stop was set (on the robot, or, with no robot open, on the banner).
        A robot that cannot be cleared (a lost link) stays latched and says why."""
        latched = self.robot is not None and self.robot.estopped
        if not latched and not self.state.view().status.estopped:
            return False
        if self.control is not None and self.running:
            self.control.clear_estop()  # the run thread calls the robot's clear()
        elif self.robot is not None:
            try:
                self.robot.clear()
            except StairbotError as exc:
                self.state.set_status(severity="error", message=f"the emergency stop "
                                      f"could not be cleared: {exc}")
                return True
        msg = "emergency stop cleared; p resumes the run" if self.running else \
            "emergency stop cleared"
        self.state.set_status(estopped=False, severity="warning", message=msg, latch="")
        self._say(Event(self._now(), EventKind.INFO, "emergency stop cleared by the operator"))
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
        if self.control.estopped:
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

    def start_recording(self, path: str) -> str:
        """Record from now on to ``path``, or, when a file is there already,
        beside it under a name not taken (``name-1.jsonl``: a recording is
        never overwritten); returns the path written to.  A name ending .mcap
        records every tick and event as MCAP (as ``stairbot run --record
        FILE.mcap``), any other the events as JSON lines.  Raises InputError
        (the file cannot be opened, or an MCAP file's start cannot be
        written)."""
        self.stop_recording()
        try:
            chosen = unused_path(path)
        except FileExistsError as exc:
            raise InputError(path, None, f"cannot write the record: {exc}") from None
        if is_mcap(chosen):
            from stairbot.recording.mcap_sink import McapRecord

            try:
                self.recorder = McapRecord(chosen, self.config)
                self._watch_recording()
            except OutputError as exc:
                self.stop_recording()
                raise InputError(exc.path, None, f"cannot write {exc.what}: "
                                 f"{exc.problem}") from None
        else:
            self.recorder = JsonLinesRecord(chosen)  # whole lines; a full disk: OutputError
        self.state.set_recording(chosen)
        return chosen

    def stop_recording(self) -> None:
        """Stop recording (an MCAP file is finished: its summary written).
        Never raises: a file the disk refused to finish keeps what it had."""
        recorder, self.recorder = self.recorder, None
        if recorder is not None:
            try:
                recorder.close()
            except (OutputError, OSError) as exc:
                self.state.set_status(severity="error", message=f"recording stopped: {exc}")
        self.state.set_recording(None)

    def shutdown(self, wait_s: float = 2.0) -> None:
        """Stop any run, wait a little for it to end, stop recording, release the
        robot.  A console that closes mid-run (a browser tab closed, a hang-up:
        no quit dialog asked first) latches the e-stop first, as quitting mid-
        run does: the robot may stand part way up a step."""
        if self.running and not self.estop_set:
            self.estop("the console closed mid-run")
        self._closing.set()
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
