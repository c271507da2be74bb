"""A board image of the qemu-stm32f4 port (firmware/port/stm32f4) run in
qemu-system-arm by firmware/port/stm32f4/sb_qemu.sh, its USART1 on a new
pseudo-terminal: what bench_qemu_link.py and tests/firmware/test_qemu_board.py
drive with the host's own serial driver.

    make -C firmware qemu      # the images this runs (arm-none-eabi-gcc, picolibc)

QEMU names the pty it opened on its standard output ("char device
redirected to /dev/pts/N (label serial0)").  The board's boot id
(Owner.boot) is the one given here, which QEMU's loader writes into the
image's RAM before reset (the STM32F405 QEMU models has no RNG)."""

from __future__ import annotations

import os
import re
import select
import shutil
import subprocess
import threading
import time
import tty
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from stairbot.control.robot_config import RobotConfig
from stairbot.drivers import messages as m
from stairbot.drivers.serial_link import FdChannel, SerialLink
from stairbot.errors import LinkLostError
from stairbot.fakes.boards_cli import make_world
from stairbot.fakes.firmware_boards import FirmwareBoard
from stairbot.fakes.plant_link import PlantLink
from stairbot.fakes.sim import motor_limits
from stairbot.inputs.scenario import Scenario

FIRMWARE = Path(__file__).resolve().parents[1] / "firmware"
RUN = FIRMWARE / "port" / "stm32f4" / "sb_qemu.sh"
TOOLS = ("make", "arm-none-eabi-gcc", "arm-none-eabi-nm", "qemu-system-arm")
START_S = 10.0  # QEMU starts in well under a second; the pty is polled for a host every second
PTY_LINE = re.compile(r"char device redirected to (/dev/pts/\d+) \(label (\w+)\)")


def missing_tools() -> list[str]:
    """What of make, the Arm cross compiler, its picolibc and QEMU is missing
    (Debian: make gcc-arm-none-eabi picolibc-arm-none-eabi qemu-system-arm)."""
    missing = [tool for tool in TOOLS if shutil.which(tool) is None]
    if "arm-none-eabi-gcc" not in missing:
        specs = subprocess.run(["arm-none-eabi-gcc", "-print-file-name=picolibc.specs"],
                               capture_output=True, text=True, check=False).stdout.strip()
        if not Path(specs).is_absolute():  # the bare name: gcc found no such file
            missing.append("picolibc")
    return missing


def build_images(out: Path) -> Path:
    """``make -C firmware qemu`` into ``out``; the directory holding the images."""
    made = subprocess.run(["make", "-s", "-C", str(FIRMWARE), f"BUILD={out}", "qemu"],
                          capture_output=True, text=True, check=False)
    if made.returncode != 0:
        raise RuntimeError(f"make -C firmware qemu failed:\n{made.stdout}{made.stderr}")
    return out / "qemu"


@dataclass
class QemuBoard:
    proc: subprocess.Popen[str]
    path: str  # USART1's pty: what a host opens (serial://PATH)
    boot: int  # the boot id the board was given


def _pty(proc: subprocess.Popen[str]) -> str:
    """The pty QEMU opened for serial0 (USART1), from its output."""
    assert proc.stdout is not None
    seen = []
    for line in proc.stdout:
        seen.append(line)
        found = PTY_LINE.search(line)
        if found and found.group(2) == "serial0":
            return found.group(1)
    raise RuntimeError(f"qemu named no pty for serial0: {''.join(seen)}")


def _await_board(path: str, board: m.Board) -> None:
    """Wait until the board answers Identify (QEMU notices a host on the
    pty within a second; the board answers once it has booted)."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    link = SerialLink(FdChannel(fd), timeout_s=0.2)
    end = time.monotonic() + START_S
    try:
        while True:
            try:
                link.exchange(board, [m.Identify()])
                return
            except LinkLostError:
                if time.monotonic() > end:
                    raise
    finally:
        link.close()


@contextmanager
def run_board(elf: Path, boot: int, board: m.Board = m.Board.MOTOR) -> Iterator[QemuBoard]:
    """``elf`` running in QEMU with boot id ``boot``, USART1 on a new pty
    (held open here, so that QEMU keeps it connected between hosts), USART2
    on nothing; stopped on leaving."""
    proc = subprocess.Popen([str(RUN), str(elf), "--boot", f"{boot:x}"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    keeper = -1
    try:
        path = _pty(proc)
        keeper = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(keeper)
        _await_board(path, board)
        yield QemuBoard(proc, path, boot)
    finally:
        proc.terminate()
        try:
            proc.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
        if keeper >= 0:
            os.close(keeper)


@contextmanager
def run_linked(program: Path, address: m.Board, config: RobotConfig, scenario: Scenario,
               serial: int, lockstep: bool = True
               ) -> Iterator[tuple[FirmwareBoard, SerialLink]]:
    """A plant-link image run by ``program`` (make's build/qemu/sb_motor_qemu_link
    or sb_sensor_qemu_link, the board at ``address``) as the fake boards run
    the native programs (FirmwareBoard: its USART1 and USART2 on sockets),
    its plant answered from a world of ``config`` and ``scenario`` by a
    thread here, and a host's link on its USART1.  The world does not move
    on its own: in lockstep it moves on the motor board's StepTo."""
    plant = PlantLink(make_world(config, scenario, lockstep=lockstep), int(address),
                      serial, motor_limits(config))
    board = FirmwareBoard(int(address), program, plant)
    done = threading.Event()

    def serve() -> None:
        while not done.is_set():
            ready, _, _ = select.select([board.link], [], [], 0.05)
            if ready and not board.serve_plant():
                return

    server = threading.Thread(target=serve, daemon=True)
    server.start()
    # retried queries cover the board's start: it greets its plant first
    link = SerialLink(FdChannel(os.dup(board.host.fileno())), timeout_s=0.5, retries=10)
    try:
        yield board, link
    finally:
        link.close()
        done.set()
        server.join()
        board.close()
