"""Robot URL schemes: a third party adds one with an entry point in the
``stairbot.robots`` group, and ``stairbot run --robot`` opens it; a scheme
nobody provides is one line and exit 2."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

TOY_MODULE = '''
from stairbot.fakes.sim import open_sim_robot


def open_toy(url, config, options):
    """A third party's robot: here the simulation, under its own scheme."""
    session = open_sim_robot("sim://", config, options)
    session.url = url
    return session
'''


def stairbot(cwd: Path, *args: str, pythonpath: Path | None = None
             ) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = os.pathsep.join(p for p in (str(pythonpath),
                                                        env.get("PYTHONPATH")) if p)
    # cwd elsewhere: the installed package runs, not the source tree
    return subprocess.run([sys.executable, "-m", "stairbot", *args], capture_output=True,
                          text=True, timeout=120, cwd=cwd, env=env)


@pytest.fixture
def toy_plugin(tmp_path: Path) -> Path:
    """A distribution on the path whose entry point adds the ``toy://`` scheme."""
    site = tmp_path / "site"
    dist = site / "toy_robot-1.0.dist-info"
    dist.mkdir(parents=True)
    (site / "toy_robot.py").write_text(TOY_MODULE)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-robot\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[stairbot.robots]\ntoy = toy_robot:open_toy\n")
    return site


def test_an_entry_point_adds_a_scheme_that_run_opens(tmp_path: Path, toy_plugin: Path) -> None:
    proc = stairbot(tmp_path, "run", "--robot", "toy://", "--json", pythonpath=toy_plugin)
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    assert result["robot"] == "toy://" and result["outcome"] == "completed"
    unknown = stairbot(tmp_path, "run", "--robot", "nope://x", pythonpath=toy_plugin)
    assert unknown.returncode == 2 and "toy://" in unknown.stderr  # listed as allowed


def test_without_the_plugin_the_scheme_is_unknown(tmp_path: Path) -> None:
    proc = stairbot(tmp_path, "run", "--robot", "toy://")
    assert proc.returncode == 2
    (line,) = proc.stderr.strip().splitlines()
    assert "toy://: unknown scheme 'toy'; allowed: can://, serial://, sim://" in line
