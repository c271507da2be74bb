"""The simulated robot's sensor board: four distance sensors (six with the
side pair) and the IMU.

:class:`SimSensors` reads SFR/SFL (segment 1's front face, looking forward)
and SBR/SBL (under segment 3, looking down) from the pymunk side view
(:mod:`stairbot.fakes.world`) and the top view (:mod:`stairbot.fakes.plan`)
through the sensor models (:mod:`stairbot.fakes.sensor_model`, one preset per
pair from the config's ``[sensors] front_model`` / ``back_model``; the cones'
rays are cast by :mod:`stairbot.fakes.beams`; a multizone front pair's board
publishes its block of zones moved up a row or more while segment 2 pitches
nose down, :func:`~stairbot.inputs.sensor_specs.rows_up`).  A robot with the
side pair (``[sensors] side_model``) also reads SSR/SSL: one level ray each from
segment 3 (``side_from_rear`` from its rear, ``side_height`` above its wheels'
contact line: lifting segment 3 raises them), square to the heading, to the
right and to the left, cast against the stairwell's faces in flight 1's frame
(:meth:`stairbot.fakes.landing.Stairwell.side_hit`: side walls, a landing's
walls, the second flight's risers), through the side model (its noise,
timing, faults; its incidence and weak-signal limits on the one ray).  A
reading's ``age_s`` is its
model's: how long before the read the published measurement was taken (a
model with a period or a latency); the ``ideal`` preset measures at every
read, so its readings are 0 s old and shared, not copied.

:func:`imu` is the board's inertial unit, which rides in segment 2: pitch
and pitch rate of segment 2's pymunk body.  The simulation is a side view in
two dimensions: nothing in it can roll, so roll and roll rate are 0 -- not a
measurement, the model's limit.
"""

from __future__ import annotations

import math

from stairbot.errors import ScenarioError
from stairbot.fakes.beams import down_fans, front_hits, total_weight
from stairbot.fakes.landing import Stairwell
from stairbot.fakes.plan import Plan
from stairbot.fakes.sensor_model import Hit, ModelSensor, SensorModel, combine
from stairbot.fakes.sensor_presets import front_blocks, model_for, preset
from stairbot.fakes.world import World
from stairbot.hardware import Imu, SensorId, SensorReading
from stairbot.inputs.config import RobotConfig
from stairbot.inputs.scenario import Scenario
from stairbot.inputs.sensor_specs import rows_up
from stairbot.readings import imu as make_imu

_SFR, _SFL, _SBR, _SBL = SensorId.SFR, SensorId.SFL, SensorId.SBR, SensorId.SBL  # bound once
_SSR, _SSL = SensorId.SSR, SensorId.SSL

IMU_SEGMENT = 1
"""The IMU rides in segment 2 (index 1 in the world)."""


class SimImu:
    """The sensor board's IMU: segment 2's pitch (+ nose up) and pitch rate;
    roll 0 (a side view cannot roll); measured now (age 0).

    The rate is the mean over the time since the last reading -- the change
    of pitch over it -- as a MEMS gyro's low-pass filter reports it, not the
    body's angular velocity after the last physics step: a contact's impulse
    in one 2 ms step can spin the body at over 100 deg/s for that step
    alone, which the tilt supervisor would take for a fall and stop a sound
    climb."""

    def __init__(self, world: World) -> None:
        self.world = world
        self._last: tuple[float, float] | None = None  # (time, pitch) of the last reading

    def read(self) -> Imu:
        w = self.world
        t, pitch = w.time, w.pitch_deg(IMU_SEGMENT)
        last, self._last = self._last, (t, pitch)
        if last is None or t - last[0] <= 0.0:
            rate = w.pitch_rate_dps(IMU_SEGMENT)  # nothing to average over yet
        else:
            rate = (pitch - last[1]) / (t - last[0])
        return make_imu(pitch, 0.0, rate, 0.0)


