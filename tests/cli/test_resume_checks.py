"""What ``stairbot run --resume`` checks before it touches the boards, and
what keeps an unfinished run's journal: a host killed mid-calibration on
fake boards (in this process, in lockstep, on a pseudo-terminal), then the
command line run here on what it left.  Every refusal is one line on
stderr, exits 2 (a journal that fails its checks) or 1 (boards or URL that
are not the journal's), and leaves the boards latched."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from stairbot.cli import main
from stairbot.drivers.board_robot import BoardRobot
from stairbot.fakes.fault_rig import SCENARIO, resume_watched
from stairbot.fakes.host_kills import Killed, killed_host
from stairbot.hardware import Imu
from stairbot.run.journal import line_hash, mark_path, read_journal

Records = list[dict[str, Any]]
KILL_TICK = 30  # the flight's calibration check: ticks 0 to 40; a context at 25


@pytest.fixture
def killed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Killed]:
    """A host killed part way through the first calibration check, its
    last journaled context holding standing readings, on serial fake boards,
    its journal where a run on them keeps it by default."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    with killed_host("serial", None, KILL_TICK) as k:
        assert k.latched() and k.last_phase() == "cal_check"
        yield k


def stairbot(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[str]]:
    """``stairbot ARGS`` in this process: its exit code and its stderr's lines."""
    capsys.readouterr()
    code = main(list(args))
    return code, capsys.readouterr().err.strip().splitlines()


def resume(capsys: pytest.CaptureFixture[str], k: Killed, *more: str) -> tuple[int, list[str]]:
    """``stairbot run --resume --yes`` on the killed host's boards and flight."""
    flight = k.journal.parent / "flight.toml"
    flight.write_text(SCENARIO)
    return stairbot(capsys, "run", "--robot", k.boards.url, "--scenario", str(flight),
                    "--resume", "--yes", "-q", *more)


def rewrite(journal: Path, edit: Callable[[Records], Records]) -> None:
    """Edit the journal's records and write them back chained, their mark
    beside them, as a writer would have: only the edit is wrong."""
    records = [json.loads(x) for x in journal.read_bytes().splitlines()]
    run_id = json.loads(mark_path(journal).read_bytes())["run_id"]
    prev, lines = "", []
    for seq, rec in enumerate(edit(records)):
        rec = {"kind": rec.get("kind"), "seq": seq, "prev": prev,
               **{k: v for k, v in rec.items() if k not in ("kind", "seq", "prev")}}
        line = json.dumps(rec, separators=(",", ":")).encode()
        prev = line_hash(line)
        lines.append(line)
    journal.write_bytes(b"\n".join(lines) + b"\n")
    mark_path(journal).write_text(json.dumps({"run_id": run_id, "seq": len(lines) - 1,
                                              "hash": prev}) + "\n")


def last_tick(records: Records) -> dict[str, Any]:
    return next(r for r in reversed(records) if r["kind"] == "tick")


def last_context(records: Records) -> dict[str, Any]:
    return next(r["context"] for r in reversed(records) if "context" in r)


def refused(code: int, err: list[str], k: Killed, exit_code: int, *words: str) -> None:
    """One line, the exit code, the words, and the boards still latched."""
    assert code == exit_code, err
    assert len(err) == 1, err
    for w in words:
        assert w in err[0], err
    assert k.latched()


# -- the tuple round trip: a calibration check's standing pairs -------------------

def test_a_host_killed_mid_calibration_check_resumes_and_completes(
        killed: Killed, capsys: pytest.CaptureFixture[str]) -> None:
    ctx = last_context([json.loads(x) for x in killed.journal.read_bytes().splitlines()])
    assert ctx["work"]["standing"], "killed before the check gathered a pair"
    code, err = resume(capsys, killed)
    assert code == 0, err
    assert read_journal(killed.journal).end["outcome"] == "completed"  # type: ignore[index]


# -- boards and URL -------------------------------------------------------------------

def with_boot(monkeypatch: pytest.MonkeyPatch, boots: dict[str, int]) -> None:
    """The boards' identity gives a boot id (as boards of protocol 5 do)."""
    identity = BoardRobot.identity

    def booted(self: BoardRobot) -> dict[str, dict[str, int]]:
        return {name: {**ident, "boot": boots[name]} for name, ident in identity(self).items()}

    monkeypatch.setattr(BoardRobot, "identity", booted)


