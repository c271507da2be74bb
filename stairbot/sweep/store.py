"""The results folder: durable, resumable, readable by a person.

::

    RESULTS/
      sweep.json          the spec (hash, axes, rules, total): what the cases came from
      cases.jsonl         one line per finished case, appended, flushed and fsynced
      failures/           every non-passing case as a scenario `stairbot run` reproduces
        case-000123.toml
        case-000123.robot.toml   (when the spec overrides the robot config)

A SIGKILL can leave at most a torn last line; opening the folder again cuts it
off, so no case is lost (it runs again) and none is counted twice.  A write the
disk refuses (a full disk) raises OutputError naming the file: the sweep stops,
every line written before stays, and ``--resume`` finishes once there is room.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from stairbot import __version__
from stairbot.errors import OutputError
from stairbot.files import LineFile, writing
from stairbot.sweep import tomlw
from stairbot.sweep.cases import Case
from stairbot.sweep.coverage import extent
from stairbot.sweep.spec import Spec, SpecError
from stairbot.sweep.verdict import passing

CASES, META, FAILURES = "cases.jsonl", "sweep.json", "failures"


class ResultsError(SpecError):
    """The results folder cannot be used (exit 2)."""


def meta_of(spec: Spec) -> dict[str, Any]:
    return {
        "name": spec.name, "hash": spec.hash, "source": spec.source,
        "description": spec.description, "seed": spec.seed, "total": spec.total,
        "axes": [{"path": a.path, "kind": a.kind, "describe": a.describe(),
                  "extent": extent(a)} for a in spec.axes],
        "rules": {"rise_margin_m": spec.rules.rise_margin_m,
                  "tread_margin_m": spec.rules.tread_margin_m, "home_m": spec.rules.home_m},
        "report": {"x": spec.report.x, "y": spec.report.y, "worst": spec.report.worst,
                   "bins": spec.report.bins},
        "stairbot": __version__,
    }


def read_records(folder: Path) -> Iterator[dict[str, Any]]:
    """Every complete line of ``cases.jsonl`` (a torn last line is skipped)."""
    path = folder / CASES
    if not path.exists():
        return
    if not path.is_file():  # a FIFO or a device would hang or never end
        raise ResultsError(str(path), None, "not a regular file; allowed: the cases.jsonl a "
                           "sweep wrote")
    with path.open(encoding="utf-8") as f:
        for line in f:
            if not line.endswith("\n"):
                break
            try:
                yield json.loads(line)
            except json.JSONDecodeError:
                continue


def read_meta(folder: Path) -> dict[str, Any]:
    try:
        meta: dict[str, Any] = json.loads((folder / META).read_text("utf-8"))
    except OSError as exc:
        raise ResultsError(str(folder), None, f"not a sweep results folder ({META}: "
                           f"{exc.strerror or exc})") from None
    except json.JSONDecodeError as exc:
        raise ResultsError(str(folder / META), None, f"not valid JSON: {exc}") from None
    return meta


class ResultStore:
    """Open (or create) a results folder for ``spec``.  Raises ResultsError when
    it holds another spec's cases, or holds cases and ``resume`` is false."""

    def __init__(self, folder: Path, spec: Spec, resume: bool) -> None:
        self.folder = folder
        self.spec = spec
        meta_path = folder / META
        if meta_path.exists():
            old = read_meta(folder)
            if old.get("hash") != spec.hash:
                theirs = str(old.get("hash", "?"))[:12]
                raise ResultsError(str(folder), None,
                                   f"holds results of another spec (hash {theirs}, this one "
                                   f"{spec.hash[:12]}); allowed: a new --out folder")
        self.done: set[int] = set()
        self.records: list[dict[str, Any]] = []
        for rec in read_records(folder):
            if rec.get("case") not in self.done:
                self.done.add(rec["case"])
                self.records.append(rec)
        if self.done and not resume:
            raise ResultsError(str(folder), None,
                               f"already holds {len(self.done)} finished case(s); allowed: "
                               "--resume to finish them, or a new --out folder")
        with writing(folder, "the sweep results folder"):
            folder.mkdir(parents=True, exist_ok=True)
            (folder / FAILURES).mkdir(exist_ok=True)
        if not meta_path.exists():
            tmp = meta_path.with_suffix(".tmp")
            with writing(tmp, "the sweep's spec"):
                tmp.write_text(json.dumps(meta_of(spec), indent=2) + "\n", "utf-8")
                os.replace(tmp, meta_path)
        with writing(folder / CASES, "the sweep results"):
            self._cut_torn_line(folder / CASES)
        # each line whole and fsynced before the next case counts as done
        self._f = LineFile(folder / CASES, "the sweep results", fresh=False, sync=True,
                           regular=True, error=ResultsError)

    @staticmethod
    def _cut_torn_line(path: Path) -> None:
        if not path.exists():
            return
        data = path.read_bytes()
        if data and not data.endswith(b"\n"):
            with path.open("r+b") as f:
                f.truncate(data.rfind(b"\n") + 1)

    def append(self, record: dict[str, Any], case: Case) -> None:
        """Write the failure files first, then the line: a line on disk means
        its case is complete."""
        if not passing(str(record.get("verdict"))):
            record["reproduce"] = self.write_failure(record, case)
        self._f.write(json.dumps(record, sort_keys=True) + "\n")
        self.done.add(case.index)
        self.records.append(record)

    def write_failure(self, record: dict[str, Any], case: Case) -> str:
        stem = self.folder / FAILURES / f"case-{case.index:06d}"
        scen, robot = stem.with_suffix(".toml"), Path(f"{stem}.robot.toml")
        # the sweep consents to limp home on a lost sensor, as --yes does
        cmd = f"stairbot run{' --yes' if case.facts.get('faults') else ''} --scenario {scen}"
        if case.config_text is not None:
            with writing(robot, "a failing case's robot config"):
                robot.write_text(case.config_text, "utf-8")
            cmd += f" --config {robot}"
        f = case.facts
        header = (f"case {case.index} of sweep {self.spec.name} (spec hash {self.spec.hash})\n"
                  f"verdict: {record.get('verdict')}: {record.get('why')}\n"
                  f"zone: {f['zone']} (max rise {f['max_rise_m']} m, limit "
                  f"{f['limit_rise_m']} m; min tread {f['min_tread_m']} m, limit "
                  f"{f['limit_tread_m']} m)\n"
                  f"axes: {json.dumps(case.axes)}\n"
                  f"reproduce: {cmd} --json\n"
                  "[expect] below is what the verdict rules call right "
                  "(docs/envelope.md)\n\n")
        expect = expect_for(f)
        text = header_comment(header) + case.scenario_text
        if expect:
            text += "\n" + tomlw.dumps({"expect": expect})
        with writing(scen, "a failing case's scenario"):
            scen.write_text(text, "utf-8")
        return cmd

    def close(self) -> None:
        self._f.close()


