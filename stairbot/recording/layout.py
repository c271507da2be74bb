"""The Foxglove layout for stairbot's MCAP recordings, built with the
Foxglove SDK's typed layouts (``foxglove.layouts``): the shipped file,
docs/foxglove-layout.json, is this module's output, and a test keeps the
two equal.  Regenerate it with::

    python -m stairbot.recording.layout > docs/foxglove-layout.json

Left: the 3-D scene (the stairs and the segments on their frames, which
the pose topic moves, followed from segment 2) over the event log.
Right: the phase and each sensor's status over time, the IMU's pitch, the
lifts' extensions, the sensors' distances, and the link's latest health.
One layout serves every robot: it names the side pair SSR/SSL too, whose
series stay empty in a recording of a robot without it (the recording has
no such field, so nothing is drawn).
"""

from __future__ import annotations

import json
from typing import Any

import foxglove.layouts as fl

from stairbot.hardware import LIFT_MOTORS, SensorId
from stairbot.recording import topics


def _plot(title: str, label: str, paths: list[tuple[str, str]]) -> fl.PlotPanel:
    return fl.PlotPanel(title=title, config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=value, label=name, enabled=True) for value, name in paths],
        y_axis_label=label, is_synced=True, show_legend=True, legend_display="floating"))


def layout() -> fl.Layout:
    """The layout (see the module)."""
    three_d = fl.ThreeDeePanel(title="stairs and segments", config=fl.ThreeDeeConfig(
        follow_tf="segment2", fixed_frame="world", follow_mode="follow-position",
        topics={topic: fl.BaseRendererSceneUpdateTopicSettings(visible=True)
                for topic in (topics.SCENE,)},
        camera_state=fl.ThreeDeeCameraState(distance=1.5)))
    log = fl.LogPanel(title="events", config=fl.LogConfig(topic_to_render=topics.EVENTS,
                                                          show_level=True))
    series = [fl.StateTransitionsSeries(value=f"{topics.PHASE}.message", label="phase")]
    series += [fl.StateTransitionsSeries(value=f"{topics.SENSORS}.{s.value}.status",
                                         label=s.value) for s in SensorId]
    states = fl.StateTransitionsPanel(title="phase and sensor status",
                                      config=fl.StateTransitionsConfig(
                                          paths=series, is_synced=True, show_legend=True))
    pitch = _plot("pitch", "deg", [(f"{topics.SENSORS}.imu.pitch_deg", "IMU pitch"),
                                   (f"{topics.SENSORS}.imu.roll_deg", "IMU roll")])
    lifts = _plot("lifts", "m", [(f"{topics.MOTORS}.{m.value}.extension_m", m.value)
                                 for m in LIFT_MOTORS])
    sensors = _plot("distance sensors", "m",
                    [(f"{topics.SENSORS}.{s.value}.distance_m", s.value) for s in SensorId])
    link = fl.RawMessagesPanel(title="link health", config=fl.RawMessagesConfig(
        topic_path=f"{topics.LINK}.health"))
    left = fl.SplitContainer(direction="column", items=[
        fl.SplitItem(proportion=3, content=three_d), fl.SplitItem(proportion=2, content=log)])
    right = fl.SplitContainer(direction="column", items=[
        fl.SplitItem(proportion=2, content=states), fl.SplitItem(content=pitch),
        fl.SplitItem(content=lifts), fl.SplitItem(content=sensors),
        fl.SplitItem(proportion=0.7, content=link)])
    return fl.Layout(content=fl.SplitContainer(direction="row", items=[
        fl.SplitItem(proportion=1, content=left), fl.SplitItem(proportion=1, content=right)]))


def layout_json() -> str:
    """The layout as the shipped file holds it: indented, one trailing newline."""
    data: Any = json.loads(layout().to_json())
    return json.dumps(data, indent=2) + "\n"


if __name__ == "__main__":
    print(layout_json(), end="")
