"""A quantity sampled on the control ticks, read at an earlier time."""

from __future__ import annotations

from collections.abc import Sequence


def value_at(samples: Sequence[tuple[float, float]], t: float) -> float:
    """The value of ``(time, value)`` samples (oldest first) at time ``t``:
    linear between the samples either side, the oldest if ``t`` is older,
    the newest if it is later."""
    later: tuple[float, float] | None = None
    for at, value in reversed(samples):
        if at <= t:
            if later is None or later[0] == at:
                return value
            return value + (later[1] - value) * (t - at) / (later[0] - at)
        later = (at, value)
    return samples[0][1]


def keep_since(samples: list[tuple[float, float]], t: float) -> None:
    """Drop the samples older than needed to read the value at ``t`` or
    later (:func:`value_at`): the newest at or before ``t`` stays."""
    while len(samples) > 2 and samples[1][0] <= t:
        del samples[0]
