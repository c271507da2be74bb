"""The hot modules of a simulated run (the simulation, perception and the
controller), compiled by mypyc when stairbot is built with
``STAIRBOT_COMPILE=1`` (setup.py), and the check that keeps a compiled
module from running code older than its source.

A compiled build writes :data:`MANIFEST` beside this file: each module of
:data:`MODULES` and the SHA-256 of the source it was compiled from.  On
import, :func:`guard` compares those with the sources beside them.  When
any differs (the checkout was edited or moved on since the build), an
extension is missing, there is no manifest (a pure-Python build, perhaps
over a compiled one), or ``STAIRBOT_PURE=1`` asks for it, every module of
the list is loaded from its ``.py`` instead: mypyc calls across the
modules of one build directly, so one stale module means none of them can
be trusted.  A stale build is said on a terminal's stderr, with the
command that rebuilds it (not where stderr is read by a program: a test,
a pipe, a log).

The compiled and the pure-Python modules run the same floating-point
operations in the same order: a sweep gives the same verdicts, outcomes and
robot times either way (docs/speed.md, "Compiled").
"""

from __future__ import annotations

import hashlib
import importlib.abc
import importlib.machinery
import importlib.util
import json
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from types import ModuleType

_ROOT = Path(__file__).resolve().parent.parent


def package_modules(package: str, but: Sequence[str] = (), root: Path = _ROOT) -> tuple[str, ...]:
    """Every module of ``package`` (its ``.py`` files but ``__init__``),
    except those named in ``but``, in name order."""
    folder = root.joinpath(*package.split("."))
    return tuple(f"{package}.{p.stem}" for p in sorted(folder.glob("*.py"))
                 if p.stem != "__init__" and p.stem not in but)


MODULES = (
    # the controller, every phase and the evidence it keeps, but: phase.py,
    # whose generic frozen dataclass (PhaseDef) mypyc compiles but cannot make
    # at run time; and the context's dataclasses (context, work, families,
    # limp), which a saved context is restored into by their type hints, and
    # a compiled dataclass's hints lose their unions (``float | None`` reads
    # as ``type``)
    *package_modules("stairbot.control.algorithm",
                     but=("phase", "context", "work", "families", "limp")),
    "stairbot.control.perception",
    "stairbot.control.robot_config",
    "stairbot.control.stuck",
    "stairbot.control.supervisor",
    "stairbot.control.tilt",
    "stairbot.control.timeline",
    "stairbot.control.tolerances",
    "stairbot.fakes.beams",
    "stairbot.fakes.fall_watch",
    "stairbot.fakes.landing",
    "stairbot.fakes.margin_watch",
    "stairbot.fakes.plan",
    "stairbot.fakes.robot_bodies",
    "stairbot.fakes.sensor_model",
    "stairbot.fakes.sensors",
    "stairbot.fakes.sim",
    "stairbot.fakes.sim_sensors",
    "stairbot.fakes.stairs",
    "stairbot.fakes.world",
    "stairbot.readings",
)
"""The modules a compiled build compiles: the simulation's sensors, world
and robot; the perception and supervision every tick runs; the controller
and its phases; and the making of the readings they pass each other."""

MANIFEST = "compiled.json"
PURE_ENV = "STAIRBOT_PURE"
REBUILD = "STAIRBOT_COMPILE=1 bash scripts/setup"


def source_of(module: str, root: Path = _ROOT) -> Path:
    return root.joinpath(*module.split(".")).with_suffix(".py")


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def manifest_of(root: Path = _ROOT) -> dict[str, dict[str, str]]:
    """What a compiled build writes to :data:`MANIFEST` (setup.py): each
    module of :data:`MODULES` and its source's SHA-256."""
    return {"modules": {m: digest(source_of(m, root)) for m in MODULES}}


def built(module: str, root: Path = _ROOT) -> bool:
    """Whether the module's compiled extension is beside its source."""
    source = source_of(module, root)
    return any(source.with_suffix(suffix).is_file()
               for suffix in importlib.machinery.EXTENSION_SUFFIXES)


def stale(manifest: dict[str, str], root: Path = _ROOT) -> list[str]:
    """The modules of ``manifest`` whose source is not what was compiled,
    or whose source or extension is gone."""
    out = []
    for module, sha in manifest.items():
        path = source_of(module, root)
        if not path.is_file() or digest(path) != sha or not built(module, root):
            out.append(module)
    return out


class _SourceFirst(importlib.abc.MetaPathFinder):
    """Finds each listed module's ``.py`` before the import system finds its
    compiled extension."""

    def __init__(self, modules: Sequence[str], root: Path) -> None:
        self.modules = {m: source_of(m, root) for m in modules}

    def find_spec(self, fullname: str, path: Sequence[str] | None,
                  target: ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        source = self.modules.get(fullname)
        if source is None or not source.is_file():
            return None
        return importlib.util.spec_from_file_location(fullname, source)


_state = {"compiled": False}


def decide(root: Path = _ROOT, pure: str = "") -> tuple[bool, str | None]:
    """Whether the compiled modules under ``root`` may run, and what to say
    when a compiled build cannot (None: nothing).  ``pure``: the value of
    ``STAIRBOT_PURE``."""
    path = root / "stairbot" / MANIFEST
    if not path.is_file():
        return False, None  # a pure-Python build (extensions left by another are not run)
    if pure not in ("", "0"):
        return False, None
    try:
        manifest = json.loads(path.read_text("utf-8"))["modules"]
        behind = stale(manifest, root)
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return False, f"{path} cannot be read"
    if not behind:
        return True, None
    names = ", ".join(m.rsplit(".", 1)[-1] for m in behind[:3])
    more = ", ..." if len(behind) > 3 else ""
    return False, (f"{len(behind)} of {len(manifest)} compiled modules are older than "
                   f"their source ({names}{more})")


def guard(root: Path = _ROOT) -> None:
    """Decide, once, whether the compiled modules run (see the module's
    docstring); called by ``stairbot/__init__.py`` before any of them is
    imported."""
    run, why = decide(root, pure=os.environ.get(PURE_ENV, ""))
    if why is not None and sys.stderr is not None and sys.stderr.isatty():
        print(f"stairbot: {why}; running them as Python (rebuild: {REBUILD})",
              file=sys.stderr)
    _state["compiled"] = run
    if not run:
        sys.meta_path.insert(0, _SourceFirst(MODULES, root))


def running_compiled() -> bool:
    """Whether the compiled modules are the ones running."""
    return _state["compiled"]
