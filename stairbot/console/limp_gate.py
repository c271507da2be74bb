"""After a degraded stop (issue 33): whether the console may offer to limp
home, and what it says of the stop, of the limp and of its end.

A sensor lost on the stairs ends the program in a *degraded stop*
(:mod:`stairbot.control.algorithm.limp`): every motor stopped, the lifts
holding, the robot's emergency stop latched by the run, and the stop's
``WARNING`` event telling what failed, where the robot stands and what
follows (``then``).  A console run never consents before it starts (there
is an operator to ask), so the robot can come down on what remains only
with a consent given now: the console then carries the same program on,
in the same session, from where it stopped -- the in-process simulation
from the context it ended with, boards from their run journal as
``stairbot run --resume --yes`` does (:func:`offer_after` checks it first,
so the question is only asked when the answer can be acted on).  Where too
little remains (``stranded``) there is nothing to ask.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from stairbot.control.algorithm.context import Context
from stairbot.control.algorithm.controller import Controller
from stairbot.control.algorithm.limp import LIMP_SPEED, PAIR_NAMES, PARTNER
from stairbot.control.algorithm.lost import awaits_consent
from stairbot.control.algorithm.phases import BY_VALUE, Mode
from stairbot.events import Event, EventSink
from stairbot.hardware import SensorId
from stairbot.inputs.config import RobotConfig
from stairbot.run.resume import moved_on
from stairbot.run.runner import RunResult


@dataclass(frozen=True)
class LimpOffer:
    """A degraded stop the robot can limp home from, once the operator
    consents: the stop as its event told it, and the program as it ended
    (``context``: :meth:`Context.to_dict`, at robot time ``stopped_s``)."""

    stop: Event
    context: dict[str, Any]
    mode: str
    """The run's mode ("full", "descend"): the program carried on is the same."""
    stopped_s: float

    @property
    def record(self) -> Mapping[str, Any]:
        """The stop's ``data["degraded"]``."""
        record: Mapping[str, Any] = self.stop.data["degraded"]
        return record


def offer_after(result: RunResult, ctl: Controller | None, stop: Event | None, mode: str,
                last_tick_s: float, check: Callable[[], object] | None) -> LimpOffer | None:
    """The offer to limp home after a run that ended (``result``, its
    controller ``ctl``) on a degraded stop (``stop``) the operator could
    consent to; None when there is none.  ``check``: how boards check that
    their journal's run resumes (as `stairbot run --resume` checks it;
    None: the simulation held here) -- its StairbotError goes through: the
    console then cannot act on a consent, and asks nothing."""
    if ctl is None or result.fell or not awaits(stop) or not awaits_consent(ctl.context):
        return None
    assert stop is not None
    if check is not None:
        check()
    return LimpOffer(stop, ctl.context.to_dict(), mode, last_tick_s)


def carried_on(offer: LimpOffer, now_s: float, config: RobotConfig, sink: EventSink,
               mode: Mode) -> Controller:
    """The program ``offer`` stopped, carried on with the operator's consent
    (the controller reopens it from the phase it stopped in, limping home),
    its timers moved on by the time it stood (``now_s``: the robot's clock)."""
    ctx = Context.from_dict(moved_on(offer.context, now_s - offer.stopped_s), "the context")
    return Controller(config, sink, mode, context=ctx, limp_home=True)


def stranded(stop: Event | None) -> bool:
    """Whether ``stop`` (a degraded stop's event) left too little to come down on."""
    return stop is not None and stop.data["degraded"].get("then") == "stranded"


def awaits(stop: Event | None) -> bool:
    """Whether ``stop`` waits for the operator's consent to limp home."""
    return stop is not None and stop.data["degraded"].get("then") == "no_consent"


# -- words ------------------------------------------------------------------------------

def _turns(lifts: Mapping[str, Any], per_turn_m: float) -> str:
    def one(motor: str, turns: float) -> str:
        return (f"{motor} {round(turns, 1) + 0.0:+.1f} turns "
                f"({round(turns * per_turn_m * 1000) + 0:+d} mm)")
    return ", ".join(one(motor, float(turns)) for motor, turns in lifts.items())


def _at(rec: Mapping[str, Any]) -> str:
    """Where the stop stands: the phase's label and the step."""
    phase = BY_VALUE.get(str(rec.get("phase")))
    label = phase.label if phase is not None else str(rec.get("phase"))
    return f"{label} ({rec['where']})" if rec.get("where") else label


def _lost(rec: Mapping[str, Any]) -> str:
    """What failed, and the sensors lost before it (a second loss)."""
    failed = str(rec.get("failed", ""))
    before = [s for s in rec.get("lost", []) if s not in failed]
    return failed + (f" ({', '.join(before)} lost before)" if before else "")


def cannot(refused: str) -> str:
    """A stop the robot could limp home from that this console cannot carry
    on (``refused``: why)."""
    return (f"it could come down on the sensors that remain, but this console cannot carry "
            f"the run on ({refused}): it stays stopped, lifts holding")


def stop_lines(stop: Event, per_turn_m: float) -> list[str]:
    """The degraded stop, plainly: what failed, where the robot stands (as
    the stop recorded it, at its time: not live), the lifts holding."""
    rec = stop.data["degraded"]
    return [
        f"DEGRADED STOP at {stop.time_s:.1f} s: {_lost(rec)}.",
        f"It stands in {_at(rec)}; {rec.get('steps_climbed', 0)} step(s) climbed, "
        f"{rec.get('steps_descended', 0)} descended.",
        f"Every motor stopped; the lifts hold: {_turns(rec.get('lifts', {}), per_turn_m)}.",
    ]


def banner_line(stop: Event, offered: bool, refused: str = "") -> str:
    """The banner after a degraded stop: what failed, where, and what now
    (``offered``: the operator is asked whether it may limp home;
    ``refused``: why this console cannot carry the run on)."""
    rec = stop.data["degraded"]
    then = ("it can come down on the sensors that remain, once you consent: answer the "
            "question (l asks again)" if offered else cannot(refused) if refused
            else str(rec.get("why", "")))
    return (f"DEGRADED STOP: {_lost(rec)} in {_at(rec)}; every motor stopped, lifts "
            f"holding; {then}")


def plan_words(stop: Event) -> str:
    """What limping home does from the stop, on what, at what speed."""
    rec = stop.data["degraded"]
    survivors = [f"{s} for the {PAIR_NAMES[SensorId(s)]} pair"
                 for s in rec.get("survivors", [])]
    on = ", ".join([*survivors, "odometry and the IMU"])
    return (f"Limping home: {rec.get('plan') or 'back to the start'}; on {on}; every motor at "
            f"most {LIMP_SPEED:.0%} of its speed.")


def limping_words(lost: Sequence[str]) -> str:
    """While limping home: which sensors are out, the survivor each pair
    runs on, the reduced speed (``SFR out: front pair on SFL · 50% speed``)."""
    pairs = []
    for name in lost:
        sid = SensorId(name)
        partner = PARTNER[sid].value
        pairs.append(f"{name} out: {PAIR_NAMES[sid]} pair on {partner}"
                     if partner not in lost else f"{name} out")
    return f"{'; '.join(pairs)} · {LIMP_SPEED:.0%} speed"
