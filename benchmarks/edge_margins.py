"""Where descent 1's edge watch places each edge, and what the bound leaves
on the tread: the figures behind ``edge_clearance_m`` and ``edge_sight_m``.

For each robot config and seed it climbs a random flight on ``sim://``
(3 steps by default, each rise and tread drawn from the ranges given, the
start turned by up to ``--yaw`` degrees) and descends it.  On every descent
step whose edge the back pair's watch placed, it prints, from the
simulation's truth (the world knows the edge):

* ``late``: how far behind the true edge (of the tread segment 3's front
  wheels stand on) the watch placed the pair's crossing (positive: placed
  late, the robot backs that much too far);
* ``axle``: segment 2's rear axle on the tread when the backing ended
  (its nearer wheel; negative: past the edge), and ``least``: the least
  over descent 1 and 2 (backing up to the edge until segment 3 is down);
* ``front``: how far segment 3's front wheels' front stands past the
  edge's corner when the backing ended (negative: on the corner).

Then the distribution per robot (median, worst).  A script that prints
figures, not a test: it asserts nothing.  Usage:

    python benchmarks/edge_margins.py [--configs reference,sonar] [--seeds 20]
"""

from __future__ import annotations

import argparse
import math
import random
import statistics
from dataclasses import dataclass, field

from stairbot.control.algorithm import motion
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.phases import Mode, Phase
from stairbot.control.robot_config import load_config
from stairbot.hardware import Snapshot
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario, parse_scenario
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import run

WATCHED = (Phase.DESCENT_BACK_TO_EDGE.value, Phase.DESCENT_LOWER_THIRD.value)
"""Phases over which segment 2's rear axle's least margin is taken."""


@dataclass
class EdgeRecord:
    """One descent step's edge, as the watch placed it and as the world has it."""

    level: int
    kind: str  # "edge" (edge_bound) or "narrow" (narrow_bound)
    phase: str  # where the watch placed it
    late_m: float = math.nan
    axle_m: float = math.nan
    least_m: float = math.inf
    front_m: float = math.nan


@dataclass
class Watch:
    """Follows one run tick by tick (``run``'s ``on_tick``)."""

    config: RobotConfig
    scenario: Scenario
    world: object
    plan: object
    records: list[EdgeRecord] = field(default_factory=list)
    _seen: tuple[float | None, float | None] = (None, None)
    _phase: str = ""

    def __post_init__(self) -> None:
        # the stairs' surface is the outline thickened by stairs_radius: a
        # riser's face, and a tread's edge, stand that much before its x
        face = self.world.params.stairs_radius  # type: ignore[attr-defined]
        x = y = 0.0
        self.risers: list[tuple[float, float]] = []  # (edge x, top y) of riser k at k - 1
        for step in self.scenario.steps:
            y += step.rise
            self.risers.append((x - face, y))
            x += step.tread

    def _level(self, y_axle: float) -> int:
        """The tread a wheel's axle at height ``y_axle`` stands on: 0 the floor,
        k the top of riser k."""
        r = self.config.geometry.wheel_radius
        heights = [0.0] + [top for _, top in self.risers]
        return min(range(len(heights)), key=lambda k: abs(heights[k] + r - y_axle))

    def _yaw(self) -> float:
        return float(self.plan.yaw)  # type: ignore[attr-defined]

    def _top_x(self, x: float) -> float:
        """A side-view x on the robot as the top view has it along the flight
        (the segments' lengths shortened by the yaw about segment 2's centre)."""
        centre = float(self.world.pose(1)[0])  # type: ignore[attr-defined]
        return centre + (x - centre) * math.cos(self._yaw())

    def _wheel_xs(self, segment: int, end: int) -> tuple[float, float, float]:
        """Top-view x of a wheel pair's two wheels (either side), and its axle's y."""
        body = self.world.wheels[segment][end]  # type: ignore[attr-defined]
        x = self._top_x(float(body.position.x))
        half = self.config.geometry.track_width / 2 * math.sin(self._yaw())
        return x - half, x + half, float(body.position.y)

    def _pair_x(self) -> float:
        """Top-view x of the back pair's midpoint (the robot's centre line)."""
        px, py, pa = self.world.pose(2)  # type: ignore[attr-defined]
        s = self.config.sensors
        lx = -self.world.lengths[2] / 2 + s.back_from_rear  # type: ignore[attr-defined]
        ly = s.back_height - self.config.geometry.wheel_radius
        return self._top_x(px + math.cos(pa) * lx - math.sin(pa) * ly)

    def _edge_x(self, segment: int = 1, end: int = 0) -> tuple[int, float]:
        """The level a wheel pair (default: segment 2's rear wheels) stands on
        and its tread's edge."""
        _a, _b, y = self._wheel_xs(segment, end)
        level = self._level(y)
        return level, self.risers[level - 1][0] if level >= 1 else math.nan

    def see(self, ctl: Controller, snap: Snapshot) -> None:
        step = ctl.context.descent
        phase = ctl.phase.value
        now = (step.edge_wheel, step.narrow_edge_wheel)
        for kind, was, placed in zip(("edge", "narrow"), self._seen, now, strict=True):
            if placed is not None and was is None:
                level = self._edge_x()[0]
                edge = self._edge_x(2, 1)[1]  # the tread segment 3 backs off
                back = (placed - motion.wheel_position(snap)) * self.config.wheel_circumference
                rec = EdgeRecord(level, kind, phase)
                rec.late_m = edge - (self._pair_x() + back * math.cos(self._yaw()))
                self.records.append(rec)
        self._seen = now
        if self.records and phase in WATCHED:
            rec = self.records[-1]
            level, edge = self._edge_x()
            if level == rec.level:
                near, _far, _y = self._wheel_xs(1, 0)
                rec.least_m = min(rec.least_m, near - edge)
        if self.records and self._phase == Phase.DESCENT_BACK_TO_EDGE.value \
                and phase == Phase.DESCENT_LOWER_THIRD.value:
            rec = self.records[-1]
            level, edge = self._edge_x()
            rec.axle_m = self._wheel_xs(1, 0)[0] - edge
            rec.front_m = edge - (self._wheel_xs(2, 1)[1] + self.config.geometry.wheel_radius)
        self._phase = phase


