"""The current phase -- what it does in the operator's words, the seed's
label beneath it -- where it stands in the flow, and the seed's variables
the operator watches: the steps climbed (``number_of_steps``) and the
treads measured (``tab_length_to_edge``), the seed's names after them."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from rich.console import Group
from rich.text import Text
from textual.widgets import Static

from stairbot.console.words import phase_words
from stairbot.control.algorithm.phases import FLOWS


def flow_text(flow: str) -> Text:
    """``calibration › ascent › descent`` with the current one highlighted."""
    out = Text(no_wrap=True, overflow="ellipsis")
    for i, name in enumerate(FLOWS):
        if i:
            out.append(" › ", "dim")
        if name == flow:
            out.append(name.upper(), "bold reverse")
        else:
            out.append(name, "dim")
    if flow == "end":
        out.append(" › ", "dim")
        out.append("END", "bold reverse")
    elif flow not in FLOWS and flow not in ("", "idle"):
        out.append(f"  {flow}", "bold")
    return out


def tab_text(context: Mapping[str, Any]) -> Text:
    """The filled entries of ``tab_length_to_edge``, in millimetres."""
    out = Text("treads mm ", "bold", no_wrap=True, overflow="ellipsis")
    tab = context.get("tab_length_to_edge")
    values: list[str] = []
    if isinstance(tab, Sequence) and not isinstance(tab, str):
        n = context.get("number_of_steps")
        used = tab[: n] if isinstance(n, int) and n > 0 else [v for v in tab if v]
        values = [f"{float(v) * 1000:.0f}" if isinstance(v, int | float) else "—" for v in used]
    out.append(" ".join(values) if values else "—")
    out.append("  tab_length_to_edge", "dim")
    return out


class PhasePanel(Static):
    """Phase label, flow, number_of_steps and tab_length_to_edge."""

    DEFAULT_CSS = "PhasePanel { height: auto; }"

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002
        super().__init__(id=id)
        self._last: object = None
        self.border_title = "phase"

    def show(self, label: str, flow: str, context: Mapping[str, Any],
             phase_id: str = "", *, degraded: str = "") -> None:
        """``label``: the seed's; ``phase_id``: the phase's value, for the
        operator's words (stairbot.console.words); ``degraded``: the title's
        word for a run that limps home ("LIMPING HOME"), or came home so."""
        key = (label, flow, phase_id, degraded, repr(context.get("number_of_steps")),
               repr(context.get("steps_descended")), repr(context.get("tab_length_to_edge")))
        if key == self._last:
            return
        self._last = key
        self.border_title = Text.assemble("phase · ", (degraded, "bold reverse")) \
            if degraded else "phase"
        words = phase_words(phase_id)
        steps = Text("steps climbed ", "bold", no_wrap=True, overflow="ellipsis")
        steps.append(str(context.get("number_of_steps", "—")))
        if context.get("steps_descended"):
            steps.append(f", down {context['steps_descended']}")
        steps.append("  number_of_steps", "dim")
        self.update(Group(
            Text(words or label or "—", "bold", no_wrap=True, overflow="ellipsis"),
            Text(label if words else "", "dim", no_wrap=True, overflow="ellipsis"),
            flow_text(flow),
            steps,
            tab_text(context),
        ))
