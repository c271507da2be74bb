"""The ``stairbot`` commands that show inputs: ``config show``, ``scenario
check``, ``scenario list`` (the parser is in :mod:`stairbot.cli.command`)."""

from __future__ import annotations

import argparse
import json
import sys

from stairbot.cli.common import EXIT_INPUT, EXIT_OK, PROG
from stairbot.control.algorithm import limits
from stairbot.control.robot_config import load_config
from stairbot.errors import InputError
from stairbot.inputs.scenario import Scenario, load_scenario, shipped_scenarios
from stairbot.text import printable

# -- config show ---------------------------------------------------------------------

_DERIVED_UNITS = {"_m_s": "m/s", "_m": "m", "TURNS": "turns", "turns": "turns"}


def _unit(name: str) -> str:
    for suffix, unit in _DERIVED_UNITS.items():
        if name.endswith(suffix) or suffix in name:
            return unit
    return "m"


def cmd_config_show(args: argparse.Namespace) -> int:
    """``stairbot config show``: the resolved config and its derived values."""
    cfg = load_config(args.config)
    data = limits.config_dict(cfg)
    if args.json:
        print(json.dumps(data, indent=2, sort_keys=True))
        return EXIT_OK
    print(f"# robot config from {printable(data['source'])}")
    for section in ("geometry", "masses", "motors", "sensors", "algorithm", "safety"):
        print(f"\n[{section}]")
        for key, value in data[section].items():
            if value is None:  # TOML has no null: a key left out takes its default
                print(f"# {key}: not set")
            else:
                print(f"{key} = {json.dumps(value)}")
    print("\n[derived]  # computed from the values above, not read from the file")
    width = max(len(k) for k in data["derived"])
    for key, value in data["derived"].items():
        print(f"{key:<{width}} = {value:<10g} # {_unit(key)}")
    refusal = limits.narrow_steps_refusal(cfg)
    if refusal is not None:
        print(f"# narrow_steps refused: {refusal}: min_tread_m stays LENGTH_OF_A_ROBOT + "
              "SAFE_LENGTH")
    return EXIT_OK


# -- scenarios ---------------------------------------------------------------------


def _describe(s: Scenario) -> str:
    stairs = (f"{len(s.steps)} steps, top {s.top}" if s.steps else "open floor")
    exp = s.expect
    want = "completed" if exp is None else ", ".join(
        f"{k}={v}" for k, v in (
            ("outcome", exp.outcome), ("ascent_end", exp.ascent_end),
            ("steps_climbed", exp.steps_climbed), ("steps_descended", exp.steps_descended),
            ("pauses", exp.pauses)) if v is not None)
    robot = f"; robot {printable(s.robot)}" if s.robot is not None else ""
    return f"{stairs}; {len(s.faults)} fault(s){robot}; expects {want}"


def cmd_scenario_check(args: argparse.Namespace) -> int:
    """``stairbot scenario check``: validate each file; exit 2 if any is invalid."""
    bad = 0
    for name in args.files:
        try:
            s = load_scenario(name)
        except InputError as exc:
            print(f"{PROG}: error: {exc}", file=sys.stderr)
            bad += 1
            continue
        print(f"ok  {printable(name)}: {_describe(s)}")
    return EXIT_INPUT if bad else EXIT_OK


def cmd_scenario_list(_args: argparse.Namespace) -> int:
    """``stairbot scenario list``: the shipped scenarios with their descriptions."""
    names = shipped_scenarios()
    width = max((len(n) for n in names), default=0)
    for name in names:
        s = load_scenario(name)
        print(printable(f"{name:<{width}}  {s.description}"))
    return EXIT_OK
