"""The motor board of the qemu-stm32f4 port (firmware/port/stm32f4:
sb_motor_qemu.elf, the trivial plant behind its HAL) in qemu-system-arm's
netduinoplus2 (an STM32F405), its USART1 on a pty, driven by the host's own
serial driver (SerialLink, handshake.open_board) as test_motor_board.py
drives the native board: Identify and the protocol version, the boot id the
image was given, one owner, speeds and counters in ReadAll, the watchdog
tripping and latching, the e-stop latched until Clear.  And the image on the
plant link (sb_motor_qemu_link.elf, USART2 on a socket answered by
stairbot.fakes.plant_link from a lockstep world), started as the fake
boards start the native programs (FirmwareBoard): its serial number, clock
and motors are the world's, and StepTo and GetTruth reach it.

Skips, saying so, without make, arm-none-eabi-gcc (with picolibc) or
qemu-system-arm (scripts/test installs them).  Each test has its own QEMU,
stopped when it ends."""

from __future__ import annotations

import secrets
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from board_host import LEASE_MS, MOTOR, NONCE, flags, host, ok, one, owner, read_all, until
from firmware_build import LIFT_LIMIT, WHEEL_LIMIT

from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers import units as u
from stairbot.drivers.handshake import check_version, open_board, release_board
from stairbot.drivers.serial_link import SerialLink
from stairbot.fakes import sim_messages as sm
from stairbot.fakes.firmware_boards import FirmwareBoard
from stairbot.inputs.scenario import load_scenario

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from qemu_board import (  # noqa: E402
    QemuBoard,
    build_images,
    missing_tools,
    run_board,
    run_linked,
)

PLANT_SERIAL = 4321
SENSOR = m.Board.SENSOR


@pytest.fixture(scope="module")
def images(tmp_path_factory: pytest.TempPathFactory) -> Path:
    missing = missing_tools()
    if missing:
        pytest.skip(f"missing {', '.join(missing)}: scripts/test installs make, "
                    "gcc-arm-none-eabi, picolibc-arm-none-eabi and qemu-system-arm")
    return build_images(tmp_path_factory.mktemp("qemu"))


@pytest.fixture
def board(images: Path) -> Iterator[QemuBoard]:
    with run_board(images / "sb_motor_qemu.elf", secrets.randbits(32) | 1) as running:
        yield running


def test_identify_the_protocol_version_and_one_owner(board: QemuBoard) -> None:
    with host(board.path) as link:
        ident, status = link.exchange(MOTOR, [m.Identify(), m.GetStatus()]).messages
        assert isinstance(ident, m.Ident) and isinstance(status, m.Status)
        assert (ident.board, ident.protocol_major, ident.protocol_minor, ident.channels,
                ident.serial) == (MOTOR, m.PROTOCOL_MAJOR, m.PROTOCOL_MINOR, 6, 1)
        check_version(f"serial://{board.path}", MOTOR, ident)
        assert status.flags & m.StatusFlag.SIMULATED and not status.flags & m.StatusFlag.LOCKSTEP
        assert one(link, m.GetSensor(0)) == ok(m.GetSensor, m.AckResult.NOT_SUPPORTED)
        assert one(link, m.GetMotor(6)) == ok(m.GetMotor, m.AckResult.BAD_CHANNEL)
    with owner(board.path) as first, host(board.path, avoid=first.session) as second:
        claimed = one(first, m.Claim(LEASE_MS, NONCE))
        assert isinstance(claimed, m.Owner) and claimed.result == m.ClaimResult.GRANTED
        assert claimed.boot == board.boot  # the id QEMU's loader wrote before reset
        held = one(second, m.Claim(LEASE_MS, NONCE + 1))
        assert isinstance(held, m.Owner) and held.result == m.ClaimResult.HELD
        assert (held.session, held.boot) == (first.session, board.boot)
        assert one(second, m.Run(0, 500)) == ok(m.Run, m.AckResult.NOT_OWNER)
        assert read_all(second)[1][0].mode == m.MotorMode.IDLE


