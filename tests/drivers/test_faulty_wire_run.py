"""A whole flight over a wire that drops, corrupts or delays 5 % of its
frames completes, on serial (a pty) and on CAN (python-can's ``virtual``),
both in lockstep: the link retries, revives within its grace period and
ignores what comes late or twice.  The one-step flight and short timeouts keep
each case to seconds; ``benchmarks/soak_faults.py`` runs the five-step default
flight over ten seeds per wire and fault (its count is in the README)."""

from __future__ import annotations

import threading
from pathlib import Path

import can
import pytest
from test_can_run import ONE_STEP

from stairbot.config import load_config
from stairbot.drivers.board_robot import BoardRobot
from stairbot.drivers.can_link import CanLink
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.fakes.serial_boards import PtyPair, SerialBoardServer, WireFaults
from stairbot.robots import RobotSession, open_robot
from stairbot.runner import RunResult, run
from stairbot.scenario import load_scenario

FAULTS = {
    "drop": {"drop": 0.05},
    "corrupt": {"corrupt": 0.05},
    # late by more than the host's timeout: the request is retried and the
    # late copy must be ignored
    "late": {"late": 0.05, "late_s": 0.03},
}
TIMEOUT = 0.01  # s: a lost frame costs the host this long
GRACE = 0.5  # s: the URLs' default


def faults_of(name: str, seed: int) -> WireFaults:
    return WireFaults(seed=seed, **FAULTS[name])  # type: ignore[arg-type]


def run_serial(scenario_file: Path, faults: WireFaults) -> tuple[RunResult, dict[str, int]]:
    world = make_world(load_config(), load_scenario(scenario_file), lockstep=True)
    pty = PtyPair()
    server = SerialBoardServer(pty.master, world, make_boards(world), faults)
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        session = open_robot(f"serial://{pty.path}?lockstep=1&timeout={TIMEOUT}", load_config())
        return finish(session)
    finally:
        server.stop()
        thread.join(5)
        pty.close()


def run_can(scenario_file: Path, faults: WireFaults, channel: str
            ) -> tuple[RunResult, dict[str, int]]:
    world = make_world(load_config(), load_scenario(scenario_file), True)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            make_boards(world), faults)
    link = CanLink(InlineBus(can.Bus(interface="virtual", channel=channel), server),
                   timeout_s=TIMEOUT, grace_s=GRACE)
    robot = LockstepRobot(link, f"can://virtual/{channel}?lockstep=1")
    try:
        return finish(RobotSession(robot, robot.clock, f"can://virtual/{channel}",
                                   robot.simulated))
    finally:
        server.bus.shutdown()


def finish(session: RobotSession) -> tuple[RunResult, dict[str, int]]:
    try:
        result = run(session, load_config())
        assert isinstance(session.robot, BoardRobot)
        stats = session.robot.link.stats
        health = {"retries": stats.retries, "lost": stats.lost, "revived": stats.revived}
    finally:
        session.close()
    return result, health


@pytest.fixture(scope="module")
def scenario_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("faulty_run") / "one_step.toml"
    path.write_text(ONE_STEP)
    return path


@pytest.mark.parametrize("wire", ["serial", "can"])
@pytest.mark.parametrize("fault", sorted(FAULTS))
def test_a_flight_over_a_wire_with_5_percent_faults_completes(
        scenario_file: Path, wire: str, fault: str) -> None:
    faults = faults_of(fault, seed=11)
    if wire == "serial":
        result, health = run_serial(scenario_file, faults)
    else:
        result, health = run_can(scenario_file, faults, f"faulty-{fault}")
    assert result.error is None, result.error
    assert (result.outcome, result.steps_climbed, result.steps_descended, result.fell) == (
        "completed", 1, 1, False)
    assert result.fault is None
    # the faults happened and the link rode them out (a speed command whose Ack
    # never came is counted lost and superseded by the next tick's, not fatal)
    assert health["retries"] > 0
