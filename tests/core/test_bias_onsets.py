"""The bias watch's onsets (:mod:`stairbot.control.algorithm.bias_onsets`) on
readings made up tick by tick: what a window's statistic lets through."""

from __future__ import annotations

from collections.abc import Callable

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


def _hang(watch: PairWatch, right_at: Callable[[int], float], left_at: Callable[[int], float],
          ticks: int = 400, first: int = 0) -> None:
    """Segment 3 hanging still, the pair reading ``right_at(k)`` and
    ``left_at(k)`` on ticks ``first`` to ``first + ticks``, with some noise."""
    start = WARM_SETTLES * settle_s(CONFIG, True)
    for k in range(first, first + ticks):
        t = start + k * TICK
        watch.tick(back_pair(t, right_at(k) - 0.001 * (k % 2), left_at(k) + 0.001 * (k % 3 - 1)),
                   0.0, 0.0, 0.0, False, ())


def test_a_disagreement_that_ends_is_no_onset_heavy_middle_envelope_1501() -> None:
    # segment 3 in the air after a climb, SBR's cone on the nosing reading
    # 2 cm long, then (the robot drove on) on the tread, agreeing with SBL:
    # SBR's step ended a disagreement, it began no offset (taken for one,
    # descent 1 matched a new split at the edge to it and judged SBR biased)
    watch = PairWatch(CONFIG, SensorId.SBR, SensorId.SBL, back=True)
    _hang(watch, lambda k: 0.066 if k < 150 else 0.046, lambda k: 0.046)
    assert watch.track.found == [] and watch.track.unconfirmed is None


def test_a_bias_that_ends_cancels_its_onset() -> None:
    # SBR reading 2 cm long from one tick on, then right again: its onset,
    # then the step back to agreement the onset explains, which cancels it
    watch = PairWatch(CONFIG, SensorId.SBR, SensorId.SBL, back=True)
    _hang(watch, lambda k: 0.066 if 100 <= k < 250 else 0.046, lambda k: 0.046, 250)
    [onset] = watch.track.found
    assert onset.sensor is SensorId.SBR and abs(onset.step_m - 0.02) < 0.003, onset
    _hang(watch, lambda k: 0.046, lambda k: 0.046, 200, first=250)
    assert watch.track.found == [] and watch.track.offsets[SensorId.SBR] == 0.0