def test_speeds_clamped_and_the_counters_on_the_boards_clock(board: QemuBoard) -> None:
    with owner(board.path) as link:
        assert one(link, m.SetLiftSpeeds(2000, -2000)) == ok(m.SetLiftSpeeds)
        first, before = read_all(link)
        until("the lifts to move", lambda: all(
            abs(a.turns_mt - b.turns_mt) > 50 for a, b in zip(
                read_all(link)[1][4:], before[4:], strict=True)))
        status, tel = read_all(link)
        assert [t.mode for t in tel[4:]] == [m.MotorMode.RUN] * 2
        assert (tel[4].speed_mtps, tel[5].speed_mtps) == (2000, -2000)
        # the plant integrates on SysTick's milliseconds: 2 milli-turns each
        elapsed_ms = status.uptime_ms - first.uptime_ms
        assert elapsed_ms > 0
        assert tel[4].turns_mt - before[4].turns_mt == 2 * elapsed_ms
        assert tel[5].turns_mt - before[5].turns_mt == -2 * elapsed_ms
        assert one(link, m.SetWheelSpeeds(500, -500, 5000, -32767)) == ok(m.SetWheelSpeeds)
        assert one(link, m.SetLiftSpeeds(20000, 0)) == ok(m.SetLiftSpeeds)
        clamped = [500, -500, WHEEL_LIMIT, -WHEEL_LIMIT, LIFT_LIMIT, 0]  # each motor's limit
        until("the measured speeds", lambda: [
            t.speed_mtps for t in read_all(link)[1]] == clamped)
        assert [t.mode for t in read_all(link)[1]] == [m.MotorMode.RUN] * 5 + [m.MotorMode.IDLE]
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)


def test_the_watchdog_stops_the_motors_and_latches_until_clear(board: QemuBoard) -> None:
    with owner(board.path) as link, host(board.path, avoid=link.session) as other:
        assert one(link, m.SetWheelSpeeds(300, 300, 300, 300)) == ok(m.SetWheelSpeeds)
        # the owner falls silent; another host's polling does not feed its watchdog
        until("the watchdog", lambda: bool(read_all(other)[0].flags & m.StatusFlag.WATCHDOG))
        status, tel = read_all(link)
        assert status.fault == m.MotorFault.WATCHDOG
        assert all(t.mode == m.MotorMode.HOLD for t in tel), tel
        until("every motor stopped", lambda: all(t.speed_mtps == 0 for t in read_all(other)[1]))
        # latched: a frame after the timeout does not un-trip it; motion is refused
        assert one(link, m.Run(0, 300)) == ok(m.Run, m.AckResult.WATCHDOG)
        assert flags(one(link, m.GetStatus())) & m.StatusFlag.WATCHDOG
        cleared = one(link, m.Clear(0x02))
        assert not flags(cleared) & m.StatusFlag.WATCHDOG
        assert all(t.mode == m.MotorMode.HOLD for t in read_all(link)[1])  # nothing restarts
        assert one(link, m.Run(0, 300)) == ok(m.Run)
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)


def test_the_estop_latches_until_the_owners_clear(board: QemuBoard) -> None:
    with owner(board.path) as link, host(board.path, avoid=link.session) as other:
        assert one(link, m.SetWheelSpeeds(300, 300, 300, 300)) == ok(m.SetWheelSpeeds)
        stopped = one(other, m.EStop())  # anyone may stop the robot
        assert flags(stopped) & m.StatusFlag.ESTOP
        assert isinstance(stopped, m.Status) and stopped.fault == m.MotorFault.ESTOP
        assert all(t.mode == m.MotorMode.HOLD for t in read_all(link)[1])
        assert one(link, m.SetWheelSpeeds(300, 300, 300, 300)) == ok(
            m.SetWheelSpeeds, m.AckResult.ESTOP)
        assert flags(one(link, m.Clear(0x06))) & m.StatusFlag.ESTOP  # only bit 0x01 clears it
        assert one(other, m.Clear(0x01)) == ok(m.Clear, m.AckResult.NOT_OWNER)
        assert flags(one(link, m.Clear(0x01))) & 0x07 == 0
        assert all(t.mode != m.MotorMode.RUN for t in read_all(link)[1])
        assert one(link, m.Run(0, 300)) == ok(m.Run)
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)


@pytest.fixture
def linked(images: Path) -> Iterator[tuple[FirmwareBoard, SerialLink]]:
    """The plant-link image on a lockstep world, and a host's link on its USART1."""
    with run_linked(images / "sb_motor_qemu_link", MOTOR, load_config(), load_scenario(),
                    PLANT_SERIAL) as running:
        yield running


