"""The serial:// driver against the fake boards on a pseudo-terminal (and a
TCP socket): reading, commanding, e-stop, watchdog, a silent board, fault
injection on the wire, and bad URLs."""

from __future__ import annotations

import re
import socket
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import serial
import serial.rfc2217

from stairbot.cli.clear import main as clear_main
from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.board_robot import BoardRobot
from stairbot.drivers.serial_robot import parse_serial_url
from stairbot.errors import (
    HardwareError,
    LatchedError,
    LinkLostError,
    NoBoardError,
    RobotUrlError,
)
from stairbot.events import Event, EventKind
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.boards import make_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.lockstep import LockstepRobot
from stairbot.fakes.serial_boards import PtyPair, SerialBoardServer, WireFaults
from stairbot.hardware import BASE_SENSORS, HasTruth, MotorId, SensorId
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario
from stairbot.run.robots import RobotSession, open_robot
from stairbot.run.runner import run

CONFIG: RobotConfig = load_config()
SCENARIO: Scenario = load_scenario()


@dataclass
class Fake:
    path: str
    world: BoardWorld
    server: SerialBoardServer

    def open(self, query: str = "lockstep=1&timeout=0.5") -> RobotSession:
        return open_robot(f"serial://{self.path}?{query}", CONFIG)


def serve(faults: WireFaults | None = None) -> Iterator[Fake]:
    world = make_world(CONFIG, SCENARIO, lockstep=True)
    pty = PtyPair()
    server = SerialBoardServer(pty.master, world, make_boards(world), faults)
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        yield Fake(pty.path, world, server)
    finally:
        server.stop()
        thread.join(5)
        pty.close()


@pytest.fixture
def fake() -> Iterator[Fake]:
    yield from serve()


def robot_of(session: RobotSession) -> BoardRobot:
    assert isinstance(session.robot, BoardRobot)
    return session.robot


def test_read_command_and_lockstep_clock(fake: Fake) -> None:
    session = fake.open()
    try:
        assert session.simulated
        snap = session.robot.read()
        assert set(snap.sensors) == set(BASE_SENSORS) and set(snap.motors) == set(MotorId)
        start = SCENARIO.start.distance  # within 3 of the pair's stated sigmas there
        assert snap.sensors[SensorId.SFR].distance_m == pytest.approx(
            start, abs=3 * CONFIG.sensors.sigma(False, start))
        for _ in range(25):
            session.robot.read()
            session.robot.command({MotorId.MTF: 10.0})
            session.clock.advance(CONFIG.algorithm.tick)
        snap = session.robot.read()
        assert session.clock.now() == pytest.approx(0.5)
        assert snap.time_s == pytest.approx(0.5)
        assert 4.0 < snap.motors[MotorId.MTF].turns <= 5.05  # 10 turns/s for 0.5 s, loaded
        assert snap.health["frames_rx"] == snap.health["frames_tx"] > 50
        assert snap.health["lost"] == 0 and snap.health["rtt_median_ms"] > 0
        diag = session.robot.diagnostics()
        assert diag["boards"]["motor"]["channels"] == 6 and diag["wire"] == "serial port"
        assert isinstance(session.robot, LockstepRobot) and isinstance(session.robot, HasTruth)
        truth = session.robot.truth()
        assert truth.fell is False and truth.max_pitch_deg is not None
    finally:
        session.close()
    assert fake.world.speeds()[MotorId.MTF] == 0.0  # close stops every motor


def test_estop_latches_on_the_boards_until_cleared(fake: Fake) -> None:
    session = fake.open()
    robot = robot_of(session)
    robot.command({MotorId.MWF: 1.0})  # held for the next StepTo (lockstep) ...
    robot.estop()  # ... and overtaken by the EStops: both boards latch first
    assert robot.estopped and fake.world.speeds()[MotorId.MWF] == 0.0
    assert robot.read().motors[MotorId.MWF].fault == "estop"  # reading goes on
    robot.command({MotorId.MWF: 1.0})
    robot.flush()
    assert robot.refused == 4 and fake.world.speeds()[MotorId.MWF] == 0.0  # 2 frames x 2
    robot.clear(m.ClearMask.ESTOP)
    assert not robot.estopped
    robot.read()
    session.close()


def test_an_emergency_stop_latched_by_a_board_itself_stops_the_reads(fake: Fake) -> None:
    session = fake.open()
    fake.server.boards[m.Board.MOTOR].estop = True  # its own input, not this host
    with pytest.raises(HardwareError, match="motor board has its emergency stop latched"):
        session.robot.read()
    session.close()


