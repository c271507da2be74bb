"""The simulation's physics and instability settings (not part of the robot
config): :class:`WorldParams`, given to :class:`stairbot.fakes.world.World`."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class WorldParams:
    """Physics and instability settings (not part of the robot config)."""

    dt: float = 1.0 / 600.0  # 12 physics steps per 20 ms control tick
    iterations: int = 10
    stairs_friction: float = 1.0  # combined by product with the wheels' 0.9
    wheel_friction: float = 0.9  # rubber on wood
    body_friction: float = 0.3  # ABS chassis on wood
    chamfer: float = 0.005  # bottom edges of each segment's chassis, m
    stairs_radius: float = 0.001  # rounds the step nosings
    collision_slop: float = 0.0005
    lift_stall: float = 0.002  # a lift's target never runs further ahead than this, m
    lift_hold_speed: float = 0.02  # a held lift corrects any creep at most this fast, m/s
    pitch_limit_deg: float = 35.0
    fall_speed: float = 1.0  # m/s downward counts as falling
    airborne_limit_s: float = 0.3  # every wheel off every support this long: fell
    contact_check_s: float = 0.1  # how often the wheels' contacts are looked up
