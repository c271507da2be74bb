"""What the controller allows a robot, computed from its config: how far the
front pair squares up from, whether narrow steps are safe for its masses,
the shortest tread it enters, the room a landing needs; and the config as
``config show``, a recording and a journal's digest see it (the file's
sections plus every derived value, these included).

The config is data (:mod:`stairbot.inputs.config`); these figures come from
the controller's own checks (perception's noise model, the static-stability
check, the landing's turning room), so they live beside them and take the
config as input.
"""

from __future__ import annotations

import math
from typing import Any
from weakref import WeakKeyDictionary

import msgspec

from stairbot.control.algorithm import landing, stability
from stairbot.control.tolerances import quiet_range_m
from stairbot.inputs.config import RobotConfig

_MARGINS: WeakKeyDictionary[RobotConfig, float] = WeakKeyDictionary()


def square_range_m(cfg: RobotConfig) -> float:
    """Farthest reading the front pair squares up from at the start.
    Within it, a cone looking up front_cone_top_rad rises no higher than
    the lowest riser the robot climbs (:func:`min_step_rise_m`), so both beams
    read the first riser alone (farther, the upper rays pass over it and
    the reading blends the risers beyond); and the pair's stated noise
    lets it square up to equal_tolerance
    (:func:`~stairbot.control.tolerances.quiet_range_m`).  Infinite for level,
    quiet rays."""
    top = cfg.front_cone_top_rad
    cone = math.inf if top <= 0.0 else \
        (min_step_rise_m(cfg) - cfg.sensors.front_height) / math.tan(top)
    return min(cone, quiet_range_m(cfg))


def sight_clearance_m(cfg: RobotConfig) -> float:
    """How far above a step's top the front beam must stand before the pair
    reads past the riser, when nothing stands ahead within its range (a
    landing, a long tread): the cone's lowest ray, looking
    :attr:`~stairbot.inputs.config.RobotConfig.front_cone_bottom_rad` down,
    meets the step's own tread, and the pair reads "too near" until that ray
    meets it at least its least range away (min_range x sin of the angle);
    nor may it graze the edge, approach_gap ahead.  0 for a cone whose
    lowest ray runs level or up, and for a ranger that hears no echo from a
    surface met that far off its normal (``echo_incidence_deg``: the tread
    is then no target).  A Sharp's 4-degree spot, level, reading from 0.10 m:
    3.5 mm."""
    down = cfg.front_cone_bottom_rad
    if down <= 0.0:
        return 0.0
    echo = cfg.sensors.spec(back=False).echo_incidence_deg
    if echo is not None and 90.0 - math.degrees(down) > echo:
        return 0.0
    near = cfg.sensors.range(back=False)[0]
    return max(near * math.sin(down), cfg.algorithm.approach_gap * math.tan(down))


def max_step_rise_m(cfg: RobotConfig) -> float:
    """Highest rise it climbs: what the lift lets the beam see over
    (:attr:`~stairbot.inputs.config.RobotConfig.max_step_rise_m`) less
    :func:`sight_clearance_m`.  Higher steps are refused (too high)."""
    return cfg.max_step_rise_m - sight_clearance_m(cfg)


def min_tread_m(cfg: RobotConfig) -> float:
    """Shortest tread it enters, measured at the first sight over the riser
    as the reading less the approach's gap: LENGTH_OF_A_ROBOT + SAFE_LENGTH;
    with narrow steps (when :func:`narrow_steps_safe`), LENGTH_OF_FIRST_MODULE
    + LENGTH_OF_SECOND_MODULE + SAFE_LENGTH."""
    if narrow_steps_safe(cfg):
        return cfg.LENGTH_OF_FIRST_MODULE + cfg.LENGTH_OF_SECOND_MODULE + cfg.SAFE_LENGTH
    return cfg.LENGTH_OF_A_ROBOT + cfg.SAFE_LENGTH


def min_step_rise_m(cfg: RobotConfig) -> float:
    """Lowest rise it climbs: :meth:`~stairbot.inputs.config.RobotConfig.min_rise_for`
    the shortest tread it enters.  Lower steps are refused."""
    return cfg.min_rise_for(min_tread_m(cfg))


def narrow_steps_margin_m(cfg: RobotConfig) -> float:
    """How far inside segment 2's wheels the centre of mass stays while
    segment 2 alone carries the robot, segment 3 at its height (in the air
    over the step below) and segment 1 anywhere from down to lifted its
    whole stroke, pitched either way as far as the supervisor lets it
    (``[safety] max_pitch_deg``): what narrow steps ask of the masses
    (:mod:`stairbot.control.algorithm.stability`; negative: outside).  Level,
    any robot that calibrates passes (calibration's lift stands it on
    segment 2's wheels too); pitched, segment 1 lifted high swings its
    weight over them, and the lighter the end segments the less.  Worked
    out once per config."""
    margin = _MARGINS.get(cfg)
    if margin is None:
        top = (cfg.MAX_OF_VERTICAL_TURNS, 0.0)
        pitch = cfg.safety.max_pitch_deg
        margin = _MARGINS[cfg] = min(stability.worst(cfg, (2,), (0.0, 0.0), top, p).margin
                                     for p in (-pitch, 0.0, pitch))
    return margin


