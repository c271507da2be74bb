"""The side pair SSR/SSL on the wire (protocol 4.1), serial and CAN: a sensor
board of 6 channels or 4; a host whose config has the pair takes six readings
from the one and refuses the other while opening, with one line naming the
config key and what the board offers; a host without the pair reads four
from either; a board that breaks the protocol (one side channel, or an Ident
that promises channels its replies lack) is an error that says so, never
missing readings mid-run nor a wait without end."""

from __future__ import annotations

import itertools
import threading
from collections.abc import Iterator

import can
import pytest
from scripted_boards import WIRES, Boards, link_to, scripted_world, wired

from stairbot.control.robot_config import load_config, parse_config
from stairbot.drivers import messages as m
from stairbot.drivers.board_session import open_board_session, wanted_side_pair
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.can_request import SAME_SHORT_LIMIT, CanRequest, Offer
from stairbot.errors import BoardMismatchError, HardwareError, LinkLostError
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import Board, SensorBoard, make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.fakes.serial_boards import PtyPair, SerialBoardServer
from stairbot.hardware import BASE_SENSORS, SIDE_SENSORS, MotorId, SensorId, SensorStatus
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotSession, open_robot

SIDE_CONFIG: RobotConfig = parse_config(
    'extends = "reference"\n[sensors]\nside_model = "vl53l0x"\n', "side.toml")
WANTS = wanted_side_pair(SIDE_CONFIG)
_channels = itertools.count()


def test_only_a_config_with_the_pair_wants_it() -> None:
    assert WANTS == 'side.toml: [sensors] side_model = "vl53l0x"'
    assert wanted_side_pair(load_config()) is None


# -- six channels or four ---------------------------------------------------------

@pytest.mark.parametrize("kind", WIRES)
def test_a_host_with_the_pair_reads_six_from_a_board_with_it(kind: str) -> None:
    with wired(kind, side_pair=True, host_side_pair=WANTS) as (host, robot, events):
        robot.distances = {**robot.distances, SensorId.SSR: 0.6214, SensorId.SSL: 1.0996}
        robot.ages = {**robot.ages, SensorId.SSR: 0.031}
        host.clock.advance(0.02)
        snap = host.read()
        assert set(snap.sensors) == set(SensorId) and len(snap.sensors) == 6
        assert snap.sensors[SensorId.SSR].distance_m == 0.621  # the wire's mm
        assert snap.sensors[SensorId.SSL].distance_m == 1.1
        assert snap.sensors[SensorId.SSR].age_s == 0.031
        assert all(snap.sensors[s].distance_m == 0.5 for s in BASE_SENSORS)
        boards = host.diagnostics()["boards"]
        assert isinstance(boards, dict) and boards["sensor"]["channels"] == 6
        health = host.health()
        assert health["stray"] == health["lost"] == health["timeouts"] == 0 and not events


@pytest.mark.parametrize("kind", WIRES)
def test_a_host_without_the_pair_reads_four_from_either_board(kind: str) -> None:
    """Nothing shows a side reading on a robot without the pair: the side
    channels a board sends are left out (on CAN they are expected, from its
    Ident, so they are not counted stray)."""
    for board_has_it in (True, False):
        with wired(kind, side_pair=board_has_it) as (host, _, _):
            for _ in range(3):
                snap = host.read()
                assert set(snap.sensors) == set(BASE_SENSORS)
                host.clock.advance(0.02)
            assert host.health()["stray"] == 0


@pytest.mark.parametrize("kind", WIRES)
def test_a_host_with_the_pair_refuses_a_board_without_it_while_opening(kind: str) -> None:
    world = scripted_world(side_pair=False)
    with link_to(kind, world, make_boards(world)) as link, \
            pytest.raises(BoardMismatchError) as info:
        open_board_session(link, f"{kind}://x", watchdog_ms=250, lockstep=True,
                           time_scale=1.0, side_pair=WANTS)
    assert str(info.value) == (
        f'{kind}://x: side.toml: [sensors] side_model = "vl53l0x" gives the robot the side '
        "pair (SSR, SSL), but the sensor board offers 4 channels (SFR, SFL, SBR, SBL) and no "
        f"side pair (protocol {m.PROTOCOL_MAJOR}.{m.PROTOCOL_MINOR}); fit a sensor board with "
        "channels 4-5 (SSR, SSL), or set "
        '[sensors] side_model = "none"')
    assert isinstance(info.value, HardwareError)  # exit 1, as every robot that cannot open