@pytest.fixture
def sensor_linked(images: Path) -> Iterator[tuple[FirmwareBoard, SerialLink]]:
    """The sensor board's image on a lockstep world, and a host's link on its USART1."""
    with run_linked(images / "sb_sensor_qemu_link", SENSOR, load_config(), load_scenario(),
                    PLANT_SERIAL) as running:
        yield running


def test_the_plant_link_image_runs_on_the_worlds_clock_and_steps(
        linked: tuple[FirmwareBoard, SerialLink]) -> None:
    board, link = linked
    ident, status = link.exchange(MOTOR, [m.Identify(), m.GetStatus()]).messages
    assert isinstance(ident, m.Ident) and ident.serial == PLANT_SERIAL  # the plant's hello
    assert board.plant.greeted
    assert isinstance(status, m.Status)
    assert status.flags & (m.StatusFlag.SIMULATED | m.StatusFlag.LOCKSTEP) == (
        m.StatusFlag.SIMULATED | m.StatusFlag.LOCKSTEP)
    open_board(link, "qemu", MOTOR, lockstep=True, watchdog_ms=250, hold_ms=0, nonce=NONCE,
               lease_ms=LEASE_MS, wait_s=lambda _s: None)
    try:
        # in lockstep the board's clock is the world's: it stands still until a StepTo
        before, tel0 = read_all(link)
        assert one(link, m.SetWheelSpeeds(500, 500, 500, 500)) == ok(m.SetWheelSpeeds)
        assert read_all(link)[0].uptime_ms == before.uptime_ms
        target = round(board.plant.world.now() * 1e6) + 200_000
        assert one(link, sm.StepTo(target)) == sm.StepDone(target)
        after, tel = read_all(link)
        assert after.uptime_ms - before.uptime_ms == 200
        assert all(t.mode == m.MotorMode.RUN for t in tel[:4])
        assert all(b.turns_mt > a.turns_mt for a, b in zip(tel0[:4], tel[:4], strict=True))
        truth = one(link, sm.GetTruth())
        assert isinstance(truth, sm.Truth) and not truth.flags & 1
        assert one(link, m.Stop(m.ALL_MOTORS_MASK)) == ok(m.Stop)
        assert board.plant.stats.commands > 0 and board.plant.stats.steps == 1
    finally:
        release_board(link, MOTOR, NONCE)


def test_the_sensor_image_reports_the_worlds_ranges_and_imu(
        sensor_linked: tuple[FirmwareBoard, SerialLink]) -> None:
    board, link = sensor_linked
    ident, status = link.exchange(SENSOR, [m.Identify(), m.GetStatus()]).messages
    assert isinstance(ident, m.Ident) and isinstance(status, m.Status)
    channels = m.BASE_SENSOR_CHANNELS  # the default robot has no side pair
    assert (ident.board, ident.serial, ident.channels) == (SENSOR, PLANT_SERIAL, channels)
    assert status.flags & (m.StatusFlag.SIMULATED | m.StatusFlag.LOCKSTEP) == (
        m.StatusFlag.SIMULATED | m.StatusFlag.LOCKSTEP)
    _, *tel = link.exchange(SENSOR, [m.ReadAll()]).messages
    ranges = [t for t in tel if isinstance(t, m.SensorTelemetry)]
    imu = [t for t in tel if isinstance(t, m.ImuTelemetry)]
    assert [t.channel for t in ranges] == list(range(channels))
    assert [t.axis for t in imu] == [int(a) for a in m.IMU_AXES]
    # the world stands still in lockstep: what it measures now is what the board said
    snap = board.plant.world.snapshot()
    assert snap is not None
    for t in ranges:
        want = u.reading_to_wire(t.channel, snap.sensors[m.SENSOR_CHANNELS[t.channel]], 0)
        assert (t.status, t.distance_mm) == (want.status, want.distance_mm), (t, want)
        assert abs(t.age_ms - want.age_ms) <= 1, (t, want)  # each side rounds to the ms
    for t in imu:
        want_imu = u.imu_to_wire(snap.imu, m.ImuAxis(t.axis))
        assert (t.status, t.angle_cdeg, t.rate_ddps) == (
            want_imu.status, want_imu.angle_cdeg, want_imu.rate_ddps), (t, want_imu)
    assert any(t.status == m.SensorCode.OK for t in ranges), ranges
    (refused,) = link.exchange(SENSOR, [m.GetMotor(0)]).messages  # the motor board's
    assert refused == ok(m.GetMotor, m.AckResult.NOT_SUPPORTED)
    assert board.plant.stats.queries > 0
