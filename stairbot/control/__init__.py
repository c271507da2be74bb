"""What a tick decides: the seed's algorithm (``algorithm/``: phases,
transition table, controller), what every tick sees (``perception``) and
checks (``supervisor``, ``tilt``), and the limits computed from a robot
config.  Pure Python; it builds on ``stairbot.inputs`` and the shared modules
at the top, and imports nothing of the run, the drivers or anything above."""
