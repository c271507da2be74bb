"""drivers/robot_lock.py: the lock a robot URL opens under, which the console
uses to find a console sharing the same robot (console/sharing.py)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from stairbot.drivers.port_lock import lock_path
from stairbot.drivers.robot_lock import robot_lock_path


@pytest.fixture(autouse=True)
def own_locks(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path / "run"))


def test_two_spellings_of_one_serial_device_are_one_lock(tmp_path: Path) -> None:
    master, slave = os.openpty()
    try:
        device = os.ttyname(slave)
        link = tmp_path / "by-id"
        link.symlink_to(device)
        here = robot_lock_path(f"serial://{device}")
        assert here == lock_path(os.path.realpath(device))
        assert robot_lock_path(f"serial://{link}?baud=115200") == here
        assert robot_lock_path(f"serial://spy://{device}") == here
    finally:
        os.close(master)
        os.close(slave)


def test_a_can_bus_is_locked_by_interface_and_channel() -> None:
    url = "can://udp_multicast/239.74.163.2"
    assert robot_lock_path(url) == lock_path("can:udp_multicast/239.74.163.2")
    assert robot_lock_path(url + "?timeout=0.02") == robot_lock_path(url)


@pytest.mark.parametrize("url", ["sim://", "serial://loop://", "can://virtual/bus0",
                                 "nonsense", "serial://", "can://"])
def test_no_lock_for_a_robot_of_this_process_alone_or_a_bad_url(url: str) -> None:
    assert robot_lock_path(url) is None
