"""The MCAP recording's topics and the JSON schemas of its JSON channels: one
place for the writer, the reader (``stairbot plot``), the Foxglove layout
and the tests.

Every tick (one control cycle) writes one message on each of
:data:`TICK_TOPICS` and on the pose topic; every event one on
:data:`EVENTS`, :data:`RECORD` and, for a phase change, :data:`PHASE`.
Times are the robot's clock (``Snapshot.time_s``, ``Event.time_s``): a
message's log time is the recording's wall-clock start (metadata
``stairbot``, ``time_origin_ns``) plus that time.

Standard library only.
"""

from __future__ import annotations

from typing import Any

from stairbot.hardware import BASE_SENSORS, LIFT_MOTORS, SIDE_SENSORS, MotorId, SensorStatus

SCENE = "/scene"
"""foxglove.SceneUpdate: the stairs (frame ``world``) and each segment with its
wheels (frames ``segment1``..``segment3``); written when a robot is opened."""
JOINTS = "/robot/joint_states"
"""foxglove.JointStates, SI units as Foxglove's schema asks: the wheel motors
as revolute joints (rad, rad/s), the lifts as prismatic ones (m, m/s)."""
MOTORS = "/robot/motors"
"""JSON: each motor's turn counter, speed, the speed commanded and any fault."""
SENSORS = "/robot/sensors"
"""JSON: each distance sensor's reading, status and age (SFR, SFL, SBR, SBL;
SSR and SSL only on a robot with the side pair); the IMU."""
LINK = "/robot/link"
"""JSON: the link's health figures the robot reports each tick (empty for a
simulation in this process: it has no link)."""
EVENTS = "/events"
"""foxglove.Log: every event of the run (the console's log, the progress lines)."""
PHASE = "/phase"
"""foxglove.Log: the phase changes alone (message: the phase, name: its flow)."""
RECORD = "/events/record"
"""JSON: every event as the JSON-lines record writes it (``Event.to_dict``)."""

TICK_TOPICS = (JOINTS, MOTORS, SENSORS, LINK)
"""One message each per tick (and one on the pose topic)."""

ATTACHMENTS = ("robot_config.json", "scenario.json", "stairbot.dbc")
"""The resolved robot config, the resolved scenario (one per robot opened),
and the boards' CAN database."""

_NUMBER = {"type": "number"}
_TIME = {"type": "number", "description": "robot time, s (Snapshot.time_s)"}


def _object(properties: dict[str, Any], description: str,
            required: list[str] | None = None) -> dict[str, Any]:
    return {"type": "object", "description": description, "properties": properties,
            "required": required if required is not None else list(properties)}


_READING = _object({
    "distance_m": {"type": "number", "description": "m; with out_of_range clamped to the "
                   "sensor's minimum or maximum; with error meaningless"},
    "status": {"type": "string", "enum": [s.value for s in SensorStatus]},
    "age_s": {"type": "number", "description": "how long before time_s it was measured"},
}, "one distance reading")

_IMU = {"oneOf": [{"type": "null"}, _object({
    "pitch_deg": {"type": "number", "description": "segment 2, + nose up"},
    "roll_deg": {"type": "number", "description": "+ right side down"},
    "pitch_rate_dps": _NUMBER, "roll_rate_dps": _NUMBER,
    "age_s": {"type": "number", "description": "how long before time_s it was measured"},
}, "the sensor board's inertial unit")]}

_SIDE_READING = {**_READING, "description": "one distance reading of the side pair: only on "
                 "a robot that has it (the config's [sensors] side_model)"}

SENSORS_SCHEMA: dict[str, Any] = {
    "title": "stairbot.Sensors",
    **_object({"time_s": _TIME, **{s.value: _READING for s in BASE_SENSORS},
               **{s.value: _SIDE_READING for s in SIDE_SENSORS}, "imu": _IMU},
              "every sensor as the host read it at one tick (raw: before perception)",
              required=["time_s", *(s.value for s in BASE_SENSORS), "imu"]),
}
"""SSR and SSL are optional: a recording of a robot without the side pair
(and every recording made before it existed) has the four base sensors alone."""

_MOTOR = {
    "turns": {"type": "number", "description": "the motor's turn counter"},
    "speed_tps": {"type": "number", "description": "present speed, turns/s"},
    "command_tps": {"type": ["number", "null"],
                    "description": "speed commanded this tick, turns/s (null: nothing "
                                   "sent, the emergency stop held every motor)"},
    "fault": {"type": ["string", "null"]},
}
_LIFT = {**_MOTOR, "extension_m": {
    "type": "number", "description": "the lift's travel: turns x lift_travel_per_turn, m "
                                     "(+ raises the end segment relative to segment 2)"}}

MOTORS_SCHEMA: dict[str, Any] = {
    "title": "stairbot.Motors",
    **_object({"time_s": _TIME,
               "sent": {"type": "boolean", "description": "whether a command was sent"},
               **{m.value: _object(_LIFT if m in LIFT_MOTORS else _MOTOR, f"motor {m.value}")
                  for m in MotorId}},
              "every motor's telemetry and command at one tick"),
}

LINK_SCHEMA: dict[str, Any] = {
    "title": "stairbot.Link",
    **_object({"time_s": _TIME,
               "health": {"type": "object", "additionalProperties": _NUMBER,
                          "description": "the link's counters and round-trip figures "
                                         "(frames_tx, retries, lost, rtt_median_ms, ...); "
                                         "empty without a link"}},
              "the link's health at one tick"),
}

RECORD_SCHEMA: dict[str, Any] = {
    "title": "stairbot.Event",
    **_object({"time_s": _TIME,
               "kind": {"type": "string"},
               "phase": {"type": ["string", "null"]},
               "message": {"type": "string"},
               "data": {"type": "object"}},
              "one event, as a line of the JSON-lines record"),
}
