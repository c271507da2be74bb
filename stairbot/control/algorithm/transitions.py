"""The transition table: every phase change the controller may make, with the
condition that makes it, drawn from the phases' records: each record's
outcomes (``on``: outcome -> next phase and condition), an armed phase's
pause (:data:`~stairbot.control.algorithm.standing.DISAGREE`) and the resume
back into it.  The controller looks each outcome a step returns up here
(:func:`exit_of`) and refuses one its phase does not list; the flowcharts in
docs/algorithm.md are drawn from it
(``python -m stairbot.control.algorithm.transitions``).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from stairbot.control.algorithm.phase import BACK_DISAGREE, FAILED, FRONT_DISAGREE, Exit
from stairbot.control.algorithm.phases import FLOWS, Phase
from stairbot.control.algorithm.stability import UNSTABLE_EDGE
from stairbot.control.algorithm.standing import DISAGREE, resumed
from stairbot.control.algorithm.table import PHASES
from stairbot.errors import TransitionError

P = Phase


def _table() -> dict[Phase, dict[str, Exit]]:
    """Every record's outcomes; an armed phase also pauses (before its
    error, as the flowcharts read), and the pause resumes into it; a lift
    phase's error names the stability check first."""
    table: dict[Phase, dict[str, Exit]] = {}
    resumes: dict[str, Exit] = {}
    for phase, record in PHASES.items():
        exits = dict(record.on)
        if record.carried_by:
            failed = exits[FAILED]
            exits[FAILED] = Exit(failed.phase, f"{UNSTABLE_EDGE}; {failed.when}")
        if record.watches is not None:
            error = exits.pop(FAILED, None)
            exits[DISAGREE] = Exit(P.PAUSED, BACK_DISAGREE if record.watches == "back"
                                   else FRONT_DISAGREE)
            if error is not None:
                exits[FAILED] = error
            resumes[resumed(phase)] = Exit(phase, "readings agree after standing_wait: resume")
        table[phase] = exits
    error = table[P.PAUSED].pop(FAILED)
    table[P.PAUSED] = {**resumes, FAILED: error}
    return table


EXITS: Mapping[Phase, Mapping[str, Exit]] = MappingProxyType(
    {src: MappingProxyType(exits) for src, exits in _table().items()}
)
"""phase -> {outcome: where it leads (the next phase, the condition in words)}."""


def _joined(exits: Mapping[str, Exit]) -> dict[Phase, str]:
    """Each next phase with the conditions of the outcomes leading to it,
    joined by "; or " in the record's order."""
    out: dict[Phase, list[str]] = {}
    for ex in exits.values():
        out.setdefault(ex.phase, []).append(ex.when)
    return {dst: "; or ".join(whens) for dst, whens in out.items()}


TRANSITIONS: Mapping[Phase, Mapping[Phase, str]] = MappingProxyType(
    {src: MappingProxyType(_joined(exits)) for src, exits in EXITS.items()}
)
"""phase -> {next phase: the conditions that lead there, in words}."""

STANDING_ARMED: frozenset[Phase] = frozenset(
    src for src, nexts in TRANSITIONS.items() if P.PAUSED in nexts
)
"""The phases where the standing rule is armed."""

BACK_PAIR_PHASES: frozenset[Phase] = frozenset(
    src for src in STANDING_ARMED if PHASES[src].watches == "back"
)
"""Armed phases watching SBR/SBL rather than SFR/SFL."""


def exit_of(src: Phase, happened: str) -> Exit:
    """Where the outcome ``happened`` of ``src`` leads.  Raises
    TransitionError when ``src`` does not list it (a bug in a phase)."""
    exits = EXITS.get(src, {})
    found = exits.get(happened)
    if found is None:
        raise TransitionError(f"{src.value} -> ?: {happened!r} is not an outcome of "
                              f"{src.value} in the transition table (it lists "
                              f"{', '.join(exits) or 'none'})")
    return found


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
    return _chart([p for p in Phase if p.flow == flow], edges)


def _chart(nodes: list[Phase], edges: list[tuple[Phase, Phase, str]]) -> str:
    """A Mermaid flowchart of ``nodes`` (and every phase the edges reach) and
    ``edges`` (source, destination, condition)."""
    nodes = list(nodes)
    for src, dst, _ in edges:
        for p in (src, dst):
            if p not in nodes:
                nodes.append(p)
    lines = ["flowchart TD"]
    lines += [_node(p) for p in nodes]
    lines += [f'    {s.value} -->|"{label}"| {d.value}' for s, d, label in edges]
    return "\n".join(lines) + "\n"


EXTENSIONS: Mapping[str, tuple[str, frozenset[Phase]]] = MappingProxyType({
    "Continuous descent": ("continuous descent", frozenset({P.DESCENT_REFUSE})),
    "Narrow steps": ("narrow", frozenset()),
    "Quarter-turn landings": ("landing", frozenset(
        {P.LANDING_SCAN, P.LANDING_SCAN_LOWER, P.LANDING_CENTRE, P.LANDING_RETURN})),
})
"""The seed's extensions, each drawn as what it adds to the flows: the
transitions whose condition names it, and every transition leaving a phase
that is its own (and the standing rule's resume into one)."""


def mermaid_extension(title: str) -> str:
    """The Mermaid flowchart of one of :data:`EXTENSIONS`.  Raises
    ValueError for an unknown one."""
    if title not in EXTENSIONS:
        raise ValueError(f"unknown extension {title!r}; allowed: {', '.join(EXTENSIONS)}")
    words, own = EXTENSIONS[title]
    edges = [(src, dst, label) for src, nexts in TRANSITIONS.items()
             for dst, label in nexts.items()
             if src in own or words in label.lower() or (src is P.PAUSED and dst in own)]
    return _chart([], edges)


def main() -> None:
    """Print the three flowcharts, then the extensions', as Markdown sections
    with Mermaid blocks."""
    for flow in FLOWS:
        print(f"### {flow.capitalize()}\n\n```mermaid\n{mermaid(flow)}```\n")
    for title in EXTENSIONS:
        print(f"### {title}\n\n```mermaid\n{mermaid_extension(title)}```\n")


if __name__ == "__main__":
    main()
