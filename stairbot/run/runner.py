"""The run loop: read the robot, tick the controller, command the motors, let
the clock advance; and the summary of a run.

The loop is the same for the simulation and for boards on a wire: the
session's clock decides whether time is simulated or waited for.  Operator
controls (stop, pause, emergency stop) come in through a thread-safe
:class:`RunControl`, so a console can run the loop on a worker thread.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any, Literal

from stairbot.clock import CountsLateTicks, HostBehind
from stairbot.control.algorithm.controller import Controller, phase_timeout_s
from stairbot.control.algorithm.lost import awaits_consent
from stairbot.control.algorithm.phases import Mode
from stairbot.errors import HardwareError, LinkLostError, OutputError, RobotFellError
from stairbot.events import Event, EventKind, EventSink, discard
from stairbot.hardware import (
    HasIdentity,
    HasTruth,
    ReportsEvents,
    Robot,
    Snapshot,
    Speeds,
    Truth,
)
from stairbot.inputs.config import RobotConfig
from stairbot.run.journal import JournalWriter
from stairbot.run.margins import Margins
from stairbot.run.robots import RobotSession

Latch = Literal["estop", "clear"]

TickTap = Callable[[Snapshot, Speeds | None], None]
"""Told after each tick: the snapshot read and the speeds sent to the robot
(None when the latched emergency stop kept them back)."""


class RunControl:
    """Operator requests to a running loop; every method is thread-safe.

    The emergency stop is latched: each press of :meth:`estop` becomes one
    ``robot.estop()`` on the run thread at the top of the next tick (the
    robot's own latch then keeps every motor stopped) and holds the
    controller.  :meth:`clear_estop` becomes one ``robot.clear()`` there, in
    the order the two were pressed; clearing alone never restarts motion --
    that takes :meth:`resume` as well."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._stop_reason: str | None = None
        self._estopped = False
        self._paused = False
        self._latches: deque[Latch] = deque()

    def request_stop(self, reason: str = "stopped by the operator") -> None:
        with self._lock:
            self._stop_reason = reason

    def estop(self) -> None:
        with self._lock:
            self._estopped = True
            self._paused = True
            self._latches.append("estop")

    def clear_estop(self) -> None:
        with self._lock:
            self._estopped = False
            self._latches.append("clear")

    def pause(self) -> None:
        with self._lock:
            self._paused = True

    def resume(self) -> None:
        with self._lock:
            if not self._estopped:
                self._paused = False

    def take_latches(self) -> list[Latch]:
        """The e-stops and clears pressed since the last call, oldest first
        (the run thread carries them out)."""
        if not self._latches:  # none pressed (every tick of a run): no lock to take
            return []
        with self._lock:
            out = list(self._latches)
            self._latches.clear()
            return out

    # One attribute read is atomic: the run thread asks these every tick, without the lock.
    @property
    def estopped(self) -> bool:
        return self._estopped

    @property
    def paused(self) -> bool:
        return self._paused

    @property
    def stop_reason(self) -> str | None:
        return self._stop_reason


@dataclass
class RunResult:
    """The summary of one run (``stairbot run --json`` prints ``to_dict()``)."""

    outcome: str  # completed | stopped | error | fell | came_home_degraded
    ascent_end: str | None
    steps_climbed: int
    steps_descended: int
    pauses: int
    error: str | None
    fell: bool
    max_pitch_deg: float | None
    final_offset_m: float | None
    sim_time_s: float
    wall_time_s: float
    realtime_factor: float | None
    tilt_watched: bool
    """Whether the supervisor watched the tilt (the config declares an IMU)."""
    fault: str | None = None
    """"link" when the run ended on a lost link, "hardware" on another
    failure the robot reported, "output" when the journal or the event
    record could not be written (a full disk); None otherwise."""
    reason: str | None = None
    """Why the program ended, whatever the outcome (the controller's words)."""
    clear_of_stairs_m: float | None = None
    """How far the robot's front face ended before the first riser (negative:
    on the stairs), where the robot can tell (a simulation): a descent from
    the top reached the floor."""
    wall_contact: str | None = None
    """The first wall (or riser) the robot's body touched, where the robot can
    tell (a simulation's top view: a landing's walls as it turns); None:
    none, or it cannot tell."""
    awaits_consent: bool = False
    """Whether the program ended on a degraded stop the robot could limp home
    from, had the operator consented (``--yes``): the front end says how to
    give the consent where it is given (a journal's resume on boards)."""
    host_behind: HostBehind | None = None
    """The ticks of the run that began more than one tick late, and the
    longest such lateness, on a clock that waits for real time (a loaded
    machine, a stalled host); None on a simulated clock, which cannot fall
    behind (``to_dict`` then leaves the key out)."""
    margins: Margins | None = None
    """How close the run came to failing (:class:`~stairbot.run.margins.Margins`)."""

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out.pop("host_behind")
        if self.host_behind is not None:
            out["host_behind"] = self.host_behind.to_dict()
        for key in ("max_pitch_deg", "final_offset_m", "sim_time_s", "wall_time_s",
                    "realtime_factor", "clear_of_stairs_m"):
            if isinstance(out[key], float):
                out[key] = round(out[key], 4)
        return out


_HOME = ("completed", "stopped", "came_home_degraded")
"""The outcomes that leave the robot where the program began (or, stopped,
where it was asked to stop): every other latches the emergency stop."""

def run(
    session: RobotSession,
    config: RobotConfig,
    sink: EventSink = discard,
    mode: Mode = Mode.FULL,
    control: RunControl | None = None,
    *,
    controller: Controller | None = None,
    max_sim_time_s: float | None = None,
    wall: Callable[[], float] = time.perf_counter,
    on_tick: Callable[[Controller, Snapshot], None] | None = None,
    journal: JournalWriter | None = None,
    tap: TickTap | None = None,
    limp_home: bool = False,
) -> RunResult:
    """Run the program on ``session`` until the controller finishes.

    Never raises for a robot failure: a HardwareError ends the run with outcome
    "error" (or "fell" for a RobotFellError) after every motor is stopped.  A
    run that ends otherwise than "completed" or "stopped" latches the robot's
    emergency stop (``robot.estop()``): boards keep it until cleared.
    ``on_tick(controller, snapshot)`` is called after each tick (for a console);
    ``tap(snapshot, sent)`` too, with the speeds sent (for a record).
    ``limp_home``: the operator's consent, given before the run, to limp home
    on the sensors that remain when one is lost on the stairs (a controller
    given as ``controller`` has its own).
    A run longer than ``max_sim_time_s`` of robot time ends with an error (by
    default an hour, or 60 phase timeouts for a robot whose slow motors make
    that longer).  Fell, pitch and offset in the result come from the robot's
    ``truth()`` (HasTruth; None for a robot without it).  ``journal`` (started
    by the caller) gets a durable record after every tick and the run's end; a
    journal (or a ``sink`` or ``tap`` writing the record) the disk refuses --
    an OutputError -- ends the run with an error, the robot stopped.
    """
    robot, clock = session.robot, session.clock
    ctl = controller or Controller(config, sink, mode, limp_home=limp_home)
    if max_sim_time_s is None:
        max_sim_time_s = max(3600.0, 60 * phase_timeout_s(config))
    if isinstance(robot, ReportsEvents):  # wired robots report link health as LINK events
        robot.attach_sink(sink)
    tick = config.algorithm.tick
    if isinstance(clock, CountsLateTicks):
        clock.begin_loop()
    t0, wall0 = clock.now(), wall()
    fell = False
    fault: str | None = None
    try:
        while not ctl.finished:
            if control is not None:
                _apply(control, ctl, robot)
                if ctl.finished:
                    break
            snap = robot.read()
            speeds = ctl.tick(snap)
            # An e-stop pressed during this tick is carried out now rather
            # than after one more command; while latched nothing is sent (the
            # robot's latch holds every motor, and boards would refuse it).
            sent: Speeds | None = None
            if control is None or not _latch(control, robot):
                robot.command(speeds)
                sent = speeds
            if tap is not None:
                tap(snap, sent)
            if journal is not None:
                _journal_tick(journal, ctl, robot, snap, speeds)
            if on_tick is not None:
                on_tick(ctl, snap)
            clock.advance(tick)
            if clock.now() - t0 > max_sim_time_s:
                ctl.abort(f"the run took longer than {max_sim_time_s:.0f} s", "error")
    except RobotFellError as exc:
        fell = True
        ctl.abort(f"robot fell: {exc}", "error")
    except LinkLostError as exc:  # the driver's message already says "link lost" and why
        fault = "link"
        ctl.abort(str(exc), "error")
    except HardwareError as exc:
        fault = "hardware"
        ctl.abort(f"hardware failure: {exc}", "error")
    except OutputError as exc:  # the journal or the event record: the disk refused a write
        fault = "output"
        ctl.abort(str(exc), "error")
    finally:
        if control is not None:  # presses the loop did not come round to
            with contextlib.suppress(HardwareError):  # a clear on a lost link
                _latch(control, robot)
        if fell or ctl.result.outcome not in _HOME:
            # An error -- a fall, a lost link, the supervisor, a phase's own
            # check, anything unforeseen -- latches the emergency stop: the
            # robot may stand part way up a step, and nothing moves it until
            # the operator clears the latch.
            robot.estop()
        robot.stop_all()
    wall_time = wall() - wall0
    sim_time = clock.now() - t0
    truth = _truth(robot)
    res = ctl.result
    fell = fell or (truth is not None and truth.fell)
    result = RunResult(
        outcome="fell" if fell else res.outcome,
        ascent_end=res.ascent_end,
        steps_climbed=res.steps_climbed,
        steps_descended=res.steps_descended,
        pauses=res.pauses,
        error=res.error,
        fell=fell,
        max_pitch_deg=truth.max_pitch_deg if truth is not None else None,
        final_offset_m=truth.offset_m if truth is not None else None,
        sim_time_s=sim_time,
        wall_time_s=wall_time,
        realtime_factor=(sim_time / wall_time) if session.simulated and wall_time > 0 else None,
        tilt_watched=ctl.config.safety.imu,
        fault=fault,
        reason=res.reason,
        clear_of_stairs_m=truth.clear_of_stairs_m if truth is not None else None,
        wall_contact=truth.wall_contact if truth is not None else None,
        awaits_consent=awaits_consent(ctl.context) and not fell,
        host_behind=clock.host_behind() if isinstance(clock, CountsLateTicks) else None,
        margins=Margins.of(truth, ctl.config, ctl.sensor_holds),
    )
    if journal is not None:
        with contextlib.suppress(OutputError):  # the result still stands
            # a lost link stopped the program, not the program itself: the
            # journal offers --resume once the wire is back; so does a degraded
            # stop the operator did not consent to limp home from (yet)
            journal.end(result.outcome, result.error, clock.now(),
                        resumable=(fault == "link" and not fell) or result.awaits_consent)
    sink(Event(clock.now(), EventKind.SUMMARY, _summary_line(result), None, result.to_dict()))
    return result


def board_identity(robot: Robot) -> dict[str, dict[str, int]] | None:
    """The boards' serial numbers and uptimes (a robot on a wire), else None."""
    return robot.identity() if isinstance(robot, HasIdentity) else None


def _journal_tick(journal: JournalWriter, ctl: Controller, robot: Robot, snap: Snapshot,
                  speeds: Speeds) -> None:
    journal.tick(time_s=snap.time_s, phase=ctl.context.phase, estopped=robot.estopped,
                 command={m.name: float(v) for m, v in speeds.items()},
                 boards=board_identity(robot), context=ctl.context.to_dict)


def _truth(robot: Robot) -> Truth | None:
    """The robot's truth if it has one it can tell now (a lost link cannot)."""
    if not isinstance(robot, HasTruth):
        return None
    try:
        return robot.truth()
    except HardwareError:
        return None


def _latch(control: RunControl, robot: Robot) -> bool:
    """Carry out the e-stops and clears pressed since the last call, in order;
    whether the e-stop is latched now."""
    for latch in control.take_latches():
        if latch == "estop":
            robot.estop()
        else:
            robot.clear()
    return control.estopped


def _apply(control: RunControl, ctl: Controller, robot: Robot) -> None:
    reason = control.stop_reason
    if reason is not None:
        _latch(control, robot)
        robot.stop_all()
        ctl.abort(reason, "stopped")
        return
    if _latch(control, robot):
        if not ctl.held:
            ctl.hold("emergency stop")
    elif control.paused:
        if not ctl.held:
            ctl.hold("paused by the operator")
    elif ctl.held:
        ctl.release()


def _summary_line(r: RunResult) -> str:
    parts = [f"run {r.outcome}"]
    if r.ascent_end:
        parts.append(f"ascent ended: {r.ascent_end}")
    parts.append(f"climbed {r.steps_climbed}, descended {r.steps_descended}")
    if r.pauses:
        parts.append(f"{r.pauses} pause(s)")
    if r.error:
        parts.append(f"error: {r.error}")
    if not r.tilt_watched:
        parts.append("tilt not watched (no IMU in the robot config)")
    return "; ".join(parts)
