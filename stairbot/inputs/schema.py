"""Strict TOML-to-struct conversion with messages a person can act on.

``convert`` turns msgspec's validation errors ("Expected `float` > 0.0 - at
`$.stairs.rise`") into ``InputError`` messages that name the file, the field
(``stairs.rise``), the value found and what is allowed.
"""

from __future__ import annotations

import math
import re
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any, TypeVar

import msgspec
import msgspec.inspect as mi

from stairbot.errors import InputError
from stairbot.files import is_file, read_input, shown

T = TypeVar("T")

_PATH = re.compile(r"^(?P<problem>.*) - at `\$(?P<path>[^`]*)`$", re.S)
_TOKEN = re.compile(r"\.([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]")


def read_text(path: Path, error: type[InputError], what: str = "a TOML file") -> str:
    """A file's text.  Raises ``error`` naming the file when it is no regular
    file, larger than :data:`~stairbot.files.MAX_TOML_BYTES`, cannot be read
    or is not UTF-8 (:func:`stairbot.files.read_input`)."""
    return read_input(path, error, what=what)


def shipped(folder: str) -> list[str]:
    """Names of the TOML files shipped in the package's ``folder``."""
    entries = resources.files("stairbot.inputs").joinpath(folder)
    return sorted(f.name.removesuffix(".toml") for f in entries.iterdir()
                  if f.name.endswith(".toml"))


def read_named(path: str | Path, folder: str, what: str,
               error: type[InputError], also: tuple[str, ...] = ()) -> tuple[str, str]:
    """The text and source name of a file, or of a ``what`` shipped in
    ``folder`` by name (a plain word that is no existing file).  Raises
    ``error`` naming the shipped ones (and ``also``) when it is neither."""
    p = Path(path)
    if isinstance(path, str) and "/" not in path and "\\" not in path \
            and not path.endswith(".toml") and not is_file(p):
        names = shipped(folder)
        if path not in names:
            names = sorted([*names, *also])
            raise error(shown(path), None, f"no such file, nor a shipped {what}; shipped: "
                        + ", ".join(names))
        entry = resources.files("stairbot.inputs").joinpath(folder, f"{path}.toml")
        return entry.read_text("utf-8"), f"<{what} {path}>"
    return read_text(p, error, f"a {what} file"), str(p)


MAX_DEPTH = 16
"""Deepest nesting of tables and lists a TOML input may have (the schemas
need 4)."""


def load_toml(text: str, source: str, error: type[InputError]) -> dict[str, Any]:
    """Parse TOML text.  Raises ``error`` (an InputError class) when it is not
    TOML, or nests tables and lists deeper than :data:`MAX_DEPTH`."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(source, None, f"not valid TOML: {exc}") from None
    except RecursionError:  # tomllib parses nested arrays and inline tables recursively
        raise error(source, None, f"nested too deeply; allowed: at most {MAX_DEPTH} levels "
                    "of tables and lists") from None
    if _depth(raw) > MAX_DEPTH:
        raise error(source, None, f"nested too deeply; allowed: at most {MAX_DEPTH} levels "
                    "of tables and lists")
    return raw


def _depth(raw: Any) -> int:
    """How deep tables and lists nest in ``raw`` (counted without recursion;
    stops counting past MAX_DEPTH)."""
    deepest = 0
    todo: list[tuple[Any, int]] = [(raw, 1)]
    while todo:
        value, level = todo.pop()
        children = value.values() if isinstance(value, dict) else (
            value if isinstance(value, list) else None)
        if children is None:
            continue
        deepest = max(deepest, level)
        if level > MAX_DEPTH:
            break
        todo.extend((child, level + 1) for child in children)
    return deepest


def convert(raw: dict[str, Any], kind: type[T], source: str, error: type[InputError]) -> T:
    """Convert parsed TOML to the struct ``kind``.  Raises ``error`` whose message
    names ``source``, the dotted field and what the field allows.  TOML's
    ``inf`` and ``nan`` are refused wherever a number goes."""
    try:
        out = msgspec.convert(raw, kind, strict=True)
    except msgspec.ValidationError as exc:
        field, problem = explain(str(exc), raw, kind)
        raise error(source, field, problem) from None
    bad = _non_finite(raw, [])
    if bad is not None:
        value, tokens = bad
        raise error(source, _dotted(tokens) or None,
                    f"{_shown(value)} is not allowed; allowed: "
                    f"{describe(_type_at(kind, tokens))}, finite")
    return out


def _non_finite(raw: Any, tokens: list[str | int]) -> tuple[float, list[str | int]] | None:
    """The first inf or nan in parsed TOML, with where it is."""
    if isinstance(raw, float):
        return None if math.isfinite(raw) else (raw, tokens)
    items = raw.items() if isinstance(raw, dict) else (
        enumerate(raw) if isinstance(raw, list) else ())
    for key, value in items:
        found = _non_finite(value, [*tokens, key])
        if found is not None:
            return found
    return None


def _shown(value: Any) -> str:
    """A value as the TOML file spells it (true, inf, 'text'), or its kind for a
    table or a list."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if value != value else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "a list"
    return repr(value)


