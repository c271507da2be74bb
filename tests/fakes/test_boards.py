"""The emulated board firmware, without a wire: watchdog trip and clear,
latched emergency stop, Move by turns, refusals, unknown messages."""

from __future__ import annotations

from collections.abc import Mapping

import pytest

from stairbot.drivers import messages as m
from stairbot.drivers.messages import RawMessage
from stairbot.errors import RobotFellError
from stairbot.fakes import sim_messages as sim
from stairbot.fakes.board_world import BoardWorld, Pacer
from stairbot.fakes.boards import MotorBoard, SensorBoard, make_boards
from stairbot.hardware import (
    BASE_SENSORS,
    SIDE_SENSORS,
    Imu,
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    Snapshot,
    Truth,
)

HOST, NONCE = 0x2A, 7  # the session and nonce of the host these tests play


class StubRobot:
    """Turns integrate the commanded speeds; ``fail`` makes read() raise;
    ``ages`` (per sensor), ``imu`` and ``motor_faults`` (per motor) are what
    the snapshot reports, for ``sensors`` (every SensorId unless told)."""

    def __init__(self, sensors: tuple[SensorId, ...] = tuple(SensorId)) -> None:
        self.t = 0.0
        self.sensors = sensors
        self.speeds = {mid: 0.0 for mid in MotorId}
        self.turns = {mid: 0.0 for mid in MotorId}
        self.reads = 0
        self.commands = 0
        self.fail = False
        self.ages = {sid: 0.0 for sid in SensorId}
        self.imu: Imu | None = None
        self.motor_faults: dict[MotorId, str] = {}

    def read(self) -> Snapshot:
        if self.fail:
            raise RobotFellError("pitch beyond 35 degrees")
        self.reads += 1
        return Snapshot(self.t, {s: SensorReading(0.5 + i / 10, age_s=self.ages[s])
                                 for i, s in enumerate(SensorId) if s in self.sensors},
                        {k: MotorState(v, self.speeds[k], self.motor_faults.get(k))
                         for k, v in self.turns.items()},
                        imu=self.imu)

    def command(self, speeds: Mapping[MotorId, float]) -> None:
        self.commands += 1
        self.speeds = {mid: float(speeds.get(mid, 0.0)) for mid in MotorId}

    def stop_all(self) -> None:
        self.speeds = {mid: 0.0 for mid in MotorId}

    def diagnostics(self) -> dict[str, object]:
        return {}

    def truth(self) -> Truth:
        return Truth(self.fail, "stub" if self.fail else None, 1.0, 3.25, 0.012)

    def close(self) -> None:
        pass


class StubClock:
    def __init__(self, robot: StubRobot) -> None:
        self.robot = robot

    def now(self) -> float:
        return self.robot.t

    def advance(self, dt: float) -> None:
        r = self.robot
        for mid in MotorId:
            r.turns[mid] += r.speeds[mid] * dt
        r.t += dt


@pytest.fixture
def rig() -> tuple[StubRobot, BoardWorld, MotorBoard, SensorBoard]:
    robot = StubRobot()
    world = BoardWorld(robot, StubClock(robot), lockstep=True)
    boards = make_boards(world)
    motor, sensor = boards[1], boards[2]
    assert isinstance(motor, MotorBoard) and isinstance(sensor, SensorBoard)
    for board in (motor, sensor):
        (owner,) = board.handle([m.Claim(m.LEASE_MS, NONCE)], HOST)
        assert owner.result == m.ClaimResult.GRANTED
    return robot, world, motor, sensor


def step(motor: MotorBoard, world: BoardWorld, seconds: float) -> None:
    """Advance board time without a host frame (what a silent host looks like)."""
    world.step_to(round(world.now() * 1e6 + seconds * 1e6))
    motor.after_step()


def test_identify_and_read_all(rig: tuple) -> None:
    robot, world, motor, sensor = rig
    (ident,) = motor.handle([m.Identify()], HOST)
    assert ident == m.Ident(1, m.PROTOCOL_MAJOR, m.PROTOCOL_MINOR, 6, 0x0100, 1)
    replies = sensor.handle([m.ReadAll()], HOST)
    assert isinstance(replies[0], m.Status)
    assert replies[0].flags & m.StatusFlag.SIMULATED and replies[0].flags & m.StatusFlag.LOCKSTEP
    assert tuple(type(r) for r in replies) == m.READ_ALL_REPLY[m.Board.SENSOR]
    assert [r.distance_mm for r in replies[1:5]] == [500, 600, 700, 800]
    assert [r.age_ms for r in replies[1:5]] == [0, 0, 0, 0]
    assert replies[5:] == [m.ImuTelemetry(0, m.ImuCode.ABSENT, 0, 0, 0),  # no IMU fitted
                           m.ImuTelemetry(1, m.ImuCode.ABSENT, 0, 0, 0)]
    motor.handle([m.ReadAll()], HOST)
    assert robot.reads == 1  # both boards share one read per instant


