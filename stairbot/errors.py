"""The typed errors of stairbot: one root, a few children a caller can act on."""

from __future__ import annotations

from stairbot.text import printable


class StairbotError(Exception):
    """Root of every error stairbot raises on purpose.

    Its message (``str()``) has every control character escaped
    (:func:`stairbot.text.printable`): it names files, fields and values from
    outside, and is printed to a terminal."""

    def __str__(self) -> str:
        return printable(super().__str__())


class TransitionError(RuntimeError):
    """A phase's step returned an outcome its record does not list: a bug in
    the controller, not the robot's or the user's (raised by
    :func:`stairbot.control.algorithm.transitions.exit_of`)."""


class InputError(StairbotError):
    """Bad user input (config, scenario, URL): the CLI exits 2 with the message.

    The message names the file, the field and what is allowed.
    """

    def __init__(self, source: str, field: str | None, problem: str) -> None:
        self.source = source
        self.field = field
        self.problem = problem
        where = f"{source}: {field}" if field else source
        super().__init__(f"{where}: {problem}")


class ConfigError(InputError):
    """A robot config file is malformed or describes an impossible robot."""


class ScenarioError(InputError):
    """A scenario file is malformed or describes impossible stairs."""


class RobotUrlError(InputError):
    """A robot URL names an unknown scheme or cannot be opened."""


class OutputError(StairbotError):
    """A file a run writes (the event record, the journal) refused a write --
    a full disk, a file grown past its limit.  The run stops (the robot is
    stopped) and the CLI exits 1 with the message, one line naming the file:
    ``PATH: cannot write WHAT: REASON``.  What was written before stays."""

    def __init__(self, path: str, what: str, problem: str) -> None:
        self.path = path
        self.what = what
        self.problem = problem
        super().__init__(f"{path}: cannot write {what}: {problem}")


class ReadFault(StairbotError):
    """The disk failed while a file was read (an I/O fault, not bad input):
    the CLI exits 1 with the message, one line naming the file."""


class HardwareError(StairbotError):
    """The robot (real or simulated) failed: the run stops in a safe state."""


class LinkLostError(HardwareError):
    """The link to a board is lost: no valid reply within the allowed time."""


class ProtocolVersionError(HardwareError):
    """A board speaks another major version of the boards' protocol
    (docs/protocol.md): its telemetry would be misread, so it is not opened.
    The message names the URL, the board and both versions."""


class LatchedError(HardwareError):
    """A board holds a latch -- its emergency stop, or its watchdog that
    tripped -- from before this host opened it.  Opening never clears a latch:
    the operator checks the robot and clears it (``stairbot clear``).  The
    message is one line naming the URL, the board, the latch and that command;
    ``boards`` holds the serial number of each board identified (as the
    boards' identity does: ``{"motor": {"serial": 7}}``), the latched one's
    among them, so the robot's journal can be found."""

    def __init__(self, message: str, boards: dict[str, dict[str, int]] | None = None) -> None:
        super().__init__(message)
        self.boards = boards or {}


class PortBusyError(HardwareError):
    """Another stairbot has the serial port open (docs/protocol.md: one host
    on a port at a time).  One line naming the port and who holds it."""


class BoardOwnedError(HardwareError):
    """Another host holds a board's lease (docs/protocol.md, section 3: one
    host owns the robot): nothing was sent that it refuses.  One line naming
    the URL, the board and the holder's session."""


class BoardMismatchError(HardwareError):
    """The boards lack what the robot config says the robot has (the side
    pair SSR/SSL): a run would miss readings it counts on.  One line naming
    the URL, the config file and key, and what the board offers."""


class RobotFellError(HardwareError):
    """The simulated world detected instability: pitch beyond the limit, a fall."""


class NoBoardError(HardwareError):
    """A board never answered on a link that opened: the URL was fine, the
    board is off, unplugged, on another port or bus, or not running.  The
    message is one line naming the board and the URL."""

    def __init__(self, url: str, board: str, problem: str) -> None:
        self.url = url
        self.board = board
        super().__init__(f"{url}: {problem}")
