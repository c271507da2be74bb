"""A quantity sampled on the control ticks, read at an earlier time."""

from __future__ import annotations

from collections.abc import Sequence


def value_at(samples: Sequence[tuple[float, float]], t: float) -> float:
    """The value of ``(time, value)`` samples (oldest first) at time ``t``:
    linear between the samples either side, the oldest if ``t`` is older,
    the newest if it is later.  Searched from the newest: the time asked
    for is most often within the last tick."""
    i = len(samples) - 1
    at, value = samples[i]
    if at <= t:
        return value
    while i > 0:
        i -= 1
        later_at, later_value = at, value
        at, value = samples[i]
        if at <= t:
            if later_at == at:
                return value
            return value + (later_value - value) * (t - at) / (later_at - at)
    return value


def keep_since(samples: list[tuple[float, float]], t: float) -> None:
    """Drop the samples older than needed to read the value at ``t`` or
    later (:func:`value_at`): the newest at or before ``t`` stays."""
    while len(samples) > 2 and samples[1][0] <= t:
        del samples[0]