def test_speeds_reach_the_robot_and_telemetry_follows(rig: tuple) -> None:
    robot, world, motor, _ = rig
    acks = motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000), m.SetLiftSpeeds(-2000, 0)], HOST)
    assert acks == [m.Ack(0x20, 0), m.Ack(0x21, 0)]
    assert robot.speeds[MotorId.MWF] == 1.0 and robot.speeds[MotorId.MTF] == -2.0
    motor.handle([sim.StepTo(200_000)], HOST)  # within the 250 ms watchdog
    tel = motor.handle([m.ReadAll()], HOST)[1:]
    assert tel[0] == m.MotorTelemetry(0, m.MotorMode.RUN, 0, 1000, 200)
    assert tel[4] == m.MotorTelemetry(4, m.MotorMode.RUN, 0, -2000, -400)
    assert tel[5].mode == m.MotorMode.IDLE


def test_watchdog_trips_stops_every_motor_and_latches_until_cleared(rig: tuple) -> None:
    robot, world, motor, sensor = rig
    motor.handle([m.SetWatchdog(100), m.SetWheelSpeeds(500, 500, 500, 500)], HOST)
    step(motor, world, 0.05)
    assert not motor.watchdog_tripped
    step(motor, world, 0.2)  # 250 ms without a host frame
    assert motor.watchdog_tripped and sensor.watchdog_tripped is False  # sensor never armed
    assert all(v == 0.0 for v in robot.speeds.values())
    status = motor.handle([m.GetStatus()], HOST)[0]
    assert status.flags & m.StatusFlag.WATCHDOG and status.fault == m.MotorFault.WATCHDOG
    # frames alone do not reset it; motion is refused until a Clear
    assert motor.handle([m.SetWheelSpeeds(500, 0, 0, 0)], HOST) == [
        m.Ack(0x20, m.AckResult.WATCHDOG)]
    assert robot.speeds[MotorId.MWF] == 0.0
    assert motor.handle([m.ReadAll()], HOST)[1].mode == m.MotorMode.HOLD
    motor.handle([m.Clear(m.ClearMask.WATCHDOG)], HOST)
    assert motor.handle([m.SetWheelSpeeds(500, 0, 0, 0)], HOST) == [m.Ack(0x20, m.AckResult.OK)]
    assert robot.speeds[MotorId.MWF] == 0.5


def test_watchdog_zero_disables_it(rig: tuple) -> None:
    _, world, motor, _ = rig
    motor.handle([m.SetWatchdog(0)], HOST)
    step(motor, world, 10.0)
    assert not motor.watchdog_tripped


def test_estop_latches_until_an_explicit_clear(rig: tuple) -> None:
    robot, _, motor, _ = rig
    motor.handle([m.SetLiftSpeeds(10000, 10000)], HOST)
    status = motor.handle([m.EStop()], HOST)[0]
    assert status.flags & m.StatusFlag.ESTOP and status.fault == m.MotorFault.ESTOP
    assert all(v == 0.0 for v in robot.speeds.values())
    assert motor.handle([m.Run(4, 100)], HOST) == [m.Ack(0x22, m.AckResult.ESTOP)]
    assert motor.handle([m.Move(0, 100, 100)], HOST) == [m.Ack(0x23, m.AckResult.ESTOP)]
    motor.handle([m.Clear(m.ClearMask.WATCHDOG)], HOST)  # the wrong latch: still stopped
    assert motor.handle([m.Run(4, 100)], HOST) == [m.Ack(0x22, m.AckResult.ESTOP)]
    status = motor.handle([m.Clear(m.ClearMask.ESTOP)], HOST)[0]
    assert not status.flags & m.StatusFlag.ESTOP
    assert motor.handle([m.Run(4, 100)], HOST) == [m.Ack(0x22, m.AckResult.OK)]


def test_move_stops_after_the_turns(rig: tuple) -> None:
    robot, world, motor, _ = rig
    assert motor.handle([m.Move(5, -1500, 1000)], HOST) == [m.Ack(0x23, 0)]
    assert robot.speeds[MotorId.MTB] == -1.0
    for _ in range(10):
        motor.handle([sim.StepTo(round(world.now() * 1e6) + 200_000)], HOST)
    assert robot.speeds[MotorId.MTB] == 0.0
    tel = motor.handle([m.GetMotor(5)], HOST)[0]
    assert tel.mode == m.MotorMode.IDLE and tel.turns_mt == -1600  # stopped at the next poll


