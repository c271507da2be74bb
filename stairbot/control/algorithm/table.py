"""Every phase's record, gathered from the modules of the flows."""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from stairbot.control.algorithm import ascent, calibration, descent, landing, standing, turns
from stairbot.control.algorithm.phase import PhaseDef
from stairbot.control.algorithm.phases import Phase

PHASES: Mapping[Phase, PhaseDef[Any]] = MappingProxyType(
    {d.phase: d for d in (*calibration.PHASES, *turns.PHASES, *ascent.PHASES, *descent.PHASES,
                           *landing.PHASES, *standing.PHASES)}
)
"""phase -> its record, for every Phase."""

missing = set(Phase) - set(PHASES)
if missing:  # pragma: no cover - caught by the import in every test
    raise RuntimeError(f"phases without a record: {sorted(p.value for p in missing)}")
