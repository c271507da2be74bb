"""The distance sensors: value and status, and whether each pair that must
agree (front right/left, back right/left) agrees within the standing rule's
tolerance at its distance (what the robot itself accepts), debounced as
perception debounces its kinds.
Operator words first (``front R``), the seed's names (SFR...) beside them,
dimmer.  On a robot with the side pair (its config's ``[sensors]
side_model``, or a reading that carries SSR/SSL) one line more, ``side``:
SSR (right) and SSL (left) beside each other, values in metres; they look
opposite ways, so no verdict joins them.  A robot without the pair shows no
such line.

Four lines (five), a bracket joining each pair to its verdict: two lines
fewer than a verdict line per pair, which an 80x24 screen needs for the
panels below (the side pair's one line takes the row the link panel has to
spare there).  The title says when the values were read; stale ones are
dimmed and marked (:mod:`stairbot.console.freshness`), and a sensor whose
own measurement is older than that says ``old`` instead of ``ok`` -- the
side pair's as every other's.
"""

from __future__ import annotations

from rich.text import Text
from textual.widgets import Static

from stairbot.console.freshness import STALE_S, age_key, is_stale, titled, without_status
from stairbot.control.perception import CONFIRM
from stairbot.control.tolerances import standing_tolerance
from stairbot.hardware import SIDE_SENSORS, SensorId, SensorReading, SensorStatus, Snapshot
from stairbot.inputs.config import RobotConfig

PAIRS = ((SensorId.SFR, SensorId.SFL), (SensorId.SBR, SensorId.SBL))
NAMES = {SensorId.SFR: "front R", SensorId.SFL: "front L", SensorId.SBR: "back R",
         SensorId.SBL: "back L", SensorId.SSR: "side R", SensorId.SSL: "side L"}
READING_WIDTH = 25  # "front R SFR 0.265 m ERROR"


def _value(line: Text, r: SensorReading | None, unit: str = " m") -> None:
    """A reading's value and status word: ``0.265 m ok``, ``out`` (of range:
    the value is the sensor's limit), ``old`` (not measured for STALE_S),
    ``ERROR``, ``none`` (no reading of it)."""
    blank = " " * len(unit)
    if r is None:
        line.append(f"  —  {blank} none", "dim")
    elif r.status is SensorStatus.ERROR:
        line.append(f"  —  {blank} ", "dim")
        line.append("ERROR", "bold red")
    else:
        line.append(f"{r.distance_m:5.3f}{unit} ")
        if r.age_s > STALE_S:  # the sensor has not measured for that long
            line.append("old", "bold yellow")
        elif r.status is SensorStatus.OUT_OF_RANGE:
            line.append("out", "yellow")
        else:
            line.append("ok", "green")


def _reading(sensor: SensorId, r: SensorReading | None, lost: bool = False) -> Text:
    """``lost``: the run limps home without it (its partner stands in): its
    value means nothing to the program, so none is shown."""
    line = Text(f"{NAMES[sensor]:<7} ", style="bold")
    line.append(f"{sensor.value} ", "dim")
    if lost:
        line.append("  —     ", "dim")
        line.append("LOST", "bold red")
    else:
        _value(line, r)
    line.pad_right(READING_WIDTH - line.cell_len)
    return line


SIDE_CELL = 15  # "SSR 0.620 ERROR"


def _side_line(sensors: dict[SensorId, SensorReading]) -> Text:
    """The side pair on one line: ``side  SSR 0.620 ok     SSL 1.300 out``."""
    line = Text("side  ", style="bold")
    for sensor in SIDE_SENSORS:
        cell = Text(f"{sensor.value} ", "dim")
        _value(cell, sensors.get(sensor), unit="")
        cell.pad_right(SIDE_CELL - cell.cell_len + 2)
        line.append_text(cell)
    line.rstrip()
    return line


def pair_verdict(a: SensorReading | None, b: SensorReading | None,
                 tolerance: float) -> tuple[Text, Text]:
    """Two short texts, beside each sensor of a pair: ``agree`` / ``Δ 1/17 mm``,
    ``DIFFER`` / ``Δ 24/17 mm`` (the difference, and the tolerance it is
    judged by), ``both out`` / ``of range``, ``cannot`` / ``compare``."""
    if a is None or b is None or not a.ok or not b.ok:
        if (a is not None and b is not None and a.status is SensorStatus.OUT_OF_RANGE
                and b.status is SensorStatus.OUT_OF_RANGE):
            return Text("both out", "yellow"), Text("of range", "yellow")
        return Text("cannot", "yellow"), Text("compare", "yellow")
    delta_mm = abs(a.distance_m - b.distance_m) * 1000
    shown = f"Δ {delta_mm:.0f}" if delta_mm < 99.5 else "Δ>99"
    delta = Text(f"{shown}/{tolerance * 1000:.0f} mm", "dim")
    if delta_mm <= tolerance * 1000:
        return Text("agree", "bold green"), delta
    return Text("DIFFER", "bold white on red"), delta


