"""The compiled build (stairbot/compiled.py, setup.py): a compiled module
runs only while its source is what it was compiled from, and a compiled run
ends as a pure-Python one does, reading for reading."""

from __future__ import annotations

import importlib.machinery
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from stairbot import compiled

MODULE = "stairbot.fakes.beams"


def tree(tmp_path: Path, *, built: bool = True, manifest: object = "match") -> Path:
    """A checkout with one module, maybe its extension, maybe a manifest."""
    source = compiled.source_of(MODULE, tmp_path)
    source.parent.mkdir(parents=True)
    source.write_text("X = 1\n", "utf-8")
    if built:
        source.with_suffix(importlib.machinery.EXTENSION_SUFFIXES[0]).write_bytes(b"")
    path = tmp_path / "stairbot" / compiled.MANIFEST
    if manifest == "match":
        path.write_text(json.dumps({"modules": {MODULE: compiled.digest(source)}}), "utf-8")
    elif isinstance(manifest, str):
        path.write_text(manifest, "utf-8")
    return tmp_path


def test_a_build_whose_sources_are_unchanged_runs_compiled(tmp_path: Path) -> None:
    assert compiled.decide(tree(tmp_path)) == (True, None)


def test_an_edited_source_runs_every_module_as_python_and_says_so(tmp_path: Path) -> None:
    root = tree(tmp_path)
    compiled.source_of(MODULE, root).write_text("X = 2\n", "utf-8")
    run, why = compiled.decide(root)
    assert not run
    assert why == "1 of 1 compiled modules are older than their source (beams)"


def test_a_missing_extension_runs_as_python(tmp_path: Path) -> None:
    run, why = compiled.decide(tree(tmp_path, built=False))
    assert not run and why is not None and "(beams)" in why


def test_extensions_without_a_manifest_are_not_run_and_nothing_is_said(tmp_path: Path) -> None:
    """A pure-Python build over a compiled one: setup.py removed the manifest."""
    assert compiled.decide(tree(tmp_path, manifest=None)) == (False, None)


def test_stairbot_pure_runs_python_without_a_word(tmp_path: Path) -> None:
    assert compiled.decide(tree(tmp_path), pure="1") == (False, None)
    assert compiled.decide(tree(tmp_path / "b"), pure="0") == (True, None)


@pytest.mark.parametrize("text", ["{not json", "[]", '{"modules": 3}'])
def test_an_unreadable_manifest_runs_as_python_and_says_so(tmp_path: Path, text: str) -> None:
    run, why = compiled.decide(tree(tmp_path, manifest=text))
    assert not run and why is not None and why.endswith("compiled.json cannot be read")


def test_the_listed_modules_load_from_source_when_not_compiled() -> None:
    code = ("import stairbot.compiled as c, importlib; "
            "print(all(importlib.import_module(m).__file__.endswith('.py') "
            "for m in c.MODULES), c.running_compiled())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**os.environ, compiled.PURE_ENV: "1"}, check=True)
    assert out.stdout.split() == ["True", "False"], out.stderr
    assert out.stderr == ""


def run_json(pure: str, scenario: str) -> dict[str, object]:
    out = subprocess.run(
        [sys.executable, "-m", "stairbot", "run", "--scenario", scenario, "--json"],
        capture_output=True, text=True, env={**os.environ, compiled.PURE_ENV: pure})
    assert out.returncode in (0, 1), out.stderr
    result = json.loads(out.stdout)
    for timing in ("wall_time_s", "realtime_factor"):
        result.pop(timing, None)
    return result


@pytest.mark.skipif(not compiled.running_compiled(),
                    reason="a pure-Python build (STAIRBOT_COMPILE=1 bash scripts/setup compiles)")
@pytest.mark.parametrize("scenario", ["default", "sensor_error_mid_run", "landing_left"])
def test_a_compiled_run_ends_as_the_pure_python_run(scenario: str) -> None:
    assert run_json("0", scenario) == run_json("1", scenario)
