"""Quarter-turn landings (issue 13, the seed's extension 1): at a wall at the
top of a flight the robot with the side pair looks sideways, turns 90°
towards the next flight, climbs it, and comes back the same way; it refuses a
landing too small to turn in, or with no next flight, and comes home; it
never touches a wall."""

from __future__ import annotations

import pytest
import simrun

from stairbot.control.algorithm.phases import Phase
from stairbot.control.robot_config import load_config, parse_config
from stairbot.errors import ConfigError, ScenarioError
from stairbot.events import Event, EventKind
from stairbot.inputs.scenario import load_scenario, parse_scenario

LANDINGS = load_config("landings")


def phases(events: list[Event]) -> list[Phase]:
    return [Phase(e.data["phase"]) for e in events if e.kind is EventKind.PHASE]


def infos(events: list[Event]) -> list[str]:
    return [e.message for e in events if e.kind is EventKind.INFO]


def landing(depth: float = 1.0, turn: str = "left", count: int = 3, width: float = 1.0,
            extra: str = "") -> str:
    return (f"[stairs]\ncount = 3\nrise = 0.17\ntread = 0.28\nwidth = {width}\n"
            f"[landing]\ndepth = {depth}\nturn = '{turn}'\ncount = {count}\n{extra}")


@pytest.mark.parametrize("turn", ["left", "right"])
def test_three_steps_a_quarter_turn_and_three_more_up_and_back_home(turn: str) -> None:
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, load_scenario(f"landing_{turn}"), events)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", "top_reached", 6, 6), result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m < 0.05
    assert result.wall_contact is None and not result.fell
    told = infos(events)
    assert any(m.startswith(f"landing: the next flight is to the {turn}") for m in told)
    assert any(m.startswith("turned onto the next flight: its steps count on from 4")
               for m in told)
    seen = phases(events)
    # scanned, centred and turned once; back where it turned once, on the way down
    assert seen.count(Phase.LANDING_SCAN) == seen.count(Phase.LANDING_CENTRE) == 1
    assert seen.count(Phase.LANDING_RETURN) == 1
    assert seen.index(Phase.LANDING_RETURN) > seen.index(Phase.DESCENT_LOWER_THIRD)


@pytest.mark.parametrize(("scenario", "end"), [("landing_too_small", "landing_too_small"),
                                               ("landing_wall", "landing_closed")])
def test_a_landing_it_cannot_turn_on_is_refused_and_the_robot_comes_home(
        scenario: str, end: str) -> None:
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, load_scenario(scenario), events)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", end, 3, 3), result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m < 0.05
    assert result.wall_contact is None
    seen = phases(events)
    assert Phase.LANDING_SCAN in seen
    assert Phase.LANDING_CENTRE not in seen  # it never turned
    assert Phase.CAL_TURN_TO not in seen[:seen.index(Phase.DESCENT_BACK_OFF)]


def test_a_landing_too_narrow_to_turn_in_is_refused() -> None:
    """0.34 m wide: 0.17 m either side of the centre line, where the robot's
    turning circle needs 0.174 m (0.40 m deep: room enough that way)."""
    # seed 2: the climb ends within the side pair's range of both walls (nearer
    # than side_min_range to one, SSR/SSL see no flight: landing_closed)
    scenario = parse_scenario(landing(width=0.34, depth=0.40, extra="[sensors]\nseed = 2\n"),
                              "narrow.toml")
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, scenario, events)
    assert (result.ascent_end, result.steps_climbed, result.steps_descended) == (
        "landing_too_small", 3, 3), result.to_dict()
    # (wherever the climb left it across the landing, one side is short of room)
    assert any(m.startswith("landing too small to turn in") and
               ("right 0.1" in m or "left 0.1" in m) for m in infos(events))


def test_a_tread_too_short_to_stand_on_is_no_landing_to_look_sideways_from() -> None:
    """0.25 m to the wall ahead: ascent 3 refuses the tread (shorter than
    min_tread_m) and the robot descends without scanning."""
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, parse_scenario(landing(depth=0.25), "short.toml"),
                            events)
    assert (result.ascent_end, result.steps_climbed, result.steps_descended) == (
        "obstacle", 2, 2), result.to_dict()
    assert Phase.LANDING_SCAN not in phases(events)


def test_the_reference_robot_refuses_a_landing_as_a_wall_and_comes_home() -> None:
    """No side pair: the landing's wall is the seed's obstacle.  Its tab (0.86 m,
    read from far) is longer than FAR_TAB_M: descent 3 and 5 of that step go by
    turns (by the reading, descent 5 ended 6.5 mm short and the robot tipped at
    154 deg/s as segment 1 was lowered onto the edge)."""
    events: list[Event] = []
    result = simrun.run_sim(load_config(), load_scenario("landing_left"), events)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", "obstacle", 3, 3), result.to_dict()
    assert not result.fell and result.final_offset_m is not None
    assert result.final_offset_m < 0.05
    assert Phase.LANDING_SCAN not in phases(events)


