"""The boards' C firmware on the simulated robot: ``stairbot fake-boards --firmware native``.

Each board's program (``firmware/build/sb_motor_native``,
``sb_sensor_native``) runs as a child process holding two sockets: its
host line and its plant link.  :class:`FirmwareBoardServer` serves the pty
the host opens (``serial://PATH``) as :class:`SerialBoardServer` does, but
relays each host frame, as bytes, to the board it addresses and each
board's reply back, as one serial pair shared by both boards would carry
them; it answers both plant links from one
:class:`~stairbot.fakes.board_world.BoardWorld` and, unless in lockstep,
advances the world as wall time passes.  The firmware keeps its own lease,
watchdog, latches and duplicate cache: nothing of ``boards.py`` is used.
Wire faults act here, on the bytes, in both directions.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import select
import shutil
import signal
import socket
import subprocess
import time
from collections import deque
from pathlib import Path

from stairbot.drivers import messages as m
from stairbot.drivers.serial_wire import CodecError, decode_frame
from stairbot.errors import InputError
from stairbot.fakes.board_world import BoardWorld
from stairbot.fakes.plant_link import Delimited, PlantLink
from stairbot.fakes.serial_boards import SerialBoardServer, WireFaults
from stairbot.hardware import MotorId

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
KINDS = ("native", "qemu")
PROGRAMS = {int(m.Board.MOTOR): "sb_motor_native", int(m.Board.SENSOR): "sb_sensor_native"}
"""The native programs, by board address (in the build directory)."""
QEMU_PROGRAMS = {int(m.Board.MOTOR): "qemu/sb_motor_qemu_link",
                 int(m.Board.SENSOR): "qemu/sb_sensor_qemu_link"}
"""The qemu-stm32f4 images' runners (firmware/port/stm32f4/sb_qemu.sh), by board address."""
QEMU_TOOLS = ("arm-none-eabi-gcc", "qemu-system-arm")
HELLO_S = 15.0  # how long a board's program may take to greet its plant (QEMU boots first)
REPLY_WAIT_S = 0.1  # how long the line waits on a board's reply before the next frame
HUNG_RESET_S = 0.25  # a hung board's independent watchdog: reset, outputs off


class FirmwareError(InputError):
    """The firmware could not be built or started; the message says why and what to do."""

    def __init__(self, problem: str) -> None:
        super().__init__("--firmware", None, problem)


def find_cc() -> str | None:
    """The C compiler $CC names, else cc, gcc or clang from PATH; None without one."""
    names = [os.environ["CC"]] if os.environ.get("CC") else ["cc", "gcc", "clang"]
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    return None


def build_native(build_dir: Path | None = None) -> Path:
    """``make -C firmware`` the native programs (into ``build_dir``, default
    firmware/build); the directory holding them.  FirmwareError names what
    is missing when they cannot be built."""
    return build_firmware("native", build_dir)


def programs(kind: str) -> dict[int, str]:
    """Each board's program of firmware ``kind`` (native, qemu), by board
    address, relative to the build directory."""
    return QEMU_PROGRAMS if kind == "qemu" else PROGRAMS


