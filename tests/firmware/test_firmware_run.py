"""The whole ascent and descent on the boards' C firmware: `stairbot
fake-boards --serial --firmware native|qemu --lockstep` in another process
(the motor and sensor boards' Linux programs, or their STM32F405 images in
qemu-system-arm, on the simulated robot's plant link), the runner in this
one on serial://<pty>, ending as sim:// does."""

from __future__ import annotations

import shutil
import signal
from pathlib import Path

import pytest
from lockstep_boards import lockstep_boards

from stairbot.control.robot_config import load_config
from stairbot.fakes.firmware_boards import KINDS, QEMU_TOOLS, find_cc
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult, run

SAME = ("outcome", "ascent_end", "steps_climbed", "steps_descended", "pauses", "fell")


def needs(kind: str) -> None:
    """Skip, saying why, without what building and running ``kind`` takes."""
    if find_cc() is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    missing = [t for t in QEMU_TOOLS if kind == "qemu" and shutil.which(t) is None]
    if missing:
        pytest.skip(f"no {' or '.join(missing)}: scripts/test installs gcc-arm-none-eabi, "
                    "picolibc-arm-none-eabi and qemu-system-arm")


@pytest.mark.parametrize("kind", KINDS)
def test_the_default_run_on_the_firmware_ends_as_sim_does(kind: str, tmp_path: Path) -> None:
    needs(kind)
    config, scenario = load_config(), load_scenario()
    sim = run(open_robot("sim://", config, RobotOptions(world=scenario)), config)
    with lockstep_boards(tmp_path, stop=signal.SIGTERM, firmware=kind) as boards:
        session = open_robot(boards.url + "&timeout=2", config)
        try:
            wire: RunResult = run(session, config)
            health = session.robot.diagnostics()["link"]
            truth = session.robot.truth()  # type: ignore[attr-defined]
        finally:
            session.close()
    assert boards.returncode == 0, boards.stderr
    if kind == "native":  # the programs' counts (the QEMU images print nothing)
        assert "sb_motor_native:" in boards.stderr and "sb_sensor_native:" in boards.stderr
    assert sim.outcome == "completed" and sim.steps_climbed == 5
    assert {k: getattr(wire, k) for k in SAME} == {k: getattr(sim, k) for k in SAME}
    assert wire.sim_time_s == pytest.approx(sim.sim_time_s, abs=1.0)
    assert wire.final_offset_m is not None and wire.final_offset_m < 0.05
    assert not truth.fell
    assert isinstance(health, dict) and health["lost"] == 0 and health["crc_errors"] == 0
