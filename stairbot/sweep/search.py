"""``stairbot sweep SPEC.toml --search N``: N cases chosen by an optimiser over
the spec's axes, minimising an objective (:mod:`stairbot.sweep.objective`),
instead of the spec's grid and Monte-Carlo order.

Phases, each explicit below:

1. the search space: every axis that can take more than one value becomes an
   Optuna distribution (:func:`space`);
2. the study: Optuna's TPE sampler, seeded, told the cases already in the
   results folder (``--resume``) and given the grid points that seed it;
3. the loop: ask a batch of as many trials as the executor runs at once,
   build each case from the values chosen, run the batch on the sweep's own
   executor and results store (:func:`~stairbot.sweep.execute.run_cases`),
   tell each trial its score in case order, until N cases are done.

Every case is a plain sweep case: the same line in ``cases.jsonl`` (plus a
``search`` field: the objective, the score, the optimiser's parameters), the
same verdicts and failing-case TOMLs.  Optuna is the optional extra
``stairbot[search]``.
"""

from __future__ import annotations

import copy
import random
import warnings
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path
from typing import Any

from stairbot.control.robot_config import parse_config
from stairbot.sweep import objective as obj
from stairbot.sweep.axes import Axis
from stairbot.sweep.cases import Case, _default_config_text, build_case, check_spec
from stairbot.sweep.execute import ExtraMissing, Outcome, run_cases
from stairbot.sweep.spec import Spec
from stairbot.sweep.store import ResultStore

SAMPLER = "TPE (multivariate, constant liar)"
GRID_SHARE = 5
"""A spec with a grid seeds the search with up to N / GRID_SHARE of its points
(a seeded shuffle of the grid, the other axes left to the sampler)."""


def load_optuna() -> Any:
    """The optuna module.  Raises ExtraMissing naming ``stairbot[search]``."""
    try:
        import optuna
    except ImportError:
        raise ExtraMissing("--search", "search") from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    return optuna


def with_seed(spec: Spec, seed: int) -> Spec:
    """``spec`` with its ``[sweep] seed`` replaced (``--seed``): every sampled
    draw, the jitters and a search's sampler follow it, and so does the hash."""
    raw = copy.deepcopy(spec.raw)
    raw.setdefault("sweep", {})["seed"] = seed
    return replace(spec, seed=seed, raw=raw)


# -- phase 1: the search space ------------------------------------------------------


@dataclass(frozen=True)
class Dimension:
    """One searched axis: its Optuna distribution and how a parameter becomes
    the axis's value (a categorical's parameter is the index of its value)."""

    axis: Axis
    distribution: Any

    def value(self, param: Any) -> Any:
        if self.axis.kind in ("list", "choice"):
            return copy.deepcopy(self.axis.values[int(param)])
        return param


def _dimension(optuna: Any, axis: Axis) -> Dimension | None:
    """The axis as a distribution; None when it holds one value only."""
    d = optuna.distributions
    if axis.kind in ("list", "choice") or (axis.kind == "range" and len(axis.values) < 2):
        if len(axis.values) < 2:
            return None
        return Dimension(axis, d.CategoricalDistribution(tuple(range(len(axis.values)))))
    if axis.kind == "range":
        lo, hi = axis.values[0], axis.values[-1]
        if all(isinstance(v, int) for v in axis.values):
            return Dimension(axis, d.IntDistribution(lo, hi, step=axis.values[1] - lo))
        # between the grid's values too: the grid is the plain sweep's resolution
        return Dimension(axis, d.FloatDistribution(float(lo), float(hi)))
    if axis.kind == "randint":
        lo, hi = int(axis.params[0]), int(axis.params[1])
        return None if lo == hi else Dimension(axis, d.IntDistribution(lo, hi))
    lo, hi = axis.extremes()  # uniform; normal: mean +- NORMAL_SIGMAS deviations
    return None if lo == hi else Dimension(axis, d.FloatDistribution(float(lo), float(hi)))


def space(optuna: Any, spec: Spec) -> dict[str, Dimension]:
    """Every axis that varies, by path (the order of the spec)."""
    dims = {a.path: _dimension(optuna, a) for a in spec.axes}
    return {p: dim for p, dim in dims.items() if dim is not None}


def fixed_values(spec: Spec) -> dict[str, Any]:
    """The axes that hold one value, as every case has them."""
    out: dict[str, Any] = {}
    for a in spec.axes:
        if a.kind in ("list", "choice", "range") and len(a.values) == 1:
            out[a.path] = copy.deepcopy(a.values[0])
        elif a.kind in ("uniform", "normal", "randint") and a.extremes()[0] == a.extremes()[1]:
            out[a.path] = a.extremes()[0]
    return out


def _param(dim: Dimension, value: Any) -> Any:
    """The parameter that gives ``value`` (a grid value) on ``dim``."""
    if dim.axis.kind in ("list", "choice"):
        return dim.axis.values.index(value)
    return value


