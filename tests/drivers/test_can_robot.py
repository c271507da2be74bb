"""The can:// driver against the fake boards on python-can's virtual bus:
the URL grammar and python-can's config, bad URLs in one line, watchdog trip
and clear, the emergency stop, a silent board, link health; and socketcan,
which needs a kernel CAN device."""

from __future__ import annotations

import itertools
import os
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import can
import pytest

import stairbot.fakes.lockstep  # noqa: F401 - registers the lockstep robot with the drivers
from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.can_link import CanLink
from stairbot.drivers.can_robot import open_bus, open_can_robot, parse_can_url, resolve_bus_config
from stairbot.drivers.can_wire import make_id, split_id
from stairbot.drivers.estop import ESTOP_COPIES
from stairbot.errors import HardwareError, LinkLostError, NoBoardError, RobotUrlError
from stairbot.events import Event
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import Board, make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.can_boards import CanBoardServer, InlineBus
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.fakes.serial_boards import WireFaults
from stairbot.hardware import Clock, HasTruth, MotorId
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotOptions, open_robot

_names = itertools.count()
FORWARD = {MotorId.MWF: 1.0, MotorId.MWB: 1.0, MotorId.MWR: 1.0, MotorId.MWL: 1.0}


@dataclass
class Rig:
    robot: LockstepRobot
    clock: Clock
    server: CanBoardServer
    world: BoardWorld
    boards: dict[int, Board]

    def tick(self, speeds: dict[MotorId, float] | None = None) -> None:
        self.robot.read()
        self.robot.command(speeds or {})
        self.clock.advance(0.02)


def make_rig(faults: WireFaults | None = None, timeout: float = 0.05) -> Rig:
    """Both fake boards in lockstep, served inline on a fresh virtual channel."""
    channel = f"rig-{next(_names)}"
    world = make_world(load_config(), load_scenario(), True)
    boards = make_boards(world)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world, boards, faults)
    link = CanLink(InlineBus(can.Bus(interface="virtual", channel=channel), server),
                   timeout_s=timeout, retries=1)
    robot = LockstepRobot(link, f"can://virtual/{channel}?lockstep=1")
    return Rig(robot, robot.clock, server, world, boards)


@pytest.fixture
def rig() -> Iterator[Rig]:
    r = make_rig()
    yield r
    r.robot.close()
    r.server.bus.shutdown()


# -- the URL ------------------------------------------------------------------------

def test_url_grammar() -> None:
    s = parse_can_url("can://udp_multicast/239.74.9.7?port=43210&timeout=0.5&lockstep=1&fd=False")
    assert (s.interface, s.channel) == ("udp_multicast", "239.74.9.7")
    assert s.bus_kwargs == {"port": 43210, "fd": False}
    assert s.options["timeout"] == 0.5 and s.options["lockstep"] == 1 and s.options["lan"] == 0
    s = parse_can_url("can://udp_multicast/ff15::7?lan=1")  # IPv6: on the network only
    assert (s.channel, s.options["lan"], s.bus_kwargs) == ("ff15::7", 1, {})
    s = parse_can_url("can://slcan//dev/ttyACM0?bitrate=500000")
    assert (s.interface, s.channel, s.bus_kwargs) == ("slcan", "/dev/ttyACM0", {"bitrate": 500000})
    s = parse_can_url("can://default/")
    assert (s.interface, s.channel) == (None, None)


