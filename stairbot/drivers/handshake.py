"""Opening a board, whatever the wire (docs/protocol.md, sections 3 and 6).

The host identifies each board, refuses one whose protocol major version is
not its own (one ProtocolVersionError naming the board and both versions,
before a single telemetry frame of another layout could be misread; a CAN
board of protocol 3.x, which ignores 4.x frames, is asked the 3.x way when
it does not answer) or whose
lockstep does not match the URL, or that holds a latch (its emergency stop,
or a watchdog that tripped: an earlier host stopped mid-run, crashed or was
cut off) -- opening never clears one, the operator does (``stairbot clear``)
-- then sets its watchdog.  Before the latch check it takes the board's lease
(Claim, protocol 5.0): a board another host holds is refused with one
BoardOwnedError line naming that host's session; a lease about to lapse (its
holder gone silent) is waited out once and taken.  A sensor board must say 4 channels, or 6 with the
side pair (SSR, SSL; protocol 4.1); one without the side pair is refused when
the robot config has it (BoardMismatchError), before any run could miss its
readings.  ``board_robot`` does this for both boards when it opens.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass, field

from stairbot.drivers import messages as m
from stairbot.drivers.link import BoardLink, CountsReplies, ProbesOldBoards, Reply
from stairbot.drivers.telemetry import BASE_NAMES, SIDE_NAMES
from stairbot.errors import (
    BoardMismatchError,
    BoardOwnedError,
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


WITH_SIDE_PAIR = max(m.SIDE_SENSOR_CHANNELS) + 1  # 6: the channels of a board with it


def check_sensor_channels(url: str, ident: m.Ident, side_pair: str | None) -> None:
    """HardwareError unless the sensor board's Ident says 4 channels (SFR, SFL,
    SBR, SBL) or 6 (the side pair SSR, SSL too; a later minor version may
    add more, which this host does not read); BoardMismatchError when it has
    no side pair and ``side_pair`` says the robot config has one (``side_pair``:
    where the config says so, for the message; None: the robot has none)."""
    n = ident.channels
    if n < m.BASE_SENSOR_CHANNELS or m.BASE_SENSOR_CHANNELS < n < WITH_SIDE_PAIR:
        raise HardwareError(
            f"{url}: the sensor board says it has {n} channel(s); allowed: "
            f"{m.BASE_SENSOR_CHANNELS} ({BASE_NAMES}) or {WITH_SIDE_PAIR} (with the side "
            f"pair {SIDE_NAMES}, protocol 4.1): a board has both side sensors or neither "
            "(docs/protocol.md, section 1)")
    if side_pair is not None and n < WITH_SIDE_PAIR:
        raise BoardMismatchError(
            f"{url}: {side_pair} gives the robot the side pair ({SIDE_NAMES}), but the sensor "
            f"board offers {n} channels ({BASE_NAMES}) and no side pair (protocol "
            f"{ident.protocol_major}.{ident.protocol_minor}); fit a sensor board with "
            f"channels 4-5 ({SIDE_NAMES}), or set [sensors] side_model = \"none\"")


MOTOR_FAULTS = (m.MotorFault.OVERCURRENT, m.MotorFault.STALL, m.MotorFault.ENCODER,
                m.MotorFault.DRIVER)
"""The motor faults a board latches until Clear 0x04 (docs/protocol.md, section 3)."""


def latches(status: m.Status) -> int:
    """The latches a Status shows, as its flags: the e-stop, the tripped
    watchdog, and FAULT when Status.fault is a latched motor fault (a
    simulated world's failure, SIMULATION, also sets FAULT, but no Clear
    undoes it: it is no latch)."""
    flags = status.flags & (m.StatusFlag.ESTOP | m.StatusFlag.WATCHDOG)
    if status.flags & m.StatusFlag.FAULT and status.fault in MOTOR_FAULTS:
        flags |= m.StatusFlag.FAULT
    return flags


def latch_names(flags: int, fault: int = m.MotorFault.NONE) -> str:
    """The latches in a Status's flags (and its fault code), in words."""
    names = []
    if flags & m.StatusFlag.ESTOP:
        names.append("its emergency stop latched")
    if flags & m.StatusFlag.WATCHDOG:
        names.append("its watchdog tripped and latched (frames stopped coming while "
                     "it was armed)")
    if flags & m.StatusFlag.FAULT:
        what = m.MotorFault(fault).name if fault in MOTOR_FAULTS else "a"
        names.append(f"{what} motor fault latched (that motor holds stopped until cleared)")
    return " and ".join(names)


