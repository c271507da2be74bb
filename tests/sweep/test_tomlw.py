"""The TOML writer behind the cases a sweep writes: what it writes reads back
as the same value (tomllib is the independent reader)."""

from __future__ import annotations

import tomllib

import pytest

from stairbot.sweep import tomlw


@pytest.mark.parametrize("text", ["plain", "tab\there", "del\x7f", "esc\x1b[2J", "bel\x07",
                                  "c1\x9b31m", "quote\" back\\slash", "Tür 中 \u202e"])
def test_every_string_reads_back_as_written(text: str) -> None:
    doc = {"name": text, "stairs": {"top": text}}
    assert tomllib.loads(tomlw.dumps(doc)) == doc
