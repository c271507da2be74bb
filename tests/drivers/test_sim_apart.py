"""The real driver path knows nothing of the simulation: the lockstep clock,
StepTo, GetTruth and falls are ``stairbot.fakes``'s (docs/protocol.md calls
them the motor board's simulation-only messages).  A host process that never
imports the fakes does not know those messages at all -- not in the codec,
not on the CAN wire; importing the fakes (as ``open_robot`` does for a
lockstep URL) adds them, so one wire still serves real and fake boards."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from importlib import resources

import pytest

REAL_PATH = ("board_robot", "board_replies", "board_session", "estop", "handshake", "keepalive",
             "link", "link_loss", "request_link", "serial_link", "serial_wire", "can_link",
             "can_request", "can_wire", "serial_robot", "can_robot", "frame_log", "health",
             "messages", "records", "codes", "units", "telemetry")
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


# A host process: every driver module, the URL dispatcher and the run loop,
# never the fakes.  What does it know of the simulation's messages?
HOST_PROBE = """
import json, pkgutil, sys, importlib
import stairbot.drivers
for info in pkgutil.iter_modules(stairbot.drivers.__path__):
    importlib.import_module(f"stairbot.drivers.{info.name}")
import stairbot.run.robots, stairbot.run.runner
from stairbot.drivers import messages as m
from stairbot.drivers.can_wire import wire
from stairbot.drivers.serial_wire import Frame, decode_frame, encode_frame
step_to = b"\\x20\\x4e\\x00\\x00"
try:
    m.decode(0x7E, step_to)
    codec = "known"
except m.CodecError as exc:
    codec = str(exc)
try:
    wire().decode(0x0F1 << 18 | 0x15A << 8 | 0x10, step_to)
    can = "known"
except m.CodecError as exc:
    can = str(exc)
print(json.dumps({
    "fakes": sorted(n for n in sys.modules if n.startswith("stairbot.fakes")),
    "types": sorted(m.MESSAGES), "names": sorted(c.__name__ for c in m.MESSAGES.values()),
    "frames": sorted(f.name for f in wire().db.messages), "dbcs": len(m.registered_dbcs()),
    "codec": codec, "can": can}))
"""


def _probe(first: str = "") -> dict[str, object]:
    out = subprocess.run([sys.executable, "-c", first + HOST_PROBE], capture_output=True,
                         text=True, check=True)
    result: dict[str, object] = json.loads(out.stdout)
    return result


def test_a_host_that_never_imports_the_fakes_does_not_know_the_simulations_messages() -> None:
    host = _probe()
    assert host["fakes"] == []
    names, frames = set(host["names"]), set(host["frames"])  # type: ignore[call-overload]
    assert names & SIM_ONLY == set()
    assert not {0x7D, 0x7E, 0xFD, 0xFE} & set(host["types"])  # type: ignore[call-overload]
    assert not any(f.split("_")[0] in SIM_ONLY for f in frames)
    assert host["dbcs"] == 0
    assert host["codec"] == "unknown message type 0x7E"
    assert str(host["can"]).startswith("unknown CAN id 0x03C55A10")


def test_the_fakes_lockstep_robot_brings_the_simulations_messages_with_it() -> None:
    # what open_robot imports before it hands a lockstep URL to its driver
    host = _probe("import stairbot.fakes.lockstep\n")
    assert {"StepTo", "StepDone", "GetTruth", "Truth"} <= set(host["names"])  # type: ignore[call-overload]
    assert {"StepTo_Motor", "GetTruth_Motor", "StepDone_Motor",
            "Truth_Motor"} <= set(host["frames"])  # type: ignore[call-overload]
    assert host["codec"] == host["can"] == "known"
