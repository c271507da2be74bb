"""``stairbot fake-boards`` stops on SIGINT even when started with SIGINT
ignored: Python keeps an inherited SIG_IGN, so a fake-board process started
from a background job or a test runner's worker ignored ``kill -INT`` (a CI
run waited 30 s for it, then killed it)."""

from __future__ import annotations

import random
import signal
import subprocess
import sys

import pytest


def _sigint_ignored() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


# a group of its own: another test's boards on the same group would answer its host
GROUP = f"239.74.{random.randrange(170, 250)}.{random.randrange(1, 250)}"


@pytest.mark.parametrize("wire", [["--serial", "--lockstep"],
                                  ["--can", f"udp_multicast/{GROUP}", "--lockstep"]],
                         ids=["serial", "can"])
def test_fake_boards_stop_on_sigint_though_started_with_it_ignored(wire: list[str]) -> None:
    proc = subprocess.Popen([sys.executable, "-m", "stairbot", "fake-boards", *wire],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_sigint_ignored)
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline().strip()  # serving: its URL
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=60) in (0, 130)  # stopped (130: interrupted while starting)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