def header_comment(text: str) -> str:
    return "".join(f"# {line}".rstrip() + "\n" for line in text.splitlines())


def expect_for(facts: dict[str, Any]) -> dict[str, Any]:
    """The ``[expect]`` of a right run, as far as the scenario schema can say it."""
    home = facts["home_m"]
    if facts.get("faults"):
        return {"max_final_offset_m": home}
    if facts.get("from_top"):
        if facts["zone"] == "inside":
            return {"outcome": "completed", "steps_descended": facts["count"]}
        if facts["zone"] == "outside":
            return {"outcome": "stopped"}
        return {}
    if facts["zone"] == "inside":
        n = facts["expected_steps"]
        return {"outcome": "completed", "steps_climbed": n, "steps_descended": n,
                "max_final_offset_m": home}
    if facts["zone"] == "outside":
        return {"outcome": "completed", "ascent_end": "obstacle", "max_final_offset_m": home}
    return {"outcome": "completed", "max_final_offset_m": home}


def stopped_for_room(exc: OutputError, what: str, kept: int, folder: Path) -> OutputError:
    """A full disk stopped ``what`` (the sweep, the search): the error again,
    saying the ``kept`` finished cases stay in ``folder`` and how to go on."""
    return OutputError(exc.path, exc.what, f"{exc.problem}; {what} stopped, {kept} finished "
                       f"case(s) kept in {folder}: rerun with --resume once there is room")
