"""The package lists each module once (no module reachable under two names),
and the core (every module but the drivers, fakes and console subpackages)
imports nothing of textual, pymunk, serial or can."""

from __future__ import annotations

import json
import pkgutil
import subprocess
import sys

import stairbot

FORBIDDEN = ("textual", "pymunk", "serial", "can")
SUBPACKAGES = {"drivers", "fakes", "console"}

PROBE = """
import importlib, json, sys
names = json.loads(sys.argv[1])
for name in names:
    importlib.import_module(name)
bad = sorted(m for m in sys.modules if m.split(".")[0] in {forbidden})
print(json.dumps(bad))
"""


def all_modules() -> list[str]:
    return [m.name for m in pkgutil.walk_packages(stairbot.__path__, "stairbot.")]


def core_modules() -> list[str]:
    return sorted(
        name for name in all_modules()
        if name.split(".")[1] not in SUBPACKAGES and name != "stairbot.__main__"
    )


def test_every_module_is_listed_once() -> None:
    names = all_modules()
    assert len(names) == len(set(names))
    assert not any(name.startswith("stairbot.stairbot") for name in names)
    for expected in ("stairbot.control.algorithm.controller", "stairbot.drivers.serial_robot",
                     "stairbot.fakes.sim", "stairbot.console.app"):
        assert expected in names


def test_the_core_modules_are_found() -> None:
    names = core_modules()
    for expected in ("stairbot.inputs.config", "stairbot.inputs.scenario", "stairbot.hardware",
                     "stairbot.events", "stairbot.cli.command",
                     "stairbot.control.algorithm.controller"):
        assert expected in names


def test_core_imports_no_textual_pymunk_serial_or_can() -> None:
    names = core_modules()
    probe = PROBE.replace("{forbidden}", repr(set(FORBIDDEN)))
    out = subprocess.run([sys.executable, "-c", probe, json.dumps(names)],
                         capture_output=True, text=True, check=True)
    assert json.loads(out.stdout) == [], f"core modules {names} pulled in {out.stdout}"


def test_the_probe_would_see_a_forbidden_import() -> None:
    probe = PROBE.replace("{forbidden}", repr(set(FORBIDDEN)))
    out = subprocess.run([sys.executable, "-c", probe, json.dumps(["serial"])],
                         capture_output=True, text=True, check=True)
    assert "serial" in json.loads(out.stdout)