LEASE_WAIT_MAX_S = 3.0
"""The longest lease left (board seconds) that opening waits out for a
holder that may be gone; a longer one is refused at once."""


def claim_board(link: BoardLink, url: str, board: m.Board, *, nonce: int, lease_ms: int,
                wait_s: Callable[[float], None]) -> m.Owner:
    """Take ``board``'s lease for this link's session (``nonce``: this host's).
    A lease held by another host is waited out once (``wait_s`` sleeps board
    seconds) when it has at most LEASE_WAIT_MAX_S left: a holder still alive
    renews it meanwhile and is refused then.  Raises BoardOwnedError (one line
    naming the holder's session), NoBoardError (no answer) or HardwareError
    (an answer that is not Owner)."""
    name = board.name.lower()
    holder = 0
    for attempt in (1, 2):
        reply = _set_up(link, url, board, m.Claim(lease_ms, nonce))
        owner = reply.messages[0] if reply.messages else None
        if not isinstance(owner, m.Owner):
            raise HardwareError(f"{url}: the {name} board gave an unexpected answer to "
                                f"Claim: {reply.messages}")
        if owner.result == m.ClaimResult.GRANTED:
            return owner
        holder, left = owner.session, owner.lease_cs / 100
        if attempt == 2 or left > LEASE_WAIT_MAX_S:
            break
        wait_s(left + 0.05)
    raise BoardOwnedError(
        f"{url}: the {name} board is held by another host (session {holder}; its "
        "lease runs on while that host keeps sending): close that host first, one host "
        "owns the robot")


def _tries(link: BoardLink) -> str:
    """How hard the link asks, for a message saying nothing answered."""
    n = link.retries + 1
    return f"{n} {'try' if n == 1 else 'tries'} of {link.timeout_s * 1e3:.0f} ms"


def _set_up(link: BoardLink, url: str, board: m.Board, msg: m.Message) -> Reply:
    """The reply to a setting-up message that does the same however often it
    runs (Claim, SetWatchdog): a board that answered Identify a moment ago and
    misses it and its retries (a host or a fake board starved of CPU) is asked
    again, under a fresh seq, as many times.  NoBoardError when it never answers."""
    name = board.name.lower()
    for attempt in range(link.retries + 1):
        try:
            return link.exchange(board, [msg])
        except LinkLostError:
            if attempt == link.retries:
                raise NoBoardError(url, name, f"the {name} board did not answer "
                                   f"{type(msg).__name__} on the {link.wire} "
                                   f"({_tries(link)})") from None
    raise AssertionError("unreachable: the last attempt returns or raises")


def release_board(link: BoardLink, board: m.Board, nonce: int) -> None:
    """Give ``board``'s lease up (Claim with lease 0); what it answers is
    not waited for beyond the link's own timeout, and nothing is raised."""
    with contextlib.suppress(Exception):  # a lease not given up lapses on its own
        link.exchange(board, [m.Claim(0, nonce)])


