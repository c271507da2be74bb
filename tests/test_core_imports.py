"""The core (every module of the ``stairbot`` package itself, not its drivers,
fakes and console subpackages) imports nothing of textual, pymunk, serial or can."""

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


def core_modules() -> list[str]:
    return sorted(
        f"stairbot.{m.name}" for m in pkgutil.iter_modules(stairbot.__path__)
        if m.name not in SUBPACKAGES and m.name != "__main__"
    )


def test_the_core_modules_are_found() -> None:
    names = core_modules()
    for expected in ("stairbot.config", "stairbot.scenario", "stairbot.hardware",
                     "stairbot.events", "stairbot.cli"):
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
