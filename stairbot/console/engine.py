"""The console's run: the program on a worker thread, on the robot the
console holds (:class:`~stairbot.console.robot_holder.RobotHolder`), and
the operator's controls reaching it safely.

The run thread owns the robot; the UI thread only ever calls
:meth:`ConsoleEngine.estop`, :meth:`pause` and friends, which set flags (and,
for the emergency stop, call the robot's own ``estop()`` directly, under the
same lock the run thread holds for each robot call, so the two never talk to
the robot at once).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypedDict

from stairbot.console import limp_gate
from stairbot.console.climb_gate import MidClimb, after_run
from stairbot.console.limp_gate import LimpOffer
from stairbot.console.robot_holder import (
    LATCH_HINT,
    NO_ROBOT_STOPPED,
    OpenFn,
    RobotHolder,
    default_open,
)
from stairbot.console.state import LiveState
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.lost import awaits_consent
from stairbot.control.algorithm.phases import Mode
from stairbot.errors import StairbotError
from stairbot.events import Event, EventKind, EventSink
from stairbot.hardware import Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.recording.record import RecordsTicks
from stairbot.run.journal import JournalWriter
from stairbot.run.journaled import ResumePlan, carry_on, plan_resume, session_journal, start_journal
from stairbot.run.resume import ResumeRefused
from stairbot.run.robots import RobotSession
from stairbot.run.runner import RunControl, RunResult

MID_CLIMB_HINT = ("the robot may stand part way up the stairs: a new run would drive it at "
                  "the riser; s offers resume (boards) or your word it is back at the start")

PHASE_PERIOD_S = 0.2  # wall seconds between copies of the controller's context

OnTick = Callable[[Controller, Snapshot], None]


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


def _default_run(session: RobotSession, config: RobotConfig, sink: EventSink,
                 mode: str, control: RunControl, on_tick: OnTick, plan: RunPlan) -> RunResult:
    from stairbot.run.runner import run

    return run(session, config, sink, _mode(mode), control, on_tick=on_tick,
               controller=plan.controller, journal=plan.journal)


def _mode(mode: str) -> Mode:
    return {"calibrate": Mode.CALIBRATE_ONLY, "descend": Mode.DESCEND}.get(mode, Mode.FULL)


def describe_result(result: RunResult, limped: tuple[str, ...] = ()) -> tuple[str, str]:
    """One line saying how a run ended, and its severity (good/warning/error);
    ``limped``: the sensors a limp home went without."""
    parts = [f"run {result.outcome}"]
    if result.error:  # first: on a narrow screen the end of the line is cut
        parts.append(result.error)
    if result.outcome == "came_home_degraded":
        lost = ", ".join(limped) or "a sensor"
        parts.append(f"back where it began WITHOUT {lost}: repair before the next run")
    if result.ascent_end:
        parts.append(result.ascent_end.replace("_", " "))
    parts.append(f"climbed {result.steps_climbed}, descended {result.steps_descended}")
    severity = {"completed": "good", "stopped": "warning",
                "came_home_degraded": "warning"}.get(result.outcome, "error")
    return " · ".join(parts), severity


class ConsoleEngine(RobotHolder):
    """Runs the program on the calling (worker) thread, on the robot the
    console holds, and takes the operator's controls from the UI thread."""

    def __init__(self, state: LiveState, config: RobotConfig, *,
                 open_fn: OpenFn = default_open,
                 run_fn: RunFn = _default_run,
                 control_fn: Callable[[], RunControl] = RunControl,
                 wall: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        super().__init__(state, config, open_fn=open_fn, wall=wall, sleep=sleep)
        self._run_fn, self._control_fn = run_fn, control_fn
        self.control: RunControl | None = None
        self._last_phase: object = None
        self._controller: Controller | None = None  # the run's, as the last tick saw it
        self._last_ctx = -1.0
        self._last_flow, self._last_label = "", ""  # the run's last phase before its end
        self._last_tick_s = 0.0  # the robot's clock at the run's last tick
        self.limp_refused = ""
        """Why the last run's degraded stop, which the robot could limp home
        from, cannot be carried on by this console ("": it can, or none)."""

    # -- the run (worker thread) -----------------------------------------------
    def run(self, mode: str = "full", resume: ResumePlan | None = None,
            limp: LimpOffer | None = None) -> RunResult | None:
        """Run the program until it ends; returns its result, or None when it
        could not run.  ``resume``: carry on the journal's run (checked by
        :meth:`plan_resume` and confirmed by the operator); ``limp``: carry
        on the program of a degraded stop, limping home (:meth:`limp_home`).
        Refused while the robot may stand mid-climb (:attr:`mid_climb`)
        unless resuming.  Never raises: failures end up in the live state."""
        if self.session is None or self.robot is None or self.clock is None:
            self.state.set_status(message="no robot open: choose a robot first (u)",
                                  severity="warning")
            return None
        if self.robot.estopped or self.latched:
            self.state.set_status(message=LATCH_HINT, severity="error")
            return None
        if self.mid_climb is not None and resume is None and limp is None:
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
            plan = self._plan(mode, resume, limp)
        except StairbotError as exc:
            self.state.set_status(message=f"not started: {exc}", severity="error")
            return None
        self.limp_offer = None
        self._running.set()
        session = RobotSession(self.robot, self.clock, self.session.url,
                               self.session.simulated, self.session.sim)
        self.state.on_result(None)
        began_s = self.clock.now()
        what = "limping home (consented)" if limp is not None else \
            "resumed from the journal" if resume is not None else (
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
        self.limp_refused = ""
        try:
            self.limp_offer = limp_gate.offer_after(
                result, self._controller, self.state.view().degraded, mode, self._last_tick_s,
                None if self.in_process else self.plan_resume)
        except StairbotError as exc:  # the journal's run does not check: no question
            self.limp_offer, self.limp_refused = None, str(exc)
            self.state.note(f"limp home cannot be offered: {exc}", "error")
        line, severity = describe_result(result, self.state.view().limping)
        stop = self.state.view().degraded
        if result.outcome == "error" and stop is not None and stop.time_s >= began_s:
            line = limp_gate.banner_line(stop, self.limp_offer is not None,  # this run's stop
                                         self.limp_refused)
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

    def _plan(self, mode: str, resume: ResumePlan | None, limp: LimpOffer | None) -> RunPlan:
        """The journal (boards on a wire: a fresh one, or the resumed run's)
        and the controller.  StairbotError when the journal cannot be written."""
        session, scenario = self.session, self.scenario
        if limp is not None and resume is None and self.clock is not None:
            # the simulation: its program carried on here, from where it stopped
            return RunPlan(controller=limp_gate.carried_on(
                limp, self.clock.now(), self.config, self._sink, _mode(limp.mode)))
        if session is None or self.in_process or scenario is None:
            return RunPlan()
        if resume is not None:
            # the resume's lines say a degraded stop resumes limping home: the
            # operator who confirms it consents to that (as `--resume` and y do)
            resumed = carry_on(resume, session, self.config, self._sink,
                               limp_home=awaits_consent(resume.context))
            return RunPlan(resumed.journal, resumed.controller)
        return RunPlan(start_journal(session_journal(session), session.url, session,
                                     self.config, scenario.name, _mode(mode)))

    def plan_resume(self) -> ResumePlan:
        """The journal's run, checked against the boards as ``stairbot run
        --resume`` checks it; its ``lines`` say where the robot believes it
        is.  Moves nothing.  ResumeRefused (or JournalError) says why not."""
        if self.session is None:
            raise ResumeRefused("no robot open")
        return plan_resume(session_journal(self.session), self.session.url, self.session,
                           self.config)

    def back_at_start(self) -> None:
        """The operator says the robot stands at the start again: a fresh run may go."""
        self.mid_climb = None
        self.state.note("the operator says the robot is back at the start", "warning")

    def limp_home(self) -> RunResult | None:
        """The operator consents: carry the program of the last run's degraded
        stop (:attr:`limp_offer`) on, limping home on the sensors that remain.
        The stop latched the robot's emergency stop; the consent clears it
        (boards: after the journal's checks), never one the operator set.
        Refused, with a message and nothing moved, when there is nothing to
        carry on, a run goes on, the operator's emergency stop is set, or the
        journal's run no longer checks.  Worker thread."""
        offer = self.limp_offer
        if offer is None or self.robot is None or self.running:
            self.state.set_status(message="no degraded stop to limp home from",
                                  severity="warning")
            return None
        if self.state.view().status.latch == "operator":
            self.state.set_status(message="not moved: the operator's emergency stop is set; "
                                  "c clears it (look at the robot), then l", severity="error")
            return None
        resume = None
        try:
            if not self.in_process:
                resume = self.plan_resume()
            if self.robot.estopped:
                self.robot.clear()
        except StairbotError as exc:
            self.state.set_status(message=f"not moved: {exc}", severity="error")
            return None
        self.state.set_status(estopped=False, latch="")
        self._say(Event(self._now(), EventKind.INFO, "limp home: the operator consents; the "
                        "degraded stop's emergency stop cleared"))
        return self.run(offer.mode, resume, limp=offer)

    def _on_tick(self, ctl: Controller, snap: Snapshot) -> None:
        self._controller = ctl
        self._last_tick_s = snap.time_s
        self._watch_phase(ctl)
        recorder, feed = self.recorder, self.live_feed()
        if self.robot is not None:
            if isinstance(recorder, RecordsTicks):
                recorder.tick(snap, self.robot.sent)
            if feed is not None:
                feed.tick(snap, self.robot.sent)

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
        robot = self.robot
        if robot is None:
            # nothing to stop: the console's latch alone, for any robot opened next
            self.state.set_status(estopped=True, paused=False, severity="error",
                                  message=NO_ROBOT_STOPPED, latch="operator")
            self._say(Event(self._now(), EventKind.WARNING, "emergency stop pressed with "
                            "no robot connected: nothing was stopped"
                            + (f" ({why})" if why else "")))
            return
        self.state.set_status(estopped=True, paused=self.running, severity="error",
                              message=LATCH_HINT, latch="operator")
        # The boards' estop() puts the stop on the wire at once, then waits for
        # their confirmation (a few ms; at most half a second, after which a
        # LINK event names the board that did not confirm).
        robot.estop()
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

