"""The shipped Foxglove layout is the one stairbot.recording.layout builds,
and every message path it names is a field the recording writes."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from stairbot.recording import topics
from stairbot.recording.layout import layout_json

SHIPPED = Path(__file__).resolve().parents[2] / "docs" / "foxglove-layout.json"
JSON_SCHEMAS = {topics.SENSORS: topics.SENSORS_SCHEMA, topics.MOTORS: topics.MOTORS_SCHEMA,
                topics.LINK: topics.LINK_SCHEMA, topics.RECORD: topics.RECORD_SCHEMA}
LOG_FIELDS = {"timestamp", "level", "message", "name", "file", "line"}
LOG_TOPICS = {topics.EVENTS, topics.PHASE}


def test_the_shipped_layout_is_the_built_one() -> None:
    assert SHIPPED.read_text(encoding="utf-8") == layout_json(), (
        "regenerate: python -m stairbot.recording.layout > docs/foxglove-layout.json")


def paths(node: Any) -> Iterator[str]:
    """Every topic or message path the layout names."""
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("value", "topicPath", "topicToRender") and isinstance(value, str):
                yield value
            elif key == "topics" and isinstance(value, dict):
                yield from value
            else:
                yield from paths(value)
    elif isinstance(node, list):
        for item in node:
            yield from paths(item)


def has_field(schema: dict[str, Any], fields: list[str]) -> bool:
    for name in fields:
        options = schema.get("oneOf", [schema])
        found = [o["properties"][name] for o in options if name in o.get("properties", {})]
        if not found:
            return False
        schema = found[0]
    return True


def test_every_path_in_the_layout_is_recorded() -> None:
    named = list(paths(json.loads(SHIPPED.read_text(encoding="utf-8"))))
    assert len(named) > 10
    for path in named:
        topic, _, rest = path.partition(".")
        fields = rest.split(".") if rest else []
        if topic in JSON_SCHEMAS:
            assert has_field(JSON_SCHEMAS[topic], fields), path
        elif topic in LOG_TOPICS:
            assert fields == [] or (len(fields) == 1 and fields[0] in LOG_FIELDS), path
        else:
            assert topic == topics.SCENE and not fields, path
    assert has_field(topics.SENSORS_SCHEMA, ["imu", "pitch_deg"])
    assert not has_field(topics.SENSORS_SCHEMA, ["SFR", "nonsense"])  # the check can fail
