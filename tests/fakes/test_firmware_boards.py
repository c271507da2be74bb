"""`stairbot fake-boards --firmware`: what a user is told when the firmware
cannot be built or run, and the options it does not take."""

from __future__ import annotations

import shutil

import pytest

from stairbot.cli.command import main
from stairbot.fakes import firmware_boards
from stairbot.fakes.firmware_boards import FirmwareError, build_firmware


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
