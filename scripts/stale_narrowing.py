"""Lists the places where mypy may keep an attribute narrowed across a call
that could change it, so that mypyc compiles in a cast the value no longer
passes (a TypeError compiled, where Python carries on).

mypy narrows an attribute chain (``w.a``, ``self.a``, ``ctx.descent.b``) by
a test (``is None``, ``is not None``, ``isinstance``, ``==``, truthiness), in
the branch the test guards, after a branch that returns, and after an
assignment, and it does not forget that narrowing when a function is
called.  For each narrowing this scan finds the later reads of the same
chain (or a longer one) inside the narrowed region that have a call before
them: in source order, or anywhere in a loop around the read.  Whether that
call can assign the attribute is for a reader to judge: each hit is a
candidate, not a fault.

It over-reports on purpose (it does not know the types, so it treats every
test of a chain as narrowing it, and both branches as narrowed) and it does
not follow properties, aliases of the same object under another name
(``ctx`` and ``t.ctx``) or narrowing across functions.

    python scripts/stale_narrowing.py [FILE...]

Without files, it scans the modules a compiled build compiles
(``stairbot/compiled.py``'s MODULES).  Each hit names the functions that
assign an attribute of the chain's name (but in ``__init__``); a chain no
function assigns is not listed.
"""

from __future__ import annotations

import ast
import runpy
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

Pos = tuple[int, int]
PACKAGE = Path(__file__).resolve().parent.parent / "stairbot"

PURE = frozenset({
    "abs", "all", "any", "bool", "callable", "dict", "divmod", "enumerate", "filter", "float",
    "frozenset", "hasattr", "id", "int", "isinstance", "issubclass", "iter", "len", "list", "map",
    "max", "min", "next", "range", "repr", "reversed", "round", "set", "sorted", "str", "sum",
    "tuple", "type", "zip", "math.atan", "math.atan2", "math.cos", "math.copysign",
    "math.degrees", "math.exp", "math.fabs", "math.floor", "math.ceil", "math.hypot",
    "math.isfinite", "math.isnan", "math.isinf", "math.log", "math.radians", "math.sin",
    "math.sqrt", "math.tan", "math.fsum", "math.asin", "math.acos"})
"""Calls that assign no attribute of the program's objects (builtins, math)."""


def may_assign(call: ast.Call) -> bool:
    """Whether a call could run the program's code (and so assign to an
    attribute): not a builtin or a function of math."""
    return ast.unparse(call.func) not in PURE


def chain(node: ast.AST) -> str | None:
    """``a.b.c`` (or ``a.b["k"]``) as text when ``node`` is an attribute
    chain on a name, else None."""
    parts = []
    while True:
        if isinstance(node, ast.Attribute):
            parts.append("." + node.attr)
            node = node.value
        elif isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant):
            parts.append(f"[{node.slice.value!r}]")
            node = node.value
        elif isinstance(node, ast.Name):
            return node.id + "".join(reversed(parts)) if parts else None
        else:
            return None


def tested(test: ast.expr) -> Iterator[tuple[str, ast.AST]]:
    """The chains a condition narrows, each with the node that narrows it."""
    if isinstance(test, ast.BoolOp):
        for value in test.values:
            yield from tested(value)
    elif isinstance(test, ast.UnaryOp) and isinstance(test.op, ast.Not):
        yield from tested(test.operand)
    elif isinstance(test, ast.Compare):
        for operand in (test.left, *test.comparators):
            name = chain(operand)
            if name is not None:
                yield name, test
    elif isinstance(test, ast.Call) and isinstance(test.func, ast.Name) \
            and test.func.id in ("isinstance", "callable") and test.args:
        name = chain(test.args[0])
        if name is not None:
            yield name, test
    elif isinstance(test, ast.NamedExpr):
        yield from tested(test.value)
    else:
        name = chain(test)
        if name is not None:
            yield name, test


