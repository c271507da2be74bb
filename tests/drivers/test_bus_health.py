"""The CAN bus's own health: its state (python-can's ``bus.state``), error
frames apart from CRC errors, a flood from another node named by its id,
and a bus-off or a flood stopping the run with the robot's emergency stop
latched.  The fake boards in lockstep, inline on python-can's virtual bus,
behind a bus double that reports a state; the link's clock is a counter
that moves only while the bus is idle, so no figure depends on the machine's
speed."""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import dataclass

import can
import pytest

from stairbot.control.robot_config import load_config
from stairbot.drivers.bus_health import FLOOD_FRAMES_PER_S, FLOOD_WINDOW_S
from stairbot.drivers.can_link import CanLink
from stairbot.errors import LinkLostError
from stairbot.events import Event
from stairbot.fakes.boards import Board, make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.fakes.serial_boards import WireFaults
from stairbot.inputs.scenario import load_scenario

_names = itertools.count()
FLOOD = int(FLOOD_FRAMES_PER_S * FLOOD_WINDOW_S) + 1  # one frame past the limit


class StatefulBus(InlineBus):
    """The boards inline, a ``state`` the test sets (None: the interface
    reports none), and a clock that moves by the time asked only when
    nothing is there to receive."""

    def __init__(self, bus: can.BusABC, server: CanBoardServer,
                 socketcan_errors: bool = True) -> None:
        super().__init__(bus, server)
        self.state: can.BusState | None = None
        self.socketcan_errors = socketcan_errors  # its error frames in SocketCAN's layout
        self.t = 0.0

    def now(self) -> float:
        return self.t

    def recv(self, timeout: float | None = None) -> can.Message | None:
        got = super().recv(0.0)
        if got is None:
            self.t += timeout or 0.0
        return got


@dataclass
class BusRig:
    robot: LockstepRobot
    bus: StatefulBus
    other: can.BusABC  # another node on the same bus
    boards: dict[int, Board]
    events: list[Event]

    def tick(self) -> None:
        self.robot.read()
        self.robot.command({})
        self.robot.clock.advance(0.02)


@pytest.fixture
def rig() -> Iterator[BusRig]:
    yield from make_rig()


def make_rig(faults: WireFaults | None = None, socketcan_errors: bool = True
             ) -> Iterator[BusRig]:
    channel = f"bus-health-{next(_names)}"
    world = make_world(load_config(), load_scenario(), True)
    boards = make_boards(world)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world, boards, faults)
    bus = StatefulBus(can.Bus(interface="virtual", channel=channel), server, socketcan_errors)
    link = CanLink(bus, timeout_s=0.05, retries=1, now=bus.now)  # type: ignore[arg-type]
    events: list[Event] = []
    robot = LockstepRobot(link, f"can://virtual/{channel}?lockstep=1", sink=events.append)
    other = can.Bus(interface="virtual", channel=channel)
    try:
        yield BusRig(robot, bus, other, boards, events)
    finally:
        robot.close()
        other.shutdown()
        server.bus.shutdown()


def test_bus_off_stops_the_run_latched_and_names_it(rig: BusRig) -> None:
    rig.tick()
    rig.bus.state = can.BusState.ERROR
    with pytest.raises(LinkLostError, match=r"link lost: the CAN bus is off \(the CAN interface "
                       r"reports bus state ERROR.*emergency stop is latched"):
        rig.robot.read()
    assert rig.robot.estopped
    assert rig.robot.health()["bus_state"] == 2
    assert any("the CAN bus is off" in e.message for e in rig.events)


def test_error_passive_is_a_figure_of_the_link_not_a_stop(rig: BusRig) -> None:
    rig.tick()
    rig.bus.state = can.BusState.PASSIVE
    rig.tick()
    rig.tick()
    h = rig.robot.health()
    assert (h["bus_state"], h["bus_passive"]) == (1, 1)  # went passive once
    rig.bus.state = can.BusState.ACTIVE
    rig.tick()
    assert rig.robot.health()["bus_state"] == 0 and not rig.robot.estopped


