"""The top view (key ``t``, in the side view's place): the stairwell seen from
above in flight 1's frame -- flight 1 runs to the right as in the side view,
its left side up -- and the robot's footprint on it, in braille dots.

Flight 1's risers are lines across it; a quarter-turn landing's walls, the
second flight's risers (up the screen for a left turn, down for a right one)
and any side walls are drawn as the simulation holds them
(stairbot/views/top_view.py).  The first wall contact the simulation reported is
written in red under the picture, and the face it names is drawn red.
"""

from __future__ import annotations

import textwrap

from rich.text import Text
from textual.widget import Widget

from stairbot.console.canvas import BrailleCanvas
from stairbot.console.widgets.picture import SEGMENT_STYLES
from stairbot.hardware import Point
from stairbot.views.top_view import (
    RISER2,
    WALL,
    PlanLine,
    RobotShape,
    TopPlan,
    TopPose,
    contact_parts,
    footprint,
    nose,
)

LINE_STYLES = {WALL: "bold white", RISER2: "grey50"}
RISER_STYLE = "grey70"
CONTACT_STYLE = "bold white on red"
CONTACT_LINE_STYLE = "bold red"
NOSE_STYLE = "bold white"
NOSE_M = 0.06  # the heading mark's length past the front face
ZOOMS = ("auto", "flight", "robot")
MIN_ROBOT_DOTS = 8  # "auto" follows the robot when the whole stairwell draws it shorter
FOLLOW_ACROSS_M = 0.15  # following: the flight's width and this either side fill the height
FOLLOW_DOTS = 14  # "robot" zoom: the robot's length in dots
MAX_CONTACT_LINES = 3


