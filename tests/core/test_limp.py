"""The limp home's rules (stairbot/control/algorithm/limp.py): the survivor
of a pair stands in for the sensor lost, and the robot limps only where
each pair keeps one sensor, the IMU watches the tilt, and it is off a
landing."""

from __future__ import annotations

from stairbot.control.algorithm.limp import cannot_limp, mirrored, on_the_floor, survivors
from stairbot.control.algorithm.modes import Purpose
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.hardware import MotorId, MotorState, SensorId, SensorReading, SensorStatus, Snapshot


def snapshot() -> Snapshot:
    sensors = {SensorId.SFR: SensorReading(0.0, SensorStatus.ERROR),
               SensorId.SFL: SensorReading(0.31),
               SensorId.SBR: SensorReading(0.05), SensorId.SBL: SensorReading(0.06)}
    return Snapshot(1.0, sensors, {m: MotorState(0.0) for m in MotorId})


def test_the_survivor_of_a_pair_reads_for_the_sensor_lost() -> None:
    snap = snapshot()
    seen = mirrored(snap, ["SFR"])
    assert seen.sensors[SensorId.SFR] == seen.sensors[SensorId.SFL] == SensorReading(0.31)
    assert seen.sensors[SensorId.SBR] != seen.sensors[SensorId.SBL]  # the other pair as read
    assert snap.sensors[SensorId.SFR].status is SensorStatus.ERROR  # the snapshot untouched


def test_a_pair_with_no_survivor_the_imu_missing_or_a_landing_stop_the_limp() -> None:
    descent = Phase.DESCENT_LOWER_THIRD
    assert cannot_limp([SensorId.SBR], descent, None, True) is None
    assert survivors([SensorId.SBR, SensorId.SFL]) == ("SBL", "SFR")
    assert "both back sensors lost" in str(cannot_limp([SensorId.SBR, SensorId.SBL], descent,
                                                        None, True))
    assert "both front sensors lost" in str(cannot_limp([SensorId.SFR, SensorId.SFL], descent,
                                                         None, True))
    assert "no IMU" in str(cannot_limp([SensorId.SFR], descent, None, False))
    assert "landing" in str(cannot_limp([SensorId.SFR], Phase.LANDING_SCAN, None, True))
    assert "landing" in str(cannot_limp([SensorId.SFR], Phase.CAL_TURN, Purpose.LANDING, True))
    assert "landing" in str(cannot_limp([SensorId.SFR], descent, None, True,
                                        turned_at_landing=True))


def test_only_squaring_up_before_the_start_is_measured_counts_as_on_the_floor() -> None:
    assert on_the_floor(Phase.CAL_CHECK, Purpose.START, 0, Mode.FULL, began=False)
    assert not on_the_floor(Phase.CAL_TURN, Purpose.START, 0, Mode.FULL, began=True)
    assert on_the_floor(Phase.CAL_TURN, Purpose.START, 0, Mode.CALIBRATE_ONLY)
    assert not on_the_floor(Phase.ASCENT_APPROACH, None, 0, Mode.FULL)  # descent 7 backs home
    assert not on_the_floor(Phase.CAL_CHECK, Purpose.ASCENT, 1, Mode.FULL)
    assert not on_the_floor(Phase.DESCENT_BACK_TO_EDGE, None, 0, Mode.DESCEND)