def test_stop_and_brake(rig: tuple) -> None:
    robot, _, motor, _ = rig
    motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000), m.SetLiftSpeeds(1000, 1000)], HOST)
    motor.handle([m.Brake(0b010001)], HOST)  # MWF and MTF
    tel = motor.handle([m.ReadAll()], HOST)[1:]
    assert tel[0].mode == m.MotorMode.BRAKE and tel[4].mode == m.MotorMode.IDLE
    assert robot.speeds[MotorId.MWF] == 0.0 and robot.speeds[MotorId.MWB] == 1.0
    motor.handle([m.Stop()], HOST)
    assert all(v == 0.0 for v in robot.speeds.values())


def test_refusals_and_unknown_messages(rig: tuple) -> None:
    robot, _, motor, sensor = rig
    assert motor.handle([m.GetMotor(6)], HOST) == [m.Ack(0x11, m.AckResult.BAD_CHANNEL)]
    assert motor.handle([m.Move(1, 10, 0)], HOST) == [m.Ack(0x23, m.AckResult.BAD_VALUE)]
    assert motor.handle([m.Stop(0x40)], HOST) == [m.Ack(0x24, m.AckResult.BAD_CHANNEL)]
    assert motor.handle([RawMessage(0x33, b"")], HOST) == [m.Ack(0x33, m.AckResult.UNKNOWN_TYPE)]
    assert sensor.handle([m.SetLiftSpeeds(1, 1)], HOST) == [m.Ack(0x21, m.AckResult.NOT_SUPPORTED)]
    assert sensor.handle([m.GetSensor(4)], HOST) == [m.Ack(0x12, m.AckResult.BAD_CHANNEL)]
    assert motor.handle([m.Ack(0, 0)], HOST) == [m.Ack(0xA0, m.AckResult.NOT_SUPPORTED)]
    assert robot.speeds[MotorId.MTF] == 0.0


def test_step_to_is_idempotent_and_lockstep_only(rig: tuple) -> None:
    robot, world, motor, sensor = rig
    # the simulation's messages are the motor board's (docs/protocol.md, section 2)
    assert sensor.handle([sim.StepTo(20_000)], HOST) == [m.Ack(0x7E, m.AckResult.NOT_SUPPORTED)]
    assert sensor.handle([sim.GetTruth()], HOST) == [m.Ack(0x7D, m.AckResult.NOT_SUPPORTED)]
    assert robot.t == 0.0
    assert motor.handle([sim.StepTo(20_000)], HOST) == [sim.StepDone(20_000)]
    assert motor.handle([sim.StepTo(20_000)], HOST) == [sim.StepDone(20_000)]
    assert motor.handle([sim.StepTo(10_000)], HOST) == [sim.StepDone(20_000)]
    assert robot.t == pytest.approx(0.02)
    world.lockstep = False
    assert motor.handle([sim.StepTo(40_000)], HOST) == [m.Ack(0x7E, m.AckResult.NOT_SUPPORTED)]
    # the lease is checked first: another session is told NOT_OWNER, not NOT_SUPPORTED
    assert motor.handle([sim.StepTo(40_000)], 0x15) == [m.Ack(0x7E, m.AckResult.NOT_OWNER)]


def test_sensor_sample_counter_advances_with_new_measurements(rig: tuple) -> None:
    _, world, motor, sensor = rig
    a = sensor.handle([m.GetSensor(0)], HOST)[0].sample
    assert sensor.handle([m.GetSensor(1)], HOST)[0].sample == a
    motor.handle([sim.StepTo(20_000)], HOST)
    assert sensor.handle([m.GetSensor(0)], HOST)[0].sample == (a + 1) & 0xFFFF


def test_a_repeated_reading_keeps_its_sample_number(rig: tuple) -> None:
    """A sensor that has not measured again (its age grew by the step) keeps
    its sample number; one that measured anew advances."""
    robot, world, motor, sensor = rig
    sfr, sfl = (sensor.handle([m.GetSensor(ch)], HOST)[0].sample for ch in (0, 1))
    robot.ages[SensorId.SFR] = 0.02  # the same measurement, 20 ms older
    motor.handle([sim.StepTo(20_000)], HOST)
    assert sensor.handle([m.GetSensor(0)], HOST)[0] == m.SensorTelemetry(0, 0, 500, sfr, 20)
    assert sensor.handle([m.GetSensor(1)], HOST)[0].sample == (sfl + 1) & 0xFFFF


