"""The margins the simulation measures from its physics (fakes/margin_watch.py):
stability, edge and stroke, from a robot standing, placed by hand, and run."""

from __future__ import annotations

import math

import pytest

from stairbot.control.robot_config import load_config
from stairbot.fakes.margin_watch import CONTACT_TOL_M, MarginWatch, treads
from stairbot.fakes.world import World
from stairbot.inputs.scenario import load_scenario

CONFIG = load_config()


def world() -> World:
    return World(CONFIG, load_scenario())  # the default stairs: rise 0.17 m, tread 0.28 m


def watch(w: World) -> MarginWatch:
    """A watch of ``w``'s bodies that looks at every call."""
    return MarginWatch(w.segments, w.boxes, w.all_wheels, w.radius, w.params.stairs_radius,
                       CONFIG.motors.lift_travel, 0.0)


def centre_of_mass_x(w: World) -> float:
    bodies = [*w.segments, *w.all_wheels]
    return sum(b.mass * b.local_to_world(b.center_of_gravity).x for b in bodies) \
        / sum(b.mass for b in bodies)


def test_a_tread_s_nosing_is_where_a_riser_comes_up_onto_it() -> None:
    outline = [(-30.0, 0.0), (0.0, 0.0), (0.0, 0.17), (0.28, 0.17), (0.28, 0.34),
               (3.28, 0.34)]
    assert treads(outline) == [(-30.0, 0.0, 0.0, None), (0.0, 0.28, 0.17, 0.0),
                               (0.28, 3.28, 0.34, 0.28)]


def test_standing_on_the_floor_the_margin_is_the_centre_of_mass_inside_its_end_wheels() -> None:
    w = world()
    w.advance(1.0)  # settled on the floor, no lift moved
    com = centre_of_mass_x(w)
    ends = [w.all_wheels[-2].position.x, w.all_wheels[1].position.x]  # the rearmost, the foremost
    m = w.margins
    assert m.stability_m == pytest.approx(min(com - ends[0], ends[1] - com), abs=1e-4)
    assert m.stability_m > 0.05
    assert m.edge_m is None  # the floor has no nosing
    assert m.stroke_m == pytest.approx(CONFIG.motors.lift_travel, abs=1e-3)


def poses(w: World, dx: float = 0.0, lift: float = 0.0) -> tuple[list[tuple[float, float, float]],
                                                                 list[tuple[float, float]]]:
    """The world's segments and wheels moved ``dx`` along x, every body ``lift`` up."""
    segments = [(b.position.x + dx, b.position.y + lift, b.angle) for b in w.segments]
    wheels = [(b.position.x + dx, b.position.y + lift) for b in w.all_wheels]
    return segments, wheels


def test_a_robot_on_its_front_wheels_alone_has_its_centre_of_mass_outside() -> None:
    w = world()
    w.advance(1.0)
    m = watch(w)
    segments, wheels = poses(w)
    # every wheel but segment 1's front one lifted clear of the floor
    wheels = [wheels[1] if i == 1 else (x, y + 0.05) for i, (x, y) in enumerate(wheels)]
    m.look(w.outline, segments, wheels, (0, 1, 2))
    assert m.stability_m == pytest.approx(centre_of_mass_x(w) - wheels[1][0], abs=1e-4)
    assert m.stability_m < -0.05


def test_a_gap_within_the_tolerance_still_bears_and_a_wider_one_does_not() -> None:
    w = world()
    w.advance(1.0)
    segments, wheels = poses(w, lift=CONTACT_TOL_M * 0.8)
    near = watch(w)
    near.look(w.outline, segments, wheels, (0, 1, 2))
    assert near.stability_m is not None and near.stability_m > 0.05
    segments, wheels = poses(w, lift=CONTACT_TOL_M * 1.5)
    far = watch(w)
    far.look(w.outline, segments, wheels, (0, 1, 2))
    assert far.stability_m is None  # resting on nothing: nothing measured


def test_a_wheel_standing_just_past_a_nosing_gives_the_edge_margin() -> None:
    w = world()
    w.advance(1.0)
    segments, wheels = poses(w)
    r = w.radius + w.params.stairs_radius
    # segment 1's rear wheel stands on tread 1, 4 mm past its nosing at x = 0
    wheels[0] = (0.004, 0.17 + r)
    m = watch(w)
    m.look(w.outline, segments, wheels, (0, 1, 2))
    assert m.edge_m == pytest.approx(0.004)
    # the same wheel while its segment is the one the lifts move, or while a wheel drives
    for judged in ((1, 2), ()):
        other = watch(w)
        other.look(w.outline, segments, wheels, judged)
        assert other.edge_m is None


def test_a_wheel_rolling_over_a_nosing_is_no_edge_margin() -> None:
    w = world()
    w.advance(1.0)
    segments, wheels = poses(w)
    r = w.radius + w.params.stairs_radius
    wheels[0] = (-0.003, 0.17 + math.sqrt(r * r - 0.003 ** 2))  # on the nosing's corner
    m = watch(w)
    m.look(w.outline, segments, wheels, (0, 1, 2))
    assert m.edge_m is None
    assert m.stability_m is not None


def test_the_stroke_margin_is_the_travel_left_at_the_more_extended_lift() -> None:
    w = world()
    m = watch(w)
    for lifts in ((0.05, -0.02), (0.01, -0.09), (0.0, 0.0)):
        m.due(0.02, lifts)
    assert m.stroke_m == pytest.approx(CONFIG.motors.lift_travel - 0.09)


def test_stability_and_edge_are_looked_at_every_period_the_stroke_every_tick() -> None:
    w = world()
    m = MarginWatch(w.segments, w.boxes, w.all_wheels, w.radius, w.params.stairs_radius,
                    CONFIG.motors.lift_travel, 0.1)
    looks = [m.due(0.02, (0.0, 0.0)) for _ in range(11)]
    assert looks == [True, False, False, False, False, True, False, False, False, False, True]
