"""The firmware of both boards, emulated, independent of the wire.

:class:`MotorBoard` and :class:`SensorBoard` answer the messages of
``stairbot.drivers.messages`` as docs/protocol.md says a real board must:
one host's lease (Claim: while it is live, only its holder may command
motion, set the watchdog, clear or step the world, and only its frames feed
the watchdog), per-board watchdog (no frame from the lease's holder for
``watchdog_ms`` -> every motor stops, lifts hold, a fault latches until an
explicit Clear), latched emergency stop (anyone may stop the robot), each
motor's fault latch (a lift at its limit is reported, not latched), Move by
turns; the motor board also answers the simulation's StepTo
and GetTruth.  What both share is :class:`~stairbot.fakes.board_base.Board`
(``board_base.py``); both are backed by one
:class:`~stairbot.fakes.board_world.BoardWorld` (``board_world.py``).

A transport (``serial_boards``, the CAN fake) feeds each valid host frame to
``board.handle(messages, session)`` with the host session the frame carries
and sends back what it returns; it calls ``board.poll()`` whenever time may
have passed.
"""

from __future__ import annotations

import secrets

from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.fakes import sim_messages as sim
from stairbot.fakes.board_base import Board
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.motor_faults import FaultLatch
from stairbot.hardware import MotorId, Snapshot


