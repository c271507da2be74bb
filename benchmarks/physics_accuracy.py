"""The physics step, checked for accuracy: what a cheaper pymunk step would
change.

The simulation steps pymunk ``WorldParams.dt`` at a time (12 steps a 20 ms
control tick) with ``WorldParams.iterations`` solver iterations.  Fewer of
either makes bare physics cheaper; this script says what it costs in
accuracy, against the shipped settings, on three checks:

1. **robot time**: the default run on every shipped robot (default stairs)
   ends as it does with the shipped settings -- the same outcome and steps --
   and its robot time is within ``--tolerance`` (0.1 s) of theirs;
2. **a fall is a fall**: the front-heavy robot of
   ``tests/safety/test_tilt_stops_a_fall.py`` (2.5 kg front segment, 4 cm
   calibration lift), run with neither the stability check nor the IMU,
   still topples;
3. **cost**: bare physics (``World.step_bare``) per control tick, by CPU time.

A candidate passes when 1 and 2 hold on every robot.  Prints one row per
candidate; asserts nothing.  Usage:

    python benchmarks/physics_accuracy.py [--steps 12 10 8 6] [--iterations 10 8 6]
                                          [--tolerance 0.1]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import msgspec

from stairbot.control.algorithm.controller import Controller
from stairbot.control.robot_config import load_config
from stairbot.fakes.sim import SimClock, SimRobot
from stairbot.fakes.world_params import WorldParams
from stairbot.hardware import MotorId
from stairbot.inputs.config import RobotConfig, shipped_configs
from stairbot.inputs.scenario import load_scenario
from stairbot.run.robots import RobotSession
from stairbot.run.runner import RunResult, run

BARE_S = 60.0
"""Simulated seconds of bare physics timed per candidate."""


def session(config: RobotConfig, params: WorldParams) -> RobotSession:
    """``sim://`` on the default stairs with these physics settings."""
    robot = SimRobot(config, load_scenario(), params)
    return RobotSession(robot=robot, clock=SimClock(robot), url="sim://", simulated=True,
                        sim=robot)


def default_run(config: RobotConfig, params: WorldParams) -> RunResult:
    s = session(config, params)
    try:
        return run(s, config)
    finally:
        s.close()


def topples(params: WorldParams) -> bool:
    """Whether the front-heavy robot, unwatched and unchecked, falls."""
    cfg = load_config()
    cfg = replace(cfg, masses=msgspec.structs.replace(cfg.masses, first_module=2.5),
                  algorithm=msgspec.structs.replace(cfg.algorithm, clearance_lift=0.04),
                  safety=msgspec.structs.replace(cfg.safety, imu=False))
    s = session(cfg, params)
    try:
        return run(s, cfg, controller=Controller(cfg, check_stability=False),
                   max_sim_time_s=60.0).fell
    finally:
        s.close()


def bare_us_per_tick(params: WorldParams) -> float:
    """CPU microseconds of bare physics per 20 ms tick, wheels driving."""
    config = load_config()
    robot = SimRobot(config, load_scenario(), params)
    robot.command({m: config.motors.wheel_speed for m in
                   (MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL)})
    tick = config.algorithm.tick
    ticks = round(BARE_S / tick)
    cpu0 = time.process_time()
    for _ in range(ticks):
        robot.world.step_bare(tick)
    return (time.process_time() - cpu0) / ticks * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, nargs="+", default=[12, 10, 8, 6],
                    help="physics steps per 20 ms tick (default: 12 10 8 6)")
    ap.add_argument("--iterations", type=int, nargs="+", default=[10, 8, 6],
                    help="pymunk solver iterations (default: 10 8 6)")
    ap.add_argument("--tolerance", type=float, default=0.1,
                    help="robot time allowed off the shipped settings', s (default 0.1)")
    args = ap.parse_args()
    shipped = WorldParams()
    tick = load_config().algorithm.tick
    robots = shipped_configs()
    configs = {name: load_config(name) for name in robots}
    reference = {name: default_run(cfg, shipped) for name, cfg in configs.items()}
    print(f"shipped settings: {round(tick / shipped.dt)} steps a tick, "
          f"{shipped.iterations} iterations; robots: {', '.join(robots)}")
    print(f"{'steps':>5} {'iter':>4} {'bare us/tick':>12} {'topples':>7} "
          f"{'worst robot-time change':>24}  verdict")
    for steps in args.steps:
        for iterations in args.iterations:
            params = replace(shipped, dt=tick / steps, iterations=iterations)
            worst, worst_robot, same_end = 0.0, "-", True
            for name, cfg in configs.items():
                r, ref = default_run(cfg, params), reference[name]
                same_end &= (r.outcome, r.steps_climbed, r.steps_descended, r.fell) == (
                    ref.outcome, ref.steps_climbed, ref.steps_descended, ref.fell)
                change = abs(r.sim_time_s - ref.sim_time_s)
                if change > worst:
                    worst, worst_robot = change, name
            fell = topples(params)
            ok = same_end and fell and worst <= args.tolerance
            ends = "" if same_end else ", an outcome changed"
            print(f"{steps:>5} {iterations:>4} {bare_us_per_tick(params):>12.1f} "
                  f"{'yes' if fell else 'NO':>7} {worst:>8.2f} s ({worst_robot}){ends:>4}  "
                  f"{'passes' if ok else 'fails'}")


if __name__ == "__main__":
    main()
