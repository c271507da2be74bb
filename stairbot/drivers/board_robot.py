"""The host's side of the boards' protocol, whatever the wire.

:class:`BoardRobot` implements the Robot protocol on a link that carries the
messages of ``messages.py`` (the serial ``Link``; the CAN driver's
``CanLink``): ``read()`` is one ReadAll to each board (both in flight at
once), ``command()`` one SetWheelSpeeds + SetLiftSpeeds whose Ack is collected
on the next call, the handshake identifies the boards and sets their
watchdogs, a keepalive thread feeds them while the robot stands idle, and
link health goes into ``Snapshot.health``, ``diagnostics()`` and LINK events
(``attach_sink``).  A lost link raises LinkLostError.  :class:`LockstepClock`
steps fake boards' simulated world once per control tick.
"""

from __future__ import annotations

import contextlib
import functools
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Concatenate, ParamSpec, TypeVar

from stairbot.clock import WallClock
from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.drivers.link import Link, Pending
from stairbot.errors import HardwareError, LinkLostError, RobotFellError, RobotUrlError
from stairbot.events import Event, EventKind, EventSink, discard
from stairbot.hardware import MotorId, MotorState, SensorId, SensorReading, Snapshot, Truth
from stairbot.robots import RobotSession

EVENT_EVERY_S = 1.0  # at most one link-trouble event per second of robot time


P = ParamSpec("P")
R = TypeVar("R")
S = TypeVar("S", bound="BoardRobot")
T = TypeVar("T", m.MotorTelemetry, m.SensorTelemetry)
K = TypeVar("K", MotorId, SensorId)
V = TypeVar("V", MotorState, SensorReading)


def locked(method: Callable[Concatenate[S, P], R]) -> Callable[Concatenate[S, P], R]:
    """Run a BoardRobot method under the robot's lock: the keepalive thread
    and the control loop (or a console) share one link."""

    @functools.wraps(method)
    def wrapper(self: S, *args: P.args, **kwargs: P.kwargs) -> R:
        with self._lock:
            return method(self, *args, **kwargs)

    return wrapper


class LockstepClock:
    """The host's clock against lockstep fake boards: ``advance(dt)`` asks the
    motor board to step the world to the new time and waits until it has."""

    def __init__(self, robot: BoardRobot) -> None:
        self._robot = robot
        self._us = 0

    def now(self) -> float:
        return self._us / 1e6

    def advance(self, dt: float) -> None:
        self._us += round(dt * 1e6)
        self._robot.step_to(self._us)


