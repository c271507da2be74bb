"""The simulation of quarter-turn landings (stairbot/fakes/landing.py): the
stairwell's geometry, the side pair SSR/SSL, the switch to flight 2's frame
and back, the footprint check, and stairs without a landing as before."""

from __future__ import annotations

import math

import pytest

from stairbot.control.robot_config import load_config, parse_config
from stairbot.fakes.landing import Stairwell
from stairbot.fakes.plan import Plan
from stairbot.fakes.sim import SimClock, SimRobot
from stairbot.fakes.stairs import WALL_HEIGHT, stairs_outline
from stairbot.hardware import BASE_SENSORS, MotorId, SensorId, SensorStatus
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, parse_scenario

# the reference robot's mechanics, every sensor one exact ray, and the side pair
SIDE = parse_config('extends = "ideal"\n[sensors]\nside_model = "ideal"\n', "side.toml")
LANDINGS = load_config("landings")  # the shipped robot: a VL53L1X side pair
TICK = SIDE.algorithm.tick
SSR, SSL = SensorId.SSR, SensorId.SSL
R, L, MTF, MTB = MotorId.MWR, MotorId.MWL, MotorId.MTF, MotorId.MTB

# 3 steps (0.17 m rise, 0.28 m tread): the last riser (the top edge) at
# x = 0.56, the landing at 0.51 m, 1.0 m wide and `depth` deep
X1, H1, HALF = 0.56, 0.51, 0.5


def landing(turn: str = "left", count: int = 3, depth: float = 1.0, extra: str = "") -> Scenario:
    return parse_scenario(f"[stairs]\ncount = 3\nrise = 0.17\ntread = 0.28\n"
                          f"[landing]\ndepth = {depth}\nturn = '{turn}'\ncount = {count}\n"
                          f"[sensors]\nnoise = 0.0\n{extra}", "landing.toml")


def robot(scenario: Scenario, config: RobotConfig = SIDE) -> tuple[SimRobot, SimClock]:
    r = SimRobot(config, scenario)
    return r, SimClock(r)


def place(r: SimRobot, c: SimClock, x: float, lateral: float = 0.0) -> None:
    """Put segment 2's centre at ``x`` on the landing, ``lateral`` across it,
    square, and let it settle."""
    w = r.world
    for body in (*w.segments, *w.all_wheels):
        body.position = (body.position.x, body.position.y + H1)
    w.shift(x - w.centre_x())
    r.plan.x, r.plan.y = w.centre_x(), lateral
    c.advance(0.5)


def hold(r: SimRobot, c: SimClock, speeds: dict[MotorId, float], seconds: float) -> None:
    for _ in range(round(seconds / TICK)):
        r.command(speeds)
        c.advance(TICK)


def lift_ends(r: SimRobot, c: SimClock) -> None:
    """Segments 1 and 3 lifted 1 cm: segment 2's wheels alone carry the robot
    and it may turn."""
    hold(r, c, {MTF: 10.0, MTB: 10.0}, 0.5)


def side(r: SimRobot) -> tuple[float, float]:
    s = r.read().sensors
    return s[SSR].distance_m, s[SSL].distance_m


# -- the geometry ------------------------------------------------------------------


def test_flight_1s_side_view_ends_at_the_landings_far_wall() -> None:
    outline = stairs_outline(landing())
    assert outline[-3:] == [(X1, H1), (X1 + 1.0, H1), (X1 + 1.0, H1 + WALL_HEIGHT)]


@pytest.mark.parametrize("turn", ["left", "right"])
def test_flight_2s_side_view_has_the_opposite_wall_behind_and_its_risers_ahead(turn: str) -> None:
    well = Stairwell(landing(turn))
    out = well.outline(2)
    assert out[:3] == [(-HALF, H1 + WALL_HEIGHT), (-HALF, H1), (HALF, H1)]
    risers = [(x, y) for (x, y), (x2, _y2) in zip(out, out[1:], strict=False) if x == x2]
    assert risers[1:] == pytest.approx([(HALF, H1), (HALF + 0.28, H1 + 0.17),
                                        (HALF + 0.56, H1 + 0.34)])
    assert out[-1] == pytest.approx((HALF + 3 * 0.28 + 3.0, H1 + 3 * 0.17))
    assert well.width(2) == 1.0
    # flight 2's frame is a quarter turn of flight 1's, about the landing's middle line
    s = 1 if turn == "left" else -1
    assert well.from_flight1(X1 + 0.2, s * 0.3, s * math.radians(50.0), 2) == pytest.approx(
        (0.3, s * 0.3, s * math.radians(-40.0)))


