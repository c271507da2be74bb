"""The simulated robot through the Robot protocol: counters, limits, turning,
sensors in the world, determinism, instability, the sim:// URL and the clock."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import pytest

from stairbot.control.robot_config import load_config
from stairbot.errors import RobotFellError, RobotUrlError
from stairbot.fakes.sim import SimClock, SimRobot, open_sim_robot
from stairbot.hardware import (
    Clock,
    HasScene,
    HasTruth,
    MotorId,
    Robot,
    SensorId,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.scenario import Scenario, parse_scenario
from stairbot.run.robots import RobotOptions

CFG = load_config("ideal")  # the simulation's mechanics, read with one exact ray
TICK = CFG.algorithm.tick
F, B, R, L = MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL
MTF, MTB = MotorId.MTF, MotorId.MTB
ALL_FWD = {F: 1.0, B: 1.0, R: 1.0, L: 1.0}


def scenario(text: str = "") -> Scenario:
    return parse_scenario(text, "<test>")


def robot(text: str = "[sensors]\nnoise = 0.0\n") -> tuple[SimRobot, SimClock]:
    r = SimRobot(CFG, scenario(text))
    return r, SimClock(r)


def hold(r: SimRobot, c: SimClock, speeds: dict[MotorId, float], seconds: float) -> None:
    for _ in range(round(seconds / TICK)):
        r.command(speeds)
        c.advance(TICK)


def test_implements_the_protocols() -> None:
    r, c = robot()
    assert isinstance(r, Robot) and isinstance(c, Clock)
    assert isinstance(r, HasTruth) and isinstance(r, HasScene)


def test_wheel_counters_follow_the_distance_travelled() -> None:
    r, c = robot()
    c.advance(0.2)
    before, x0 = r.read(), r.world.centre_x()
    hold(r, c, ALL_FWD, 2.0)
    r.stop_all()
    c.advance(0.2)
    after = r.read()
    travelled = r.world.centre_x() - x0
    assert travelled == pytest.approx(0.2, rel=0.03)
    for m in (F, B, R, L):
        turns = after.turns(m) - before.turns(m)
        assert turns == pytest.approx(CFG.wheel_turns(travelled), rel=0.02)
    assert r.truth().offset_m == pytest.approx(travelled, abs=1e-4)


def test_backwards_counts_down() -> None:
    r, c = robot()
    hold(r, c, {m: -1.0 for m in (F, B, R, L)}, 1.0)
    snap = r.read()
    assert all(snap.turns(m) < -0.9 for m in (F, B, R, L))


def test_commands_beyond_the_motor_limits_are_clamped() -> None:
    r, c = robot()
    hold(r, c, {F: 5.0, B: 5.0, R: 5.0, L: 5.0, MTF: 50.0}, 1.0)
    snap = r.read()
    assert snap.motors[R].speed_tps == pytest.approx(CFG.motors.wheel_speed, rel=0.05)
    assert snap.turns(MTF) == pytest.approx(CFG.motors.lift_speed * 1.0, rel=0.05)


def test_lift_counters_are_the_actual_offsets_and_hold_when_stopped() -> None:
    r, c = robot()
    hold(r, c, {MTF: 10.0}, 1.0)
    raised = r.read().turns(MTF)
    assert raised == pytest.approx(10.0, abs=0.3)
    assert r.world.lift_offset(0) == pytest.approx(raised * CFG.motors.lift_travel_per_turn)
    hold(r, c, {}, 2.0)  # segment 1 cantilevered: the lead screw holds it
    assert r.read().turns(MTF) == pytest.approx(raised, abs=0.02)
    assert r.read().motors[MTF].speed_tps == pytest.approx(0.0, abs=0.05)


def test_lifts_stop_at_the_end_of_their_stroke() -> None:
    r, c = robot()
    hold(r, c, {MTF: 10.0}, CFG.MAX_OF_VERTICAL_TURNS / 10.0 + 1.0)
    assert r.read().turns(MTF) == pytest.approx(CFG.MAX_OF_VERTICAL_TURNS, abs=0.3)


def test_segment_two_turns_the_robot_only_with_both_ends_lifted() -> None:
    r, c = robot()
    spin = {R: 1.0, L: -1.0}
    hold(r, c, spin, 0.2)
    assert r.plan.yaw == 0.0  # ends on the ground scrub: no turn
    lift = CFG.NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE
    hold(r, c, {MTF: 10.0, MTB: 10.0}, lift / 10.0)
    start = r.read()
    hold(r, c, spin, 0.2)
    end = r.read()
    rate = 2 * CFG.wheel_circumference / CFG.geometry.track_width  # rad/s at 1 turn/s
    assert r.plan.yaw == pytest.approx(rate * 0.2, rel=0.05)
    assert end.turns(R) - start.turns(R) == pytest.approx(0.2, abs=0.02)
    assert end.turns(L) - start.turns(L) == pytest.approx(-0.2, abs=0.02)
    # turned left: the left sensor now stands further from the riser
    assert end.sensors[SensorId.SFL].distance_m > end.sensors[SensorId.SFR].distance_m


def test_front_and_back_sensors_see_the_riser_and_the_floor() -> None:
    r, c = robot()
    c.advance(0.2)
    snap = r.read()
    for s in (SensorId.SFR, SensorId.SFL):
        assert snap.sensors[s].status is SensorStatus.OK
        assert snap.sensors[s].distance_m == pytest.approx(0.5, abs=0.002)
    for s in (SensorId.SBR, SensorId.SBL):
        assert snap.sensors[s].distance_m == pytest.approx(CFG.BACK_CLEARANCE, abs=0.0015)


def test_open_floor_and_a_lifted_beam_read_out_of_range() -> None:
    r, c = robot("[stairs]\ncount = 0\n[sensors]\nnoise = 0.0\n")
    c.advance(0.1)
    assert r.read().sensors[SensorId.SFL].status is SensorStatus.OUT_OF_RANGE
    r, c = robot("[stairs]\ncount = 1\nrise = 0.1\ntread = 0.3\n[sensors]\nnoise = 0.0\n")
    hold(r, c, {MTF: 10.0}, 10.0)  # beam 0.2 m over the floor: above the landing
    assert r.read().sensors[SensorId.SFL].status is SensorStatus.OUT_OF_RANGE


def test_a_wall_at_the_top_is_seen_over_the_last_step() -> None:
    r, c = robot("[stairs]\ncount = 1\nrise = 0.1\ntread = 0.3\ntop = \"wall\"\n"
                 "[sensors]\nnoise = 0.0\n")
    hold(r, c, {MTF: 10.0}, 10.0)
    reading = r.read().sensors[SensorId.SFL]
    assert reading.status is SensorStatus.OK
    assert reading.distance_m == pytest.approx(0.5 + 0.3, abs=0.003)


def test_yawed_towards_a_side_wall_the_near_sensor_reads_the_wall() -> None:
    text = ("[stairs]\nwidth = 0.6\nside_wall = \"left\"\n"
            "[start]\ndistance = 1.0\nyaw_deg = 30.0\nlateral = 0.1\n[sensors]\nnoise = 0.0\n")
    r, c = robot(text)
    c.advance(0.1)
    snap = r.read()
    sfl, sfr = snap.sensors[SensorId.SFL], snap.sensors[SensorId.SFR]
    assert sfl.ok and sfr.ok
    assert sfl.distance_m < sfr.distance_m  # SFL meets the wall before the riser
    fwd = CFG.LENGTH_OF_FIRST_MODULE + CFG.LENGTH_OF_SECOND_MODULE / 2
    yaw = math.radians(30.0)
    y_sfl = 0.1 + fwd * math.sin(yaw) + CFG.sensors.front_lateral * math.cos(yaw)
    assert sfl.distance_m == pytest.approx((0.3 - y_sfl) / math.sin(yaw), abs=0.003)
    # the same pose with no side wall: the beam leaves the flight and sees nothing
    r2, c2 = robot(text.replace('"left"', '"none"'))
    c2.advance(0.1)
    assert r2.read().sensors[SensorId.SFL].status is SensorStatus.OUT_OF_RANGE


def test_scenario_faults_reach_the_readings() -> None:
    r, c = robot("[sensors]\nnoise = 0.0\n[[faults]]\nat = 0.1\nsensor = \"SBR\"\n"
                 "kind = \"error\"\nduration = 0.2\n")
    assert r.read().sensors[SensorId.SBR].ok
    c.advance(0.12)
    assert r.read().sensors[SensorId.SBR].status is SensorStatus.ERROR
    assert r.read().sensors[SensorId.SBL].ok
    c.advance(0.2)
    assert r.read().sensors[SensorId.SBR].ok


def script(r: SimRobot, c: SimClock) -> list[Snapshot]:
    out = []
    plan = [({MTF: 10.0, MTB: 10.0}, 0.6), ({R: 0.5, L: -0.5}, 0.3), ({MTF: -10.0, MTB: -10.0},
            0.6), (ALL_FWD, 1.0), ({MTF: 10.0}, 0.5)]
    for speeds, seconds in plan:
        for _ in range(round(seconds / TICK)):
            out.append(r.read())
            r.command(speeds)
            c.advance(TICK)
    out.append(r.read())
    return out


def test_same_scenario_and_commands_give_bit_identical_runs() -> None:
    text = "[sensors]\nnoise = 0.003\nseed = 5\n"
    a, b = script(*robot(text)), script(*robot(text))
    assert a == b
    other = script(*robot("[sensors]\nnoise = 0.003\nseed = 6\n"))
    assert [s.motors for s in other] == [s.motors for s in a]  # noise moves no wheel
    assert [s.sensors for s in other] != [s.sensors for s in a]


def test_reading_twice_at_one_time_gives_one_sample() -> None:
    r, c = robot("[sensors]\nnoise = 0.01\n")
    c.advance(TICK)
    assert r.read() is r.read()


def test_every_wheel_off_every_support_is_a_fall() -> None:
    r, c = robot()
    r.world.space.gravity = (0.0, 0.0)
    for body in r.world.space.bodies:
        body.position = (body.position.x, body.position.y + 0.05)
    with pytest.raises(RobotFellError, match="no wheel"):
        for _ in range(50):
            c.advance(TICK)
            r.read()
    assert r.truth().fell is True


def test_truth_diagnostics_and_scene_describe_the_pose() -> None:
    r, c = robot()
    c.advance(0.1)
    t = r.truth()
    assert not t.fell and t.fall_reason is None and t.offset_m is not None
    assert t.pitch_deg is not None and t.max_pitch_deg is not None
    assert abs(t.pitch_deg) <= t.max_pitch_deg < 1.0
    d = r.diagnostics()
    for key in ("sim_time_s", "yaw_deg", "lateral_m", "x_m", "lift_front_m", "lift_back_m"):
        assert key in d
    scene = r.scene()
    assert scene.stairs[1] == (0.0, 0.0)
    assert len(scene.segments) == 3 and len(scene.wheels) == 6
    assert scene.wheel_radius == CFG.geometry.wheel_radius
    front = max(x for x, _y in scene.segments[0])
    assert front == pytest.approx(-0.5, abs=0.002)


def test_open_sim_robot_accepts_only_sim_url() -> None:
    session = open_sim_robot("sim://", CFG, RobotOptions())
    assert session.simulated and isinstance(session.sim, SimRobot)
    assert session.robot is session.sim
    session.close()
    for bad in ("sim://host", "sim:///path", "sim://?x=1", "serial://x"):
        with pytest.raises(RobotUrlError):
            open_sim_robot(bad, CFG, RobotOptions())


def test_clock_paces_only_when_asked() -> None:
    wall = [0.0]
    slept: list[float] = []

    def sleep(s: float) -> None:
        slept.append(s)
        wall[0] += s

    r, _ = robot()
    fast = SimClock(r, None, monotonic=lambda: wall[0], sleep=sleep)
    fast.advance(0.1)
    assert slept == [] and fast.now() == pytest.approx(0.1)
    paced = SimClock(r, 2.0, monotonic=lambda: wall[0], sleep=sleep)
    paced.advance(0.2)
    assert sum(slept) == pytest.approx(0.1)
    session = open_sim_robot("sim://", CFG, RobotOptions(realtime=True))
    assert isinstance(session.clock, SimClock) and session.clock.time_scale == 1.0


_RUN_IN_CHILD = """
import hashlib
from stairbot.control.robot_config import load_config
from stairbot.inputs.scenario import parse_scenario
from stairbot.fakes.sim import SimClock, SimRobot
from stairbot.hardware import MotorId as M
r = SimRobot(load_config("ideal"), parse_scenario("[sensors]\\nnoise = 0.003\\n", "<child>"))
c = SimClock(r)
h = hashlib.sha256()
for i in range(150):
    s = r.read()
    h.update(repr((s.time_s, sorted(s.sensors.items()), sorted(s.motors.items()))).encode())
    r.command({M.MWF: 1.0, M.MWB: 1.0, M.MWR: 1.0, M.MWL: 0.8, M.MTF: 10.0 if i < 60 else 0.0})
    c.advance(0.02)
