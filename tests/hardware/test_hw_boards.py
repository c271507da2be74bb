"""The driver against boards: identity, a whole read, zero speeds, the
e-stop latched and cleared (also while another thread reads), the link over
many reads, an idle host's keepalive.  Run: see conftest.py."""

from __future__ import annotations

import threading
import time

import pytest

from stairbot.drivers import messages as m
from stairbot.drivers.board_robot import BoardRobot
from stairbot.hardware import BASE_SENSORS, SIDE_SENSORS, ZERO_SPEEDS, MotorId
from stairbot.inputs.config import RobotConfig

pytestmark = pytest.mark.hardware

ESTOP_CONFIRM_S = 0.1  # issue 11: every EStop acknowledged within 100 ms


def latched(robot: BoardRobot, flag: m.StatusFlag) -> set[str]:
    """The boards whose last Status has ``flag`` (read afresh)."""
    robot.read()
    return {m.Board(b).name.lower() for b, s in robot.status.items() if s.flags & flag}


def test_both_boards_answer_with_their_identity(boards: BoardRobot) -> None:
    ident = boards.identity()
    assert set(ident) == {"motor", "sensor"}
    for board in ident.values():
        assert board["uptime_ms"] >= 0
    assert not boards.latched, f"the boards hold latches: {boards.latched} (stairbot clear)"


def test_a_read_has_every_motor_and_sensor_and_fresh_ages(boards: BoardRobot,
                                                          hw_config: RobotConfig) -> None:
    """Every sensor the robot has: the side pair too when its config has it."""
    snap = boards.read()
    assert set(snap.motors) == set(MotorId)
    side = SIDE_SENSORS if hw_config.sensors.has_side_pair else ()
    assert set(snap.sensors) == set(BASE_SENSORS + side)
    for sid, reading in snap.sensors.items():
        assert 0 <= reading.age_s < 0.5, (sid, reading)
    if snap.imu is not None:
        assert snap.imu.age_s < 0.5


def test_zero_speeds_leave_every_motor_at_rest(boards: BoardRobot) -> None:
    boards.command(ZERO_SPEEDS)
    time.sleep(0.1)
    before = boards.read()
    time.sleep(0.3)
    after = boards.read()
    for mid in MotorId:
        assert abs(after.motors[mid].turns - before.motors[mid].turns) < 0.01, mid
        assert after.motors[mid].fault is None, (mid, after.motors[mid].fault)


def test_the_estop_latches_on_both_boards_and_clear_releases_it(boards: BoardRobot) -> None:
    t0 = time.monotonic()
    boards.estop()
    assert time.monotonic() - t0 < ESTOP_CONFIRM_S * 5
    assert boards.estopped
    assert latched(boards, m.StatusFlag.ESTOP) == {"motor", "sensor"}
    boards.clear()
    assert not boards.estopped
    assert latched(boards, m.StatusFlag.ESTOP) == set()


def test_an_estop_from_another_thread_gets_through_reads_in_progress(
        boards: BoardRobot) -> None:
    stop = threading.Event()
    errors: list[BaseException] = []

    def reader() -> None:
        try:
            while not stop.is_set():
                boards.read()
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    thread = threading.Thread(target=reader)
    thread.start()
    try:
        time.sleep(0.2)
        boards.estop()
        deadline = time.monotonic() + 1.0
        while time.monotonic() < deadline and not all(
                s.flags & m.StatusFlag.ESTOP for s in boards.status.values()):
            time.sleep(0.01)
    finally:
        stop.set()
        thread.join(5)
    assert not errors, errors
    assert latched(boards, m.StatusFlag.ESTOP) == {"motor", "sensor"}
    boards.clear()
    assert latched(boards, m.StatusFlag.ESTOP) == set()


def test_the_link_holds_over_500_reads(boards: BoardRobot) -> None:
    for _ in range(500):
        boards.read()
    stats = boards.link.stats
    assert stats.lost == 0, boards.health()
    assert stats.crc_errors + stats.malformed <= stats.frames_rx // 100, boards.health()


def test_an_idle_host_keeps_the_watchdog_fed(boards: BoardRobot) -> None:
    boards.read()
    time.sleep(max(1.0, 4 * boards.watchdog_ms / 1000))  # only the keepalive talks
    assert latched(boards, m.StatusFlag.WATCHDOG) == set()
