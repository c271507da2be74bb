"""The options both wires' URLs take (``serial://...?timeout=0.05``,
``can://...?retries=2``): their bounds, checked in one place.

Every number is finite and within the bounds below; each refusal is one
RobotUrlError naming the URL, the option and what is allowed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from urllib.parse import parse_qsl

from stairbot.errors import RobotUrlError
from stairbot.run.robots import TIME_SCALE_MAX, TIME_SCALE_MIN

MAX_TIMEOUT_S = 60.0
MAX_RETRIES = 100
MAX_LOST = 1000
MAX_GRACE_S = 60.0
MAX_WATCHDOG_MS = 65535
MIN_BAUD, MAX_BAUD = 50, 20_000_000

# option -> (whole number?, accepts(value), what is allowed)
_RULES: dict[str, tuple[bool, Callable[[float], bool], str]] = {
    "timeout": (False, lambda v: 0 < v <= MAX_TIMEOUT_S,
                f"seconds, 0 < timeout <= {MAX_TIMEOUT_S:g}"),
    "retries": (True, lambda v: 0 <= v <= MAX_RETRIES, f"a whole number, 0 to {MAX_RETRIES}"),
    "lost": (True, lambda v: 1 <= v <= MAX_LOST, f"a whole number, 1 to {MAX_LOST}"),
    "grace": (False, lambda v: 0 <= v <= MAX_GRACE_S, f"seconds, 0 <= grace <= {MAX_GRACE_S:g}"),
    "watchdog": (True, lambda v: 0 <= v <= MAX_WATCHDOG_MS,
                 f"ms, 0 to {MAX_WATCHDOG_MS} (0 = off)"),
    "lockstep": (True, lambda v: v in (0, 1), "0 or 1"),
    "lan": (True, lambda v: v in (0, 1), "0 or 1"),
    "time_scale": (False, lambda v: TIME_SCALE_MIN <= v <= TIME_SCALE_MAX,
                   f"{TIME_SCALE_MIN:g} to {TIME_SCALE_MAX:g}"),
    "baud": (True, lambda v: MIN_BAUD <= v <= MAX_BAUD,
             f"bit/s, a whole number, {MIN_BAUD} to {MAX_BAUD}"),
}


def allowed(key: str) -> str:
    """What option ``key`` allows, in words."""
    return _RULES[key][2]


def number_option(url: str, key: str, text: str) -> float:
    """The value of option ``key`` (one of the table above).  RobotUrlError
    naming the URL, the option, the value and what is allowed otherwise."""
    whole, accepts, words = _RULES[key]
    shown = text if len(text) <= 40 else text[:40] + "..."
    try:
        value: float = int(text) if whole else float(text)
    except ValueError:
        kind = "an integer" if whole else "a number"
        raise RobotUrlError(url, key, f"{shown!r} is not {kind}; allowed: {words}") from None
    if not math.isfinite(value) or not accepts(value):
        raise RobotUrlError(url, key, f"{shown} is out of range; allowed: {words}")
    return value


def query_pairs(url: str, query: str, *, strict: bool = True) -> list[tuple[str, str]]:
    """The ``key=value`` pairs of a URL's query, percent-decoded as UTF-8.
    RobotUrlError when a part does not decode, or (``strict``) is not
    ``key=value``."""
    try:
        return parse_qsl(query, keep_blank_values=True, strict_parsing=strict and bool(query),
                         errors="strict")
    except UnicodeDecodeError:
        raise RobotUrlError(url, "query", "bad percent-encoding (not UTF-8); allowed: "
                            "key=value&key=value, %XX only for UTF-8 text") from None
    except ValueError as exc:
        raise RobotUrlError(url, "query", f"malformed options ({exc}); "
                            "expected key=value&key=value") from None
