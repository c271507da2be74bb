"""The host killed anywhere in a run can be resumed: the context restores at
every tick of one recorded run's journal (in this process, no boards), and
a few real kills -- inside phases whose working state holds the pairs JSON
turns into lists -- are resumed to the end on both wires.  Every phase at
three points on both wires: ``python benchmarks/host_kills.py``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from stairbot.control.algorithm.work import ProbeWork, StandingWork
from stairbot.control.robot_config import load_config
from stairbot.fakes.host_kills import EndedBeforeKill, kill_tick, killed_host, recorded, run_kill
from stairbot.run.journal import JournalState, mark_path, read_journal
from stairbot.run.resume import check, restored_context


def test_the_context_restores_at_every_tick_of_a_whole_run(tmp_path: Path) -> None:
    journal = tmp_path / "journal.jsonl"
    phases, data, mark = recorded("can")
    journal.write_bytes(data)
    mark_path(journal).write_bytes(mark)
    whole = read_journal(journal)  # every line checked
    assert whole.end is not None and whole.end["outcome"] == "completed"
    records = [json.loads(line) for line in journal.read_bytes().splitlines()]
    start, max_steps = records[0], load_config().algorithm.max_steps
    context: dict[str, object] | None = None
    restored = pairs = 0
    for rec in records:
        if rec["kind"] != "tick":
            continue
        if "context" in rec:
            context = rec
        assert context is not None
        state = JournalState(str(journal), start, rec, context["context"],  # type: ignore[arg-type]
                             float(context["time_s"]), None,  # type: ignore[arg-type]
                             boards=rec["boards"])
        check(state, start["url"], rec["boards"])  # as if the host died after this tick
        ctx = restored_context(state, rec["time_s"] + 1.0, max_steps)
        assert ctx.phase == context["context"]["phase"]  # type: ignore[index]
        work = ctx.work
        pairs += bool(isinstance(work, StandingWork) and work.standing
                      or isinstance(work, ProbeWork) and work.probe_recent)
        restored += 1
    assert restored == len(phases)
    assert pairs > 0  # the ticks that could not be resumed before


@pytest.mark.parametrize(("wire", "phase", "point"), [
    ("can", "cal_check", "last"), ("serial", "cal_probe", "middle"),
])
def test_a_host_killed_inside_a_phase_is_resumed_to_the_end(
        wire: str, phase: str, point: str) -> None:
    assert kill_tick(wire, phase, point) > kill_tick(wire, phase, "first")
    cell = run_kill(wire, phase, point)
    assert cell.verdict == "resumed", cell.reason


def test_a_run_that_ends_before_the_kill_says_how_it_ended(tmp_path: Path) -> None:
    ended = r"the run ended \(completed\) after \d+ ticks"
    with pytest.raises(EndedBeforeKill, match=ended), \
            killed_host("can", tmp_path / "journal.jsonl", 10**7):
        pass


def test_a_resume_whose_link_fails_is_a_stop_with_the_boards_latched(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The new host's first reply later than the serial rig's timeout (a
    loaded machine): the resume raised LinkLostError and the whole fault
    matrix died with it.  It is a stop: the boards left standing, latched."""
    from stairbot.errors import LinkLostError
    from stairbot.fakes import fault_rig

    def lost(*_args: object, **_kw: object) -> None:
        raise LinkLostError("serial://test: link lost: no reply from the motor board")

    monkeypatch.setattr(fault_rig, "resume", lost)
    cell = run_kill("serial", "cal_check", "middle")
    assert cell.verdict == "stopped", cell.reason
    assert cell.reason.startswith("the resume's link failed: ")


def test_a_resumed_run_that_loses_its_link_is_a_stop_with_the_boards_latched(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The resume took over, then the boards went deaf: the resumed run ends
    on a lost link, the boards' watchdogs latch them standing.  That is the
    same stop as a resume whose link fails, not an unsafe end."""
    from stairbot.fakes import fault_rig

    opened: list[fault_rig.BoardsOnWire] = []
    real_open, real_run = fault_rig.BoardsOnWire.open, fault_rig.run

    def opening(self: fault_rig.BoardsOnWire, allow_latched: bool = False) -> object:
        opened.append(self)
        return real_open(self, allow_latched)

    def deafened(*args: object, **kw: object) -> object:
        opened[-1].deaf(True)
        return real_run(*args, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(fault_rig.BoardsOnWire, "open", opening)
    monkeypatch.setattr(fault_rig, "run", deafened)
    cell = run_kill("can", "cal_check", "middle")
    assert cell.verdict == "stopped", cell.reason
    assert cell.reason.startswith("the resumed run lost its link: ")
