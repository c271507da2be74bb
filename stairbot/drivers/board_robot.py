"""The host's side of the boards' protocol, whatever the wire.

:class:`BoardRobot` implements the Robot protocol on a
:class:`~stairbot.drivers.link.BoardLink` (the serial link, the CAN link):
``read()`` is one ReadAll to each board (both in flight at once; the replies
become the snapshot in ``board_replies.py``), ``command()`` one
SetWheelSpeeds + SetLiftSpeeds whose Ack is collected on the next call.
Opening the robot identifies the boards, takes their leases and sets their
watchdogs (``handshake.py``); a keepalive thread feeds them and renews the
leases while the robot stands idle (``keepalive.py``); the emergency stop is
``estop.py``'s.  Link health goes into ``Snapshot.health``,
``diagnostics()`` and LINK events (``attach_sink``).  A lost link raises
LinkLostError saying what became of the motors (``link_loss.py``); a board
that never answers while opening, NoBoardError.

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
from collections.abc import Callable, Iterator, Sequence
from typing import Concatenate, Final, NoReturn, ParamSpec, TypeVar

from stairbot.clock import WallClock
from stairbot.drivers import estop, link_loss, telemetry
from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.drivers.board_replies import ReplyReader, identity, vars_of
from stairbot.drivers.handshake import check_owned, latches, open_boards, release_board
from stairbot.drivers.health import HealthReport
from stairbot.drivers.keepalive import Keepalive
from stairbot.drivers.link import BoardLink, BusFaultError, Reply, Request
from stairbot.errors import HardwareError, LinkLostError
from stairbot.events import Event, EventKind, EventSink, discard
from stairbot.hardware import Clock, Imu, Snapshot, Speeds

# A speed command keeps its motors running for at most COMMAND_HOLD_MS of
# wall time (scaled like the watchdog) without a newer one: a host that falls
# silent mid-drive has its motors stopped after that, well before its
# watchdog latches (docs/protocol.md, "Command hold").  Five control ticks:
# a lost command frame or two is ridden out.
COMMAND_HOLD_MS = 100

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
        self.nonce = secrets.randbits(32)  # tells this host's leases from another's
        self._time_scale = time_scale
        self.replies = ReplyReader(url, side_pair, self._check_status)
        self.report = HealthReport(link.stats, monotonic)
        self._monotonic = monotonic
        self._commands: list[Request] = []
        self._closed = False
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
        opened = open_boards(
            link, url, lockstep=self.LOCKSTEP, watchdog_ms=self.board_watchdog_ms,
            hold_ms=self.board_hold_ms, nonce=self.nonce, lease_ms=self.board_lease_ms,
            wait_s=self._wait_board_s, allow_latched=allow_latched, side_pair=side_pair,
            opened=self._sent_to)
        self.idents, self.status, self.boots = opened.idents, opened.status, opened.boots
        self.latched = {b: latches(s) for b, s in self.status.items() if latches(s)}
        # an e-stop latch found when opening is this host's to hold
        self._estopped = any(s.flags & m.StatusFlag.ESTOP for s in self.status.values())
        # Heartbeats to any board the host has not addressed for ``feed_s``.
        self._keepalive = (Keepalive(f"{link.wire} robot keepalive", lambda: self.feed_s,
                                     self._keep_alive) if keepalive else None)

    # -- setting up ------------------------------------------------------------
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
        """Each board's serial number, uptime and boot id (``board_replies.identity``)."""
        return identity(self.idents, self.status, self.boots)

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
        motors = self.replies.motors(fm.messages)
        sensors = self.replies.sensors(fs.messages, transit, now)
        imu = self.replies.imu(fs.messages, transit, now, self.sink)
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
        zeros from now on), and on both boards (``estop.press``).  Callable
        from any thread, it does not wait for the robot's lock.  Never
        raises: a board that does not confirm is a LINK event naming it."""
        self._estopped = True
        if self._closed:
            return
        unconfirmed = estop.press(self.link, self._lock, self._monotonic)
        if unconfirmed is not None:
            self.sink(Event(self.clock.now(), EventKind.LINK,
                            estop.unconfirmed_text(unconfirmed.boards, unconfirmed.why,
                                                   self.watchdog_ms), None, self.health()))

    @locked
    def clear(self, mask: int = m.ClearMask.ALL) -> None:
        """Clear latches (e-stop, watchdog, faults) on both boards; the host's
        e-stop latch once both boards confirm.  LinkLostError if they do not;
        BoardOwnedError if a board refuses (another host took its lease)."""
        for reply in self._wait(self._broadcast(m.Clear(mask))):
            check_owned(self.url, reply, "Clear")
        if mask & m.ClearMask.ESTOP:
            self._estopped = False

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
                "imu": self.replies.diagnostics()}

    @locked
    def _keep_alive(self) -> bool:
        """One beat of the keepalive; False once the robot is closed."""
        if self._closed:
            return False
        self.heartbeat()
        self._reap()
        return True

    def close(self) -> None:
        if self._keepalive is not None:
            self._keepalive.stop()
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
    @contextlib.contextmanager
    def _on_link(self) -> Iterator[None]:
        """A LinkLostError of the link (no reply, or the wire itself failed:
        a port that went away, bus-off) becomes this robot's (``_lost``)."""
        try:
            yield
        except LinkLostError as exc:
            self._lost(str(exc), latch=isinstance(exc, BusFaultError))

    def _sent_to(self, board: int) -> None:
        self._last_tx[board] = self._monotonic()

    def _request(self, board: int, msgs: list[m.Message], send: bool = True) -> Request:
        self._sent_to(board)
        with self._on_link():
            return self.link.request(board, msgs, send=send)

    def _broadcast(self, msg: m.Message) -> Sequence[Request]:
        with self._on_link():
            return self.link.broadcast(msg)

    def _wait(self, requests: Sequence[Request]) -> list[Reply]:
        try:
            with self._on_link():
                return self.link.wait(requests)
        except HardwareError as exc:  # a board that broke the protocol
            if isinstance(exc, LinkLostError):
                raise
            raise HardwareError(f"{self.url}: {exc}") from None

    def _lost(self, reason: str, boards_stopped: bool = False, latch: bool = False) -> NoReturn:
        """Report the lost link (a LINK event, the first time only: the stop,
        truth and close that follow a loss would each report it again) and
        raise LinkLostError saying what became of the motors
        (``link_loss.consequence``), and what is wrong with the wire itself if
        the link knows (``bus_trouble``).  A failed wire (``latch``: bus-off,
        a flood) first latches this robot's emergency stop."""
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
        after = link_loss.consequence(self.watchdog_ms, latch=latch,
                                      boards_stopped=boards_stopped)
        raise LinkLostError(f"{self.url}: link lost: {reason}{after}")

    def _reap(self) -> None:
        with self._on_link():
            self.link.poll()
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
                check_owned(self.url, p.reply, "a command")

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
