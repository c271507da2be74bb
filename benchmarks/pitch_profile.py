"""How far the robot pitches on a normal run: the figures behind the default
``[safety] max_pitch_deg`` and ``max_rate_dps``.

For each scenario (default: every shipped one) it runs the program on
``sim://`` and prints segment 2's least and greatest pitch and its fastest
pitch rate as the IMU reports them (``Snapshot.imu``, every tick), with the
phase each happened in, and the largest pitch of any segment from the
simulation's truth.  The last line gives the maxima over all runs.

A script that prints figures, not a test: it asserts nothing.  Usage:

    python benchmarks/pitch_profile.py [SCENARIO ...] [--config FILE]
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

from stairbot.control.algorithm.controller import Controller
from stairbot.control.robot_config import load_config
from stairbot.hardware import Snapshot
from stairbot.inputs.scenario import load_scenario, shipped_scenarios
from stairbot.run.robots import RobotOptions, open_robot
from stairbot.run.runner import run


@dataclass
class Profile:
    low: float = 0.0
    high: float = 0.0
    rate: float = 0.0
    pitch_phase: str = "-"
    rate_phase: str = "-"

    def see(self, ctl: Controller, snap: Snapshot) -> None:
        imu = snap.imu
        if imu is None:
            return
        if imu.pitch_deg < self.low or imu.pitch_deg > self.high:
            if abs(imu.pitch_deg) > max(-self.low, self.high):
                self.pitch_phase = ctl.phase.value
            self.low, self.high = min(self.low, imu.pitch_deg), max(self.high, imu.pitch_deg)
        if abs(imu.pitch_rate_dps) > self.rate:
            self.rate, self.rate_phase = abs(imu.pitch_rate_dps), ctl.phase.value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", help="scenario files or shipped names")
    parser.add_argument("--config", help="robot config (default: the shipped one)")
    args = parser.parse_args()
    config = load_config(args.config)
    most_pitch = most_rate = 0.0
    for name in args.scenarios or shipped_scenarios():
        scenario = load_scenario(name)
        profile = Profile()
        session = open_robot("sim://", config, RobotOptions(world=scenario))
        try:
            result = run(session, config, on_tick=profile.see)
        finally:
            session.close()
        most_pitch = max(most_pitch, -profile.low, profile.high)
        most_rate = max(most_rate, profile.rate)
        truth = result.max_pitch_deg or 0.0
        print(f"{scenario.name:30s} {result.outcome:9s} pitch {profile.low:+6.2f} .. "
              f"{profile.high:+6.2f} deg ({profile.pitch_phase}), rate {profile.rate:5.1f} deg/s "
              f"({profile.rate_phase}); any segment {truth:.2f} deg")
    print(f"most: pitch {most_pitch:.2f} deg, rate {most_rate:.1f} deg/s")


if __name__ == "__main__":
    main()
