"""What :mod:`~stairbot.control.algorithm.squaring_bias` says."""

from __future__ import annotations

import math


def chased(index: int, off_rad: float, allowed_rad: float, sfr: float, sfl: float,
           lost: bool) -> str:
    what = (f"the squaring turn lost both beams {math.degrees(off_rad):+.1f}° from"
            if lost else f"the squaring turn went {math.degrees(off_rad):+.1f}° from")
    return (f"descent 1, step {index + 1}: {what} the heading the step was climbed with "
            f"(by the odometer; SFR {sfr:.3f} m, SFL {sfl:.3f} m), where square to the "
            f"riser lies within {math.degrees(allowed_rad):.1f}° of it: the turn chases an "
            "offset of one front sensor, and nothing names which; turning back to that "
            "heading, then neither front sensor is trusted")


def distrusted(why: str) -> tuple[str, str]:
    """Why SFR and why SFL are distrusted."""
    return f"distrusted: {why}", "distrusted with SFR: the front pair"


def lost_both(where: str, made_rad: float, sfr: float, sfl: float) -> str:
    return (f"calibration ({where}): the squaring turn lost both beams after "
            f"{math.degrees(made_rad):.0f}°, and standing on all wheels neither meets the "
            f"riser (SFR {sfr:.3f} m, SFL {sfl:.3f} m): no heading square to a riser loses "
            "both; one front sensor may read an offset, which the turn chased until "
            "neither beam met the riser; stopping")
