"""Every phase's record, gathered from the modules of the flows and bound to
the :class:`~stairbot.control.algorithm.phases.Phase` enum (whose ``record``,
``label`` and ``flow`` read them).  The package imports this module first, so
the records are bound before any phase is asked for one."""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from stairbot.control.algorithm import ascent, calibration, descent, landing, standing, turns
from stairbot.control.algorithm.phase import PhaseDef
from stairbot.control.algorithm.phases import Phase, bind

PHASES: Mapping[Phase, PhaseDef[Any]] = MappingProxyType(
    {d.phase: d for d in (*calibration.PHASES, *turns.PHASES, *ascent.PHASES, *descent.PHASES,
                           *landing.PHASES, *standing.PHASES)}
)
"""phase -> its record, for every Phase."""

bind(PHASES)
