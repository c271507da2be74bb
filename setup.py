"""Builds stairbot.  With ``STAIRBOT_COMPILE=1`` it also compiles the
simulation's hot modules (``stairbot/compiled.py``'s MODULES) with mypyc
and writes the manifest the package checks them against on import; without
it (or when the build fails), any manifest an earlier compiled build left
is removed, so extensions left beside the sources are not run
(``stairbot.compiled.guard``).  The metadata is in pyproject.toml."""

from __future__ import annotations

import json
import os
import runpy
from importlib.machinery import EXTENSION_SUFFIXES
from pathlib import Path

from setuptools import setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
compiled = runpy.run_path(str(HERE / "stairbot" / "compiled.py"))
manifest = HERE / "stairbot" / compiled["MANIFEST"]

NEEDS = ("STAIRBOT_COMPILE=1 type-checks the modules against stairbot's installed "
         "dependencies: install stairbot, mypy and setuptools>=68 first, then build "
         "without isolation (pip install --no-build-isolation ...; or: "
         "STAIRBOT_COMPILE=1 bash scripts/setup), with a C compiler on the PATH")


class BuildExt(build_ext):
    """Writes the manifest once the extensions are built, beside them: a
    build that fails leaves none, and its sources run as Python."""

    def run(self) -> None:
        super().run()
        if not self.extensions:
            return
        package = HERE / "stairbot" if self.inplace else Path(self.build_lib) / "stairbot"
        package.mkdir(parents=True, exist_ok=True)
        (package / compiled["MANIFEST"]).write_text(
            json.dumps(compiled["manifest_of"](HERE), indent=1) + "\n", "utf-8")


def remove_extensions() -> None:
    """Removes the extensions an earlier build left in the checkout: a module
    since taken off the list would otherwise go on running compiled."""
    for suffix in EXTENSION_SUFFIXES:
        for path in [*(HERE / "stairbot").rglob(f"*{suffix}"), *HERE.glob(f"*__mypyc{suffix}")]:
            path.unlink()


manifest.unlink(missing_ok=True)  # until this build's extensions are in place
remove_extensions()
ext_modules = []
if os.environ.get("STAIRBOT_COMPILE", "") not in ("", "0"):
    try:
        import msgspec  # noqa: F401 - a dependency: the build is not isolated
        from mypyc.build import mypycify
    except ImportError:
        raise SystemExit(NEEDS) from None
    sources = [compiled["source_of"](m, HERE) for m in compiled["MODULES"]]
    ext_modules = mypycify([str(p.relative_to(HERE)) for p in sources], opt_level="3")

setup(ext_modules=ext_modules, cmdclass={"build_ext": BuildExt})
