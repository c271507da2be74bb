"""How fast the simulation runs: the full default run against bare physics.

Prints three figures:

1. the realtime factor of the full default run (``stairbot run`` on the
   default scenario: controller, sensors, motors and physics), simulated
   seconds per wall second;
2. the realtime factor of the same world (same stairs, robot and physics step)
   stepped for the same simulated time with no controller, no sensors and no
   motor models (``World.step_bare``), the wheels driving forward;
3. the ratio of the two: how much the controller, sensors and motors add over
   bare physics stepping;
4. (with ``--parts``) what a tick of the full run costs by part: physics
   (pymunk's steps), world (the lifts, stability checks, odometry and the
   top view around them), sensors (the sensor models and their ray casts),
   records (the snapshot: motor states, IMU), perception (the sensors'
   verdicts and the bias watch), controller (the program's tick) and loop
   (the runner and the clock).  Each part's own CPU time, a part called
   inside another taken out of it, from one more run with a timer around
   each part (which adds about a microsecond a call to the part that calls
   it: the realtime figures come from the runs without timers).

Each figure is given by wall clock and by the process's CPU time (the latter
is steadier when other work shares the machine).

A script that prints figures, not a test: it asserts nothing.  Usage:

    python benchmarks/bench_sim.py [--repeat N] [--parts] [--scenario FILE|NAME] [--config FILE]

It runs the build that is installed: with ``STAIRBOT_COMPILE=1 bash
scripts/setup``, the modules of ``stairbot/compiled.py`` compiled by mypyc
(``STAIRBOT_PURE=1`` runs them as Python).  ``--parts`` needs the
pure-Python build: compiled modules call each other past the timers.

(``--config`` chooses the robot, e.g. one whose ``[sensors] front_model`` and
``back_model`` name a realistic sensor preset.)
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from stairbot import compiled
from stairbot.control.algorithm.bias import BiasWatch
from stairbot.control.algorithm.controller import Controller
from stairbot.control.perception import Perception
from stairbot.control.robot_config import load_config
from stairbot.fakes.sim import SimRobot
from stairbot.fakes.sim_sensors import SimSensors
from stairbot.fakes.world import World
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


PARTS: tuple[tuple[str, type, str], ...] = (
    ("physics", World, "_steps"),
    ("world", World, "advance"),
    ("world", SimRobot, "advance"),
    ("sensors", SimSensors, "read"),
    ("records", SimRobot, "read"),
    ("perception", Perception, "see"),
    ("perception", BiasWatch, "see"),
    ("controller", Controller, "tick"),
)
"""What is timed as which part: (part, class, method).  What no method here
covers is the loop's."""


@contextmanager
def timed_parts(own: dict[str, float]) -> Iterator[None]:
    """While inside, each method of :data:`PARTS` adds its own CPU time (its
    time less that of the timed methods it calls) to ``own[part]``."""
    clock = time.process_time
    inner: list[float] = []  # per timed call in progress: time spent in timed calls within

    def timer(part: str, method: Callable[..., Any]) -> Callable[..., Any]:
        def timed(*args: Any, **kwargs: Any) -> Any:
            t0 = clock()
            inner.append(0.0)
            try:
                return method(*args, **kwargs)
            finally:
                spent = clock() - t0
                own[part] = own.get(part, 0.0) + spent - inner.pop()
                if inner:
                    inner[-1] += spent
        return timed

    originals = [(cls, name, cls.__dict__[name]) for _part, cls, name in PARTS]
    try:
        for part, cls, name in PARTS:
            setattr(cls, name, timer(part, cls.__dict__[name]))
        yield
    finally:
        for cls, name, method in originals:
            setattr(cls, name, method)


def parts_run(config: RobotConfig, scenario: Scenario) -> tuple[dict[str, float], float, int]:
    """One more full run with a timer around each part: each part's own CPU
    time, the run's CPU time and the number of ticks."""
    own: dict[str, float] = {}
    with timed_parts(own):
        result, cpu = full_run(config, scenario)
    own["loop"] = cpu - sum(own.values())
    return own, cpu, round(result.sim_time_s / config.algorithm.tick)


def print_parts(own: dict[str, float], cpu: float, ticks: int) -> None:
    print(f"a tick by part      (one run with timers: {cpu:.2f} s CPU, {ticks} ticks)")
    print(f"{'':<20}{'us a tick':<16}share")
    for part in ("physics", "world", "sensors", "records", "perception", "controller",
                 "loop"):
        spent = own.get(part, 0.0)
        print(f"{part:<20}{spent / ticks * 1e6:<16.1f}{spent / cpu:.0%}")
    rest = cpu - own.get("physics", 0.0)
    print(f"{'all but physics':<20}{rest / ticks * 1e6:<16.1f}"
          f"{rest / max(own.get('physics', 0.0), 1e-9):.2f} x physics")


def build_name() -> str:
    if compiled.running_compiled():
        return f"compiled: {len(compiled.MODULES)} modules by mypyc (stairbot/compiled.py)"
    return "pure Python"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3, help="runs of each kind (median shown)")
    p.add_argument("--scenario", default=None, help="scenario file or name (default stairs)")
    p.add_argument("--config", default=None, help="robot config file (default: the shipped one)")
    p.add_argument("--parts", action="store_true",
                   help="one more run, timed by part of a tick (physics, sensors, ...)")
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
    print(f"build               {build_name()}")
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
    print("(1.00: the controller, sensors and motors cost nothing over bare physics.  "
          "CPU time is steadier on a busy machine.)")
    if args.parts and compiled.running_compiled():
        print(f"a tick by part      needs the pure-Python build ({compiled.PURE_ENV}=1): "
              "compiled modules call each other directly, past the timers")
    elif args.parts:
        print_parts(*parts_run(config, scenario))


if __name__ == "__main__":
    main()