def test_landings_need_the_side_pair() -> None:
    with pytest.raises(ConfigError) as info:
        parse_config('extends = "reference"\n[algorithm]\nlandings = true\n', "x.toml")
    assert info.value.field == "algorithm.landings"
    assert "side pair" in str(info.value)


def test_a_stray_side_reading_while_lifting_is_no_flight() -> None:
    """The landings sweep, case 197: with 1 % outliers, SSL read past the wall
    on its left for a moment as segment 3 rose; taken for the next flight,
    the robot turned left to a wall, and touched it.  A side is open only if
    it reads past what it saw standing at the top of the lift."""
    scenario = parse_scenario(landing(depth=0.4, turn="right", extra=(
        "[start]\nyaw_deg = 7.218421\nlateral = -0.011017\n"
        "[sensors]\nseed = 138644\noutliers = 0.01\n")), "case197.toml")
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, scenario, events)
    assert (result.steps_climbed, result.steps_descended, result.wall_contact) == (
        6, 6, None), result.to_dict()
    assert any(m.startswith("landing: the next flight is to the right") for m in infos(events))


def test_the_next_flights_first_step_refused_it_turns_back_before_it_descends() -> None:
    """A second flight whose first riser (0.215 m) the side pair sees over
    (0.24 m up) but ascent 3 cannot climb (max_step_rise_m 0.202 m): an
    obstacle after the turn.  The robot backs to where it turned, turns back,
    and descends the first flight home -- not backwards off the landing's
    side."""
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, parse_scenario(
        landing(extra="rise = 0.215\n"), "high.toml"), events)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", "obstacle", 3, 3), result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m < 0.05
    seen = phases(events)
    # the landing's wall, then the next flight's first riser
    obstacles = [i for i, p in enumerate(seen) if p is Phase.ASCENT_LOWER_OBSTACLE]
    assert [seen[i + 1] for i in obstacles] == [Phase.LANDING_SCAN, Phase.LANDING_RETURN]
    assert result.wall_contact is None


FAULTS = "[[faults]]\nat = {at}\nsensor = 'SSR'\nkind = '{kind}'\n{more}"


@pytest.mark.parametrize(("width", "turn", "fault", "end", "steps"), [
    # SSR 0.3 m long from the scan on, a flight 0.6 m wide between walls: the way
    # down backed to where the side pair said the turn was, turned back into a wall
    (0.6, "right", FAULTS.format(at=138.04, kind="offset", more="offset = 0.3\n"),
     "top_reached", 6),
    # SSR (the wall's side) 1 m long from 10 mm up: read past its range at the
    # top, it was taken for the flight; the robot turned to the wall
    (1.0, "left", FAULTS.format(at=138.64, kind="offset", more="offset = 1.0\n"),
     "top_reached", 6),
    # SSR failing for 3 s during the scan ended the program on the landing
    (1.0, "left", FAULTS.format(at=142.04, kind="error", more="duration = 3.0\n"),
     "top_reached", 6),
    # the open side's sensor failing for good during the scan: no flight seen, home
    (1.0, "right", FAULTS.format(at=142.04, kind="error", more=""), "landing_closed", 3),
    # the open side's sensor 0.3 m long from mid-lift: lowered again it does not
    # read what it read there before the lift -- a sensor wrong, not the flight
    # proven -- so no flight is taken on its word, and the landing is refused
    (0.6, "right", FAULTS.format(at=143.0, kind="offset", more="offset = 0.3\n"),
     "landing_closed", 3),
])
def test_a_side_sensor_that_fails_or_reads_wrong_during_the_scan_is_no_reason_to_stop(
        width: float, turn: str, fault: str, end: str, steps: int) -> None:
    """The red team's faults on SSR around the scan (125-155 s robot time):
    the robot climbs on to the flight the other sensor saw, or refuses the
    landing, and comes home; it never turns to a wall, nor stops on the
    landing."""
    walls = "side_wall = 'both'\n" if width < 1.0 else ""
    scenario = parse_scenario(landing(width=width, turn=turn, extra=fault).replace(
        "[landing]", walls + "[landing]"), "fault.toml")
    result = simrun.run_sim(LANDINGS, scenario)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", end, steps, steps), result.to_dict()
    assert result.final_offset_m is not None and result.final_offset_m < 0.05
    assert result.wall_contact is None and not result.fell


@pytest.mark.parametrize(("key", "value", "says"), [
    ("side_height", "0.5", "lowest riser the robot climbs"),
    ("side_min_range", "1.5", "must be below side_max_range")])