def test_missing_parts_come_from_python_cans_config(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAN_INTERFACE", "virtual")
    monkeypatch.setenv("CAN_CHANNEL", "from-env")
    monkeypatch.setenv("CAN_BITRATE", "250000")
    cfg = resolve_bus_config(parse_can_url("can://default/"))
    assert (cfg["interface"], cfg["channel"], cfg["bitrate"]) == ("virtual", "from-env", 250000)
    cfg = resolve_bus_config(parse_can_url("can://virtual/mine?bitrate=1000000"))
    assert (cfg["channel"], cfg["bitrate"]) == ("mine", 1000000)  # the URL wins


@pytest.mark.parametrize(("url", "words"), [
    ("can://nosuch/x", "unknown python-can interface 'nosuch'"),
    ("can://virtual/x?timeout=-1", "timeout"),
    ("can://virtual/x?lockstep=2", "0 or 1"),
    ("can://virtual/x?bitrate=fast", "bitrate"),
    ("can://udp_multicast/10.0.0.1", "not a multicast group"),
    ("can://udp_multicast/not-an-address", "multicast group address"),
    ("can://udp_multicast/ff15::7", "IPv6 group.*loopback.*lan=1"),
    ("can://udp_multicast/239.74.9.7?lan=2", "lan.*0 or 1"),
    ("can://virtual/x?lan=1", "udp_multicast only"),
    ("can://virtual/x?channel=y", "in the path"),
])
def test_bad_urls_say_what_is_allowed(url: str, words: str) -> None:
    with pytest.raises(RobotUrlError, match=words) as info:
        parse_can_url(url)
    assert "\n" not in str(info.value)


def test_no_interface_anywhere_is_one_clear_line(monkeypatch: pytest.MonkeyPatch) -> None:
    for var in ("CAN_INTERFACE", "CAN_CHANNEL", "CAN_BITRATE", "CAN_CONFIG"):
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setattr(can, "rc", {})
    monkeypatch.setenv("HOME", "/nonexistent")
    with pytest.raises(RobotUrlError, match="no CAN interface given"):
        resolve_bus_config(parse_can_url("can://default/"))


def test_a_bus_that_cannot_open_is_one_line_and_no_boards_is_one_line() -> None:
    config = load_config()
    with pytest.raises(RobotUrlError, match="cannot open CAN bus slcan//dev/nonexistent"):
        open_robot("can://slcan//dev/nonexistent", config)
    url = f"can://virtual/empty-{next(_names)}?timeout=0.01&retries=0"
    with pytest.raises(NoBoardError) as info:  # the URL was fine: a hardware error
        open_robot(url, config)
    assert str(info.value) == (f"{url}: no motor board answered on the CAN bus "
                               "(1 try of 10 ms)")
    assert (info.value.board, info.value.url) == ("motor", url)


@pytest.mark.skipif(not os.path.exists("/sys/class/net/vcan0"),
                    reason="no kernel CAN support on this machine")
def test_socketcan_vcan0_opens() -> None:  # pragma: no cover - needs a kernel CAN device
    """The URL opens a socketcan bus on vcan0, and that bus carries frames:
    one sent on it reaches a second bus on the same device."""
    from can.interfaces.socketcan import SocketcanBus

    s = parse_can_url("can://socketcan/vcan0")
    bus, other = open_bus(s), open_bus(s)
    try:
        assert isinstance(bus, SocketcanBus) and bus.channel == "vcan0"
        bus.send(can.Message(arbitration_id=0x0EF << 18, data=b"", is_extended_id=True))
        heard = other.recv(timeout=5.0)
        assert heard is not None and heard.arbitration_id == 0x0EF << 18  # Identify_All
    finally:
        bus.shutdown()
        other.shutdown()


# -- the boards over the wire ----------------------------------------------------------

def test_reads_commands_and_counts_link_health(rig: Rig) -> None:
    start = rig.robot.read().turns(MotorId.MWF)
    for _ in range(25):
        rig.tick(FORWARD)
    snap = rig.robot.read()
    assert snap.turns(MotorId.MWF) - start == pytest.approx(0.48, abs=0.05)  # 1 turn/s
    assert snap.time_s == pytest.approx(0.5)
    h = snap.health
    assert h["lost"] == h["timeouts"] == h["malformed"] == 0
    assert h["frames_rx"] > 0 and h["rtt_median_ms"] > 0 and h["bits_tx"] > 0


def test_watchdog_trips_when_the_host_goes_quiet_and_only_a_clear_resets_it(rig: Rig) -> None:
    rig.tick(FORWARD)
    # the host says nothing while 0.3 s of board time pass (watchdog 250 ms)
    rig.world.step_to(round((rig.clock.now() + 0.3) * 1e6))
    for board in rig.boards.values():
        board.poll()
    with pytest.raises(LinkLostError, match="watchdog tripped"):
        rig.robot.read()
    motor = rig.boards[m.Board.MOTOR]
    assert motor.watchdog_tripped
    assert all(mode == m.MotorMode.HOLD for mode in motor.modes)  # lifts hold
    assert rig.world.speeds()[MotorId.MWF] == 0.0
    rig.robot.command(FORWARD)  # refused while latched
    rig.robot.flush()
    assert rig.robot.health()["refused"] >= 1
    rig.robot.clear(m.ClearMask.WATCHDOG)
    rig.clock.advance(0.02)
    rig.tick(FORWARD)
    assert rig.robot.read().motors[MotorId.MWF].fault is None
    assert rig.world.speeds()[MotorId.MWF] == 1.0


def test_emergency_stop_is_broadcast_frames_and_latches(rig: Rig) -> None:
    rig.tick(FORWARD)
    rig.robot.link.flush()  # the tick's held command and StepTo go out first
    tx = rig.robot.link.stats.frames_tx
    rig.robot.estop()
    assert rig.robot.link.stats.frames_tx == tx + ESTOP_COPIES  # EStop_All (0x00F), copies
    assert rig.robot.estopped
    assert rig.world.speeds() == {mid: 0.0 for mid in MotorId}
    assert all(b.estop for b in rig.boards.values())  # latched on both boards
    snap = rig.robot.read()  # this host's own latch: reading goes on
    assert snap.motors[MotorId.MTF].fault == "estop"
    rig.robot.command(FORWARD)
    rig.robot.flush()
    assert rig.world.speeds()[MotorId.MWF] == 0.0  # zeros sent, and refused
    rig.robot.clear(m.ClearMask.ESTOP)
    assert not rig.robot.estopped and not any(b.estop for b in rig.boards.values())
    rig.robot.read()
    rig.robot.command(FORWARD)
    rig.robot.flush()
    assert rig.world.speeds()[MotorId.MWF] == 1.0


def test_an_emergency_stop_a_board_latched_on_its_own_stops_the_reads(rig: Rig) -> None:
    rig.tick(FORWARD)
    rig.boards[m.Board.SENSOR].estop = True  # the board's own input, not this host
    with pytest.raises(HardwareError, match="sensor board has its emergency stop latched"):
        rig.robot.read()


def test_estop_never_raises_and_latches_on_a_silent_bus() -> None:
    # from 0.05 s of board time on the boards hear the host but never answer
    rig = make_rig(WireFaults(silent_after_s=0.05), timeout=0.01)
    try:
        rig.tick(FORWARD)
        rig.clock.advance(0.04)
        rig.robot.link.flush()  # the StepTo goes out: silent from then on
        events: list[Event] = []
        rig.robot.attach_sink(events.append)
        rig.robot.estop()
        assert rig.robot.estopped
        assert all(b.estop for b in rig.boards.values())  # they heard it
        assert [e.message.split(":")[0] for e in events] == [
            "emergency stop not confirmed by the motor board and the sensor board"]
        rig.robot.close()
        rig.robot.estop()  # closed: still no exception, still latched
        rig.robot.stop_all()
        assert rig.robot.estopped
    finally:
        rig.robot.close()
        rig.server.bus.shutdown()


def test_the_emergency_stop_does_not_wait_for_the_robots_lock(
        rig: Rig, monkeypatch: pytest.MonkeyPatch) -> None:
    """While another thread holds the robot (a read retrying), the EStop frames
    go on the bus at once; the confirmation is taken in once the lock comes free."""
    rig.tick(FORWARD)
    rig.robot.link.flush()
    bus = rig.robot.link.bus
    sent: list[tuple[int, bool]] = []  # (id, whether the holder still held the lock)
    holding, release = threading.Event(), threading.Event()
    send = bus.send

    def spy(msg: can.Message, timeout: float | None = None) -> None:
        sent.append((msg.arbitration_id, not release.is_set()))
        send(msg, timeout)

    def hold() -> None:
        with rig.robot._lock:
            holding.set()
            release.wait(5)

    monkeypatch.setattr(bus, "send", spy)
    holder = threading.Thread(target=hold)
    holder.start()
    holding.wait(5)
    stopper = threading.Thread(target=rig.robot.estop)
    stopper.start()
    deadline = time.monotonic() + 5
    while len(sent) < ESTOP_COPIES and time.monotonic() < deadline:
        time.sleep(0.001)
    release.set()
    holder.join(5)
    stopper.join(5)
    assert [(split_id(i)[0], held) for i, held in sent[:ESTOP_COPIES]] == [
        (0x00F, True)] * ESTOP_COPIES  # EStop_All, lock held
    assert all(b.estop for b in rig.boards.values())
    assert rig.robot.estopped and rig.robot.link.stats.lost == 0  # confirmed, not given up


def test_a_silent_board_means_link_lost_and_a_link_event() -> None:
    r = make_rig(WireFaults(silent_board=2, silent_after_s=0.1), timeout=0.01)
    events: list[Event] = []
    r.robot.attach_sink(events.append)
    try:
        for _ in range(4):
            r.tick()
        with pytest.raises(LinkLostError, match="no reply from the sensor board .*ReadAll"):
            for _ in range(10):
                r.tick()
        assert r.robot.health()["lost"] >= 1 and r.robot.health()["retries"] >= 1
        assert any(e.kind.value == "link" and "link lost" in e.message for e in events)
    finally:
        r.robot.close()
        r.server.bus.shutdown()


def test_dropped_and_late_frames_are_counted_not_fatal() -> None:
    r = make_rig(WireFaults(drop=0.01, seed=3), timeout=0.01)
    try:
        lost = 0
        for _ in range(60):
            try:
                r.tick()
            except LinkLostError:
                lost += 1
        h = r.robot.health()
        assert h["timeouts"] >= 1 and h["retries"] >= 1  # dropped replies were asked again
        assert lost < 10  # a retry mostly recovers; the link is not given up for good
        assert r.server.stats.injected >= 1
    finally:
        r.robot.close()
        r.server.bus.shutdown()


def test_threaded_server_on_a_virtual_bus_via_open_robot() -> None:
    """The real arrangement in one process: the server on its own thread,
    the host opened by URL."""
    channel = f"threaded-{next(_names)}"
    world = make_world(load_config(), load_scenario(), True)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            make_boards(world))
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        session = open_can_robot(f"can://virtual/{channel}?lockstep=1&timeout=1",
                                 load_config(), RobotOptions())
        assert session.simulated
        for _ in range(10):
            session.robot.read()
            session.robot.command(FORWARD)
            session.clock.advance(0.02)
        diag = session.robot.diagnostics()
        assert "bus" in diag and diag["wire"] == "CAN bus"
        assert isinstance(session.robot, HasTruth)  # fake boards in lockstep
        truth = session.robot.truth()
        assert truth.fell is False and truth.offset_m is not None and truth.offset_m > 0
        session.close()
    finally:
        server.stop()
        thread.join(5)
        server.bus.shutdown()


