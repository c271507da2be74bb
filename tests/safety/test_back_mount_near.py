"""A back sensor biased short as segment 3 leaves its last surface before
descent (issue 33, limp home): descent 2's standing rule stops with the
pair apart, no onset names either, and the robot must still be named the
faulted sensor by what each read on that surface, and come home.

* Reference robot: the bias set in 0.24 s before ascent 7 lifted segment 3.
  The sensor read too near to measure for those last 12 ticks on the
  surface while its partner held its mount height; the second's mean
  averaged it away.
* Sonar robot: the sensor read too near for the whole last second, and its
  healthy partner read 4.3 mm over its mount height (the HC-SR04's 3 mm
  steps), beyond half the step threshold: it still held, against a clamp
  2 cm short.

The scenarios are cases of sweeps/sensor_faults.toml (their index in the
names); each ended stranded on the stairs before."""

from __future__ import annotations

from lost_sensor import degraded
from lost_sensor import sweep_flight as flight
from simrun import run_sim

from stairbot.control.algorithm.bias_evidence import MOUNT_TICKS, TAIL_TICKS, MountHeights
from stairbot.control.algorithm.bias_mount import by_mount
from stairbot.control.robot_config import load_config
from stairbot.events import Event
from stairbot.hardware import SensorId
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.runner import RunResult

CLEARANCE = 0.04
NEAR = 0.03
THRESHOLD = 0.02
"""About the reference robot's step threshold at descent 2's wait (m)."""


def run(text: str, robot: str) -> tuple[RunResult, list[Event]]:
    events: list[Event] = []
    r = run_sim(load_config(robot), parse_scenario(text, "<mount near>"), events, limp_home=True)
    return r, events


def home(r: RunResult) -> bool:
    return (r.outcome == "came_home_degraded" and not r.fell
            and r.steps_climbed == r.steps_descended == 2
            and r.final_offset_m is not None and r.final_offset_m <= 0.05)


def _judged(events: list[Event], sensor: str) -> str:
    stop = degraded(events)
    assert (stop["lost"], stop["biased"], stop["phase"], stop["then"]) == (
        [sensor], [sensor], "descent_lower_third", "limp_home"), stop
    failed = str(stop["failed"])
    assert f"{sensor} read too near to measure" in failed, failed
    return failed


def test_case_478_a_back_bias_set_in_as_segment_3_left_the_surface_is_named_by_its_tail() -> None:
    # SBR 3 cm short from 70.1 s, ascent 6 of the top step
    r, events = run(flight(573820, 70.1, "SBR", 'kind = "offset"\noffset = -0.03'), "reference")
    assert home(r), r.to_dict()
    assert "as it left the surface" in _judged(events, "SBR")


def test_case_503_sonar_a_back_sensor_too_near_is_named_beside_a_partner_4mm_off() -> None:
    # SBL 3 cm short from 43.4 s, ascent 7 of step 1
    r, events = run(flight(668896, 43.4, "SBL", 'kind = "offset"\noffset = -0.03'), "sonar")
    assert home(r), r.to_dict()
    assert "as it left the surface" not in _judged(events, "SBL")


def _stretch(tail: int, partner: float = CLEARANCE + 0.003) -> MountHeights:
    """A second on a surface, both sensors on their mount height, then SBR too
    near to measure for the last ``tail`` ticks while SBL reads ``partner``."""
    mount = MountHeights(CLEARANCE)
    for _ in range(MOUNT_TICKS):
        mount.add(CLEARANCE + 0.002, CLEARANCE + 0.003, False, False)
    for _ in range(tail):
        mount.add(NEAR, partner, True, False)
    mount.end()
    return mount


def test_a_tail_of_too_near_readings_names_the_sensor_the_disagreement_says() -> None:
    found = by_mount(_stretch(TAIL_TICKS), CLEARANCE, 0.027, 0.01, THRESHOLD)
    assert found is not None and found[0] is SensorId.SBR, found
    assert "as it left the surface" in found[1]


def test_a_tail_shorter_than_tail_ticks_names_nothing() -> None:
    assert by_mount(_stretch(TAIL_TICKS - 1), CLEARANCE, 0.027, 0.01, THRESHOLD) is None


def test_a_tail_whose_partner_strayed_names_nothing() -> None:
    # SBL 1.5 cm off its mount height meanwhile: the segment tipped, not a bias
    mount = _stretch(TAIL_TICKS, partner=CLEARANCE + 0.015)
    assert by_mount(mount, CLEARANCE, 0.027, 0.01, THRESHOLD) is None


def test_a_tail_that_says_the_other_way_names_nothing() -> None:
    # the pair now reads SBR the longer: its clamp said it read short
    assert by_mount(_stretch(TAIL_TICKS), CLEARANCE, -0.027, 0.01, THRESHOLD) is None


def test_a_partner_off_by_more_than_a_quarter_of_the_shortfall_names_nothing() -> None:
    mount = MountHeights(CLEARANCE)
    for _ in range(MOUNT_TICKS):
        mount.add(NEAR, CLEARANCE + 0.004, True, False)
    # the clamp says 1 cm short; a partner 4 mm off (over a quarter) did not hold
    assert by_mount(mount, CLEARANCE, 0.03, 0.01, 0.008) is None
    mount = MountHeights(CLEARANCE)
    for _ in range(MOUNT_TICKS):
        mount.add(CLEARANCE - 0.02, CLEARANCE + 0.0043, True, False)
    found = by_mount(mount, CLEARANCE, 0.03, 0.01, 0.008)
    assert found is not None and found[0] is SensorId.SBR, found