def test_estop_never_raises_when_the_boards_fall_silent() -> None:
    for fake in serve(WireFaults(silent_after_s=0.05)):  # they hear, but never answer
        session = fake.open("lockstep=1&timeout=0.05&retries=0")
        events: list[Event] = []
        robot_of(session).attach_sink(events.append)
        session.clock.advance(0.1)
        robot_of(session).link.flush()  # the StepTo goes out: silent from then on
        session.robot.estop()
        assert session.robot.estopped
        assert [e.message.split(":")[0] for e in events if e.kind == EventKind.LINK] == [
            "emergency stop not confirmed by the motor board and the sensor board"]
        (said,) = [e.message for e in events if e.kind == EventKind.LINK]
        # the host cannot know a silent board stopped: it says so, never that it did
        assert "this host cannot tell whether it stopped" in said
        assert all(b.estop for b in fake.server.boards.values())  # they did hear it
        session.close()
        session.robot.estop()  # closed: no exception either
        assert session.robot.estopped


def test_heartbeat_feeds_boards_the_host_has_not_addressed_lately(fake: Fake) -> None:
    session = fake.open("lockstep=1&timeout=0.5&watchdog=60000")
    robot = robot_of(session)
    before = robot.link.stats.frames_tx
    robot.heartbeat()  # both boards were just addressed while opening
    assert robot.link.stats.frames_tx == before
    robot._last_tx = {b: time.monotonic() - 20.0 for b in robot._last_tx}  # 20 s ago
    robot.heartbeat()
    robot.flush()
    assert robot.link.stats.frames_tx == before + 2
    session.close()


def test_watchdog_trips_when_the_host_falls_silent_and_only_the_operator_clears_it(
        fake: Fake, capsys: pytest.CaptureFixture[str]) -> None:
    session = fake.open("lockstep=1&timeout=0.5&watchdog=100")
    robot = robot_of(session)
    robot.read()
    robot.command({MotorId.MWF: 1.0})
    robot.step_to(300_000)  # 300 ms of board time without another host frame
    assert fake.world.speeds()[MotorId.MWF] == 0.0
    with pytest.raises(LinkLostError, match="motor board's watchdog tripped"):
        robot.read()
    session.close()
    url = f"serial://{fake.path}?lockstep=1&timeout=0.5"
    with pytest.raises(LatchedError) as info:  # opening never clears a latch
        fake.open()
    assert str(info.value) == (
        f"{url}: the motor board has its watchdog tripped and latched (frames stopped "
        "coming while it was armed); opening never clears a latch: check the robot, "
        f"then `stairbot clear --robot {url}`")
    assert clear_main(["--robot", url], confirm=lambda _q: False) == 2  # not confirmed
    assert "not cleared" in capsys.readouterr().err
    with pytest.raises(LatchedError):
        fake.open()
    asked: list[str] = []
    assert clear_main(["--robot", url], confirm=lambda q: asked.append(q) or True) == 0
    out = capsys.readouterr().out
    assert "the motor board has its watchdog tripped" in out and out.endswith("cleared\n")
    assert asked and "Look at the robot first" in asked[0]
    again = fake.open()
    again.robot.read()
    again.close()
    assert clear_main(["--robot", url]) == 0  # a clean close leaves nothing latched
    assert "nothing to clear" in capsys.readouterr().out


def test_a_run_that_ends_in_an_error_leaves_the_emergency_stop_latched(fake: Fake) -> None:
    session = fake.open()
    events: list[Event] = []
    robot_of(session).attach_sink(events.append)
    result = run(session, CONFIG, max_sim_time_s=0.5)  # "took longer than 0.5 s": an error
    session.close()
    assert result.outcome == "error"
    assert all(b.estop for b in fake.server.boards.values())
    with pytest.raises(LatchedError, match="motor board has its emergency stop latched"):
        fake.open()
    assert clear_main(["--robot", f"serial://{fake.path}?lockstep=1&timeout=0.5",
                       "--yes"]) == 0
    fake.open().close()


def test_a_silent_board_loses_the_link_and_the_run_stops() -> None:
    for fake in serve(WireFaults(silent_board=1, silent_after_s=0.2)):
        # silent from 0.2 s of board time on: two attempts of 0.1 s, sent again
        # while the board is within its grace period (0.3 s of silence), then lost
        session = fake.open("lockstep=1&timeout=0.1&retries=1&grace=0.3")
        events: list[Event] = []
        robot_of(session).attach_sink(events.append)
        result = run(session, CONFIG, sink=events.append)
        assert result.outcome == "error"
        assert result.error is not None
        said = re.search(r"no reply from the motor board for (\d+\.\d\d) s \(StepTo: (\d+) "
                         r"attempt\(s\) of 100 ms", result.error)
        assert said, result.error
        assert float(said[1]) >= 0.3 and int(said[2]) >= 3
        assert robot_of(session).link.stats.revived >= 1
        assert result.error.endswith("a board that hears nothing more stops its motors when "
                                     "its watchdog (250 ms) runs out")
        assert robot_of(session).link.stats.retries >= 1
        session.close()
        # one loss, one LINK event: the stop, truth and close that follow do not repeat it
        lost = [e for e in events if e.kind is EventKind.LINK and "link lost" in e.message]
        assert len(lost) == 1


