"""Bias: a distance sensor that keeps measuring but reads wrong by a constant
offset (not in the seed, which has no sensor faults).

Two sensors of a pair that disagree cannot say which of them is wrong; the
host knows more than the pair.  :class:`BiasWatch` keeps, every tick, the
evidence (:mod:`~stairbot.control.algorithm.bias_evidence`):

* *onsets* (:mod:`~stairbot.control.algorithm.bias_onsets`): one sensor's
  reading jumped by more than the motion since explains (the odometer, the
  turn, MTB's travel) while its partner's followed the motion;
* *mount heights*: what each back sensor read, less BACK_CLEARANCE, the last
  second segment 3 stood on a surface away from an edge;
* *risers*: where the start position and each tab_length_to_edge put the
  riser ahead, by the odometer.

An onset is evidence, not yet a verdict.  A sensor is *judged* biased, and
reads as ERROR from then on in the snapshot :meth:`BiasWatch.see` returns,
only where the evidence decides something:

* at the end of the standing rule's wait, the pair still disagreeing: by the
  onsets that say what the disagreement says; else, for the back pair, by
  the mount heights, or in descent 2 by the rise each back sensor read at
  the end of that step's ascent 7 (:mod:`~stairbot.control.algorithm.bias_rise`);
  else, for the front pair on a tread or the floor on the way down, by the
  riser the odometer places;
* at once, where the robot steers by the pair (calibration squaring up to a
  riser: the front pair; descent 1 finding the edge and descent 2 finding
  the floor: the back pair), by the onsets, while the pair reads as far
  apart as they say: squared up to one sensor's offset the robot would
  stand atan(offset / (2 front_lateral)) askew (17 deg for 3 cm); in
  descent 1 also by the mount heights (:mod:`~stairbot.control.algorithm.bias_mount`)
  and by the step's rise (:mod:`~stairbot.control.algorithm.bias_flat`).

A judged sensor is lost (:mod:`~stairbot.control.algorithm.limp`): on the
floor where the program began the run ends on it; elsewhere a degraded
stop, and with the operator's consent its partner stands in for it on the
way home.  Where nothing names one of two sensors that disagree, the
standing rule ends the program, as it always has -- but for the front pair
where the way home needs no front reading
(:mod:`~stairbot.control.algorithm.blind`): both are distrusted there.

Pure Python, on the controller's clock (the snapshots' times); it keeps no
state in the context (a resumed run starts with no evidence).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from stairbot.control.algorithm import bias_mount, blind, motion, standing
from stairbot.control.algorithm.bias_evidence import MountHeights, Onsets, Reference
from stairbot.control.algorithm.bias_flat import FlatDrop
from stairbot.control.algorithm.bias_mount import MATCH_SHARE, by_mount
from stairbot.control.algorithm.bias_mount import signed as _signed
from stairbot.control.algorithm.bias_onsets import STEP_SIGMAS, PairWatch, distance
from stairbot.control.algorithm.bias_rise import Rises, by_rise
from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.families import Calibration
from stairbot.control.algorithm.modes import Purpose
from stairbot.control.algorithm.phases import BY_VALUE, Phase
from stairbot.control.algorithm.squaring_bias import distrusted as distrusted_chasing
from stairbot.control.algorithm.texts import back_pair as say_rise
from stairbot.control.algorithm.texts import bias as say
from stairbot.control.tolerances import pair_tolerance, standing_tolerance
from stairbot.hardware import (
    WHEEL_MOTORS,
    MotorId,
    SensorId,
    SensorReading,
    SensorStatus,
    Snapshot,
)
from stairbot.inputs.config import RobotConfig

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
    Phase.ASCENT_LIFT_SECOND, Phase.ASCENT_DRIVE_SECOND, Phase.DESCENT_DRIVE_SECOND,
    Phase.DESCENT_LOWER_SECOND, Phase.DESCENT_DRIVE_FIRST, Phase.DESCENT_LOWER_FIRST,
    Phase.DESCENT_FINISH})
"""The phases in which segment 3 stands on a surface and moves on it: its
sensors read their mount height (BACK_CLEARANCE), until one reads a drop
(DROP_M more: descent 1 backs off towards the edge)."""
DROP_M = 0.07
"""A back sensor reading this much over BACK_CLEARANCE sees a drop (the lowest
rise a flight has is about 0.08 m): a biased one reading 5 cm long does not."""
HANGING = frozenset({Phase.ASCENT_LIFT_THIRD, Phase.DESCENT_LOWER_THIRD})
"""The phases in which MTB lifts or lowers segment 3 in the air: what its
sensors read moves with MTB's counter."""
FIRST_STANDS = frozenset({Phase.ASCENT_LIFT_SECOND, Phase.DESCENT_LOWER_SECOND})
"""The phases in which MTF moves segment 2 while segment 1 stands on its
tread; in any other it moves segment 1, and the front cones with it, in the
air (lifted for the turns, over a riser, lowered off a tread)."""
ON_THE_TREAD = frozenset({Phase.DESCENT_BACK_OFF, Phase.DESCENT_BACK_TO_EDGE,
                          Phase.DESCENT_LOWER_THIRD, Phase.DESCENT_DRIVE_SECOND,
                          Phase.DESCENT_LOWER_SECOND, Phase.DESCENT_DRIVE_FIRST})
