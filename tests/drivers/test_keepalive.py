"""The board robot's keepalive: while the control loop is idle, Heartbeats
feed the boards' watchdogs.  The boards are served inline (no server thread,
no pacing), so the boards' clock and the host's are driven by the test
together: no test here waits on the wall clock against a watchdog."""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections.abc import Callable, Iterator

from stairbot.control.robot_config import load_config
from stairbot.drivers.board_robot import BoardRobot
from stairbot.drivers.serial_link import SerialLink
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import Board, make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.serial_boards import InlineChannel, SerialBoardServer
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario

CONFIG: RobotConfig = load_config()
SCENARIO: Scenario = load_scenario()


@contextlib.contextmanager
def inline_robot(keepalive: bool, monotonic: Callable[[], float] = time.monotonic
                 ) -> Iterator[tuple[BoardRobot, BoardWorld, dict[int, Board]]]:
    """Fake boards not in lockstep, served inline on a socket pair: their
    world moves only when the test advances it.  Watchdog 400 ms."""
    world = make_world(CONFIG, SCENARIO, lockstep=False)
    boards = make_boards(world)
    host, board_end = socket.socketpair()
    server = SerialBoardServer(board_end.fileno(), world, boards)
    link = SerialLink(InlineChannel(host.detach(), server), timeout_s=0.5)
    robot = BoardRobot(link, "serial://inline", watchdog_ms=400, keepalive=keepalive,
                       monotonic=monotonic)
    try:
        yield robot, world, boards
    finally:
        robot.close()
        board_end.close()


def test_an_idle_robot_keeps_the_watchdogs_fed() -> None:
    """Heartbeats alone feed the boards' 400 ms watchdogs through 1.2 s of
    board time with nothing from the control loop; without them they trip.
    The boards' clock and the host's move together, driven by the test."""
    wall = [0.0]
    with inline_robot(keepalive=False, monotonic=lambda: wall[0]) as (robot, world, boards):

        def let_pass(seconds: float, heartbeat: bool) -> None:
            for _ in range(round(seconds / 0.05)):
                wall[0] += 0.05
                world.advance(0.05)
                for board in boards.values():
                    board.poll()
                if heartbeat:  # what the keepalive thread does each period
                    robot.heartbeat()
                    robot.flush()

        before = robot.link.stats.frames_tx
        let_pass(1.2, heartbeat=True)
        assert not any(b.watchdog_tripped for b in boards.values())
        robot.read()  # no watchdog trip
        assert robot.link.stats.frames_tx - before >= 2 * 10  # a Heartbeat a board per 0.1 s
        let_pass(0.5, heartbeat=False)
        assert all(b.watchdog_tripped for b in boards.values())


def test_the_keepalive_thread_sends_the_heartbeats() -> None:
    with inline_robot(keepalive=True) as (robot, _world, _boards):
        calls: list[int] = []
        done = threading.Event()
        heartbeat = robot.heartbeat

        def spy() -> None:
            heartbeat()
            calls.append(1)
            if len(calls) >= 3:
                done.set()

        before = robot.link.stats.frames_tx
        robot.heartbeat = spy  # type: ignore[method-assign]
        assert done.wait(30.0)  # every 0.1 s; the bound is only for a stuck thread
        assert robot.link.stats.frames_tx > before
