"""The transition table: every phase change the controller may make, with the
condition that makes it.  The single source of truth: the controller refuses
any change not listed here, the standing rule is armed exactly in the phases
that list :attr:`Phase.PAUSED`, and the flowcharts in docs/algorithm.md are
drawn from it (``python -m stairbot.algorithm.transitions``).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from stairbot.algorithm.phases import FLOWS, Phase

P = Phase


class TransitionError(RuntimeError):
    """The controller tried a phase change the table does not list: a bug."""


FAULT = "sensor error, motor fault or phase timeout"
FRONT_DISAGREE = "SFR ≠ SFL for 3 ticks"
BACK_DISAGREE = "SBR ≠ SBL for 3 ticks"

_TABLE: dict[Phase, dict[Phase, str]] = {
    # -- calibration ---------------------------------------------------------------
    P.CAL_CHECK: {
        P.DONE: "case 1: both read ≥ LENGTH_OF_INFINITY (nothing ahead)",
        P.CAL_LIFT: "start: case 2 (SFR ≠ SFL) or case 3 (SFR = SFL); later: SFR ≠ SFL",
        P.ASCENT_APPROACH: "ascent 1 on a later step: SFR = SFL",
        P.DESCENT_BACK_TO_EDGE: "descent 1: SFR = SFL",
        P.ERROR: "case 1: sensor error; later: nothing ahead where a riser should be",
    },
    P.CAL_LIFT: {
        P.CAL_TURN: "lifted; case 2",
        P.CAL_PROBE: "lifted; case 3",
        P.ERROR: FAULT,
    },
    P.CAL_PROBE: {
        P.CAL_CORNER: "SFR grew, SFL shrank: case 3B",
        P.CAL_TURN: "otherwise: case 3A, turn back right",
        P.ERROR: FAULT,
    },
    P.CAL_CORNER: {
        P.CAL_TURN: "both readings shrink",
        P.ERROR: "turned too far; " + FAULT,
    },
    P.CAL_TURN: {
        P.CAL_LOWER: "SFR = SFL",
        P.ERROR: "turned too far; " + FAULT,
    },
    P.CAL_LOWER: {
        P.ASCENT_APPROACH: "lowered (start or ascent 1)",
        P.DESCENT_BACK_TO_EDGE: "lowered (descent 1)",
        P.DONE: "lowered; calibrate-only mode",
        P.ERROR: FAULT,
    },
    # -- ascent --------------------------------------------------------------------
    P.ASCENT_APPROACH: {
        P.ASCENT_APPROACH_TURNS: "reads SAFE_DISTANCE_IN_FRONT_OF_STEP",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: "riser lost (nothing ahead); " + FAULT,
    },
    P.ASCENT_APPROACH_TURNS: {
        P.ASCENT_LIFT_FIRST: "turns made",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.ASCENT_LIFT_FIRST: {
        P.ASCENT_LIFT_FIRST_MORE: "reads ≥ LENGTH_OF_A_ROBOT + SAFE_LENGTH",
        P.ASCENT_LOWER_OBSTACLE: "MAX_OF_VERTICAL_TURNS − number_of_vertical_turns made: "
                                 "step too high or tread too short",
        P.ERROR: FAULT,
    },
    P.ASCENT_LIFT_FIRST_MORE: {
        P.ASCENT_DRIVE_FIRST: "turns made: number_of_turns_for_step_height stored",
        P.ERROR: FAULT,
    },
    P.ASCENT_LOWER_OBSTACLE: {
        P.DESCENT_BACK_OFF: "lowered; number_of_steps > 0",
        P.DESCENT_FINISH: "lowered; number_of_steps = 0",
        P.ERROR: FAULT,
    },
    P.ASCENT_DRIVE_FIRST: {
        P.ASCENT_LIFT_SECOND: "reads length_of_next_step − LENGTH_OF_FIRST_MODULE "
                              "(or turns made)",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.ASCENT_LIFT_SECOND: {
        P.ASCENT_DRIVE_SECOND: "turns made",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.ASCENT_DRIVE_SECOND: {
        P.ASCENT_LIFT_THIRD: "reads length_of_next_step − LENGTH_OF_FIRST_MODULE − "
                             "LENGTH_OF_SECOND_MODULE (or turns made)",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.ASCENT_LIFT_THIRD: {
        P.ASCENT_CHECK: "turns made; tab_length_to_edge[i] stored, number_of_steps + 1",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.ASCENT_CHECK: {
        P.DESCENT_LOWER_THIRD: "reads ≥ LENGTH_OF_INFINITY (top reached) "
                               "or number_of_steps = max_steps",
        P.ASCENT_DRIVE_THIRD: "otherwise",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.ASCENT_DRIVE_THIRD: {
        P.CAL_CHECK: "reads length_of_next_step − LENGTH_OF_A_ROBOT (or turns made): "
                     "next step, ascent 1",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    # -- descent -------------------------------------------------------------------
    P.DESCENT_BACK_OFF: {
        P.CAL_CHECK: "turns made: calibrate (case 2)",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.DESCENT_BACK_TO_EDGE: {
        P.DESCENT_LOWER_THIRD: "reads tab_length_to_edge[i]",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: "tab_length_to_edge[i] unknown; " + FAULT,
    },
    P.DESCENT_LOWER_THIRD: {
        P.DESCENT_DRIVE_SECOND: "SBR/SBL read BACK_CLEARANCE: "
                                "number_of_turns_for_step_height stored",
        P.PAUSED: BACK_DISAGREE,
        P.ERROR: "reads ≤ BACK_CLEARANCE at the start, or floor not found "
                 "within MAX_OF_VERTICAL_TURNS; " + FAULT,
    },
    P.DESCENT_DRIVE_SECOND: {
        P.DESCENT_LOWER_SECOND: "reads LENGTH_OF_SECOND_MODULE + tab_length_to_edge[i] "
                                "(or turns made)",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.DESCENT_LOWER_SECOND: {
        P.DESCENT_DRIVE_FIRST: "turns made",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.DESCENT_DRIVE_FIRST: {
        P.DESCENT_LOWER_FIRST: "reads LENGTH_OF_FIRST_MODULE + LENGTH_OF_SECOND_MODULE + "
                               "tab_length_to_edge[i] (or turns made)",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    P.DESCENT_LOWER_FIRST: {
        P.DESCENT_BACK_OFF: "turns made; steps remain",
        P.DESCENT_FINISH: "turns made; all number_of_steps descended",
        P.ERROR: FAULT,
    },
    P.DESCENT_FINISH: {
        P.DONE: "reads the start reading (or turns made)",
        P.PAUSED: FRONT_DISAGREE,
        P.ERROR: FAULT,
    },
    # -- the standing rule and the ends -----------------------------------------------
    P.PAUSED: {},  # filled below: back to every phase that can pause
    P.DONE: {},
    P.ERROR: {},
}

for _src, _nexts in list(_TABLE.items()):
    if P.PAUSED in _nexts:
        _TABLE[P.PAUSED][_src] = "readings agree after standing_wait: resume"
_TABLE[P.PAUSED][P.ERROR] = "readings still disagree after standing_wait; " + FAULT

TRANSITIONS: Mapping[Phase, Mapping[Phase, str]] = MappingProxyType(
    {src: MappingProxyType(dict(nexts)) for src, nexts in _TABLE.items()}
)
"""phase -> {next phase: the condition, in words}."""

STANDING_ARMED: frozenset[Phase] = frozenset(
    src for src, nexts in TRANSITIONS.items() if P.PAUSED in nexts
)
"""The phases where the standing rule is armed."""

BACK_PAIR_PHASES: frozenset[Phase] = frozenset(
    src for src in STANDING_ARMED if TRANSITIONS[src][P.PAUSED] == BACK_DISAGREE
)
"""Armed phases watching SBR/SBL rather than SFR/SFL."""


def allowed(src: Phase, dst: Phase) -> bool:
    """True when the table lists the change ``src -> dst``."""
    return dst in TRANSITIONS.get(src, {})


def _node(phase: Phase) -> str:
    shape = ("([", "])") if phase.terminal else ("{{", "}}") if phase is P.PAUSED else ("[", "]")
    return f'    {phase.value}{shape[0]}"{phase.label}"{shape[1]}'


def mermaid(flow: str) -> str:
    """The Mermaid flowchart of one flow ("calibration", "ascent", "descent").

    It draws every transition leaving a phase of that flow, and every resume
    from the standing rule's wait into one; phases of other flows appear as
    the nodes those edges reach.  Raises ValueError for an unknown flow.
    """
    if flow not in FLOWS:
        raise ValueError(f"unknown flow {flow!r}; allowed: {', '.join(FLOWS)}")
    pauses = any(src.flow == flow for src in STANDING_ARMED)
    edges: list[tuple[Phase, Phase, str]] = []
    for src, nexts in TRANSITIONS.items():
        for dst, label in nexts.items():
            resume = src is P.PAUSED and (dst.flow == flow or (pauses and dst is P.ERROR))
            if src.flow == flow or resume:
                edges.append((src, dst, label))
    nodes: list[Phase] = [p for p in Phase if p.flow == flow]
    for src, dst, _ in edges:
        for p in (src, dst):
            if p not in nodes:
                nodes.append(p)
    lines = ["flowchart TD"]
    lines += [_node(p) for p in nodes]
    lines += [f'    {s.value} -->|"{label}"| {d.value}' for s, d, label in edges]
    return "\n".join(lines) + "\n"


def main() -> None:
    """Print the three flowcharts as Markdown sections with Mermaid blocks."""
    for flow in FLOWS:
        print(f"### {flow.capitalize()}\n\n```mermaid\n{mermaid(flow)}```\n")


if __name__ == "__main__":
    main()
