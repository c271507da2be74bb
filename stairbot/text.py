"""Text from outside stairbot as a terminal shows it.

Names, descriptions and paths come from files and the command line, and may
hold control characters: ESC starting an ANSI or OSC sequence (colours, the
window title, a hyperlink, a cursor move), a carriage return that overwrites
the line, a newline that forges another, a bidirectional override that shows
the text in another order.  :func:`printable` writes each of them as an
escape before such text is printed; :func:`check_line` refuses them in a
field that is a name.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from stairbot.errors import InputError

_CONTROL = re.compile(
    "[\x00-\x1f\x7f-\x9f"  # C0 (ESC among them), DEL, C1 (CSI, OSC, ST among them)
    "\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069"  # bidirectional marks and overrides
    "\u2028\u2029]"  # line and paragraph separators
)

LINE_ALLOWED = "printable text on one line (no control characters or escape sequences)"
"""What :func:`check_line` allows, in the words of its error."""


def _escape(match: re.Match[str]) -> str:
    code = ord(match.group())
    return f"\\x{code:02x}" if code <= 0xFF else f"\\u{code:04x}"


def printable(text: object) -> str:
    """``str(text)`` with every control character written as a visible escape
    (ESC as ``\\x1b``, U+202E as ``\\u202e``): nothing in it moves the cursor,
    sets a colour or a title, or starts a new line.  Text without control
    characters comes back unchanged, so applying it twice changes nothing."""
    return _CONTROL.sub(_escape, str(text))


def check_line(value: str | None, source: str, field: str,
               error: type[InputError]) -> None:
    """Refuse a name or description that holds a control character: raises
    ``error`` naming ``source``, ``field`` and what is allowed."""
    if value is None:
        return
    found = _CONTROL.search(value)
    if found is not None:
        raise error(source, field, f"holds the control character {printable(found.group())} "
                    f"at character {found.start()}; allowed: {LINE_ALLOWED}")
