"""Fake boards simulate a robot of their own (``stairbot fake-boards
--config NAME``, as their registry entry says: console/connections.py), and
the console drives whatever it opens with its own robot config.  When the
two differ, the boards would be driven with another robot's geometry and
limits: the console says so before it opens them, naming both, and offers
the boards' robot config instead (:func:`open_chosen`).

The boards' config is *borrowed*: the console's panels were built for its
own robot at start, so only a robot they fit (the same sensors: the side
pair or not) is offered, and opening any other robot afterwards gives the
console its own config back (a simulation's world is the console's robot).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from stairbot.console.connections import Listing
from stairbot.console.modals import ChoiceScreen
from stairbot.control.robot_config import load_config
from stairbot.errors import StairbotError
from stairbot.inputs.config import RobotConfig, source_ref
from stairbot.views.top_view import RobotShape

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole


def robot_name(config: RobotConfig) -> str:
    """``reference``, ``heavy_middle``, or the file the config was read from."""
    return source_ref(config.source)


def same_robot(a: RobotConfig, b: RobotConfig) -> bool:
    """Whether ``a`` and ``b`` are the same robot, wherever each was read from."""
    return replace(b, source=a.source) == a


def boards_robot(listing: Listing | None, url: str) -> str | None:
    """The robot the fake boards at ``url`` simulate, as they registered
    (None: ``url`` is not fake boards the manager listed)."""
    if listing is None:
        return None
    for entry in listing.group("Fake boards"):
        if entry.url == url and entry.robot:
            return entry.robot
    return None


def own_config(app: StairbotConsole) -> RobotConfig:
    """The console's own robot config (not one borrowed from fake boards)."""
    return app.own_config if app.own_config is not None else app.engine.config


def use_config(app: StairbotConsole, config: RobotConfig) -> None:
    """Drive the next robot opened with ``config``: the engine's runs and
    the panels that read the config (the sensors' tolerances, the lifts'
    millimetres, the top view's outline)."""
    own = own_config(app)
    app.own_config = None if config is own else own
    app.engine.config = config
    app.sensors.config = config
    app.trends.lift_m_per_turn = config.motors.lift_travel_per_turn
    app.robot_shape = RobotShape.of(config)


def open_chosen(app: StairbotConsole, url: str, listing: Listing | None) -> None:
    """Open ``url``, chosen in the connection manager (``listing``: what it
    listed).  Fake boards that simulate another robot than the console's
    config: a question first, naming both; c opens them with the console's
    config, b (where the panels fit) with theirs, Escape opens nothing."""
    own = own_config(app)
    theirs_name = boards_robot(listing, url)
    if theirs_name is None:
        _open(app, url, own)
        return
    theirs, why = _load(theirs_name)
    if theirs is not None and same_robot(own, theirs):
        _open(app, url, own)
        return
    mine = robot_name(own)
    question = (f"These fake boards simulate the {theirs_name} robot (their registry "
                f"entry); this console's config is the {mine} robot.  Driven with "
                f"{mine}'s config, the controller works from another robot's "
                "geometry and limits.")
    choices = [("c", f"Use {mine} (c)")]
    if theirs is None:
        question += f"\n\nThe boards' robot config: {why}."
    elif theirs.sensors.has_side_pair != own.sensors.has_side_pair:
        question += (f"\n\nThe panels are built for {mine}'s sensors, not {theirs_name}'s: "
                     f"for theirs, start `stairbot console --config {theirs_name} "
                     f"--robot {url}`.")
    else:
        question += f"\n\nb uses the boards' robot, {theirs_name}, for them."
        choices.append(("b", f"Use {theirs_name} (b)"))

    def answered(key: str | None) -> None:
        if key == "c":
            _open(app, url, own)
        elif key == "b" and theirs is not None:
            _open(app, url, theirs)
            app.say(f"driving {url} with the {theirs_name} robot's config (the boards' "
                    f"robot); another robot opened goes back to {mine}")
        else:
            app.say(f"nothing opened: {url} simulates the {theirs_name} robot, this "
                    f"console's config is {mine}", keep=False)

    app.push_screen(ChoiceScreen(question, choices), answered)


def _load(name: str) -> tuple[RobotConfig | None, str]:
    """The config ``name`` (a shipped robot or a file), or None and why not."""
    try:
        return load_config(name), ""
    except (StairbotError, OSError) as exc:
        return None, f"cannot read it here ({exc})"


def _open(app: StairbotConsole, url: str, config: RobotConfig) -> None:
    if config is not app.engine.config:
        use_config(app, config)
    app.open_robot(url, app.scenario)
