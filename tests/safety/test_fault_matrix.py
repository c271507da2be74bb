"""The fault matrix (stairbot/fakes/fault_matrix.py) in CI: every fault
once on CAN, in phases spread over the flight, and a few on serial; each
cell ends safe.  ``STAIRBOT_FAULT_MATRIX=full`` runs every cell (782; the
table in docs/reliability.md comes from ``benchmarks/fault_matrix.py``)."""

from __future__ import annotations

import os

import pytest

from stairbot.drivers import board_robot
from stairbot.drivers.board_robot import BoardRobot
from stairbot.fakes import boards as fake_boards
from stairbot.fakes import fault_matrix
from stairbot.fakes.fault_matrix import FAULTS, PHASES, cells, run_cell
from stairbot.fakes.firmware_boards import FirmwareBoardServer, find_cc
from stairbot.hardware import MotorId

# Each fault once on CAN; the 20 % faults in the descent, where less of the
# run is left to crawl through them.
CAN_PHASES = {
    "drop 1%": "ascent_lift_first", "drop 5%": "cal_turn", "drop 20%": "descent_lower_first",
    "corrupt 1%": "ascent_drive_second", "corrupt 5%": "ascent_drive_third",
    "corrupt 20%": "descent_finish",
    "late 1%": "descent_back_to_edge", "late 5%": "ascent_lift_second",
    "late 20%": "descent_drive_first",
    "duplicate 1%": "ascent_approach_turns", "duplicate 5%": "descent_back_off",
    "duplicate 20%": "descent_lower_second",
    "motor board killed": "ascent_lift_first_more", "sensor board killed": "cal_probe",
    "motor board hung": "descent_lower_third", "sensor board hung": "ascent_drive_first",
    "host killed": "ascent_lift_third",
}
SERIAL = [("late 5%", "descent_lower_second"), ("host killed", "cal_lift")]
# The boards' C firmware on the serial wire: a board that hangs (its own
# independent watchdog must stop its motors), one killed, a killed host, and
# corrupted frames the firmware's own CRC check must refuse.
FIRMWARE = [("motor board hung", "ascent_lift_second"), ("sensor board killed", "cal_turn"),
            ("host killed", "descent_drive_first"), ("corrupt 5%", "ascent_drive_first")]

if os.environ.get("STAIRBOT_FAULT_MATRIX") == "full":
    CELLS = list(cells())
else:
    CELLS = [(f, p, "can") for f, p in CAN_PHASES.items()] + [(f, p, "serial")
                                                              for f, p in SERIAL]
    CELLS += [(f, p, "firmware") for f, p in FIRMWARE]


def expected(fault: str) -> set[str]:
    """What a cell may end as: up to 5 % of frames faulty the run completes
    (issue 11); at 20 % it completes or stops safe; a dead board stops it; a
    killed host's run is finished by the next."""
    kind = FAULTS[fault].kind
    if kind == "wire":
        return {"completed"} if not fault.endswith("20%") else {"completed", "stopped"}
    return {"resumed"} if kind == "host" else {"stopped"}


def test_the_ci_subset_has_every_fault_and_real_phases() -> None:
    assert set(CAN_PHASES) == set(FAULTS)
    assert set(CAN_PHASES.values()) <= set(PHASES)


@pytest.mark.parametrize(("fault", "phase", "wire"), CELLS,
                         ids=[f"{w}-{f.replace(' ', '_')}-{p}" for f, p, w in CELLS])
def test_a_fault_in_any_phase_ends_safe(fault: str, phase: str, wire: str) -> None:
    if wire == "firmware" and find_cc() is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    cell = run_cell(fault, phase, wire)
    assert cell.injected, cell.reason
    assert cell.safe, cell.reason
    assert cell.verdict in expected(fault), (cell.verdict, cell.reason)
    if cell.verdict == "stopped" and FAULTS[fault].kind != "wire":
        # "no reply from the motor board for 0.50 s (StepTo: ...)", or, the
        # commands noticing first, "3 commands in a row went unanswered,
        # nothing from the motor board for 0.51 s"
        which = "motor" if fault.startswith("motor") else "sensor"
        assert "link lost" in cell.reason and f"from the {which} board for" in cell.reason


def careless_host(monkeypatch: pytest.MonkeyPatch) -> None:
    """A host that drives a lift in every command and never stops it, on
    boards with no watchdog and no command hold."""
    command = BoardRobot.command

    def lift_too(self: BoardRobot, speeds: dict[MotorId, float]) -> None:
        command(self, {**speeds, MotorId.MTB: 0.5})

    monkeypatch.setattr(BoardRobot, "command", lift_too)
    for name in ("stop_all", "estop", "close"):
        monkeypatch.setattr(BoardRobot, name, lambda self: None)
    monkeypatch.setattr(fake_boards.Board, "poll", lambda self: None)
    monkeypatch.setattr(board_robot, "COMMAND_HOLD_MS", 0)


def test_the_judge_sees_motors_left_running(monkeypatch: pytest.MonkeyPatch) -> None:
    """A host that drives a lift and does not stop it on a lost link, and
    boards with no watchdog and no command hold: the cell is UNSAFE, so the
    matrix can fail."""
    careless_host(monkeypatch)
    cell = run_cell("sensor board killed", "cal_lift", "can")
    assert cell.verdict == "UNSAFE"
    assert "motors left running" in cell.reason and "a lift moved" in cell.reason


def test_the_judge_sees_a_hung_firmware_board_left_driving(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The C motor board hung as segment 2 lifts with no independent watchdog
    to reset it: its motors run on with no host, and the cell is UNSAFE --
    so the firmware's cells can fail too."""
    if find_cc() is None:
        pytest.skip("no C compiler on PATH (cc, gcc or clang, or $CC): scripts/test installs gcc")
    monkeypatch.setattr(FirmwareBoardServer, "after_step", lambda self: None)
    cell = run_cell("motor board hung", "ascent_lift_second", "firmware")
    assert cell.verdict == "UNSAFE"
    assert "motors running 2 s on" in cell.reason


def ended_early(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every run of the matrix ends with an error after 3 s of robot time,
    in calibration, long before the descent."""
    real_run = fault_matrix.run

    def short(*args: object, **kwargs: object) -> object:
        return real_run(*args, max_sim_time_s=3.0, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(fault_matrix, "run", short)


def test_a_run_that_ends_safely_before_its_phase_is_untested(
        monkeypatch: pytest.MonkeyPatch) -> None:
    ended_early(monkeypatch)
    cell = run_cell("drop 5%", "descent_finish", "can")
    assert not cell.injected
    assert cell.verdict == "untested"
    assert cell.reason.startswith("the run never entered descent_finish (it ended error:")


def test_a_run_that_ends_unsafely_before_its_phase_is_unsafe(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Its own stop leaves a lift driving: UNSAFE, though its fault never began."""
    ended_early(monkeypatch)
    careless_host(monkeypatch)
    cell = run_cell("drop 5%", "descent_finish", "can")
    assert cell.verdict == "UNSAFE"
    assert cell.reason.startswith("the run never entered descent_finish")
    assert "motors left running" in cell.reason