def test_the_side_pair_reads_the_wall_and_flight_2s_first_riser() -> None:
    """On the middle of the landing, square: SSR sees the right wall and SSL
    flight 2's first riser, both 0.5 - 0.09 m away."""
    r, c = robot(landing("left"))
    place(r, c, X1 + 0.5)
    assert side(r) == pytest.approx((0.41, 0.41), abs=1e-3)
    r, c = robot(landing("right"))  # the wall on the left now
    place(r, c, X1 + 0.5, lateral=0.1)
    assert side(r) == pytest.approx((0.51, 0.31), abs=1e-3)


def test_lifting_segment_3_the_beam_clears_flight_2s_first_riser_not_the_wall() -> None:
    """SSL's beam, 3 cm above the wheels' contact line, rises with segment 3:
    once above the first riser's top (0.17 m over the landing) it meets the
    second riser, a tread further; SSR keeps seeing the wall."""
    r, c = robot(landing("left"))
    place(r, c, X1 + 0.5)
    readings = []
    for _ in range(9):
        hold(r, c, {MTB: 10.0}, 1.0)
        readings.append((r.world.lift_offset(1), *side(r)))
    below = [(ssr, ssl) for lift, ssr, ssl in readings if lift < 0.17 - 0.03 - 0.005]
    above = [(ssr, ssl) for lift, ssr, ssl in readings if lift > 0.17 - 0.03 + 0.005]
    assert below and above
    assert all(ssl == pytest.approx(0.41, abs=1e-3) for _, ssl in below)
    assert all(ssl == pytest.approx(0.41 + 0.28, abs=1e-3) for _, ssl in above)
    assert all(ssr == pytest.approx(0.41, abs=1e-3) for ssr, _ in below + above)


def test_without_a_second_flight_both_sides_are_walls() -> None:
    r, c = robot(landing("left", count=0))
    place(r, c, X1 + 0.5)
    assert side(r) == pytest.approx((0.41, 0.41), abs=1e-3)
    hold(r, c, {MTB: 10.0}, 9.0)
    assert r.world.lift_offset(1) > 0.17
    assert side(r) == pytest.approx((0.41, 0.41), abs=1e-3)


def test_the_side_pair_sees_flight_1s_side_walls_or_nothing() -> None:
    walled = parse_scenario("[stairs]\nwidth = 0.6\nside_wall = 'both'\n[start]\n"
                            "lateral = 0.05\n[sensors]\nnoise = 0.0\n", "walled.toml")
    r, _c = robot(walled)
    assert side(r) == pytest.approx((0.3 + 0.05 - 0.09, 0.3 - 0.05 - 0.09), abs=1e-3)
    r, _c = robot(parse_scenario("[sensors]\nnoise = 0.0\n", "open.toml"))
    snap = r.read().sensors
    assert snap[SSR].status is snap[SSL].status is SensorStatus.OUT_OF_RANGE


def test_turned_the_side_pair_meets_the_risers_ahead() -> None:
    """Turned 30 degrees right on the floor 0.5 m before riser 1 of a wide
    flight, SSL's beam runs forward-left into the first riser (a level beam
    meets any face it crosses between its bottom and top)."""
    r, _c = robot(parse_scenario("[stairs]\nwidth = 4.0\n[start]\nyaw_deg = -30.0\n"
                                 "[sensors]\nnoise = 0.0\n", "t"))
    well, x = r.well, r.world.centre_x()
    behind = -0.075  # segment 3's middle, where the pair rides
    ahead = -(x + behind * math.cos(math.radians(30.0)) + 0.09 * math.sin(math.radians(30.0)))
    assert side(r)[1] == pytest.approx(ahead / math.sin(math.radians(30.0)), abs=1e-3)
    assert well.side_hit(-1.0, 0.0, 0.2, 1.0, 0.0, 5.0) == pytest.approx((1.28, 1.0))


def test_a_robot_without_the_side_pair_reads_its_four_sensors_only() -> None:
    for config in (load_config(), load_config("ideal")):
        r, c = robot(landing(), config)
        place(r, c, X1 + 0.5)
        assert tuple(r.read().sensors) == BASE_SENSORS


