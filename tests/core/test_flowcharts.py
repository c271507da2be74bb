"""docs/algorithm.md draws the calibration, ascent and descent flowcharts from
the controller's transition table: this fails when the drawing and the code
disagree (regenerate with ``python -m stairbot.control.algorithm.transitions``)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from stairbot.control.algorithm.phases import FLOWS
from stairbot.control.algorithm.transitions import (
    EXTENSIONS,
    TRANSITIONS,
    mermaid,
    mermaid_extension,
)

DOC = Path(__file__).resolve().parents[2] / "docs" / "algorithm.md"
FIX = ("the flowcharts in docs/algorithm.md are stale: paste "
       "`python -m stairbot.control.algorithm.transitions`")


def drawn(flow: str) -> str:
    text = DOC.read_text("utf-8")
    title = flow if flow in EXTENSIONS else flow.capitalize()
    m = re.search(rf"^### {title}\n\n```mermaid\n(.*?)```", text, re.S | re.M)
    assert m is not None, f"docs/algorithm.md has no '### {title}' mermaid block"
    return m.group(1)


@pytest.mark.parametrize("flow", FLOWS)
def test_the_drawing_is_the_table(flow: str) -> None:
    assert drawn(flow) == mermaid(flow), FIX


@pytest.mark.parametrize("title", list(EXTENSIONS))
def test_each_extension_is_drawn_from_the_table(title: str) -> None:
    chart = mermaid_extension(title)
    assert drawn(title) == chart, FIX
    assert chart.count("-->") >= 2  # it names transitions of its own


def test_every_transition_of_the_table_is_drawn_somewhere() -> None:
    charts = "".join(drawn(flow) for flow in (*FLOWS, *EXTENSIONS))
    edges = set(re.findall(r"^\s+(\w+) -->\|\"[^\"]*\"\| (\w+)$", charts, re.M))
    for src, nexts in TRANSITIONS.items():
        for dst in nexts:
            assert (src.value, dst.value) in edges, f"{src.value} -> {dst.value} not drawn"
