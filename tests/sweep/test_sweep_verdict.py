"""The verdict rules, one case each (docs/envelope.md)."""

from __future__ import annotations

import pytest

from stairbot.sweep.cases import Case
from stairbot.sweep.verdict import judge
from stairbot.sweep.worker import run_case

FACTS = {"zone": "inside", "expected_steps": 3, "faults": 0, "home_m": 0.05}


def result(outcome: str = "completed", up: int = 3, down: int = 3, offset: float = 0.01,
           fell: bool = False) -> dict[str, object]:
    return {"outcome": outcome, "steps_climbed": up, "steps_descended": down,
            "final_offset_m": offset, "fell": fell, "ascent_end": "top_reached",
            "error": None}


@pytest.mark.parametrize(("res", "zone", "faults", "moving", "want"), [
    (result(), "inside", 0, (), "climbed"),
    (result(), "band", 0, (), "climbed"),
    (result(), "outside", 0, (), "wrong"),
    (result(up=0, down=0), "outside", 0, (), "refused"),
    (result(up=0, down=0), "band", 0, (), "refused"),
    (result(up=0, down=0), "inside", 0, (), "wrong"),
    (result(outcome="error", up=1, down=1), "inside", 1, (), "refused"),  # a fault may refuse
    (result(outcome="error", up=1, down=1), "inside", 0, (), "wrong"),
    (result(outcome="fell", fell=True, up=0, down=0, offset=0.5), "outside", 0, (), "unsafe"),
    (result(), "inside", 0, ("MTF",), "unsafe"),
    (result(outcome="error", up=2, down=0, offset=0.6), "inside", 0, (), "stranded"),
    (result(up=3, down=3, offset=0.2), "inside", 0, (), "stranded"),
    # a sensor lost on the stairs, the robot limped home
    (result(outcome="came_home_degraded", up=1, down=1), "inside", 1, (), "came_home"),
    (result(outcome="came_home_degraded", up=1, down=1), "inside", 0, (), "wrong"),
    (result(outcome="came_home_degraded", up=2, down=1, offset=0.4), "inside", 1, (),
     "stranded"),
    (result(outcome="came_home_degraded", up=1, down=1, offset=0.2), "inside", 1, (),
     "stranded"),
])
def test_judge(res: dict[str, object], zone: str, faults: int, moving: tuple[str, ...],
               want: str) -> None:
    verdict, why = judge(res, {**FACTS, "zone": zone, "faults": faults}, moving)
    assert verdict == want, why


TOP = {"zone": "inside", "count": 4, "expected_steps": 4, "faults": 0, "home_m": 0.05,
       "from_top": True}


def descent(outcome: str = "completed", down: int = 4, clear: float | None = 0.36,
            fell: bool = False) -> dict[str, object]:
    return {"outcome": outcome, "steps_climbed": 0, "steps_descended": down,
            "final_offset_m": 1.5, "clear_of_stairs_m": clear, "fell": fell,
            "ascent_end": None, "error": None}


@pytest.mark.parametrize(("res", "zone", "faults", "moving", "want"), [
    (descent(), "inside", 0, (), "descended"),
    (descent(), "band", 0, (), "descended"),
    (descent(), "outside", 0, (), "wrong"),
    (descent(outcome="stopped", down=2, clear=-0.6), "outside", 0, (), "refused"),
    (descent(outcome="stopped", down=2, clear=-0.6), "band", 0, (), "refused"),
    (descent(outcome="stopped", down=2, clear=-0.6), "inside", 0, (), "wrong"),
    (descent(outcome="stopped", down=2, clear=-0.6), "inside", 1, (), "refused"),
    (descent(outcome="error", down=2, clear=-0.6), "outside", 0, (), "stranded"),
    (descent(down=3, clear=-0.2), "inside", 0, (), "stranded"),  # "the floor" too soon
    (descent(clear=None), "inside", 0, (), "stranded"),  # cannot tell where it is
    (descent(outcome="fell", fell=True, down=1), "outside", 0, (), "unsafe"),
    (descent(), "inside", 0, ("MWF",), "unsafe"),
    ({**descent(outcome="error", down=0, clear=-0.5), "fell": True,
      "fell_after": "segment 1 pitched 38 deg"}, "inside", 1, (), "unsafe"),
    (descent(outcome="error", down=1, clear=-0.5), "inside", 1, (), "refused"),  # a fault
    (descent(outcome="came_home_degraded"), "inside", 1, (), "came_home"),
])
def test_judge_a_descent_from_the_top(res: dict[str, object], zone: str, faults: int,
                                      moving: tuple[str, ...], want: str) -> None:
    verdict, why = judge(res, {**TOP, "zone": zone, "faults": faults}, moving)
    assert verdict == want, why


def test_a_case_that_crashes_is_an_error_with_its_traceback() -> None:
    rec = run_case(Case(7, {}, "[stairs]\ncount = -1\n", None, dict(FACTS)))
    assert rec["case"] == 7 and rec["verdict"] == "error" and rec["result"] is None
    assert "Traceback" in rec["traceback"] and "ScenarioError" in rec["why"]


def test_a_robot_that_falls_after_the_run_is_unsafe_whatever_the_run_said() -> None:
    """The tilt supervisor stopped a robot already past its support: it went
    on tipping and fell half a second after the run ended "fell: no"."""
    from stairbot.errors import RobotFellError
    from stairbot.sweep.worker import _fell_after

    class Clock:
        def __init__(self) -> None:
            self.t = 0.0

        def advance(self, dt: float) -> None:
            self.t += dt

    class Robot:
        def __init__(self, clock: Clock, falls_at: float | None) -> None:
            self.clock, self.falls_at = clock, falls_at

        def read(self) -> None:
            if self.falls_at is not None and self.clock.t >= self.falls_at:
                raise RobotFellError("segment 1 pitched 38 deg")

    class Session:
        def __init__(self, falls_at: float | None) -> None:
            self.clock = Clock()
            self.robot = Robot(self.clock, falls_at)

    from stairbot.control.robot_config import load_config

    cfg = load_config()
    assert _fell_after(Session(0.5), cfg) == "segment 1 pitched 38 deg"
    assert _fell_after(Session(None), cfg) is None
    verdict, why = judge({**result(outcome="error", up=1, down=0), "fell": True,
                          "fell_after": "segment 1 pitched 38 deg"}, FACTS)
    assert verdict == "unsafe" and "after the run" in why
