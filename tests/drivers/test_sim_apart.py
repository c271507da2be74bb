"""The real driver path knows nothing of the simulation: the lockstep clock,
StepTo, GetTruth and falls are ``stairbot.fakes``'s (docs/protocol.md calls
them the motor board's simulation-only messages).  The codec still knows
their codes, so one wire serves real and fake boards."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from importlib import resources

import pytest

REAL_PATH = ("board_robot", "link", "serial_link", "can_link", "serial_robot", "can_robot",
             "health", "records", "codes", "units")
SIM_ONLY = {"StepTo", "StepDone", "GetTruth", "Truth", "RobotFellError", "LockstepClock",
            "sim_messages", "step_to", "truth"}


def names_in(module: str) -> set[str]:
    source = resources.files("stairbot.drivers").joinpath(f"{module}.py").read_text()
    out: set[str] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Name):
            out.add(node.id)
        elif isinstance(node, ast.Attribute):
            out.add(node.attr)
        elif isinstance(node, ast.ImportFrom):
            out.update(a.name for a in node.names)
            out.update((node.module or "").split("."))
        elif isinstance(node, ast.FunctionDef | ast.ClassDef):
            out.add(node.name)
    return out


@pytest.mark.parametrize("module", REAL_PATH)
def test_a_real_driver_module_names_nothing_of_the_simulation(module: str) -> None:
    assert names_in(module) & SIM_ONLY == set()


def test_opening_real_boards_imports_nothing_of_the_fakes() -> None:
    probe = ("import json, sys\n"
             "import stairbot.drivers.serial_robot, stairbot.drivers.can_robot\n"
             "print(json.dumps(sorted(m for m in sys.modules if m.startswith('stairbot.fakes'))))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True)
    assert json.loads(out.stdout) == []
