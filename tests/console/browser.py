"""Driving `stairbot console --serve` in Debian's Chromium (headless, through
Playwright and the system's binary: nothing downloads a browser).  A module
of its own, not conftest.py: scripts/console_browser_screenshot.py uses it too.

The page draws its terminal (xterm.js) on a canvas, so the text is read from
xterm's own buffer: an init script catches textual-serve's terminal object
as the page builds it (textual.js keeps it in the object that gets a
``fitAddon``, right after ``terminal``), and ``screen_text`` reads its rows.
The bounds on waiting only stop a broken test; nothing asserts a time.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from typing import Any

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")

CATCH_TERMINAL = """
Object.defineProperty(Object.prototype, "fitAddon", {
  configurable: true,
  get() { return undefined; },
  set(value) {
    Object.defineProperty(this, "fitAddon",
      {value, writable: true, configurable: true, enumerable: true});
    if (this.terminal && !window.__stairbotTerminal) window.__stairbotTerminal = this.terminal;
  },
});
"""

READ_SCREEN = """() => {
  const t = window.__stairbotTerminal;
  if (!t) return null;
  const b = t.buffer.active, rows = [];
  for (let y = 0; y < t.rows; y++) {
    const line = b.getLine(b.viewportY + y);
    rows.push(line ? line.translateToString(true) : "");
  }
  return rows.join("\\n");
}"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@contextlib.contextmanager
def served_console(*options: str, cwd: str | None = None) -> Iterator[tuple[str, Any]]:
    """Run ``stairbot console --serve 127.0.0.1:PORT OPTIONS`` until the block
    ends; yields (its URL, the process).  The server and the consoles it
    started are one process group, ended together."""
    port = free_port()
    with tempfile.TemporaryFile() as out:
        proc = subprocess.Popen(
            [sys.executable, "-m", "stairbot", "console", "--serve", f"127.0.0.1:{port}",
             *options],
            stdout=out, stderr=subprocess.STDOUT, start_new_session=True, cwd=cwd)

        def output() -> str:
            out.seek(0)
            return out.read().decode(errors="replace")

        try:
            for _ in range(600):
                if proc.poll() is not None:
                    raise AssertionError(f"the server ended ({proc.returncode}):\n{output()}")
                with socket.socket() as s:
                    if s.connect_ex(("127.0.0.1", port)) == 0:
                        break
                time.sleep(0.1)
            else:
                raise AssertionError(f"the server never listened:\n{output()}")
            yield f"http://127.0.0.1:{port}/", proc
        finally:
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)  # textual-serve ends its consoles, then itself
                try:
                    proc.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait()
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)  # a console the server left behind


@contextlib.contextmanager
def chromium_tabs(url: str, width: int = 1100, height: int = 640) -> Iterator[Callable[[], Any]]:
    """A headless Chromium; yields a function that opens a tab (a page) on
    ``url``, every request elsewhere refused (the page asks Google for a
    font: the fallback monospace is fine)."""
    from playwright.sync_api import sync_playwright

    assert CHROMIUM is not None, "no chromium: apt-get install chromium (scripts/test does)"
    origin = url.rstrip("/")
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, headless=True)
        context = browser.new_context(viewport={"width": width, "height": height})

        def open_tab() -> Any:
            page = context.new_page()
            page.route("**/*", lambda route: route.continue_()
                       if route.request.url.startswith(origin) else route.abort())
            page.add_init_script(CATCH_TERMINAL)
            page.goto(url)
            return page
        try:
            yield open_tab
        finally:
            browser.close()


@contextlib.contextmanager
def chromium_page(url: str, width: int = 1100, height: int = 640) -> Iterator[Any]:
    """A headless Chromium page on ``url`` (:func:`chromium_tabs`, one tab)."""
    with chromium_tabs(url, width, height) as open_tab:
        yield open_tab()


def screen_text(page: Any) -> str:
    """The terminal's rows as the page holds them, one a line ("" before it exists)."""
    return str(page.evaluate(READ_SCREEN) or "")


def wait_screen(page: Any, cond: Callable[[str], bool], what: str) -> str:
    """Read the page's terminal until ``cond`` holds."""
    screen = ""
    for _ in range(600):
        screen = screen_text(page)
        if cond(screen):
            return screen
        page.wait_for_timeout(100)
    raise AssertionError(f"never happened: {what}\n{screen}")


def press(page: Any, key: str) -> None:
    """Type ``key`` into the terminal (xterm's input takes the keyboard)."""
    page.locator(".xterm-helper-textarea").focus()
    page.keyboard.press(key)