def test_scenario_faults_reach_the_side_pair_and_the_shipped_robot_reads_it() -> None:
    r, c = robot(landing(extra="[[faults]]\nat = 0.0\nsensor = 'SSL'\nkind = 'error'\n"))
    assert r.read().sensors[SSL].status is SensorStatus.ERROR
    assert r.read().sensors[SSR].status is SensorStatus.OUT_OF_RANGE
    r, c = robot(landing(), LANDINGS)
    place(r, c, X1 + 0.5)
    hold(r, c, {}, 0.2)
    snap = r.read().sensors
    assert set(snap) == set(SensorId)
    assert snap[SSR].distance_m == pytest.approx(0.41, abs=0.03)  # the VL53L1X's noise


# -- the front pair on the landing ---------------------------------------------------


def test_plan_walls_over_part_of_the_length_stop_a_beam_only_there() -> None:
    plan = Plan(1.0, "none", x=0.0, yaw=math.radians(30.0), walls=(((1.0, math.inf),), ()))
    assert plan.left_wall and not plan.right_wall
    # the beam crosses y = 0.5 at x = 0.866: before the wall starts, it meets nothing
    assert plan.front_distance(0.0, 0.0, None, 1.0) is None
    plan.x = 0.5  # now it crosses at x = 1.366
    assert plan.front_distance(0.0, 0.0, None, 1.0) == pytest.approx(1.0)
    whole = Plan(1.0, "left", yaw=math.radians(30.0))
    assert whole.whole_length() == (True, False)
    assert whole.front_distance(0.0, 0.0, None, 1.0) == pytest.approx(1.0)


def test_turning_on_the_landing_the_front_pair_sees_its_walls() -> None:
    r, c = robot(landing("left"))
    place(r, c, X1 + 0.5)
    front = r.world.centre_x() + 0.1125
    sfr, sfl = r.board.front_seen()
    rounding = r.world.profile.radius  # the side view's surfaces are the stairs' radius thick
    assert (sfr, sfl) == pytest.approx((X1 + 1.0 - rounding - front,) * 2, abs=1e-6)
    r.plan.turn(math.radians(-50.0))  # SFR turned towards the right wall, nearer than the far one
    sfr, _ = r.board.front_seen()
    mount_y = 0.1125 * math.sin(math.radians(-50.0)) - 0.05 * math.cos(math.radians(-50.0))
    assert sfr == pytest.approx((HALF + mount_y) / math.sin(math.radians(50.0)), abs=1e-6)
    r.plan.turn(math.radians(100.0))  # SFL turned 50 degrees left, towards flight 2's first riser
    _, sfl = r.board.front_seen()
    assert sfl == pytest.approx((HALF + mount_y) / math.sin(math.radians(50.0)), abs=1e-6)


# -- the switch to flight 2's frame and back -------------------------------------------


def seen(r: SimRobot) -> list[float | None]:
    """Every beam's true distance now (before the sensors' models)."""
    side_r, side_l = r.board.side_seen()
    return [*r.board.front_seen(), *r.board._back_truth(),
            None if side_r is None else side_r[0], None if side_l is None else side_l[0]]


