"""`stairbot fake-boards --firmware`: what a user is told when the firmware
cannot be built or run, and the options it does not take."""

from __future__ import annotations

import select
import shutil
from pathlib import Path

import pytest

from stairbot.cli.command import main
from stairbot.control.robot_config import load_config
from stairbot.fakes import firmware_boards
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.firmware_boards import FirmwareBoard, FirmwareError, build_firmware
from stairbot.fakes.plant_link import PlantLink
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
