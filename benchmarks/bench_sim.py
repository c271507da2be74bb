"""How fast the simulation runs: the full default run against bare physics.

Prints three figures:

1. the realtime factor of the full default run (``stairbot run`` on the
   default scenario: controller, sensors, motors and physics), simulated
   seconds per wall second;
2. the realtime factor of the same world (same stairs, robot and physics step)
   stepped for the same simulated time with no controller, no sensors and no
   motor models (``World.step_bare``), the wheels driving forward;
3. the ratio of the two: how much the controller, sensors and motors add over
   bare physics stepping.

A script that prints figures, not a test: it asserts nothing.  Usage:

    python benchmarks/bench_sim.py [--repeat N] [--scenario FILE|NAME]
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

from stairbot.config import RobotConfig, load_config
from stairbot.hardware import MotorId
from stairbot.robots import RobotOptions, open_robot
from stairbot.runner import RunResult, run
from stairbot.scenario import Scenario, load_scenario


def full_run(config: RobotConfig, scenario: Scenario) -> RunResult:
    """One whole run of the program on ``sim://``, as fast as possible."""
    session = open_robot("sim://", config, scenario, RobotOptions())
    try:
        return run(session, config)
    finally:
        session.close()


def bare_run(config: RobotConfig, scenario: Scenario, sim_time_s: float) -> float:
    """Step a fresh world of the same scenario for ``sim_time_s`` in control-tick
    chunks with nothing but physics; returns the wall time taken."""
    session = open_robot("sim://", config, scenario, RobotOptions())
    robot: Any = session.sim  # stairbot.fakes.sim.SimRobot
    robot.command({m: config.motors.wheel_speed for m in
                   (MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL)})
    world, tick = robot.world, config.algorithm.tick
    steps = round(sim_time_s / tick)
    t0 = time.perf_counter()
    for _ in range(steps):
        world.step_bare(tick)
    return time.perf_counter() - t0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3, help="runs of each kind (median shown)")
    p.add_argument("--scenario", default=None, help="scenario file or name (default stairs)")
    args = p.parse_args()
    config, scenario = load_config(), load_scenario(args.scenario)

    full: list[float] = []
    bare: list[float] = []
    result: RunResult | None = None
    for _ in range(args.repeat):
        result = full_run(config, scenario)
        full.append(result.sim_time_s / result.wall_time_s)
        bare.append(result.sim_time_s / bare_run(config, scenario, result.sim_time_s))
    assert result is not None
    f, b = statistics.median(full), statistics.median(bare)
    print(f"scenario            {scenario.name}: outcome {result.outcome}, "
          f"{result.steps_climbed} up, {result.steps_descended} down, "
          f"{result.sim_time_s:.1f} s simulated")
    print(f"full run            realtime x{f:.0f}  (runs: "
          + ", ".join(f"x{v:.0f}" for v in full) + ")")
    print(f"bare physics        realtime x{b:.0f}  (runs: "
          + ", ".join(f"x{v:.0f}" for v in bare) + ")")
    print(f"full / bare time    {b / f:.2f}  (1.00 = the controller, sensors and motors "
          "cost nothing; the issue allows at most 1.50)")


if __name__ == "__main__":
    main()
