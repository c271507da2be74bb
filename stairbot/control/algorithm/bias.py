"""Bias: a distance sensor that keeps measuring but reads wrong by a constant
offset (not in the seed, which has no sensor faults).

Two sensors of a pair that disagree cannot say which of them is wrong; the
host knows more than the pair: how far the drive moved and turned (the
odometer), and when.  A bias that sets in is a *jump*: one sensor's reading
moves by more than the motion since explains, while its partner's follows
the motion.  :class:`BiasWatch` looks at every tick's filtered readings,
pair by pair, and finds such onsets:

* each reading is *compensated* for the motion the host knows: a front
  sensor looks along the drive, so its reading plus the odometer stays put
  while the robot drives at a riser, and turning left lengthens SFL and
  shortens SFR by front_lateral per radian (the odometer's yaw); a back
  sensor looks down, and driving on a floor does not move what it reads;
* the compensated readings' means over a window (:data:`WINDOW_SETTLES`
  filter settle times) are compared with their means over the window
  before it, a settle time earlier (the gap the filter's median takes to
  come round to a new level): the pair's difference *steps* when they
  differ by more than :data:`STEP_SIGMAS` of the pair's tolerance
  (:func:`~stairbot.control.tolerances.pair_tolerance`);
* a step is an *onset* of the one sensor that moved when its partner's
  compensated reading held (it moved less than ATTRIBUTE_SHARE of the step):
  a front cone seeing over a riser, a back pair crossing an edge, a lift
  moving segment 3 move both, and name nobody.  A later step of the partner
  the same way (both saw the world change) cancels it.

An onset is evidence, not yet a verdict.  A sensor is *judged* biased, and
reads as ERROR from then on (:meth:`BiasWatch.marked`), only where the
evidence decides something:

* at the end of the standing rule's wait, when the pair it watches still
  disagrees by what the onsets say (within the standing tolerance, or
  MATCH_SHARE of the disagreement): the onset names the sensor;
* in calibration, facing a riser (its check, the squaring turn, closing
  in, case 3's probe): the robot steers by the pair's difference there,
  and a squaring turn that goes on to square up to one sensor's offset
  leaves it askew by atan(offset / (2 front_lateral)) (17 deg for 3 cm),
  so a front onset there is judged at once.

A judged sensor reads as ERROR: the controller stops the robot and treats
it as lost (:mod:`~stairbot.control.algorithm.limp`): on the floor where
the program began the run ends on it; elsewhere a degraded stop, and with
the operator's consent the partner stands in for it on the way home.
Where no onset names one of two sensors that disagree, the standing rule
ends the program, as it always has.

Pure Python, on the controller's clock (the snapshots' times); it keeps no
state in the context (a resumed run starts with no evidence).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

from stairbot.control.algorithm import motion
from stairbot.control.algorithm.bias_evidence import (
    MountHeights,
    Onset,
    Onsets,
    Reference,
    Sample,
    Step,
    Unconfirmed,
)
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.edge_measure import floor_tolerance
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import Purpose
from stairbot.control.algorithm.phases import BY_VALUE, Phase
from stairbot.control.algorithm.texts import bias as say
from stairbot.control.tolerances import pair_tolerance, settle_s, standing_tolerance
from stairbot.hardware import (
    BACK_SENSORS,
    FRONT_SENSORS,
    WHEEL_MOTORS,
    MotorId,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.config import RobotConfig

MIN_WINDOW_TICKS = 5
"""The gap between the two windows whose means are compared spans the pair's
settle time (:func:`~stairbot.control.tolerances.settle_s`: the filter's
median comes round to a new level within it), and at least this many
ticks."""
WINDOW_SETTLES = 2.0
"""Each of the two windows spans this many settle times: long enough that
its mean is quieter than a tick by about the square root of the
measurements it holds."""
STEP_SIGMAS = 1.0
"""A step counts when the pair's difference moves by more than this many of
its pair tolerance (itself four sigmas of one tick's difference, so more
sigmas of two windows' means): a fault-free run must not take its noise for
an onset, and the next window must bear an onset out before it counts."""
MAX_ONSET_M = 0.08
"""A one-sided step larger than this is one sensor crossing an edge before its
partner (the back pair askew over a drop, a front cone over a riser): not
an onset.  (A bias as large is judged by the other evidence, or not at all.)"""
ATTRIBUTE_SHARE = 0.4
"""A step is one sensor's onset when its partner's compensated reading moved
less than this share of the step (or half the threshold, if more)."""
MATCH_SHARE = 0.35
"""Evidence matches the standing rule's disagreement within the standing
tolerance, or this share of the disagreement if more."""
WARM_SETTLES = 3.0
"""A pair is watched from this many of its settle times into the run on."""
STILL_M = 0.001
STILL_RAD = math.radians(0.2)

STEERS_BY_THE_FRONT = frozenset({Phase.CAL_CHECK, Phase.CAL_CLOSE_IN, Phase.CAL_PROBE,
                                 Phase.CAL_TURN})
"""The calibration phases in which the robot squares up to a riser by the
front pair's difference: its onsets are judged at once there."""
_RISER_PURPOSES = (Purpose.START, Purpose.ASCENT, Purpose.DESCENT)
STEERS_BY_THE_BACK = frozenset({Phase.DESCENT_BACK_OFF, Phase.DESCENT_BACK_TO_EDGE})
"""Descent 1's phases, in which the back pair finds the edge (where both read
the drop): its onsets are judged at once there."""
ON_A_SURFACE = frozenset({
    Phase.CAL_CLOSE_IN, Phase.DESCENT_BACK_OFF, Phase.ASCENT_APPROACH, Phase.ASCENT_APPROACH_TURNS,
    Phase.ASCENT_LIFT_FIRST, Phase.ASCENT_LIFT_FIRST_MORE, Phase.ASCENT_DRIVE_FIRST,
    Phase.DESCENT_DRIVE_SECOND, Phase.DESCENT_LOWER_SECOND, Phase.DESCENT_DRIVE_FIRST,
    Phase.DESCENT_LOWER_FIRST, Phase.DESCENT_FINISH})
"""The phases in which segment 3 stands on a surface and moves on it: its
sensors read their mount height (BACK_CLEARANCE), until one reads a drop
(DROP_M more: descent 1 backs off towards the edge)."""
DROP_M = 0.05
HANGING = frozenset({Phase.ASCENT_LIFT_THIRD, Phase.DESCENT_LOWER_THIRD})
"""The phases in which MTB lifts or lowers segment 3 in the air: what its
sensors read moves with MTB's counter."""
ON_THE_TREAD = frozenset({Phase.DESCENT_BACK_OFF, Phase.DESCENT_BACK_TO_EDGE,
                          Phase.DESCENT_LOWER_THIRD, Phase.DESCENT_DRIVE_SECOND,
                          Phase.DESCENT_LOWER_SECOND, Phase.DESCENT_DRIVE_FIRST})
"""Descent 1 to 5 of a step: segment 1 stands on its tread and the front pair
faces the riser above it, whose place the tab measured on the way up and
the odometer since say (descent 6 lowers the pair past the tread)."""
ON_THE_FLOOR = frozenset({Phase.DESCENT_FINISH, Phase.DESCENT_FINISH_FLOOR})


class BiasWatch:
    """Gathers the evidence and judges biased sensors (see the module
    docstring).  One per controller, told every tick's filtered snapshot."""

    def __init__(self, cfg: RobotConfig) -> None:
        self._cfg = cfg
        self._lateral = cfg.sensors.front_lateral
        self._metres_per_turn = cfg.wheel_circumference / len(WHEEL_MOTORS)
        self._wheel_m = cfg.wheel_circumference
        self._near = (cfg.sensors.range(False)[0], cfg.sensors.range(True)[0])
        self._pairs: list[Onsets] = []
        for back, (right, left) in ((False, FRONT_SENSORS), (True, BACK_SENSORS)):
            ticks = max(MIN_WINDOW_TICKS, round(settle_s(cfg, back) / cfg.algorithm.tick))
            self._pairs.append(Onsets(right, left, back, round(WINDOW_SETTLES * ticks), ticks))
        self._warm = [WARM_SETTLES * settle_s(cfg, back) for back in (False, True)]
        """Robot time from which each pair is watched."""
        self._mount = MountHeights(cfg.BACK_CLEARANCE)
        self._lift_m = cfg.motors.lift_travel_per_turn
        self._yaw_per_turn = motion.turn_yaw_rad(cfg, 0.5)  # twist is half MWR less MWL
        self._least_step = STEP_SIGMAS * cfg.algorithm.equal_tolerance
        """No pair tolerance is less than equal_tolerance: a step below this is none."""
        self._risers: dict[int, Reference] = {}
        """Where the riser ahead of each tread stood by the odometer (0: the floor's)."""
        self._judged: dict[SensorId, str] = {}

    @property
    def judged(self) -> dict[SensorId, str]:
        """The sensors judged biased, each with the evidence in words."""
        return self._judged

    def why(self, sensor: SensorId, otherwise: str | None = None) -> str:
        """Why ``sensor`` reads as ERROR: judged biased, else ``otherwise``
        (perception's reason), else it reports an error."""
        return self._judged.get(sensor) or otherwise or "reports an error"

    def all_judged(self, sensors: Sequence[SensorId]) -> bool:
        """Whether every one of ``sensors`` is judged biased: no use waiting
        for them to come back."""
        return all(s in self._judged for s in sensors)

    def onsets(self, back: bool) -> list[Onset]:
        """The pair's onsets not cancelled, oldest first."""
        return list(self._pairs[1 if back else 0].found)

    def see(self, snap: Snapshot, ctx: Context) -> Snapshot:
        """Take this tick's filtered snapshot (before any stand-in), judge
        where the evidence decides (module docstring); the snapshot with
        every sensor judged biased reading as ERROR."""
        phase = BY_VALUE[ctx.phase]
        motors = snap.motors
        odometer = sum(motors[m].turns for m in WHEEL_MOTORS) * self._metres_per_turn
        yaw = (motors[MotorId.MWR].turns - motors[MotorId.MWL].turns) * self._yaw_per_turn
        front, back = self._pairs
        self._track(front, snap, odometer, yaw, 0.0)
        surface = phase in ON_A_SURFACE and not ctx.from_top
        self._track(back, snap, odometer, yaw,
                    motors[MotorId.MTB].turns * self._lift_m if phase in HANGING else 0.0, surface)
        self._on_a_surface(snap, surface)
        if ctx.number_of_steps not in self._risers:
            self._references(snap, ctx, odometer, yaw)
        if phase is Phase.PAUSED and ctx.pause is not None:
            self._judge_pause(snap, ctx, odometer, yaw)
        elif phase in STEERS_BY_THE_FRONT and not ctx.from_top:
            family = ctx.family
            if isinstance(family, Calibration) and family.purpose in _RISER_PURPOSES:
                self._judge_at_once(front, snap, None)
        elif phase in STEERS_BY_THE_BACK:
            self._judge_at_once(back, snap, None)
        elif phase is Phase.DESCENT_LOWER_THIRD:
            # lowered until the pair's mean reads BACK_CLEARANCE within the floor
            # tolerance: one sensor off by twice that never gets there
            self._judge_at_once(back, snap, 2 * floor_tolerance(self._cfg))
        if not self._judged:
            return snap
        sensors = dict(snap.sensors)
        for sid in self._judged:
            r = sensors[sid]
            sensors[sid] = SensorReading(r.distance_m, SensorStatus.ERROR, r.age_s)
        return replace(snap, sensors=sensors)

    # -- gathering ------------------------------------------------------------------------
    def _distance(self, r: SensorReading, back: bool) -> float | None:
        """A reading's distance: OK, or too near to measure (its clamp, the
        nearest it can tell); None for an error or nothing in range."""
        if r.ok:
            return r.distance_m
        if r.status is SensorStatus.OUT_OF_RANGE and r.distance_m <= self._near[back] + 1e-9:
            return r.distance_m
        return None

    def _references(self, snap: Snapshot, ctx: Context, odometer: float, yaw: float) -> None:
        """Note the start position (tread 0), and each tab_length_to_edge the
        ascent stores (the tread it climbed onto), as the odometer places them,
        when the pair read them alike."""
        risers = self._risers
        if ctx.number_of_steps == 0 and ctx.start.reading is not None \
                and ctx.start.wheel is not None and ctx.climb_twist[0] is not None:
            risers[0] = Reference(ctx.start.reading + ctx.start.wheel * self._wheel_m,
                                  motion.turn_yaw_rad(self._cfg, ctx.climb_twist[0]), 0)
        k = ctx.number_of_steps
        if 0 < k <= len(ctx.tab_length_to_edge) and k not in risers and ctx.landing.step is None:
            tab = ctx.tab_length_to_edge[k - 1]
            diff = motion.pair_difference(snap, self._cfg)
            if tab is not None and diff is not None \
                    and abs(diff) <= standing_tolerance(self._cfg, tab):
                risers[k] = Reference(tab + odometer, yaw, k)

    def _on_a_surface(self, snap: Snapshot, surface: bool) -> None:
        if not surface:
            self._mount.end()
            return
        r, left = snap.sensors[SensorId.SBR], snap.sensors[SensorId.SBL]
        dr, dl = self._distance(r, True), self._distance(left, True)
        drop = self._cfg.BACK_CLEARANCE + DROP_M
        if dr is None or dl is None or max(dr, dl) > drop:
            self._mount.end()
        else:
            self._mount.add(dr, dl, not r.ok, not left.ok)

    def _track(self, track: Onsets, snap: Snapshot, odometer: float, yaw: float,
               lifted_m: float, surface: bool = True) -> None:
        """One pair's tick (``surface``: for the back pair, segment 3 stands on
        a surface, away from an edge; ``lifted_m``: what MTB lifted it)."""
        sensors, back = snap.sensors, track.back
        r, left = sensors[track.right], sensors[track.left]
        dr, dl = self._distance(r, back), self._distance(left, back)
        if dr is None or dl is None or track.right in self._judged \
                or track.left in self._judged or (not back and max(dr, dl)
                                                  >= self._cfg.LENGTH_OF_INFINITY):
            if track.pending is not None:  # a step seen before one of them stopped reading
                self._decide(track, track.pending)
            if track.unconfirmed is not None:
                self._confirm(track, True)
            track.clear()
            return
        if snap.time_s < self._warm[back]:
            return  # the filter's first medians are of its first few measurements
        if not back:  # looking along the drive: plus the odometer, less the turn
            turn = self._lateral * yaw
            dr, dl = dr + odometer + turn, dl + odometer - turn
        else:  # looking down from segment 3: less what MTB lifted it
            dr, dl = dr - lifted_m, dl - lifted_m
        moved = track.add((snap.time_s, dr, dl, odometer, yaw, not r.ok, not left.ok, surface))
        waiting = track.unconfirmed
        if waiting is not None and len(track.buf) == track.window:
            level = sum(x[2] - x[1] for x in track.buf) / track.window
            self._confirm(track, abs(level - waiting.level) <= waiting.share)
        if moved is None:
            return
        moved_r, moved_l = moved
        step = moved_l - moved_r
        pending = track.pending
        if pending is None and abs(step) <= self._least_step:
            return  # the common case, kept short
        near = min(r.distance_m, left.distance_m)
        threshold = STEP_SIGMAS * pair_tolerance(self._cfg, near, back=back)
        if abs(step) > threshold and (pending is None or abs(step) >= pending.size):
            at = track.buf[track.window + track.gap // 2][0]
            track.pending = Step(abs(step), moved_r, moved_l, threshold, at)
            return
        if pending is not None:
            self._decide(track, pending)
            track.clear()  # the pair's new level is the next windows' first

    def _decide(self, track: Onsets, step: Step) -> None:
        """Attribute a step to the sensor that moved, if its partner held; the
        onset counts once the next window bears it out (:meth:`_confirm`)."""
        if step.size > MAX_ONSET_M:
            return  # one sensor crossed an edge before its partner: not a bias
        share = max(ATTRIBUTE_SHARE * step.size, step.threshold / 2)
        before, after = track.windows()
        if track.back and not all(x[7] for x in before + after) \
                and max(x[3] for x in before + after) - min(x[3] for x in before + after) > STILL_M:
            return  # driving segment 3 near an edge: a cone crosses it a little at a time
        what = _motion(before, after)
        if abs(step.moved_right) <= share:
            near = any(s[6] for s in before) or any(s[6] for s in after)
            onset = Onset(track.left, step.moved_left, step.moved_right, step.at_s, what, near)
        elif abs(step.moved_left) <= share:
            near = any(s[5] for s in before) or any(s[5] for s in after)
            onset = Onset(track.right, step.moved_right, step.moved_left, step.at_s, what, near)
        else:
            return  # both moved: the world changed, or nobody can tell
        level = sum(s[2] - s[1] for s in before) / len(before) \
            + step.moved_left - step.moved_right
        track.unconfirmed = Unconfirmed(onset, level, share, step.threshold)

    def _confirm(self, track: Onsets, held: bool) -> None:
        """Count the onset waiting for the next window if the pair's
        difference held at its new level there (``held``; or the pair stopped
        reading first: it may have)."""
        waiting, track.unconfirmed = track.unconfirmed, None
        assert waiting is not None
        if held:
            track.record(waiting.onset, waiting.threshold)

    def _judge_at_once(self, track: Onsets, snap: Snapshot, bar: float | None) -> None:
        """Where the robot steers by the pair: a sensor its onsets name, by
        more than ``bar`` (None: than the standing rule tolerates), is judged
        now (steering on it would leave the robot askew, take the floor for
        the drop, or lower segment 3 past the floor)."""
        diff = motion.pair_difference(snap, self._cfg, track.back)
        if not track.found or diff is None:
            return
        offsets = track.offsets
        for sensor, partner in ((track.left, track.right), (track.right, track.left)):
            off = offsets[sensor]
            reading = snap.sensors[sensor].distance_m
            tolerance = standing_tolerance(self._cfg, reading, back=track.back)
            limit = tolerance if bar is None else bar
            # the pair reads as far apart now as the onsets say (an offset that
            # ended unseen, while the pair read nothing, no longer does)
            said = _signed(diff, sensor)
            still = abs(said) > limit and abs(said - off + offsets[partner]) <= max(
                pair_tolerance(self._cfg, reading, back=track.back), MATCH_SHARE * abs(off))
            if abs(off) > limit and still and abs(offsets[partner]) <= abs(off) / 2:
                onsets = [o for o in track.found if o.sensor is sensor]
                self._judged[sensor] = say.judged_at_once(onsets, track.back)
                return

    # -- the standing rule's wait ends -----------------------------------------------------
    def _judge_pause(self, snap: Snapshot, ctx: Context, odometer: float, yaw: float) -> None:
        pause = ctx.pause
        assert pause is not None
        cfg = self._cfg
        if snap.time_s - pause.started_s < cfg.algorithm.standing_wait - cfg.algorithm.tick / 2 \
                or not pause.diffs:
            return
        resume = BY_VALUE[pause.resume_phase]
        back = resume.record.watches == "back"
        if motion.pair_difference(snap, cfg, back) is None:
            return  # a pair that gives no figure now does not disagree (the standing rule)
        diffs = sorted(pause.diffs)
        disagree = diffs[len(diffs) // 2]  # left − right
        r, left = motion.pair(snap, back)
        near = min(r.distance_m, left.distance_m)
        tolerance = standing_tolerance(cfg, near, back=back)
        if abs(disagree) <= tolerance:
            return
        match = max(tolerance, MATCH_SHARE * abs(disagree))
        threshold = STEP_SIGMAS * pair_tolerance(cfg, near, back=back)
        track = self._pairs[1 if back else 0]
        found = self._by_onsets(track, disagree, match, threshold)
        if found is None and back:
            found = self._by_mount(disagree, match, threshold)
        tread = ctx.number_of_steps - ctx.steps_descended if resume in ON_THE_TREAD else \
            0 if resume in ON_THE_FLOOR else None
        if found is None and not back and tread is not None and tread in self._risers \
                and ctx.landing.step is None and not ctx.from_top:
            found = self._by_riser(snap, self._risers[tread], odometer, yaw, disagree,
                                   min(tolerance, match))
        if found is not None:
            sensor, evidence = found
            self._judged[sensor] = evidence

    def _by_onsets(self, track: Onsets, disagree: float, match: float,
                   threshold: float) -> tuple[SensorId, str] | None:
        offsets = track.offsets
        if not track.found:
            return None
        for sensor, partner in ((track.left, track.right), (track.right, track.left)):
            off, said = offsets[sensor], _signed(disagree, sensor)
            # an onset read too near to measure moved at least what it says
            agrees = off * said > 0 and abs(said) >= abs(off) - match if track.at_least[sensor] \
                else abs(off - said) <= match
            # (each onset counted when it was a step beyond the threshold there)
            if agrees and off != 0.0 and abs(offsets[partner]) <= abs(off) / 2:
                onsets = [o for o in track.found if o.sensor is sensor]
                return sensor, say.judged_by_onsets(onsets, partner, _signed(disagree, sensor))
        return None

    def _by_mount(self, disagree: float, match: float,
                  threshold: float) -> tuple[SensorId, str] | None:
        last = self._mount.last
        if last is None:
            return None
        for sensor, partner, (off, near), (p_off, p_near) in (
                (SensorId.SBL, SensorId.SBR, last[1], last[0]),
                (SensorId.SBR, SensorId.SBL, last[0], last[1])):
            said = _signed(disagree, sensor)
            if p_near or abs(p_off) > threshold / 2:
                continue
            # read too near to measure, it reads at least that much short
            if (near and said <= off) or (not near and abs(off) >= threshold
                                          and abs(off - p_off - said) <= match):
                return sensor, say.judged_by_mount(sensor, partner, off, p_off, near, said,
                                                   self._cfg.BACK_CLEARANCE)
        return None

    def _by_riser(self, snap: Snapshot, riser: Reference, odometer: float, yaw: float,
                  disagree: float, within: float) -> tuple[SensorId, str] | None:
        """The sensor the drive does not bear out: its partner reads where the
        riser stands by the odometer, within ``within``."""
        turn = self._lateral * (yaw - riser.yaw_rad)
        r, left = motion.pair(snap)
        off_r = r.distance_m - (riser.position_m - odometer - turn)
        off_l = left.distance_m - (riser.position_m - odometer + turn)
        for sensor, partner, off, p_off in ((SensorId.SFL, SensorId.SFR, off_l, off_r),
                                            (SensorId.SFR, SensorId.SFL, off_r, off_l)):
            if abs(p_off) <= within < abs(off) and abs(off) >= 2 * abs(p_off):
                return sensor, say.judged_by_riser(sensor, partner, off, p_off, riser.tread,
                                                   _signed(disagree, sensor))
        return None


def _signed(disagree: float, sensor: SensorId) -> float:
    """The disagreement (left − right) as how far ``sensor`` reads past its partner."""
    return disagree if sensor in (SensorId.SFL, SensorId.SBL) else -disagree


def _motion(before: list[Sample], after: list[Sample]) -> str:
    """What the robot did between two windows, by the odometer, in words."""
    drove = sum(s[3] for s in after) / len(after) - sum(s[3] for s in before) / len(before)
    turned = sum(s[4] for s in after) / len(after) - sum(s[4] for s in before) / len(before)
    return say.motion(drove, turned, abs(drove) < STILL_M and abs(turned) < STILL_RAD)
