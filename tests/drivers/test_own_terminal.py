"""A serial URL naming the terminal stairbot itself runs in is refused
before it is opened: opened as a robot's port, it would set the terminal's
modes, read the operator's keys (the emergency stop's among them) and write
binary frames onto the screen."""

from __future__ import annotations

import os
import termios
from collections.abc import Iterator

import pytest

from stairbot.drivers.serial_robot import open_channel
from stairbot.errors import RobotUrlError


@pytest.fixture
def stdin_on_a_terminal() -> Iterator[str]:
    """Standard input on a new pseudo-terminal (as a console's is); its path."""
    master, slave = os.openpty()
    saved = os.dup(0)
    os.dup2(slave, 0)
    try:
        yield os.ttyname(slave)
    finally:
        os.dup2(saved, 0)
        for fd in (saved, slave, master):
            os.close(fd)


def test_the_controlling_terminal_is_refused_as_a_serial_port() -> None:
    with pytest.raises(RobotUrlError, match="own terminal"):
        open_channel("/dev/tty", 1_000_000, "serial:///dev/tty")


def test_the_terminal_of_standard_input_is_refused_and_left_untouched(
        stdin_on_a_terminal: str) -> None:
    before = termios.tcgetattr(0)
    with pytest.raises(RobotUrlError, match="own terminal"):
        open_channel(stdin_on_a_terminal, 1_000_000, f"serial://{stdin_on_a_terminal}")
    assert termios.tcgetattr(0) == before


def test_another_pseudo_terminal_still_opens(stdin_on_a_terminal: str) -> None:
    master, slave = os.openpty()
    try:
        channel = open_channel(os.ttyname(slave), 1_000_000, "serial://other")
        channel.close()
    finally:
        os.close(slave)
        os.close(master)