@pytest.mark.parametrize("turn", ["left", "right"])
def test_the_switch_keeps_the_robot_where_it_is_and_what_it_sees(turn: str) -> None:
    r, c = robot(landing(turn))
    place(r, c, X1 + 0.45, lateral=0.05)
    w, plan, well = r.world, r.plan, r.well
    s = 1 if turn == "left" else -1
    plan.turn(s * math.radians(45.5))
    heights = [body.position.y for body in w.segments]
    angles = [body.angle for body in (*w.segments, *w.all_wheels)]
    x, y, yaw = w.centre_x(), plan.y, plan.yaw
    before, pose = seen(r), r.truth()
    assert well.switch(w, plan) and well.flight == 2
    assert w.outline == well.outline(2) and w.profile.segments[0][:2] == (-HALF, H1 + 2.0)
    # segment 2's centre is where it was, in flight 2's frame
    assert (w.centre_x(), plan.y, plan.yaw) == pytest.approx(
        (s * y, -s * (x - (X1 + 0.5)), yaw - s * math.pi / 2))
    assert plan.width == 1.0 and plan.x == pytest.approx(w.centre_x())
    assert [body.position.y for body in w.segments] == heights
    assert [body.angle for body in (*w.segments, *w.all_wheels)] == angles
    after, now = seen(r), r.truth()
    # the front pair met the far wall in the side view, now as a wall of the top view,
    # which has no rounding (the side view's 1 mm): otherwise the same
    assert after[:2] == pytest.approx(before[:2], abs=2e-3)
    assert after[2:] == pytest.approx(before[2:], abs=1e-9)
    assert (now.flight, pose.flight) == (2, 1)
    assert (now.flight1_x_m, now.flight1_y_m, now.flight1_yaw_deg, now.offset_m,
            now.clear_of_stairs_m) == pytest.approx(
        (pose.flight1_x_m, pose.flight1_y_m, pose.flight1_yaw_deg, pose.offset_m,
         pose.clear_of_stairs_m), abs=1e-12)
    assert r.scene().stairs == tuple(well.outline(2))
    # turned back past 45 degrees: flight 1's frame as it was
    plan.turn(-s * math.radians(1.0))
    assert well.switch(w, plan) and well.flight == 1
    assert w.outline == stairs_outline(r.scenario)
    assert (w.centre_x(), plan.y, plan.yaw) == pytest.approx(
        (x, y, yaw - s * math.radians(1.0)), abs=1e-12)
    assert plan.walls == well.walls(1) and plan.width == 1.0


def test_turning_on_the_landing_switches_frames_with_counters_and_readings_continuous() -> None:
    """Driven as the controller would: ends lifted, segment 2's wheels turn the
    robot 90 degrees left (the frame switches at 45), then back."""
    r, c = robot(landing("left"))
    place(r, c, X1 + 0.5)
    lift_ends(r, c)
    flights, snaps, beams = [], [], []
    for speeds in ({R: 0.5, L: -0.5}, {R: -0.5, L: 0.5}):
        for _ in range(round(2.5 / TICK)):
            r.command(speeds)
            c.advance(TICK)
            snaps.append(r.read())
            flights.append(r.truth().flight)
            beams.append(seen(r))
    assert flights[0] == 1 and 2 in flights and flights[-1] == 1
    switches = [i for i in range(1, len(flights)) if flights[i] != flights[i - 1]]
    assert len(switches) == 2
    assert r.truth().flight1_yaw_deg == pytest.approx(0.0, abs=1e-6)
    for i in switches:
        a, b = snaps[i - 1], snaps[i]
        for motor in MotorId:  # a tick's worth of turning, no jump
            assert abs(b.turns(motor) - a.turns(motor)) < 0.02, motor
        # every beam moves by no more than a tick's turn (0.7 degrees) moves it
        for d0, d1 in zip(beams[i - 1], beams[i], strict=True):
            assert (d0 is None) == (d1 is None)
            assert d0 is None or d1 is None or abs(d1 - d0) < 0.02
    assert r.truth().wall_contact is None  # a 1 m landing leaves room to turn
    assert r.truth().flight1_x_m == pytest.approx(X1 + 0.5, abs=1e-3)


def test_no_switch_off_the_landing_nor_without_a_second_flight() -> None:
    r, c = robot(parse_scenario("[stairs]\ncount = 3\n[landing]\n[start]\nyaw_deg = 60.0\n",
                                "turned_start.toml"))
    c.advance(0.2)
    assert r.truth().flight == 1  # turned 60 degrees, but on the floor before flight 1
    r, c = robot(landing(count=0))
    place(r, c, X1 + 0.5)
    r.plan.turn(math.radians(60.0))
    assert not r.well.switch(r.world, r.plan) and r.well.flight == 1


def test_on_flight_2_turned_past_45_degrees_stays_in_flight_2s_frame() -> None:
    r, c = robot(landing("left"))
    place(r, c, X1 + 0.5)
    r.plan.turn(math.radians(80.0))
    assert r.well.switch(r.world, r.plan)
    r.world.shift(0.8)  # segment 2's centre past flight 2's first riser (x' = 0.5)
    r.plan.turn(math.radians(-80.0))  # turned 70 degrees right of flight 2
    assert not r.well.switch(r.world, r.plan) and r.well.flight == 2


# -- the footprint check -----------------------------------------------------------------


