"""Save the console as an operator sees it mid-climb, at 80x24, as SVG:
the picture docs/console-80x24.svg (README links it).

    python scripts/console_screenshot.py [OUT.svg] [--size 80x24]
    python scripts/console_screenshot.py docs/console-plots.svg --plot SFR,SFL,MTF.lift

The simulated robot at 10x, started with s, taken once a segment stands over
the first tread.  ``--plot KEYS``: those signals plotted (key v; the keys
as console/signals.py names them), in the graphs' place.
"""

from __future__ import annotations

import argparse
import asyncio
from pathlib import Path

from stairbot.console import plotting
from stairbot.console.app import build_app


async def shoot(out: Path, width: int, height: int, plot: list[str]) -> None:
    app = build_app(speed="10x")
    async with app.run_test(size=(width, height)) as pilot:
        await app.workers.wait_for_complete()
        if plot:
            plotting.plot(app, plot)
            picked = [s.key for s in app.plotting.picked]
            if picked != plot:
                known = ", ".join(s.key for s in app.plotting.signals(app))
                raise SystemExit(f"--plot: {', '.join(k for k in plot if k not in picked)}"
                                 f" is no signal of this robot; allowed: {known}")
        await pilot.press("s")
        for _ in range(2400):
            scene = app.state.view().scene
            if scene is not None and max(scene.segment_steps()) >= 1:
                break
            await asyncio.sleep(0.05)
        await pilot.pause(0.3)
        app.save_screenshot(filename=out.name, path=str(out.parent))
        await pilot.press("space")
        await pilot.pause(0.2)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", nargs="?", default="docs/console-80x24.svg")
    p.add_argument("--size", default="80x24")
    p.add_argument("--plot", default="", help="signals to plot, comma-separated (SFR,MTF.lift)")
    args = p.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    asyncio.run(shoot(Path(args.out), width, height, [k for k in args.plot.split(",") if k]))
    print(args.out)


if __name__ == "__main__":
    main()