class SimSensors:
    """SFR, SFL, SBR and SBL on the simulated robot, and SSR and SSL on one with
    the side pair (see the module docstring).  ``well``: the stairwell and the
    frame the world is in (the side pair's, built from ``scenario`` if not given)."""

    def __init__(self, config: RobotConfig, scenario: Scenario, world: World,
                 plan: Plan, well: Stairwell | None = None) -> None:
        self.config = config
        self.world = world
        self.plan = plan
        s, n = config.sensors, scenario.sensors
        if not s.has_side_pair:
            for i, fault in enumerate(scenario.faults):
                if fault.sensor in ("SSR", "SSL"):
                    raise ScenarioError(scenario.source, f"faults[{i}].sensor",
                                        f"{fault.sensor}, but the robot config has no side pair "
                                        "([sensors] side_model): the fault would do nothing; "
                                        "allowed: SFR, SFL, SBR, SBL, or a robot with the pair")
        self.front_model, self.back_model = model_for(s, back=False), model_for(s, back=True)
        # a multizone pair's block of zones, and the same moved up row by row,
        # which the board publishes while pitched nose down (rows_up)
        self._front_blocks = front_blocks(s)
        self._zone_deg = s.spec(back=False).zone_deg
        self.sensors = {
            sid: ModelSensor(sid, model, lo, hi, s.resolution, n.noise, n.seed, scenario.faults,
                             n.outliers)
            for sid, model, lo, hi in (
                (SensorId.SFR, self.front_model, s.front_min_range, s.front_max_range),
                (SensorId.SFL, self.front_model, s.front_min_range, s.front_max_range),
                (SensorId.SBR, self.back_model, s.back_min_range, s.back_max_range),
                (SensorId.SBL, self.back_model, s.back_min_range, s.back_max_range),
            )
        }
        # only a model with a period or a latency, or a sensor that a freeze fault
        # stops, publishes readings older than now
        frozen = {f.sensor for f in scenario.faults if f.kind == "freeze"}
        self._front_timed = (self.front_model.period_s > 0.0 or self.front_model.latency_s > 0.0
                             or bool(frozen & {"SFR", "SFL"}))
        self._back_timed = (self.back_model.period_s > 0.0 or self.back_model.latency_s > 0.0
                            or bool(frozen & {"SBR", "SBL"}))
        self._front_single = self.front_model.single_ray
        self._back_single = self.back_model.single_ray
        self._pairs = ((self.sensors[SensorId.SFR], self.sensors[SensorId.SFL]),
                       (self.sensors[SensorId.SBR], self.sensors[SensorId.SBL]))
        self._front_weight = total_weight(self.front_model.cone)
        self._back_weight = total_weight(self.back_model.fan)
        r = config.geometry.wheel_radius
        # sensor mounts in their segment's frame (origin: centre of the axle line)
        # rays reach a little past what the sensor reports (its range within the config's)
        self._front_mount = (world.lengths[0] / 2, s.front_height - r,
                             self.sensors[SensorId.SFR].max_range * 1.05)
        self._back_mount = (-world.lengths[2] / 2 + s.back_from_rear,
                            s.back_height - r,
                            self.sensors[SensorId.SBR].max_range * 1.05)
        self._front_laterals = (-s.front_lateral, s.front_lateral)  # SFR, SFL
        self.well = well if well is not None else Stairwell(scenario)
        self.side_model = preset(s.side_model) if s.has_side_pair else None
        self._side: tuple[ModelSensor, ModelSensor] | None = None
        if self.side_model is not None:
            for sid in (_SSR, _SSL):
                self.sensors[sid] = ModelSensor(sid, self.side_model, s.side_min_range,
                                                s.side_max_range, s.resolution, n.noise,
                                                n.seed, scenario.faults, n.outliers)
            self._side = (self.sensors[_SSR], self.sensors[_SSL])
            self._side_mount = (-world.lengths[2] / 2 + s.side_from_rear, s.side_height - r,
                                self.sensors[_SSR].max_range * 1.05)

    def read(self, t: float) -> dict[SensorId, SensorReading]:
        """Every distance sensor's published reading at ``t``, with its age."""
        sfr, sfl = self._front_readings(t)
        sbr, sbl = self._back_readings(t)
        if self._side is None:
            return {_SFR: sfr, _SFL: sfl, _SBR: sbr, _SBL: sbl}
        ssr, ssl = self._side_readings(t, self._side)
        return {_SFR: sfr, _SFL: sfl, _SBR: sbr, _SBL: sbl, _SSR: ssr, _SSL: ssl}

    def _side_readings(self, t: float, pair: tuple[ModelSensor, ModelSensor]
                       ) -> tuple[SensorReading, SensorReading]:
        """What SSR and SSL publish at ``t``: one ray each, cast when a
        measurement is due."""
        right, left = pair
        due_r, due_l = right.due(t), left.due(t)
        if due_r or due_l:
            model = self.side_model
            assert model is not None
            seen_r, seen_l = self.side_seen()
            for sensor, due, seen in ((right, due_r, seen_r), (left, due_l, seen_l)):
                if due:
                    hits: list[Hit] = [] if seen is None else [(seen[0], seen[1], 1.0)]
                    sensor.sample(combine(model, hits, 1.0), t)
        return right.published(t), left.published(t)

    def side_seen(self) -> tuple[tuple[float, float] | None, tuple[float, float] | None]:
        """What SSR's and SSL's beams meet now, before the sensor's model: the
        distance and the cosine of the incidence, each (None: nothing within
        reach).  Needs the side pair."""
        px, py, pa, _turns, _lifts = self.world.state()
        lx, ly, reach = self._side_mount
        a3 = pa[2]
        c, s = math.cos(a3), math.sin(a3)
        mx, z = px[2] + c * lx - s * ly, py[2] + s * lx + c * ly
        well, plan = self.well, self.plan
        x, y, yaw = well.in_flight1(px[1], plan.y, plan.yaw)
        # the pair's point on the centre line, `behind` along the robot from segment 2's centre
        behind = mx - px[1]
        cy, sy = math.cos(yaw), math.sin(yaw)
        bx, by = x + behind * cy, y + behind * sy
        lat = self.config.sensors.side_lateral
        right = well.side_hit(bx + lat * sy, by - lat * cy, z, sy, -cy, reach)
        left = well.side_hit(bx - lat * sy, by + lat * cy, z, -sy, cy, reach)
        return right, left

    def _front_readings(self, t: float) -> tuple[SensorReading, SensorReading]:
        """What SFR and SFL publish at ``t``: one ray each for a single-ray model,
        else their cones, cast only when a measurement is due."""
        right, left = self._pairs[0]
        if self._front_single:
            sfr, sfl = self._front_truth()
            now = right.measure(sfr, t), left.measure(sfl, t)
            if not self._front_timed:
                return now
        else:
            due_r, due_l = right.due(t), left.due(t)
            if due_r or due_l:
                model = self._front_block()
                mx, my, a1, _c, _s, forward = self._front_origin()
                hits = front_hits(self.world, self.plan, model, (mx, my), a1, forward,
                                  self._front_laterals, self._front_mount[2])
                if due_r:
                    right.sample(combine(model, hits[0], self._front_weight), t)
                if due_l:
                    left.sample(combine(model, hits[1], self._front_weight), t)
        if self._front_timed:
            return right.published(t), left.published(t)
        return right.reading(t), left.reading(t)

    def _back_readings(self, t: float) -> tuple[SensorReading, SensorReading]:
        """What SBR and SBL publish at ``t`` (see _front_readings)."""
        right, left = self._pairs[1]
        model = self.back_model
        if self._back_single:
            sbr, sbl = self._back_truth()
            now = right.measure(sbr, t), left.measure(sbl, t)
            if not self._back_timed:
                return now
        else:
            due_r, due_l = right.due(t), left.due(t)
            if due_r or due_l:
                (xr, xl), my, a3, _c, _s, reach = self._back_origins()
                if xl == xr:  # square to the flight: the two see the same
                    hits = down_fans(self.world, model, (xr,), my, a3, reach) * 2
                else:
                    hits = down_fans(self.world, model, (xr, xl), my, a3, reach)
                seen = None
                if due_r:
                    seen = combine(model, hits[0], self._back_weight)
                    right.sample(seen, t)
                if due_l:
                    if seen is None or hits[1] is not hits[0]:
                        seen = combine(model, hits[1], self._back_weight)
                    left.sample(seen, t)
        if self._back_timed:
            return right.published(t), left.published(t)
        return right.reading(t), left.reading(t)

    def front_seen(self) -> tuple[float | None, float | None]:
        """What SFR's and SFL's beams meet now, before the sensor's noise,
        outliers, dropouts, range and timing: one ray each for a single-ray
        model, else the cone combined as the model combines it (None: nothing,
        or too weak an echo).  The sweep's verdict asks this of the start pose
        (is the first riser in sight?)."""
        model = self._front_block()
        if model.single_ray:
            return self._front_truth()
        mx, my, a1, _c, _s, forward = self._front_origin()
        hits = front_hits(self.world, self.plan, model, (mx, my), a1, forward,
                          self._front_laterals, self._front_mount[2])
        right, left = (combine(model, seen, self._front_weight)[0] for seen in hits)
        return right, left

    def _front_block(self) -> SensorModel:
        """The front model as the board publishes it now: a multizone pair's
        block moved up by :func:`rows_up` rows at segment 2's pitch (as far
        as the field goes); any other, as mounted."""
        blocks = self._front_blocks
        if len(blocks) == 1:
            return blocks[0]
        up = rows_up(self.world.pitch_deg(IMU_SEGMENT), self._zone_deg)
        return blocks[min(up, len(blocks) - 1)]

    def _front_origin(self) -> tuple[float, float, float, float, float, float]:
        """The front mount in the side view (x, y), segment 1's angle, its cos
        and sin, and the mount's distance ahead of segment 2's centre."""
        px, py, pa, _turns, _lifts = self.world.state()
        lx, ly, _reach = self._front_mount
        a1 = pa[0]
        c, s = math.cos(a1), math.sin(a1)
        mx, my = px[0] + c * lx - s * ly, py[0] + s * lx + c * ly
        # the mount's distance ahead of segment 2's centre, along the robot
        a2 = pa[1]
        forward = math.cos(a2) * (mx - px[1]) + math.sin(a2) * (my - py[1])
        return mx, my, a1, c, s, forward

    def _front_truth(self) -> tuple[float | None, float | None]:
        """True distances seen by SFR and SFL (None: nothing within range)."""
        w = self.world
        reach = self._front_mount[2]
        mx, my, _a1, c, s, forward = self._front_origin()
        x1 = mx + c * reach
        best, _i = w.profile.first(mx, my, x1, my + s * reach)  # profile.ray's x, written out
        hit_dx = None if best == math.inf else (mx + (x1 - mx) * best) - mx
        slant = 1.0 / max(c, 1e-6)
        lat = self.config.sensors.front_lateral
        # Plan.front_distance for both, turned by the one yaw
        plan = self.plan
        cos_yaw, sin_yaw = plan.yaw_trig()
        sfr = plan.front_hit_at(forward, -lat, hit_dx, slant, cos_yaw, sin_yaw)
        sfl = plan.front_hit_at(forward, lat, hit_dx, slant, cos_yaw, sin_yaw)
        return None if sfr is None else sfr[0], None if sfl is None else sfl[0]

    def _back_truth(self) -> tuple[float | None, float | None]:
        """True distances seen by SBR and SBL, looking down from segment 3.  Turned
        by a yaw, the two stand at different x (over a nosing they may disagree)."""
        (xr, xl), my, _a3, c, s, reach = self._back_origins()
        d = self._down(xr, my, c, s, reach)
        return d, (d if xl == xr else self._down(xl, my, c, s, reach))

    def _back_origins(self) -> tuple[tuple[float, float], float, float, float, float, float]:
        """The side-view x of SBR and SBL, their height, segment 3's angle, its
        cos and sin, and the rays' reach.  Turned by a yaw, the two stand at
        different x."""
        px, py, pa, _turns, _lifts = self.world.state()
        lx, ly, reach = self._back_mount
        a3 = pa[2]
        c, s = math.cos(a3), math.sin(a3)
        mx, my = px[2] + c * lx - s * ly, py[2] + s * lx + c * ly
        plan = self.plan
        if plan.yaw == 0.0:
            return (mx, mx), my, a3, c, s, reach
        # top view: the mount sits `behind` along the robot and +-lateral across it
        cos_yaw, sin_yaw = plan.yaw_trig()
        behind = mx - px[1]
        shift = behind * (cos_yaw - 1.0)
        lat = self.config.sensors.back_lateral * sin_yaw
        return (mx + shift + lat, mx + shift - lat), my, a3, c, s, reach

    def _down(self, mx: float, my: float, c: float, s: float, reach: float) -> float | None:
        x1, y1 = mx + s * reach, my - c * reach
        best, _i = self.world.profile.first(mx, my, x1, y1)  # (ray's point, written out)
        if best == math.inf:
            return None
        return math.hypot((mx + (x1 - mx) * best) - mx, (my + (y1 - my) * best) - my)
