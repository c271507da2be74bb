"""A scenario the limp-home tests share: SFR errs from 42 s, in ascent 7 of
step 1 (segment 3 rising) of a two-step flight on the reference robot -- a
degraded stop the robot can limp home from on SFL."""

LOST_MID_CLIMB = """
[stairs]
count = 2
[[faults]]
at = 42.0
sensor = "SFR"
kind = "error"
"""