def test_the_sensor_board_serves_each_readings_age_and_the_imu(rig: tuple) -> None:
    robot, world, motor, sensor = rig
    robot.ages = {**robot.ages, **dict(zip(BASE_SENSORS, (0.0123, 0.2, 1.5, 100.0), strict=True))}
    robot.imu = Imu(5.234, -0.756, 1.52, -0.24, 0.0031)
    replies = sensor.handle([m.ReadAll()], HOST)
    assert [r.age_ms for r in replies[1:5]] == [12, 200, 1500, m.AGE_MAX_MS]  # saturated
    assert replies[5:] == [m.ImuTelemetry(0, m.ImuCode.OK, 523, 15, 3),
                           m.ImuTelemetry(1, m.ImuCode.OK, -76, -2, 3)]
    assert sensor.handle([m.GetImu(1)], HOST) == [m.ImuTelemetry(1, m.ImuCode.OK, -76, -2, 3)]
    assert sensor.handle([m.GetImu(2)], HOST) == [m.Ack(m.GetImu.TYPE, m.AckResult.BAD_CHANNEL)]
    assert motor.handle([m.GetImu(0)], HOST) == [m.Ack(m.GetImu.TYPE, m.AckResult.NOT_SUPPORTED)]


@pytest.mark.parametrize(("imu", "pitch", "roll"), [
    (Imu(float("nan"), 1.0, 0.0, 0.0, 0.0),  # an attitude that is not a number: ERROR
     m.ImuTelemetry(0, m.ImuCode.ERROR, 0, 0, 0), m.ImuTelemetry(1, m.ImuCode.OK, 100, 0, 0)),
    (Imu(10.0, 200.0, 0.0, float("inf"), 0.0),  # beyond +-180, a rate that is not a number
     m.ImuTelemetry(0, m.ImuCode.OK, 1000, 0, 0), m.ImuTelemetry(1, m.ImuCode.ERROR, 0, 0, 0)),
    (Imu(-180.0, 180.0, 5000.0, -5000.0, float("nan")),  # rates saturate; an unknown age too
     m.ImuTelemetry(0, m.ImuCode.OK, -18000, 32767, m.AGE_MAX_MS),
     m.ImuTelemetry(1, m.ImuCode.OK, 18000, -32767, m.AGE_MAX_MS)),
])
def test_an_imu_value_the_wire_cannot_carry_goes_as_error_or_saturates(
        rig: tuple, imu: Imu, pitch: m.ImuTelemetry, roll: m.ImuTelemetry) -> None:
    robot, world, motor, sensor = rig
    robot.imu = imu
    assert sensor.handle([m.ReadAll()], HOST)[5:] == [pitch, roll]


def test_a_failed_world_is_a_latched_simulation_fault(rig: tuple) -> None:
    robot, world, motor, sensor = rig
    robot.fail = True
    motor.handle([sim.StepTo(20_000)], HOST)
    status = sensor.handle([m.ReadAll()], HOST)[0]
    assert status.fault == m.MotorFault.SIMULATION and status.flags & m.StatusFlag.FAULT
    truth = motor.handle([sim.GetTruth()], HOST)[0]
    assert truth == sim.Truth(1, 325, 12)


def test_the_pacer_keeps_the_world_up_with_the_wall_clock_one_step_at_a_time(
        rig: tuple) -> None:
    robot, world, motor, _ = rig
    wall = [100.0]
    pacer = Pacer(world, [motor], time_scale=10.0, step_s=0.005, monotonic=lambda: wall[0])
    world.lockstep = True
    assert pacer.step() == Pacer.MAX_WAIT_S and robot.t == 0.0  # lockstep: StepTo only
    world.lockstep = False
    assert pacer.step() == pytest.approx(0.0005)  # the first step is due 0.5 ms from now
    wall[0] += 0.00201  # 20.1 ms of world time are due: four steps, one per call
    waits = [pacer.step() for _ in range(5)]
    assert waits[:4] == [0.0] * 4 and waits[4] > 0.0
    assert robot.t == pytest.approx(0.02)
    motor.handle([m.SetWatchdog(10)], HOST)
    wall[0] += 0.002
    while pacer.step() == 0.0:
        pass
    assert motor.watchdog_tripped  # the boards are polled between steps