"""Descent 1 to 5 of a step: segment 1 stands on its tread and the front pair
faces the riser above it, whose place the tab measured on the way up and
the odometer since say (descent 6 lowers the pair past the tread)."""
ON_THE_FLOOR = frozenset({Phase.DESCENT_FINISH, Phase.DESCENT_FINISH_FLOOR})
ONTO_THE_TREAD = frozenset({Phase.ASCENT_DRIVE_FIRST, Phase.ASCENT_LIFT_SECOND,
                            Phase.ASCENT_DRIVE_SECOND, Phase.ASCENT_LIFT_THIRD})
"""Ascent 4 to 7: the robot goes onto the tread length_of_next_step measured
(ascent 3); limping home it finishes the step by it."""


def _values(phases: frozenset[Phase]) -> frozenset[str]:
    """``phases`` by their values, as the context holds them: :meth:`BiasWatch.see`
    asks every tick, and a str hashes faster than an Enum member."""
    return frozenset(p.value for p in phases)


_FIRST_STANDS, _ON_A_SURFACE, _HANGING = _values(FIRST_STANDS), _values(ON_A_SURFACE), \
    _values(HANGING)
_STEERS_BY_THE_FRONT, _STEERS_BY_THE_BACK = _values(STEERS_BY_THE_FRONT), \
    _values(STEERS_BY_THE_BACK)

# bound once: an enum member's look-up costs, every tick
_PAUSED = Phase.PAUSED
_MWF, _MWB, _MWR, _MWL = MotorId.MWF, MotorId.MWB, MotorId.MWR, MotorId.MWL
_MTF, _MTB = MotorId.MTF, MotorId.MTB
_SBR, _SBL = SensorId.SBR, SensorId.SBL
_OK = SensorStatus.OK


