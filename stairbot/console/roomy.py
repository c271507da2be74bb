"""Where the event list goes on a screen taller than the right column needs.

The right column (sensors, motors, phase, link) holds what it holds; on a
tall screen, the rows under it would stay empty while the event list,
under the picture, is squeezed to the left column's width.  There the
console is *roomy*: the right column takes the rows it needs, level with
the picture, and the event list runs the whole width under both.  On a
screen with fewer than ``LOG_MIN_ROWS`` to spare (80x24) the right column
runs the whole height and the event list stays under the picture.

``#main`` is a two-column grid (console.tcss): the picture's column, the
right column, the event list in the cell under the picture; roomy, the
right column spans one row and the event list two columns.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from stairbot.console.widgets.banner import MESSAGE_LINES

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole

LOG_MIN_ROWS = 6
"""The least rows the event list keeps under both columns, roomy."""

SLACK_ROWS = 2
"""Rows the right column's row keeps beyond what its panels need now."""

PICTURE_SHARE = 0.6
"""The share of the rows the picture's row keeps at least, roomy: as it has
beside the event list otherwise (3fr to 2fr)."""


def right_rows(app: StairbotConsole) -> int:
    """The rows the right column's panels need: each one's border and lines."""
    rows = 0
    for panel in (app.sensors, app.motors, app.phase):
        if panel.display:
            rows += panel.outer_size.height
    return rows + 1 + app.link.lines_shown


FAULT_LINES = MESSAGE_LINES
"""The lines a FAULT's message keeps, whatever the screen: the robot cannot
be read or opened, its reason is the news (an operator must read why, whole),
and the link's figures are not live."""


def message_rows(app: StairbotConsole, most: int, *, fault: bool = False) -> int:
    """How many lines the banner's message may take (at most ``most``, at
    least one, or FAULT_LINES for a ``fault``) and leave every line of the
    right column on the screen: the screen's rows less the footer, the
    banner's strip and the right column's panels (80x24: one line; the rest
    of a longer message is in the event list)."""
    rows = app.screen_rows if app.screen_rows is not None else app.size.height
    if app.sensors.outer_size.height == 0:  # not laid out yet: nothing to go by
        return most
    return min(most, max(FAULT_LINES if fault else 1, rows - 2 - right_rows(app)))


class Roomy:
    """The layout of ``#main``, kept as the panels grow: the right column's
    row keeps the most rows its panels have needed since the screen's size
    changed, and SLACK_ROWS more, so a panel that grows by a line or two
    (a motor's commanded speed wrapping) hides nothing under it while the
    layout catches up, and the picture's row does not jump with every
    phase."""

    def __init__(self) -> None:
        self._need = 0

    def reset(self) -> None:
        """The screen's size changed: measure the right column again."""
        self._need = 0

    def arrange(self, app: StairbotConsole) -> None:
        """Lay ``#main`` out for its height now: roomy when the right column
        leaves LOG_MIN_ROWS or more under it (once its panels are laid out)."""
        rows = app.main_area.size.height
        if app.sensors.outer_size.height > 0:
            self._need = max(self._need, right_rows(app) + SLACK_ROWS)
        top = max(self._need, round(rows * PICTURE_SHARE))
        roomy = self._need > 0 and rows - top >= LOG_MIN_ROWS
        main = app.main_area
        main.set_class(roomy, "-roomy")
        main.styles.grid_rows = f"{top} 1fr" if roomy else "3fr 2fr"  # (a change only relays out)
