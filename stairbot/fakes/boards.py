"""The firmware of both boards, emulated, independent of the wire.

:class:`MotorBoard` and :class:`SensorBoard` answer the messages of
``stairbot.drivers.messages`` as docs/protocol.md says a real board must:
per-board watchdog (no valid host frame for ``watchdog_ms`` -> every motor
stops, lifts hold, a fault latches until an explicit Clear), latched emergency
stop, fault latch, Move by turns.  Both are backed by one :class:`BoardWorld`:
any Robot and Clock -- in practice the simulation's SimRobot and SimClock, so
the fake boards drive the same physics as ``sim://``.

A transport (``serial_boards``, the CAN fake) feeds each valid host frame to
``board.handle(messages)`` and sends back what it returns; it calls
``board.poll()`` whenever time may have passed.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Sequence

from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.drivers.serial_wire import RawMessage
from stairbot.errors import HardwareError
from stairbot.hardware import Clock, HasTruth, MotorId, Robot, Snapshot

FIRMWARE_VERSION = 0x0100
DEFAULT_WATCHDOG_MS = 250


class BoardWorld:
    """The robot behind both boards, read at most once per instant (so the
    sensor noise draws are the same as a ``sim://`` run's), and its clock.

    In lockstep the world advances only on :meth:`step_to`; otherwise the
    server calls :meth:`advance` as wall time passes."""

    def __init__(self, robot: Robot, clock: Clock, lockstep: bool = False) -> None:
        self.robot = robot
        self.clock = clock
        self.lockstep = lockstep
        self.failure: str | None = None
        self._snap: Snapshot | None = None
        self._snap_time = -1.0
        self._time_us = round(clock.now() * 1e6)
        self._speeds: dict[MotorId, float] = {mid: 0.0 for mid in m.MOTOR_CHANNELS}

    def now(self) -> float:
        return self.clock.now()

    def snapshot(self) -> Snapshot | None:
        """The robot now, or None once the world has failed (see ``failure``)."""
        if self.failure is not None:
            return self._snap
        t = self.clock.now()
        if self._snap is None or t != self._snap_time:
            try:
                self._snap = self.robot.read()
            except HardwareError as exc:
                self._fail(str(exc))
                return self._snap
            self._snap_time = t
        return self._snap

    def _fail(self, reason: str) -> None:
        self.failure = reason
        self.robot.stop_all()

    def set_speeds(self, speeds: dict[MotorId, float]) -> None:
        self._speeds.update(speeds)
        if self.failure is None:
            self.robot.command(dict(self._speeds))

    def speeds(self) -> dict[MotorId, float]:
        return dict(self._speeds)

    def step_to(self, time_us: int) -> int:
        """Advance to ``time_us`` (no-op if already there or past); the time now."""
        if time_us > self._time_us and self.failure is None:
            self.advance((time_us - self._time_us) / 1e6)
            self._time_us = time_us
        return self._time_us

    def advance(self, seconds: float) -> None:
        if self.failure is not None:
            return
        try:
            self.clock.advance(seconds)
        except HardwareError as exc:
            self._fail(str(exc))
        if not self.lockstep:
            self._time_us = round(self.clock.now() * 1e6)

    def truth(self) -> m.Truth:
        """GetTruth's answer: the world's own truth (a robot without it, such
        as a test's stub, reports zeros), and a fall the world failed on."""
        fell, pitch, offset = False, 0.0, 0.0
        if isinstance(self.robot, HasTruth):
            t = self.robot.truth()
            fell, pitch, offset = t.fell, t.max_pitch_deg or 0.0, t.offset_m or 0.0
        fell = fell or (self.failure is not None and "fell" in self.failure.lower())
        return m.Truth(
            1 if fell else 0,
            max(-32767, min(32767, round(pitch * 100))),
            max(-(2**31) + 1, min(2**31 - 1, round(offset * 1000))),
        )


class Pacer:
    """Keeps a world that is not in lockstep up with the wall clock times
    ``time_scale``, one ``step_s`` step per :meth:`step`, so that a server
    looks at its line between steps: one that fell behind answers the host
    before it catches up.  Shared by the serial and the CAN server."""

    MAX_WAIT_S = 0.05  # the longest a server waits on its line before looking again

    def __init__(self, world: BoardWorld, boards: Iterable[Board], time_scale: float = 1.0,
                 step_s: float = 0.005, monotonic: Callable[[], float] = time.monotonic
                 ) -> None:
        self.world = world
        self.boards = list(boards)
        self.time_scale = time_scale
        self.step_s = step_s
        self._monotonic = monotonic
        self._start: tuple[float, float] | None = None  # (wall, world) at the first step

    def step(self) -> float:
        """Advance the world one step if it is due (and let every board check
        its watchdog and Moves); the seconds the server may then wait on its
        line: 0 after a step, until the next step is due otherwise, and
        MAX_WAIT_S in lockstep (only StepTo advances the world)."""
        if self.world.lockstep:
            return self.MAX_WAIT_S
        if self._start is None:
            self._start = (self._monotonic(), self.world.now())
        wall0, world0 = self._start
        due = world0 + (self._monotonic() - wall0) * self.time_scale
        if self.world.now() + self.step_s <= due:
            self.world.advance(self.step_s)
            for board in self.boards:
                board.poll()
            return 0.0
        return min(self.MAX_WAIT_S, (self.world.now() + self.step_s - due) / self.time_scale)


class Board:
    """What both boards share: identity, watchdog, e-stop and fault latches."""

    BOARD: m.Board = m.Board.MOTOR
    CHANNELS = 0

    def __init__(self, world: BoardWorld, serial: int = 1) -> None:
        self.world = world
        self.serial = serial
        self.watchdog_ms = DEFAULT_WATCHDOG_MS
        self.estop = False
        self.watchdog_tripped = False
        self.fault = m.MotorFault.NONE
        self._last_feed: float | None = None  # the watchdog arms on the first host frame
        self._start = world.now()
        self.handled = 0

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

    def fault_code(self) -> int:
        if self.world.failure is not None:
            return int(m.MotorFault.SIMULATION)
        if self.estop:
            return int(m.MotorFault.ESTOP)
        if self.watchdog_tripped:
            return int(m.MotorFault.WATCHDOG)
        return int(self.fault)

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

    # -- messages --------------------------------------------------------------
    def handle(self, msgs: Sequence[m.Message | RawMessage]) -> list[m.Message]:
        """The replies to one valid host frame, in order; feeds the watchdog."""
        self.poll()  # a frame that comes too late does not un-trip the watchdog
        self._last_feed = self.world.now()
        self.handled += 1
        out: list[m.Message] = []
        for msg in msgs:
            if isinstance(msg, RawMessage):
                out.append(m.Ack(msg.type_code, m.AckResult.UNKNOWN_TYPE))
            elif msg.REPLY:
                out.append(m.Ack(msg.TYPE, m.AckResult.NOT_SUPPORTED))
            else:
                out.extend(self.answer(msg))
        return out

    def answer(self, msg: m.Message) -> list[m.Message]:
        if isinstance(msg, m.Identify):
            return [m.Ident(self.BOARD, m.PROTOCOL_MAJOR, m.PROTOCOL_MINOR, self.CHANNELS,
                            FIRMWARE_VERSION, self.serial)]
        if isinstance(msg, m.Heartbeat | m.GetStatus):
            return [self.status()]
        if isinstance(msg, m.SetWatchdog):
            self.watchdog_ms = msg.timeout_ms
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
                self.fault = m.MotorFault.NONE
            return [self.status()]
        return [m.Ack(msg.TYPE, m.AckResult.NOT_SUPPORTED)]


class MotorBoard(Board):
    """Six motors, channels in ``messages.MOTOR_CHANNELS`` order."""

    BOARD = m.Board.MOTOR
    CHANNELS = len(m.MOTOR_CHANNELS)

    def __init__(self, world: BoardWorld, serial: int = 1) -> None:
        super().__init__(world, serial)
        self.modes = [m.MotorMode.IDLE] * self.CHANNELS
        self._move_target: list[float | None] = [None] * self.CHANNELS
        self.peer: Board | None = None  # the sensor board, whose StepTo polls we share

    def _set(self, speeds: dict[int, float], mode: m.MotorMode | None = None) -> None:
        for ch, tps in speeds.items():
            self.modes[ch] = mode if mode is not None else (
                m.MotorMode.RUN if tps != 0 else m.MotorMode.IDLE)
            self._move_target[ch] = None
        self.world.set_speeds({m.MOTOR_CHANNELS[ch]: tps for ch, tps in speeds.items()})

    def halt(self) -> None:
        self._set({ch: 0.0 for ch in range(self.CHANNELS)}, m.MotorMode.HOLD)

    def telemetry(self, ch: int) -> m.MotorTelemetry:
        snap = self.world.snapshot()
        mid = m.MOTOR_CHANNELS[ch]
        turns = snap.motors[mid].turns if snap else 0.0
        speed = snap.motors[mid].speed_tps if snap else 0.0
        fault = self.fault_code()
        if fault == m.MotorFault.NONE and snap and snap.motors[mid].fault:
            fault = int(m.MotorFault.LIMIT if "limit" in str(snap.motors[mid].fault)
                        else m.MotorFault.DRIVER)
        return m.MotorTelemetry(ch, int(self.modes[ch]), fault, u.speed_to_wire(speed),
                                u.turns_to_wire(turns))

    def poll(self) -> None:
        super().poll()
        snap = None
        for ch, target in enumerate(self._move_target):
            if target is None:
                continue
            snap = snap or self.world.snapshot()
            if snap is None:
                continue
            turns = snap.motors[m.MOTOR_CHANNELS[ch]].turns
            speed = self.world.speeds()[m.MOTOR_CHANNELS[ch]]
            if (speed >= 0 and turns >= target) or (speed < 0 and turns <= target):
                self._set({ch: 0.0})

    def _motion(self, msg: m.Message, speeds: dict[int, float]) -> list[m.Message]:
        refusal = self.refusal()
        if refusal is not m.AckResult.OK:
            return [m.Ack(msg.TYPE, refusal)]
        self._set(speeds)
        return [m.Ack(msg.TYPE, m.AckResult.OK)]

    def answer(self, msg: m.Message) -> list[m.Message]:
        sp = u.speed_from_wire
        if isinstance(msg, m.ReadAll):
            tel = [self.telemetry(ch) for ch in range(self.CHANNELS)]  # reads the world first
            return [self.status(), *tel]
        if isinstance(msg, m.GetMotor):
            if msg.channel >= self.CHANNELS:
                return [m.Ack(msg.TYPE, m.AckResult.BAD_CHANNEL)]
            return [self.telemetry(msg.channel)]
        if isinstance(msg, m.SetWheelSpeeds):
            return self._motion(msg, {0: sp(msg.mwf), 1: sp(msg.mwb), 2: sp(msg.mwr),
                                      3: sp(msg.mwl)})
        if isinstance(msg, m.SetLiftSpeeds):
            return self._motion(msg, {4: sp(msg.mtf), 5: sp(msg.mtb)})
        if isinstance(msg, m.Run):
            if msg.channel >= self.CHANNELS:
                return [m.Ack(msg.TYPE, m.AckResult.BAD_CHANNEL)]
            return self._motion(msg, {msg.channel: sp(msg.speed_mtps)})
        if isinstance(msg, m.Move):
            return self._move(msg)
        if isinstance(msg, m.StepTo):  # the simulation's messages go to the motor board
            if not self.world.lockstep:
                return [m.Ack(msg.TYPE, m.AckResult.NOT_SUPPORTED)]
            done = self.world.step_to(msg.time_us)
            self.after_step()
            return [m.StepDone(done & 0xFFFFFFFF)]
        if isinstance(msg, m.GetTruth):
            return [self.world.truth()]
        if isinstance(msg, m.Stop | m.Brake):
            if msg.mask & ~m.ALL_MOTORS_MASK:
                return [m.Ack(msg.TYPE, m.AckResult.BAD_CHANNEL)]
            chans = [ch for ch in range(self.CHANNELS) if msg.mask >> ch & 1]
            self._set({ch: 0.0 for ch in chans})
            if isinstance(msg, m.Brake):
                for ch in chans:
                    if ch not in m.LIFT_CHANNELS:
                        self.modes[ch] = m.MotorMode.BRAKE
            return [m.Ack(msg.TYPE, m.AckResult.OK)]
        return super().answer(msg)

    def after_step(self) -> None:
        """The world moved on: check both boards' watchdogs and the Moves."""
        self.poll()
        if self.peer is not None:
            self.peer.poll()

    def _move(self, msg: m.Move) -> list[m.Message]:
        if msg.channel >= self.CHANNELS:
            return [m.Ack(msg.TYPE, m.AckResult.BAD_CHANNEL)]
        if msg.speed_mtps == 0 or msg.speed_mtps > m.INT16_MAX:
            return [m.Ack(msg.TYPE, m.AckResult.BAD_VALUE)]
        refusal = self.refusal()
        if refusal is not m.AckResult.OK:
            return [m.Ack(msg.TYPE, refusal)]
        snap = self.world.snapshot()
        if snap is None:
            return [m.Ack(msg.TYPE, m.AckResult.NOT_SUPPORTED)]
        start = snap.motors[m.MOTOR_CHANNELS[msg.channel]].turns
        speed = u.speed_from_wire(msg.speed_mtps) * (1 if msg.turns_mt >= 0 else -1)
        self._set({msg.channel: speed}, m.MotorMode.MOVE)
        self._move_target[msg.channel] = start + u.turns_from_wire(msg.turns_mt)
        if msg.turns_mt == 0:
            self._set({msg.channel: 0.0})
        return [m.Ack(msg.TYPE, m.AckResult.OK)]


class SensorBoard(Board):
    """Four distance sensors, channels in ``messages.SENSOR_CHANNELS`` order."""

    BOARD = m.Board.SENSOR
    CHANNELS = len(m.SENSOR_CHANNELS)

    def __init__(self, world: BoardWorld, serial: int = 2) -> None:
        super().__init__(world, serial)
        self._sample = 0
        self._sample_time: float | None = None

    def telemetry(self, ch: int) -> m.SensorTelemetry:
        snap = self.world.snapshot()
        if snap is None:
            return m.SensorTelemetry(ch, int(m.SensorCode.ERROR), 0, self._sample)
        if snap.time_s != self._sample_time:
            self._sample_time = snap.time_s
            self._sample = (self._sample + 1) & 0xFFFF
        r = snap.sensors[m.SENSOR_CHANNELS[ch]]
        return m.SensorTelemetry(ch, u.sensor_code(r.status), u.distance_to_wire(r.distance_m),
                                 self._sample)

    def answer(self, msg: m.Message) -> list[m.Message]:
        if isinstance(msg, m.ReadAll):
            tel = [self.telemetry(ch) for ch in range(self.CHANNELS)]  # reads the world first
            return [self.status(), *tel]
        if isinstance(msg, m.GetSensor):
            if msg.channel >= self.CHANNELS:
                return [m.Ack(msg.TYPE, m.AckResult.BAD_CHANNEL)]
            return [self.telemetry(msg.channel)]
        return super().answer(msg)


def make_boards(world: BoardWorld) -> dict[int, Board]:
    """Both boards on one world, keyed by board address."""
    motor, sensor = MotorBoard(world), SensorBoard(world)
    motor.peer = sensor
    return {int(m.Board.MOTOR): motor, int(m.Board.SENSOR): sensor}