def narrow_steps_refusal(cfg: RobotConfig) -> str | None:
    """Why ``[algorithm] narrow_steps`` is not safe for this robot, or None
    (also None when it is not asked for)."""
    if not cfg.algorithm.narrow_steps:
        return None
    margin, need = narrow_steps_margin_m(cfg), cfg.safety.stability_margin
    if margin < need:
        side = "inside" if margin >= 0 else "outside"
        return (f"with segment 2's wheels alone carrying the robot, segment 1 lifted and "
                f"the robot pitched {cfg.safety.max_pitch_deg:g}°, the centre of mass "
                f"would stand {abs(margin) * 1000:.1f} mm {side} them, less than [safety] "
                f"stability_margin ({need * 1000:g} mm)")
    near = cfg.SAFE_LENGTH + cfg.algorithm.approach_gap
    reads_from = cfg.sensors.range(back=False)[0]
    if reads_from > near:
        return (f"on a narrow step the front pair stands SAFE_LENGTH + approach_gap "
                f"({near:.3f} m) from the next riser, nearer than it reads "
                f"({reads_from:.3f} m)")
    return None


def narrow_steps_safe(cfg: RobotConfig) -> bool:
    """``[algorithm] narrow_steps`` is set and nothing refuses it
    (:func:`narrow_steps_refusal`: the static-stability check, and the
    front pair's range).  When refused, the robot keeps the whole
    length's min_tread_m (``config show`` and ``run`` say why)."""
    return cfg.algorithm.narrow_steps and narrow_steps_refusal(cfg) is None


REACH_TREADS_M = (0.26, 0.30, 0.33, 0.36, 0.40, 0.50)
"""Treads ``config show`` gives the lowest riser behind
(``min_rise_behind_<tread>_m``): residential treads to the long ones of
landings and split levels."""


def reach(cfg: RobotConfig) -> dict[str, float]:
    """The lowest next riser the robot measures each of :data:`REACH_TREADS_M`
    against (:meth:`~stairbot.inputs.config.RobotConfig.min_rise_for`), keyed
    ``min_rise_behind_<tread>_m``."""
    return {f"min_rise_behind_{t:.2f}_m": cfg.min_rise_for(t) for t in REACH_TREADS_M}


def derived(cfg: RobotConfig) -> dict[str, float]:
    """Everything that follows from the file, for ``config show``."""
    names = ("LENGTH_OF_A_ROBOT", "BACK_CLEARANCE", "MAX_OF_VERTICAL_TURNS",
             "NUMBER_OF_VERTICAL_TURNS_FOR_CLEARANCE",
             "NUMBER_OF_HORIZONTAL_TURNS_FOR_APPROACH",
             "NUMBER_OF_HORIZONTAL_TURNS_FOR_FIRST_MODULE",
             "NUMBER_OF_HORIZONTAL_TURNS_FOR_SECOND_MODULE")
    out = {name: float(getattr(cfg, name)) for name in names}
    out["number_of_vertical_turns"] = cfg.initial_number_of_vertical_turns
    out["wheel_circumference_m"] = cfg.wheel_circumference
    out["wheel_speed_m_s"] = float(cfg.wheel_speed_m_s)
    out["lift_speed_m_s"] = float(cfg.lift_speed_m_s)
    out["max_step_rise_m"] = float(max_step_rise_m(cfg))
    out["min_tread_m"] = float(min_tread_m(cfg))
    out["min_step_rise_m"] = float(min_step_rise_m(cfg))
    out.update(reach(cfg))
    out["max_drop_m"] = float(cfg.max_drop_m)
    if cfg.algorithm.narrow_steps:
        out["narrow_steps_margin_m"] = narrow_steps_margin_m(cfg)
    square = square_range_m(cfg)
    if math.isfinite(square):  # a cone looking up, or a noisy pair
        out["square_range_m"] = square
    if cfg.algorithm.landings:
        # the controller's own figures (it refuses a landing with less room)
        room = landing.turn_room_m(cfg)
        out["landing_turn_room_m"] = room
        out["min_landing_m"] = 2.0 * room + landing.DEPTH_MARGIN
    return out


def config_dict(cfg: RobotConfig) -> dict[str, Any]:
    """The resolved config as plain data: the file's sections plus ``derived``
    (and, with narrow steps asked for, why they are refused: None when not)."""
    out: dict[str, Any] = {
        name: msgspec.to_builtins(getattr(cfg, name))
        for name in ("geometry", "masses", "motors", "sensors", "algorithm", "safety")
    }
    out["geometry"]["LENGTH_OF_A_ROBOT"] = round(cfg.LENGTH_OF_A_ROBOT, 6)
    out["derived"] = {k: round(v, 6) for k, v in derived(cfg).items()}
    if cfg.algorithm.narrow_steps:
        out["narrow_steps_refused"] = narrow_steps_refusal(cfg)  # None: it may
    out["source"] = cfg.source
    return out