def test_a_server_that_stalled_pauses_the_world_instead_of_rushing_its_watchdog(
        rig: tuple) -> None:
    # A loaded machine leaves the server unscheduled for 0.4 s while the
    # host's frames wait on the line.  It reads them when it runs again; the
    # world must not then run the missed 0.4 s in a burst, or the watchdog
    # counts time in which the host was feeding it and trips.
    robot, world, motor, _ = rig
    wall = [100.0]
    pacer = Pacer(world, [motor], time_scale=1.0, step_s=0.005, monotonic=lambda: wall[0])
    world.lockstep = False
    motor.handle([m.SetWatchdog(250)], HOST)
    while pacer.step() == 0.0:
        pass
    wall[0] += 0.4
    motor.handle([m.Heartbeat()], HOST)  # the frame that waited, read at once
    t0 = robot.t
    while pacer.step() == 0.0:
        pass
    assert robot.t - t0 <= Pacer.MAX_LAG_S + 0.005 + 1e-9
    assert not motor.watchdog_tripped
    assert pacer.behind == 1 and pacer.behind_s == pytest.approx(0.4 - Pacer.MAX_LAG_S, abs=0.006)
    assert "fell behind real time 1 time(s), 0.35 s let go" in pacer.report()
    for _ in range(60):  # the server keeps up; the host says nothing for 0.3 s: it trips
        wall[0] += 0.005
        while pacer.step() == 0.0:
            pass
    assert motor.watchdog_tripped and pacer.behind == 1


# -- the side pair (protocol 4.1) ---------------------------------------------------

def side_rig(sensors: tuple[SensorId, ...]) -> tuple[StubRobot, SensorBoard]:
    """A sensor board whose world's robot has the side pair; its snapshot
    holds ``sensors``."""
    robot = StubRobot(sensors)
    world = BoardWorld(robot, StubClock(robot), lockstep=True, side_pair=True)
    sensor = make_boards(world)[2]
    assert isinstance(sensor, SensorBoard)
    return robot, sensor


def test_a_sensor_board_with_the_side_pair_has_six_channels() -> None:
    _, sensor = side_rig(tuple(SensorId))
    (ident,) = sensor.handle([m.Identify()], HOST)
    assert ident == m.Ident(2, m.PROTOCOL_MAJOR, m.PROTOCOL_MINOR, 6, 0x0100, 2)
    assert (m.PROTOCOL_MAJOR, m.PROTOCOL_MINOR) >= (4, 1)  # the side pair came in 4.1
    replies = sensor.handle([m.ReadAll()], HOST)
    assert tuple(type(r) for r in replies) == m.read_all_reply(m.Board.SENSOR, 6)
    tel = [r for r in replies if isinstance(r, m.SensorTelemetry)]
    assert [(t.channel, t.distance_mm) for t in tel] == [(c, 500 + 100 * c) for c in range(6)]
    assert sensor.handle([m.GetSensor(5)], HOST) == [tel[5]]  # SSL
    assert sensor.handle([m.GetSensor(6)], HOST) == [
        m.Ack(m.GetSensor.TYPE, m.AckResult.BAD_CHANNEL)]


def test_a_sensor_board_without_it_has_four_whatever_the_world_reads(rig: tuple) -> None:
    robot, world, motor, sensor = rig
    assert set(SIDE_SENSORS) <= set(robot.sensors)  # the stub reads them; the board has none
    assert sensor.handle([m.Identify()], HOST)[0].channels == 4
    replies = sensor.handle([m.ReadAll()], HOST)
    assert [r.channel for r in replies if isinstance(r, m.SensorTelemetry)] == [0, 1, 2, 3]
    assert sensor.handle([m.GetSensor(4)], HOST) == [
        m.Ack(m.GetSensor.TYPE, m.AckResult.BAD_CHANNEL)]


def test_a_side_sensor_the_world_does_not_read_goes_as_never_measured() -> None:
    """A simulation that does not model the side pair yet: the board invents
    no distance; it says ERROR with the age saturated (docs/protocol.md, "Ages")."""
    _, sensor = side_rig(BASE_SENSORS)
    replies = sensor.handle([m.ReadAll()], HOST)
    tel = [r for r in replies if isinstance(r, m.SensorTelemetry)]
    assert [t.channel for t in tel] == [0, 1, 2, 3, 4, 5]
    assert tel[4] == m.SensorTelemetry(4, m.SensorCode.ERROR, 0, 0, m.AGE_MAX_MS)
    assert tel[5] == m.SensorTelemetry(5, m.SensorCode.ERROR, 0, 0, m.AGE_MAX_MS)


# -- one host owns the boards (protocol 5.0) ----------------------------------------

OTHER = 0x15  # a second host's session


