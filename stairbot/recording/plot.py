"""A recording drawn over time as a PNG (``stairbot plot``; matplotlib, the
optional extra ``stairbot[plot]``): the phases as bands, the pitch, the
segments' heights, the lifts' extensions and the distance sensors'
readings with their status (the side pair's in a panel of its own, drawn
only when the recording has it).  A JSON-lines record holds events alone, so
its plot has the phases and the events, and says so."""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from stairbot.errors import InputError
from stairbot.recording.read import Recording

FLOW_COLOURS = {"calibration": "#cfe2f3", "ascent": "#d9ead3", "descent": "#fce5cd",
                "landing": "#ead1dc",
                "end": "#eeeeee"}
OTHER_FLOW = "#e6e6e6"
SEGMENT_COLOURS = {"segment1": "#d55e00", "segment2": "#0072b2", "segment3": "#009e73"}
SENSOR_COLOURS = {"SFR": "#d55e00", "SFL": "#e69f00", "SBR": "#0072b2", "SBL": "#56b4e9",
                  "SSR": "#009e73", "SSL": "#cc79a7"}
SIDE_PAIR = ("SSR", "SSL")
STATUS_MARKS = {"out_of_range": "x", "error": "o"}
"""How a reading that is not ok is marked (in the sensor's colour)."""
EVENT_LINES = {"error": "#d62728", "pause": "#ff7f0e", "warning": "#ff7f0e", "link": "#9467bd"}
EXTRA = "plot"


class PlotExtraMissing(InputError):
    """matplotlib (or the MCAP reader) is not installed."""

    def __init__(self, missing: str) -> None:
        super().__init__("stairbot plot", None, f"needs {missing}, which is not installed: "
                         f"pip install 'stairbot[{EXTRA}]'")


def check_extra() -> None:
    """Raise PlotExtraMissing unless everything ``stairbot plot`` draws with is there."""
    for module in ("matplotlib", "mcap", "mcap_protobuf"):
        try:
            __import__(module)
        except ImportError:
            raise PlotExtraMissing(module.replace("_", "-")) from None


@dataclass(frozen=True)
class Band:
    start_s: float
    end_s: float
    phase: str
    flow: str


def phase_bands(events: Sequence[dict[str, Any]], end_s: float) -> list[Band]:
    """Each phase from the event that entered it to the next phase (or ``end_s``)."""
    starts = [(float(e["time_s"]), str(e.get("phase") or e.get("message", "")),
               str((e.get("data") or {}).get("flow", "")))
              for e in events if e.get("kind") == "phase"]
    bands = []
    for i, (t, phase, flow) in enumerate(starts):
        nxt = starts[i + 1][0] if i + 1 < len(starts) else max(end_s, t)
        bands.append(Band(t, nxt, phase, flow))
    return bands


def _end_time(rec: Recording) -> float:
    times = [float(e["time_s"]) for e in rec.events]
    tel = rec.telemetry
    for column in (tel.time_s, tel.motor_time_s, tel.pose_time_s):
        if column:
            times.append(column[-1])
    return max(times, default=0.0)


def _title(rec: Recording) -> str:
    robot = rec.metadata.get("robot", {})
    where = f"{robot.get('scenario', '?')} on {robot.get('url', '?')}" if robot else ""
    summary = next((e for e in reversed(rec.events) if e.get("kind") == "summary"), None)
    ended = summary["message"] if summary else "no summary: the recording ends before the run"
    cut = "" if rec.complete else " (cut short: read up to where it ends)"
    return f"{rec.path}{cut}\n{where}{' · ' if where else ''}{ended}"


def render(rec: Recording, *, width_in: float = 12.0, dpi: int = 100) -> bytes:
    """The PNG of ``rec``.  Raises PlotExtraMissing without matplotlib."""
    check_extra()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    end = _end_time(rec)
    bands = phase_bands(rec.events, end)
    telemetry = bool(rec.telemetry.time_s or rec.telemetry.pose_time_s)
    side = telemetry and any(name in rec.telemetry.distance_m for name in SIDE_PAIR)
    ratios = [0.5, 1, 1, 1, 1, 1, *([1] if side else [])] if telemetry else [0.5, 1]
    fig, axes = plt.subplots(len(ratios), 1, sharex=True, figsize=(width_in, 2.2 * sum(ratios)),
                             dpi=dpi, gridspec_kw={"height_ratios": ratios})
    _phase_strip(axes[0], bands)
    if telemetry:
        _pitch(axes[1], rec)
        _heights(axes[2], rec)
        _lifts(axes[3], rec)
        _sensors(axes[4], rec, ("SFR", "SFL"), "front sensors")
        _sensors(axes[5], rec, ("SBR", "SBL"), "back sensors")
        if side:
            _sensors(axes[6], rec, SIDE_PAIR, "side sensors")
    else:
        _events_only(axes[1], rec)
    for ax in axes[1:]:
        for b in bands:
            ax.axvspan(b.start_s, b.end_s, color=FLOW_COLOURS.get(b.flow, OTHER_FLOW),
                       alpha=0.45, linewidth=0, zorder=0)
        for e in rec.events:
            colour = EVENT_LINES.get(str(e.get("kind")))
            if colour is not None:
                ax.axvline(float(e["time_s"]), color=colour, linewidth=0.8, zorder=1)
        ax.grid(True, linewidth=0.3, alpha=0.6)
    axes[-1].set_xlabel("robot time (s)")
    start = min([0.0, *(b.start_s for b in bands[:1])])
    axes[0].set_xlim(start, max(end, start + 1e-3))
    fig.suptitle(_title(rec), fontsize=9, x=0.01, ha="left")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def _phase_strip(ax: Any, bands: Sequence[Band]) -> None:
    from matplotlib.patches import Patch

    span = max((b.end_s for b in bands), default=1.0) - min((b.start_s for b in bands),
                                                            default=0.0)
    for b in bands:
        ax.axvspan(b.start_s, b.end_s, facecolor=FLOW_COLOURS.get(b.flow, OTHER_FLOW),
                   linewidth=0.3, edgecolor="white")
        if span > 0 and (b.end_s - b.start_s) / span > 0.04:  # room for a name
            ax.text((b.start_s + b.end_s) / 2, 0.5, b.phase.split(" — ")[-1][:28],
                    ha="center", va="center", fontsize=6, rotation=0, clip_on=True)
    ax.set_yticks([])
    ax.set_ylabel("phase", fontsize=8)
    flows = [f for f in FLOW_COLOURS if any(b.flow == f for b in bands)]
    if flows:
        ax.legend(handles=[Patch(color=FLOW_COLOURS[f], label=f) for f in flows],
                  loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7, frameon=False)


