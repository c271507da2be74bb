"""Save the console as a browser shows it mid-climb (`stairbot console
--serve`, in Debian's headless Chromium) as PNG: docs/console-browser.png
(README links it).

    python scripts/console_browser_screenshot.py [OUT.png] [--size 1100x640]
    python scripts/console_browser_screenshot.py --watching docs/console-browser-watching.png

Needs the test tools (`bash scripts/setup test`: textual-serve, Playwright)
and `apt-get install chromium`.  The simulated robot at 10x, started with s,
taken once a segment stands over the first tread; then space stops it.
``--watching``: fake boards on a pty served to two tabs; the second tab,
watching the first's robot, once it has refused a start (s).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path

# The helpers the browser tests use (tests/console/browser.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "console"))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))  # lockstep_boards
from browser import (  # noqa: E402
    chromium_page,
    chromium_tabs,
    press,
    served_console,
    wait_screen,
)

CAPTION = re.compile(r"steps (\d)\|(\d)\|(\d)\s+MTF")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", nargs="?", default="docs/console-browser.png")
    p.add_argument("--size", default="1100x640", help="the browser's viewport, WIDTHxHEIGHT")
    p.add_argument("--watching", action="store_true",
                   help="two tabs on fake boards: the second one, watching the first's robot")
    args = p.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    if args.watching:
        watching(args.out, width, height)
        print(args.out)
        return
    with served_console("--speed", "10x") as (url, _), \
            chromium_page(url, width, height) as page:
        wait_screen(page, lambda s: "READY" in s, "the console ready")
        press(page, "s")
        wait_screen(page, lambda s: (c := CAPTION.search(s)) is not None and c.group(1) == "1",
                    "segment 1 over the first tread")
        page.screenshot(path=args.out)
        press(page, "Space")
        wait_screen(page, lambda s: re.search(r"E-STOP\s+\(operator\)", s) is not None,
                    "the robot stopped")
    print(args.out)


def watching(out: str, width: int, height: int) -> None:
    import tempfile

    from lockstep_boards import fake_boards

    with tempfile.TemporaryDirectory() as tmp:
        os.environ["XDG_RUNTIME_DIR"] = str(Path(tmp) / "run")  # locks of their own
        os.environ["XDG_STATE_HOME"] = str(Path(tmp) / "state")
        with fake_boards(Path(tmp)) as robot, served_console(
                "--robot", robot, cwd=tmp) as (url, _), \
                chromium_tabs(url, width, height) as open_tab:
            first = open_tab()
            wait_screen(first, lambda s: "READY" in s, "the first tab controls")
            second = open_tab()
            wait_screen(second, lambda s: "WATCHING" in s and "READY" in s, "the second watches")
            press(second, "s")
            wait_screen(second, lambda s: "watching: another console controls" in s,
                        "the start refused")
            second.screenshot(path=out)


if __name__ == "__main__":
    main()