# -- boards that break the protocol --------------------------------------------------

def sensor_board(ident_channels: int | None = None,
                 drop: tuple[int, ...] = ()) -> Boards:
    """Boards whose sensor board says ``ident_channels`` in its Ident (None:
    its own count) and leaves the channels ``drop`` out of its ReadAll reply."""

    class Odd(SensorBoard):
        def answer(self, msg: m.Message) -> list[m.Message]:
            replies = super().answer(msg)
            if isinstance(msg, m.Identify) and ident_channels is not None:
                (ident,) = replies
                assert isinstance(ident, m.Ident)
                return [m.Ident(ident.board, ident.protocol_major, ident.protocol_minor,
                                ident_channels, ident.firmware, ident.serial)]
            return [r for r in replies
                    if not (isinstance(r, m.SensorTelemetry) and r.channel in drop)]

    def make(world: BoardWorld) -> dict[int, Board]:
        boards = make_boards(world)
        boards[m.Board.SENSOR] = Odd(world)
        return boards

    return make


@pytest.mark.parametrize("kind", WIRES)
@pytest.mark.parametrize("channels", [3, 5])
def test_a_sensor_board_of_neither_4_nor_6_channels_is_refused(kind: str,
                                                               channels: int) -> None:
    world = scripted_world(side_pair=True)
    with link_to(kind, world, sensor_board(channels)(world)) as link, \
            pytest.raises(HardwareError) as info:
        open_board_session(link, f"{kind}://x", watchdog_ms=250, lockstep=True,
                           time_scale=1.0)
    assert str(info.value).startswith(
        f"{kind}://x: the sensor board says it has {channels} channel(s); allowed: 4 (SFR, "
        "SFL, SBR, SBL) or 6 (with the side pair SSR, SSL, protocol 4.1)")


def test_a_serial_reply_with_one_side_channel_is_a_protocol_error() -> None:
    with wired("serial", sensor_board(drop=(5,)), side_pair=True, host_side_pair=WANTS) \
            as (host, _, _), pytest.raises(HardwareError) as info:
        host.read()
    assert "the sensor board's ReadAll reply has SSR (channel 4) but not SSL (channel 5): a " \
           "sensor board sends both side channels or neither" in str(info.value)
    assert not isinstance(info.value, LinkLostError)


def test_a_serial_reply_without_the_side_channels_its_ident_promised() -> None:
    """At the first read, before any tick could miss them."""
    with wired("serial", sensor_board(drop=(4, 5)), side_pair=True, host_side_pair=WANTS) \
            as (host, _, _), pytest.raises(BoardMismatchError) as info:
        host.read()
    assert str(info.value) == (
        'serial://inline?lockstep=1: side.toml: [sensors] side_model = "vl53l0x" gives the '
        "robot the side pair (SSR, SSL), but the sensor board's ReadAll reply has channels "
        "0-3 alone (SFR, SFL, SBR, SBL) and no side readings")


@pytest.mark.parametrize("drop", [(5,), (4, 5)], ids=["one", "both"])
def test_a_can_board_that_leaves_out_frames_its_ident_promised_is_an_error_not_a_hang(
        drop: tuple[int, ...]) -> None:
    """On CAN the host counts a reply's frames by the Ident: a board that
    always sends fewer would be asked again without end (it answers, so its
    grace never runs out).  After SAME_SHORT_LIMIT attempts short of the same
    frames it is a protocol error."""
    world = scripted_world(side_pair=True)
    channel = f"short-{next(_channels)}"
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            sensor_board(drop=drop)(world))
    link = CanLink(InlineBus(can.Bus(interface="virtual", channel=channel), server),
                   timeout_s=0.1, retries=2, grace_s=0.5)  # can:// URLs' own defaults
    host = LockstepRobot(link, "can://inline?lockstep=1", side_pair=WANTS)
    try:
        with pytest.raises(HardwareError) as info:
            host.read()
    finally:
        host.close()
        server.bus.shutdown()
    lacked = ", ".join(f"SensorTelemetry channel {c}" for c in drop)
    assert str(info.value) == (
        f"can://inline?lockstep=1: the sensor board broke the protocol: it answered ReadAll "
        f"{SAME_SHORT_LIMIT} times in a row without {lacked} (its Ident said 6 channels), "
        "though it answered each time")


