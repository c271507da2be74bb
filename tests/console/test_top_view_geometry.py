"""The top view's geometry (stairbot/views/top_view.py): the stairwell seen from
above is the simulation's (fakes/landing.py), face for face; the footprint
is the one the simulation checks; the pose comes from Truth."""

from __future__ import annotations

import math

import pytest

from stairbot.control.robot_config import load_config
from stairbot.fakes import landing as sim_landing
from stairbot.fakes import stairs as sim_stairs
from stairbot.fakes.landing import Stairwell
from stairbot.fakes.sim import SimClock, SimRobot
from stairbot.hardware import Truth
from stairbot.inputs.scenario import Scenario, load_scenario, parse_scenario
from stairbot.views.top_view import (
    FLOOR_BEHIND,
    FOOTPRINT_MARGIN,
    LANDING,
    OPEN_FLOOR,
    RISER,
    RISER2,
    WALL,
    RobotShape,
    TopPose,
    contact_parts,
    footprint,
    nose,
    plan_of,
    top_pose,
)

SHAPE = RobotShape.of(load_config())  # 3 x 0.075 m, 0.16 + 0.02 m wide


def as_lines(scenario: Scenario) -> set[tuple[str, str, tuple[float, ...]]]:
    return {(line.kind, line.name, tuple(round(v, 9) for v in (*line.a, *line.b)))
            for line in plan_of(scenario).lines}


def faces_from_above(scenario: Scenario) -> set[tuple[str, str, tuple[float, ...]]]:
    out = set()
    for f in Stairwell(scenario).faces:
        a, b = ((f.at, f.lo), (f.at, f.hi)) if f.across == "x" else ((f.lo, f.at), (f.hi, f.at))
        out.add((f.kind, f.name, tuple(round(v, 9) for v in (*a, *b))))
    return out


def stairs(extra: str) -> Scenario:
    return parse_scenario(extra, "stairs.toml")


@pytest.mark.parametrize("scenario", [
    *(load_scenario(name) for name in ("landing_left", "landing_right", "landing_too_small",
                                       "landing_wall", "default", "wall_at_top",
                                       "side_wall_square")),
    stairs("[stairs]\ncount = 2\nside_wall = 'both'\ntop = 'wall'\n"),
    stairs("[stairs]\ncount = 2\nside_wall = 'left'\n"),
    stairs("[stairs]\ncount = 0\nside_wall = 'right'\n"),
    stairs("[stairs]\ncount = 3\nside_wall = 'both'\n[landing]\ndepth = 0.8\nturn = 'right'\n"
           "count = 2\n"),
    stairs("[stairs]\nsteps = [{rise = 0.15, tread = 0.3}, {rise = 0.18, tread = 0.26}]\n"
           "[landing]\ndepth = 1.2\nturn = 'left'\ncount = 2\nrise = 0.16\ntread = 0.31\n"),
], ids=lambda s: f"{s.name}-{len(s.steps)}-{s.side_wall}")
def test_the_stairwell_is_the_simulations_face_for_face(scenario: Scenario) -> None:
    assert as_lines(scenario) == faces_from_above(scenario)


def test_the_simulations_constants_are_the_same() -> None:
    assert (FLOOR_BEHIND, LANDING, OPEN_FLOOR) == (sim_stairs.FLOOR_BEHIND, sim_stairs.LANDING,
                                                   sim_stairs.OPEN_FLOOR)
    assert FOOTPRINT_MARGIN == sim_landing.FOOTPRINT_MARGIN


def test_a_left_landing_from_above() -> None:
    """landing_left: 3 risers 0.28 m apart across a 1 m flight, the landing 1 m
    deep from the last one (x = 0.56), flight 2 leaving it on the left (+y)."""
    plan = plan_of(load_scenario("landing_left"))
    risers = sorted(line.a[0] for line in plan.lines if line.kind == RISER)
    assert risers == pytest.approx([0.0, 0.28, 0.56])
    second = sorted(line.a[1] for line in plan.lines if line.kind == RISER2)
    assert second == pytest.approx([0.5, 0.78, 1.06])
    walls = {line.name: line for line in plan.lines if line.kind == WALL}
    assert walls["the landing's far wall"].a[0] == pytest.approx(1.56)
    assert walls["the landing's right wall"].a[1] == pytest.approx(-0.5)
    x0, y0, x1, y1 = plan.bounds
    assert x0 < -0.5 - 0.5  # the start (0.5 m before riser 1) and the floor behind it
    assert x1 > 1.56 and y0 < -0.5 and y1 > 1.06  # the far wall, both sides, flight 2
    assert plan.landing and plan.across == 1.0