def test_turning_on_a_landing_too_small_touches_the_far_wall() -> None:
    r, c = robot(landing(depth=0.25))
    place(r, c, X1 + 0.125)  # 1.25 cm from the far wall and from the top edge
    lift_ends(r, c)
    assert r.truth().wall_contact is None
    hold(r, c, {R: 0.5, L: -0.5}, 1.0)
    contact = r.truth().wall_contact
    assert contact is not None and contact.startswith("segment 1 against the landing's far wall")


def test_standing_into_flight_2s_first_riser_is_a_contact_above_it_none() -> None:
    r, c = robot(landing("left"))
    place(r, c, X1 + 0.5, lateral=HALF - 0.08)  # the footprint 1 cm into the riser
    contact = r.truth().wall_contact
    assert contact is not None and contact.startswith("segment 1 against riser 1 of flight 2")
    well, w = r.well, r.world
    x, y, yaw = r.flight1_pose()
    assert well.contact(w, x, y - 0.01, yaw) is None  # 2 mm short
    for body in (*w.segments, *w.all_wheels):  # the whole robot above the riser's top
        body.position = (body.position.x, body.position.y + 0.18)
    assert well.contact(w, x, y, yaw) is None


def test_stairs_without_walls_are_not_watched() -> None:
    r, c = robot(parse_scenario("[start]\nlateral = 0.45\nyaw_deg = 30.0\n", "open.toml"))
    assert not r.well.watches()
    hold(r, c, {R: 1.0, L: 1.0}, 1.0)
    assert r.truth().wall_contact is None


def test_a_side_wall_of_flight_1_is_watched() -> None:
    r, c = robot(parse_scenario("[stairs]\nside_wall = 'left'\n[start]\nlateral = 0.3\n"
                                "yaw_deg = 30.0\n", "walled.toml"))
    assert r.truth().wall_contact is None
    hold(r, c, {MotorId.MWF: 1.0, MotorId.MWB: 1.0, R: 1.0, L: 1.0}, 3.0)
    contact = r.truth().wall_contact
    assert contact is not None and contact.startswith("segment 1 against flight 1's left wall")


# -- stairs without a landing ------------------------------------------------------------


def test_without_a_landing_the_truth_is_flight_1s_side_view() -> None:
    r, c = robot(parse_scenario("[start]\nyaw_deg = 10.0\nlateral = 0.1\n", "plain.toml"))
    hold(r, c, {R: 1.0, L: 1.0, MotorId.MWF: 1.0, MotorId.MWB: 1.0}, 1.0)
    t, w = r.truth(), r.world
    assert r.plan.walls is None and not r.well.turns
    assert (t.flight, t.flight1_x_m, t.flight1_y_m, t.flight1_yaw_deg) == (
        1, w.centre_x(), r.plan.y, pytest.approx(10.0))
    assert t.clear_of_stairs_m == w.clear_of_stairs_m()
    assert t.offset_m == math.hypot(w.centre_x() - w.start_x, r.plan.y - 0.1)


@pytest.mark.parametrize("turn", ["left", "right"])
def test_a_recording_poses_the_robot_in_flight_1s_frame_whichever_frame_the_side_view_is_in(
        turn: str) -> None:
    """The recording's stairs are flight 1's (written once, at the start): its
    pose of the segments stays in flight 1's frame after the switch, or the
    robot on flight 2 would be drawn where flight 2's frame put it."""
    from stairbot.recording.pose import SimulationPose

    r, c = robot(landing(turn))
    place(r, c, X1 + 0.45, lateral=0.05)
    s = 1 if turn == "left" else -1
    before = SimulationPose(r).poses(r.read())
    r.plan.turn(s * math.radians(45.5))
    turned = SimulationPose(r).poses(r.read())
    assert r.well.switch(r.world, r.plan) and r.scene().flight2 is not None
    after = SimulationPose(r).poses(r.read())
    for a, b in zip(turned, after, strict=True):
        assert (b.x, b.y, b.z, b.pitch, b.yaw) == pytest.approx(
            (a.x, a.y, a.z, a.pitch, a.yaw), abs=1e-6)
    x, y, _yaw = r.flight1_pose()
    assert (after[1].x, after[1].y) == pytest.approx((x, y), abs=1e-6)
    assert before[1].yaw == 0.0 and after[1].yaw == pytest.approx(s * math.radians(45.5))