class TopViewPicture(Widget):
    """Draws a :class:`TopPlan` and the footprint at a :class:`TopPose`,
    scaled to the widget, with a caption: the pose in words, the wall
    contact; or, with nothing to draw, why."""

    DEFAULT_CSS = """
    TopViewPicture { height: 1fr; min-height: 5; }
    """

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002 - Textual's name
        super().__init__(id=id)
        self._plan: TopPlan | None = None
        self._pose: TopPose | None = None
        self._shape: RobotShape | None = None
        self._note = ""
        self._stale = False
        self._key: object = None
        self.zoom = "auto"
        self.following = False

    def show(self, plan: TopPlan | None, pose: TopPose | None, shape: RobotShape,
             note: str = "", stale: bool = False) -> None:
        """Set what to draw (``note``: why there is nothing, shown instead of the
        caption; ``stale``: the pose is not live); repaints only on a change."""
        key = (plan, pose, shape, note, stale)
        if key == self._key:
            return
        self._key = key
        self._plan, self._pose, self._shape = plan, pose, shape
        self._note, self._stale = note, stale
        self.refresh()

    def cycle_zoom(self) -> str:
        """auto -> the whole stairwell -> follow the robot -> auto; returns the new mode."""
        self.zoom = ZOOMS[(ZOOMS.index(self.zoom) + 1) % len(ZOOMS)]
        self.refresh()
        return self.zoom

    # -- drawing --------------------------------------------------------------------
    def render(self) -> Text:
        width, height = self.size.width, self.size.height
        if width < 4 or height < 2:
            return Text("")
        caption = self._caption(width)
        rows = max(1, height - len(caption))
        canvas = BrailleCanvas(width, rows)
        plan, pose, shape = self._plan, self._pose, self._shape
        if plan is not None and not self._note:
            self._draw(canvas, plan, pose, shape)
        out = canvas.to_text()
        for line in caption[: height - rows]:
            out.append("\n")
            out.append_text(line)
        return out

    def _draw(self, canvas: BrailleCanvas, plan: TopPlan, pose: TopPose | None,
              shape: RobotShape | None) -> None:
        dw, dh = canvas.dot_width, canvas.dot_height
        segments = footprint(pose, shape) if pose is not None and shape is not None else ()
        x0, y0, x1, y1 = self._window(plan, pose, shape, segments, dw, dh)
        scale = min((dw - 1) / max(x1 - x0, 1e-6), (dh - 1) / max(y1 - y0, 1e-6))

        def to_dots(p: Point) -> Point:
            return ((p[0] - x0) * scale, (dh - 1) - (p[1] - y0) * scale)

        touched = contact_parts(pose.wall_contact) if pose and pose.wall_contact else None
        for line in plan.lines:
            a, b = _clip(line, (x0, y0, x1, y1))
            if a is None or b is None:
                continue
            if touched is not None and line.name == touched[1]:
                canvas.line(to_dots(a), to_dots(b), CONTACT_LINE_STYLE, 2)
            else:
                canvas.line(to_dots(a), to_dots(b), LINE_STYLES.get(line.kind, RISER_STYLE), 1)
        for i, corners in enumerate(segments):
            canvas.polygon([to_dots(p) for p in corners], SEGMENT_STYLES[i], 3)
        if pose is not None and shape is not None:
            tip, ahead = nose(pose, shape, NOSE_M)
            canvas.line(to_dots(tip), to_dots(ahead), NOSE_STYLE, 4)

    def _window(self, plan: TopPlan, pose: TopPose | None, shape: RobotShape | None,
                segments: tuple[tuple[Point, ...], ...], dw: int,
                dh: int) -> tuple[float, float, float, float]:
        """The part of the stairwell drawn: the whole of it (with the robot), or a
        window centred on the robot (``following``)."""
        x0, y0, x1, y1 = plan.bounds
        for corners in segments:
            for x, y in corners:
                x0, y0, x1, y1 = min(x0, x), min(y0, y), max(x1, x), max(y1, y)
        self.following = False
        if pose is None or shape is None:
            return x0, y0, x1, y1
        length = sum(shape.lengths)
        whole = min((dw - 1) / (x1 - x0), (dh - 1) / (y1 - y0))
        if self.zoom == "flight" or (self.zoom == "auto" and length * whole >= MIN_ROBOT_DOTS):
            return x0, y0, x1, y1
        self.following = True
        if self.zoom == "robot":
            scale = FOLLOW_DOTS / length
        else:  # the stairwell's width top to bottom (the robot not shorter than the least)
            scale = max((dh - 1) / (plan.across + 2 * FOLLOW_ACROSS_M), MIN_ROBOT_DOTS / length)
        w, h = (dw - 1) / scale, (dh - 1) / scale
        return pose.x - w / 2, pose.y - h / 2, pose.x + w / 2, pose.y + h / 2

    def _caption(self, width: int) -> list[Text]:
        """The lines under the picture: the note alone; or the wall contact (red,
        whole) and the pose in words."""
        if self._note:
            return [Text(line, "italic") for line in textwrap.wrap(self._note, width)[:2]]
        lines: list[Text] = []
        pose = self._pose
        if pose is not None and pose.wall_contact:
            words = f"WALL CONTACT: {pose.wall_contact}"
            wrapped = textwrap.wrap(words, width)
            if len(wrapped) > MAX_CONTACT_LINES:
                wrapped = textwrap.wrap(words, width, max_lines=MAX_CONTACT_LINES,
                                        placeholder="…")
            lines.extend(Text(line, CONTACT_STYLE) for line in wrapped)
        out = Text(no_wrap=True, overflow="ellipsis")
        if self._stale:
            out.append("STALE ", "bold red")
        if pose is None:
            out.append("no pose", "italic")
        else:
            out.append(f"x {pose.x:+.2f} y {pose.y:+.2f} m  yaw {pose.yaw_deg:+.0f}°")
            out.append(f"  flight {pose.flight}", "bold" if pose.flight != 1 else "")
        if self.following and out.cell_len + 8 <= width:
            out.append("  zoomed", "dim")
        out.truncate(width)
        lines.append(out)
        return lines


def _clip(line: PlanLine, box: tuple[float, float, float, float]
          ) -> tuple[Point | None, Point | None]:
    """The part of an axis-aligned line inside the box; (None, None): none."""
    (ax, ay), (bx, by) = line.a, line.b
    x0, y0, x1, y1 = box
    lo_x, hi_x = max(min(ax, bx), x0), min(max(ax, bx), x1)
    lo_y, hi_y = max(min(ay, by), y0), min(max(ay, by), y1)
    if lo_x > hi_x or lo_y > hi_y:
        return None, None
    return (lo_x, lo_y), (hi_x, hi_y)