def ends(body: list[ast.stmt]) -> bool:
    """Whether a block never falls through to the statement after it."""
    if not body:
        return False
    last = body[-1]
    if isinstance(last, (ast.Return, ast.Raise, ast.Continue, ast.Break)):
        return True
    if isinstance(last, ast.If):
        return ends(last.body) and ends(last.orelse)
    return False


@dataclass
class Narrowing:
    name: str
    line: int
    start: Pos          # where the narrowing takes hold
    region: list[ast.AST]  # the subtrees in which it holds


def start(node: ast.AST) -> Pos:
    return node.lineno, node.col_offset  # type: ignore[attr-defined]


def end(node: ast.AST) -> Pos:
    return node.end_lineno, node.end_col_offset  # type: ignore[attr-defined]


def assigned(body: list[ast.stmt]) -> set[str]:
    """The chains a block assigns in its own statements (not nested ones)."""
    out = set()
    for stmt in body:
        targets = stmt.targets if isinstance(stmt, ast.Assign) else \
            [stmt.target] if isinstance(stmt, ast.AnnAssign) else []
        for target in targets:
            for t in target.elts if isinstance(target, ast.Tuple) else [target]:
                name = chain(t)
                if name is not None:
                    out.add(name)
    return out


def narrowings(body: list[ast.stmt], after: list[ast.AST] | None = None) -> Iterator[Narrowing]:
    """Every narrowing in a block of one function (not the functions it
    defines), with its region.  ``after``: the statements after the ``if``
    the block is a branch of (a chain a branch assigns may stay narrowed
    there)."""
    for i, stmt in enumerate(body):
        rest: list[ast.AST] = list(body[i + 1:])
        if isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            continue
        if isinstance(stmt, (ast.If, ast.While)):
            region: list[ast.AST] = [stmt]
            branch_sets = assigned(stmt.body) | assigned(stmt.orelse)
            for name, node in tested(stmt.test):
                # after an ``if``: narrowed when a branch returns, or assigns
                # the chain (``if w.a is None: w.a = ...``)
                if isinstance(stmt, ast.If) and (ends(stmt.body) or ends(stmt.orelse)
                                                 or name in branch_sets):
                    yield Narrowing(name, node.lineno, end(node), region + rest)
                else:
                    yield Narrowing(name, node.lineno, end(node), region)
        elif isinstance(stmt, ast.Assert):
            for name, node in tested(stmt.test):
                yield Narrowing(name, node.lineno, end(node), [stmt, *rest])
        elif isinstance(stmt, (ast.Assign, ast.AnnAssign)):
            for name in assigned([stmt]):
                yield Narrowing(name, stmt.lineno, end(stmt), rest + (after or []))
        # narrowings inside expressions: ``a and b``, ``x if c else y``
        for node in walk(stmt):
            if isinstance(node, ast.BoolOp):
                for value in node.values[:-1]:
                    for name, n in tested(value):
                        yield Narrowing(name, n.lineno, end(n), [node])
            elif isinstance(node, ast.IfExp):
                for name, n in tested(node.test):
                    yield Narrowing(name, n.lineno, end(n), [node])
            elif isinstance(node, ast.comprehension):
                for cond in node.ifs:
                    for name, n in tested(cond):
                        yield Narrowing(name, n.lineno, end(n), [node])
        for field in ("body", "orelse", "finalbody", "handlers"):
            inner = getattr(stmt, field, None)
            if isinstance(inner, list):
                blocks = [h.body for h in inner] if field == "handlers" else [inner]
                for block in blocks:
                    yield from narrowings(block, rest if isinstance(stmt, ast.If) else None)


def walk(node: ast.AST) -> Iterator[ast.AST]:
    """``ast.walk`` in one function: not into the functions, lambdas and
    classes it defines."""
    yield node
    for child in ast.iter_child_nodes(node):
        if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue
        yield from walk(child)


