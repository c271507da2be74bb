"""The side view: the stairs and the robot's three segments, to scale, in
braille dots so the picture gets twice the columns and four times the rows."""

from __future__ import annotations

from rich.text import Text
from textual.widget import Widget

from stairbot.console.canvas import BrailleCanvas
from stairbot.views.side_view import Point, SceneView

SEGMENT_STYLES = ("bold bright_cyan", "bold yellow", "bold magenta")
STAIRS_STYLE = "grey70"
WHEEL_STYLE = "bold white"
MARGIN_M = 0.05
FLOOR_BEHIND_M = 0.3  # floor drawn behind the robot's rear end
TOP_AHEAD_M = 0.6  # landing drawn past the last riser
MIN_ROBOT_DOTS = 12  # "auto" zoom follows the robot when the flight draws it shorter
FOLLOW_DOTS = 14  # the robot's length in dots when following it
ZOOMS = ("auto", "flight", "robot")


def lift_mm(offset_m: float) -> str:
    """A lift's offset in whole millimetres, signed, ``+0`` for what rounds to
    nothing (never ``-0``)."""
    mm = round(offset_m * 1000)
    return f"{mm + 0:+4d}"


class StairsPicture(Widget):
    """Draws the latest :class:`SceneView` scaled to the widget, with a caption
    line: the step each segment stands over and the two lift offsets."""

    DEFAULT_CSS = """
    StairsPicture { height: 1fr; min-height: 5; }
    """

    def __init__(self, *, id: str | None = None) -> None:  # noqa: A002 - Textual's name
        super().__init__(id=id)
        self._scene: SceneView | None = None
        self._stairs: tuple[Point, ...] = ()
        self._lifts: tuple[float, float] | None = None
        self._note = ""
        self._bounds: tuple[float, float, float, float] | None = None
        self._key: object = None
        self.zoom = "auto"
        self.following = False

    def show(self, scene: SceneView | None, stairs: tuple[Point, ...],
             lifts_m: tuple[float, float] | None, note: str = "") -> None:
        """Set what to draw; repaints only when something changed."""
        key = (scene, stairs, lifts_m, note)
        if key == self._key:
            return
        if (scene.stairs if scene else stairs) != (self._scene.stairs if self._scene
                                                    else self._stairs):
            self._bounds = None  # new stairs: fit them afresh
        self._key = key
        self._scene, self._stairs, self._lifts, self._note = scene, stairs, lifts_m, note
        self.refresh()

    # -- geometry ----------------------------------------------------------------
    def _world_bounds(self, view: SceneView) -> tuple[float, float, float, float]:
        """Bounds that only grow while the stairs stay the same, so the picture
        does not jump as the robot moves."""
        rx0, ry0, rx1, ry1 = SceneView(stairs=(), segments=view.segments,
                                       wheels=view.wheels).bounds()
        if not view.segments:
            rx0 = rx1 = view.risers()[0] if view.risers() else 0.0
            ry0 = ry1 = 0.0
        risers = view.risers()
        far = (max(risers) if risers else rx1 + 1.0) + TOP_AHEAD_M
        xs = [min(max(p[0], rx0 - FLOOR_BEHIND_M), far) for p in view.stairs]
        ys = [p[1] for p in view.stairs]
        x0 = min([rx0, *xs]) - MARGIN_M
        x1 = max([rx1, *xs]) + MARGIN_M
        y0 = min([ry0, *ys]) - MARGIN_M / 2
        y1 = max([ry1, *ys]) + MARGIN_M
        if self._bounds is not None:
            b = self._bounds
            x0, y0, x1, y1 = min(x0, b[0]), min(y0, b[1]), max(x1, b[2]), max(y1, b[3])
        self._bounds = (x0, y0, x1, y1)
        return self._bounds

    def render(self) -> Text:
        width, height = self.size.width, self.size.height
        if width < 4 or height < 2:
            return Text("")
        canvas = BrailleCanvas(width, height - 1)
        view = self._scene or SceneView(stairs=self._stairs)
        if view.stairs or view.segments:
            self._draw(canvas, view)
        if self._note:
            canvas.write(0, 0, self._note[:width], "italic")
        out = canvas.to_text()
        out.append("\n")
        out.append_text(self._caption(view, width))
        return out

    def _follow_bounds(self, view: SceneView, dw: int,
                       dh: int) -> tuple[float, float, float, float]:
        """A window that moves with the robot: the robot FOLLOW_DOTS long, a fifth
        of the way in from the left and a sixth of the way up."""
        rx0, ry0, rx1, ry1 = SceneView(stairs=(), segments=view.segments,
                                       wheels=view.wheels).bounds()
        scale = FOLLOW_DOTS / max(rx1 - rx0, 1e-6)
        width, height = dw / scale, dh / scale
        x0 = (rx0 + rx1) / 2 - width / 5
        y0 = ry0 - height / 6
        return (x0, y0, x0 + width, y0 + height)

    def _draw(self, canvas: BrailleCanvas, view: SceneView) -> None:
        dw, dh = canvas.dot_width, canvas.dot_height
        x0, y0, x1, y1 = self._world_bounds(view)
        scale = min((dw - 1) / max(x1 - x0, 1e-6), (dh - 1) / max(y1 - y0, 1e-6))
        self.following = False
        if view.segments:
            rx0, _, rx1, _ = SceneView(stairs=(), segments=view.segments).bounds()
            if self.zoom == "robot" or (self.zoom == "auto"
                                        and (rx1 - rx0) * scale < MIN_ROBOT_DOTS):
                x0, y0, x1, y1 = self._follow_bounds(view, dw, dh)
                scale = min((dw - 1) / (x1 - x0), (dh - 1) / (y1 - y0))
                self.following = True

        def to_dots(p: Point) -> Point:
            return ((p[0] - x0) * scale, (dh - 1) - (p[1] - y0) * scale)

        canvas.polyline([to_dots(p) for p in view.stairs], STAIRS_STYLE, 1)
        for i, poly in enumerate(view.segments):
            style = SEGMENT_STYLES[min(i, len(SEGMENT_STYLES) - 1)]
            canvas.polygon([to_dots(p) for p in poly], style, 3)
        for x, y, r in view.wheels:
            canvas.circle(to_dots((x, y)), r * scale, WHEEL_STYLE, 4)

    def cycle_zoom(self) -> str:
        """auto -> whole flight -> follow the robot -> auto; returns the new mode."""
        self.zoom = ZOOMS[(ZOOMS.index(self.zoom) + 1) % len(ZOOMS)]
        self.refresh()
        return self.zoom

    def _caption(self, view: SceneView, width: int) -> Text:
        out = Text(no_wrap=True, overflow="ellipsis")
        if view.segments:
            steps = view.segment_steps()
            out.append("steps ")
            for i, n in enumerate(steps):
                if i:
                    out.append("|", "dim")
                out.append(str(n), SEGMENT_STYLES[min(i, 2)])
            out.append("  ")
        if self._lifts is not None:
            mtf, mtb = self._lifts
            out.append("MTF ", SEGMENT_STYLES[0])
            out.append(f"{lift_mm(mtf)} mm  ")
            out.append("MTB ", SEGMENT_STYLES[2])
            out.append(f"{lift_mm(mtb)} mm")
        if self.following and out.cell_len + 8 <= width:
            out.append("  zoomed", "dim")
        out.truncate(width)
        return out
