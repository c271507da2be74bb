"""The controller: the seed's algorithm advanced one tick at a time.

Each :meth:`Controller.tick` takes one :class:`~stairbot.hardware.Snapshot`
and returns a speed for all six motors.  Faults are checked before the
phase's own logic (a motor fault, a phase that takes too long, the
supervisor's tilt and stall), then a sensor the phase needs that reads as
ERROR (the robot stands and waits for it, up to SENSOR_WAIT_S), then the
standing rule, then -- once, before a lift phase's first step -- the
static-stability check (:mod:`~stairbot.control.algorithm.stability`), then the
phase's step.  Whichever decides returns a :class:`~stairbot.control.algorithm.phase.Step`; if it
says what happened, :meth:`Controller._apply` looks the outcome up in
:data:`~stairbot.control.algorithm.transitions.EXITS` and enters the phase it
leads to — the one place a phase is entered, at most once a tick — and tells
it as an event.  The clock is ``Snapshot.time_s`` alone; nothing here sleeps.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from stairbot.control.algorithm import bias, guards, limp, lost, motion, stability, standing
from stairbot.control.algorithm.context import Context, Pause, Watch
from stairbot.control.algorithm.families import Calibration, Family
from stairbot.control.algorithm.guards import (
    SENSOR_WAIT_S,
    check_restored,
    link_meanwhile,
    needed_sensors,
    phase_timeout_s,
)
from stairbot.control.algorithm.modes import Outcome, Purpose
from stairbot.control.algorithm.phase import PhaseDef, Step, Tick, fail, where
from stairbot.control.algorithm.phases import BY_VALUE, Mode, Phase
from stairbot.control.algorithm.result import ControllerResult
from stairbot.control.algorithm.texts import limp as say_limp
from stairbot.control.algorithm.transitions import exit_of
from stairbot.control.perception import Perception
from stairbot.control.supervisor import Supervisor
from stairbot.events import Event, EventKind, EventSink, discard
from stairbot.hardware import LIFT_MOTORS, MotorId, SensorId, Snapshot
from stairbot.inputs.config import RobotConfig


class Controller:
    """Runs the algorithm against snapshots of a robot.

    ``context`` restores a saved run (:meth:`Context.to_dict`); the snapshots
    must then come from the same clock.  ``hold``/``release``/``abort`` are
    for the operator and must be called from the thread that ticks.
    ``check_stability=False`` skips the static-stability check before the
    lifts (:mod:`stairbot.control.algorithm.stability`): only for a test that shows
    what the supervisor does without it.  ``limp_home``: the operator's
    consent, given before the run, to limp home on the sensors that remain
    when one is lost on the stairs (:mod:`~stairbot.control.algorithm.limp`).
    """

    def __init__(self, config: RobotConfig, sink: EventSink = discard,
                 mode: Mode = Mode.FULL, context: Context | None = None, *,
                 check_stability: bool = True, limp_home: bool = False) -> None:
        self.config = config
        self.mode = mode
        self.limp_home = limp_home
        self.check_stability = check_stability
        self._sink = sink
        if context is None:
            context = Context(number_of_vertical_turns=config.initial_number_of_vertical_turns,
                              family=Calibration(Purpose.START))
            if mode is Mode.DESCEND:  # on the top: no riser to square up to, the edge behind
                context.from_top = True
                context.family = None
                context.phase = Phase.DESCENT_BACK_TO_EDGE.value
        # a program reopened to limp home is said so at its first tick, on its time
        self._reopened = limp_home and context.phase_started_s is not None and lost.reopen(context)
        if context.phase_started_s is not None:
            check_restored(context)
        self._ctx = context
        self._started = context.phase_started_s is not None
        self._held: str | None = None
        self._held_since: float | None = None
        self.sensor_holds = 0
        """The sensor holds of this controller's ticks (a resumed program's start at 0)."""
        self._time = context.phase_started_s or 0.0
        m = config.motors
        self._vmax = {mo: m.lift_speed if mo in LIFT_MOTORS else m.wheel_speed for mo in MotorId}
        self._vmax_limp = {mo: v * limp.LIMP_SPEED for mo, v in self._vmax.items()}
        self._stroke = config.MAX_OF_VERTICAL_TURNS
        self._timeout = phase_timeout_s(config)
        self._perception = Perception(config)
        self._bias = bias.BiasWatch(config)
        self._supervisor = Supervisor(config)
        self._tilt = self._supervisor.tilt
        self._sensor_since: float | None = None
        self._sensor_link: dict[str, float] = {}  # the link's figures when the hold began
        self._phase_link: Mapping[str, float] = {}  # ... when the present phase began
        # what _present looked its answer up for: the phase, the pause, the lost
        self._now_phase, self._now_lost = "", 0
        self._now_pause: Pause | None = None
        self._now: tuple[Phase, PhaseDef[Any], tuple[SensorId, ...]] | None = None
        self._say_fn = self._say  # bound once: every tick's Tick carries it

    # -- what the outside sees --------------------------------------------------------
    @property
    def phase(self) -> Phase:
        return BY_VALUE[self._ctx.phase]

    @property
    def flow(self) -> str:
        """Where the program stands: the present phase's flow, or, while the
        standing rule waits, the flow of the phase it stopped in."""
        ctx = self._ctx
        if ctx.phase == Phase.PAUSED.value and ctx.pause is not None:
            return BY_VALUE[ctx.pause.resume_phase].flow
        return self.phase.flow

    @property
    def context(self) -> Context:
        return self._ctx

    @property
    def finished(self) -> bool:
        return _TERMINAL[self._ctx.phase]  # asked twice a tick: no Phase look-up

    @property
    def held(self) -> bool:
        return self._held is not None

    @property
    def result(self) -> ControllerResult:
        ctx = self._ctx
        return ControllerResult("running" if ctx.outcome is None else ctx.outcome.value,
                                None if ctx.ascent_end is None else ctx.ascent_end.value,
                                ctx.error,
                                ctx.number_of_steps, ctx.steps_descended, ctx.pauses,
                                ctx.end_reason)

    # -- operator ---------------------------------------------------------------------
    def hold(self, reason: str) -> None:
        """Stop every motor from the next tick on and freeze the timers, until
        :meth:`release`.  The phase carries on from where it was afterwards."""
        if self.finished or self._held is not None:
            return
        self._held = reason
        self._emit(EventKind.INFO, f"held: {reason}", self._time, {"held": True})

    def release(self) -> None:
        """Let a held controller go on where it was."""
        if self._held is None:
            return
        self._held = None
        self._emit(EventKind.INFO, "released: carrying on", self._time, {"held": False})

    def abort(self, reason: str, outcome: Outcome | str = Outcome.ERROR) -> None:
        """End the program now with ``outcome`` (ERROR or STOPPED, or its
        value); every later tick commands zero.  Outside the transition table
        on purpose: it is the operator's (or the run loop's) decision, not the
        algorithm's."""
        if outcome not in _OUTCOMES or Outcome(outcome) not in _ABORTS:
            raise ValueError(f"outcome {outcome!r}; allowed: "
                             f"{', '.join(o.value for o in _ABORTS)}")
        if self.finished:
            return
        ends = Outcome(outcome)
        self._finish(Phase.ERROR if ends is Outcome.ERROR else Phase.DONE, ends, reason,
                     self._time)

    # -- the tick ---------------------------------------------------------------------
    def tick(self, snap: Snapshot) -> dict[MotorId, float]:
        """Advance the program by one snapshot; returns a speed (turns/s) for
        every motor.  After the end, and while held, every speed is 0.  The
        first tick enters the program's first phase and moves nothing."""
        self._time = snap.time_s
        if _TERMINAL[self._ctx.phase]:  # self.finished, without the property's call
            return _zeros()
        snap = self._perception.see(snap)
        snap = self._bias.see(snap, self._ctx)  # a sensor judged biased reads as ERROR: lost
        if self._reopened:
            self._reopened = False
            self._emit(EventKind.RESUME, say_limp.REOPENED, snap.time_s,
                       {"limp": self._ctx.to_dict()["limp"]})
        if self._ctx.limp is not None:
            snap = limp.mirrored(snap, self._ctx.limp.lost)
        if self._held is not None:
            if self._held_since is None:
                self._held_since = snap.time_s
            self._supervisor.commanded({})
            return _zeros()
        if self._held_since is not None:
            self._shift_timers(snap.time_s - self._held_since)
            self._held_since = None
        if not self._started:
            self._started = True
            self._enter(self.phase, "program start", snap)
            tilt = self._supervisor.tilt
            self._say(tilt.describe(), tilt_watched=tilt.watched)
            return _zeros()
        ctx = self._ctx
        phase, record, needed = self._present()
        timeout = self._timeout if ctx.limp is None else self._timeout_now()
        fault = guards.fault(snap, phase, needed, ctx.phase_started_s, timeout) \
            or self._supervisor.check(snap)
        if fault is not None:  # and what the link lost in the phase, if it lost frames
            self._apply(fail(fault + link_meanwhile(self._phase_link, snap.health)), snap)
            return _zeros()
        if self._sensor_hold(snap, phase, needed):
            self._supervisor.commanded({})
            return _zeros()
        t = Tick(snap, self.config, ctx, self.mode, self._say_fn)
        step = standing.watch(t, record)
        if step is None and record.carried_by and not ctx.work.balanced \
                and self.check_stability:
            step = stability.before_lift(t, record, ctx.work)
        if step is None:
            assert record.step is not None  # only DONE and ERROR have none
            step = record.step(t, ctx.work)
        if step.wrong is not None:
            self._perception.distrust(*step.wrong)
        if step.happened is not None:
            self._apply(step, snap)
            speeds = _zeros()
        else:
            speeds = guards.limit_speeds(step.speeds, snap, self._vmax if ctx.limp is None
                                         else self._vmax_limp, self._stroke)
        self._supervisor.commanded(speeds)
        return speeds

    def _timeout_now(self) -> float:
        """How long the present phase may last (longer while limping home, slower)."""
        return self._timeout if self._ctx.limp is None else self._timeout / limp.LIMP_SPEED

    def _present(self) -> tuple[Phase, PhaseDef[Any], tuple[SensorId, ...]]:
        """The present phase, its record and :func:`guards.needed_sensors`, looked up
        again only when the phase, the pause (and so the phase it resumes) or the
        lost change."""
        ctx = self._ctx
        limp, now = ctx.limp, self._now
        lost = 0 if limp is None else len(limp.lost)
        if now is None or ctx.phase != self._now_phase or ctx.pause is not self._now_pause \
                or lost != self._now_lost:
            phase = BY_VALUE[ctx.phase]
            now = self._now = (phase, phase.record, needed_sensors(phase, ctx))
            self._now_phase, self._now_pause, self._now_lost = ctx.phase, ctx.pause, lost
        return now

    def _sensor_hold(self, snap: Snapshot, phase: Phase, needed: tuple[SensorId, ...]) -> bool:
        """While a sensor the phase needs (``needed``) reads as ERROR (errors, stale) or
        the IMU's reading is too old to watch tilt by (``TiltWatch.stale``): every motor
        stops, the lifts hold, the timers stand, up to SENSOR_WAIT_S; then every sensor
        in error, needed or not (``lost.every_error``), is lost.  True while holding."""
        ctx = self._ctx
        errors = motion.sensor_errors(snap, needed)
        imu = self._tilt.stale(snap)
        if not errors and imu is None:
            if self._sensor_since is not None:
                held = snap.time_s - self._sensor_since
                self._shift_timers(held)
                self._sensor_since = None
                self._emit(EventKind.RESUME, f"sensors back after {held:.2f} s: resuming "
                           f"{phase.label}", snap.time_s, {"phase": phase.value})
            return False
        errors = lost.every_error(ctx, snap, errors)  # the phase's, then any other in error
        why = "; ".join([f"{s} {self._bias.why(s, self._perception.why(s))}"
                         for s in errors] + ([imu] if imu is not None else []))
        # a sensor judged biased does not come back: no use waiting for it
        wait = 0.0 if imu is None and self._bias.all_judged(errors) else SENSOR_WAIT_S
        if self._sensor_since is None:
            self._sensor_since, self._sensor_link = snap.time_s, dict(snap.health)
            if wait > 0.0:
                ctx.pauses += 1
                self.sensor_holds += 1
                self._emit(EventKind.PAUSE, f"sensor hold: {why} in {phase.label}: all motors "
                           f"stopped, lifts holding, waiting up to {wait:g} s", snap.time_s,
                           {"resume_phase": phase.value, "sensors": list(errors),
                            "imu_stale": imu is not None})
                return True
        if snap.time_s - self._sensor_since < wait:
            return True
        since, self._sensor_since = self._sensor_since, None
        stale = link_meanwhile(self._sensor_link, snap.health,
                               "the readings were stale on the wire")
        stop = None if imu is not None else lost.degraded_stop(
            ctx, snap, phase, errors, why, mode=self.mode, consent=self.limp_home,
            tilt_watched=self._tilt.watched, biased=tuple(self._bias.judged))
        if stop is None:
            self._apply(fail(say_limp.lost_sensor_end(why, wait, phase.label) + stale), snap)
            return True
        self._emit(EventKind.WARNING, say_limp.stopped_at(  # (the phase a pause stopped in)
            why, BY_VALUE[stop.phase].label, stop.where, stop.lifts, stop.steps_climbed,
            stop.steps_descended) + ": " + stop.why, snap.time_s, {"degraded": stop.to_dict()})
        if stop.then == "no_consent":
            lost.start_limping(ctx, stop, snap.time_s, phase.label)
        if stop.then != "limp_home":
            self._apply(fail(say_limp.lost_sensor_end(why, wait, BY_VALUE[stop.phase].label,
                                                      stop.why) + stale), snap)
            return True
        lost.start_limping(ctx, stop, snap.time_s, phase.label)
        self._shift_timers(snap.time_s - since)
        self._emit(EventKind.RESUME, f"limping home: resuming {phase.label}", snap.time_s,
                   {"phase": phase.value, "limp": list(stop.lost)})
        return True  # from the next tick on the survivors stand in for the lost

    # -- phase changes: the one place a phase is entered ----------------------------------
    def _apply(self, step: Step, snap: Snapshot) -> None:
        """Enter the phase ``step.happened`` leads to from the present one;
        raises TransitionError when the present phase does not list that
        outcome (a bug in a phase)."""
        src, ctx = self.phase, self._ctx
        assert step.happened is not None
        exit_ = exit_of(src, step.happened)
        nxt = exit_.phase
        if nxt is Phase.ERROR:
            self._finish(Phase.ERROR, Outcome.ERROR, step.reason or "error", snap.time_s)
        elif nxt is Phase.DONE:
            outcome = step.outcome or Outcome.COMPLETED
            if outcome is Outcome.COMPLETED and ctx.limp is not None:
                outcome = Outcome.CAME_HOME_DEGRADED
            self._finish(Phase.DONE, outcome, step.reason or "done", snap.time_s)
        elif nxt is Phase.PAUSED:
            ctx.pause = Pause(src.value, snap.time_s)
            ctx.pauses += 1
            self._emit(EventKind.PAUSE, step.reason or "paused", snap.time_s,
                       {"resume_phase": ctx.pause.resume_phase})
            self._enter(nxt, exit_.when, snap, fresh=False)
        elif src is Phase.PAUSED:
            assert ctx.pause is not None
            if ctx.phase_started_s is not None:
                ctx.phase_started_s += snap.time_s - ctx.pause.started_s
            ctx.pause = None
            self._emit(EventKind.RESUME, step.reason or "resumed", snap.time_s,
                       {"phase": nxt.value})
            self._enter(nxt, exit_.when, snap, fresh=False)
        else:
            self._enter(nxt, step.reason or exit_.when, snap, begin=step.begin)

    def _enter(self, phase: Phase, why: str, snap: Snapshot, fresh: bool = True,
               begin: Family | None = None) -> None:
        """Make ``phase`` the present one.  ``fresh``: a new start of the phase
        (its timer, its work, its family's state if it enters the family
        (``begin``, or the family's defaults), its entry action); not fresh:
        the standing rule's wait, or the phase it resumes."""
        ctx = self._ctx
        previous = ctx.phase
        ctx.phase = phase.value
        ctx.watch = Watch()
        if fresh:
            record = phase.record
            ctx.phase_started_s = snap.time_s
            self._phase_link = dict(snap.health)
            ctx.work = record.work.at_entry(snap)
            if begin is not None:
                assert record.family is not None and isinstance(begin, record.family), begin
                ctx.family = begin
            elif record.family is None:
                ctx.family = None
            elif type(ctx.family) is not record.family:
                ctx.family = record.family()
        note = where(ctx, phase)
        where_text = f" ({note})" if note else ""
        resumed = "" if fresh or phase is Phase.PAUSED else " (resumed)"
        self._emit(EventKind.PHASE, f"{phase.label}{where_text}{resumed}", snap.time_s,
                   {"phase": phase.value, "flow": phase.flow, "from": previous, "why": why})
        if fresh:
            phase.record.enter(Tick(snap, self.config, ctx, self.mode, self._say), ctx.work)

    def _say(self, message: str, **data: Any) -> None:
        limping = self._ctx.limp
        if limping is not None and limping.consented:  # a pair's figures are one sensor's
            message += say_limp.stand_ins(limping.lost)
        self._emit(EventKind.INFO, message, self._time, data)

    def _finish(self, phase: Phase, outcome: Outcome, reason: str, time_s: float) -> None:
        ctx = self._ctx
        previous = ctx.phase
        ctx.outcome = outcome
        ctx.end_reason = reason
        ctx.phase = phase.value
        if outcome is Outcome.ERROR:
            ctx.error = reason
            self._emit(EventKind.ERROR, reason, time_s, {"from": previous})
        self._emit(EventKind.PHASE, phase.label, time_s,
                   {"phase": phase.value, "flow": phase.flow, "from": previous, "why": reason})
        self._emit(EventKind.END, f"program ended ({outcome.value}): {reason}", time_s,
                   self.result.to_dict())

    def _shift_timers(self, delta: float) -> None:
        ctx = self._ctx
        if ctx.phase_started_s is not None:
            ctx.phase_started_s += delta
        if ctx.pause is not None:
            ctx.pause.started_s += delta

    def _emit(self, kind: EventKind, message: str, time_s: float,
              data: dict[str, Any]) -> None:
        phase = self.phase.label
        self._sink(Event(time_s, kind, message, phase, data))


_OUTCOMES = (*Outcome, *(o.value for o in Outcome))
_ABORTS = (Outcome.COMPLETED, Outcome.STOPPED, Outcome.ERROR)
"""What :meth:`Controller.abort` may end a program with (not CAME_HOME_DEGRADED:
only a limp home that reaches the start ends so)."""
ALL_MOTORS: tuple[MotorId, ...] = tuple(MotorId)
_ZEROS: dict[MotorId, float] = dict.fromkeys(ALL_MOTORS, 0.0)
_TERMINAL: dict[str, bool] = {p.value: p.terminal for p in Phase}


def _zeros() -> dict[MotorId, float]:
    return _ZEROS.copy()