def test_faults_on_the_wire_are_survived_and_counted() -> None:
    faults = WireFaults(drop=0.03, corrupt=0.03, duplicate=0.03, seed=7)
    for fake in serve(faults):
        session = fake.open("lockstep=1&timeout=0.05&retries=8&lost=10")
        robot = robot_of(session)
        events: list[Event] = []
        robot.attach_sink(events.append)
        for _ in range(150):
            robot.read()
            robot.command({MotorId.MWF: 0.5})
            session.clock.advance(0.02)
        h = robot.health()
        assert h["retries"] > 0 and h["crc_errors"] + h["malformed"] > 0
        assert h["duplicates"] > 0  # duplicated replies
        assert fake.server.stats.duplicates > 0 and fake.server.stats.injected > 0
        link_events = [e for e in events if e.kind is EventKind.LINK]
        assert link_events and "retries" in link_events[0].message
        assert 1 <= len(link_events) <= 3  # at most one a second of robot time (3 s here)
        session.close()


def test_late_replies_cause_retries_and_the_copies_are_not_acted_upon() -> None:
    # half the replies come 200 ms late, after the host's 100 ms timeout
    for fake in serve(WireFaults(late=0.5, late_s=0.2, seed=3)):
        session = fake.open("lockstep=1&timeout=0.1&retries=5")
        robot = robot_of(session)
        h = robot.link.stats
        lost_opening = h.lost  # SetWatchdog is a command: late means lost, then sent anew
        for _ in range(10):
            robot.read()
        assert h.retries >= 1 and h.lost == lost_opening  # queries always got through
        for _ in range(500):  # the retried copy's answer arrives later still
            if h.stray + h.late + h.duplicates:
                break
            robot.link.poll()
            time.sleep(0.01)
        assert h.stray + h.late + h.duplicates >= 1
        session.close()


def test_a_duplicated_move_is_executed_once() -> None:
    for fake in serve(WireFaults(duplicate=1.0)):
        session = fake.open()
        robot = robot_of(session)
        reply = robot.link.exchange(m.Board.MOTOR, [m.Move(4, 2000, 10000)])
        assert reply.messages == (m.Ack(m.Move.TYPE, m.AckResult.OK),)
        for _ in range(20):
            snap = robot.read()  # keeps the sensor board's watchdog fed too
            session.clock.advance(0.05)
        snap = robot.read()
        assert snap.motors[MotorId.MTF].turns == pytest.approx(2.0, abs=0.6)
        assert fake.server.stats.duplicates > 0
        session.close()


def test_any_pyserial_url_works_as_the_port_socket() -> None:
    world = make_world(CONFIG, SCENARIO, lockstep=True)
    listener = socket.create_server(("127.0.0.1", 0))
    port = listener.getsockname()[1]
    servers: list[SerialBoardServer] = []

    def accept() -> None:
        conn, _ = listener.accept()
        server = SerialBoardServer(conn.fileno(), world, make_boards(world))
        servers.append(server)
        server.serve()
        conn.close()

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    session = open_robot(f"serial://socket://127.0.0.1:{port}?lockstep=1&timeout=0.5",
                         CONFIG)
    try:
        assert session.robot.read().sensors[SensorId.SFL].ok
        session.robot.command({MotorId.MWB: 1.0})
        session.clock.advance(0.1)
        assert session.robot.read().motors[MotorId.MWB].turns > 0.05
    finally:
        session.close()
        servers[0].stop()
        thread.join(5)
        listener.close()


class _PtyPort(serial.Serial):
    """A pty has no modem lines: report them idle, ignore setting them."""

    cts = dsr = ri = cd = property(lambda self: False)  # type: ignore[assignment]

    def _update_rts_state(self) -> None:
        pass

    def _update_dtr_state(self) -> None:
        pass


class _Rfc2217Bridge:
    """A minimal RFC 2217 server (pyserial's PortManager) in front of the fake
    boards' pty, the way examples/rfc2217_server.py bridges a real port."""

    def __init__(self, device_path: str) -> None:
        self.device = _PtyPort(device_path, timeout=0.01)
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.alive = True
        self.threads = [threading.Thread(target=self._serve, daemon=True)]
        self.threads[0].start()

    def write(self, data: bytes) -> None:  # PortManager's connection
        self.conn.sendall(data)

    def _serve(self) -> None:
        self.conn, _ = self.listener.accept()
        manager = serial.rfc2217.PortManager(self.device, self)

        def device_to_net() -> None:
            while self.alive:
                data = self.device.read(self.device.in_waiting or 1)
                if data:
                    self.conn.sendall(b"".join(manager.escape(data)))

        self.threads.append(threading.Thread(target=device_to_net, daemon=True))
        self.threads[-1].start()
        while self.alive:
            data = self.conn.recv(4096)
            if not data:
                break
            self.device.write(b"".join(manager.filter(data)))

    def close(self) -> None:
        self.alive = False
        for t in self.threads:
            t.join(5)
        self.conn.close()
        self.listener.close()
        self.device.close()


