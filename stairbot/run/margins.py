"""How close a run came to failing: the least of each safety margin over the
run, for ``stairbot run --json`` and every sweep result line
(docs/envelope.md, "Margins", defines each and says which a real robot
could estimate)."""

from __future__ import annotations

from dataclasses import dataclass

from stairbot.hardware import Truth
from stairbot.inputs.config import RobotConfig


@dataclass(frozen=True, slots=True)
class Margins:
    """The least margins of a run; the physical ones None where the robot
    cannot tell (boards on a wire) or never measured them."""

    stability_m: float | None
    """How far the centre of mass stood inside the span of the loaded wheels'
    contacts, seen from the side; negative: outside it."""
    pitch_deg: float | None
    """The supervisor's pitch limit (``[safety] max_pitch_deg``) less the
    largest pitch of any segment."""
    edge_m: float | None
    """How far a loaded wheel's centre stood past its tread's nosing; negative:
    beyond the edge, the wheel on the nosing.  None: no wheel on a tread
    with a nosing (the run never left the floor)."""
    stroke_m: float | None
    """The lift travel left at the more extended lift."""
    sensor_holds: int
    """The sensor holds (motors stopped while a sensor the phase needs read
    an error); they are counted in the run's ``pauses`` too."""

    @staticmethod
    def of(truth: Truth | None, config: RobotConfig, sensor_holds: int) -> Margins:
        """The margins from a robot's ``truth`` at the end of a run."""
        seen = truth.margins if truth is not None else None
        pitch = (None if truth is None or truth.max_pitch_deg is None
                 else config.safety.max_pitch_deg - truth.max_pitch_deg)
        return Margins(
            stability_m=_mm(seen.stability_m if seen else None),
            pitch_deg=None if pitch is None else round(pitch, 2),
            edge_m=_mm(seen.edge_m if seen else None),
            stroke_m=_mm(seen.stroke_m if seen else None),
            sensor_holds=sensor_holds,
        )


def _mm(metres: float | None) -> float | None:
    """To a tenth of a millimetre, as the result prints its distances."""
    return None if metres is None else round(metres, 4)