def loops_around(region: list[ast.AST], target: ast.AST) -> list[ast.AST]:
    """The loops within ``region`` that contain ``target``."""
    out = []
    for root in region:
        for node in walk(root):
            if isinstance(node, (ast.For, ast.While, ast.comprehension)) \
                    and any(n is target for n in walk(node)):
                out.append(node)
    return out


def stale_reads(fn: ast.FunctionDef | ast.AsyncFunctionDef
                ) -> Iterator[tuple[Narrowing, int, ast.Call]]:
    """(narrowing, line of the read, first call before it) for each read of a
    narrowed chain after a call in its region.  Source order stands for
    the order of running: a call in a branch that returned before the read
    counts too, and so does an assignment that narrows the chain again
    between the call and the read (both over-report)."""
    for n in narrowings(fn.body):
        nodes = [x for root in n.region for x in walk(root)]
        calls = [c for c in nodes if isinstance(c, ast.Call) and may_assign(c)
                 and start(c) >= n.start]
        for node in nodes:
            if not isinstance(node, (ast.Attribute, ast.Subscript)) \
                    or not isinstance(getattr(node, "ctx", None), ast.Load):
                continue
            name = chain(node)
            if name != n.name or start(node) < n.start:
                continue
            # a longer chain (``w.a.b``) counts as a read of ``w.a`` through its inner node
            before = [c for c in calls if end(c) <= start(node)]
            for loop in loops_around(n.region, node):
                before += [c for c in walk(loop) if isinstance(c, ast.Call) and may_assign(c)
                           and start(c) >= n.start and not any(x is node for x in walk(c))]
            if before:
                yield n, node.lineno, before[0]


MAKERS = frozenset({"__init__", "__post_init__", "__new__"})
"""Methods that assign attributes of a new object only."""


def assigners(package: Path) -> dict[str, set[str]]:
    """For each attribute name, the functions under ``package`` that assign
    an attribute of that name (``x.name = ...``, ``x.name += ...``), but in
    :data:`MAKERS`: ``path:function``."""
    out: dict[str, set[str]] = {}
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text("utf-8"), str(path))
        for fn in ast.walk(tree):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)) or fn.name in MAKERS:
                continue
            for node in ast.walk(fn):
                if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
                    out.setdefault(node.attr, set()).add(f"{path}:{fn.name}")
    return out


def attributes(name: str) -> list[str]:
    """The attribute names of a chain: ``ctx.descent.edge_wheel`` ->
    ``descent``, ``edge_wheel``."""
    return [part for part in name.replace("[", ".").split(".")[1:] if part.isidentifier()]


def scan(path: Path, stores: dict[str, set[str]]) -> Iterator[str]:
    tree = ast.parse(path.read_text("utf-8"), str(path))
    seen = set()
    for fn in ast.walk(tree):
        if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for n, line, call in stale_reads(fn):
            key = (fn.name, n.name, line)
            if key in seen:
                continue
            seen.add(key)
            by = sorted({f for a in attributes(n.name) for f in stores.get(a, ())})
            if not by:
                continue  # no function assigns it (or any object on its way)
            yield (f"{path}:{line}: {fn.name}: {n.name} (narrowed at {n.line}) "
                   f"read after {ast.unparse(call.func)}() at {call.lineno}; "
                   f"assigned in {', '.join(f.rsplit('/', 1)[-1] for f in by)}")


def compiled_sources() -> list[Path]:
    compiled = runpy.run_path(str(PACKAGE / "compiled.py"))
    return [compiled["source_of"](m, PACKAGE.parent) for m in compiled["MODULES"]]


def main(argv: list[str]) -> int:
    stores = assigners(PACKAGE)
    if not argv:
        argv = [str(p.relative_to(PACKAGE.parent)) for p in compiled_sources()]
    found = [hit for arg in argv for hit in scan(Path(arg), stores)]
    print("\n".join(found))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
