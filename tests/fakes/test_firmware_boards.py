"""`stairbot fake-boards --firmware`: what a user is told when the firmware
cannot be built or run, and the options it does not take."""

from __future__ import annotations

import select
import shutil
import socket
from pathlib import Path

import pytest

from stairbot.cli.command import main
from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.serial_wire import Frame, encode_frame
from stairbot.fakes import firmware_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.firmware_boards import (
    FirmwareBoard,
    FirmwareBoardServer,
    FirmwareError,
    build_firmware,
)
from stairbot.fakes.plant_link import Delimited, PlantLink
from stairbot.fakes.sim import motor_limits
from stairbot.inputs.scenario import load_scenario


def test_qemu_without_its_tools_names_them_and_the_packages(
        monkeypatch: pytest.MonkeyPatch) -> None:
    which = shutil.which
    monkeypatch.setattr(firmware_boards.shutil, "which",
                        lambda name: None if name == "qemu-system-arm" else which(name))
    if firmware_boards.find_cc() is None:
        pytest.skip("no C compiler: the compiler's message comes first")
    with pytest.raises(FirmwareError) as refused:
        build_firmware("qemu")
    text = str(refused.value)
    assert "--firmware qemu needs" in text and "qemu-system-arm" in text
    assert "apt-get install" in text


def test_no_compiler_is_one_line_naming_what_to_install(monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    monkeypatch.setattr(firmware_boards, "find_cc", lambda: None)
    code = main(["fake-boards", "--serial", "--firmware", "native"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "needs a C compiler" in err and "apt-get install gcc" in err


def test_firmware_on_can_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exited:
        main(["fake-boards", "--can", "virtual/x", "--firmware", "native"])
    assert exited.value.code == 2
    assert "--firmware serves the serial wire only" in capsys.readouterr().err


def test_a_board_killed_with_a_question_in_flight_ends_its_link_quietly(
        tmp_path: Path) -> None:
    """The program dies after asking its plant: the answer has nowhere to
    go, and serving that link says it is over rather than raising (which
    would end the relay for the other board too)."""
    if firmware_boards.find_cc() is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    config = load_config()
    world = make_world(config, load_scenario(), lockstep=True)
    plant = PlantLink(world, 1, 7, motor_limits(config))
    board = FirmwareBoard(1, build_firmware("native", tmp_path) / "sb_motor_native", plant)
    try:
        while not plant.greeted:
            assert select.select([board.link], [], [], 5)[0], "the board never greeted its plant"
            assert board.serve_plant()
        assert select.select([board.link], [], [], 5)[0], "the board never asked again"
        board.proc.kill()
        board.proc.wait()
        assert board.serve_plant() is False
    finally:
        board.close()


class _Program:
    """A board's program as the relay sees it: what it was handed, and the
    socket its replies come back on (written to from the other end here)."""

    def __init__(self, address: int, exe: Path, plant: PlantLink) -> None:
        self.address = address
        self.exe = exe
        self.plant = plant
        self.host, self.other = socket.socketpair()
        self.link, self.plant_end = socket.socketpair()
        self.replies = Delimited()
        self.alive = True
        self.handed: list[bytes] = []

    def send(self, wire: bytes) -> None:
        self.handed += Delimited().frames(wire)

    def reply(self) -> None:
        self.other.sendall(b"\x05reply\x00")

    def close(self) -> str:
        for s in (self.host, self.other, self.link, self.plant_end):
            s.close()
        return ""


def test_a_boards_frames_go_on_together_and_the_other_boards_wait_for_every_reply(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The host's frames for the motor board are handed on at once (its
    line keeps them in order); the sensor board's frame behind them waits
    until the motor board has answered each, so a StepTo among them is done
    before the sensor board reads the world."""
    monkeypatch.setattr(firmware_boards, "FirmwareBoard", _Program)
    monkeypatch.setattr(FirmwareBoardServer, "_await_hello", lambda self: None)
    config = load_config()
    line, host = socket.socketpair()
    server = FirmwareBoardServer(line.fileno(), make_world(config, load_scenario(), True),
                                 Path("build"), motor_limits(config), (7, 8))
    motor, sensor = (server.firmware[int(b)] for b in (m.Board.MOTOR, m.Board.SENSOR))
    assert isinstance(motor, _Program) and isinstance(sensor, _Program)
    frames = [encode_frame(Frame(board, seq, (m.ReadAll(),), session=0x5A)) for board, seq in
              ((m.Board.MOTOR, 1), (m.Board.MOTOR, 2), (m.Board.MOTOR, 3), (m.Board.SENSOR, 4))]
    try:
        server.receive(b"".join(frames))
        assert motor.handed == frames[:3] and sensor.handed == []
        for _ in range(2):
            motor.reply()
            server._side_ready(motor.host.fileno())  # as serve() does
            assert sensor.handed == []
        motor.reply()
        server._side_ready(motor.host.fileno())  # as serve() does
        assert sensor.handed == frames[3:]
        assert host.recv(4096) == b"\x05reply\x00" * 3
    finally:
        server.close()
        line.close()
        host.close()