def test_boards_that_restarted_since_the_journal_are_refused_by_their_boot_id(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    boots = {"motor": 7, "sensor": 9}
    with_boot(monkeypatch, boots)
    with killed_host("serial", None, KILL_TICK) as k:
        boots["motor"] = 8  # its uptime is higher than the journal's: only the boot id tells
        code, err = resume(capsys, k)
        refused(code, err, k, 1, "the motor board restarted since the journal (boot id 7, "
                "then 8)", "bring the robot to the floor by hand")


def without_boot(monkeypatch: pytest.MonkeyPatch) -> None:
    """The boards' identity without a boot id (a robot driver that has none)."""
    identity = BoardRobot.identity

    def bootless(self: BoardRobot) -> dict[str, dict[str, int]]:
        return {name: {k: v for k, v in ident.items() if k != "boot"}
                for name, ident in identity(self).items()}

    monkeypatch.setattr(BoardRobot, "identity", bootless)


@pytest.mark.parametrize("side", ["journal", "boards"])
def test_a_boot_id_on_one_side_only_is_refused(
        side: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    if side == "journal":
        without_boot(monkeypatch)
    with killed_host("serial", None, KILL_TICK) as k:
        if side == "journal":
            monkeypatch.undo()
            monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
        else:
            without_boot(monkeypatch)
        code, err = resume(capsys, k)
        refused(code, err, k, 1, "boot id", "another firmware or host version")


def test_a_journal_of_another_url_is_refused(killed: Killed) -> None:
    """A serial run's journal, resumed as if on a CAN bus (the same boards
    answer): the URL differs, refused before any Clear."""
    taken = resume_watched(killed.boards, killed.config, killed.journal,
                           url="can://socketcan/can0?lockstep=1")
    assert taken.verdict == "refused" and not taken.cleared and taken.latched
    assert taken.reason == (f"can://socketcan/can0?lockstep=1: the journal's run was on "
                            f"{killed.boards.url}, not on can://socketcan/can0: resume it on "
                            f"{killed.boards.url} (or pass the journal of this robot)")


# -- a journal cut short or crafted -----------------------------------------------------

def test_a_journal_cut_to_its_first_3000_bytes_is_refused(
        killed: Killed, capsys: pytest.CaptureFixture[str]) -> None:
    data = killed.journal.read_bytes()
    killed.journal.write_bytes(data[:3000])
    code, err = resume(capsys, killed)
    refused(code, err, killed, 2, f"{killed.journal}: cut short: it ends at line",
            "had been made durable")


def test_a_journal_that_lost_its_last_whole_lines_is_refused(
        killed: Killed, capsys: pytest.CaptureFixture[str]) -> None:
    """Cut at a line's end: every line left is whole and chained; the mark
    says more were durable."""
    lines = killed.journal.read_bytes().splitlines(keepends=True)
    killed.journal.write_bytes(b"".join(lines[:-3]))
    code, err = resume(capsys, killed)
    refused(code, err, killed, 2, "cut short", f"line {len(lines)} had been made durable")


def test_a_line_changed_in_the_middle_breaks_the_chain(
        killed: Killed, capsys: pytest.CaptureFixture[str]) -> None:
    lines = killed.journal.read_bytes().splitlines(keepends=True)
    lines[5] = lines[5].replace(b'"estopped":false', b'"estopped":true ')
    killed.journal.write_bytes(b"".join(lines))
    code, err = resume(capsys, killed)
    refused(code, err, killed, 2, "line 7: seq: the chain breaks here")


def _no_run_id(records: Records) -> Records:
    del records[0]["run_id"]
    return records


def _set_tick(key: str, value: object) -> Callable[[Records], Records]:
    def edit(records: Records) -> Records:
        last_tick(records)[key] = value
        return records
    return edit


def _set_context(key: str, value: object) -> Callable[[Records], Records]:
    def edit(records: Records) -> Records:
        last_context(records)[key] = value
        return records
    return edit


@pytest.mark.parametrize(("edit", "words"), [
    (_no_run_id, "line 1: run_id: missing"),
    (_set_tick("time_s", "abc"), "time_s: 'abc' is not a number"),
    (_set_tick("time_s", math.nan), "time_s: nan is out of range"),
    (_set_tick("phase", "cal_dance"), "phase: 'cal_dance' is not a phase"),
    (_set_context("number_of_steps", 1e9), "context.number_of_steps: 1000000000.0 is not of "
                                           "type int"),
    (_set_context("number_of_steps", 10**9), "context.number_of_steps: 1000000000 is out of "
                                             "range"),
], ids=["start_without_run_id", "time_abc", "time_nan", "unknown_phase", "steps_1e9",
        "steps_10_to_the_9"])
def test_a_crafted_line_is_refused_in_one_line(
        edit: Callable[[Records], Records], words: str, killed: Killed,
        capsys: pytest.CaptureFixture[str]) -> None:
    rewrite(killed.journal, edit)
    code, err = resume(capsys, killed)
    refused(code, err, killed, 2, f"{killed.journal}: ", words)


def _version_1(records: Records) -> Records:
    """The journal as stairbot wrote it before the context was split: no
    context version at its start, its contexts one flat table."""
    del records[0]["context_version"]
    for rec in records:
        if "context" in rec:
            ctx = rec["context"]
            ctx["purpose"] = ctx.pop("family")["purpose"]
            del ctx["work"]["kind"]
    return records


def test_a_journal_of_the_context_before_version_2_is_refused_naming_both_versions(
        killed: Killed, capsys: pytest.CaptureFixture[str]) -> None:
    rewrite(killed.journal, _version_1)
    code, err = resume(capsys, killed)
    refused(code, err, killed, 2, f"{killed.journal}: line 1: context_version: its contexts "
            "are of version 1; this stairbot reads context version 2")


def test_steps_beyond_the_configs_max_steps_are_refused(
        killed: Killed, capsys: pytest.CaptureFixture[str]) -> None:
    rewrite(killed.journal, _set_context("number_of_steps", 15))
    code, err = resume(capsys, killed)
    refused(code, err, killed, 2, "the last context: number_of_steps: 15 is out of range; "
            "allowed: 0 to the config's max_steps, 10")


# -- never losing the unfinished run ----------------------------------------------------

def test_a_plain_run_over_an_unfinished_journal_is_refused_and_clear_keeps_it(
        killed: Killed, capsys: pytest.CaptureFixture[str]) -> None:
    url, journal = killed.boards.url, killed.journal
    before = journal.read_bytes()
    code, err = stairbot(capsys, "run", "--robot", url, "-q")
    refused(code, err, killed, 2, f"{journal} holds run ", "stopped in calibration")
    assert err[0].index("--resume") < err[0].index("stairbot clear") < err[0].index(
        "--discard-journal")
    code = main(["clear", "--robot", url, "--yes"])
    out = capsys.readouterr().out
    assert code == 0 and f"{url}: cleared" in out
    assert f"the journal {journal} holds run " in out and "clearing keeps it" in out
    assert journal.read_bytes() == before
    code, err = stairbot(capsys, "run", "--robot", url, "-q")
    assert code == 2 and "--resume" in err[0]  # still refused: the run is still there
    code, err = resume(capsys, killed)
    assert code == 0, err
    assert read_journal(journal).end["outcome"] == "completed"  # type: ignore[index]


def test_discarding_the_journal_keeps_it_renamed(
        killed: Killed, capsys: pytest.CaptureFixture[str]) -> None:
    url, journal = killed.boards.url, killed.journal
    before = journal.read_bytes()
    code, err = stairbot(capsys, "run", "--robot", url, "-q", "--discard-journal")
    aside = journal.with_name(journal.stem + ".discarded.jsonl")
    assert err[0] == f"stairbot: the journal of the run that did not finish is kept as {aside}"
    assert aside.read_bytes() == before and mark_path(aside).exists()
    assert code == 1 and "latch" in err[-1]  # the boards still hold theirs: nothing moved
    assert killed.latched()
    assert read_journal(aside).start["url"] == url


# -- the robot itself ---------------------------------------------------------------

@pytest.mark.parametrize(("imu", "words"), [
    (Imu(31.0, 0.5, 0.0, 0.0, 0.01), ("the IMU reads pitch +31.0°", "tipped")),
    (Imu(0.5, -22.0, 0.0, 0.0, 0.01), ("the IMU reads roll -22.0°", "tipped")),
    (Imu(0.1, 0.0, 0.0, 0.0, 1.0), ("the IMU's reading is 1.00 s old", "cannot be told")),
])
def test_a_robot_that_tipped_while_no_host_watched_is_not_resumed(
        imu: Imu, words: tuple[str, ...], killed: Killed, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(BoardRobot, "attitude", lambda self: imu)
    code, err = resume(capsys, killed)
    refused(code, err, killed, 1, *words)


def test_the_journal_is_kept_by_the_motor_boards_serial_not_the_port(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Console defect 6: the journal follows the robot to another port, and
    another robot on this one's port never finds it; a journal an earlier
    stairbot kept by the port is still found by its own robot."""
    from stairbot.run.journaled import default_path

    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path))
    robot = {"motor": {"serial": 4711, "uptime_ms": 1, "boot": 3}, "sensor": {"serial": 12}}
    other = {"motor": {"serial": 4712}, "sensor": {"serial": 12}}
    here, there = "serial:///dev/ttyUSB0?timeout=0.1", "serial:///dev/ttyACM1"
    assert default_path(here, robot) == default_path(there, robot) \
        == tmp_path / "stairbot" / "journal-motor-4711.jsonl"
    assert default_path(here, other) != default_path(here, robot)
    assert default_path("can://socketcan/can0", robot) == default_path(here, robot)
    assert default_path(here) == default_path(here.split("?")[0])  # not known: by the port
    assert default_path(here) != default_path(there)
    assert default_path("sim://", robot) is None
    # a journal kept by the port, as stairbot did before: this robot's stays in use
    by_port = default_path(here)
    assert by_port is not None
    by_port.parent.mkdir(parents=True)
    by_port.write_text(json.dumps({"kind": "start", "boards": robot}) + "\n")
    assert default_path(here, robot) == by_port
    assert default_path(here, other) == tmp_path / "stairbot" / "journal-motor-4712.jsonl"
    (tmp_path / "stairbot" / "journal-motor-4711.jsonl").write_text("")
    assert default_path(here, robot) == tmp_path / "stairbot" / "journal-motor-4711.jsonl"
