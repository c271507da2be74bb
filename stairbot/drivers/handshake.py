"""Opening a board, whatever the wire (docs/protocol.md, sections 3 and 6).

The host identifies each board, refuses one whose protocol major version is
not its own (one ProtocolVersionError naming the board and both versions,
before a single telemetry frame of another layout could be misread; a CAN
board of protocol 3.x, which ignores 4.x frames, is asked the 3.x way when
it does not answer) or whose
lockstep does not match the URL, or that holds a latch (its emergency stop,
or a watchdog that tripped: an earlier host stopped mid-run, crashed or was
cut off) -- opening never clears one, the operator does (``stairbot clear``)
-- then sets its watchdog.  ``board_robot`` does this for both boards when it
opens.
"""

from __future__ import annotations

from stairbot.drivers import messages as m
from stairbot.drivers.link import BoardLink, ProbesOldBoards
from stairbot.errors import (
    HardwareError,
    LatchedError,
    LinkLostError,
    NoBoardError,
    ProtocolVersionError,
    RobotUrlError,
)


def check_version(url: str, board: m.Board, ident: m.Ident) -> None:
    """ProtocolVersionError unless ``ident`` speaks this host's major version
    (Ident has the same layout in every version, so any board can say)."""
    if ident.protocol_major != m.PROTOCOL_MAJOR:
        raise ProtocolVersionError(
            f"{url}: the {board.name.lower()} board speaks protocol {ident.protocol_major}."
            f"{ident.protocol_minor}; this host speaks {m.PROTOCOL_MAJOR}.x "
            "(docs/protocol.md): update the board's firmware or the host")


LATCHES = m.StatusFlag.ESTOP | m.StatusFlag.WATCHDOG


def latch_names(flags: int) -> str:
    """The latches in a Status's flags, in words."""
    names = []
    if flags & m.StatusFlag.ESTOP:
        names.append("its emergency stop latched")
    if flags & m.StatusFlag.WATCHDOG:
        names.append("its watchdog tripped and latched (frames stopped coming while "
                     "it was armed)")
    return " and ".join(names)


def open_board(link: BoardLink, url: str, board: m.Board, *, lockstep: bool,
               watchdog_ms: int, allow_latched: bool = False
               ) -> tuple[m.Ident, m.Status | None]:
    """Identify ``board`` and set it up; its Ident and the Status after set-up.
    Raises NoBoardError (no answer), ProtocolVersionError, RobotUrlError (a
    lockstep mismatch), LatchedError (a latch, unless ``allow_latched``: the
    clear command) or HardwareError (an answer that is not Ident + Status)."""
    n = link.retries + 1
    tries = f"{n} {'try' if n == 1 else 'tries'} of {link.timeout_s * 1e3:.0f} ms"
    name = board.name.lower()
    try:
        reply = link.exchange(board, [m.Identify(), m.GetStatus()])
    except LinkLostError:
        # A board of an older protocol may ignore this host's frames (on CAN,
        # 3.x boards take no 29-bit id): asked the old way, it says what it
        # speaks, and the error says so rather than "no board".
        old = link.probe_old_ident(board) if isinstance(link, ProbesOldBoards) else None
        if old is not None:
            check_version(url, board, old)
        raise NoBoardError(url, name, f"no {name} board answered on the "
                           f"{link.wire} ({tries})") from None
    ident, status = (reply.messages + (None, None))[:2]
    if isinstance(ident, m.Ident):
        check_version(url, board, ident)
    if not isinstance(ident, m.Ident) or not isinstance(status, m.Status):
        raise HardwareError(f"{url}: the {name} board gave an unexpected "
                            f"answer to Identify: {reply.messages}")
    board_lockstep = bool(status.flags & m.StatusFlag.LOCKSTEP)
    if board_lockstep != lockstep:
        hint = ("add ?lockstep=1 to the URL" if board_lockstep
                else "start the fake boards with --lockstep")
        state = "run" if board_lockstep else "do not run"
        raise RobotUrlError(url, "lockstep", f"the boards {state} in lockstep; {hint}")
    if status.flags & LATCHES and not allow_latched:
        raise LatchedError(
            f"{url}: the {name} board has {latch_names(status.flags)}; opening never "
            f"clears a latch: check the robot, then `stairbot clear --robot {url}`")
    # Setting up is the one place where a command frame is sent again after a
    # timeout (SetWatchdog sets a value: the same effect however often it runs).
    for attempt in range(link.retries + 1):
        try:
            reply = link.exchange(board, [m.SetWatchdog(watchdog_ms)])
            break
        except LinkLostError:
            if attempt == link.retries:
                raise NoBoardError(url, name, f"the {name} board did not answer "
                                   f"SetWatchdog on the {link.wire} ({tries})") from None
    last = reply.messages[-1] if reply.messages else None
    return ident, last if isinstance(last, m.Status) else None
