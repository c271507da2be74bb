"""``stairbot console --scenario``: the console opens on the robot the
scenario names unless --config gives another (noted on stderr)."""

from __future__ import annotations

from typing import Any

import pytest

import stairbot.console.app as console_app
from stairbot.console.cli import main


class _App:
    return_code = 0

    def run(self) -> None:
        pass


@pytest.fixture
def opened(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The configs the console's screen would open on (the screen is not opened)."""
    configs: list[Any] = []

    def build_app(config: Any, **_kw: Any) -> _App:
        configs.append(config)
        return _App()

    monkeypatch.setattr(console_app, "build_app", build_app)
    return configs


def test_the_console_uses_the_scenarios_robot(opened: list[Any],
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--scenario", "landing_left"]) == 0
    assert [c.source for c in opened] == ["<robot landings>"]
    assert capsys.readouterr().err == ""


def test_config_overrides_the_scenarios_robot_with_a_note(
        opened: list[Any], capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--scenario", "landing_left", "--config", "ideal"]) == 0
    assert [c.source for c in opened] == ["<robot ideal>"]
    assert capsys.readouterr().err == (
        "stairbot console: note: --config ideal overrides the robot landing_left is "
        "written for (landings): its [expect] may not hold\n")