@pytest.mark.parametrize(("spec", "words"), [
    ("virtual/x", "a virtual bus lives inside one process"),
    ("udp_multicast/10.0.0.1", "not a multicast group"),
    ("nosuch/1", "unknown python-can interface"),
])
def test_fake_boards_on_a_bad_bus_exit_2_with_one_line(
        spec: str, words: str, capsys: pytest.CaptureFixture[str]) -> None:
    from stairbot.cli import main

    assert main(["fake-boards", "--can", spec]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err and "Traceback" not in err


def test_fake_boards_help_says_udp_multicast_stays_on_loopback() -> None:
    from stairbot.fakes.boards_cli import build_parser

    text = " ".join(build_parser().format_help().split())
    assert "on loopback only (127.0.0.1, TTL 0) unless the URL adds ?lan=1" in text
    assert "no other host can send the boards frames" in text


def test_faster_than_real_time_without_lockstep() -> None:
    """--time-scale on both sides: the fake's world runs 20x the wall clock and
    so does the host's clock, its timeouts and its grace are 1/20 of the
    URL's in wall time; the robot drives forward as commanded."""
    channel = f"scaled-{next(_names)}"
    world = make_world(load_config(), load_scenario(), False)
    server = CanBoardServer(can.Bus(interface="virtual", channel=channel), world,
                            make_boards(world), time_scale=20.0)
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        session = open_can_robot(f"can://virtual/{channel}?time_scale=20&timeout=1&watchdog=5000",
                                 load_config(), RobotOptions())
        assert not isinstance(session.robot, HasTruth)  # a board robot, as a real one
        first = session.robot.read()
        for _ in range(25):
            session.robot.read()
            session.robot.command(FORWARD)
            session.clock.advance(0.02)
        last = session.robot.read()
        assert last.time_s > first.time_s
        assert last.turns(MotorId.MWF) > first.turns(MotorId.MWF)
        assert world.now() > 0
        # timeout, grace and watchdog are times of the robot's clock: the
        # boards count the watchdog in theirs, the host waits 1/20 of the wall
        link = session.robot.link  # type: ignore[attr-defined]
        assert session.robot.board_watchdog_ms == 5000  # type: ignore[attr-defined]
        assert (link.timeout_s, link.grace_s) == (1 / 20, 0.5 / 20)
        session.close()
    finally:
        server.stop()
        thread.join(5)
        server.bus.shutdown()


def test_a_bus_that_refuses_the_boards_replies_costs_frames_not_the_server() -> None:
    world = make_world(load_config(), load_scenario(), True)
    bus = can.Bus(interface="virtual", channel=f"refuse-{next(_names)}")
    server = CanBoardServer(bus, world, make_boards(world))
    identify = can.Message(arbitration_id=make_id(0x0EF, 1, 0), data=b"", is_extended_id=True)
    bus.shutdown()  # every send now raises CanOperationError
    server.receive(identify)  # both boards answer: two replies refused
    assert (server.stats.frames_rx, server.stats.send_errors, server.stats.frames_tx) == (2, 2, 0)


def test_a_read_all_reply_without_every_channel_is_a_hardware_error(rig: Rig) -> None:
    status = m.Status(0x40, 0, 250, 0)
    tel = tuple(m.MotorTelemetry(c, 1, 0, 1000, 5) for c in range(5))  # MTB missing
    with pytest.raises(HardwareError, match="motor board's ReadAll reply lacks channels"):
        rig.robot.replies.motors((status, *tel))
    with pytest.raises(HardwareError, match="sensor board answered ReadAll with"):
        rig.robot.replies.sensors(tel, 0.0)


def test_every_frame_twice_reads_every_channel_once_and_counts_the_copies() -> None:
    # A duplicated telemetry frame must not stand in for another channel's
    # ("ReadAll reply lacks channels"); each copy of a host frame is answered
    # from the board's cache, and each copy of a reply counted a duplicate.
    r = make_rig(WireFaults(duplicate=1.0, seed=1), timeout=0.05)
    try:
        for _ in range(20):
            r.tick()
        snap = r.robot.read()
        assert set(snap.motors) == set(MotorId)
        h = r.robot.health()
        assert h["duplicates"] >= 20 and h["stray"] == h["late"] == h["lost"] == 0
        assert r.server.stats.duplicates >= 20
    finally:
        r.robot.close()
        r.server.bus.shutdown()


def test_a_reply_frame_lost_between_others_is_a_gap_matched_by_channel() -> None:
    from stairbot.drivers.can_request import CanRequest, Offer

    req = CanRequest(int(m.Board.MOTOR), (m.ReadAll(),), True, 0.0, 1.0)
    req.expect()
    tel = [m.MotorTelemetry(c, 1, 0, 1000, 5) for c in range(6)]
    taken = Offer.TAKEN
    assert req.offer(m.Status(0x40, 0, 250, 0), 0) is taken and req.offer(tel[0], 0) is taken
    assert req.offer(tel[0], 0) is Offer.DUPLICATE  # a copy of channel 0: not channel 1
    assert req.offer(tel[2], 0) is taken and req.gap  # channel 1 was lost on the way
    assert req.offer(tel[1], 0) is Offer.LATE  # too late: the board sends in order
    assert req.offer(m.Ident(1, 4, 0, 6, 1, 1), 0) is Offer.STRAY  # no reply to ReadAll
    for t in tel[3:]:
        assert req.offer(t, 0) is taken
    assert req.owed == 0 and req.gap  # every reply that will come came; incomplete


def test_a_virtual_bus_is_locked_per_process_as_it_does_not_leave_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Two processes on one ``virtual`` channel name are two buses: the
    other's lock does not refuse this one (two pytest-xdist workers opened
    ``virtual/conformance-4`` at once and one was told the bus was in use);
    a second host on it in this process is still refused."""
    import subprocess
    import sys

    from stairbot.drivers.can_robot import lock_bus
    from stairbot.errors import PortBusyError

    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path))
    env = dict(os.environ)
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys\nfrom stairbot.drivers.can_robot import lock_bus, "
         "parse_can_url\nlock = lock_bus(parse_can_url('can://virtual/owned'))\n"
         "print('held', flush=True)\nsys.stdin.read()\n"],
        env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        mine = lock_bus(parse_can_url("can://virtual/owned"))
        try:
            with pytest.raises(PortBusyError, match="in use by another stairbot"):
                lock_bus(parse_can_url("can://virtual/owned"))
        finally:
            mine.release()
    finally:
        holder.communicate("", timeout=30)
