"""Raw frames to a file (``log=FILE`` on ``can://`` and ``serial://``): a CAN
run's candump log decodes with the cantools CLI and the shipped DBC, every
frame known, and reads back with python-can; a serial run's log has a line
per frame that our frame decoder reads; the file holds each frame before
the robot closes; a bad path is one line and exit 2."""

from __future__ import annotations

import itertools
import subprocess
import sys
import threading
from collections.abc import Iterator
from importlib import resources
from pathlib import Path

import can
import pytest

from stairbot.control.robot_config import load_config
from stairbot.drivers.board_robot import BoardRobot
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.frame_log import read_serial_log
from stairbot.drivers.serial_link import SerialLink
from stairbot.drivers.serial_wire import decode_frame
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer
from stairbot.fakes.serial_boards import PtyPair, SerialBoardServer
from stairbot.hardware import MotorId
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotSession, open_robot

_names = itertools.count()
# a lockstep run's log: the real boards' DBC and the simulation's, concatenated
LOCKSTEP_DBC = (resources.files("stairbot.drivers").joinpath("stairbot.dbc").read_text()
                + resources.files("stairbot.fakes").joinpath("stairbot_sim.dbc").read_text())


def drive(session: RobotSession, ticks: int = 10) -> BoardRobot:
    robot = session.robot
    assert isinstance(robot, BoardRobot)
    for _ in range(ticks):
        robot.read()
        robot.command({MotorId.MWF: 0.5, MotorId.MTF: 0.2})
        session.clock.advance(0.02)
    robot.estop()
    robot.clear()
    return robot


@pytest.fixture
def can_boards() -> Iterator[str]:
    """Fake boards in lockstep on a virtual bus, served from a thread."""
    channel = f"frame-log-{next(_names)}"
    world = make_world(load_config(), load_scenario(), True)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            make_boards(world))
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    yield f"can://virtual/{channel}?lockstep=1&timeout=1"
    server.stop()
    thread.join(5)
    server.bus.shutdown()


def test_a_can_run_logged_as_candump_decodes_with_cantools_every_frame_known(
        can_boards: str, tmp_path: Path) -> None:
    log = tmp_path / "run.log"
    session = open_robot(f"{can_boards}&log={log}", load_config())
    robot = drive(session)
    link = robot.link
    assert isinstance(link, CanLink)
    assert link.log is not None
    written = log.read_text().splitlines()  # flushed as written: on disk before close
    assert len(written) == link.log.frames >= link.stats.frames_tx + link.stats.frames_rx > 0
    session.close()
    lines = log.read_text().splitlines()
    sent = [x for x in lines if x.endswith(" T")]
    assert len(sent) == link.stats.frames_tx and len(lines) - len(sent) >= link.stats.frames_rx
    dbc = tmp_path / "lockstep.dbc"
    dbc.write_text(LOCKSTEP_DBC)
    decoded = subprocess.run(
        [sys.executable, "-m", "cantools", "decode", "--single-line", "-m", "0x1FFC0000",
         str(dbc)],
        input=log.read_text(), capture_output=True, text=True, check=True).stdout.splitlines()
    assert len(decoded) == len(lines)
    assert [x for x in decoded if "Unknown frame id" in x] == []
    names = {x.split(" :: ")[1].split("(")[0] for x in decoded}
    assert {"Identify_Motor", "Ident_Sensor", "ReadAll_All", "MotorTelemetry_Motor",
            "SetWheelSpeeds_Motor", "Ack_Motor", "EStop_All", "Clear_All",
            "StepTo_Motor"} <= names
    # python-can reads it back, frame for frame, for can.Player to replay
    back = list(can.LogReader(str(log)))
    assert len(back) == len(lines) and all(f.is_extended_id for f in back)
    assert [f.is_rx for f in back].count(False) == len(sent)


def test_a_can_run_logged_as_asc_reads_back(can_boards: str, tmp_path: Path) -> None:
    log = tmp_path / "run.asc"
    session = open_robot(f"{can_boards}&log={log}", load_config())
    link = drive(session, ticks=3).link
    assert isinstance(link, CanLink)
    session.close()  # its last frames (Stop, SetWatchdog 0) are logged too
    back = list(can.LogReader(str(log)))
    assert len([f for f in back if not f.is_rx]) == link.stats.frames_tx
    assert link.describe()["frame_log"] == {"path": str(log), "frames": len(back),
                                            "failed": None}


def test_a_serial_run_logs_a_line_per_frame_that_our_decoder_reads(tmp_path: Path) -> None:
    world = make_world(load_config(), load_scenario(), lockstep=True)
    pty = PtyPair()
    server = SerialBoardServer(pty.master, world, make_boards(world))
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    log = tmp_path / "run.txt"
    try:
        session = open_robot(f"serial://{pty.path}?lockstep=1&timeout=0.5&log={log}",
                             load_config())
        link = drive(session).link
        assert isinstance(link, SerialLink)
        session.close()
    finally:
        server.stop()
        thread.join(5)
        pty.close()
    lines = read_serial_log(log)
    frames = [(direction, decode_frame(wire[:-1])) for _, direction, wire in lines]
    assert all(wire.endswith(b"\x00") and wire.count(0) == 1 for _, _, wire in lines)
    sent = [f for d, f in frames if d == "TX"]
    heard = [f for d, f in frames if d == "RX"]
    assert len(sent) == link.stats.frames_tx
    assert not any(f.from_board for f in sent) and all(f.from_board for f in heard)
    assert len(heard) >= link.stats.frames_rx > 0
    assert {f.session for f in sent} == {link.session}
    times = [t for t, _, _ in lines]
    assert times == sorted(times)


@pytest.mark.parametrize(("url", "words"), [
    ("can://virtual/x?log=/nonexistent/dir/run.log", "cannot write /nonexistent/dir/run.log"),
    ("can://virtual/x?log=run.bin", "'run.bin' has no frame-log extension; allowed: .log"),
    ("can://virtual/x?log=", "no frame-log extension"),
    ("serial://loop://?log=/nonexistent/dir/run.txt", "cannot write /nonexistent/dir/run.txt"),
    ("serial://loop://?log=", "no file name"),
])
def test_a_bad_log_path_is_one_line_and_exit_2(
        url: str, words: str, capsys: pytest.CaptureFixture[str]) -> None:
    from stairbot.cli import main

    assert main(["run", "--robot", url]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err and "Traceback" not in err
