"""The host's side of the boards' protocol, whatever the wire.

:class:`BoardRobot` implements the Robot protocol on a
:class:`~stairbot.drivers.link.BoardLink` (the serial link, the CAN link):
``read()`` is one ReadAll to each board (both in flight at once; the replies
become the snapshot in ``telemetry.py``: the four base sensors, and the side
pair SSR/SSL on a robot whose config has one), ``command()``
one SetWheelSpeeds + SetLiftSpeeds whose Ack is collected on the next call,
the handshake identifies the boards, takes their leases (one host owns the
robot: docs/protocol.md, section 3) and sets their watchdogs, a keepalive
thread feeds them and renews the leases while the robot stands idle, and link health goes into
``Snapshot.health``, ``diagnostics()`` and LINK events (``attach_sink``).  A
lost link raises LinkLostError; a board that never answers while opening,
NoBoardError.

Fake boards in lockstep are a simulation, not a robot on a wire: their clock,
StepTo, truth and falls belong to the fakes, which register their robot
with :mod:`stairbot.drivers.board_session` (the drivers never import them).
"""

from __future__ import annotations

import contextlib
import functools
import secrets
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any, Concatenate, Final, ParamSpec, TypeVar

from stairbot.clock import WallClock
from stairbot.drivers import messages as m
from stairbot.drivers import telemetry
from stairbot.drivers import units as u
from stairbot.drivers.handshake import LATCHES, open_board, release_board
from stairbot.drivers.health import HealthReport
from stairbot.drivers.link import BoardLink, BusFaultError, Reply, Request
from stairbot.drivers.telemetry import K, T, V
from stairbot.errors import BoardMismatchError, BoardOwnedError, HardwareError, LinkLostError
from stairbot.events import Event, EventKind, EventSink, discard
from stairbot.hardware import Clock, Imu, SensorId, SensorReading, Snapshot, Speeds

# The emergency stop (docs/protocol.md, "Emergency stop"): each press puts
# ESTOP_COPIES EStop frames to each board on the wire at once, sends the
# unanswered ones again every ESTOP_RESEND_S, and gives up on a board that has
# not confirmed within ESTOP_CONFIRM_S (a LINK event says so).
# A speed command keeps its motors running for at most COMMAND_HOLD_MS of
# wall time (scaled like the watchdog) without a newer one: a host that falls
# silent mid-drive has its motors stopped after that, well before its
# watchdog latches (docs/protocol.md, "Command hold").  Five control ticks:
# a lost command frame or two is ridden out.
COMMAND_HOLD_MS = 100
ESTOP_COPIES = 3
ESTOP_RESEND_S = 0.02
ESTOP_CONFIRM_S = 0.5

P = ParamSpec("P")
R = TypeVar("R")
S = TypeVar("S", bound="BoardRobot")


def locked(method: Callable[Concatenate[S, P], R]) -> Callable[Concatenate[S, P], R]:
    """Run a BoardRobot method under the robot's lock: the keepalive thread
    and the control loop (or a console) share one link."""

    @functools.wraps(method)
    def wrapper(self: S, *args: P.args, **kwargs: P.kwargs) -> R:
        with self._lock:
            return method(self, *args, **kwargs)

    return wrapper