class MotorBoard(Board):
    """Six motors, channels in ``messages.MOTOR_CHANNELS`` order.  A motor
    whose snapshot reports a fault other than LIMIT latches it when the
    board reads its world (telemetry, a Move): the motor stops (HOLD) and
    stays stopped until Clear 0x04."""

    BOARD = m.Board.MOTOR
    CHANNELS = len(m.MOTOR_CHANNELS)

    def __init__(self, world: BoardWorld, serial: int = 1) -> None:
        super().__init__(world, serial)
        self.modes = [m.MotorMode.IDLE] * self.CHANNELS
        self.faults = FaultLatch()  # each motor's latched fault
        self._move_target: list[int | None] = [None] * self.CHANNELS  # counter, mturn
        self.peer: Board | None = None  # the sensor board, whose StepTo polls we share
        self._commanded = world.now()  # the host's last motion command: the hold counts from it

    def _set(self, speeds: dict[int, float], mode: m.MotorMode | None = None) -> None:
        """Set the motors' speeds and modes (RUN, or IDLE at 0, unless
        ``mode``), cancelling their Moves; a motor with a latched fault
        stays stopped in HOLD whatever it is told.  The board's own speed
        changes come here alone; a host's motion command through
        :meth:`_command`."""
        out: dict[MotorId, float] = {}
        for ch, tps in speeds.items():
            if self.faults.held(ch):
                tps, self.modes[ch] = 0.0, m.MotorMode.HOLD
            else:
                self.modes[ch] = mode if mode is not None else (
                    m.MotorMode.RUN if tps != 0 else m.MotorMode.IDLE)
            self._move_target[ch] = None
            out[m.MOTOR_CHANNELS[ch]] = tps
        self.world.set_speeds(out)

    def _command(self, speeds: dict[int, float], mode: m.MotorMode | None = None) -> None:
        """A motion command of the host, obeyed: :meth:`_set`, and the hold
        restarts."""
        self._commanded = self.world.now()
        self._set(speeds, mode)

    def _snapshot(self) -> Snapshot | None:
        """The world now, its motors' faults latched (each motor's first;
        Status.fault the board's first)."""
        snap = self.world.snapshot()
        new = self.faults.see(snap)
        if new:
            self.fault = self.faults.first
            self._set({ch: 0.0 for ch in new})
        return snap

    def clear_faults(self) -> None:
        super().clear_faults()
        self.faults.clear()

    def halt(self) -> None:
        self._set({ch: 0.0 for ch in range(self.CHANNELS)}, m.MotorMode.HOLD)

    def may_move(self) -> bool:
        return any(mode in (m.MotorMode.RUN, m.MotorMode.MOVE) for mode in self.modes)

    def telemetry(self, ch: int) -> m.MotorTelemetry:
        """The motor now; its fault: the board's latch, else the motor's
        latched fault, else LIMIT (a lift at the end of its stroke), else NONE."""
        snap = self._snapshot()
        mid = m.MOTOR_CHANNELS[ch]
        turns = snap.motors[mid].turns if snap else 0.0
        speed = snap.motors[mid].speed_tps if snap else 0.0
        fault = self.board_latch() or self.faults.of(ch, snap)
        return m.MotorTelemetry(ch, int(self.modes[ch]), int(fault), u.speed_to_wire(speed),
                                u.turns_to_wire(turns))

    def poll(self) -> None:
        super().poll()
        if self.hold_ms and (self.world.now() - self._commanded) * 1000 > self.hold_ms:
            running = {ch: 0.0 for ch, mode in enumerate(self.modes)
                       if mode == m.MotorMode.RUN}
            if running:  # the command outlived its hold: stop, latch nothing
                self.held_out += 1
                self._set(running)
        snap = None
        for ch, target in enumerate(self._move_target):
            if target is None:
                continue
            snap = snap or self._snapshot()
            if snap is None:
                continue
            turns = u.turns_to_wire(snap.motors[m.MOTOR_CHANNELS[ch]].turns)  # as reported
            speed = self.world.speeds()[m.MOTOR_CHANNELS[ch]]
            if (speed >= 0 and turns >= target) or (speed < 0 and turns <= target):
                self._set({ch: 0.0})

    def _motion(self, msg: m.Message, speeds: dict[int, float]) -> list[m.Message]:
        refusal = self.refusal()
        if refusal is not m.AckResult.OK:
            return [m.Ack(msg.TYPE, refusal)]
        self._command(speeds)
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
        if isinstance(msg, sim.StepTo):  # the simulation's messages go to the motor board
            if not self.world.lockstep:
                return [m.Ack(msg.TYPE, m.AckResult.NOT_SUPPORTED)]
            done = self.world.step_to(msg.time_us)
            self.after_step()
            return [sim.StepDone(done & 0xFFFFFFFF)]
        if isinstance(msg, sim.GetTruth):
            return [self.world.truth()]
        if isinstance(msg, m.Stop | m.Brake):
            if msg.mask & ~m.ALL_MOTORS_MASK:
                return [m.Ack(msg.TYPE, m.AckResult.BAD_CHANNEL)]
            chans = [ch for ch in range(self.CHANNELS) if msg.mask >> ch & 1]
            self._command({ch: 0.0 for ch in chans})
            if isinstance(msg, m.Brake):
                for ch in chans:
                    if ch not in m.LIFT_CHANNELS and not self.faults.held(ch):
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
        snap = self._snapshot()
        if snap is None:
            return [m.Ack(msg.TYPE, m.AckResult.NOT_SUPPORTED)]
        start = u.turns_to_wire(snap.motors[m.MOTOR_CHANNELS[msg.channel]].turns)
        speed = u.speed_from_wire(msg.speed_mtps) * (1 if msg.turns_mt >= 0 else -1)
        self._command({msg.channel: speed}, m.MotorMode.MOVE)
        if self.modes[msg.channel] == m.MotorMode.MOVE:  # not a motor held by its fault
            self._move_target[msg.channel] = start + msg.turns_mt
        if msg.turns_mt == 0:
            self._set({msg.channel: 0.0})
        return [m.Ack(msg.TYPE, m.AckResult.OK)]