print(h.hexdigest())
"""


def test_runs_are_identical_across_processes() -> None:
    digests = set()
    for hash_seed in ("1", "2"):
        env = dict(os.environ, PYTHONHASHSEED=hash_seed)
        out = subprocess.run([sys.executable, "-c", _RUN_IN_CHILD], env=env, check=True,
                             capture_output=True, text=True)
        digests.add(out.stdout.strip())
    assert len(digests) == 1


def test_a_segment_dropping_fast_is_a_fall() -> None:
    r, c = robot()
    for body in r.world.space.bodies:
        body.position = (body.position.x, body.position.y + 0.3)
    with pytest.raises(RobotFellError, match="falling"):
        for _ in range(25):
            c.advance(TICK)
            r.read()
    r.stop_all()
    assert "falling" in str(r.truth().fall_reason)


def test_a_speed_that_is_not_a_number_stops_the_motor() -> None:
    r, c = robot()
    hold(r, c, {F: math.nan, B: math.inf, R: 1.0, L: 1.0}, 0.2)
    snap = r.read()
    assert r.world.lift_speed == [0.0, 0.0]
    assert math.isfinite(snap.turns(F)) and not r.world.fell


SIDE_WALL_YAWED = """
[stairs]
steps = [{rise = 0.1187, tread = 0.273}, {rise = 0.1211, tread = 0.2702}]
top = "wall"
width = 0.83
side_wall = "both"
[start]
distance = 0.773
yaw_deg = -16.4
lateral = -0.134
[sensors]
noise = 0.001
seed = 4086
"""


@pytest.mark.parametrize("yaw", [-16.4, 40.0, 60.0])
def test_the_robot_never_moves_faster_than_its_wheels(yaw: float) -> None:
    """A yawed robot driving at full speed, then turning, then driving again:
    segment 2's centre moves (top view) no faster than the wheels roll, and
    the wheel counters count the whole travel."""
    sim = SimRobot(CFG, scenario(SIDE_WALL_YAWED.replace("-16.4", str(yaw))))
    clock = SimClock(sim)
    # 15 %: the physics' transients for a few ticks when the wheels start with
    # the end segments lifted (steady driving is the wheels' speed to 0.1 %);
    # a yawed robot that outran its wheels did so by 1/cos(yaw): 31 % at 40°
    limit = CFG.wheel_speed_m_s * TICK * 1.15
    travelled = counted_fwd = travelled_fwd = 0.0
    for speeds in ([ALL_FWD] * 150 + [{MTF: 10.0, MTB: 10.0}] * 30
                   + [{R: 0.15, L: -0.15}] * 100 + [ALL_FWD] * 100):
        before = (sim.world.centre_x(), sim.plan.y)
        odometer = sim.read().turns(MotorId.MWR) + sim.read().turns(MotorId.MWL)
        sim.command(speeds)
        clock.advance(TICK)
        after = (sim.world.centre_x(), sim.plan.y)
        step = math.dist(before, after)
        if speeds is ALL_FWD:  # (lifting shifts the centre a little too: not a drive)
            assert step <= limit, f"moved {step * 1000:.2f} mm in one tick at yaw {yaw}"
        travelled += step
        counted = sim.read().turns(MotorId.MWR) + sim.read().turns(MotorId.MWL) - odometer
        if speeds is ALL_FWD:
            counted_fwd += counted / 2 * CFG.wheel_circumference
            travelled_fwd += step
    assert sim.offset_m() <= travelled + 1e-9
    # the encoders count the travel along the heading, not its projection
    assert counted_fwd == pytest.approx(travelled_fwd, rel=0.05)
