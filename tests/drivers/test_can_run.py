"""The whole ascent and descent over CAN, ending exactly as sim:// does: on
python-can's ``virtual`` bus (boards served in this process) and on
``udp_multicast`` (``stairbot fake-boards --can`` in another process), both in
lockstep.  A one-step flight keeps each test to seconds: python-can costs tens
of microseconds a frame and a tick is about twenty frames.  The five-step
default flight runs over the pty in test_serial_run.py; over CAN by hand
(``stairbot fake-boards --can udp_multicast/GROUP --lockstep``, then
``stairbot run --robot`` the URL it prints: about 25 s)."""

from __future__ import annotations

import random
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import can
import pytest

from stairbot.control.robot_config import load_config
from stairbot.drivers.can_link import CanLink
from stairbot.events import Event, EventKind
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.inputs.scenario import Scenario, load_scenario
from stairbot.run.robots import RobotOptions, RobotSession, open_robot
from stairbot.run.runner import RunResult, run

WIRE_TICKS = 3
"""How many ticks apart a phase change over the wire may come from sim://'s."""
SAME = ("outcome", "ascent_end", "steps_climbed", "steps_descended", "pauses", "error", "fell")
ONE_STEP = """
name = "one_step"
description = "One residential step, then a landing, starting close"
[stairs]
count = 1
rise = 0.17
tread = 0.28
top = "landing"
width = 1.0
side_wall = "none"
[start]
distance = 0.2
yaw_deg = 0.0
lateral = 0.0
[sensors]
noise = 0.001
seed = 3
[expect]
outcome = "completed"
ascent_end = "top_reached"
steps_climbed = 1
steps_descended = 1
"""


@pytest.fixture(scope="module")
def scenario_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("can_run") / "one_step.toml"
    path.write_text(ONE_STEP)
    return path


def run_recorded(session: RobotSession) -> tuple[RunResult, list[Event]]:
    events: list[Event] = []
    result = run(session, load_config(), sink=events.append)
    return result, [e for e in events if e.kind in (EventKind.PHASE, EventKind.PAUSE)]


@pytest.fixture(scope="module")
def sim_run(scenario_file: Path) -> tuple[RunResult, list[Event]]:
    return run_recorded(open_robot("sim://", load_config(),
                                   RobotOptions(world=load_scenario(scenario_file))))


def assert_same_end(wire: RunResult, wire_events: list[Event],
                    sim: tuple[RunResult, list[Event]]) -> None:
    ref, ref_events = sim
    assert ref.outcome == "completed" and ref.steps_climbed == 1
    assert {k: getattr(wire, k) for k in SAME} == {k: getattr(ref, k) for k in SAME}
    # Phase for phase, in the same order, and within a few ticks: speeds travel
    # the wire in thousandths of a turn per second, so a slow calibration turn
    # is not quite sim://'s and a threshold may be crossed a tick apart.
    assert [e.message for e in wire_events] == [e.message for e in ref_events]
    assert max(abs(w.time_s - r.time_s) for w, r in zip(wire_events, ref_events, strict=True)
               ) <= WIRE_TICKS * load_config().algorithm.tick + 1e-6
    assert wire.sim_time_s == pytest.approx(ref.sim_time_s, abs=WIRE_TICKS * 0.02 + 1e-6)
    assert wire.final_offset_m == pytest.approx(ref.final_offset_m, abs=0.001)  # mm on the wire
    # The fake boards' world reports its largest pitch a few hundredths of a
    # degree off sim://'s (the serial wire shows the same): not the wire's doing.
    assert wire.max_pitch_deg == pytest.approx(ref.max_pitch_deg, abs=0.25)


def inline_session(scenario: Scenario, channel: str) -> tuple[RobotSession, CanBoardServer]:
    world = make_world(load_config(), scenario, True)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            make_boards(world))
    link = CanLink(InlineBus(can.Bus(interface="virtual", channel=channel), server),
                   timeout_s=2.0)
    robot = LockstepRobot(link, f"can://virtual/{channel}?lockstep=1")
    return RobotSession(robot, robot.clock, f"can://virtual/{channel}", robot.simulated), server


def test_full_ascent_and_descent_over_virtual_can_ends_as_sim_does(
        scenario_file: Path, sim_run: tuple[RunResult, list[Event]]) -> None:
    session, server = inline_session(load_scenario(scenario_file), "full-run")
    try:
        wire, events = run_recorded(session)
        health = session.robot.diagnostics()["link"]
    finally:
        session.close()
        server.bus.shutdown()
    assert_same_end(wire, events, sim_run)
    assert isinstance(health, dict)
    assert health["lost"] == health["timeouts"] == health["malformed"] == 0


@pytest.fixture
def fake_boards_url(scenario_file: Path) -> Iterator[str]:
    group = f"239.74.{random.randrange(1, 255)}.{random.randrange(1, 255)}"
    port = random.randrange(40000, 60000)
    proc = subprocess.Popen(
        [sys.executable, "-m", "stairbot", "fake-boards", "--can",
         f"udp_multicast/{group}?port={port}", "--lockstep", "--scenario", str(scenario_file)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    url = proc.stdout.readline().strip()
    try:
        assert url == f"can://udp_multicast/{group}?port={port}&lockstep=1", url
        yield url
    finally:
        proc.terminate()
        _, err = proc.communicate(timeout=10)
        assert proc.returncode == 0, err
        assert "frames in" in err  # the fake reports its counters on SIGTERM
        assert "this machine only: loopback 127.0.0.1, TTL 0 (Ctrl-C" in err


def test_full_ascent_and_descent_over_udp_multicast_ends_as_sim_does(
        fake_boards_url: str, scenario_file: Path,
        sim_run: tuple[RunResult, list[Event]]) -> None:
    session = open_robot(fake_boards_url + "&timeout=2", load_config())
    try:
        wire, events = run_recorded(session)
        health = session.robot.diagnostics()["link"]
    finally:
        session.close()
    assert_same_end(wire, events, sim_run)
    assert isinstance(health, dict) and health["lost"] == 0 and health["malformed"] == 0
