"""The braille canvas and the scene model the picture draws from."""

from __future__ import annotations

from typing import Any

from stairbot.console.canvas import BrailleCanvas
from stairbot.control.robot_config import load_config
from stairbot.hardware import Scene
from stairbot.inputs.scenario import load_scenario
from stairbot.views.side_view import SceneView, scene_view, stairs_from_scenario


def test_dots_map_to_braille_bits() -> None:
    c = BrailleCanvas(2, 1)
    c.plot(0, 0)
    c.plot(1, 3)
    c.plot(2, 1)
    text = c.to_text().plain
    assert text == chr(0x2800 + 0x01 + 0x80) + chr(0x2800 + 0x02)


def test_off_canvas_dots_are_ignored_and_polygon_fills() -> None:
    c = BrailleCanvas(3, 2)
    c.plot(-1, 0)
    c.plot(100, 100)
    assert c.to_text().plain == "   \n   "
    c.polygon([(0, 0), (5, 0), (5, 7), (0, 7)], "red")
    assert c.to_text().plain == "⣿⣿⣿\n⣿⣿⣿"


def test_scenario_stairs_outline() -> None:
    sc = load_scenario()  # five steps 0.17 / 0.28
    pts = stairs_from_scenario(sc, 0.225)
    view = SceneView(stairs=pts)
    assert [round(x, 6) for x in view.risers()] == [0.0, 0.28, 0.56, 0.84, 1.12]
    assert abs(max(p[1] for p in pts) - 0.85) < 1e-9
    assert view.step_under(-0.1) == 0
    assert view.step_under(0.3) == 2


def test_scene_from_the_simulation_shows_the_robot_before_the_stairs() -> None:
    from stairbot.fakes.sim import open_sim_robot
    from stairbot.run.robots import RobotOptions

    session = open_sim_robot("sim://", load_config(), RobotOptions(world=load_scenario()))
    view = scene_view(session.sim.scene())  # type: ignore[union-attr]
    assert len(view.segments) == 3
    assert view.segment_steps() == [0, 0, 0]
    front = max(p[0] for p in view.segments[0])
    assert abs(front + 0.5) < 0.01  # the scenario puts the front 0.5 m before the riser
    assert len(view.wheels) == 6


def test_the_picture_is_the_scene_with_its_wheel_radius() -> None:
    scene = Scene(time_s=1.5, stairs=((0.0, 0.0), (1.0, 0.0)),
                  segments=(((0.0, 0.0), (1.0, 0.0), (1.0, 1.0)),), wheels=((0.5, 0.1),),
                  wheel_radius=0.02, yaw_deg=0.0, lateral_m=0.0, fell=False)
    view = scene_view(scene)
    assert view.stairs == scene.stairs and view.segments == scene.segments
    assert view.wheels == ((0.5, 0.1, 0.02),) and view.time_s == 1.5


def test_sensor_pairs_agree_differ_or_cannot_compare() -> None:
    from stairbot.console.widgets.sensors import pair_verdict
    from stairbot.hardware import SensorReading, SensorStatus

    def verdict(a: SensorReading, b: SensorReading) -> str:
        top, bottom = pair_verdict(a, b, 0.005)
        return f"{top.plain} {bottom.plain}"

    ok, near = SensorReading(0.500), SensorReading(0.503)
    far = SensorReading(0.520)
    out = SensorReading(1.3, SensorStatus.OUT_OF_RANGE)
    assert verdict(ok, near) == "agree Δ 3/5 mm"
    assert verdict(ok, far) == "DIFFER Δ 20/5 mm"
    assert verdict(ok, SensorReading(0.9)) == "DIFFER Δ>99/5 mm"
    assert verdict(out, out) == "both out of range"
    assert verdict(ok, SensorReading(0, SensorStatus.ERROR)) == "cannot compare"


def test_motor_direction_glyphs() -> None:
    from stairbot.console.widgets.motors import direction
    from stairbot.hardware import MotorId

    assert direction(MotorId.MWF, 1.0)[0] == "▶"
    assert direction(MotorId.MWL, -1.0)[0] == "◀"
    assert direction(MotorId.MTF, 10.0)[0] == "1▲"
    assert direction(MotorId.MTB, -10.0)[0] == "3▼"
    assert direction(MotorId.MTB, 0.0)[0] == "■"


def test_lift_arrows_show_the_segment_that_moves() -> None:
    """Issue 12 item 5, "it speaks code": a lift's arrow showed the motor's
    sign, not which segment moves.  Lifting segment 2 (ascent 5: segments 1
    and 3 stand) turns both lifts negative, and segment 2 rises."""
    from stairbot.console.widgets.motors import direction
    from stairbot.console.words import carried_by
    from stairbot.hardware import MotorId

    standing = carried_by("ascent_lift_second")
    assert standing == (1, 3)
    assert direction(MotorId.MTF, -10.0, standing)[0] == "2▲"
    assert direction(MotorId.MTB, -10.0, standing)[0] == "2▲"
    # Lifting segment 1 (ascent 3: segments 2 and 3 stand): segment 1 rises.
    assert direction(MotorId.MTF, 10.0, carried_by("ascent_lift_first"))[0] == "1▲"
    # Going down, lowering segment 3 (segments 1 and 2 stand).
    assert direction(MotorId.MTB, -10.0, carried_by("descent_lower_third"))[0] == "3▼"


def test_dead_reckoning_follows_the_simulated_climb() -> None:
    """The picture of a robot on a wire, from its counters alone, stays within
    5 cm (wheel slip adds up) and 2 cm in height of the simulation's truth
    over calibration and the first two steps."""
    from stairbot.run.robots import open_robot
    from stairbot.run.runner import RunControl, run
    from stairbot.views.reckon import dead_reckon

    cfg, sc = load_config(), load_scenario()
    from stairbot.run.robots import RobotOptions

    session = open_robot("sim://", cfg, RobotOptions(world=sc))
    control = RunControl()
    worst = [0.0, 0.0]

    def on_tick(_ctl: object, snap: Any) -> None:
        if round(snap.time_s / cfg.algorithm.tick) % 25:
            return
        truth = scene_view(session.sim.scene())  # type: ignore[union-attr]
        est = dead_reckon(snap, truth.stairs, cfg, sc.start.distance)
        for a, b in zip(truth.segments, est.segments, strict=True):
            worst[0] = max(worst[0], abs(_mean(a, 0) - _mean(b, 0)))
            worst[1] = max(worst[1], abs(_mean(a, 1) - _mean(b, 1)))
        if snap.time_s > 80.0:
            control.request_stop("enough")

    run(session, cfg, control=control, on_tick=on_tick)
    assert worst[0] < 0.05 and worst[1] < 0.02, worst


def _mean(points: Any, axis: int) -> float:
    return sum(p[axis] for p in points) / len(points)
