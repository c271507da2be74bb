"""What the console's plot (key ``v``) costs the UI thread: the plot panel
(console/widgets/plots.py) built alone in a Textual app at 80x24 and
160x50, four signals in two units over the graphs' 30 s window of readings
at the control tick (50 a second: 1,500 readings), and a redraw timed in
its two parts, each in CPU time of the UI thread (``time.thread_time``):

- ``show``: the series read out of the readings, thinned, handed to plotext;
- ``build``: plotext drawing the plot into text (``PlotextPlot.render``),
  what Textual runs when the plot is refreshed.

It prints, for each size, the median and largest of each part over the
rounds, the redraws a second the panel allows (its throttle, worked out
from the measured cost), and the share of the UI thread those redraws take
at that rate; and, for comparison, the share a redraw at every refresh of
the screen (REFRESH_HZ) would take.

    python benchmarks/bench_console_plot.py [--rounds N] [--noisy]

``--noisy``: distances that jump every reading (a sawtooth, as a sensor
that flickers between a tread and the floor), which plotext draws as many
long vertical strokes: its dearest case.
"""

from __future__ import annotations

import argparse
import asyncio
import math
import statistics
import time

from textual.app import App, ComposeResult

from stairbot.console.app import REFRESH_HZ
from stairbot.console.history import WINDOW_S
from stairbot.console.signals import Reading, by_key, catalogue
from stairbot.console.widgets.plots import PlotPanel
from stairbot.control.robot_config import load_config
from stairbot.hardware import Imu, MotorId, MotorState, SensorId, SensorReading, Snapshot

TICK_S = 0.02
PICKED = ("SFR", "SFL", "MTF.lift", "MTB.lift")


def reading(t: float, noisy: bool = False) -> Snapshot:
    """A reading at robot time ``t``: distances that rise and fall over a
    step (a riser passing under them; ``noisy``: a sawtooth that jumps every
    reading), lifts that move up and down."""
    sensors = {s: SensorReading(0.2 + 0.1 * ((t * 7.3 * (i + 1)) % 1.0 if noisy
                                             else math.sin(t / (2 + i))))
               for i, s in enumerate(SensorId) if s.value in ("SFR", "SFL", "SBR", "SBL")}
    motors = {m: MotorState(5 * math.sin(t / (4 + i)), speed_tps=0.5)
              for i, m in enumerate(MotorId)}
    return Snapshot(t, sensors, motors, {}, imu=Imu(t % 5.0, 0.5))


class Bench(App[None]):
    def __init__(self) -> None:
        super().__init__()
        self.panel = PlotPanel(id="plots")

    def compose(self) -> ComposeResult:
        yield self.panel


def median_max(xs: list[float]) -> str:
    return f"median {statistics.median(xs) * 1000:6.1f} ms, max {max(xs) * 1000:6.1f} ms"


async def measure(size: tuple[int, int], rounds: int, noisy: bool) -> None:
    app = Bench()
    readings: list[Reading] = []
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        panel = app.panel
        config = load_config()
        n = int(WINDOW_S / TICK_S)
        snaps = [reading(i * TICK_S, noisy) for i in range(n)]
        known = by_key(catalogue(snaps, config.motors.lift_travel_per_turn))
        picked = tuple(known[k] for k in PICKED)
        readings = [(s.time_s, s) for s in snaps]
        shows: list[float] = []
        builds: list[float] = []
        for r in range(rounds):
            more = reading((n + r) * TICK_S, noisy)
            readings = readings[1:] + [(more.time_s, more)]
            panel.redraw()
            t0 = time.thread_time()
            panel.show(picked, readings, 0.05)
            t1 = time.thread_time()
            panel.plot.render()
            t2 = time.thread_time()
            shows.append(t1 - t0)
            builds.append(t2 - t1)
            await pilot.pause()
        cost = statistics.median(shows) + statistics.median(builds)
        period = panel.period_for(cost)
        w, h = panel.plot.size
        print(f"{size[0]}x{size[1]} (plot {w}x{h}), {len(readings)} "
              f"{'noisy ' if noisy else ''}readings, {len(picked)} signals, {rounds} rounds:")
        print(f"  show  {median_max(shows)}")
        print(f"  build {median_max(builds)}")
        print(f"  throttle: at most one redraw every {period:.2f} s "
              f"({1 / period:.1f} a second): {cost / period:.0%} of the UI thread; "
              f"a redraw at every refresh ({REFRESH_HZ:.0f} a second) would take "
              f"{cost * REFRESH_HZ:.0%}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=20)
    parser.add_argument("--noisy", action="store_true",
                        help="distances that jump every reading (plotext's dearest case)")
    args = parser.parse_args()
    for size in ((80, 24), (160, 50)):
        asyncio.run(measure(size, args.rounds, args.noisy))


if __name__ == "__main__":
    main()
