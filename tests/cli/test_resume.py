"""A host killed mid-lift, then ``stairbot run --resume``: without the
operator's confirmation nothing moves; with it the robot finishes and comes
home.  A resume is refused, one line, when the boards are another robot's,
when the run ended, or on the simulation.  The fake boards run in a process
of their own on a pseudo-terminal, in lockstep (their world stands still
while no host steps it, so the test is as fast as the machine and its timing
cannot flake)."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from lockstep_boards import kill_mid_lift, last_tick, lockstep_boards
from lost_sensor import LOST_MID_CLIMB

from stairbot.run.journal import JournalWriter, read_journal
from stairbot.run.resume import ResumeRefused, check, describe


def stairbot(*args: str, env: dict[str, str], **kw: object) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "stairbot", *args], text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, env=env, **kw)  # type: ignore[call-overload]


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return {**os.environ, "XDG_STATE_HOME": str(tmp_path / "state")}


@pytest.fixture
def boards(env: dict[str, str], tmp_path: Path) -> Iterator[tuple[str, subprocess.Popen[str]]]:
    """Fake boards in lockstep in another process: (their URL, the process)."""
    with lockstep_boards(tmp_path, env) as served:
        yield served.url, served.proc


def test_kill_9_mid_lift_then_resume_with_confirmation_finishes_and_comes_home(
        boards: tuple[str, subprocess.Popen[str]], env: dict[str, str],
        tmp_path: Path) -> None:
    url, _ = boards
    journal = tmp_path / "run.jsonl"
    killed = kill_mid_lift(url, journal, env, tmp_path, "--journal", str(journal))
    assert read_journal(journal).end is None

    # Without confirmation (no terminal, no --yes): one line, exit 2, nothing moved.
    refused = stairbot("run", "--robot", url, "--journal", str(journal), "--resume",
                       env=env, cwd=tmp_path)
    out, err = refused.communicate(timeout=60)
    assert refused.returncode == 2, err
    assert err.strip().splitlines() == [
        "stairbot: error: not resumed: no confirmation (answer y on a terminal, or add "
        "--yes); nothing moved"]
    assert "the host stopped in: ascent 3 — lift segment 1" in out
    assert "last command: MTF +10.00 turn/s" in out
    assert last_tick(journal) == killed  # nothing written: the run did not go on

    resumed = stairbot("run", "--robot", url, "--journal", str(journal), "--resume", "--yes",
                       "--json", env=env, cwd=tmp_path)
    out, err = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, err[-2000:]
    result = json.loads(out)
    assert (result["outcome"], result["steps_climbed"], result["steps_descended"],
            result["fell"]) == ("completed", 5, 5, False)
    assert result["final_offset_m"] < 0.05
    records = [json.loads(x) for x in journal.read_text().splitlines()]
    resume = next(i for i, r in enumerate(records) if r["kind"] == "resume")
    first = records[resume + 1]
    # The world stood still in between (lockstep): the refused resume moved
    # nothing.  The kill lands either before or after the killed tick's StepTo
    # reached the boards, so the world resumes at most one tick past it.
    t_killed = float(killed["time_s"])
    assert t_killed - 1e-6 <= first["time_s"] <= t_killed + 0.02 + 1e-6
    assert records[-1]["kind"] == "end" and records[-1]["outcome"] == "completed"


def test_a_resume_on_boards_served_again_is_refused_as_another_robot(
        boards: tuple[str, subprocess.Popen[str]], env: dict[str, str],
        tmp_path: Path) -> None:
    url, proc = boards
    journal = tmp_path / "run.jsonl"
    kill_mid_lift(url, journal, env, tmp_path, "--journal", str(journal))
    proc.send_signal(signal.SIGINT)
    proc.wait(10)
    again = stairbot("fake-boards", "--serial", "--lockstep", env=env, cwd=tmp_path)
    assert again.stdout is not None
    url2 = again.stdout.readline().strip()
    try:
        host = stairbot("run", "--robot", url2, "--journal", str(journal), "--resume", "--yes",
                        env=env, cwd=tmp_path)
        _, err = host.communicate(timeout=60)
    finally:
        again.send_signal(signal.SIGINT)
        again.wait(10)
    assert host.returncode == 1
    (line,) = err.strip().splitlines()
    # each launch of the fake boards is a robot of its own (its own serial
    # numbers): boards that restarted (the same serials, another boot id) are
    # refused in tests/cli/test_resume_checks.py
    assert re.fullmatch(rf"stairbot: error: cannot resume: {re.escape(url2)}: the motor board "
                        rf"is serial \d+, the journal's was \d+: not the robot of "
                        rf"{re.escape(str(journal))}", line), line


def test_a_run_that_ended_has_nothing_to_resume(tmp_path: Path, env: dict[str, str]) -> None:
    journal = tmp_path / "sim.jsonl"
    done = stairbot("run", "--journal", str(journal), "--scenario", "step_too_high", "-q",
                    env=env, cwd=tmp_path)
    done.communicate(timeout=300)
    assert done.returncode == 0
    assert read_journal(journal).end is not None
    again = stairbot("run", "--journal", str(journal), "--resume", "--yes", env=env,
                     cwd=tmp_path)
    _, err = again.communicate(timeout=60)
    assert again.returncode == 1
    assert err.strip().splitlines() == [
        f"stairbot: error: cannot resume: {journal}: the last run ended (completed): "
        "nothing to resume"]


def test_the_simulation_cannot_be_resumed(tmp_path: Path, env: dict[str, str]) -> None:
    proc = stairbot("run", "--resume", env=env, cwd=tmp_path)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1
    assert err.strip().splitlines() == [
        "stairbot: error: cannot resume: sim://: a simulation cannot be resumed: its world "
        "ended with the host that ran it"]


def test_a_line_cut_short_by_a_power_loss_is_skipped(tmp_path: Path) -> None:
    path = tmp_path / "j.jsonl"
    w = JournalWriter(path, fresh=True)
    w.start(url="serial://x", config="c", config_sha256="0", scenario="s", mode="full",
            boards=None, time_s=0.0)
    w.tick(time_s=0.02, phase="cal_check", estopped=False, command={}, boards=None,
           context=lambda: {"phase": "cal_check"})
    w.close()
    with open(path, "ab") as f:
        f.write(b'{"kind":"tick","run_id":"')  # the power went here
    state = read_journal(path)
    assert state.last["time_s"] == 0.02 and state.context == {"phase": "cal_check"}


def test_a_run_stopped_by_a_lost_link_can_be_resumed_one_that_failed_cannot(
        tmp_path: Path) -> None:
    """The journal's end says resumable only for a lost link: the program was
    stopped from outside, part way through, and the boards may come back."""
    boards = {"motor": {"serial": 1, "uptime_ms": 5000}, "sensor": {"serial": 2,
                                                                     "uptime_ms": 5000}}
    for resumable in (True, False):
        path = tmp_path / f"j-{resumable}.jsonl"
        w = JournalWriter(path, fresh=True)
        w.start(url="serial://x", config="c", config_sha256="0", scenario="s", mode="full",
                boards=boards, time_s=0.0)
        w.tick(time_s=0.02, phase="ascent_lift_first", estopped=False, command={},
               boards=boards, context=lambda: {"phase": "ascent_lift_first"})
        w.end("error", "link lost: no reply from the motor board for 0.52 s", 0.04,
              resumable=resumable)
        w.close()
        state = read_journal(path)
        if resumable:
            check(state, "serial://x", boards)
            assert describe(state)[-1] == ("the run stopped: link lost: no reply from the "
                                           "motor board for 0.52 s")
        else:
            with pytest.raises(ResumeRefused, match="the last run ended"):
                check(state, "serial://x", boards)


def test_resumes_are_counted_through_a_journal_longer_than_a_read_piece(
        tmp_path: Path) -> None:
    """read_journal reads a journal whole, a piece at a time: the resumes of
    a long run in its first piece are counted too."""
    from stairbot.run.journal_read import CHUNK

    path = tmp_path / "j.jsonl"
    w = JournalWriter(path, fresh=True)
    w.start(url="serial://x", config="c", config_sha256="0", scenario="s", mode="full",
            boards=None, time_s=0.0)
    run_id = w.run_id
    for n in range(2):
        w.resume(run_id, None, 1.0 + n)
        w.tick(time_s=1.0 + n, phase="cal_check", estopped=False, command={}, boards=None,
               context=lambda: {"phase": "cal_check"})
    n = 0
    while path.stat().st_size < 2 * CHUNK:  # a long run after the resumes
        w.tick(time_s=3.0 + n * 0.02, phase="ascent_approach", estopped=False,
               command={"MWF": 1.0}, boards=None, context=lambda: {"phase": "ascent_approach"})
        n += 1
    w.close()
    state = read_journal(path)
    assert state.start["run_id"] == run_id
    assert state.resumes == 2
    assert state.last["phase"] == "ascent_approach"


def test_a_descent_from_the_top_killed_mid_lift_resumes_down_to_the_floor(
        env: dict[str, str], tmp_path: Path) -> None:
    """The journal keeps the mode (descend) and the context (from the top):
    killed while descent 2 lowers segment 3, the resumed run carries on down
    the flight it never climbed, and stops on the floor."""
    journal = tmp_path / "run.jsonl"
    with lockstep_boards(tmp_path, env, scenario="top_descent") as served:
        killed = kill_mid_lift(served.url, journal, env, tmp_path, "--scenario", "top_descent",
                               "--journal", str(journal), phase="descent_lower_third",
                               lift=("MTB", -1))
        assert killed["phase"] == "descent_lower_third"
        resumed = stairbot("run", "--robot", served.url, "--scenario", "top_descent",
                           "--journal", str(journal), "--resume", "--yes", "--json",
                           env=env, cwd=tmp_path)
        out, err = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, err[-2000:]
    result = json.loads(out)
    assert (result["outcome"], result["steps_climbed"], result["steps_descended"],
            result["fell"]) == ("completed", 0, 5, False)
    assert "on the floor" in result["reason"]


def test_a_climb_killed_mid_scan_on_a_landing_resumes_turns_and_comes_home(
        env: dict[str, str], tmp_path: Path) -> None:
    """The journal keeps the landing's scan (its working state) and what the
    robot learnt of the landing: killed while landing 1 lifts segment 3
    looking sideways, on boards with the side pair, the resumed run finishes
    the scan, turns onto the second flight, climbs it and comes home."""
    journal = tmp_path / "run.jsonl"
    args = ("--scenario", "landing_left", "--config", "landings")
    with lockstep_boards(tmp_path, env, scenario="landing_left", config="landings") as served:
        killed = kill_mid_lift(served.url, journal, env, tmp_path, *args,
                               "--journal", str(journal), phase="landing_scan",
                               lift=("MTB", 1))
        assert killed["phase"] == "landing_scan"
        resumed = stairbot("run", "--robot", served.url, *args, "--journal", str(journal),
                           "--resume", "--yes", "--json", env=env, cwd=tmp_path)
        out, err = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, err[-2000:]
    result = json.loads(out)
    assert (result["outcome"], result["steps_climbed"], result["steps_descended"],
            result["fell"]) == ("completed", 6, 6, False), result
    assert "the next flight is to the left" in err


def test_a_resume_drops_a_line_cut_short_and_carries_the_chain_on(tmp_path: Path) -> None:
    """A power loss cut the last line: the resumed run's writer drops it
    before it appends, and the journal reads back whole, chained."""
    from stairbot.run.journal import mark_path

    path = tmp_path / "j.jsonl"
    w = JournalWriter(path, fresh=True)
    w.start(url="serial://x", config="c", config_sha256="0", scenario="s", mode="full",
            boards=None, time_s=0.0)
    w.tick(time_s=0.02, phase="cal_check", estopped=False, command={}, boards=None,
           context=lambda: {"phase": "cal_check"})
    w.close()
    with open(path, "ab") as f:
        f.write(b'{"kind":"tick","seq":2,"pr')  # the power went here
    state = read_journal(path)
    assert state.tail is not None and state.tail.seq == 1
    w = JournalWriter(path, fresh=False, tail=state.tail)
    w.resume(state.start["run_id"], None, 5.0)
    w.tick(time_s=5.0, phase="cal_check", estopped=False, command={}, boards=None,
           context=lambda: {"phase": "cal_check"})
    w.close()
    again = read_journal(path)
    assert again.resumes == 1 and again.last["time_s"] == 5.0
    assert b'"pr{' not in path.read_bytes()
    assert json.loads(mark_path(path).read_bytes())["seq"] == 3


def test_a_sensor_lost_mid_climb_without_consent_stops_and_resume_yes_limps_home(
        env: dict[str, str], tmp_path: Path) -> None:
    scenario = tmp_path / "lost.toml"
    scenario.write_text(LOST_MID_CLIMB, "utf-8")
    journal = tmp_path / "run.jsonl"
    with lockstep_boards(tmp_path, env, scenario=str(scenario)) as served:
        url = served.url
        first = stairbot("run", "--robot", url, "--journal", str(journal), "--json",
                         env=env, cwd=tmp_path)
        out, err = first.communicate(timeout=600)
        assert first.returncode == 1, err[-2000:]
        result = json.loads(out)
        assert result["outcome"] == "error" and result["steps_descended"] == 0
        assert result["awaits_consent"] is True, result
        assert (f"`stairbot run --robot {url} --journal {journal} --resume --yes` carries "
                "this run on home") in err, err[-2000:]
        end = read_journal(journal).end
        assert end is not None and end.get("resumable") is True, end

        # A resume shows why, and moves nothing without the consent.
        asked = stairbot("run", "--robot", url, "--journal", str(journal), "--resume",
                         env=env, cwd=tmp_path)
        out, err = asked.communicate(timeout=60)
        assert asked.returncode == 2, err
        assert "a sensor was lost (SFR) in ascent 7 — lift segment 3 (step 1)" in out

        home = stairbot("run", "--robot", url, "--journal", str(journal), "--resume", "--yes",
                        "--json", env=env, cwd=tmp_path)
        out, err = home.communicate(timeout=600)
        assert home.returncode == 1, err[-2000:]  # the default [expect]: completed
        result = json.loads(out)
        assert (result["outcome"], result["ascent_end"], result["steps_climbed"],
                result["steps_descended"], result["fell"]) == (
            "came_home_degraded", "sensor_lost", 1, 1, False), result
        assert "limp home (consented on resuming)" in err
        end = read_journal(journal).end
        assert end is not None and end["outcome"] == "came_home_degraded", end