def test_a_right_landing_goes_the_other_way_and_plain_stairs_have_no_landing() -> None:
    plan = plan_of(load_scenario("landing_right"))
    assert all(line.a[1] < 0 for line in plan.lines if line.kind == RISER2)
    assert plan.bounds[1] < -1.06 and plan.bounds[3] < 1.0
    plain = plan_of(load_scenario("default"))
    assert not plain.landing
    assert not any(line.kind in (WALL, RISER2) for line in plain.lines)
    assert len([line for line in plain.lines if line.kind == RISER]) == 5


def test_the_footprint_at_a_pose() -> None:
    """Segments end to end along the heading, segment 2 centred on the pose."""
    straight = footprint(TopPose(1.0, 0.0, 0.0), SHAPE)
    xs = [sorted({round(x, 9) for x, _ in seg}) for seg in straight]
    assert xs == [[1.0375, 1.1125], [0.9625, 1.0375], [0.8875, 0.9625]]
    assert {round(y, 9) for seg in straight for _, y in seg} == {-0.09, 0.09}
    left = footprint(TopPose(1.0, 0.2, 90.0), SHAPE)  # turned left: the front points +y
    front = max(y for _, y in left[0])
    assert front == pytest.approx(0.2 + 0.1125)
    assert max(x for x, _ in left[0]) == pytest.approx(1.09)
    tip, ahead = nose(TopPose(0.0, 0.0, -90.0), SHAPE, 0.05)
    assert tip == pytest.approx((0.0, -0.1125)) and ahead == pytest.approx((0.0, -0.1625))


def test_the_footprint_is_what_the_simulation_finds_in_contact() -> None:
    """Segment 1's footprint 1 cm into flight 2's first riser: the simulation
    reports it, by the name the plan gives that riser."""
    r = SimRobot(load_config("landings"), load_scenario("landing_left"))
    w = r.world
    for body in (*w.segments, *w.all_wheels):  # onto the landing (0.51 m up)
        body.position = (body.position.x, body.position.y + 0.51)
    w.shift(0.56 + 0.5 - w.centre_x())
    r.plan.x, r.plan.y = w.centre_x(), 0.5 - 0.08
    SimClock(r).advance(0.5)
    truth = r.truth()
    pose = top_pose(truth)
    assert pose is not None and pose.wall_contact is not None
    parts = contact_parts(pose.wall_contact)
    assert parts == (1, "riser 1 of flight 2")
    names = {line.name for line in plan_of(r.scenario).lines}
    assert parts[1] in names
    shape = RobotShape.of(r.config)
    assert max(y for _, y in footprint(pose, shape)[0]) == pytest.approx(0.51, abs=1e-3)


def test_the_pose_comes_from_truth_or_not_at_all() -> None:
    truth = Truth(fell=False, fall_reason=None, pitch_deg=0.0, max_pitch_deg=0.0,
                  offset_m=0.0, flight=2, flight1_x_m=1.1, flight1_y_m=0.2,
                  flight1_yaw_deg=88.0, wall_contact="segment 3 against the landing's far "
                                                     "wall at 41.20 s")
    assert top_pose(truth) == TopPose(1.1, 0.2, 88.0, 2, truth.wall_contact)
    blind = Truth(fell=False, fall_reason=None, pitch_deg=None, max_pitch_deg=None,
                  offset_m=None)
    assert top_pose(blind) is None


def test_a_contact_names_its_segment_and_face() -> None:
    assert contact_parts("segment 3 against the landing's far wall at 41.20 s") == (
        3, "the landing's far wall")
    assert contact_parts("segment 1 against flight 1's left wall at 0.02 s") == (
        1, "flight 1's left wall")
    assert contact_parts("something else") is None
    assert math.isclose(SHAPE.width, 0.18)