def grid_seeds(spec: Spec, dims: dict[str, Dimension], n: int, seed: int) -> list[dict[str, Any]]:
    """The grid points that open the search: up to n / GRID_SHARE of them, in a
    seeded shuffle, each as the parameters of its grid axes."""
    grid = [a for a in spec.grid_axes if a.path in dims]
    if not grid:
        return []
    k = min(spec.grid_size, max(1, n // GRID_SHARE))
    points = random.Random(f"{seed}/search-grid").sample(range(spec.grid_size), k)
    out = []
    for point in points:
        values = spec.axis_values(point * spec.samples_per_point)
        out.append({a.path: _param(dims[a.path], values[a.path]) for a in grid})
    return out


# -- phase 2: the study ---------------------------------------------------------------


@dataclass(frozen=True)
class Plan:
    """What ``--search N --objective NAME`` asked for."""

    n: int
    objective: str
    seed: int


def describe(spec: Spec, plan: Plan, batch: int) -> dict[str, Any]:
    """The ``search`` entry of sweep.json."""
    optuna = load_optuna()
    seeds = grid_seeds(spec, space(optuna, spec), plan.n, plan.seed)
    return {"n": plan.n, "objective": plan.objective, "seed": plan.seed, "sampler": SAMPLER,
            "optuna": optuna.__version__, "grid_seeds": len(seeds), "batch": batch}


def open_study(optuna: Any, plan: Plan, dims: dict[str, Dimension],
               records: list[dict[str, Any]]) -> Any:
    """A seeded TPE study told every finished case in ``records`` (``--resume``)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        sampler = optuna.samplers.TPESampler(seed=plan.seed, multivariate=True,
                                             constant_liar=True)
    study = optuna.create_study(direction="minimize", sampler=sampler)
    dists = {p: d.distribution for p, d in dims.items()}
    for rec in sorted(records, key=lambda r: r["case"]):
        info = rec.get("search") or {}
        params = info.get("params") or {}
        if set(params) != set(dists):
            continue  # not a case of this search space: nothing to tell
        value = info.get("score")
        state = optuna.trial.TrialState.COMPLETE if value is not None else \
            optuna.trial.TrialState.FAIL
        study.add_trial(optuna.trial.create_trial(state=state, value=value, params=params,
                                                  distributions=dists))
    return study


# -- phase 3: the loop ------------------------------------------------------------------


@cache
def _scales(config_text: str | None) -> dict[str, float]:
    return obj.scales(parse_config(config_text or _default_config_text(), "<config>"))


class SearchStore(ResultStore):
    """The results store, writing each case's ``search`` field (objective,
    score, normalised margin, parameters) into its line."""

    def __init__(self, folder: Path, spec: Spec, resume: bool,
                 objective: str = obj.DEFAULT) -> None:
        super().__init__(folder, spec, resume)
        self.objective = objective
        self.params: dict[int, dict[str, Any]] = {}  # case index -> the trial's parameters

    def append(self, record: dict[str, Any], case: Case) -> None:
        scale = _scales(case.config_text)
        margins = (record.get("result") or {}).get("margins") or {}
        record["search"] = {"objective": self.objective,
                            "score": obj.score(record, self.objective, scale),
                            "margin": obj.normalised(margins, scale),
                            "params": self.params.pop(case.index, {})}
        super().append(record, case)


def search(spec: Spec, plan: Plan, store: SearchStore, executor: Executor, jobs: int,
           on_record: Callable[[dict[str, Any]], None]) -> Outcome:
    """Run the search until ``plan.n`` cases are in ``store`` (or Ctrl-C)."""
    optuna = load_optuna()
    check_spec(spec, 1)  # every distribution's edges build, as a plain sweep checks
    dims = space(optuna, spec)
    fixed = fixed_values(spec)
    dists = {p: d.distribution for p, d in dims.items()}
    study = open_study(optuna, plan, dims, store.records)
    todo = [i for i in range(plan.n) if i not in store.done]
    seeds = grid_seeds(spec, dims, plan.n, plan.seed)
    for index in todo:
        if index < len(seeds):
            study.enqueue_trial(seeds[index])
    total = Outcome()
    while todo:
        batch, todo = todo[:max(1, jobs)], todo[max(1, jobs):]
        trials, cases = {}, []
        for index in batch:
            trial = study.ask(dists)
            chosen = {**fixed, **{p: dims[p].value(v) for p, v in trial.params.items()}}
            values = {a.path: chosen[a.path] for a in spec.axes}
            store.params[index] = dict(trial.params)
            trials[index] = trial
            cases.append(build_case(spec, index, chosen=values))
        out = run_cases(cases, store, executor, on_record, jobs)
        done = {r["case"]: r for r in out.records}
        for index in batch:
            if index in done:
                value = done[index]["search"]["score"]
                if value is None:
                    study.tell(trials[index], state=optuna.trial.TrialState.FAIL)
                else:
                    study.tell(trials[index], value)
        total.ran += out.ran
        total.wall_s += out.wall_s
        total.records += out.records
        if out.interrupted:
            total.interrupted = True
            break
    return total
