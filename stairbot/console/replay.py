"""Playing a recording into the console: :class:`ReplayPlayer` moves a
position along the recording's robot time, by the clock it is given times
the chosen speed, and writes what the recording holds up to there into a
:class:`~stairbot.console.state.LiveState` through the writers a live run
uses (``on_read``, ``on_command``, ``on_scene``, ``on_event``,
``on_phase``), so the console's panels draw it as they draw a run.

The clock is injected: nothing here sleeps or reads the wall clock, and a
test that moves its own clock gets the same position every time.  The
values' ages are the recording's: the live state's clock is the position,
so a reading recorded 2 s before it is 2 s old (STALE where the recording
has a gap), however long the replay stood paused.

No robot is opened here, and nothing is ever commanded.
"""

from __future__ import annotations

from collections.abc import Callable

from stairbot.console.history import WINDOW_S
from stairbot.console.state import LiveState
from stairbot.events import EventKind
from stairbot.inputs.config import RobotConfig
from stairbot.recording.pose import DeadReckonedPose
from stairbot.recording.replay_source import ReplaySource, scene_of

SPEEDS: tuple[float, ...] = (0.25, 0.5, 1.0, 2.0, 5.0, 10.0, 50.0)
"""Recording seconds per clock second the operator can pick (+ and -)."""


def speed_name(speed: float) -> str:
    """``0.25×``, ``1×``, ``50×``."""
    return f"{speed:g}×"


class ReplayPlayer:
    """A position in ``source`` that moves by ``clock`` while playing, and the
    live state it writes to (:attr:`state`).  ``config``: the robot the
    recording was made with (sizes for the picture)."""

    def __init__(self, source: ReplaySource, config: RobotConfig,
                 clock: Callable[[], float], *, speed: float = 1.0,
                 playing: bool = True) -> None:
        if speed not in SPEEDS:
            raise ValueError(f"speed {speed!r}; allowed: {', '.join(map(str, SPEEDS))}")
        self.source = source
        self.config = config
        self._clock = clock
        self.speed = speed
        self.start_s, self.end_s = source.start_s, source.end_s
        self.position = self.start_s
        self.playing = playing and self.end_s > self.start_s
        self.rewinds = 0
        """How many times the state was emptied to play again from the start
        (a seek back): the event list the screen shows must be emptied too."""
        self._part = 0  # the part (robot) the state was last named after
        self.state = LiveState(url=self.robot_name, scenario=source.parts[0].scenario,
                               wall=self.now)
        self._ticks_done = 0  # ticks written into the state (the first ones)
        self._events_done = 0
        self._last = clock()
        self._reset()
        self._apply()

    @property
    def robot_name(self) -> str:
        """What the recording says of its robot (the part playing), never as a
        live one."""
        url = self.source.parts[self._part].url
        return f"recorded on {url}" if url else "recorded"

    def part_line(self) -> str:
        """``recorded on sim://, default``, and for a recording of several
        robots which one plays and where its own clock stands."""
        parts, i = self.source.parts, self.source.part_at(self.position)
        part = parts[i]
        out = self.robot_name if i == self._part else (
            f"recorded on {part.url}" if part.url else "recorded")
        if part.scenario:
            out += f", {part.scenario}"
        if len(parts) > 1:
            clock = self.position - part.start_s + (part.first_t or 0.0)
            out += f" · robot {i + 1} of {len(parts)} (its clock {clock:.1f} s)"
        return out

    def now(self) -> float:
        """The position, in the recording's robot time (the values' ages go by it)."""
        return self.position

    # -- the operator's controls --------------------------------------------------
    def update(self) -> None:
        """Move the position by the clock since the last call (while playing),
        stop at the end, and write what came up to there into the state."""
        now = self._clock()
        elapsed, self._last = now - self._last, now
        if self.playing and elapsed > 0:
            self.position = min(self.end_s, self.position + elapsed * self.speed)
            if self.position >= self.end_s:
                self.playing = False
        self._apply()

    def toggle(self) -> None:
        """Pause, or play on (from the start again when at the end)."""
        self.update()
        if self.playing:
            self.playing = False
            return
        if self.position >= self.end_s:
            self.seek(self.start_s)
        self.playing = self.end_s > self.start_s

    def faster(self) -> float:
        return self._set_speed(+1)

    def slower(self) -> float:
        return self._set_speed(-1)

    def _set_speed(self, step: int) -> float:
        self.update()  # the time so far at the old speed
        i = SPEEDS.index(self.speed) + step
        self.speed = SPEEDS[max(0, min(len(SPEEDS) - 1, i))]
        return self.speed

    def seek(self, to_s: float) -> None:
        """Go to ``to_s`` (within the recording), playing or paused as before."""
        self.update()
        to_s = max(self.start_s, min(self.end_s, to_s))
        if to_s < self.position:
            self._reset()
        self.position = to_s
        self._apply()

    def step(self, delta_s: float) -> None:
        self.seek(self.position + delta_s)

    # -- writing the state -----------------------------------------------------------
    def _reset(self) -> None:
        """An empty state, as before the recording's first tick."""
        self.rewinds += 1
        self._part = 0
        part = self.source.parts[0]
        wired = bool(part.url) and not part.url.startswith("sim://") \
            or part.pose_topic == DeadReckonedPose.topic
        self.state.clear_events()
        self.state.set_robot(self.robot_name, part.scenario, not wired, part.stairs,
                             wired=wired)
        self._ticks_done = self._events_done = 0

    def _apply(self) -> None:
        """Write the ticks and events from where the state stands up to the
        position: every event (the log), the ticks of the graphs' window
        (older ones would be dropped at once), the last pose as the picture."""
        src, state = self.source, self.state
        done = src.tick_index(self.position)
        if done > self._ticks_done:
            first = max(self._ticks_done, src.tick_index(self.position - WINDOW_S))
            commanded, framed = None, None
            last = src.ticks[done - 1].part
            if last != self._part:  # another robot of the recording: its name
                self._part = last
                part = src.parts[last]
                self.state.rename(self.robot_name, part.scenario, part.stairs)
            for tick in src.ticks[first:done]:
                if tick.snapshot is not None:
                    state.on_read(tick.snapshot, at=tick.time_s)
                    commanded = tick.commanded
                if tick.frames:
                    framed = tick
            state.on_command(commanded or {})
            if framed is not None:
                scene = scene_of(framed, src.parts[framed.part].stairs, self.config)
                if scene is not None:
                    state.on_scene(scene)
            self._ticks_done = done
        upto = src.event_index(self.position)
        for event in src.events[self._events_done:upto]:
            state.on_event(event)
            if event.kind is EventKind.PHASE:
                flow = event.data.get("flow")
                phase_id = event.data.get("phase")
                state.on_phase(event.phase or event.message,
                               flow if isinstance(flow, str) else "", None,
                               phase_id if isinstance(phase_id, str) else "")
        self._events_done = upto

    def line(self) -> str:
        """``▶ 2× · t = 12.3 s / 85.0 s`` (⏸ paused, ■ at the end)."""
        mark = "▶" if self.playing else "■" if self.position >= self.end_s else "⏸"
        return (f"{mark} {speed_name(self.speed)} · t = {self.position:.1f} s / "
                f"{self.end_s:.1f} s")
