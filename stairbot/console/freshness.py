"""How old what the screen shows is: every panel of robot values says when
they were read, and values older than :data:`STALE_S` are dimmed and
marked STALE -- never shown as live.  The robot is read every tick during a
run and every :data:`POLL_PERIOD_S` while idle, so a live value is never
older than that; one older than two missed polls is stale."""

from __future__ import annotations

from rich.text import Text

POLL_PERIOD_S = 0.5
"""Seconds between reads of an idle robot (no run going): sensors and link."""
STALE_S = 3 * POLL_PERIOD_S
"""Values read longer ago than this are stale."""
STILL_TPS = 0.05
"""Turns/s below which a motor reads as stopped: what its speed shows at one
decimal (``+0.0``)."""


def is_stale(age_s: float | None) -> bool:
    return age_s is None or age_s > STALE_S


def age_words(age_s: float | None) -> str:
    """``0.2 s ago``, ``STALE 12 s``, ``STALE 3 min``, ``never read``."""
    if age_s is None:
        return "never read"
    if age_s < 10:
        shown = f"{age_s:.1f} s"
    elif age_s < 120:
        shown = f"{age_s:.0f} s"
    else:
        shown = f"{age_s / 60:.0f} min"
    return f"STALE {shown}" if is_stale(age_s) else f"{shown} ago"


def age_key(age_s: float | None) -> object:
    """What changes when :func:`age_words` would (a panel redraws then)."""
    return age_words(age_s)


def titled(name: str, age_s: float | None) -> Text:
    """A panel's border title with the age of its values (red when stale)."""
    out = Text(f"{name} · ")
    out.append(age_words(age_s), "bold red" if is_stale(age_s) else "dim")
    return out


def without_status(text: Text) -> Text:
    """``text`` all dim, its colours gone: a stale panel's values say nothing
    about now, so no green "ok", red "DIFFER" or bold figure may look live."""
    return Text(text.plain, style="dim", no_wrap=text.no_wrap, overflow=text.overflow)