def build_firmware(kind: str, build_dir: Path | None = None) -> Path:
    """Build both boards' programs of ``kind`` with make (native: the Linux
    programs; qemu: the qemu-stm32f4 images and their runners) into
    ``build_dir`` (default firmware/build); the directory.  FirmwareError
    names what is missing when they cannot be built or run."""
    out = build_dir or FIRMWARE / "build"
    if not (FIRMWARE / "Makefile").is_file():
        raise FirmwareError(f"no firmware sources at {FIRMWARE}: --firmware needs a source "
                            "checkout of stairbot (its firmware/ directory)")
    cc = find_cc()
    if cc is None:
        raise FirmwareError("--firmware needs a C compiler (cc, gcc or clang on PATH, "
                            "or $CC; Debian: apt-get install gcc make)")
    missing = [tool for tool in QEMU_TOOLS if kind == "qemu" and shutil.which(tool) is None]
    if missing:
        raise FirmwareError(f"--firmware qemu needs {' and '.join(missing)} (Debian: apt-get "
                            "install gcc-arm-none-eabi picolibc-arm-none-eabi qemu-system-arm)")
    targets = ["qemu"] if kind == "qemu" else [str(out / p) for p in PROGRAMS.values()]
    try:
        out.mkdir(parents=True, exist_ok=True)
        with open(out / ".lock", "w") as lock:  # one make at a time in a build directory
            fcntl.flock(lock, fcntl.LOCK_EX)
            made = subprocess.run(["make", "-s", "-C", str(FIRMWARE), f"BUILD={out}",
                                   f"CC={cc}", *targets],
                                  capture_output=True, text=True, check=False)
    except OSError as exc:
        if not isinstance(exc, FileNotFoundError):
            raise FirmwareError(f"cannot build the {kind} firmware in {out}: {exc}") from exc
        raise FirmwareError("--firmware needs make and a C compiler "
                            "(Debian: apt-get install make gcc)") from exc
    if made.returncode != 0:
        last = (made.stderr.strip().splitlines() or ["(no output)"])[-1]
        raise FirmwareError(f"building the {kind} firmware failed: {last} "
                            f"(make -C {FIRMWARE} shows the whole error)")
    return out


