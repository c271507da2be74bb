"""What one read of the simulated sensor board costs, and one advance of the
simulated robot, with and without the side pair SSR/SSL and a quarter-turn
landing.

The robot stands still (its wheels stopped, its lifts holding) where it is
put, and for each case the script times ``SimSensors.read`` (every distance
sensor, each measured anew: ``ideal`` sensors, or the presets' timing) and
``SimRobot.advance`` by one control tick (the physics, the frame switch's
check and the footprint check), in CPU microseconds, median over rounds of
many calls:

* ``reference``, default stairs, on the floor before the first riser (the four
  sensors; no walls to watch);
* ``landings``, default stairs, the same place (the side pair looking at
  nothing: every face tested);
* ``landings``, ``landing_left``, on the landing (the side pair sees a wall and
  flight 2's first riser; the landing's walls watched);
* ``landings``, ``landing_left``, on the landing in flight 2's frame (turned
  60 degrees left).

and, with the side pair, what its two casts alone cost (``side_seen``).

A script that prints figures, not a test.  Usage:

    python benchmarks/bench_sim_sensors.py [--rounds N] [--calls N]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from collections.abc import Callable

from stairbot.control.robot_config import load_config
from stairbot.fakes.sim import SimClock, SimRobot
from stairbot.inputs.scenario import load_scenario


def _median_us(fn: Callable[[], object], rounds: int, calls: int) -> float:
    per: list[float] = []
    for _ in range(rounds):
        t0 = time.process_time()  # CPU time: steadier than the wall clock on a shared machine
        for _ in range(calls):
            fn()
        per.append((time.process_time() - t0) / calls * 1e6)
    return statistics.median(per)


def _robot(config: str, scenario: str, on_landing: bool, turned_deg: float = 0.0
           ) -> tuple[SimRobot, SimClock]:
    robot = SimRobot(load_config(config), load_scenario(scenario))
    clock = SimClock(robot)
    if on_landing:
        w, h1 = robot.world, robot.well.h1
        for body in (*w.segments, *w.all_wheels):
            body.position = (body.position.x, body.position.y + h1)
        w.shift(robot.well.x1 + 0.5 - w.centre_x())
        robot.plan.x = w.centre_x()
        clock.advance(0.5)
        robot.plan.turn(math.radians(turned_deg))
        robot.advance(0.02)  # the frame switch, if turned past 45 degrees
    return robot, clock


def _case(robot: SimRobot, rounds: int, calls: int) -> tuple[float, float, float]:
    """Median microseconds of a read, of the side pair's casts (nan: none) and of
    an advance by one tick."""
    board, ticks = robot.board, iter(range(10**9))
    start = robot.world.time
    # each read a tick later (the physics standing still): the sensors measure when due
    read = _median_us(lambda: board.read(start + 0.02 * next(ticks)), rounds, calls)
    side = (_median_us(board.side_seen, rounds, calls) if board.side_model is not None
            else math.nan)
    advance = _median_us(lambda: robot.advance(0.02), rounds, calls // 5)
    return read, side, advance


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=7, help="rounds (median shown)")
    p.add_argument("--calls", type=int, default=500, help="calls a round")
    args = p.parse_args()
    cases = (("reference, default stairs, floor", "reference", "default", False, 0.0),
             ("landings, default stairs, floor", "landings", "default", False, 0.0),
             ("landings, landing_left, landing", "landings", "landing_left", True, 0.0),
             ("landings, landing_left, flight 2's frame", "landings", "landing_left", True,
              60.0))
    print(f"{'case':<42}{'read, us':>10}{'side casts, us':>16}{'advance 20 ms, us':>19}"
          f"{'frame':>7}")
    for label, config, scenario, on_landing, turned in cases:
        robot, _clock = _robot(config, scenario, on_landing, turned)
        read, side, advance = _case(robot, args.rounds, args.calls)
        print(f"{label:<42}{read:>10.1f}{side:>16.1f}{advance:>19.1f}{robot.well.flight:>7}")
    print(f"(median of {args.rounds} rounds of {args.calls} reads, each 20 ms after the last, "
          f"and {args.calls // 5} advances; the sensors' own timing applies: a VL53L1X "
          "measures every 50 ms; side casts: SimSensors.side_seen, both beams)")


if __name__ == "__main__":
    main()