def _tokens(path: str) -> list[str | int]:
    return [name if name else int(index) for name, index in _TOKEN.findall(path)]


def _dotted(tokens: list[str | int]) -> str:
    out = ""
    for t in tokens:
        out += f"[{t}]" if isinstance(t, int) else (f".{t}" if out else t)
    return out


def _strip_optional(t: mi.Type) -> mi.Type:
    """``t`` without its ``| None`` and its metadata (a unit): the type that
    bounds its values."""
    t = _bare(t)
    if isinstance(t, mi.UnionType):
        rest = [u for u in t.types if not isinstance(u, mi.NoneType)]
        if len(rest) == 1:
            return _bare(rest[0])
    return t


def _bare(t: mi.Type) -> mi.Type:
    """``t`` without the metadata a ``msgspec.Meta(extra=...)`` wraps it in."""
    return t.type if isinstance(t, mi.Metadata) else t


def describe_at(kind: Any, dotted: str) -> str:
    """What the field ``dotted`` (``"motors.wheel_speed"``) of the struct
    ``kind`` allows, in words (:func:`describe`)."""
    return describe(_type_at(kind, _tokens("." + dotted)))


def unit_at(kind: Any, dotted: str) -> str | None:
    """The unit a field of the struct ``kind`` is given in (``"m"``,
    ``"turns/s"``: its ``msgspec.Meta(extra={"unit": ...})``), None when the
    schema gives none."""
    t = _type_at(kind, _tokens("." + dotted))
    if isinstance(t, mi.UnionType):
        t = next((u for u in t.types if not isinstance(u, mi.NoneType)), None)
    if isinstance(t, mi.Metadata) and t.extra:
        unit = t.extra.get("unit")
        return unit if isinstance(unit, str) else None
    return None


def _type_at(kind: Any, tokens: list[str | int]) -> mi.Type | None:
    t: mi.Type | None = mi.type_info(kind)
    for tok in tokens:
        t = _strip_optional(t) if t is not None else None
        if isinstance(tok, int):
            t = t.item_type if isinstance(t, mi.ListType) else None
        elif isinstance(t, mi.StructType):
            t = next((f.type for f in t.fields if f.encode_name == tok), None)
        else:
            return None
    return t


def _value_at(raw: Any, tokens: list[str | int]) -> Any:
    for tok in tokens:
        try:
            raw = raw[tok]
        except (KeyError, IndexError, TypeError):
            return None
    return raw


def _literals(t: mi.Type) -> list[str]:
    values: list[str] = []
    for u in t.types if isinstance(t, mi.UnionType) else (t,):
        u = _bare(u)
        if isinstance(u, mi.LiteralType):
            values += [str(v) for v in u.values]
    return values


def describe(t: mi.Type | None) -> str:
    """What a field allows, in words: "a number > 0", "one of 'a', 'b'"."""
    if t is None:
        return "see the schema"
    t = _strip_optional(t)
    lits = _literals(t)
    if lits:
        return "one of " + ", ".join(repr(v) for v in lits)
    if isinstance(t, mi.UnionType):
        return " or ".join(describe(u) for u in t.types if not isinstance(u, mi.NoneType))
    if isinstance(t, mi.FloatType | mi.IntType):
        noun = "a number" if isinstance(t, mi.FloatType) else "a whole number"
        bounds = [f"{op} {v:g}" for op, v in
                  ((">", t.gt), (">=", t.ge), ("<", t.lt), ("<=", t.le)) if v is not None]
        return noun + (" " + " and ".join(bounds) if bounds else "")
    if isinstance(t, mi.StrType):
        return "text"
    if isinstance(t, mi.BoolType):
        return "true or false"
    if isinstance(t, mi.ListType):
        return "a list, each " + describe(t.item_type)
    if isinstance(t, mi.StructType):
        return "a table with keys " + ", ".join(f.encode_name for f in t.fields)
    return "see the schema"


def explain(message: str, raw: dict[str, Any], kind: Any) -> tuple[str | None, str]:
    """Turn one msgspec validation message into (dotted field, problem)."""
    m = _PATH.match(message)
    problem, tokens = (m["problem"], _tokens(m["path"])) if m else (message, [])
    unknown = re.match(r"Object contains unknown field `(.*)`", problem)
    if unknown:
        owner = _strip_optional(_type_at(kind, tokens) or mi.AnyType())
        allowed = (", ".join(f.encode_name for f in owner.fields)
                   if isinstance(owner, mi.StructType) else "see the schema")
        return _dotted([*tokens, unknown[1]]), f"unknown key; allowed keys here: {allowed}"
    missing = re.match(r"Object missing required field `(.*)`", problem)
    if missing:
        full = [*tokens, missing[1]]
        return _dotted(full), f"required but missing; allowed: {describe(_type_at(kind, full))}"
    field = _dotted(tokens) or None
    value = _value_at(raw, tokens)
    finite = ", finite" if isinstance(value, float) and not math.isfinite(value) else ""
    return field, (f"{_shown(value)} is not allowed; allowed: "
                   f"{describe(_type_at(kind, tokens))}{finite}")