class BoardRobot:
    """Both boards over one link: see the module docstring.

    ``watchdog_ms`` is the boards' watchdog in ms of the robot's clock (0:
    off): wall time, or for boards paced at ``time_scale`` times real time,
    simulated time, which they count it in; the robot's clock (a WallClock
    unless ``clock`` is given) runs as fast, and the keepalive that many
    times more often.
    ``monotonic`` is the wall clock the keepalive goes by.  ``side_pair``
    names where the robot config gives the robot the side pair (SSR, SSL;
    ``wanted_side_pair``), None when it has none: the sensor board must then
    have it (BoardMismatchError when opening), and every snapshot carries six
    readings; otherwise four, whatever the board sends."""

    LOCKSTEP = False  # what the boards' LOCKSTEP flag must say (the lockstep robot: True)
    estop_any_thread: Final = True  # estop() does not wait for the lock (EstopsFromAnyThread)
    HOLD_COMMANDS = False  # True: commands wait for the next frame sent (a StepTo)

    def __init__(self, link: BoardLink, url: str, watchdog_ms: int = 250, *,
                 time_scale: float = 1.0, clock: Clock | None = None,
                 sink: EventSink = discard, keepalive: bool = True,
                 monotonic: Callable[[], float] = time.monotonic,
                 allow_latched: bool = False, side_pair: str | None = None) -> None:
        self.link = link
        self.url = url
        self.side_pair = side_pair
        self.sink = sink
        self.clock: Clock = clock or WallClock(
            monotonic=lambda: monotonic() * time_scale, sleep=lambda s: time.sleep(s / time_scale))
        self.idents: dict[int, m.Ident] = {}
        self.status: dict[int, m.Status] = {}
        self.boots: dict[int, int] = {}  # board -> boot id (its Owner reply)
        self.nonce = secrets.randbits(32)  # tells this host's leases from another's
        self._time_scale = time_scale
        self.imu_read = telemetry.ImuRead(None, "unknown")  # the IMU as last read
        self.imu_rejected = 0  # replies whose IMU broke the protocol
        self.report = HealthReport(link.stats, monotonic)
        self._monotonic = monotonic
        self._commands: list[Request] = []
        self._closed = False
        self._estopped = False
        self._link_lost = False
        self._last_tx: dict[int, float] = {}
        self.watchdog_ms = watchdog_ms  # in ms of the robot's clock
        # Fake boards paced at X times real time count it, the lease and the
        # command hold in simulated time: the host has 1/X of each in wall
        # time (timing.py).
        self.board_watchdog_ms = watchdog_ms
        self.board_hold_ms = COMMAND_HOLD_MS
        self.lease_ms = m.LEASE_MS  # in ms of the robot's clock, as the watchdog
        self._lock = threading.RLock()
        self.latched: dict[int, int] = {}  # board -> latch flags found when opening
        try:
            self._handshake(allow_latched)
        except BaseException:
            for board in self.boots:  # the leases taken so far
                release_board(self.link, m.Board(board), self.nonce)
            raise
        # A robot opened and left idle (a console before its run starts) must
        # neither trip the boards' watchdogs nor let its leases lapse: a daemon
        # thread sends Heartbeats to any board the host has not addressed for
        # a quarter of the shorter of the two.
        self._stop = threading.Event()
        self._keepalive: threading.Thread | None = None
        if keepalive:
            self._keepalive = threading.Thread(target=self._keep_alive, daemon=True,
                                               name=f"{link.wire} robot keepalive")
            self._keepalive.start()

    # -- setting up ------------------------------------------------------------
    def _handshake(self, allow_latched: bool) -> None:
        for board in m.Board:
            self.idents[board], status, owner = open_board(
                self.link, self.url, board, lockstep=self.LOCKSTEP,
                watchdog_ms=self.board_watchdog_ms, hold_ms=self.board_hold_ms,
                nonce=self.nonce,
                lease_ms=self.board_lease_ms, wait_s=self._wait_board_s,
                allow_latched=allow_latched, side_pair=self.side_pair)
            self.boots[board] = owner.boot
            if status is not None:
                self.status[board] = status
                if status.flags & LATCHES:
                    self.latched[board] = status.flags & LATCHES
                if status.flags & m.StatusFlag.ESTOP:
                    self._estopped = True  # this host holds the latch it found
            self._last_tx[board] = self._monotonic()

    @property
    def board_lease_ms(self) -> int:
        """The lease asked of the boards, in their ms (the robot's, as the watchdog)."""
        return self.lease_ms

    def _wait_board_s(self, seconds: float) -> None:
        """Sleep ``seconds`` of the boards' clock."""
        time.sleep(seconds / self._time_scale)

    @property
    def feed_s(self) -> float:
        """How often, in wall seconds, a board must hear from this host to
        keep both its watchdog fed and its lease: a quarter of the shorter."""
        return min(self.watchdog_ms or self.lease_ms, self.lease_ms) / 4000 / self._time_scale

    def identity(self) -> dict[str, dict[str, int]]:
        """Each board's serial number, uptime (ms, from its last Status) and
        boot id (drawn by the board at power-up): what a journal keeps, and
        what tells a resumed run whether these are the same boards, still
        running since (their counters still valid)."""
        return {m.Board(b).name.lower(): {
                    "serial": ident.serial,
                    "uptime_ms": self.status[b].uptime_ms if b in self.status else -1,
                    "boot": self.boots.get(b, 0)}
                for b, ident in self.idents.items()}

    @property
    def simulated(self) -> bool:
        """Whether the boards say they are fake (StatusFlag.SIMULATED)."""
        return any(s.flags & m.StatusFlag.SIMULATED for s in self.status.values())

    def attach_sink(self, sink: EventSink) -> None:
        """Send LINK events to ``sink`` from now on."""
        self.sink = sink

    # -- the Robot protocol ----------------------------------------------------
    @locked
    def read(self) -> Snapshot:
        """One ReadAll to each board.  Raises LinkLostError (no reply, or a
        board's watchdog tripped) or HardwareError (an e-stop a board latched
        on its own, a failed world behind fake boards, a bad reply).  While
        this host's own e-stop is latched, reading goes on.

        A reading's age is the board's plus the robot-clock time from sending
        the ReadAll to the snapshot (the board answered within it): never
        younger than the truth, exact when the clock stands still (lockstep).
        An IMU whose values the protocol does not allow reads as None."""
        self._reap()
        sent = self.clock.now()
        pm = self._request(m.Board.MOTOR, [m.ReadAll()], send=False)
        ps = self._request(m.Board.SENSOR, [m.ReadAll()])
        fm, fs = self._collect([pm, ps])
        self._link_lost = False  # both boards answered: any earlier loss is over
        now = self.clock.now()
        transit = max(0.0, now - sent)
        motors = self._read_all(m.Board.MOTOR, fm.messages, m.MotorTelemetry,
                                m.MOTOR_CHANNELS, u.state_from_wire)
        sensors = self._read_sensors(fs.messages, transit)
        imu = self._read_imu(fs.messages, transit, now)
        health = self.health()
        self.report.maybe_event(health, now, self.sink)
        return Snapshot(now, sensors, motors, health, imu)

    def _collect(self, reads: list[Request]) -> list[Reply]:
        """The replies to a read's ReadAlls (fakes.lockstep adds its StepTo)."""
        return self._wait(reads)

    @locked
    def attitude(self) -> Imu | None:
        """The sensor board's IMU now (one ReadAll to it), read whatever the
        boards' latches: ``read()`` stops at a tripped watchdog, and a resume
        must know whether the robot tipped while no host watched it."""
        sent = self.clock.now()
        (reply,) = self._wait([self._request(m.Board.SENSOR, [m.ReadAll()])])
        return telemetry.imu_of(reply.messages, max(0.0, self.clock.now() - sent)).imu

    @locked
    def command(self, speeds: Speeds) -> None:
        """Send every motor's speed in one frame; its Ack is checked later.
        While the e-stop is latched every speed sent is 0."""
        self._reap()
        reason = self.link.commands_lost()
        if reason is not None:
            self._lost(reason)
        wheels, lifts = u.speeds_to_wire({} if self._estopped else speeds)
        self._commands.append(self._request(m.Board.MOTOR, [wheels, lifts],
                                            send=not self.HOLD_COMMANDS))

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
        if self._closed:
            return
        with contextlib.suppress(Exception):
            self._wait([self._request(m.Board.MOTOR, [m.Stop(m.ALL_MOTORS_MASK)])])

    def estop(self) -> None:
        """Latch the emergency stop: here at once (``command`` sends only
        zeros from now on), and on both boards.  Callable from any thread, it
        does not wait for the robot's lock: ESTOP_COPIES EStop frames to each
        board (broadcast frames on CAN) go on the wire at once, between the
        retries of a read in progress; the unanswered ones are sent again
        every ESTOP_RESEND_S until each board has confirmed (its Status), for
        at most ESTOP_CONFIRM_S.  Never raises: a board that does not confirm
        is a LINK event naming it."""
        self._estopped = True
        if self._closed:
            return
        t0 = self._monotonic()
        try:
            reqs = self.link.urgent(m.EStop(), copies=ESTOP_COPIES)
        except Exception as exc:  # noqa: BLE001 - the Robot protocol: estop never raises
            self._estop_unconfirmed(list(m.Board), f"cannot send it: {exc}")
            return
        sent = t0
        while True:
            waiting = {r.board for r in reqs} - {r.board for r in reqs if r.reply is not None}
            if not waiting:
                break
            now = self._monotonic()
            if now - t0 >= ESTOP_CONFIRM_S:
                self.link.forget(reqs)
                self._estop_unconfirmed(sorted(m.Board(b) for b in waiting),
                                        f"no Status within {ESTOP_CONFIRM_S * 1e3:.0f} ms of "
                                        f"{sum(r.attempts for r in reqs)} EStop frames")
                return
            if now - sent >= ESTOP_RESEND_S:
                sent = now
                # a write that fails: keep trying till the end
                with contextlib.suppress(Exception):
                    self.link.resend_urgent([r for r in reqs if r.board in waiting])
            # Whoever holds the lock (a read in progress) takes in the replies;
            # when nobody does, this thread does.
            if self._lock.acquire(blocking=False):
                try:
                    self.link.poll()
                except Exception:  # noqa: BLE001 - a read that fails is a later read()'s news
                    pass
                finally:
                    self._lock.release()
            time.sleep(0.001)
        self.link.forget(reqs, lost=False)  # the spare copies: their replies count as late

    def _estop_unconfirmed(self, boards: Sequence[m.Board], why: str) -> None:
        names = " and ".join(f"the {b.name.lower()} board" for b in boards)
        # What the host knows: not whether the board stopped, only what a
        # working board's watchdog is set to do.
        watchdog = (f"; this host cannot tell whether it stopped (a board that still runs "
                    f"stops its motors {self.watchdog_ms} ms after it last heard the host)"
                    if self.watchdog_ms else "; the watchdogs are off (watchdog=0)")
        self.sink(Event(self.clock.now(), EventKind.LINK,
                        f"emergency stop not confirmed by {names}: {why}{watchdog}", None,
                        self.health()))

    @locked
    def clear(self, mask: int = m.ClearMask.ALL) -> None:
        """Clear latches (e-stop, watchdog, faults) on both boards; the host's
        e-stop latch once both boards confirm.  LinkLostError if they do not;
        BoardOwnedError if a board refuses (another host took its lease)."""
        for reply in self._wait(self._broadcast(m.Clear(mask))):
            self._check_owned(reply, "Clear")
        if mask & m.ClearMask.ESTOP:
            self._estopped = False

    def _check_owned(self, reply: Reply, what: str) -> None:
        """BoardOwnedError when a board answered ``what`` with Ack(NOT_OWNER)."""
        for msg in reply.messages:
            if isinstance(msg, m.Ack) and msg.result == m.AckResult.NOT_OWNER:
                raise BoardOwnedError(
                    f"{self.url}: the {m.Board(reply.board).name.lower()} board refused "
                    f"{what}: this host no longer holds its lease (another host took it, "
                    "or this one fell silent for longer than the lease); one host owns "
                    "the robot")

    @property
    def estopped(self) -> bool:
        """True from estop() until a clear() of the e-stop latch."""
        return self._estopped

    @locked
    def heartbeat(self) -> None:
        """Feed the watchdog and renew the lease of a board that was sent
        nothing for ``feed_s`` (the control loop's own frames normally do this)."""
        now = self._monotonic()
        for board in m.Board:
            if now - self._last_tx.get(board, 0.0) > self.feed_s:
                self._commands.append(self._request(board, [m.Heartbeat()]))

    @locked
    def diagnostics(self) -> dict[str, object]:
        """The URL, the wire, link health and the boards' identities."""
        return {"url": self.url, **self.link.describe(), "link": self.health(),
                "boards": {m.Board(b).name.lower(): vars_of(i)
                           for b, i in self.idents.items()},
                "imu": {"state": self.imu_read.state, "problem": self.imu_read.problem,
                        "rejected": self.imu_rejected}}

    def _keep_alive(self) -> None:
        while not self._stop.wait(self.feed_s):
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
        """Stop every motor; once both boards confirm, switch off the
        watchdogs this host set and give its leases up: a watchdog still armed
        after a close trips, and its latch then tells the next host that this
        one stopped without closing.  A board whose lease another host holds
        refuses both (this host set nothing there that it may undo)."""
        if self._closed:
            return
        with contextlib.suppress(Exception):
            self._wait([self._request(m.Board.MOTOR, [m.Stop(m.ALL_MOTORS_MASK)])])
            if self.watchdog_ms:
                self._wait(self._broadcast(m.SetWatchdog(0)))
        if not self._link_lost:  # a lease on a lost link lapses by itself
            for board in self.boots:
                release_board(self.link, m.Board(board), self.nonce)
        self._closed = True
        self.link.close()

    def health(self) -> dict[str, float]:
        """The link's figures (see HealthReport.figures)."""
        return self.report.figures()

    @property
    def refused(self) -> int:
        """Commands a board refused so far."""
        return self.report.refused

    # -- internals ---------------------------------------------------------------
    def _request(self, board: int, msgs: list[m.Message], send: bool = True) -> Request:
        self._last_tx[board] = self._monotonic()
        try:
            return self.link.request(board, msgs, send=send)
        except LinkLostError as exc:  # the wire itself failed (a port that went away)
            self._lost(str(exc), latch=isinstance(exc, BusFaultError))
            raise  # unreachable: _lost raises

    def _broadcast(self, msg: m.Message) -> Sequence[Request]:
        try:
            return self.link.broadcast(msg)
        except LinkLostError as exc:  # the wire itself failed
            self._lost(str(exc), latch=isinstance(exc, BusFaultError))
            raise  # unreachable: _lost raises

    def _wait(self, requests: Sequence[Request]) -> list[Reply]:
        try:
            return self.link.wait(requests)
        except LinkLostError as exc:
            self._lost(str(exc), latch=isinstance(exc, BusFaultError))
            raise  # unreachable: _lost raises
        except HardwareError as exc:  # a board that broke the protocol
            raise HardwareError(f"{self.url}: {exc}") from None

    def _lost(self, reason: str, boards_stopped: bool = False, latch: bool = False) -> None:
        """Report the lost link (a LINK event, the first time only: the stop,
        truth and close that follow a loss would each report it again) and
        raise LinkLostError saying what became of the motors, and what is
        wrong with the wire itself if the link knows (``bus_trouble``).  A
        failed wire (``latch``: bus-off, a flood) first latches this robot's
        emergency stop."""
        if latch:
            self.estop()  # never raises; the boards may not hear it
        else:
            trouble = self.link.bus_trouble()
            if trouble is not None:
                reason = f"{reason}; meanwhile {trouble}"
        if not self._link_lost:
            self._link_lost = True
            self.sink(Event(self.clock.now(), EventKind.LINK, f"link lost: {reason}", None,
                            self.health()))
        if latch:
            after = ("; this host's emergency stop is latched (EStop frames sent; a board "
                     "that did not hear them stops its motors when its watchdog runs out)")
        elif boards_stopped:
            after = ""
        elif self.watchdog_ms:
            # What the host cannot know it does not say: whether the boards
            # are alive, and so whether their watchdogs have stopped anything.
            after = (f"; a board that hears nothing more stops its motors when its "
                     f"watchdog ({self.watchdog_ms} ms) runs out")
        else:
            after = "; the boards' watchdogs are off (watchdog=0): motors may still run"
        raise LinkLostError(f"{self.url}: link lost: {reason}{after}")

    def _reap(self) -> None:
        try:
            self.link.poll()
        except LinkLostError as exc:  # the wire itself failed
            self._lost(str(exc), latch=isinstance(exc, BusFaultError))
        still = []
        done_now = []
        for p in self._commands:
            if p.reply is not None:
                done_now.append(p)
                for msg in p.reply.messages:
                    if isinstance(msg, m.Ack) and msg.result != m.AckResult.OK:
                        self.report.refused += 1
            elif not p.failed:
                still.append(p)
        self._commands = still
        for p in done_now:
            if p.reply is not None:
                self._check_owned(p.reply, "a command")

    def _check_status(self, board: m.Board, status: m.Status) -> None:
        self.status[board] = status
        name = board.name.lower()
        if status.flags & m.StatusFlag.WATCHDOG:
            what = ": its motors are stopped until cleared" if board == m.Board.MOTOR else ""
            self._lost(f"the {name} board's watchdog tripped (nothing from the host for "
                       f"{status.watchdog_ms} ms){what}",
                       boards_stopped=board == m.Board.MOTOR)
        if status.fault == m.MotorFault.SIMULATION:
            self._world_failed(board)
        if status.flags & m.StatusFlag.ESTOP and not self._estopped:
            raise HardwareError(f"the {name} board has its emergency stop latched "
                                "(not by this host: the board's own input?)")

    def _world_failed(self, board: m.Board) -> None:
        """Fake boards say the simulated world behind them failed (a fall)."""
        raise HardwareError(f"the {board.name.lower()} board's simulated world failed")

    def _read_all(self, board: m.Board, msgs: tuple[Any, ...], kind: type[T],
                  ids: Sequence[K], convert: Callable[[T], V]) -> dict[K, V]:
        """A ReadAll reply -- Status, then one ``kind`` telemetry per channel --
        as ``{ids[channel]: convert(telemetry)}``, after checking the Status.
        HardwareError when the reply is not that."""
        self._check_reply_status(board, msgs)
        return telemetry.channels(board, msgs[1:], kind, ids, convert)

    def _read_sensors(self, msgs: tuple[Any, ...], transit_s: float
                      ) -> dict[SensorId, SensorReading]:
        """The sensor board's ReadAll reply as readings, after checking its
        Status: the base four, and the side pair on a robot that has one
        (``telemetry.sensors_of``).  HardwareError when the reply is not that;
        BoardMismatchError (naming this URL) when the side pair lacks."""
        self._check_reply_status(m.Board.SENSOR, msgs)
        try:
            return telemetry.sensors_of(msgs[1:], lambda t: u.reading_from_wire(t, transit_s),
                                        self.side_pair)
        except BoardMismatchError as exc:
            raise BoardMismatchError(f"{self.url}: {exc}") from None

    def _check_reply_status(self, board: m.Board, msgs: tuple[Any, ...]) -> None:
        """HardwareError unless a ReadAll reply starts with a Status; check it."""
        if not msgs or not isinstance(msgs[0], m.Status):
            raise HardwareError(f"the {board.name.lower()} board answered ReadAll with "
                                f"{msgs!r}")
        self._check_status(board, msgs[0])

    def _read_imu(self, msgs: tuple[Any, ...], transit_s: float, now: float) -> Imu | None:
        """The IMU of the sensor board's ReadAll reply (None unless it is
        there, OK and valid).  A board that breaks the protocol is counted
        (``imu_rejected``) and told once, as a WARNING, until it mends (a
        value that changes every tick is one trouble, not one a tick)."""
        got = telemetry.imu_of(msgs, transit_s)
        if got.broken:
            self.imu_rejected += 1
            if got.state != self.imu_read.state:
                self.sink(Event(now, EventKind.WARNING, f"sensor board IMU read as none: "
                                f"{got.problem}", None, {"imu": got.state}))
        self.imu_read = got
        return got.imu


def vars_of(ident: m.Ident) -> dict[str, int]:
    return {"protocol": ident.protocol_major * 256 + ident.protocol_minor,
            "firmware": ident.firmware, "serial": ident.serial, "channels": ident.channels}
