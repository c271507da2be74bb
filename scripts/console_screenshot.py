"""Save the console as an operator sees it mid-climb, at 80x24, as SVG:
the picture docs/console-80x24.svg (README links it).

    python scripts/console_screenshot.py [OUT.svg] [--size 80x24]
    python scripts/console_screenshot.py --parameters [docs/console-parameters.svg]
    python scripts/console_screenshot.py --connections [docs/console-connections.svg]
    python scripts/console_screenshot.py docs/console-plots.svg --plot SFR,SFL,MTF.lift
    python scripts/console_screenshot.py docs/console-events.svg --size 110x35 --events lift

The simulated robot at 10x, started with s, taken once a segment stands over
the first tread.  ``--parameters``: the parameters screen (``i``) between
runs, the cursor on motors.wheel_speed (OUT); then that value changed to 0.5
and its diff shown before it is used (OUT-diff.svg; nothing is written: the
diff is answered no).  ``--connections``: the connection manager (u) instead,
with fake boards served on a pty for it to list (their registry, and the
recent URLs, in a temporary directory of their own).  ``--plot KEYS``:
those signals plotted (key v; the keys as console/signals.py names them),
in the graphs' place.  ``--events WORD``: the event list filtered to the
phases (e) holding WORD (/).
"""

from __future__ import annotations

import argparse
import asyncio
import os
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

from textual.widgets import Input

from stairbot.console import plotting
from stairbot.console.app import build_app


async def shoot_parameters(out: Path, width: int, height: int) -> None:
    from stairbot.console.params_screen import DiffScreen, ParamsScreen

    # the path the diff names, as an operator's would read (nothing is written)
    os.environ["XDG_CONFIG_HOME"] = "/home/operator/.config"
    app = build_app(speed="10x")
    async with app.run_test(size=(width, height)) as pilot:
        await app.workers.wait_for_complete()
        await pilot.press("i")
        screen = app.screen
        assert isinstance(screen, ParamsScreen)
        screen.show_key("motors.wheel_speed")
        await pilot.pause(0.2)
        app.save_screenshot(filename=out.name, path=str(out.parent))
        await pilot.press("enter")
        await pilot.pause(0.1)
        screen.query_one("#params-edit", Input).value = "0.5"
        await pilot.press("enter")
        await pilot.pause(0.3)
        assert isinstance(app.screen, DiffScreen)
        app.save_screenshot(filename=f"{out.stem}-diff{out.suffix}", path=str(out.parent))
        await pilot.press("escape")


async def shoot(out: Path, width: int, height: int, plot: list[str],
                events: str | None = None) -> None:
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
        if events is not None:  # e: phases and pauses only, then / and the word
            await pilot.press("e", "e", "e")
            app.log_panel.set_filter(search=events)
        await pilot.pause(0.3)
        app.save_screenshot(filename=out.name, path=str(out.parent))
        await pilot.press("space")
        await pilot.pause(0.2)


async def shoot_connections(out: Path, width: int, height: int) -> None:
    from stairbot.console.connect_screen import ConnectScreen

    app = build_app(speed="1x")
    async with app.run_test(size=(width, height)) as pilot:
        await app.workers.wait_for_complete()
        await pilot.press("u")
        for _ in range(400):
            if isinstance(app.screen, ConnectScreen) and app.screen.listing is not None:
                break
            await asyncio.sleep(0.05)
        await pilot.pause(0.3)
        app.save_screenshot(filename=out.name, path=str(out.parent))
        await pilot.press("escape")


def with_fake_boards(out: Path, width: int, height: int) -> None:
    """Serve fake boards (lockstep: idle until a host steps them) while the
    manager's picture is taken."""
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["XDG_RUNTIME_DIR"] = str(Path(tmp) / "run")
        os.environ["XDG_STATE_HOME"] = str(Path(tmp) / "state")
        boards = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", "--serial",
                                   "--lockstep"], stdout=subprocess.PIPE,
                                  stderr=subprocess.DEVNULL, text=True)
        try:
            assert boards.stdout is not None
            boards.stdout.readline()  # the URL: registered by now
            asyncio.run(shoot_connections(out, width, height))
        finally:
            boards.send_signal(signal.SIGINT)
            boards.wait(10)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", nargs="?", default=None)
    p.add_argument("--size", default="80x24")
    p.add_argument("--parameters", action="store_true",
                   help="the parameters screen (i) with a change's diff")
    p.add_argument("--connections", action="store_true",
                   help="the connection manager (u), with fake boards to list")
    p.add_argument("--plot", default="", help="signals to plot, comma-separated (SFR,MTF.lift)")
    p.add_argument("--events", metavar="WORD", default=None,
                   help="the event list filtered: phases only (e), holding WORD (/)")
    args = p.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    if args.parameters:
        args.out = args.out or "docs/console-parameters.svg"
        asyncio.run(shoot_parameters(Path(args.out), width, height))
    elif args.connections:
        args.out = args.out or "docs/console-connections.svg"
        with_fake_boards(Path(args.out), width, height)
    else:
        args.out = args.out or "docs/console-80x24.svg"
        asyncio.run(shoot(Path(args.out), width, height, [k for k in args.plot.split(",") if k],
                          args.events))
    print(args.out)


if __name__ == "__main__":
    main()
