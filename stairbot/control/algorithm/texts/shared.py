"""What the phases every flow shares say: a reading drive whose reading
jumps, the standing rule, and the stability check before a lift
(:mod:`~stairbot.control.algorithm.moves`,
:mod:`~stairbot.control.algorithm.standing`,
:mod:`~stairbot.control.algorithm.stability`)."""

from __future__ import annotations


# -- a reading drive --------------------------------------------------------------------
def reading_jumped(jump: float, reading: float) -> str:
    return (f"SFR/SFL jumped {jump * 1000:+.0f} mm from what the wheels explain "
            f"(reading {reading:.3f} m): the rest of the drive goes by turns")


# -- the standing rule ------------------------------------------------------------------
def _pair(back: bool) -> str:
    return "SBR/SBL" if back else "SFR/SFL"


def _readings(readings: tuple[float, float]) -> str:
    right, left = readings
    return f"{right:.3f} m / {left:.3f} m"


def disagree(back: bool, readings: tuple[float, float], label: str, wait_s: float) -> str:
    """``readings``: the pair's (right, left); ``label``: the phase's."""
    return (f"standing rule: {_pair(back)} disagree ({_readings(readings)}) in "
            f"{label}: all motors stopped, measuring again in "
            f"{wait_s:g} s")


def agree_again(back: bool, readings: tuple[float, float], label: str) -> str:
    return (f"standing rule: {_pair(back)} agree again "
            f"({_readings(readings)}): resuming {label}")


def no_figure(back: bool, label: str) -> str:
    """The wait's end, the pair giving no figure (lost: it reads as ERROR)."""
    return (f"standing rule: {_pair(back)} give no figure to compare (lost): resuming "
            f"{label}")


def still_disagree(back: bool, wait_s: float, readings: tuple[float, float], label: str) -> str:
    return (f"standing rule: {_pair(back)} still disagree after "
            f"{wait_s:g} s ({_readings(readings)}) in "
            f"{label}")


# -- stability before a lift ------------------------------------------------------------
UNSTABLE = "unstable lift"
"""How the reason of a refused lift begins (as "sensor error", "motor fault")."""


def unstable_lift(label: str, margin: float, carried: tuple[int, ...], rear_x: float,
                  front_x: float, centre_x: float, pitch_deg: float, need: float) -> str:
    """``label``: the lift phase's; ``margin`` how far inside the carrying
    wheels (``carried``: segments 1, 2, 3) the centre of mass would be
    (negative: outside); positions about segment 2's centre (m); ``need``:
    [safety] stability_margin."""
    who = " and ".join(str(i) for i in carried)
    plural = "s" if len(carried) > 1 else ""
    side = "outside" if margin < 0 else "inside"
    return (
        f"{UNSTABLE}: {label} would leave the centre of mass {abs(margin) * 1000:.1f} mm "
        f"{side} the wheels that carry the robot (segment{plural} {who}: {rear_x * 1000:+.1f} "
        f"to {front_x * 1000:+.1f} mm about segment 2's centre, the centre of mass at "
        f"{centre_x * 1000:+.1f} mm, pitch {pitch_deg:+.1f}°), less than [safety] "
        f"stability_margin {need * 1000:g} mm: refused before moving, every motor stopped, "
        "lifts holding")
