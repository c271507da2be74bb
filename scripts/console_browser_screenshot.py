"""Save the console as a browser shows it mid-climb (`stairbot console
--serve`, in Debian's headless Chromium) as PNG: docs/console-browser.png
(README links it).

    python scripts/console_browser_screenshot.py [OUT.png] [--size 1100x640]

Needs the test tools (`bash scripts/setup test`: textual-serve, Playwright)
and `apt-get install chromium`.  The simulated robot at 10x, started with s,
taken once a segment stands over the first tread; then space stops it.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

# The helpers the browser tests use (tests/console/browser.py).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "console"))
from browser import chromium_page, press, served_console, wait_screen  # noqa: E402

CAPTION = re.compile(r"steps (\d)\|(\d)\|(\d)\s+MTF")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", nargs="?", default="docs/console-browser.png")
    p.add_argument("--size", default="1100x640", help="the browser's viewport, WIDTHxHEIGHT")
    args = p.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
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


if __name__ == "__main__":
    main()