def test_error_frames_are_counted_apart_from_crc_errors(rig: BusRig) -> None:
    rig.tick()
    # SocketCAN's controller-problem class, data[1]: TX error-passive
    rig.other.send(can.Message(is_error_frame=True, arbitration_id=0x004,
                               data=bytes([0, 0x20, 0, 0, 0, 0, 0, 0])))
    rig.tick()
    h = rig.robot.health()
    assert (h["error_frames"], h["crc_errors"], h["bus_state"]) == (1, 0, 1)


def test_a_socketcan_bus_off_error_frame_stops_the_run_latched(rig: BusRig) -> None:
    rig.tick()
    rig.other.send(can.Message(is_error_frame=True, arbitration_id=0x040, dlc=8))
    with pytest.raises(LinkLostError, match="the CAN bus is off .an error frame says bus-off"):
        rig.tick()
    assert rig.robot.estopped


def test_error_frames_of_a_bus_other_than_socketcan_are_counted_not_decoded() -> None:
    # the fake boards' corrupted frames on udp_multicast: error frames that
    # keep the frame's own id, whatever its bits (here SocketCAN's bus-off)
    for rig in make_rig(socketcan_errors=False):
        rig.tick()
        rig.other.send(can.Message(is_error_frame=True, arbitration_id=0x040, dlc=8))
        rig.tick()
        h = rig.robot.health()
        assert (h["error_frames"], h["bus_state"]) == (1, 0) and not rig.robot.estopped


def test_error_frames_are_not_a_flood_the_controller_judges_them() -> None:
    # a lossy bus in a simulation faster than real time: many error frames
    # in little wall time, and the bus still error-active
    for rig in make_rig(socketcan_errors=False):
        rig.tick()
        for _ in range(FLOOD):
            rig.other.send(can.Message(is_error_frame=True, arbitration_id=0x123, dlc=8))
        rig.tick()
        h = rig.robot.health()
        assert (h["error_frames"], h["foreign"], h["flood_id"]) == (FLOOD, 0, -1)
        assert not rig.robot.estopped


def test_a_flood_from_another_node_stops_the_run_latched_and_names_its_id(rig: BusRig) -> None:
    rig.tick()
    for _ in range(FLOOD):  # all at one instant of the link's clock
        rig.other.send(can.Message(arbitration_id=0x000, is_extended_id=False))
    with pytest.raises(LinkLostError, match=f"a flood on the CAN bus: {FLOOD} frames from "
                       f"another node .* {FLOOD} of them id 0x000 .malformed.*emergency stop"):
        rig.tick()
    assert rig.robot.estopped
    h = rig.robot.health()
    assert (h["flood_id"], h["foreign"], h["malformed"]) == (0, FLOOD, FLOOD)


def test_fewer_foreign_frames_than_a_flood_are_counted_and_the_run_goes_on(rig: BusRig) -> None:
    rig.tick()
    for _ in range(FLOOD - 1):
        rig.other.send(can.Message(arbitration_id=0x123, is_extended_id=False, data=b"\x01"))
    rig.tick()
    h = rig.robot.health()
    assert (h["flood_id"], h["foreign"]) == (-1, FLOOD - 1) and not rig.robot.estopped


def test_a_link_lost_while_foreign_frames_come_names_them() -> None:
    # the boards fall silent after the first tick; a node sends 40 frames of
    # id 0x000 meanwhile: the loss says so, not only "no reply"
    for rig in make_rig(WireFaults(silent_after_s=0.03)):
        rig.tick()
        rig.tick()
        for _ in range(40):
            rig.other.send(can.Message(arbitration_id=0x000, is_extended_id=False))
        with pytest.raises(LinkLostError, match="no reply from the .* board.*; meanwhile 40 frames "
                           "from other nodes on the CAN bus lately, 40 of them id 0x000"):
            for _ in range(5):
                rig.tick()
        assert isinstance(rig.robot.link, CanLink)
        assert rig.robot.health()["foreign"] == 40
        assert not [b for b in rig.boards.values() if b.estop]  # an ordinary loss: no latch here