class FirmwareBoard:
    """One board's program, its two sockets, and its plant link."""

    def __init__(self, address: int, exe: Path, plant: PlantLink) -> None:
        self.address = address
        self.exe = exe
        self.plant = plant
        self.host, host_child = socket.socketpair()
        self.link, link_child = socket.socketpair()
        self.replies = Delimited()
        self.hung_at: float | None = None  # world time it hung (SIGSTOP), None while it runs
        try:
            self.proc = subprocess.Popen(
                [str(exe), "--host-fd", str(host_child.fileno()),
                 "--plant-fd", str(link_child.fileno())],
                pass_fds=(host_child.fileno(), link_child.fileno()),
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        except OSError as exc:
            raise FirmwareError(f"cannot start {exe}: {exc}") from exc
        finally:
            host_child.close()
            link_child.close()
        for s in (self.host, self.link):
            s.setblocking(False)

    def serve_plant(self) -> bool:
        """Answer what the board asked its plant; False once it closed the link."""
        try:
            data = self.link.recv(4096)
        except BlockingIOError:
            return True
        except OSError:
            data = b""
        if not data:
            return False
        answer = self.plant.feed(data)
        if answer:
            try:
                self.link.sendall(answer)
            except OSError:  # the program died with a question in flight
                return False
        return True

    @property
    def alive(self) -> bool:
        """Running and not hung: it answers its host and asks its plant."""
        return self.hung_at is None and self.proc.poll() is None

    def send(self, wire: bytes) -> None:
        with contextlib.suppress(BlockingIOError, BrokenPipeError, ConnectionResetError):
            self.host.sendall(wire)

    def close(self) -> str:
        """Stop the program; what it printed on stderr (its counts, unless
        it was killed)."""
        for s in (self.host, self.link):
            with contextlib.suppress(OSError):
                s.close()
        if self.proc.poll() is None:
            if self.hung_at is not None:
                self.proc.send_signal(signal.SIGCONT)
            self.proc.terminate()
        try:
            _, err = self.proc.communicate(timeout=5)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            _, err = self.proc.communicate()
        return err.decode(errors="replace").strip()


class FirmwareBoardServer(SerialBoardServer):
    """Serve the C boards on ``fd`` (a pty's master), each board's program
    of firmware ``kind`` (native, qemu) started from ``build_dir`` on
    ``world``.  ``serials``: the motor board's and the sensor board's serial
    numbers, which their plants give them."""

    def __init__(self, fd: int, world: BoardWorld, build_dir: Path,
                 limits_tps: dict[MotorId, float], serials: tuple[int, int],
                 faults: WireFaults | None = None, time_scale: float = 1.0,
                 step_s: float = 0.005, kind: str = "native") -> None:
        super().__init__(fd, world, {}, faults, time_scale, step_s)
        self.firmware: dict[int, FirmwareBoard] = {}
        self.serials = dict(zip(PROGRAMS, serials, strict=True))
        self._inbox = Delimited()
        self._queue: deque[tuple[int | None, bytes, int]] = deque()  # (address, wire, copies)
        self._flight: tuple[int, int, float] | None = None  # (address, replies due, deadline)
        self.killed: set[int] = set()
        try:
            for address, name in programs(kind).items():
                plant = PlantLink(world, address, self.serials[address], limits_tps,
                                  after_step=self.after_step)
                self.firmware[address] = FirmwareBoard(address, build_dir / name, plant)
            self._await_hello()
        except BaseException:
            self.close()
            raise

    def _await_hello(self) -> None:
        left = HELLO_S
        waiting = {b.link.fileno(): b for b in self.firmware.values()}
        while any(not b.plant.greeted for b in self.firmware.values()):
            ready, _, _ = select.select(list(waiting), [], [], min(left, 0.1))
            for fd in ready:
                waiting[fd].serve_plant()
            left -= 0.1 if not ready else 0.0
            dead = [b for b in self.firmware.values() if b.proc.poll() is not None]
            if dead or left <= 0:
                board = (dead or [b for b in self.firmware.values() if not b.plant.greeted])[0]
                raise FirmwareError(f"{board.exe.name} did not start: "
                                    f"{board.close() or 'it never greeted its plant'}")

    # -- the host's frames in ---------------------------------------------------------------
    def receive(self, data: bytes) -> None:
        """Queue each frame the host sent for the board it addresses (a frame
        that is not a valid host frame for both, as a shared line would carry
        it); wire faults act on whole frames, as in :class:`SerialBoardServer`."""
        f = self.faults
        for wire in self._inbox.frames(data):
            if self._chance(f.drop):
                continue
            if self._chance(f.corrupt):
                wire = self._corrupt(wire)
            copies = 2 if self._chance(f.duplicate) else 1
            self.stats.frames_rx += 1
            self._queue.append((_address(wire), wire, copies))
        self._pump()

    def _pump(self) -> None:
        """Hand on queued frames, one board's requests in flight at a time:
        frames to the board already answering follow at once (its line keeps
        them in order, as the host's back-to-back frames reach a board on a
        real line), and a frame to the other board waits for every reply due
        (each within REPLY_WAIT_S of the last), so the boards see the host's
        frames in the order it sent them -- a StepTo to the motor board is
        done before the sensor board reads the world for the next ReadAll."""
        now = time.monotonic()
        if self._flight is not None and (now >= self._flight[2]
                                         or not self.firmware[self._flight[0]].alive):
            self._flight = None  # (a board killed or hung meanwhile will not answer: no wait)
        while self._queue:
            address, wire, copies = self._queue[0]
            if self._flight is not None and address != self._flight[0]:
                return
            self._queue.popleft()
            if address is None:  # no board answers it: to both, nothing awaited
                for board in self.firmware.values():
                    self._hand_on(board, wire * copies)
                continue
            board = self.firmware[address]
            self._hand_on(board, wire * copies)
            if board.alive:  # a killed or hung board answers nothing: nothing awaited
                due = copies + (self._flight[1] if self._flight is not None else 0)
                self._flight = (address, due, now + REPLY_WAIT_S)

    def _hand_on(self, board: FirmwareBoard, wire: bytes) -> None:
        """The bytes go down the board's line."""
        board.send(wire)

    # -- the boards' replies and plants --------------------------------------------------------
    def _side_fds(self) -> list[int]:
        """The plant links before the host lines: a board's motor command,
        sent before its reply, reaches the world before the host sees the reply."""
        running = [b for a, b in self.firmware.items() if a not in self.killed]
        return [b.link.fileno() for b in running] + [b.host.fileno() for b in running]

    def _side_ready(self, fd: int) -> None:
        for board in self.firmware.values():
            if fd == board.link.fileno():
                if not board.serve_plant() and board.address not in self.killed:
                    self.stop()  # the program ended: nothing more to serve
            elif fd == board.host.fileno():
                self._relay_replies(board)

    def _idle(self) -> None:
        self._pump()  # a reply that never came frees the line after REPLY_WAIT_S

    def _relay_replies(self, board: FirmwareBoard) -> None:
        try:
            data = board.host.recv(4096)
        except BlockingIOError:
            return
        if not data:
            if board.address not in self.killed:
                self.stop()  # the program ended: nothing more to serve
            return
        for wire in board.replies.frames(data):
            if self._flight is not None and self._flight[0] == board.address:
                address, left, _ = self._flight
                self._flight = (address, left - 1, time.monotonic() + REPLY_WAIT_S) \
                    if left > 1 else None
            if not self._silent(board.address):
                self._write(wire)
        if self._out:
            out, self._out = bytes(self._out), bytearray()
            self._write_all(out)
        self._pump()

    # -- faults of the boards themselves (the fault matrix) ---------------------------------------
    def kill(self, address: int) -> None:
        """The board loses power: its program is killed and its motors stop
        (the lifts are self-locking and hold)."""
        board = self.firmware[address]
        self.killed.add(address)
        if board.proc.poll() is None:
            if board.hung_at is not None:
                board.proc.send_signal(signal.SIGCONT)
            board.proc.kill()
            board.proc.wait()
        self._power_off(address)

    def hang(self, address: int) -> None:
        """The board's program hangs (SIGSTOP): it answers nothing and its
        motors run on as last told, until its independent watchdog -- a
        hardware timer, :data:`HUNG_RESET_S` -- resets it, its outputs off."""
        self.firmware[address].proc.send_signal(signal.SIGSTOP)
        self.firmware[address].hung_at = self.world.now()

    def _power_off(self, address: int) -> None:
        if address == int(m.Board.MOTOR):
            self.world.set_speeds(dict.fromkeys(m.MOTOR_CHANNELS, 0.0))

    def after_step(self) -> None:
        """The world moved on: a hung board whose independent watchdog ran
        out is reset, its outputs off."""
        for address, board in self.firmware.items():
            if board.hung_at is not None and self.world.now() - board.hung_at >= HUNG_RESET_S:
                self._power_off(address)

    def latched(self) -> bool:
        """Whether a running board says it holds a latch (its e-stop or its
        tripped watchdog), as its last plant query reported its status."""
        latches = int(m.StatusFlag.ESTOP | m.StatusFlag.WATCHDOG)
        return any(b.plant.board_flags & latches for b in self.firmware.values() if b.alive)

    def run_on(self, seconds: float) -> None:
        """The world goes on with no host, in 10 ms steps, each running board
        asking its plant after each (its watchdog sees the time pass).  Call
        it while the server is not serving on another thread."""
        t_us = round(self.world.now() * 1e6)
        for _ in range(round(seconds / 0.01)):
            t_us += 10_000
            self.world.step_to(t_us)
            self.after_step()
            self._await_queries()

    def _await_queries(self) -> None:
        """Serve the plant links until each running board has asked once more
        (or 0.5 s of wall time passed)."""
        live = {b.link.fileno(): b for b in self.firmware.values() if b.alive}
        asked = {fd: b.plant.stats.queries for fd, b in live.items()}
        deadline = time.monotonic() + 0.5
        while live and time.monotonic() < deadline:
            ready, _, _ = select.select(list(live), [], [], 0.05)
            for fd in ready:
                live[fd].serve_plant()
                if live[fd].plant.stats.queries > asked[fd]:
                    del live[fd]

    def rearm(self) -> None:
        """Let :meth:`serve` run again after :meth:`stop`."""
        self._stop.clear()

    def close(self) -> list[str]:
        """Stop every board's program; the lines they printed."""
        return [line for b in self.firmware.values() if (line := b.close())]


def _address(wire: bytes) -> int | None:
    """The board a valid host frame addresses; None for anything else (no
    board answers a frame failing its checks, or a board's own)."""
    try:
        frame = decode_frame(wire[:-1])
    except CodecError:
        return None
    return None if frame.from_board else frame.board


__all__ = ["KINDS", "FirmwareBoardServer", "FirmwareError", "build_firmware", "build_native",
           "find_cc", "programs"]
