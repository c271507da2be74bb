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
            "offset of one front sensor; turning back to that heading")


def distrusted(why: str) -> tuple[str, str]:
    """Why SFR and why SFL are distrusted."""
    return f"distrusted: {why}", "distrusted with SFR: the front pair"


def lost_both(where: str, made_rad: float, sfr: float, sfl: float) -> str:
    return (f"calibration ({where}): the squaring turn lost both beams after "
            f"{math.degrees(made_rad):.0f}°, and standing on all wheels neither meets the "
            f"riser (SFR {sfr:.3f} m, SFL {sfl:.3f} m): no heading square to a riser loses "
            "both; one front sensor may read an offset, which the turn chased until "
            "neither beam met the riser")


def turning_back(lost: str) -> str:
    return f"{lost}; turning back to the heading the turn began from (by the odometer)"


def named(sensor: str, moved: float, partner: str, partner_moved: float, chased: str) -> str:
    more = "more" if moved > 0 else "less"
    return (f"judged biased: back on the heading where the squaring turn began (by the "
            f"odometer), {sensor} reads {abs(moved) * 100:.1f} cm {more} than it did there "
            f"and {partner} within {abs(partner_moved) * 1000:.1f} mm of it: {sensor}'s "
            f"offset began meanwhile, and the turn chased it ({chased})")


def unnamed(chased: str, moved: tuple[float, float] | None) -> str:
    if moved is None:
        return ("back on the heading where the squaring turn began (by the odometer), no "
                f"reading of the pair there to compare: nothing names which ({chased})")
    return ("back on the heading where the squaring turn began (by the odometer), SFR "
            f"reads {moved[0] * 1000:+.1f} mm and SFL {moved[1] * 1000:+.1f} mm from what "
            "they read there: the offset was there before the turn, and nothing names "
            f"which sensor carries it ({chased})")
