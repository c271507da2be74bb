"""Segment 2 onto the step before segment 3 rises (ascent 6 and 7): the ir
robot on treads of 0.46-0.48 m, whose front pair, pitched nose down by
ascent 5, read the tread it stood on instead of the next riser, and the
ascent-7 stop that catches a segment 2 left behind the nosing whatever
left it there (docs/envelope.md, "Reach")."""

from __future__ import annotations

import pytest
import simrun

from stairbot.control.algorithm.ascent import LIFT_THIRD_MAX_PITCH_DEG
from stairbot.control.algorithm.texts.ascent import TIPPING_BACK
from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.hardware import ZERO_SPEEDS, HasTruth
from stairbot.inputs.scenario import parse_scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import run

IR = load_config("ir")
REFERENCE = load_config("reference")

CASE_176 = ("[start]\ndistance = 0.454797\nyaw_deg = -3.064325\nlateral = 0.031804\n"
            "[sensors]\nnoise = 0.001\nseed = 601193\n")
"""The start of reach case 176 on the ir robot (5 steps of 0.13 x 0.48 m:
a tilt stop at +15.5 degrees in ascent 7, then the fall)."""

HEALTHY_PITCH_DEG = 7.0
"""Above any pitch a healthy climb of these flights reaches (5.5-5.6 nose
down, in ascent 5 and 6)."""


@pytest.mark.parametrize("rise", [0.08, 0.13, 0.19])
def test_the_ir_robot_climbs_0_48_m_treads_driving_segment_2_on_by_turns(rise: float) -> None:
    """Ascent 6 drove by the Sharp pair's reading of the tread ~0.35 m ahead
    and ended 18 mm short; lifting segment 3 levered the robot over the
    nosing to the tilt stop (step 1 at rises 0.08 and 0.13, step 2 at
    0.19).  The riser, 0.415 m ahead, lies beyond where the pair meets the
    tread at -4.5 degrees: the drive goes by turns."""
    text = (f"[stairs]\ncount = 3\nrise = {rise}\ntread = 0.48\ntop = 'landing'\n"
            + CASE_176)
    events: list[Event] = []
    result = simrun.run_sim(IR, parse_scenario(text, "<t>"), events)
    assert (result.outcome, result.steps_climbed, result.steps_descended) == \
        ("completed", 3, 3), result.to_dict()
    assert not result.fell
    assert result.max_pitch_deg is not None and result.max_pitch_deg < HEALTHY_PITCH_DEG
    told = [e.message for e in events if e.kind is EventKind.INFO]
    assert sum("is beyond where the front pair meets the tread" in m for m in told) == 2


SHORT_SIX = ("[[faults]]\nat = 36.0\nsensor = 'SFR'\nkind = 'offset'\noffset = -0.03\n"
             "duration = 3.5\n[[faults]]\nat = 36.0\nsensor = 'SFL'\nkind = 'offset'\n"
             "offset = -0.03\nduration = 3.5\n")
"""Both front sensors 30 mm short from late in ascent 5 of step 1 through
ascent 6 (the reference robot, 2 steps of 0.17 x 0.30 m): ascent 6 ends
30 mm short by its readings, segment 2's rear axle behind the nosing."""

HOLD_S = 2.0
"""After the stop, the robot is left standing this long with every motor at 0."""


def test_ascent_7_stops_when_segment_2_pitches_past_level_and_the_robot_stands() -> None:
    """Without the stop, lifting segment 3 levered the robot over the
    nosing to the tilt stop at +15.3 degrees."""
    text = ("[stairs]\ncount = 2\nrise = 0.17\ntread = 0.30\ntop = 'landing'\n"
            "[start]\ndistance = 0.5\n[sensors]\nseed = 1\n" + SHORT_SIX)
    session = open_robot("sim://", REFERENCE,
                         RobotOptions(world=parse_scenario(text, "<t>")))
    try:
        result = run(session, REFERENCE)
        robot = session.robot
        assert isinstance(robot, HasTruth)
        assert result.outcome == "error" and not result.fell, result.to_dict()
        error = str(result.error)
        assert error.startswith(f"{TIPPING_BACK}: segment 2 pitches +3."), error
        assert "(ascent 7, step 1)" in error and "lifts holding" in error
        pitch = robot.truth().pitch_deg
        assert pitch is not None and LIFT_THIRD_MAX_PITCH_DEG < pitch < 5.0
        for _ in range(round(HOLD_S / REFERENCE.algorithm.tick)):
            robot.command(ZERO_SPEEDS)
            session.clock.advance(REFERENCE.algorithm.tick)
        truth = robot.truth()
        assert not truth.fell
        assert truth.pitch_deg is not None and truth.pitch_deg < 5.0
    finally:
        session.close()

