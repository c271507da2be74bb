"""A sensor's repeated sample keeps its measurement time whatever the reply's
transit: the host reads each SensorTelemetry.sample once, so a reply that
came back faster than the last cannot make an old measurement new -- and
one erring measurement read three times over a jittery line is one
measurement, not "3 measurements in a row report an error"."""

from __future__ import annotations

from stairbot.control.perception import Perception
from stairbot.control.robot_config import load_config
from stairbot.drivers import messages as m
from stairbot.drivers.board_replies import ReplyReader
from stairbot.hardware import MotorId, MotorState, SensorId, SensorStatus, Snapshot

CFG = load_config("ideal")
TICK = CFG.algorithm.tick
OK, ERR = int(m.SensorCode.OK), int(m.SensorCode.ERROR)


def reply(sample: int, age_ms: int, code: int = OK, mm: int = 300) -> list[object]:
    """A sensor board's ReadAll reply: every channel the same sample."""
    status = m.Status(0, 0, 0, 0)
    tel = [m.SensorTelemetry(ch, code, mm, sample, age_ms)
           for ch in range(m.BASE_SENSOR_CHANNELS)]
    return [status, *tel]


def reader() -> ReplyReader:
    return ReplyReader("test://", None, lambda board, status: None)


def test_a_repeated_sample_read_back_faster_keeps_its_first_measurement_time() -> None:
    r = reader()
    # taken at 0.100 - 0.012 - 0.008 = 0.080; read again 20 ms later, its
    # reply 6 ms quicker: the board's age 32 ms and transit 2 ms would say 0.086
    first = r.sensors(reply(7, 12), 0.008, now=0.100)[SensorId.SFR]
    again = r.sensors(reply(7, 32), 0.002, now=0.120)[SensorId.SFR]
    assert round(0.100 - first.age_s, 6) == 0.080
    assert round(0.120 - again.age_s, 6) == 0.080
    # slower this time: older than first seen, as the board and transit say
    slow = r.sensors(reply(7, 52), 0.010, now=0.140)[SensorId.SFR]
    assert round(0.140 - slow.age_s, 6) == 0.078
    # a new sample is its own measurement, however near in time
    new = r.sensors(reply(8, 1), 0.001, now=0.160)[SensorId.SFR]
    assert round(0.160 - new.age_s, 6) == 0.158


def test_without_a_time_each_reading_is_aged_as_the_board_says() -> None:
    r = reader()
    r.sensors(reply(7, 12), 0.008, now=0.100)
    again = r.sensors(reply(7, 32), 0.002)[SensorId.SFR]
    assert round(again.age_s, 6) == 0.034


def see(p: Perception, sensors: dict[SensorId, object], t: float) -> SensorStatus:
    motors = {mid: MotorState(0.0) for mid in MotorId}
    snap = Snapshot(t, sensors, motors)  # type: ignore[arg-type]
    return p.see(snap).sensors[SensorId.SFR].status


def run_jittery(pinned: bool) -> list[SensorStatus]:
    """A sensor measuring every third tick, its fifth sample an error, read
    every tick over a line whose replies take 8 ms; the board answers 6, 3
    and 1 ms after the host sent, so each read of one sample looks newer than
    the last by the board's age and the transit alone."""
    r, p = reader(), Perception(CFG)
    statuses = []
    measured = 0.0
    for i in range(30):
        t = round((i + 1) * TICK, 6)
        if i % 3 == 0:
            measured = t - 0.010
        sample = i // 3 + 1
        up = (0.006, 0.003, 0.001)[i % 3]
        transit = 0.008
        age_ms = round((t - transit + up - measured) * 1000)
        code = ERR if sample == 5 else OK
        got = r.sensors(reply(sample, age_ms, code), transit, now=t if pinned else None)
        statuses.append(see(p, got, t))
    return statuses


def test_one_erring_sample_read_thrice_over_a_jittery_line_is_one_bad_measurement() -> None:
    assert set(run_jittery(pinned=True)) == {SensorStatus.OK}
    # each read taken as a measurement: the one error counts three times
    assert SensorStatus.ERROR in run_jittery(pinned=False)
