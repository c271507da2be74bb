"""Default runs on the in-process simulation with a host that now and then
stalls: does the controller ride out a late tick?

    python benchmarks/soak_host_stalls.py [--seeds 30] [--p 0.003]
                                          [--stall 0.05 0.15] [--config NAME]

A host stall -- a scheduler's time slice, a collection, a slow disk -- lets
the world run on with the last speeds sent for longer than a tick.  Here,
after each tick, with probability P the clock advances a tick plus a stall
drawn uniformly from [LOW, HIGH] seconds of robot time: the robot moves on
the last command for that long, unwatched.  The readings the host then takes
are fresh (this is the world running on, not a late reply; a late reply is
what the fake boards' ``--fault late`` and the IMU's age are for).  Fake CAN
boards at ``--time-scale 20`` with ``can.logger`` on the bus on a loaded
2-core machine see stalls of about this size: a 5 ms wall-clock stall there
is 100 ms of robot time (benchmarks/soak_can_logger.py).

Prints one line per run that did not complete (the phase it ended in, the
stalls in its last seconds) and a count of outcomes.  Exit status 1 if any
run did not complete or fell.  A script that prints figures, not a test.
"""

from __future__ import annotations

import argparse
import collections
import random
import sys

from stairbot.control.robot_config import load_config
from stairbot.events import Event, EventKind
from stairbot.hardware import Clock
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import run


class StallingClock:
    """``inner``, but each advance is now and then longer by a stall."""

    def __init__(self, inner: Clock, rng: random.Random, p: float, low: float,
                 high: float) -> None:
        self.inner, self.rng, self.p, self.low, self.high = inner, rng, p, low, high
        self.stalls: list[tuple[float, float]] = []  # (robot time, stall s)

    def now(self) -> float:
        return self.inner.now()

    def advance(self, dt: float) -> None:
        if self.rng.random() < self.p:
            stall = self.rng.uniform(self.low, self.high)
            self.stalls.append((self.inner.now(), stall))
            dt += stall
        self.inner.advance(dt)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=30)
    ap.add_argument("--p", type=float, default=0.003, help="chance of a stall after a tick")
    ap.add_argument("--stall", type=float, nargs=2, default=(0.05, 0.15),
                    metavar=("LOW", "HIGH"), help="a stall's length, s of robot time")
    ap.add_argument("--config", help="robot config (default: the default robot)")
    args = ap.parse_args(argv)
    cfg = load_config(args.config)
    counts: collections.Counter[str] = collections.Counter()
    bad = 0
    for seed in range(1, args.seeds + 1):
        session = open_robot("sim://", cfg, RobotOptions())
        clock = StallingClock(session.clock, random.Random(seed), args.p, *args.stall)
        session.clock = clock
        events: list[Event] = []
        r = run(session, cfg, sink=events.append)
        counts["fell" if r.fell else r.outcome] += 1
        if r.outcome != "completed" or r.fell:
            bad += 1
            phases = [e.message for e in events if e.kind is EventKind.PHASE]
            last = [f"{s * 1000:.0f} ms at {t:.2f} s" for t, s in clock.stalls
                    if t > r.sim_time_s - 5.0]
            print(f"seed {seed}: {r.outcome}, fell {r.fell}, up {r.steps_climbed} down "
                  f"{r.steps_descended}, in {phases[-2] if len(phases) > 1 else '?'}: "
                  f"{r.error}; {len(clock.stalls)} stalls, in the last 5 s: "
                  f"{', '.join(last) or 'none'}", flush=True)
    print(f"\n{counts['completed']}/{args.seeds} completed, {counts['fell']} fell "
          f"(default runs, a stall of {args.stall[0]:g}-{args.stall[1]:g} s after "
          f"{args.p:g} of the ticks)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
