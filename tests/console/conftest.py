"""Fixtures of the console tests."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from still_robot import make_still_app

from stairbot.console.app import StairbotConsole


@pytest.fixture
def still_app() -> Callable[..., StairbotConsole]:
    return make_still_app
