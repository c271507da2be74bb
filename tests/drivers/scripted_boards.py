"""Fake boards in lockstep over a world whose snapshot a test sets, served
inline (no thread) on either wire.  (A module of its own, not conftest.py:
the wire-quality and the side-pair tests share it.)"""

from __future__ import annotations

import contextlib
import itertools
import socket
from collections.abc import Callable, Iterator, Mapping

import can

from stairbot.drivers.can_link import CanLink
from stairbot.drivers.link import BoardLink
from stairbot.drivers.serial_link import SerialLink
from stairbot.events import Event
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import Board, make_boards
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.fakes.serial_boards import InlineChannel, SerialBoardServer
from stairbot.hardware import (
    BASE_SENSORS,
    SIDE_SENSORS,
    Imu,
    MotorId,
    MotorState,
    SensorId,
    SensorReading,
    Snapshot,
)

WIRES = ("serial", "can")
_channels = itertools.count()


class Scripted:
    """The robot behind the fake boards: the snapshot the test sets, at the
    world's time; with the side pair (``side_pair``) six readings, else four;
    ``motor_faults``: what each motor reports (none unless set)."""

    def __init__(self, side_pair: bool = False) -> None:
        self.t = 0.0
        self.sensors: tuple[SensorId, ...] = BASE_SENSORS + (SIDE_SENSORS if side_pair else ())
        self.ages: Mapping[SensorId, float] = dict.fromkeys(SensorId, 0.0)
        self.distances: Mapping[SensorId, float] = dict.fromkeys(SensorId, 0.5)
        self.imu: Imu | None = None
        self.motor_faults: Mapping[MotorId, str] = {}

    def read(self) -> Snapshot:
        return Snapshot(self.t, {s: SensorReading(self.distances[s], age_s=self.ages[s])
                                 for s in self.sensors},
                        {k: MotorState(0.0, 0.0, self.motor_faults.get(k)) for k in MotorId},
                        imu=self.imu)

    def command(self, speeds: Mapping[MotorId, float]) -> None:
        pass

    def stop_all(self) -> None:
        pass


class ScriptedClock:
    def __init__(self, robot: Scripted) -> None:
        self.robot = robot

    def now(self) -> float:
        return self.robot.t

    def advance(self, dt: float) -> None:
        self.robot.t += dt


Boards = Callable[[BoardWorld], dict[int, Board]]


def scripted_world(side_pair: bool = False, lockstep: bool = True) -> BoardWorld:
    """A Scripted world; ``side_pair``: the robot (and so the sensor board) has it."""
    robot = Scripted(side_pair)
    return BoardWorld(robot, ScriptedClock(robot), lockstep=lockstep, side_pair=side_pair)


@contextlib.contextmanager
def link_to(kind: str, world: BoardWorld, boards: dict[int, Board]) -> Iterator[BoardLink]:
    """A host link to ``boards`` served inline on ``kind`` (serial: a socket
    pair; can: a fresh python-can virtual channel)."""
    if kind == "serial":
        host, end = socket.socketpair()
        server = SerialBoardServer(end.fileno(), world, boards)
        link: BoardLink = SerialLink(InlineChannel(host.detach(), server), timeout_s=0.5)
        try:
            yield link
        finally:
            with contextlib.suppress(OSError):  # closed already by the robot that used it
                link.close()
            end.close()
    else:
        channel = f"quality-{next(_channels)}"
        can_server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world, boards)
        link = CanLink(InlineBus(can.Bus(interface="virtual", channel=channel), can_server),
                       timeout_s=0.5, retries=0)
        try:
            yield link
        finally:
            link.close()
            can_server.bus.shutdown()


@contextlib.contextmanager
def wired(kind: str, boards: Boards = make_boards, *, side_pair: bool = False,
          host_side_pair: str | None = None
          ) -> Iterator[tuple[LockstepRobot, Scripted, list[Event]]]:
    """Fake boards in lockstep over a Scripted world (``side_pair``: its robot
    and sensor board have the pair); the host's robot (``host_side_pair``:
    where its config gives it the pair, as ``wanted_side_pair`` says), the
    world's robot and the events the host told."""
    world = scripted_world(side_pair)
    assert isinstance(world.robot, Scripted)
    events: list[Event] = []
    with link_to(kind, world, boards(world)) as link:
        host = LockstepRobot(link, f"{kind}://inline?lockstep=1", sink=events.append,
                             side_pair=host_side_pair)
        try:
            yield host, world.robot, events
        finally:
            host.close()
