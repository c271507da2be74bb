"""docs/protocol.md is what a firmware author reads: its test vectors must be
the machine-readable ones the wire tests check (drivers/vectors_*.json), hex
for hex, and its tables must name every message of the model."""

from __future__ import annotations

import json
import re
from importlib import resources
from pathlib import Path
from typing import Any

import pytest

from stairbot.drivers import messages as m
from stairbot.fakes import sim_messages  # noqa: F401 - the doc's tables have them too

DOC_PATH = Path(__file__).resolve().parents[2] / "docs" / "protocol.md"
pytestmark = pytest.mark.skipif(not DOC_PATH.exists(), reason="needs the source checkout's docs/")


def _json(name: str, package: str = "stairbot.drivers") -> dict[str, Any]:
    data: dict[str, Any] = json.loads(resources.files(package).joinpath(name).read_text())
    return data


def _section(doc: str, start: str, end: str) -> str:
    i = doc.index(start)
    return doc[i:doc.index(end, i)]


def test_serial_vectors_in_the_doc_are_the_json_ones() -> None:
    doc = DOC_PATH.read_text()
    text = _section(doc, "### Test vectors", "## 6.")
    frames = re.findall(r"^\*\*(.+?)\*\* — (.+)\n\n    body: (.+)\n    wire: (.+)$", text, re.M)
    streams = re.findall(r"^\*\*(.+?)\*\* — (.+)\n\n    ((?:[0-9a-f]{2} ?)+)$", text, re.M)
    data = _json("vectors_serial.json")
    assert frames == [(v["name"], v["meaning"], v["body_hex"], v["wire_hex"])
                      for v in data["vectors"]]
    assert streams == [(s["name"], s["meaning"], s["wire_hex"]) for s in data["streams"]]


def test_can_vectors_in_the_doc_are_the_json_ones() -> None:
    doc = DOC_PATH.read_text()
    text = _section(doc, "### CAN test vectors", "### Requests and replies on CAN")
    rows = re.findall(r"^\| `(0x[0-9A-F]{8})` \| `(0x[0-9A-F]{3})` \| (\d+) \| (\d+) \| "
                      r"(?:`([0-9a-f ]+)`|—) \| (\w+) \| (.+) \|$", text, re.M)
    assert rows == [(v["id"], v["base"], str(v["session"]), str(v["seq"]),
                     bytes.fromhex(v["data"]).hex(" "), v["frame"], v["meaning"])
                    for v in [*_json("vectors_can.json")["vectors"],
                              *_json("vectors_sim_can.json", "stairbot.fakes")["vectors"]]]


def test_every_message_is_in_the_doc_with_its_type_code() -> None:
    doc = DOC_PATH.read_text()
    for code, cls in m.MESSAGES.items():
        assert re.search(rf"^\| 0x{code:02X} +\| {cls.__name__} ", doc, re.M), cls.__name__
