"""The console after a run that limped home (issue 33): the robot stands where
it began, so a new run is not refused as mid-climb."""

from __future__ import annotations

from stairbot.console.climb_gate import after_run
from stairbot.run.runner import RunResult


def ended(outcome: str) -> RunResult:
    return RunResult(outcome, "sensor_lost", 1, 1, 1, None, False, 4.2, 0.003, 113.5, 1.6,
                     72.0, True)


def test_a_run_that_came_home_degraded_is_not_mid_climb() -> None:
    assert after_run(ended("came_home_degraded"), "descent", "descent 7") is None
    assert after_run(ended("error"), "descent", "descent 3") is not None