def test_a_second_host_cannot_command_set_the_watchdog_clear_or_step(rig: tuple) -> None:
    robot, world, motor, sensor = rig
    (held,) = motor.handle([m.Claim(m.LEASE_MS, 99)], OTHER)
    assert (held.result, held.session, held.boot) == (m.ClaimResult.HELD, HOST, motor.boot)
    for msg in (m.SetWheelSpeeds(1000, 1000, 1000, 1000), m.SetLiftSpeeds(500, 0),
                m.Run(0, 100), m.Move(0, 100, 100), m.SetWatchdog(0), m.Clear(),
                sim.StepTo(round(world.now() * 1e6) + 20_000)):
        assert motor.handle([msg], OTHER) == [m.Ack(msg.TYPE, m.AckResult.NOT_OWNER)]
    assert sensor.handle([m.SetWatchdog(0)], OTHER) == [
        m.Ack(m.SetWatchdog.TYPE, m.AckResult.NOT_OWNER)]
    assert motor.watchdog_ms == sensor.watchdog_ms == 250
    assert robot.speeds[MotorId.MWF] == 0.0
    # queries are answered; stopping is anyone's right
    assert isinstance(motor.handle([m.GetStatus()], OTHER)[0], m.Status)
    motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000)], HOST)
    assert motor.handle([m.Stop(m.ALL_MOTORS_MASK)], OTHER) == [m.Ack(m.Stop.TYPE, 0)]
    assert robot.speeds[MotorId.MWF] == 0.0
    assert motor.handle([m.EStop()], OTHER)[0].flags & m.StatusFlag.ESTOP


def test_a_second_host_does_not_feed_the_owners_watchdog(rig: tuple) -> None:
    robot, world, motor, sensor = rig
    motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000)], HOST)
    for _ in range(10):  # the other host talks every 50 ms; the owner is silent
        step(motor, world, 0.05)
        motor.handle([m.Heartbeat(), m.ReadAll()], OTHER)
    assert motor.watchdog_tripped and robot.speeds[MotorId.MWF] == 0.0


def test_the_same_session_with_another_nonce_is_another_host(rig: tuple) -> None:
    _, _, motor, _ = rig
    (held,) = motor.handle([m.Claim(m.LEASE_MS, NONCE + 1)], HOST)
    assert held.result == m.ClaimResult.HELD
    (again,) = motor.handle([m.Claim(m.LEASE_MS, NONCE)], HOST)
    assert again.result == m.ClaimResult.GRANTED


def test_the_watchdog_cannot_be_switched_off_while_a_motor_runs(rig: tuple) -> None:
    _, _, motor, _ = rig
    motor.handle([m.SetLiftSpeeds(500, 0)], HOST)
    assert motor.handle([m.SetWatchdog(0)], HOST) == [
        m.Ack(m.SetWatchdog.TYPE, m.AckResult.BAD_VALUE)]
    motor.handle([m.Stop(m.ALL_MOTORS_MASK)], HOST)
    assert motor.handle([m.SetWatchdog(0)], HOST)[0].watchdog_ms == 0


