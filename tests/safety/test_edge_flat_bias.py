"""A back sensor biased long as descent 1 backs off the tread (issue 33): its
reading steps past the edge watch's drop line, far short of the step's rise
the robot measured climbing it, and holds there while the robot backs.  No
edge reads so (a crossed edge reads the rise within the backing its cone
takes to leave it): it is judged biased, and the robot comes home on its
partner, where the edge watch ended the run "turned too far from the edge".
A real edge, crossed by one sensor before the other, is never judged so.
The scenarios are cases of sweeps/sensor_faults.toml (their index in the
names)."""

from __future__ import annotations

from lost_sensor import degraded, home, sweep_flight
from simrun import run_sim

from stairbot.control.algorithm.bias_flat import FlatDrop, crossing_m, hold_m, short_of_m
from stairbot.control.algorithm.bias_rise import Rise
from stairbot.control.algorithm.edge_measure import edge_drop_m
from stairbot.control.robot_config import load_config
from stairbot.events import Event
from stairbot.hardware import SensorId, SensorReading, Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.runner import RunResult

REFERENCE = load_config()
SONAR = load_config("sonar")
RISE = 0.17
"""The sweep flight's rise."""


def run(cfg: RobotConfig, seed: int, at: float) -> tuple[RunResult, list[Event]]:
    events: list[Event] = []
    text = sweep_flight(seed, at, "SBR", 'kind = "offset"\noffset = 0.05')
    r = run_sim(cfg, parse_scenario(text, "<flat bias>"), events, limp_home=True)
    return r, events


def test_a_back_sensor_biased_long_while_backing_off_is_judged_and_the_robot_comes_home() -> None:
    # case 617: SBR 5 cm long from 107.7 s, as descent 1 of the top step
    # backs off: no second of mount heights on the tread, and the edge watch
    # ended the run 48 mm later with SBL "still the floor"
    r, events = run(REFERENCE, 503734, 107.7)
    assert r.outcome == "came_home_degraded" and home(r), r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["survivors"], stop["phase"]) == (
        ["SBR"], ["SBL"], "descent_back_off")
    assert "no edge explains it" in stop["failed"], stop["failed"]


def test_a_sonar_back_sensor_biased_long_while_backing_off_is_judged() -> None:
    # case 616 on the sonar robot: SBR 5 cm long from 102.9 s
    r, events = run(SONAR, 126182, 102.9)
    assert r.outcome == "came_home_degraded" and home(r), r.to_dict()
    stop = degraded(events)
    assert (stop["lost"], stop["phase"]) == (["SBR"], "descent_back_off")
    assert "no edge explains it" in stop["failed"], stop["failed"]


def _snap(i: int, right: float, left: float, cfg: RobotConfig) -> Snapshot:
    return Snapshot(i * cfg.algorithm.tick, {SensorId.SBR: SensorReading(right),
                                             SensorId.SBL: SensorReading(left)}, {})


def _backing(cfg: RobotConfig, reading_at: float, metres: float) -> SensorId | None:
    """Back ``metres`` a millimetre a tick, SBR reading ``reading_at(backed)``
    past the drop line from the start and SBL the floor: the sensor judged."""
    watch, rise = FlatDrop(cfg), Rise(1, RISE + cfg.BACK_CLEARANCE, RISE + cfg.BACK_CLEARANCE)
    for i in range(round(metres * 1000) + 1):
        backed = i / 1000
        found = watch.see(_snap(i, reading_at(backed), cfg.BACK_CLEARANCE, cfg), -backed, rise)
        if found is not None:
            return found[0]
    return None


def test_a_real_edge_crossed_one_sensor_first_is_never_judged() -> None:
    # the crossing sensor past the drop line grows to the rise within
    # crossing_m, at its slowest (a straight climb from the line); its
    # partner still reads the floor as far as the edge watch lets it (47 mm)
    for cfg in (REFERENCE, SONAR):
        drop, rise_m = edge_drop_m(cfg) + 0.001, RISE + cfg.BACK_CLEARANCE
        span = crossing_m(cfg, rise_m)

        def real(backed: float, drop: float = drop, rise_m: float = rise_m,
                 span: float = span) -> float:
            return min(rise_m, drop + (rise_m - drop) * backed / span)

        assert _backing(cfg, real, 0.1) is None, cfg.sensors.spec(True).name


def test_a_drop_held_short_of_the_rise_is_judged_only_past_the_crossing() -> None:
    for cfg in (REFERENCE, SONAR):
        rise_m = RISE + cfg.BACK_CLEARANCE
        held = cfg.BACK_CLEARANCE + 0.05
        assert edge_drop_m(cfg) < held < short_of_m(cfg, rise_m)
        assert _backing(cfg, lambda _b, h=held: h, 0.1) is SensorId.SBR
        # not before the backing a crossing would need
        assert _backing(cfg, lambda _b, h=held: h, hold_m(cfg, rise_m) - 0.002) is None
