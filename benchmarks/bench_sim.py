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

Each figure is given by wall clock and by the process's CPU time (the latter
is steadier when other work shares the machine).

A script that prints figures, not a test: it asserts nothing.  Usage:

    python benchmarks/bench_sim.py [--repeat N] [--scenario FILE|NAME] [--config FILE]

(``--config`` chooses the robot, e.g. one whose ``[sensors] front_model`` and
``back_model`` name a realistic sensor preset.)
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

from stairbot.control.robot_config import load_config
from stairbot.hardware import MotorId
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, load_scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import RunResult, run


def full_run(config: RobotConfig, scenario: Scenario) -> tuple[RunResult, float]:
    """One whole run of the program on ``sim://``, as fast as possible; returns
    the result and the CPU time the run took."""
    session = open_robot("sim://", config, RobotOptions(world=scenario))
    try:
        cpu0 = time.process_time()
        result = run(session, config)
        return result, time.process_time() - cpu0
    finally:
        session.close()


def bare_run(config: RobotConfig, scenario: Scenario, sim_time_s: float) -> tuple[float, float]:
    """Step a fresh world of the same scenario for ``sim_time_s`` in control-tick
    chunks with nothing but physics; returns the wall time and CPU time taken."""
    session = open_robot("sim://", config, RobotOptions(world=scenario))
    robot: Any = session.sim  # stairbot.fakes.sim.SimRobot
    robot.command({m: config.motors.wheel_speed for m in
                   (MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL)})
    world, tick = robot.world, config.algorithm.tick
    steps = round(sim_time_s / tick)
    t0, cpu0 = time.perf_counter(), time.process_time()
    for _ in range(steps):
        world.step_bare(tick)
    return time.perf_counter() - t0, time.process_time() - cpu0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3, help="runs of each kind (median shown)")
    p.add_argument("--scenario", default=None, help="scenario file or name (default stairs)")
    p.add_argument("--config", default=None, help="robot config file (default: the shipped one)")
    args = p.parse_args()
    config, scenario = load_config(args.config), load_scenario(args.scenario)

    full: list[float] = []
    bare: list[float] = []
    full_cpu: list[float] = []
    bare_cpu: list[float] = []
    result: RunResult | None = None
    for _ in range(args.repeat):
        result, cpu = full_run(config, scenario)
        sim = result.sim_time_s
        full.append(sim / result.wall_time_s)
        full_cpu.append(sim / cpu)
        wall_b, cpu_b = bare_run(config, scenario, sim)
        bare.append(sim / wall_b)
        bare_cpu.append(sim / cpu_b)
    assert result is not None
    print(f"sensor models       front {config.sensors.front_model}, "
          f"back {config.sensors.back_model}")
    print(f"scenario            {scenario.name}: outcome {result.outcome}, "
          f"{result.steps_climbed} up, {result.steps_descended} down, "
          f"{result.sim_time_s:.1f} s simulated; median of {args.repeat} run(s)")
    print("                    realtime factor (simulated s per s)")
    print("                    by wall clock   by CPU time")
    for label, w, c in (("full run", full, full_cpu), ("bare physics", bare, bare_cpu)):
        print(f"{label:<20}x{statistics.median(w):<15.0f}x{statistics.median(c):.0f}")
    ratio_w = statistics.median(bare) / statistics.median(full)
    ratio_c = statistics.median(bare_cpu) / statistics.median(full_cpu)
    print(f"{'full / bare time':<20}{ratio_w:<16.2f}{ratio_c:.2f}")
    print("(1.00: the controller, sensors and motors cost nothing over bare physics; "
          "the issue allows at most 1.50.  CPU time is steadier on a busy machine.)")

if __name__ == "__main__":
    main()