def flight(seed: int, args: argparse.Namespace) -> Scenario:
    """A random flight of ``args.steps`` steps, its start turned by up to
    ``args.yaw`` degrees."""
    rnd = random.Random(seed)
    steps = ", ".join(f"{{ rise = {rnd.uniform(*args.rise):.3f}, "
                      f"tread = {rnd.uniform(*args.tread):.3f} }}" for _ in range(args.steps))
    yaw = rnd.uniform(-args.yaw, args.yaw)
    start = f"on = 'top'\ndistance = {rnd.uniform(0.05, 0.3):.3f}" if args.top else \
        "distance = 0.3"
    text = (f"name = 'edge-{seed}'\n[stairs]\nsteps = [{steps}]\n"
            f"[start]\n{start}\nyaw_deg = {yaw:.1f}\n[sensors]\nseed = {seed}\n")
    return parse_scenario(text, f"edge-{seed}.toml")


def one(config: RobotConfig, scenario: Scenario) -> tuple[str, list[EdgeRecord]]:
    session = open_robot("sim://", config, RobotOptions(world=scenario))
    robot = session.robot
    watch = Watch(config, scenario, robot.world, robot.plan)  # type: ignore[attr-defined]
    try:
        result = run(session, config, mode=Mode.for_start(scenario.start.on),
                     on_tick=watch.see)
    finally:
        session.close()
    return result.outcome, watch.records


def summary(name: str, records: list[EdgeRecord]) -> None:
    for kind in ("edge", "narrow"):
        rs = [r for r in records if r.kind == kind]
        if not rs:
            continue
        print(f"{name} {kind} ({len(rs)} edges):")
        for label, get, worst in (("late", lambda r: r.late_m, max),
                                  ("axle", lambda r: r.axle_m, min),
                                  ("least", lambda r: r.least_m, min),
                                  ("front", lambda r: r.front_m, min)):
            xs = [x for x in map(get, rs) if math.isfinite(x)]
            if xs:
                print(f"  {label:5s} median {statistics.median(xs) * 1000:+6.1f}  "
                      f"worst {worst(xs) * 1000:+6.1f}  "
                      f"range {min(xs) * 1000:+6.1f} .. {max(xs) * 1000:+6.1f} mm")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configs", default="reference,sonar,ir,ideal,heavy_middle")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--steps", type=int, default=3)
    parser.add_argument("--rise", type=float, nargs=2, default=(0.10, 0.20))
    parser.add_argument("--tread", type=float, nargs=2, default=(0.22, 0.40))
    parser.add_argument("--yaw", type=float, default=8.0, help="most start yaw, degrees")
    parser.add_argument("--top", action="store_true",
                        help="start on the top (a continuous descent), not the floor")
    parser.add_argument("-v", "--verbose", action="store_true", help="every edge")
    args = parser.parse_args()
    for name in args.configs.split(","):
        config = load_config(name)
        records: list[EdgeRecord] = []
        outcomes: dict[str, int] = {}
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            scenario = flight(seed, args)
            outcome, recs = one(config, scenario)
            outcomes[outcome] = outcomes.get(outcome, 0) + 1
            records += recs
            if args.verbose:
                for r in recs:
                    print(f"  {name} seed {seed} {outcome} level {r.level} {r.kind} ({r.phase}): "
                          f"late {r.late_m * 1000:+6.1f} axle {r.axle_m * 1000:+6.1f} "
                          f"least {r.least_m * 1000:+6.1f} front {r.front_m * 1000:+6.1f} mm",
                          flush=True)
        print(f"{name}: {args.seeds} runs {dict(sorted(outcomes.items()))}")
        summary(name, records)


if __name__ == "__main__":
    main()
