"""Issue 35, defect 8: ``DIFFER`` flickered red at idle on 11 mm of noise
against a ``±5 mm`` title, while the robot itself accepted the pair (the
standing rule's tolerance at that distance is about 18 mm).  The panel now
judges each pair by the standing rule's own tolerance and changes its
verdict only once CONFIRM readings in a row say the new one."""

from __future__ import annotations

from stairbot.console.widgets.sensors import _Debounced, pair_tolerance_m, pair_verdict
from stairbot.control.perception import CONFIRM
from stairbot.control.robot_config import load_config
from stairbot.control.tolerances import standing_tolerance
from stairbot.hardware import SensorReading, SensorStatus

CFG = load_config()


def test_a_pair_is_judged_by_the_standing_rules_tolerance() -> None:
    a, b = SensorReading(0.26), SensorReading(0.271)
    tol = pair_tolerance_m(CFG, a, b, back=False)
    assert tol == standing_tolerance(CFG, 0.26)
    assert tol > 0.011  # 11 mm of noise: the robot accepts it
    assert pair_verdict(a, b, tol)[0].plain == "agree"
    assert pair_tolerance_m(CFG, SensorReading(0.04), SensorReading(0.05), back=True) \
        == standing_tolerance(CFG, 0.04, back=True)
    error = SensorReading(0.0, SensorStatus.ERROR)
    assert pair_tolerance_m(CFG, error, None, back=True) == CFG.algorithm.equal_tolerance


def test_a_verdict_changes_only_after_confirm_readings_in_a_row() -> None:
    tol = 0.01
    agree = pair_verdict(SensorReading(0.3), SensorReading(0.305), tol)
    differ = pair_verdict(SensorReading(0.3), SensorReading(0.33), tol)
    shown = _Debounced()
    t = 0.0
    assert shown.see(agree, t)[0].plain == "agree"
    for _ in range(5):  # a lone DIFFER between agreeing readings never shows
        t += 0.02
        assert shown.see(differ, t)[0].plain == "agree"
        t += 0.02
        assert shown.see(agree, t)[0].plain == "agree"
    for i in range(CONFIRM):
        t += 0.02
        word = shown.see(differ, t)[0].plain
        assert word == ("DIFFER" if i == CONFIRM - 1 else "agree")
    # the same reading seen again (the screen redraws between readings) counts once
    assert shown.see(agree, t)[0].plain == "DIFFER"
    assert shown.see(agree, t)[0].plain == "DIFFER"


def test_a_pair_that_cannot_be_compared_says_so_at_once_and_back() -> None:
    tol = 0.01
    agree = pair_verdict(SensorReading(0.3), SensorReading(0.305), tol)
    cannot = pair_verdict(SensorReading(0.3), SensorReading(0.0, SensorStatus.ERROR), tol)
    shown = _Debounced()
    assert shown.see(cannot, None)[0].plain == "cannot"
    assert shown.see(agree, 1.0)[0].plain == "agree"
    assert shown.see(cannot, 1.02)[0].plain == "cannot"