def open_board(link: BoardLink, url: str, board: m.Board, *, lockstep: bool,
               watchdog_ms: int, hold_ms: int, nonce: int, lease_ms: int,
               wait_s: Callable[[float], None], allow_latched: bool = False,
               side_pair: str | None = None
               ) -> tuple[m.Ident, m.Status | None, m.Owner]:
    """Identify ``board``, take its lease (``claim_board``) and set it up
    (its watchdog, and the command hold ``hold_ms``: docs/protocol.md, "Command hold");
    its Ident, the Status after set-up and the Owner reply (the boot id).
    Raises NoBoardError (no answer), ProtocolVersionError, RobotUrlError (a
    lockstep mismatch), BoardOwnedError (another host holds it), LatchedError
    (a latch, unless ``allow_latched``: the clear command), BoardMismatchError
    (a sensor board without the side pair that ``side_pair`` names: see
    ``check_sensor_channels``) or HardwareError (an answer that is not Ident +
    Status, a sensor board's channel count)."""
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
                           f"{link.wire} ({_tries(link)})") from None
    ident, status = (reply.messages + (None, None))[:2]
    if isinstance(ident, m.Ident):
        check_version(url, board, ident)
    if not isinstance(ident, m.Ident) or not isinstance(status, m.Status):
        raise HardwareError(f"{url}: the {name} board gave an unexpected "
                            f"answer to Identify: {reply.messages}")
    if board == m.Board.SENSOR:
        check_sensor_channels(url, ident, side_pair)
        if isinstance(link, CountsReplies):  # the motor board's six are the protocol's
            link.set_channels(board, ident.channels)
    board_lockstep = bool(status.flags & m.StatusFlag.LOCKSTEP)
    if board_lockstep != lockstep:
        hint = ("add ?lockstep=1 to the URL" if board_lockstep
                else "start the fake boards with --lockstep")
        state = "run" if board_lockstep else "do not run"
        raise RobotUrlError(url, "lockstep", f"the boards {state} in lockstep; {hint}")
    owner = claim_board(link, url, board, nonce=nonce, lease_ms=lease_ms,
                        wait_s=wait_s)
    if latches(status) and not allow_latched:
        raise LatchedError(
            f"{url}: the {name} board has {latch_names(latches(status), status.fault)}; "
            f"opening never "
            f"clears a latch: check the robot, then `stairbot clear --robot {url}`",
            {name: {"serial": ident.serial}})
    # Setting up is the one place where a command frame is sent again after a
    # timeout (SetWatchdog sets a value: the same effect however often it runs).
    reply = _set_up(link, url, board, m.SetWatchdog(watchdog_ms, hold_ms))
    last = reply.messages[-1] if reply.messages else None
    if isinstance(last, m.Ack) and last.result == m.AckResult.NOT_OWNER:
        raise BoardOwnedError(f"{url}: the {name} board refused SetWatchdog: another host "
                              "took its lease; one host owns the robot")
    return ident, last if isinstance(last, m.Status) else None, owner



@dataclass
class OpenedBoards:
    """What opening both boards found: each board's Ident, its Status after
    set-up (when it sent one) and its boot id (its Owner reply)."""

    idents: dict[int, m.Ident] = field(default_factory=dict)
    status: dict[int, m.Status] = field(default_factory=dict)
    boots: dict[int, int] = field(default_factory=dict)


def open_boards(link: BoardLink, url: str, *, lockstep: bool, watchdog_ms: int, hold_ms: int,
                nonce: int, lease_ms: int, wait_s: Callable[[float], None],
                allow_latched: bool = False, side_pair: str | None = None,
                opened: Callable[[m.Board], None] = lambda board: None) -> OpenedBoards:
    """Every board opened in turn (``open_board``); ``opened`` is told each
    board once it is.  Raises what ``open_board`` raises, after giving up
    the leases taken so far."""
    out = OpenedBoards()
    try:
        for board in m.Board:
            out.idents[board], status, owner = open_board(
                link, url, board, lockstep=lockstep, watchdog_ms=watchdog_ms,
                hold_ms=hold_ms, nonce=nonce, lease_ms=lease_ms, wait_s=wait_s,
                allow_latched=allow_latched, side_pair=side_pair)
            out.boots[board] = owner.boot
            if status is not None:
                out.status[board] = status
            opened(board)
    except BaseException as exc:
        for taken in out.boots:  # the leases taken so far
            release_board(link, m.Board(taken), nonce)
        if isinstance(exc, LatchedError):  # the boards identified before the latched one
            exc.boards.update({m.Board(b).name.lower(): {"serial": ident.serial}
                               for b, ident in out.idents.items()})
        raise
    return out


def check_owned(url: str, reply: Reply, what: str) -> None:
    """BoardOwnedError when a board answered ``what`` with Ack(NOT_OWNER)."""
    for msg in reply.messages:
        if isinstance(msg, m.Ack) and msg.result == m.AckResult.NOT_OWNER:
            raise BoardOwnedError(
                f"{url}: the {m.Board(reply.board).name.lower()} board refused "
                f"{what}: this host no longer holds its lease (another host took it, "
                "or this one fell silent for longer than the lease); one host owns "
                "the robot")