class SensorBoard(Board):
    """Four distance sensors -- six when the world's robot has the side pair
    (``BoardWorld.side_pair``: channels 4 SSR and 5 SSL, protocol 4.1) --
    channels in ``messages.SENSOR_CHANNELS`` order, and the IMU
    (``messages.IMU_AXES``), as the world's snapshot holds them: each reading's
    age and the IMU's (None: no IMU fitted, ABSENT) grow by the time from the
    snapshot to the reply, as a real board's count would.  A channel the
    snapshot lacks (a side sensor the simulation does not model) is sent as
    a sensor that has never measured: ERROR, age saturated."""

    BOARD = m.Board.SENSOR
    CHANNELS = m.BASE_SENSOR_CHANNELS
    NEW_SAMPLE_S = 1e-6  # measurement times closer than this are one measurement

    def __init__(self, world: BoardWorld, serial: int = 2) -> None:
        super().__init__(world, serial)
        if world.side_pair:
            self.CHANNELS = max(m.SIDE_SENSOR_CHANNELS) + 1
        self._sample = [0] * self.CHANNELS
        self._sample_time: list[float | None] = [None] * self.CHANNELS

    def _since(self, snap_time: float) -> float:
        """How long ago (board time) the snapshot was taken."""
        return max(0.0, self.world.now() - snap_time)

    def telemetry(self, ch: int) -> m.SensorTelemetry:
        snap = self.world.snapshot()
        if snap is None:
            return m.SensorTelemetry(ch, int(m.SensorCode.ERROR), 0, self._sample[ch],
                                     m.AGE_MAX_MS)
        r = snap.sensors.get(m.SENSOR_CHANNELS[ch])
        if r is None:  # never measured (docs/protocol.md, section 3: "Ages")
            return m.SensorTelemetry(ch, int(m.SensorCode.ERROR), 0, self._sample[ch],
                                     m.AGE_MAX_MS)
        measured = snap.time_s - r.age_s  # a repeated value keeps its measurement time
        last = self._sample_time[ch]
        if last is None or not abs(measured - last) < self.NEW_SAMPLE_S:
            self._sample_time[ch] = measured
            self._sample[ch] = (self._sample[ch] + 1) & 0xFFFF
        return u.reading_to_wire(ch, r, self._sample[ch], self._since(snap.time_s))

    def imu_telemetry(self, axis: m.ImuAxis) -> m.ImuTelemetry:
        snap = self.world.snapshot()
        if snap is None:
            return m.ImuTelemetry(int(axis), int(m.ImuCode.ERROR), 0, 0, m.AGE_MAX_MS)
        return u.imu_to_wire(snap.imu, axis, self._since(snap.time_s))

    def answer(self, msg: m.Message) -> list[m.Message]:
        if isinstance(msg, m.ReadAll):  # reads the world before the status
            tel: list[m.Message] = [self.telemetry(ch) for ch in range(self.CHANNELS)]
            tel += [self.imu_telemetry(axis) for axis in m.IMU_AXES]
            return [self.status(), *tel]
        if isinstance(msg, m.GetSensor):
            if msg.channel >= self.CHANNELS:
                return [m.Ack(msg.TYPE, m.AckResult.BAD_CHANNEL)]
            return [self.telemetry(msg.channel)]
        if isinstance(msg, m.GetImu):
            if msg.axis >= len(m.IMU_AXES):
                return [m.Ack(msg.TYPE, m.AckResult.BAD_CHANNEL)]
            return [self.imu_telemetry(m.IMU_AXES[msg.axis])]
        return super().answer(msg)


def make_boards(world: BoardWorld, serials: tuple[int, int] = (1, 2)) -> dict[int, Board]:
    """Both boards on one world, keyed by board address; ``serials``: the
    motor board's and the sensor board's serial numbers."""
    motor, sensor = MotorBoard(world, serials[0]), SensorBoard(world, serials[1])
    motor.peer = sensor
    return {int(m.Board.MOTOR): motor, int(m.Board.SENSOR): sensor}


def launch_serials() -> tuple[int, int]:
    """Serial numbers for the boards of one ``stairbot fake-boards`` process,
    drawn anew each launch: its world begins and ends with it, so it is a
    robot of its own, as two real robots' boards differ (a journal kept on
    one is never taken for another's, on a port or bus they both used)."""
    return 1 + secrets.randbelow(0xFFFF), 1 + secrets.randbelow(0xFFFF)


def serials_words(boards: dict[int, Board]) -> str:
    """The boards' serial numbers in words, for the fake boards' banner."""
    return ", ".join(f"{type(b).__name__.removesuffix('Board').lower()} board serial {b.serial}"
                     for _, b in sorted(boards.items()))
