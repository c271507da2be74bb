"""A braille-dot canvas: each terminal cell holds 2 x 4 dots, so a picture gets
twice the columns and four times the rows of the cells it occupies.

Dots are roughly square on a terminal (a cell is about twice as tall as wide),
so one scale serves both axes and the drawing stays to scale.  Every cell has
one colour: the last drawing with the highest priority wins.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from rich.style import Style
from rich.text import Text

# Bit of each dot in a braille cell, indexed [row][column].
_DOT_BITS = ((0x01, 0x08), (0x02, 0x10), (0x04, 0x20), (0x40, 0x80))
_BRAILLE_BASE = 0x2800

Point = tuple[float, float]


class BrailleCanvas:
    """A grid of ``width`` x ``height`` cells addressed in dots (x right, y down)."""

    def __init__(self, width: int, height: int) -> None:
        self.width = max(0, width)
        self.height = max(0, height)
        self._bits = [[0] * self.width for _ in range(self.height)]
        self._style: list[list[tuple[int, Style | str]]] = [
            [(-1, "")] * self.width for _ in range(self.height)
        ]
        self._text: dict[tuple[int, int], tuple[str, Style | str]] = {}

    @property
    def dot_width(self) -> int:
        return self.width * 2

    @property
    def dot_height(self) -> int:
        return self.height * 4

    def plot(self, x: int, y: int, style: Style | str = "", priority: int = 0) -> None:
        """Set one dot; dots off the canvas are ignored."""
        if x < 0 or y < 0:
            return
        cx, cy = x >> 1, y >> 2
        if cx >= self.width or cy >= self.height:
            return
        self._bits[cy][cx] |= _DOT_BITS[y & 3][x & 1]
        if priority >= self._style[cy][cx][0]:
            self._style[cy][cx] = (priority, style)

    def line(self, p0: Point, p1: Point, style: Style | str = "", priority: int = 0) -> None:
        """Draw a straight line between two points given in dots."""
        x0, y0 = p0
        x1, y1 = p1
        steps = int(max(abs(x1 - x0), abs(y1 - y0))) + 1
        for i in range(steps + 1):
            t = i / steps
            self.plot(round(x0 + (x1 - x0) * t), round(y0 + (y1 - y0) * t), style, priority)

    def polyline(self, points: Sequence[Point], style: Style | str = "",
                 priority: int = 0) -> None:
        for a, b in zip(points, points[1:], strict=False):
            self.line(a, b, style, priority)

    def polygon(self, points: Sequence[Point], style: Style | str = "",
                priority: int = 0) -> None:
        """Fill a polygon (even-odd rule) and draw its outline, in dots."""
        if len(points) < 3:
            self.polyline(points, style, priority)
            return
        ys = [p[1] for p in points]
        n = len(points)
        for y in range(max(0, math.floor(min(ys))), min(self.dot_height, math.ceil(max(ys)) + 1)):
            yc = y + 0.5
            xs: list[float] = []
            for i in range(n):
                (ax, ay), (bx, by) = points[i], points[(i + 1) % n]
                if (ay <= yc < by) or (by <= yc < ay):
                    xs.append(ax + (yc - ay) * (bx - ax) / (by - ay))
            xs.sort()
            for left, right in zip(xs[::2], xs[1::2], strict=False):
                for x in range(round(left), round(right) + 1):
                    self.plot(x, y, style, priority)
        self.polyline([*points, points[0]], style, priority)

    def circle(self, centre: Point, radius: float, style: Style | str = "",
               priority: int = 0) -> None:
        """A filled disc (at least one dot)."""
        cx, cy = centre
        r = max(radius, 0.5)
        for y in range(math.floor(cy - r), math.ceil(cy + r) + 1):
            for x in range(math.floor(cx - r), math.ceil(cx + r) + 1):
                if (x - cx) ** 2 + (y - cy) ** 2 <= r * r + 0.25:
                    self.plot(x, y, style, priority)
        self.plot(round(cx), round(cy), style, priority)

    def write(self, cx: int, cy: int, text: str, style: Style | str = "") -> None:
        """Put plain text over the dots, starting at cell (cx, cy)."""
        for i, ch in enumerate(text):
            if 0 <= cx + i < self.width and 0 <= cy < self.height:
                self._text[(cx + i, cy)] = (ch, style)

    def to_text(self) -> Text:
        """The canvas as rich Text, one line per cell row."""
        out = Text(no_wrap=True, overflow="crop")
        for cy in range(self.height):
            for cx in range(self.width):
                label = self._text.get((cx, cy))
                if label is not None:
                    out.append(label[0], label[1])
                    continue
                bits = self._bits[cy][cx]
                if bits:
                    out.append(chr(_BRAILLE_BASE + bits), self._style[cy][cx][1])
                else:
                    out.append(" ")
            if cy < self.height - 1:
                out.append("\n")
        return out
