"""Fixtures of the console tests."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from still_robot import make_still_app

from stairbot.console.app import StairbotConsole


@pytest.fixture
def still_app() -> Callable[..., StairbotConsole]:
    return make_still_app


@pytest.fixture(autouse=True)
def own_state_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every console remembers the URLs it opened under $XDG_STATE_HOME
    (console/recent.py): a test's go to its own directory, not the user's."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
