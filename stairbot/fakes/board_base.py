"""What both fake boards share (``boards.py``): identity, the lease
(``board_lease.py``), the watchdog, the latched emergency stop and the
motor-fault latch Status reports, and a host frame's handling in the order
docs/protocol.md (section 3, "Unknown input") gives: a board message, a
Claim, the lease, then the board's own answer."""

from __future__ import annotations

import secrets
import time
from collections.abc import Sequence

from stairbot.drivers import messages as m
from stairbot.fakes import sim_messages as sim
from stairbot.fakes.board_lease import Lease
from stairbot.fakes.board_world import BoardWorld

FIRMWARE_VERSION = 0x0100
DEFAULT_WATCHDOG_MS = 250

# What only the holder of a live lease may send; anyone may query, stop or
# brake (Stop, Brake) and latch the emergency stop.
OWNED: tuple[type[m.Message], ...] = (
    m.SetWatchdog, m.Clear, m.SetWheelSpeeds, m.SetLiftSpeeds, m.Run, m.Move, sim.StepTo)


class Board:
    """What both boards share: identity, watchdog, e-stop and fault latches."""

    BOARD: m.Board = m.Board.MOTOR
    CHANNELS = 0

    def __init__(self, world: BoardWorld, serial: int = 1) -> None:
        self.world = world
        self.serial = serial
        self.watchdog_ms = DEFAULT_WATCHDOG_MS
        self.hold_ms = 0  # a speed command's life (SetWatchdog.hold_ms); 0: until changed
        self.held_out = 0  # motors stopped because their command outlived hold_ms
        self.estop = False
        self.watchdog_tripped = False
        self.fault = m.MotorFault.NONE
        self._last_feed: float | None = None  # the watchdog arms when a lease is granted
        self._start = world.now()
        self.handled = 0
        self.boot = secrets.randbits(32) or 1  # drawn at power-up (Owner.boot)
        self.lease = Lease(time.monotonic if world.lockstep else world.now,
                           lambda: self.watchdog_ms, self.boot, kept_by_holder=world.lockstep)

    # -- status ----------------------------------------------------------------
    def flags(self) -> int:
        f = m.StatusFlag.SIMULATED
        if self.world.lockstep:
            f |= m.StatusFlag.LOCKSTEP
        if self.estop:
            f |= m.StatusFlag.ESTOP
        if self.watchdog_tripped:
            f |= m.StatusFlag.WATCHDOG
        if self.fault != m.MotorFault.NONE or self.world.failure is not None:
            f |= m.StatusFlag.FAULT
        return int(f)

    def board_latch(self) -> m.MotorFault:
        """The whole board's latch that every motor reports: SIMULATION,
        ESTOP, WATCHDOG, in that order; NONE when none is set."""
        if self.world.failure is not None:
            return m.MotorFault.SIMULATION
        if self.estop:
            return m.MotorFault.ESTOP
        if self.watchdog_tripped:
            return m.MotorFault.WATCHDOG
        return m.MotorFault.NONE

    def fault_code(self) -> int:
        """Status.fault: the board's latch, else the first motor fault latched."""
        return int(self.board_latch() or self.fault)

    def status(self) -> m.Status:
        uptime = int((self.world.now() - self._start) * 1000) & 0xFFFFFFFF
        return m.Status(self.flags(), self.fault_code(), self.watchdog_ms, uptime)

    def refusal(self) -> m.AckResult:
        """Why a motion command is refused now (OK when it is not)."""
        if self.estop:
            return m.AckResult.ESTOP
        if self.watchdog_tripped:
            return m.AckResult.WATCHDOG
        return m.AckResult.OK

    # -- time ------------------------------------------------------------------
    def poll(self) -> None:
        """Check the watchdog (and, on the motor board, Moves) at the present time."""
        if (self.watchdog_ms and self._last_feed is not None and not self.watchdog_tripped
                and (self.world.now() - self._last_feed) * 1000 > self.watchdog_ms):
            self.watchdog_tripped = True
            self.halt()

    def halt(self) -> None:
        """Stop every motor this board drives (nothing on the sensor board)."""

    # -- the lease ---------------------------------------------------------------
    def owns(self, session: int) -> bool:
        """Whether ``session`` holds a live lease of this board."""
        return self.lease.owns(session)

    def _claim(self, msg: m.Claim, session: int) -> m.Owner:
        granted = self.lease.claim(msg, session)
        if granted.result == m.ClaimResult.GRANTED:
            self._last_feed = self.world.now()  # the watchdog is armed from now on
        return granted

    # -- messages --------------------------------------------------------------
    def handle(self, msgs: Sequence[m.Message | m.RawMessage], session: int
               ) -> list[m.Message]:
        """The replies to one valid host frame of host session ``session``,
        in order.  A frame of the lease's holder renews the lease and feeds
        the watchdog; another session's commands that need the lease are
        answered Ack(NOT_OWNER) and not executed."""
        self.poll()  # a frame that comes too late does not un-trip the watchdog
        if self.owns(session):
            self._last_feed = self.world.now()
            self.lease.renew()
        self.handled += 1
        out: list[m.Message] = []
        for msg in msgs:
            if isinstance(msg, m.RawMessage):
                out.append(m.Ack(msg.type_code, m.AckResult.UNKNOWN_TYPE))
            elif msg.REPLY:
                out.append(m.Ack(msg.TYPE, m.AckResult.NOT_SUPPORTED))
            elif isinstance(msg, m.Claim):
                out.append(self._claim(msg, session))
            elif isinstance(msg, OWNED) and not self.owns(session):
                out.append(m.Ack(msg.TYPE, m.AckResult.NOT_OWNER))
            else:
                out.extend(self.answer(msg))
        return out

    def may_move(self) -> bool:
        """Whether a motor of this board may be moving (none on the sensor board)."""
        return False

    def clear_faults(self) -> None:
        """Clear 0x04: every motor fault latch reset (no motor restarted)."""
        self.fault = m.MotorFault.NONE

    def answer(self, msg: m.Message) -> list[m.Message]:
        if isinstance(msg, m.Identify):
            return [m.Ident(self.BOARD, m.PROTOCOL_MAJOR, m.PROTOCOL_MINOR, self.CHANNELS,
                            FIRMWARE_VERSION, self.serial)]
        if isinstance(msg, m.Heartbeat | m.GetStatus):
            return [self.status()]
        if isinstance(msg, m.SetWatchdog):
            if msg.timeout_ms == 0 and self.may_move():
                return [m.Ack(msg.TYPE, m.AckResult.BAD_VALUE)]  # stop the motors first
            self.watchdog_ms, self.hold_ms = msg.timeout_ms, msg.hold_ms
            return [self.status()]
        if isinstance(msg, m.EStop):
            self.estop = True
            self.halt()
            return [self.status()]
        if isinstance(msg, m.Clear):
            if msg.mask & m.ClearMask.ESTOP:
                self.estop = False
            if msg.mask & m.ClearMask.WATCHDOG:
                self.watchdog_tripped = False
            if msg.mask & m.ClearMask.FAULTS:
                self.clear_faults()
            return [self.status()]
        return [m.Ack(msg.TYPE, m.AckResult.NOT_SUPPORTED)]