class BiasWatch:
    """Gathers the evidence and judges biased sensors (see the module
    docstring).  One per controller, told every tick's filtered snapshot."""

    def __init__(self, cfg: RobotConfig) -> None:
        self._cfg = cfg
        self._lateral = cfg.sensors.front_lateral
        self._metres_per_turn = cfg.wheel_circumference / len(WHEEL_MOTORS)
        self._wheel_m = cfg.wheel_circumference
        self._near = cfg.sensors.range(True)[0]
        self._drop = cfg.BACK_CLEARANCE + DROP_M
        self._watches = (PairWatch(cfg, SensorId.SFR, SensorId.SFL, False),
                         PairWatch(cfg, SensorId.SBR, SensorId.SBL, True))
        self._pairs = (self._watches[0].track, self._watches[1].track)
        self._mount = MountHeights(cfg.BACK_CLEARANCE)
        self._rises = Rises(cfg)
        self._flat = FlatDrop(cfg)
        self._lift_m = cfg.motors.lift_travel_per_turn
        self._mtf: float | None = None
        self._cones_m = 0.0
        """How far MTF has moved segment 1 in the air (not FIRST_STANDS), summed
        over the run: a front step while it changed is no onset."""
        self._mtb: float | None = None
        self._hung_m = 0.0
        """How far MTB has moved segment 3 in the air (HANGING), summed over the
        run: the back pair's readings less it stay put while it hangs, and
        do not jump when it sets down or lifts off."""
        self._yaw_per_turn = motion.turn_yaw_rad(cfg, 0.5)  # twist is half MWR less MWL
        self._risers: dict[int, Reference] = {}
        """Where the riser ahead of each tread stood by the odometer (0: the floor's)."""
        self._judged: dict[SensorId, str] = {}
        self._distrusted: dict[SensorId, str] = {}
        """Both front sensors, where they still disagree and nothing names one
        (:mod:`~stairbot.control.algorithm.blind`), each with why in words."""
        self._tread: tuple[float | None, float] = (None, -1.0)
        """length_of_next_step as last seen, and when it was measured."""

    @property
    def judged(self) -> dict[SensorId, str]:
        """The sensors judged biased, each with the evidence in words."""
        return self._judged

    def why(self, sensor: SensorId, otherwise: str | None = None) -> str:
        """Why ``sensor`` reads as ERROR: judged biased, else ``otherwise``
        (perception's reason), else it reports an error."""
        return self._judged.get(sensor) or self._distrusted.get(sensor) or otherwise \
            or "reports an error"

    def all_judged(self, sensors: Sequence[SensorId]) -> bool:
        """Whether every one of ``sensors`` is judged biased, or distrusted with
        its pair: no use waiting for them to come back."""
        return all(s in self._judged or s in self._distrusted for s in sensors)

    def see(self, snap: Snapshot, ctx: Context) -> Snapshot:
        """Take this tick's filtered snapshot (before any stand-in), judge
        where the evidence decides (module docstring); the snapshot with
        every sensor judged biased reading as ERROR."""
        phase = BY_VALUE[ctx.phase]
        paused = phase is _PAUSED
        # the standing rule's wait stands where the phase it stopped in stood
        at = ctx.pause.resume_phase if paused and ctx.pause is not None else ctx.phase
        where = BY_VALUE[at]
        motors = snap.motors
        right, left = motors[_MWR].turns, motors[_MWL].turns
        odometer = sum((motors[_MWF].turns, motors[_MWB].turns, right, left)) \
            * self._metres_per_turn
        yaw = (right - left) * self._yaw_per_turn
        front, back = self._pairs
        judged = self._judged
        mtf = motors[_MTF].turns
        if at not in _FIRST_STANDS and self._mtf is not None:
            self._cones_m += (mtf - self._mtf) * self._lift_m
        self._mtf = mtf
        self._watches[0].tick(snap, odometer, yaw, self._cones_m, True, judged)
        surface = at in _ON_A_SURFACE and not ctx.from_top
        mtb = motors[_MTB].turns
        if at in _HANGING and self._mtb is not None:
            self._hung_m += (mtb - self._mtb) * self._lift_m
        self._mtb = mtb
        self._watches[1].tick(snap, odometer, yaw, self._hung_m, surface, judged)
        self._on_a_surface(snap, surface)
        self._rises.tick(snap, where, paused, ctx.number_of_steps)
        if ctx.length_of_next_step != self._tread[0]:
            self._tread = (ctx.length_of_next_step, snap.time_s)
        if ctx.number_of_steps not in self._risers:
            self._references(snap, ctx, odometer, yaw)
        if not self._distrusted:  # a squaring turn chased an offset (squaring_bias.py)
            chased = distrusted_chasing(ctx, where)
            if chased:
                (self._judged if len(chased) == 1 else self._distrusted).update(chased)
        if paused and ctx.pause is not None:
            self._judge_pause(snap, ctx, odometer, yaw)
        elif ctx.phase in _STEERS_BY_THE_FRONT and not ctx.from_top:
            family = ctx.family
            if isinstance(family, Calibration) and family.purpose in _RISER_PURPOSES:
                self._judge_at_once(front, snap)
        elif ctx.phase in _STEERS_BY_THE_BACK:
            self._judge_at_once(back, snap)
            found = None if judged or ctx.from_top else bias_mount.at_once(self._cfg, self._mount,
                                                                           snap)
            if found is None and not judged and not ctx.from_top:
                step = ctx.number_of_steps - ctx.steps_descended - 1
                found = self._flat.see(snap, odometer, self._rises.rises.get(step))
            if found is not None:
                judged[found[0]] = found[1]
        if not self._judged and not self._distrusted:
            return snap
        sensors = dict(snap.sensors)
        for sid in (*self._judged, *self._distrusted):
            r = sensors[sid]
            sensors[sid] = SensorReading(r.distance_m, SensorStatus.ERROR, r.age_s)
        return replace(snap, sensors=sensors)

    # -- gathering ------------------------------------------------------------------------
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
        r, left = snap.sensors[_SBR], snap.sensors[_SBL]
        dr, dl = distance(r, self._near), distance(left, self._near)
        if dr is None or dl is None or max(dr, dl) > self._drop:
            self._mount.end()
        else:
            self._mount.add(dr, dl, r.status is not _OK, left.status is not _OK)

    def _judge_at_once(self, track: Onsets, snap: Snapshot) -> None:
        """Where the robot steers by the pair: a sensor its onsets name, by
        more than the standing rule tolerates, is judged now (steering on it
        would leave the robot askew, or take the floor for the drop); not
        while one back sensor reads a drop and its partner a surface."""
        diff = motion.pair_difference(snap, self._cfg, track.back)
        if not track.found or diff is None:
            return
        drop = self._cfg.BACK_CLEARANCE + DROP_M
        if track.back and (snap.sensors[track.right].distance_m > drop) \
                != (snap.sensors[track.left].distance_m > drop):
            return  # one back cone over an edge before the other: the rise splits them
        offsets = track.offsets
        for sensor, partner in ((track.left, track.right), (track.right, track.left)):
            off = offsets[sensor]
            reading = snap.sensors[sensor].distance_m
            limit = standing_tolerance(self._cfg, reading, back=track.back)
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
        # the back pair: its mount heights and rises judged as far apart as
        # the standing rule ends the program on (the median beyond its
        # smoothed tolerance); its onsets, as before, only beyond the wider
        # tolerance of one tick (within it, on the sonar robot, a 1 cm bias's
        # onset was taken for its healthy partner's)
        ends = standing_tolerance(cfg, near, motion.DIFF_SMOOTHING, back) if back else tolerance
        if abs(disagree) <= ends:
            if not back:
                self._distrust(snap, ctx, resume)
            return
        match = max(tolerance, MATCH_SHARE * abs(disagree))
        threshold = STEP_SIGMAS * pair_tolerance(cfg, near, back=back)
        track = self._pairs[1 if back else 0]
        found = self._by_onsets(track, disagree, match) if abs(disagree) > tolerance else None
        if found is not None and not back and resume in ONTO_THE_TREAD \
                and min(o.at_s for o in track.found if o.sensor is found[0]) <= self._tread[1]:
            # it went wrong before the tread ahead was measured on it: finishing
            # the step by that figure is not safe (climbing on, it would tip).
            # On the first step the robot undoes it by the odometer, neither
            # sensor trusted; elsewhere the standing rule ends the program
            if not blind.needs_no_front(resume, ctx):
                return
            found = None
        if found is None and back:
            found = by_mount(self._mount, cfg.BACK_CLEARANCE, disagree, match, threshold)
        if found is None and back and resume is Phase.DESCENT_LOWER_THIRD and not ctx.from_top:
            found = self._by_rise(ctx.number_of_steps - ctx.steps_descended - 1, disagree,
                                  match, ends)
        tread = ctx.number_of_steps - ctx.steps_descended if resume in ON_THE_TREAD else \
            0 if resume in ON_THE_FLOOR else None
        if found is None and not back and tread is not None and tread in self._risers \
                and ctx.landing.step is None and not ctx.from_top:
            found = self._by_riser(snap, self._risers[tread], odometer, yaw, disagree,
                                   min(tolerance, match))
        if found is not None:
            sensor, evidence = found
            self._judged[sensor] = evidence
        else:
            self._distrust(snap, ctx, resume)

    def _distrust(self, snap: Snapshot, ctx: Context, resume: Phase) -> None:
        """Nothing names one of the front pair: where the way home needs no
        front reading, neither is trusted from the tick on which the standing
        rule would end the program (:func:`standing.ends_now`)."""
        if resume.record.watches == "back" or not blind.needs_no_front(resume, ctx):
            return
        median = standing.ends_now(snap, ctx, self._cfg)
        if median is not None:
            self._distrusted = dict(zip((SensorId.SFR, SensorId.SFL),
                                        say.distrusted(median), strict=True))

    def _by_onsets(self, track: Onsets, disagree: float,
                   match: float) -> tuple[SensorId, str] | None:
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

    def _by_rise(self, step: int, disagree: float, match: float,
                 off_by: float) -> tuple[SensorId, str] | None:
        """Descent 2: the sensor that no longer reads the rise it read at the
        end of the step's ascent 7 (:mod:`~stairbot.control.algorithm.bias_rise`)."""
        rise, standing = self._rises.rises.get(step), self._rises.standing()
        found = None if rise is None or standing is None else \
            by_rise(self._cfg, rise, standing, disagree, match, off_by)
        if found is None:
            return None
        sensor, off, p_off = found
        return sensor, say_rise.judged_by_rise(sensor, off, p_off, step,
                                               _signed(disagree, sensor))

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