@pytest.mark.filterwarnings("ignore:set(Daemon|Name)\\(\\) is deprecated:DeprecationWarning")
def test_any_pyserial_url_works_as_the_port_rfc2217(fake: Fake) -> None:
    bridge = _Rfc2217Bridge(fake.path)
    session = open_robot(f"serial://rfc2217://127.0.0.1:{bridge.port}?baud=115200&lockstep=1&timeout=1",
                         CONFIG)
    try:
        session.robot.command({MotorId.MTB: -10.0})
        session.clock.advance(0.1)
        assert session.robot.read().motors[MotorId.MTB].turns < -0.5
    finally:
        session.close()
        bridge.close()


def test_spy_wrapper_sees_the_traffic(fake: Fake, tmp_path: Path) -> None:
    dump = tmp_path / "spy.txt"
    session = open_robot(f"serial://spy://{fake.path}?file={dump}&lockstep=1&timeout=0.5",
                         CONFIG)
    session.robot.read()
    session.close()
    text = dump.read_text()
    assert "TX" in text and "RX" in text  # pyserial's spy:// hex dump of both directions


def test_lockstep_must_match_the_boards(fake: Fake) -> None:
    with pytest.raises(RobotUrlError, match="run in lockstep; add \\?lockstep=1"):
        fake.open("timeout=0.2&watchdog=1000")  # 3 x 200 ms fit in 1 s - a tick


def test_url_options() -> None:
    port, opts = parse_serial_url(
        "serial://socket://127.0.0.1:5000?baud=115200&timeout=0.2&logging=debug")
    assert port == "socket://127.0.0.1:5000?logging=debug"
    assert opts["baud"] == 115200 and opts["timeout"] == 0.2
    assert parse_serial_url("serial:///dev/ttyUSB0")[0] == "/dev/ttyUSB0"
    with pytest.raises(RobotUrlError, match="baud: 'fast' is not an integer"):
        parse_serial_url("serial:///dev/ttyUSB0?baud=fast")
    with pytest.raises(RobotUrlError, match="lockstep"):
        parse_serial_url("serial:///dev/ttyUSB0?lockstep=2")
    with pytest.raises(RobotUrlError, match="timeout"):
        parse_serial_url("serial:///dev/ttyUSB0?timeout=0")


@pytest.mark.parametrize("url, problem", [
    ("serial:///dev/no-such-port", "cannot open port /dev/no-such-port"),
    ("serial://", "expected serial://PORT"),
])
def test_a_port_that_cannot_be_used_is_one_clear_line(url: str, problem: str) -> None:
    with pytest.raises(RobotUrlError) as info:
        open_robot(url, CONFIG)
    assert problem in str(info.value) and "\n" not in str(info.value)


def test_no_board_answering_is_a_hardware_error_naming_board_and_url() -> None:
    url = "serial://loop://?timeout=0.01&retries=1"
    with pytest.raises(NoBoardError) as info:
        open_robot(url, CONFIG)
    assert str(info.value) == (f"{url}: no motor board answered on the serial port "
                               "(2 tries of 10 ms)")
    assert (info.value.board, info.value.url) == ("motor", url)


def test_boards_that_go_away_mid_run_are_a_link_event_and_an_error() -> None:
    """The fake boards' process dies (its pty closes): the host's next write
    or read fails, and that is reported as a lost link, once, with what the
    host saw -- not a bare OSError, and not a run that merely ended."""
    world = make_world(CONFIG, SCENARIO, lockstep=True)
    pty = PtyPair()
    server = SerialBoardServer(pty.master, world, make_boards(world))
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    session = open_robot(f"serial://{pty.path}?lockstep=1&timeout=0.1", CONFIG)
    events: list[Event] = []
    robot_of(session).attach_sink(events.append)
    for _ in range(3):
        session.robot.read()
        session.clock.advance(0.02)
    server.stop()
    thread.join(5)
    pty.close()  # both ends: the port is gone
    with pytest.raises(LinkLostError) as info:
        for _ in range(20):
            session.robot.read()
            session.clock.advance(0.02)
    assert "link lost: cannot " in str(info.value) and "the serial port" in str(info.value)
    lost = [e for e in events if e.kind is EventKind.LINK]
    assert len(lost) == 1 and lost[0].message.startswith("link lost: ")
    session.close()