def _legend(ax: Any) -> None:
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7, frameon=False)


def _pitch(ax: Any, rec: Recording) -> None:
    tel = rec.telemetry
    if any(not math.isnan(p) for p in tel.pitch_deg):
        ax.plot(tel.time_s, tel.pitch_deg, color="black", linewidth=0.8, label="IMU")
    if tel.pose_topic == "/sim/true_pose" and "segment2" in tel.pose_pitch_deg:
        ax.plot(tel.pose_time_s, tel.pose_pitch_deg["segment2"], color="#0072b2",
                linewidth=0.8, linestyle="--", label="segment 2\n(simulation)")
    ax.set_ylabel("pitch (deg)", fontsize=8)
    _legend(ax)


def _heights(ax: Any, rec: Recording) -> None:
    tel = rec.telemetry
    what = "simulation" if tel.pose_topic == "/sim/true_pose" else "estimated"
    for frame, heights in tel.height_m.items():
        ax.plot(tel.pose_time_s, heights, color=SEGMENT_COLOURS.get(frame), linewidth=0.9,
                label=frame.replace("segment", "segment "))
    ax.set_ylabel(f"axle height (m)\n{what}", fontsize=8)
    _legend(ax)


def _lifts(ax: Any, rec: Recording) -> None:
    tel = rec.telemetry
    for name, values in tel.lift_m.items():
        ax.plot(tel.motor_time_s, values, linewidth=0.9, label=name)
    ax.set_ylabel("lift extension (m)", fontsize=8)
    _legend(ax)


def _sensors(ax: Any, rec: Recording, names: Sequence[str], what: str) -> None:
    """The readings with status ok as lines, the others as marks where the
    sensor put them (out of range: clamped to its range; error: meaningless)."""
    from matplotlib.lines import Line2D

    tel = rec.telemetry
    shown_status: set[str] = set()
    for name in names:
        values = tel.distance_m.get(name)
        if values is None:
            continue
        statuses = tel.status.get(name, [])
        colour = SENSOR_COLOURS.get(name)
        ok = [v if s == "ok" else math.nan for v, s in zip(values, statuses, strict=False)]
        ax.plot(tel.time_s, ok, color=colour, linewidth=0.8, label=name)
        for status, marker in STATUS_MARKS.items():
            xs = [t for t, s in zip(tel.time_s, statuses, strict=False) if s == status]
            ys = [v for v, s in zip(values, statuses, strict=False) if s == status]
            if xs:
                shown_status.add(status)
                ax.scatter(xs, ys, marker=marker, s=5, color=colour, linewidths=0.5,
                           zorder=3)
    handles, _labels = ax.get_legend_handles_labels()
    handles += [Line2D([], [], linestyle="", marker=STATUS_MARKS[s], color="#555555",
                       label=s.replace("_", " ")) for s in STATUS_MARKS if s in shown_status]
    ax.set_ylabel(f"{what} (m)", fontsize=8)
    if handles:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7,
                  frameon=False)


def _events_only(ax: Any, rec: Recording) -> None:
    kinds = sorted({str(e.get("kind")) for e in rec.events})
    for e in rec.events:
        ax.plot([float(e["time_s"])], [kinds.index(str(e.get("kind")))], marker="|",
                color=EVENT_LINES.get(str(e.get("kind")), "black"), markersize=10)
    ax.set_yticks(range(len(kinds)), kinds, fontsize=7)
    ax.set_ylabel("events", fontsize=8)
    why = ("a JSON-lines record holds the events alone: record to FILE.mcap for the pitch, "
           "heights, lifts and sensors" if rec.kind == "jsonl"
           else "no tick was recorded: the events alone")
    ax.text(0.5, -0.35, why, transform=ax.transAxes, ha="center", fontsize=8, color="#555555")