def pair_tolerance_m(config: RobotConfig, a: SensorReading | None, b: SensorReading | None,
                     back: bool) -> float:
    """How far the pair may differ and still agree: the standing rule's own
    tolerance (:func:`~stairbot.control.tolerances.standing_tolerance`) at
    the nearer reading -- what the robot itself accepts of its sensors'
    noise; ``equal_tolerance`` when there is no reading to size it by."""
    near = [r.distance_m for r in (a, b) if r is not None and r.ok]
    if not near:
        return config.algorithm.equal_tolerance
    return standing_tolerance(config, min(near), back=back)


class SensorPanel(Static):
    """Four sensor lines, each pair bracketed with its verdict; the side
    pair's line after them on a robot that has it.  A pair's verdict
    (agree, DIFFER, ...) changes only once CONFIRM readings in a row say
    the new one, as perception's kinds do: noise the robot accepts does not
    make it flicker."""

    DEFAULT_CSS = "SensorPanel { height: auto; }"

    def __init__(self, config: RobotConfig, *, side_pair: bool = False,
                 id: str | None = None) -> None:  # noqa: A002
        """``side_pair``: the robot has SSR/SSL (its config says so); their
        line shows then, and whenever a reading carries them."""
        super().__init__(id=id)
        self.config = config
        self.side_pair = side_pair
        self._last: object = ()
        self._verdicts: dict[SensorId, _Debounced] = {a: _Debounced() for a, _b in PAIRS}
        self.border_title = titled("sensors", None)

    def show(self, snap: Snapshot | None, age_s: float | None = None,
             lost: tuple[str, ...] = ()) -> None:
        """``age_s``: wall seconds since ``snap`` was read (None: never);
        ``lost``: the sensors a limp home goes without (their pair runs on
        the other: its verdict says which)."""
        sensors = dict(snap.sensors) if snap is not None else {}
        key = (sensors, age_key(age_s), lost)
        if key == self._last:
            return
        self._last = key
        self.border_title = titled("sensors", age_s)
        stale = is_stale(age_s)
        self.set_class(stale, "-stale")
        lines = []
        reading_time = None if snap is None else snap.time_s
        for back, (a, b) in enumerate(PAIRS):
            ra, rb = sensors.get(a), sensors.get(b)
            top, bottom = self._verdicts[a].see(
                pair_verdict(ra, rb, pair_tolerance_m(self.config, ra, rb, bool(back))),
                reading_time)
            if stale:  # whether the pair agrees now is not known
                top, bottom = Text("—"), Text()
            gone = [s for s in (a, b) if s.value in lost]
            if len(gone) == 1:  # the pair runs on its survivor
                survivor = b if gone[0] is a else a
                top, bottom = Text("runs on", "bold yellow"), Text(survivor.value, "bold yellow")
            for sensor, bracket, verdict in ((a, " ┐ ", top), (b, " ┘ ", bottom)):
                line = _reading(sensor, sensors.get(sensor), sensor.value in lost)
                line.append(bracket, "dim")
                line.append_text(verdict)
                lines.append(line)
        if self.side_pair or any(s in sensors for s in SIDE_SENSORS):
            lines.append(_side_line(sensors))
        if stale:
            lines = [without_status(line) for line in lines]
        self.update(Text("\n").join(lines))


_JUDGED = {"agree", "DIFFER"}


class _Debounced:
    """A pair's verdict as shown: agree and DIFFER give way to each other only
    once CONFIRM readings in a row say so (readings the panel is shown, each
    counted once by its robot time); any other verdict (cannot compare, both
    out of range) shows at once."""

    def __init__(self) -> None:
        self.shown: tuple[Text, Text] | None = None
        self.candidate = ""  # a verdict other than the one shown, and its readings in a row
        self.run = 0
        self.at: float | None = None  # the robot time of the last reading counted

    def see(self, verdict: tuple[Text, Text], reading_time: float | None) -> tuple[Text, Text]:
        word = verdict[0].plain
        new_reading = reading_time != self.at
        self.at = reading_time
        if self.shown is None or word == self.shown[0].plain \
                or not {word, self.shown[0].plain} <= _JUDGED:
            # the verdict shown (its figures as they stand now), or a pair that
            # can or cannot be compared now: shown at once, no change pending
            self.shown, self.candidate, self.run = verdict, "", 0
            return verdict
        if new_reading:
            self.run = self.run + 1 if word == self.candidate else 1
            self.candidate = word
        if word == self.candidate and self.run >= CONFIRM:
            self.shown, self.candidate, self.run = verdict, "", 0
        return self.shown
