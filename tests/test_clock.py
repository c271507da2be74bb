"""The wall clock keeps a control loop's period and counts the ticks that
began more than one tick late; a fake monotonic clock and sleep stand in for
real time (no test here waits or measures)."""

from __future__ import annotations

from stairbot.clock import CountsLateTicks, HostBehind, WallClock
from stairbot.control.robot_config import load_config
from stairbot.run.robots import RobotOptions, RobotSession, open_robot
from stairbot.run.runner import run

TICK = 0.02


class FakeTime:
    """A monotonic clock that moves only when slept on or told to."""

    def __init__(self) -> None:
        self.t = 100.0
        self.slept: list[float] = []

    def monotonic(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        self.slept.append(seconds)
        self.t += seconds


def loop(clock: WallClock, fake: FakeTime, work: list[float]) -> None:
    """One tick per entry: the cycle's work takes that long, then the clock advances."""
    for seconds in work:
        fake.t += seconds
        clock.advance(TICK)


def test_a_loop_that_keeps_its_period_is_never_behind() -> None:
    fake = FakeTime()
    clock = WallClock(fake.monotonic, fake.sleep)
    loop(clock, fake, [0.005, 0.019, 0.001, 0.015] * 5)
    assert clock.host_behind() == HostBehind(0, 0.0)


def test_a_cycle_late_by_less_than_a_tick_is_caught_up_not_counted() -> None:
    fake = FakeTime()
    clock = WallClock(fake.monotonic, fake.sleep)
    loop(clock, fake, [0.005, 0.035, 0.001, 0.001])  # 15 ms late, then caught up
    assert clock.host_behind() == HostBehind(0, 0.0)
    assert fake.slept[-1] < TICK  # the catching up: a shorter wait


def test_ticks_that_begin_more_than_a_tick_late_are_counted_with_the_longest() -> None:
    fake = FakeTime()
    clock = WallClock(fake.monotonic, fake.sleep)
    # the 2nd cycle overruns its tick by 30 ms: the 3rd begins 30 ms late and
    # is not caught up; the 3rd ends 5 ms late; the 4th, still catching up,
    # overruns by 100 ms (a stalled host): the 5th begins 105 ms late
    loop(clock, fake, [0.005, 0.050, 0.005, 0.120, 0.005])
    behind = clock.host_behind()
    assert behind.ticks == 2
    assert abs(behind.longest_s - 0.105) < 1e-9
    assert behind.to_dict() == {"ticks": 2, "longest_s": 0.105}


def test_the_first_advance_of_a_loop_only_sets_the_period() -> None:
    fake = FakeTime()
    clock = WallClock(fake.monotonic, fake.sleep)
    fake.t += 5.0  # opening the robot took long: no tick was due yet
    loop(clock, fake, [0.005, 0.005])
    assert clock.host_behind().ticks == 0
    loop(clock, fake, [0.080])
    assert clock.host_behind().ticks == 1
    fake.t += 30.0  # the robot stood idle between two runs
    clock.begin_loop()
    loop(clock, fake, [0.005, 0.005])
    assert clock.host_behind() == HostBehind(0, 0.0)


def test_a_run_on_a_wall_clock_reports_the_ticks_its_host_fell_behind() -> None:
    # The simulated robot on a fake wall clock whose every 50th cycle stalls
    # 100 ms; the physics steps only when the sim's own clock advances, so
    # the run is driven through the sim's clock as well.
    config = load_config()
    sim = open_robot("sim://", config, RobotOptions())
    fake = FakeTime()
    wall = WallClock(fake.monotonic, fake.sleep)
    ticks = 0

    class Both:
        def now(self) -> float:
            return sim.clock.now()

        def advance(self, dt: float) -> None:
            nonlocal ticks
            ticks += 1
            sim.clock.advance(dt)
            fake.t += 0.120 if ticks % 50 == 0 else 0.001
            wall.advance(dt)

        def begin_loop(self) -> None:
            wall.begin_loop()

        def host_behind(self) -> HostBehind:
            return wall.host_behind()

    both = Both()
    assert isinstance(both, CountsLateTicks)
    session = RobotSession(robot=sim.robot, clock=both, url="sim://", simulated=True)
    result = run(session, config, max_sim_time_s=20.0)
    assert result.host_behind is not None
    assert result.host_behind.ticks == ticks // 50
    assert result.to_dict()["host_behind"]["ticks"] == ticks // 50


def test_a_simulated_clock_leaves_host_behind_out() -> None:
    config = load_config()
    result = run(open_robot("sim://", config, RobotOptions()), config, max_sim_time_s=2.0)
    assert result.host_behind is None
    assert "host_behind" not in result.to_dict()