def test_a_side_pair_that_cannot_tell_a_flight_is_refused(key: str, value: str,
                                                          says: str) -> None:
    with pytest.raises(ConfigError) as info:
        parse_config(f'extends = "landings"\n[sensors]\n{key} = {value}\n', "x.toml")
    assert info.value.field == f"sensors.{key}" and says in str(info.value)


def test_a_fault_on_a_side_sensor_the_robot_does_not_have_is_refused() -> None:
    scenario = parse_scenario("[stairs]\ncount = 2\n[[faults]]\nat = 1.0\nsensor = 'SSL'\n"
                              "kind = 'error'\n", "f.toml")
    with pytest.raises(ScenarioError) as info:
        simrun.run_sim(load_config(), scenario)
    assert info.value.field == "faults[0].sensor" and "no side pair" in str(info.value)


@pytest.mark.parametrize("offset", [0.1, 0.3, 1.0])
@pytest.mark.parametrize("at", [140.6, 143.0, 145.2])
def test_a_side_reading_that_jumps_mid_scan_is_no_flight_when_lowered_it_still_reads_past(
        at: float, offset: float) -> None:
    """SSR (on the landing's wall side) reading ``offset`` long from ``at``,
    while segment 3 rises above the lowest riser the robot climbs and before
    SSL sees over the flight on the left: the jump read as a flight whose
    first riser is lower than the left one's, and the robot turned right, into
    the wall (every start from 140.2 to 145.4 s, for 0.1, 0.3 and 1.0 m).
    Lowered again, SSR still reads past what it saw there before the lift:
    not the stairs.  The robot climbs the flight SSL saw."""
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, parse_scenario(landing(extra=FAULTS.format(
        at=at, kind="offset", more=f"offset = {offset}\n")), "jump.toml"), events)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", "top_reached", 6, 6), result.to_dict()
    assert result.wall_contact is None and not result.fell
    told = infos(events)
    # the fault struck mid-scan: SSR saw over, and lowered did not read it again
    assert any(m.startswith("landing: SSR does not read again what it saw") for m in told)
    assert any(m.startswith("landing: the next flight is to the left") for m in told)


@pytest.mark.parametrize(("at", "more"), [
    # from mid-lift on
    (142.0, "offset = 0.3\n"),
    # for 1 s from standing at the top: never past it while rising, and what
    # it saw again once lowered
    (149.3, "offset = 0.3\nduration = 1.0\n"),
])
def test_a_side_reading_that_jumps_mid_scan_opens_no_wall(at: float, more: str) -> None:
    """No second flight (walls on both sides and ahead): SSR 0.3 m long from
    ``at`` -- while segment 3 rises, or only standing at the top -- read as a
    flight, and the robot turned right, into the wall.  A side is seen over
    only if its reading moved past what it saw while the beam rose, and still
    reads what it saw once lowered again: it refuses the landing and comes
    home."""
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, parse_scenario(landing(count=0, extra=FAULTS.format(
        at=at, kind="offset", more=more)), "wall.toml"), events)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", "landing_closed", 3, 3), result.to_dict()
    assert result.wall_contact is None and not result.fell
    assert Phase.LANDING_SCAN in phases(events)


SKEWED_ONTO_A_NARROW_FLIGHT = """
[stairs]
count = 3
rise = 0.17
tread = 0.28
width = 0.6
[start]
distance = 0.5
yaw_deg = -3.945422
lateral = 0.014349
[sensors]
noise = 0.001
seed = 814971
outliers = 0.01
[landing]
turn = "left"
depth = 0.4
count = 3
[[faults]]
at = 0.0
sensor = "SFL"
kind = "offset"
offset = 0.002
duration = 14.5
"""


def test_a_side_wall_grazed_beside_an_open_top_is_the_top_not_a_riser_to_turn_to() -> None:
    """SFL 2 mm long while the start squares up leaves the robot 4° askew
    (inside equal_tolerance); the landing's turn carries it onto a second
    flight 0.4 m wide, climbed towards the landing's far wall, which runs on
    past the top.  At ascent 8 of the top step SFR's cone grazes that wall
    (0.44 m) and SFL reads nothing ahead: taken for a riser out of SFL's
    reach, the ascent went on and the next calibration turned towards the
    wall until segment 1 met it.  A reading that far short of
    LENGTH_OF_INFINITY is no riser the other beam misses, ascent 3 measured
    none: the top, and home."""
    events: list[Event] = []
    result = simrun.run_sim(LANDINGS, parse_scenario(SKEWED_ONTO_A_NARROW_FLIGHT, "skewed"),
                            events)
    assert (result.outcome, result.ascent_end, result.steps_climbed,
            result.steps_descended) == ("completed", "top_reached", 6, 6), result.to_dict()
    assert result.wall_contact is None and not result.fell
    assert any(m.startswith("top reached after 6 steps") and "SFR sees no riser" in m
               for m in infos(events))
