"""Save the console as an operator sees it mid-climb, at 80x24, as SVG:
the picture docs/console-80x24.svg (README links it).

    python scripts/console_screenshot.py [OUT.svg] [--size 80x24]
    python scripts/console_screenshot.py docs/console-connections.svg --connections

The simulated robot at 10x, started with s, taken once a segment stands over
the first tread.  ``--connections``: the connection manager (u) instead,
with fake boards served on a pty for it to list (their registry, and the
recent URLs, in a temporary directory of their own).
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

from stairbot.console.app import build_app


async def shoot(out: Path, width: int, height: int) -> None:
    app = build_app(speed="10x")
    async with app.run_test(size=(width, height)) as pilot:
        await app.workers.wait_for_complete()
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
    p.add_argument("out", nargs="?", default="docs/console-80x24.svg")
    p.add_argument("--size", default="80x24")
    p.add_argument("--connections", action="store_true",
                   help="the connection manager (u), with fake boards to list")
    args = p.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    if args.connections:
        with_fake_boards(Path(args.out), width, height)
    else:
        asyncio.run(shoot(Path(args.out), width, height))
    print(args.out)


if __name__ == "__main__":
    main()
