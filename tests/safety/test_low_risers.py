"""Steps lower than the front sensors stand (30 mm up on every shipped
robot): the pair reads a riser beyond while the wheels push against the
first.  Ascent 2 finds the riser it placed going away, refuses the step,
and the robot comes home -- on the floor by an odometer the slipping wheels
ran on, which the robot corrects by placing the riser again backed off the
step -- or goes back down the steps it climbed.  A riser the start closed in
on and then lost (one below the beams) is refused the same way.

Each case here was stranded: pushing against the step until the phase
timed out, or stopped where it stood (sweeps/low_risers.toml finds them;
docs/envelope.md "Findings")."""

from __future__ import annotations

import pytest

from stairbot.control.robot_config import load_config
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.resume import moved_on
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult, run

HOME_M = 0.05


def flight(rise: float, tread: float = 0.28, count: int = 3, seed: int = 1,
           distance: float = 0.5) -> str:
    steps = ", ".join(f"{{ rise = {rise}, tread = {tread} }}" for _ in range(count))
    return (f"[stairs]\nsteps = [{steps}]\n[start]\ndistance = {distance}\n"
            f"[sensors]\nseed = {seed}\n")


def climb(text: str, robot: str) -> tuple[RunResult, list[str]]:
    config = load_config(robot)
    session = open_robot("sim://", config, RobotOptions(world=parse_scenario(text, "low.toml")))
    said: list[str] = []
    try:
        result = run(session, config, sink=lambda e: said.append(e.message))
    finally:
        session.close()
    return result, said


@pytest.mark.parametrize(("robot", "rise"), [
    ("reference", 0.025),  # the riser read holds until the wheels push, then goes away
    ("reference", 0.019),  # pressed against the step the pair pitches and reads short
    ("reference", 0.022),  # the standing rule pauses it against the step first
    ("reference", 0.016),  # the front wheels bounce on the lip: the riser read jumps
    ("ir", 0.0175),
    ("heavy_middle", 0.028),
])
def test_a_step_below_the_beams_is_refused_and_the_robot_comes_home(robot: str,
                                                                     rise: float) -> None:
    result, said = climb(flight(rise), robot)
    assert (result.outcome, result.ascent_end, result.steps_climbed) == (
        "completed", "obstacle", 0), result.to_dict()
    assert not result.fell
    assert result.final_offset_m is not None and result.final_offset_m <= HOME_M, \
        result.to_dict()
    assert any("is below the front sensors" in m for m in said), said


def test_slipping_wheels_are_told_and_the_start_moved_by_what_they_slipped() -> None:
    """The odometer ran on against the step: the robot says how much, and
    comes home within HOME_M of where it began (backing the odometer's
    count would leave it that far short)."""
    result, said = climb(flight(0.025), "reference")
    slipped = [m for m in said if "the wheels slipped" in m]
    assert len(slipped) == 1, said
    assert result.final_offset_m is not None and result.final_offset_m <= HOME_M


def test_a_low_step_mid_flight_is_refused_and_the_robot_goes_back_down() -> None:
    text = ("[stairs]\nsteps = [{ rise = 0.15, tread = 0.40 }, { rise = 0.022, tread = 0.30 }, "
            "{ rise = 0.15, tread = 0.30 }]\n[start]\ndistance = 0.5\n[sensors]\nseed = 3\n")
    result, said = climb(text, "reference")
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", "obstacle", 1, 1), result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m <= HOME_M
    assert any("step 2 is below the front sensors" in m for m in said), said


@pytest.mark.parametrize("rise", [0.01, 0.013])
def test_a_riser_closed_in_on_and_lost_at_the_start_sends_the_robot_home(rise: float) -> None:
    """The ir robot's Sharp pair reads the risers beyond from the start,
    closes in, and then reads nothing ahead: calibration's case 1, after it
    drove, backs the distance home instead of stopping where it stands."""
    result, said = climb(flight(rise), "ir")
    assert result.outcome == "completed", result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m <= HOME_M, \
        result.to_dict()
    assert any("nothing ahead after closing in" in m for m in said), said


def test_a_resume_moves_the_blocked_stand_on_with_the_phase_timers() -> None:
    """A host killed while the approach stands blocked resumes with the time
    it stood still not counted: the stand's start moves on with the phase's
    own timers (else a clock begun again would stand it until the phase
    timed out)."""
    saved = {"phase_started_s": 10.0, "work": {"still_since": 11.0, "blocked_since": 12.0,
                                               "went_m": 0.05}}
    moved = moved_on(saved, -5.0)
    assert (moved["phase_started_s"], moved["work"]["still_since"],
            moved["work"]["blocked_since"], moved["work"]["went_m"]) == (5.0, 6.0, 7.0, 0.05)