def test_a_lease_released_or_lapsed_can_be_taken(rig: tuple,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    _, _, motor, sensor = rig
    (gone,) = motor.handle([m.Claim(0, NONCE)], HOST)
    assert (gone.result, gone.session) == (m.ClaimResult.RELEASED, 0)
    assert motor.handle([m.Claim(m.LEASE_MS, 5)], OTHER)[0].result == m.ClaimResult.GRANTED
    # The sensor board's holder falls silent: its lease (lockstep: wall time)
    # lapses after the longer of the lease and the watchdog.
    clock = [1000.0]
    monkeypatch.setattr(sensor.lease, "_clock", lambda: clock[0])
    sensor.handle([m.Claim(m.LEASE_MS, NONCE)], HOST)
    clock[0] += m.LEASE_MS / 1000 - 0.01
    (held,) = sensor.handle([m.Claim(m.LEASE_MS, 5)], OTHER)
    assert held.result == m.ClaimResult.HELD and held.lease_cs == 1
    clock[0] += 0.02
    assert sensor.handle([m.Claim(m.LEASE_MS, 5)], OTHER)[0].result == m.ClaimResult.GRANTED
    assert sensor.handle([m.Clear()], HOST) == [m.Ack(m.Clear.TYPE, m.AckResult.NOT_OWNER)]


def test_a_lockstep_holder_silent_past_its_lease_in_wall_time_keeps_its_boards(
        rig: tuple, monkeypatch: pytest.MonkeyPatch) -> None:
    """The world stood still while the holder said nothing for longer than
    the lease (a loaded machine did not schedule it): its next frames are
    obeyed and renew the lease; only another host's claim takes it."""
    _, world, motor, _ = rig
    clock = [1000.0]
    monkeypatch.setattr(motor.lease, "_clock", lambda: clock[0])
    motor.lease.renew()
    clock[0] += 3 * m.LEASE_MS / 1000
    assert motor.handle([sim.StepTo(20_000)], HOST) == [sim.StepDone(20_000)]
    (ack,) = motor.handle([m.SetWheelSpeeds(100, 100, 100, 100)], HOST)
    assert ack == m.Ack(m.SetWheelSpeeds.TYPE, m.AckResult.OK)
    (held,) = motor.handle([m.Claim(m.LEASE_MS, 5)], OTHER)  # renewed by those frames
    assert held.result == m.ClaimResult.HELD and held.session == HOST
    clock[0] += 3 * m.LEASE_MS / 1000
    assert motor.handle([m.Claim(m.LEASE_MS, 5)], OTHER)[0].result == m.ClaimResult.GRANTED
    assert motor.handle([sim.StepTo(40_000)], HOST) == [m.Ack(0x7E, m.AckResult.NOT_OWNER)]
    assert world.now() == pytest.approx(0.02)


def test_a_real_time_holder_silent_past_its_lease_loses_it() -> None:
    """Off lockstep the lease counts the boards' own time: a holder silent
    for longer than it holds nothing, whether or not another host claimed."""
    robot = StubRobot()
    world = BoardWorld(robot, StubClock(robot), lockstep=False)
    motor = make_boards(world)[1]
    motor.handle([m.Claim(m.LEASE_MS, NONCE), m.SetWatchdog(0)], HOST)
    robot.t += 3 * m.LEASE_MS / 1000
    assert motor.handle([m.SetWheelSpeeds(100, 100, 100, 100)], HOST) == [
        m.Ack(m.SetWheelSpeeds.TYPE, m.AckResult.NOT_OWNER)]


def test_a_speed_command_outlives_its_hold_and_stops_without_a_latch(rig: tuple) -> None:
    """A host that falls silent mid-drive: its motors stop after hold_ms (a
    wheel coasts, a lift holds), long before the watchdog latches."""
    robot, world, motor, _ = rig
    motor.handle([m.SetWatchdog(250, 100), m.SetWheelSpeeds(1000, 1000, 1000, 1000),
                  m.SetLiftSpeeds(500, 0)], HOST)
    step(motor, world, 0.08)
    assert robot.speeds[MotorId.MWF] == 1.0 and robot.speeds[MotorId.MTF] == 0.5
    step(motor, world, 0.04)  # 120 ms since the command
    assert all(v == 0.0 for v in robot.speeds.values())
    status = motor.handle([m.GetStatus()], HOST)[0]
    assert status.flags & (m.StatusFlag.WATCHDOG | m.StatusFlag.ESTOP) == 0
    assert motor.held_out == 1
    motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000)], HOST)  # runs again
    assert robot.speeds[MotorId.MWF] == 1.0


def test_commands_each_tick_keep_the_motors_running(rig: tuple) -> None:
    robot, world, motor, _ = rig
    motor.handle([m.SetWatchdog(250, 100)], HOST)
    for _ in range(20):  # 0.4 s of 20 ms ticks
        motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000), m.SetLiftSpeeds(0, 0)], HOST)
        step(motor, world, 0.02)
    assert robot.speeds[MotorId.MWF] == 1.0 and motor.held_out == 0


def test_a_lift_at_its_limit_says_limit_in_its_telemetry_only(rig: tuple) -> None:
    """LIMIT latches nothing: no FAULT flag, Status.fault NONE, the mode as
    commanded; it goes when the lift leaves the end of its stroke."""
    robot, world, motor, _ = rig
    motor.handle([m.SetLiftSpeeds(500, 0)], HOST)
    robot.motor_faults[MotorId.MTF] = "lift limit"
    step(motor, world, 0.01)
    status, *tel = motor.handle([m.ReadAll()], HOST)
    assert not status.flags & m.StatusFlag.FAULT and status.fault == m.MotorFault.NONE
    assert (tel[4].fault, tel[4].mode) == (m.MotorFault.LIMIT, m.MotorMode.RUN)
    assert [t.fault for t in tel[:4] + tel[5:]] == [m.MotorFault.NONE] * 5
    motor.handle([m.SetLiftSpeeds(-500, 0)], HOST)  # away from the end: obeyed
    assert robot.speeds[MotorId.MTF] == -0.5
    del robot.motor_faults[MotorId.MTF]
    step(motor, world, 0.01)
    assert motor.handle([m.GetMotor(4)], HOST)[0].fault == m.MotorFault.NONE


