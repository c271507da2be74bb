"""The bias watch's onsets (:mod:`stairbot.control.algorithm.bias_onsets`) on
readings made up tick by tick: what a window's statistic lets through."""

from __future__ import annotations

from stairbot.control.algorithm.bias_onsets import WARM_SETTLES, PairWatch
from stairbot.control.robot_config import load_config
from stairbot.control.tolerances import settle_s
from stairbot.hardware import MotorId, MotorState, SensorId, SensorReading, Snapshot

CONFIG = load_config()
TICK = CONFIG.algorithm.tick


def back_pair(t: float, right: float, left: float) -> Snapshot:
    sensors = {SensorId.SFR: SensorReading(0.45), SensorId.SFL: SensorReading(0.45),
               SensorId.SBR: SensorReading(right), SensorId.SBL: SensorReading(left)}
    return Snapshot(t, sensors, {m: MotorState(0.0) for m in MotorId})


def test_a_spike_through_the_filter_in_a_window_is_no_onset() -> None:
    # standing still on a tread, both back sensors reading their mount
    # height; perception's median let 0.517 m through for three ticks (three
    # outliers among its five measurements: case 141 of sweeps/landings.toml),
    # in the first window the pair's windows held.  In that window's mean it
    # was an 8 cm step of SBL's, borne out by the next window.
    watch = PairWatch(CONFIG, SensorId.SBR, SensorId.SBL, back=True)
    start = WARM_SETTLES * settle_s(CONFIG, True)
    for k in range(400):
        t = start + k * TICK
        left = 0.517 if 3 <= k < 6 else 0.044 + 0.001 * (k % 3 - 1)
        watch.tick(back_pair(t, 0.046 - 0.001 * (k % 2), left), 0.0, 0.0, 0.0, False, ())
    assert watch.track.found == [] and watch.track.unconfirmed is None


def test_a_step_that_holds_is_still_an_onset() -> None:
    # the same pair, SBL reading 3 cm shorter from one tick on and holding
    watch = PairWatch(CONFIG, SensorId.SBR, SensorId.SBL, back=True)
    start = WARM_SETTLES * settle_s(CONFIG, True)
    for k in range(400):
        t = start + k * TICK
        left = 0.074 + 0.001 * (k % 3 - 1) - (0.03 if k >= 100 else 0.0)
        watch.tick(back_pair(t, 0.076 - 0.001 * (k % 2), left), 0.0, 0.0, 0.0, False, ())
    [onset] = watch.track.found
    assert onset.sensor is SensorId.SBL and abs(onset.step_m + 0.03) < 0.003, onset