class BoardRobot:
    """Both boards over one link (a serial Link, or the CAN driver's CanLink):
    see the module docstring."""

    PIPELINED_STEP = True
    WIRE = "link"  # what the boards hang on, for messages: "serial port", "CAN bus"

    def __init__(self, link: Link, url: str, watchdog_ms: int = 250,
                 lockstep: bool = False, sink: EventSink = discard,
                 time_scale: float = 1.0) -> None:
        self.link = link
        self.url = url
        self.lockstep = lockstep
        self.sink = sink
        self.clock: Any = None  # set by board_session
        self.idents: dict[int, m.Ident] = {}
        self.status: dict[int, m.Status] = {}
        self.refused = 0
        self._commands: list[Pending] = []
        self._step: Pending | None = None
        self._rate_mark = (time.monotonic(), 0)
        self._fps = 0.0
        self._reported: dict[str, float] = {}
        self._last_event = float("-inf")
        self._closed = False
        self._estopped = False
        self._link_lost = False
        self._last_tx: dict[int, float] = {}
        self.watchdog_ms = watchdog_ms  # in wall-clock ms
        # Fake boards paced at X times real time count the watchdog in their
        # simulated time: X times the wall time the host has to feed it.
        scale = 1.0 if lockstep else time_scale
        self.board_watchdog_ms = min(65535, round(watchdog_ms * scale))
        self._lock = threading.RLock()
        self._handshake()
        # A robot opened and left idle (a console before its run starts) must
        # not trip the boards' watchdogs: a daemon thread sends Heartbeats to
        # any board the host has not addressed for a quarter of the timeout.
        # Lockstep boards count simulated time, which stands still meanwhile.
        self._stop = threading.Event()
        self._keepalive: threading.Thread | None = None
        if watchdog_ms and not lockstep:
            self._keepalive = threading.Thread(target=self._keep_alive, daemon=True,
                                               name=f"{self.WIRE} robot keepalive")
            self._keepalive.start()

    # -- setting up ------------------------------------------------------------
    def _handshake(self) -> None:
        for board in m.Board:
            name = board.name.lower()
            try:
                reply = self.link.exchange(board, [m.Identify(), m.GetStatus()])
            except LinkLostError:
                raise RobotUrlError(self.url, None, f"no {name} board answered on the "
                                    f"{self.WIRE} ({self.link.retries + 1} tries of "
                                    f"{self.link.timeout_s * 1e3:.0f} ms)") from None
            ident, status = (reply.messages + (None, None))[:2]
            if not isinstance(ident, m.Ident) or not isinstance(status, m.Status):
                raise RobotUrlError(self.url, None, f"the {name} board gave an unexpected "
                                    f"answer to Identify: {reply.messages}")
            if ident.protocol_major != m.PROTOCOL_MAJOR:
                raise RobotUrlError(self.url, None, f"the {name} board speaks protocol "
                                    f"{ident.protocol_major}.{ident.protocol_minor}; "
                                    f"this host speaks {m.PROTOCOL_MAJOR}.x")
            board_lockstep = bool(status.flags & m.StatusFlag.LOCKSTEP)
            if board_lockstep != self.lockstep:
                hint = ("add ?lockstep=1 to the URL" if board_lockstep
                        else "start the fake boards with --lockstep")
                state = "run" if board_lockstep else "do not run"
                raise RobotUrlError(self.url, "lockstep",
                                    f"the boards {state} in lockstep; {hint}")
            self.idents[board] = ident
            # Opening the robot is the explicit clear of a watchdog latch left by
            # an earlier session; an emergency stop stays latched.  Setting up is
            # the one place where a command frame is sent again after a timeout.
            for attempt in range(self.link.retries + 1):
                try:
                    reply = self.link.exchange(board, [m.SetWatchdog(self.board_watchdog_ms),
                                                       m.Clear(m.ClearMask.WATCHDOG)])
                    break
                except LinkLostError:
                    if attempt == self.link.retries:
                        raise RobotUrlError(self.url, None, f"the {name} board did not "
                                            "answer SetWatchdog") from None
            status = reply.messages[-1]
            if isinstance(status, m.Status):
                self.status[board] = status
            self._last_tx[board] = time.monotonic()

    @property
    def simulated(self) -> bool:
        return any(s.flags & m.StatusFlag.SIMULATED for s in self.status.values())

    def attach_sink(self, sink: EventSink) -> None:
        """Send LINK events to ``sink`` from now on."""
        self.sink = sink

    def _now(self) -> float:
        return float(self.clock.now()) if self.clock is not None else 0.0

    # -- the Robot protocol ----------------------------------------------------
    @locked
    def read(self) -> Snapshot:
        """One ReadAll to each board.  Raises LinkLostError (no reply, or a
        board's watchdog tripped), RobotFellError (fake boards: the simulated
        robot fell) or HardwareError (e-stop latched on a board, bad reply)."""
        self._reap()
        pm = self.link.request(m.Board.MOTOR, [m.ReadAll()], send=False)
        ps = self.link.request(m.Board.SENSOR, [m.ReadAll()])
        step, self._step = self._step, None
        if step is None:
            fm, fs = self._wait([pm, ps])
        else:  # the boards stepped the world before they answered ReadAll
            done, fm, fs = self._wait([step, pm, ps])
            self._check_step(done)
        self._link_lost = False  # both boards answered: any earlier loss is over
        motors = self._read_all(m.Board.MOTOR, fm.messages, m.MotorTelemetry,
                                m.MOTOR_CHANNELS, u.state_from_wire)
        sensors = self._read_all(m.Board.SENSOR, fs.messages, m.SensorTelemetry,
                                 m.SENSOR_CHANNELS, u.reading_from_wire)
        health = self.health()
        self._maybe_event(health)
        return Snapshot(self._now(), sensors, motors, health)

    @locked
    def command(self, speeds: Mapping[MotorId, float]) -> None:
        """Send every motor's speed in one frame; its Ack is checked later."""
        self._reap()
        if self.link.lost_streak >= self.link.max_lost:
            self._lost(f"{self.link.lost_streak} commands in a row went unanswered")
        wheels, lifts = u.speeds_to_wire(speeds)
        # In lockstep the StepTo that follows every command carries it out in
        # the same write.
        self._commands.append(self._request(m.Board.MOTOR, [wheels, lifts],
                                            send=not self.lockstep))

    @locked
    def flush(self) -> None:
        """Wait for the Acks of every command still in flight (LinkLostError
        if one never comes)."""
        pending = [p for p in self._commands if not p.done]
        if pending:
            self._wait(pending)
        self._reap()

    @locked
    def stop_all(self) -> None:
        """Stop every motor (lifts hold); never raises."""
        with contextlib.suppress(Exception):
            self._wait([self._request(m.Board.MOTOR, [m.Stop(m.ALL_MOTORS_MASK)])])

    @locked
    def estop(self) -> None:
        """Latch the emergency stop on both boards."""
        self._estopped = True
        self._wait([self._request(b, [m.EStop()]) for b in m.Board])

    @locked
    def clear(self, mask: int = m.ClearMask.ALL) -> None:
        """Clear latches (e-stop, watchdog, faults) on both boards."""
        self._wait([self._request(b, [m.Clear(mask)]) for b in m.Board])
        if mask & m.ClearMask.ESTOP:
            self._estopped = False

    @property
    def estopped(self) -> bool:
        """True from estop() until a clear() of the e-stop latch."""
        return self._estopped

    @locked
    def step_to(self, time_us: int) -> None:
        """Lockstep: the world advances to ``time_us``.  With PIPELINED_STEP
        the StepDone is awaited by the next read() (the boards handle frames
        in order, so that read sees the stepped world): one round trip per
        tick instead of two.  Otherwise waits here."""
        if self._step is not None:
            self._check_step(self._wait([self._step])[0])
        # Pipelined, the StepTo waits in the output buffer with the speeds
        # before it, and the next read's requests carry all of them in one
        # write: a pty write costs a context switch, the dearest part of a tick.
        self._step = self._request(m.Board.MOTOR, [m.StepTo(time_us)],
                                   send=not self.PIPELINED_STEP)
        if not self.PIPELINED_STEP:
            step, self._step = self._step, None
            self._check_step(self._wait([step])[0])

    def _check_step(self, reply: Any) -> None:
        if not reply.messages or not isinstance(reply.messages[0], m.StepDone):
            raise HardwareError(f"the motor board refused StepTo: {reply.messages}")

    @locked
    def heartbeat(self) -> None:
        """Feed the watchdog of a board that was sent nothing for a quarter of
        its timeout (the control loop's own frames normally do this)."""
        if not self.watchdog_ms:
            return
        now = time.monotonic()
        for board in m.Board:
            if now - self._last_tx.get(board, 0.0) > self.watchdog_ms / 4000:
                self._commands.append(self._request(board, [m.Heartbeat()]))

    @locked
    def diagnostics(self) -> dict[str, object]:
        out: dict[str, object] = {"url": self.url, "lockstep": self.lockstep,
                                  "link": self.health(),
                                  "boards": {m.Board(b).name.lower(): vars_of(i)
                                             for b, i in self.idents.items()}}
        if self.simulated and not self._closed:
            with contextlib.suppress(Exception):
                truth = self.truth()
                out.update(fell=truth.fell, max_pitch_deg=truth.max_pitch_deg,
                           offset_m=truth.offset_m)
        return out

    @locked
    def truth(self) -> Truth:
        """What fake boards know of their simulated world (GetTruth): fell,
        the most it pitched, the offset from the start (no pitch now, no fall
        reason: the wire does not carry them).  HardwareError for boards that
        are not simulated, a closed robot or a lost link."""
        if not self.simulated or self._closed:
            raise HardwareError(f"{self.url}: only fake boards tell the truth of a "
                                "simulated world")
        (reply,) = self._wait([self._request(m.Board.MOTOR, [m.GetTruth()])])
        truth = reply.messages[0] if reply.messages else None
        if not isinstance(truth, m.Truth):
            raise HardwareError(f"the motor board answered GetTruth with {reply.messages}")
        return Truth(fell=bool(truth.flags & 1), fall_reason=None, pitch_deg=None,
                     max_pitch_deg=truth.max_pitch_cdeg / 100, offset_m=truth.offset_mm / 1000)

    def _keep_alive(self) -> None:
        period = self.watchdog_ms / 4000
        while not self._stop.wait(period):
            try:
                with self._lock:
                    if self._closed:
                        return
                    self.heartbeat()
                    self._reap()
            except Exception:  # noqa: BLE001 - link trouble shows on the next read()
                continue

    def close(self) -> None:
        self._stop.set()
        if self._keepalive is not None and self._keepalive is not threading.current_thread():
            self._keepalive.join(1.0)
        self._close()

    @locked
    def _close(self) -> None:
        if self._closed:
            return
        self.stop_all()
        self._closed = True
        self.link.close()

    def health(self) -> dict[str, float]:
        """The link's counters, RTT figures, ``rtt_ms`` (the latest round
        trip) and ``frames_per_s`` (frames both ways, over the last second or
        so of wall time)."""
        stats = self.link.stats
        h = stats.as_dict()
        h["refused"] = float(self.refused)
        h["rtt_ms"] = round(stats.rtt_s[-1] * 1e3, 3) if stats.rtt_s else 0.0
        now, frames = time.monotonic(), stats.frames_tx + stats.frames_rx
        t0, f0 = self._rate_mark
        if now - t0 >= 1.0:
            self._fps = (frames - f0) / (now - t0)
            self._rate_mark = (now, frames)
        h["frames_per_s"] = round(self._fps, 1)
        return h

    # -- internals ---------------------------------------------------------------
    def _request(self, board: int, msgs: list[m.Message], send: bool = True) -> Pending:
        self._last_tx[board] = time.monotonic()
        return self.link.request(board, msgs, send=send)

    def _wait(self, pendings: list[Pending]) -> list[Any]:
        try:
            return self.link.wait(pendings)
        except LinkLostError as exc:
            self._lost(str(exc))
            raise  # unreachable: _lost raises

    def _lost(self, reason: str, boards_stopped: bool = False) -> None:
        """Report the lost link (a LINK event, the first time only: the stop,
        truth and close that follow a loss would each report it again) and
        raise LinkLostError saying what became of the motors."""
        if not self._link_lost:
            self._link_lost = True
            self.sink(Event(self._now(), EventKind.LINK, f"link lost: {reason}", None,
                            self.health()))
        if boards_stopped:
            after = ""
        elif self.watchdog_ms:
            after = f"; the boards' watchdogs stop every motor within {self.watchdog_ms} ms"
        else:
            after = "; the boards' watchdogs are off (watchdog=0): motors may still run"
        raise LinkLostError(f"{self.url}: link lost: {reason}{after}")

    def _reap(self) -> None:
        self.link.poll()
        still = []
        for p in self._commands:
            if p.reply is not None:
                for msg in p.reply.messages:
                    if isinstance(msg, m.Ack) and msg.result != m.AckResult.OK:
                        self.refused += 1
            elif not p.failed:
                still.append(p)
        self._commands = still

    def _check_status(self, board: m.Board, status: m.Status) -> None:
        self.status[board] = status
        name = board.name.lower()
        if status.flags & m.StatusFlag.WATCHDOG:
            what = ": its motors are stopped until cleared" if board == m.Board.MOTOR else ""
            self._lost(f"the {name} board's watchdog tripped (nothing from the host for "
                       f"{status.watchdog_ms} ms){what}",
                       boards_stopped=board == m.Board.MOTOR)
        if status.fault == m.MotorFault.SIMULATION:
            truth = self.diagnostics()
            if truth.get("fell"):
                raise RobotFellError("the simulated robot fell (reported by the fake boards)")
            raise HardwareError(f"the {name} board's simulated world failed")
        if status.flags & m.StatusFlag.ESTOP:
            raise HardwareError(f"the {name} board has its emergency stop latched")

    def _read_all(self, board: m.Board, msgs: tuple[Any, ...], kind: type[T],
                  ids: Sequence[K], convert: Callable[[T], V]) -> dict[K, V]:
        """A ReadAll reply -- Status, then one ``kind`` telemetry per channel --
        as ``{ids[channel]: convert(telemetry)}``, after checking the Status.
        HardwareError when the reply is not that."""
        name = board.name.lower()
        if not msgs or not isinstance(msgs[0], m.Status):
            raise HardwareError(f"the {name} board answered ReadAll with {msgs!r}")
        self._check_status(board, msgs[0])
        out = {ids[t.channel]: convert(t) for t in msgs[1:]
               if isinstance(t, kind) and t.channel < len(ids)}
        if len(out) != len(ids):
            raise HardwareError(f"the {name} board's ReadAll reply lacks channels: {msgs!r}")
        return out

    def _maybe_event(self, health: dict[str, float]) -> None:
        keys = ("retries", "timeouts", "lost", "late", "stray", "crc_errors", "malformed",
                "refused")
        changed = {k: health[k] - self._reported.get(k, 0.0) for k in keys
                   if health[k] != self._reported.get(k, 0.0)}
        now = self._now()
        if changed and now - self._last_event >= EVENT_EVERY_S:
            self._last_event = now
            self._reported = dict(health)
            what = ", ".join(f"+{v:g} {k}" for k, v in changed.items())
            self.sink(Event(now, EventKind.LINK, f"link: {what} (rtt median "
                            f"{health['rtt_median_ms']:.2f} ms)", None, dict(health)))


def board_session(robot: BoardRobot, url: str, time_scale: float) -> RobotSession:
    """The session of an opened board robot: its lockstep clock, or the wall
    clock (sped up by ``time_scale`` when the fake boards run faster)."""
    clock: LockstepClock | WallClock
    if robot.lockstep:
        clock = LockstepClock(robot)
    else:
        clock = WallClock(monotonic=lambda: time.monotonic() * time_scale,
                          sleep=lambda s: time.sleep(s / time_scale))
    robot.clock = clock
    return RobotSession(robot=robot, clock=clock, url=url, simulated=robot.simulated, sim=None)


def vars_of(ident: m.Ident) -> dict[str, int]:
    return {"protocol": ident.protocol_major * 256 + ident.protocol_minor,
            "firmware": ident.firmware, "serial": ident.serial, "channels": ident.channels}
