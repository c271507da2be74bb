"""A small TOML writer for the documents stairbot writes (scenarios and robot
configs): scalars, tables of scalars, lists, inline tables and arrays of tables.

Floats are written with ``repr`` so that reading the file back gives the very
same number: a case written to disk runs bit for bit as it ran in the sweep.
"""

from __future__ import annotations

import json
import math
import re
from typing import Any

_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(key: str) -> str:
    return key if _BARE.match(key) else json.dumps(key)


def value(v: Any) -> str:
    """One TOML value.  Raises ValueError for what TOML cannot hold (None, inf)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"{v} cannot be written to TOML")
        return repr(v)
    if isinstance(v, str):
        # JSON leaves DEL as it is; TOML wants it escaped, as every control but tab
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, list | tuple):
        return "[" + ", ".join(value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {value(x)}" for k, x in v.items()) + "}"
    raise ValueError(f"{v!r} cannot be written to TOML")


def _is_table_array(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def dumps(doc: dict[str, Any], header: str = "") -> str:
    """A TOML document: top-level scalars, then one ``[table]`` per dict (one
    level deep) and one ``[[array]]`` entry per table in a list of tables."""
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    tables: list[tuple[str, dict[str, Any]]] = []
    arrays: list[tuple[str, list[dict[str, Any]]]] = []
    for k, v in doc.items():
        if isinstance(v, dict):
            tables.append((k, v))
        elif _is_table_array(v) and k != "steps":
            arrays.append((k, v))
        else:
            lines.append(f"{_key(k)} = {value(v)}")
    for name, table in tables:
        lines += ["", f"[{_key(name)}]"]
        lines += [f"{_key(k)} = {value(v)}" for k, v in table.items()]
    for name, items in arrays:
        for item in items:
            lines += ["", f"[[{_key(name)}]]"]
            lines += [f"{_key(k)} = {value(v)}" for k, v in item.items()]
    return "\n".join(lines).lstrip("\n") + "\n"