def test_a_minor_0_sensor_board_reads_as_one_without_the_pair() -> None:
    class Minor0(SensorBoard):
        def answer(self, msg: m.Message) -> list[m.Message]:
            if isinstance(msg, m.Identify):
                return [m.Ident(self.BOARD, m.PROTOCOL_MAJOR, 0, 4, 0x0100, self.serial)]
            return super().answer(msg)

    def boards(world: BoardWorld) -> dict[int, Board]:
        out = make_boards(world)
        out[m.Board.SENSOR] = Minor0(world)
        return out

    for kind in WIRES:
        with wired(kind, boards) as (host, _, _):
            assert set(host.read().sensors) == set(BASE_SENSORS)


# -- the fake boards of a robot config, opened by URL ----------------------------------

def served(kind: str, config: RobotConfig) -> Iterator[str]:
    """Fake boards in lockstep for ``config``'s robot, served on a thread; the
    URL to open."""
    world = make_world(config, load_scenario(), lockstep=True)
    server: SerialBoardServer | CanBoardServer
    if kind == "serial":
        pty = PtyPair()
        server = SerialBoardServer(pty.master, world, make_boards(world))
        url, close = f"serial://{pty.path}?lockstep=1&timeout=0.5", pty.close
    else:
        channel = f"side-{next(_channels)}"
        server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                                make_boards(world))
        url, close = f"can://virtual/{channel}?lockstep=1&timeout=0.5", server.bus.shutdown
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        yield url
    finally:
        server.stop()
        thread.join(5)
        close()


@pytest.mark.parametrize("kind", WIRES)
def test_fake_boards_of_a_robot_with_the_pair_serve_six_channels(kind: str) -> None:
    for url in served(kind, SIDE_CONFIG):
        session: RobotSession = open_robot(url, SIDE_CONFIG)
        try:
            for _ in range(3):
                snap = session.robot.read()
                session.robot.command({MotorId.MWF: 0.5})
                session.clock.advance(0.02)
            assert set(snap.sensors) == set(SensorId)
            # The simulation reads no side pair yet: its sensors say they never measured
            # (or, once it models them, read): never a distance made up on the way.
            for s in SIDE_SENSORS:
                r = snap.sensors[s]
                assert r.status is not SensorStatus.ERROR or r.age_s >= 65.535
        finally:
            session.close()


@pytest.mark.parametrize("kind", WIRES)
def test_a_config_with_the_pair_refuses_fake_boards_without_it_by_url(kind: str) -> None:
    for url in served(kind, load_config()):
        with pytest.raises(BoardMismatchError, match=r"side_model = \"vl53l0x\" gives the "
                           r"robot the side pair \(SSR, SSL\), but the sensor board offers 4"):
            open_robot(url, SIDE_CONFIG)


def test_only_the_same_gap_attempt_after_attempt_counts_as_a_broken_board() -> None:
    """A reply skipped before a later one was not sent (CAN keeps a sender's
    order); a timeout with replies still owed may be a slow board: it counts
    nothing.  A different gap starts the count afresh."""
    req = CanRequest(int(m.Board.SENSOR), (m.ReadAll(),), True, 0.0, 1.0, channels=6)
    status = m.Status(0x40, 0, 250, 0)
    tel = [m.SensorTelemetry(c, 0, 500, 1, 0) for c in range(6)]
    imu = [m.ImuTelemetry(a, 0, 0, 0, 0) for a in range(2)]

    def attempt(*replies: m.Message) -> str | None:
        req.expect()
        for r in replies:
            assert req.offer(r, 0) is Offer.TAKEN
        return req.attempt_failed()

    without_side = (status, *tel[:4], *imu)
    for _ in range(SAME_SHORT_LIMIT - 1):
        assert attempt(*without_side) is None
    assert attempt(status, *tel[:3]) is None  # timed out, replies owed: a slow board?
    for _ in range(SAME_SHORT_LIMIT - 1):
        assert attempt(*without_side) is None
    assert attempt(status, *tel[:4], tel[5], *imu) is None  # another gap: afresh
    for _ in range(SAME_SHORT_LIMIT - 1):
        assert attempt(*without_side) is None
    why = attempt(*without_side)
    assert why is not None and "without SensorTelemetry channel 4, SensorTelemetry channel 5" \
        in why
