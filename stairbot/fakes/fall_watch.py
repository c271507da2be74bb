"""Whether the simulated robot has fallen, checked once per
:meth:`~stairbot.fakes.world.World.advance`: a segment pitched beyond the
limit, falling (by its height change since the last check), below the floor,
or every wheel off every support for longer than the airborne limit
(:class:`~stairbot.fakes.world_params.WorldParams` holds the limits).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pymunk

try:  # pymunk's C layer: a wheel's contacts counted without an Arbiter object for each
    from pymunk._chipmunk import ffi as _ffi
    from pymunk._chipmunk import lib as _cp
except ImportError:  # pragma: no cover - another pymunk layout: the public API is used
    _cp = _ffi = None

from stairbot.fakes.world_params import WorldParams


class FallWatch:
    """The robot's fall, once it happened (``fell``, ``reason``), and the
    largest pitch of any segment so far."""

    def __init__(self, params: WorldParams, wheels: list[pymunk.Body], y: list[float]) -> None:
        """``wheels``: every wheel of the robot; ``y``: its segments' heights now."""
        self.params = params
        self.wheels = wheels
        self.max_pitch_deg = 0.0
        self._max_pitch_rad = 0.0  # the angle whose pitch is max_pitch_deg
        self.fell = False
        self.reason: str | None = None
        self._airborne_s = 0.0
        self._since_contact_check = 0.0
        self._check_y, self._check_t = list(y), 0.0
        self._in_contact = _contact_probe(wheels)

    def _wheel_in_contact(self) -> bool:
        if self._in_contact is not None:
            return self._in_contact()
        found = False

        def seen(_arb: pymunk.Arbiter) -> None:
            nonlocal found
            found = True

        for w in self.wheels:
            w.each_arbiter(seen)
            if found:
                return True
        return False

    def check(self, time: float, py: list[float], pa: list[float]) -> None:
        """Track the pitch; detect a pitch beyond the limit, a segment falling (by
        its height change since the last check) and every wheel off every support.
        ``time``: the world's; ``py``, ``pa``: its segments' heights and angles."""
        p = self.params
        prev_y = self._check_y
        elapsed = max(time - self._check_t, 1e-9)
        self._check_t = time
        for i in (0, 1, 2):
            # degrees() keeps the order of angles: an angle no larger than the
            # one of the largest pitch so far is no larger a pitch, and (that
            # one within the limit while the robot stands) within the limit
            angle = abs(pa[i])
            if angle > self._max_pitch_rad:
                pitch = math.degrees(angle)
                if pitch > self.max_pitch_deg:
                    self.max_pitch_deg, self._max_pitch_rad = pitch, angle
                if pitch > p.pitch_limit_deg:
                    self._fall(f"segment {i + 1} pitched {pitch:.0f} deg (limit "
                               f"{p.pitch_limit_deg:.0f})")
                    return
            y = py[i]
            vy = (y - prev_y[i]) / elapsed
            prev_y[i] = y
            if vy < -p.fall_speed:
                self._fall(f"segment {i + 1} falling at {-vy:.1f} m/s")
                return
            if y < -0.1:
                self._fall(f"segment {i + 1} below the floor")
                return
        # contacts are looked up a few times a second: enough for a 0.3 s limit
        self._since_contact_check += elapsed
        if self._since_contact_check < p.contact_check_s - 1e-9:
            return
        if self._wheel_in_contact():
            self._airborne_s = 0.0
        else:
            self._airborne_s += self._since_contact_check
            if self._airborne_s > p.airborne_limit_s:
                self._fall(f"no wheel on any support for {self._airborne_s:.2f} s")
        self._since_contact_check = 0.0

    def _fall(self, reason: str) -> None:
        self.fell = True
        self.reason = reason


def _contact_probe(wheels: list[pymunk.Body]) -> Callable[[], bool] | None:
    """A function telling whether any of ``wheels`` touches anything now (has
    an arbiter: what Body.each_arbiter goes through), by chipmunk's
    cpBodyEachArbiter with a C callback that counts; None where pymunk's C
    layer is not at hand."""
    seen = [0]

    def count(_body: Any, _arbiter: Any, _data: Any) -> None:
        seen[0] += 1

    try:
        callback = _ffi.callback("void(cpBody *, cpArbiter *, void *)", count)
        bodies = [w._body for w in wheels]
        each, null = _cp.cpBodyEachArbiter, _ffi.NULL
    except (AttributeError, TypeError, MemoryError):  # pragma: no cover - another pymunk
        return None

    def in_contact() -> bool:
        seen[0] = 0
        for body in bodies:
            each(body, callback, null)  # (the callback, kept by this closure, stays alive)
            if seen[0]:
                return True
        return False

    return in_contact
