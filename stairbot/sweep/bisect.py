"""Where a verdict changes along one axis: scan, then k-section.

The search knows nothing of robots: it asks a ``probe`` function for the
behaviour at a batch of axis values (``"climbed"``, ``"refused"``,
``"stranded"``, ...) and narrows every interval whose two ends differ.

* **Scan.**  The scan values (both ends of the range among them) are probed
  first; every pair of neighbours whose behaviours differ is a bracket.
* **k-section.**  Each round puts ``per_round`` probes evenly inside every
  bracket still wider than the tolerance (2 probes with ``-j 2``: thirds;
  1: bisection), all brackets' probes in one batch, so the executor runs
  them side by side.  A bracket whose probes show more than one change is
  **non-monotonic**: it is recorded (with its probes) and each change in it
  is narrowed on as a bracket of its own, never merged into one.
* The search stops when every bracket is at most ``tolerance`` wide, or
  after ``max_probes`` probes (the brackets left wider say so).

A change narrower than the scan's spacing, with the same behaviour either
side, is not seen: the scan's spacing is the finest feature it resolves.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

Probe = Callable[[list[float]], list[str]]
"""Behaviours at these axis values, in the same order."""


@dataclass(frozen=True)
class Bracket:
    """The last value of one behaviour and the first of the next, along the axis."""

    low: float
    low_is: str
    high: float
    high_is: str

    @property
    def width(self) -> float:
        return self.high - self.low

    @property
    def middle(self) -> float:
        return (self.low + self.high) / 2.0


@dataclass(frozen=True)
class Tangle:
    """A bracket whose probes changed behaviour more than once inside it."""

    low: float
    high: float
    probes: tuple[tuple[float, str], ...]


@dataclass
class Search:
    """What a search found: every probe in order, the final brackets (low to
    high), the non-monotonic brackets met on the way, and whether it ran out
    of probes before every bracket was narrow enough."""

    probes: list[tuple[float, str]] = field(default_factory=list)
    brackets: list[Bracket] = field(default_factory=list)
    tangles: list[Tangle] = field(default_factory=list)
    rounds: int = 0
    exhausted: bool = False

    @property
    def monotonic(self) -> bool:
        return not self.tangles


def scan_values(low: float, high: float, count: int, integer: bool = False,
                digits: int = 9) -> list[float]:
    """``count`` evenly spaced values from ``low`` to ``high``, both included,
    rounded to ``digits`` decimals (whole numbers, each once, for an integer
    axis)."""
    if count < 2 or high <= low:
        return [low] if high <= low else [low, high]
    step = (high - low) / (count - 1)
    values = [low + k * step for k in range(count)]
    values[-1] = high
    if integer:
        return sorted({float(round(v)) for v in values})
    return [round(v, digits) for v in values]


def _inside(b: Bracket, per_round: int, integer: bool, digits: int) -> list[float]:
    """The probes one round puts inside ``b``: ``per_round`` evenly spaced
    (whole numbers strictly between the ends, for an integer axis)."""
    pts = [b.low + b.width * k / (per_round + 1) for k in range(1, per_round + 1)]
    if integer:
        return sorted({float(round(p)) for p in pts} - {b.low, b.high})
    return sorted({round(p, digits) for p in pts} - {b.low, b.high})


def _split(points: Sequence[tuple[float, str]]) -> list[Bracket]:
    """The brackets between neighbours (sorted by value) that differ."""
    return [Bracket(a, ia, b, ib) for (a, ia), (b, ib) in zip(points, points[1:], strict=False)
            if ia != ib]


def search(scan: Sequence[float], probe: Probe, tolerance: float, per_round: int = 2,
           max_probes: int = 200, integer: bool = False, digits: int = 9) -> Search:
    """Scan ``scan`` (sorted axis values), then k-section every change to
    ``tolerance``, each probe's value rounded to ``digits`` decimals (the
    precision a case holds).  ``probe`` is called once per round with that
    round's values."""
    if tolerance <= 0 or not math.isfinite(tolerance):
        raise ValueError(f"tolerance {tolerance!r}: allowed: a number > 0")
    out = Search()
    values = sorted(set(scan))
    seen = list(zip(values, probe(values), strict=True))
    out.probes += seen
    out.rounds = 1
    open_ = _split(seen)
    done: list[Bracket] = []
    need = 1.0 if integer else tolerance
    while open_:
        narrow = [b for b in open_ if b.width <= need + 1e-12]
        done += narrow
        wide = [b for b in open_ if b.width > need + 1e-12]
        if not wide:
            break
        plan = [(b, _inside(b, per_round, integer, digits)) for b in wide]
        batch = [v for _, pts in plan for v in pts]
        if not batch or len(out.probes) + len(batch) > max_probes:
            out.exhausted = bool(batch)
            done += wide
            break
        got = dict(zip(batch, probe(batch), strict=True))
        out.probes += [(v, got[v]) for v in batch]
        out.rounds += 1
        open_ = []
        for b, pts in plan:
            points = [(b.low, b.low_is), *((v, got[v]) for v in pts), (b.high, b.high_is)]
            parts = _split(points)
            if len(parts) > 1:
                out.tangles.append(Tangle(b.low, b.high, tuple(points)))
            open_ += parts
    out.brackets = sorted(done, key=lambda b: b.low)
    return out


def changes(seq: Sequence[str]) -> int:
    """How many times a sequence of behaviours changes from one to the next."""
    return sum(1 for a, b in zip(seq, seq[1:], strict=False) if a != b)
