"""Chains of ``extends``: a loop is refused naming the files in it, a chain
deeper than MAX_EXTENDS is refused as too deep (not as a loop), and one file
is one link however it is spelt."""

from __future__ import annotations

from pathlib import Path

import pytest

from stairbot.cli import main
from stairbot.control.robot_config import load_config
from stairbot.errors import ConfigError
from stairbot.inputs.config import MAX_EXTENDS


def chain(folder: Path, files: int, last: str = "reference") -> Path:
    """c000.toml extends c001.toml ... the last extends ``last``; returns c000."""
    for i in range(files):
        base = f"c{i + 1:03d}.toml" if i + 1 < files else last
        (folder / f"c{i:03d}.toml").write_text(
            f'extends = "{base}"\n[algorithm]\nmax_steps = {i + 1}\n', encoding="utf-8")
    return folder / "c000.toml"


def test_a_long_chain_without_a_loop_is_too_deep_not_a_loop(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    first = chain(tmp_path, 300)
    assert main(["config", "show", "--config", str(first)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    deepest = tmp_path / f"c{MAX_EXTENDS:03d}.toml"
    assert err == [f"stairbot: error: {deepest}: extends: 'c{MAX_EXTENDS + 1:03d}.toml': the "
                   f"chain of extends from {first} goes deeper than {MAX_EXTENDS} configs; "
                   f"allowed: a config stands on at most {MAX_EXTENDS} others"]


def test_a_chain_of_max_extends_loads_and_one_more_does_not(tmp_path: Path) -> None:
    # MAX_EXTENDS - 1 files under the first, then the reference robot: MAX_EXTENDS in all
    cfg = load_config(chain(tmp_path, MAX_EXTENDS))
    assert cfg.algorithm.max_steps == 1  # the first file's value wins
    with pytest.raises(ConfigError, match="goes deeper than"):
        load_config(chain(tmp_path, MAX_EXTENDS + 1))


def test_a_loop_names_the_files_in_it(tmp_path: Path) -> None:
    (tmp_path / "top.toml").write_text('extends = "a.toml"\n', encoding="utf-8")
    (tmp_path / "a.toml").write_text('extends = "b.toml"\n', encoding="utf-8")
    (tmp_path / "b.toml").write_text('extends = "./a.toml"\n', encoding="utf-8")
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    with pytest.raises(ConfigError) as err:
        load_config(tmp_path / "top.toml")
    assert str(err.value) == (f"{b}: extends: './a.toml' makes a loop: {a} -> {b} -> "
                              f"{tmp_path / './a.toml'}; allowed: a chain without loops")


def test_files_of_the_same_name_in_other_folders_are_no_loop(tmp_path: Path) -> None:
    (tmp_path / "sub" / "sub").mkdir(parents=True)
    (tmp_path / "robot.toml").write_text('extends = "sub/robot.toml"\n', encoding="utf-8")
    (tmp_path / "sub" / "robot.toml").write_text('extends = "sub/robot.toml"\n',
                                                 encoding="utf-8")
    (tmp_path / "sub" / "sub" / "robot.toml").write_text(
        'extends = "reference"\n[algorithm]\nmax_steps = 2\n', encoding="utf-8")
    assert load_config(tmp_path / "robot.toml").algorithm.max_steps == 2

