"""Descent 1's edge watch (stairbot.control.algorithm.edge): where it places the
back pair's crossing of an edge, fed readings tick by tick."""

from __future__ import annotations

import pytest

from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.edge import edge_bound
from stairbot.control.algorithm.edge_measure import edge_clearance_m, edge_doubt_m, edge_sight_m
from stairbot.control.algorithm.phase import Tick
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.control.algorithm.work import EdgeWork
from stairbot.control.robot_config import load_config
from stairbot.hardware import WHEEL_MOTORS, MotorId, MotorState, SensorId, SensorReading, Snapshot

CFG = load_config("reference")
FLOOR = CFG.BACK_CLEARANCE
DROP = FLOOR + 0.17


def _watch(right_at_m: float, left_at_m: float, ticks: int = 80) -> Context:
    """Back at full speed from 0 m; SBR reads the drop from ``right_at_m``
    backed, SBL from ``left_at_m``: the context once the watch placed the
    crossing."""
    ctx = Context(phase=Phase.DESCENT_BACK_OFF.value)
    speed_tps = -CFG.wheel_speed_m_s / CFG.wheel_circumference
    work: EdgeWork | None = None
    for i in range(ticks):
        backed = i * CFG.algorithm.tick * CFG.wheel_speed_m_s
        motors = {m: MotorState(0.0) for m in MotorId}
        for m in WHEEL_MOTORS:
            motors[m] = MotorState(-CFG.wheel_turns(backed), speed_tps)
        sensors = {SensorId.SFR: SensorReading(0.5), SensorId.SFL: SensorReading(0.5),
                   SensorId.SBR: SensorReading(DROP if backed >= right_at_m else FLOOR),
                   SensorId.SBL: SensorReading(DROP if backed >= left_at_m else FLOOR)}
        snap = Snapshot(i * CFG.algorithm.tick, sensors, motors)
        if work is None:
            work = EdgeWork.at_entry(snap)
        edge_bound(Tick(snap, CFG, ctx, Mode.FULL, lambda *a, **k: None), work, False)
        if ctx.descent.edge_wheel is not None:
            return ctx
    raise AssertionError("the watch placed no crossing")


def _crossing_m(ctx: Context) -> float:
    """How far from the start the watch placed the pair's crossing."""
    assert ctx.descent.edge_wheel is not None
    return -ctx.descent.edge_wheel * CFG.wheel_circumference


def test_both_sensors_reading_the_drop_together_place_the_crossing_their_lag_behind() -> None:
    ctx = _watch(0.05, 0.05)
    sight = edge_sight_m(CFG, CFG.wheel_speed_m_s)
    assert _crossing_m(ctx) == pytest.approx(0.05 - sight, abs=0.0025)


def test_one_sensor_reading_the_drop_first_places_the_crossing_between_the_two() -> None:
    """Case 99 of the landings sweep: SBL read the drop 12 mm after SBR.
    Placed where the second read it, the crossing was put 6 mm too far back
    (for the robot's centre line) and backing the rest of the clearance
    tipped the robot back.  One measurement period's backing of the lag is
    the sensors' timing, not counted (envelope case 1464 on sonar)."""
    together = _crossing_m(_watch(0.062, 0.062))
    apart = _crossing_m(_watch(0.050, 0.062))
    # half the 12 mm, less what one measurement period's backing explains
    assert apart == pytest.approx(together - (0.012 - edge_doubt_m(CFG)) / 2, abs=0.0015)
    # either sensor first: the same place
    assert _crossing_m(_watch(0.062, 0.050)) == pytest.approx(apart, abs=1e-9)


def test_the_bound_is_the_clearance_past_the_crossing() -> None:
    ctx = _watch(0.050, 0.062)
    assert ctx.descent.edge_wheel is not None
    bound = edge_bound(Tick(None, CFG, ctx, Mode.FULL, lambda *a, **k: None),  # type: ignore[arg-type]
                       EdgeWork(), False)
    assert bound == pytest.approx(ctx.descent.edge_wheel
                                  - CFG.wheel_turns(edge_clearance_m(CFG)))


def test_a_lag_one_measurement_period_explains_moves_no_crossing() -> None:
    together = _crossing_m(_watch(0.062, 0.062))
    within = _crossing_m(_watch(0.062 - edge_doubt_m(CFG) + 0.0005, 0.062))
    assert within == pytest.approx(together, abs=0.0025)
