"""unused_path: a record never overwrites a file already on disk."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from stairbot.run import paths
from stairbot.run.paths import unused_path


def test_a_free_name_is_kept(tmp_path: Path) -> None:
    assert unused_path(str(tmp_path / "events.jsonl")) == str(tmp_path / "events.jsonl")


def test_a_taken_name_gets_the_first_free_number(tmp_path: Path) -> None:
    (tmp_path / "events.jsonl").write_text("old\n")
    assert unused_path(str(tmp_path / "events.jsonl")) == str(tmp_path / "events-1.jsonl")
    (tmp_path / "events-1.jsonl").write_text("older\n")
    (tmp_path / "events-3.jsonl").write_text("\n")
    assert unused_path(str(tmp_path / "events.jsonl")) == str(tmp_path / "events-2.jsonl")
    (tmp_path / "run").write_text("no suffix\n")
    assert unused_path(str(tmp_path / "run")) == str(tmp_path / "run-1")


def test_what_is_not_a_regular_file_keeps_its_name(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    for target in (str(fifo), os.devnull, str(tmp_path)):
        assert unused_path(target) == target


def test_every_name_taken_is_an_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(paths, "MAX_TRIES", 3)
    for name in ("e.jsonl", "e-1.jsonl", "e-2.jsonl"):
        (tmp_path / name).write_text("\n")
    with pytest.raises(FileExistsError, match="e-1.jsonl to e-2.jsonl exist too"):
        unused_path(str(tmp_path / "e.jsonl"))
