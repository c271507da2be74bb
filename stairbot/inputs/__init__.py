"""What a run is given, read and checked: the robot config, the scenario, the
TOML schema they share, the sensors' datasheet figures, and the shipped TOML
files (``default_robot.toml``, ``configs/``, ``scenarios/``, ``sweeps/``).
Data only: it imports nothing of the control package or anything above it."""