def test_a_motor_fault_latches_and_holds_that_motor_stopped_until_clear(rig: tuple) -> None:
    """OVERCURRENT on MWB: that motor stops (HOLD) and reports it, the FAULT
    flag and Status.fault say it; gone from the motor, it stays latched and
    no command drives MWB until Clear 0x04, which restarts nothing.  A
    later fault on another motor leaves Status.fault the first; a fault the
    protocol has no name for is DRIVER."""
    robot, world, motor, _ = rig
    motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000)], HOST)
    robot.motor_faults[MotorId.MWB] = "overcurrent"
    step(motor, world, 0.01)
    status, *tel = motor.handle([m.ReadAll()], HOST)
    assert status.flags & m.StatusFlag.FAULT and status.fault == m.MotorFault.OVERCURRENT
    assert (tel[1].fault, tel[1].mode) == (m.MotorFault.OVERCURRENT, m.MotorMode.HOLD)
    assert (tel[0].fault, tel[0].mode) == (m.MotorFault.NONE, m.MotorMode.RUN)
    assert robot.speeds[MotorId.MWB] == 0.0 and robot.speeds[MotorId.MWF] == 1.0
    del robot.motor_faults[MotorId.MWB]
    robot.motor_faults[MotorId.MTB] = "hot"
    step(motor, world, 0.01)
    for msg in (m.SetWheelSpeeds(1000, 1000, 1000, 1000), m.Run(1, 500), m.Move(1, 300, 500),
                m.Brake(0b10)):
        assert motor.handle([msg], HOST) == [m.Ack(msg.TYPE, m.AckResult.OK)]
        assert robot.speeds[MotorId.MWB] == 0.0 and motor.modes[1] == m.MotorMode.HOLD
    status, *tel = motor.handle([m.ReadAll()], HOST)
    assert status.fault == m.MotorFault.OVERCURRENT and tel[5].fault == m.MotorFault.DRIVER
    del robot.motor_faults[MotorId.MTB]
    step(motor, world, 0.01)
    status = motor.handle([m.Clear(m.ClearMask.FAULTS)], HOST)[0]
    assert not status.flags & m.StatusFlag.FAULT and status.fault == m.MotorFault.NONE
    assert robot.speeds[MotorId.MWB] == 0.0  # nothing restarted
    motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000)], HOST)
    assert robot.speeds[MotorId.MWB] == 1.0
    assert motor.handle([m.GetMotor(1)], HOST)[0].fault == m.MotorFault.NONE


def test_a_move_reaching_its_stop_point_does_not_lengthen_another_motors_hold(
        rig: tuple) -> None:
    """The hold counts from the host's last motion command only: the wheels
    commanded at 0 ms with a 100 ms hold stop by 110 ms, although a Move on
    MTF (50 mturn at 1 turn/s) reached its stop point, the board's own
    speed change, at 60 ms."""
    robot, world, motor, _ = rig
    motor.handle([m.SetWatchdog(250, 100), m.SetWheelSpeeds(1000, 1000, 1000, 1000),
                  m.Move(4, 50, 1000)], HOST)
    step(motor, world, 0.06)
    assert robot.speeds[MotorId.MTF] == 0.0 and motor.modes[4] == m.MotorMode.IDLE
    assert robot.speeds[MotorId.MWF] == 1.0
    step(motor, world, 0.05)  # 110 ms since the command, 50 ms since the Move stopped
    assert all(v == 0.0 for v in robot.speeds.values()) and motor.held_out == 1


def test_the_watchdog_stays_armed_after_the_lease_is_given_up(rig: tuple) -> None:
    """A host that gives its lease up mid-motion without switching the
    watchdog off still has its motors stopped watchdog_ms after its last
    frame, and the latch set, though another host is talking."""
    robot, world, motor, _ = rig
    motor.handle([m.SetWheelSpeeds(1000, 1000, 1000, 1000), m.Claim(0, NONCE)], HOST)
    for _ in range(6):  # 300 ms; another host polls without a lease
        step(motor, world, 0.05)
        motor.handle([m.GetStatus()], OTHER)
    status = motor.handle([m.GetStatus()], OTHER)[0]
    assert status.flags & m.StatusFlag.WATCHDOG and status.fault == m.MotorFault.WATCHDOG
    assert all(v == 0.0 for v in robot.speeds.values())


def test_a_move_stops_when_the_counter_as_reported_lands_on_its_stop_point(
        rig: tuple) -> None:
    """A Move's stop point in integer milli-turns: from 3.276 turns, -397
    mturn stops at a counter of 2.879 turns (2879 on the wire), where the
    float sum 3.276 - 0.397 = 2.8789999999999996 lies a hair beyond it."""
    robot, world, motor, _ = rig
    robot.turns[MotorId.MWF] = 3.276
    motor.handle([m.Move(0, -397, 1000)], HOST)
    assert robot.speeds[MotorId.MWF] == -1.0
    robot.speeds[MotorId.MWF] = 0.0  # the counter stands on the stop point from here on
    robot.turns[MotorId.MWF] = 2.879
    step(motor, world, 0.001)
    tel = motor.handle([m.GetMotor(0)], HOST)[0]
    assert (tel.mode, tel.turns_mt) == (m.MotorMode.IDLE, 2879)
