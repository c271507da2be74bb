"""Executors and the sweep loop.

Local by default: a ``concurrent.futures`` process pool (``forkserver``, one
worker per core, ``-j N``).  With ``--dask ADDRESS`` (a running scheduler) or
``--dask local`` (a LocalCluster on this machine) the very same loop runs on
``Client.get_executor()``, a ``concurrent.futures.Executor`` too.

Cases run in a shuffled order (seeded by the spec hash), so a sweep stopped
early has covered its whole grid thinly rather than its first rows.  At most
two cases per worker are in flight, so Ctrl-C stops quickly: no new case
starts, the running ones finish and are written, then the loop returns.
"""

from __future__ import annotations

import multiprocessing
import os
import random
import time
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor, wait
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from stairbot.sweep.cases import Case
from stairbot.sweep.spec import SpecError
from stairbot.sweep.store import ResultStore
from stairbot.sweep.worker import ignore_sigint, run_case


class ExtraMissing(SpecError):
    """An optional extra (dask, plot) is not installed: exit 2, naming it."""

    def __init__(self, what: str, extra: str) -> None:
        super().__init__(what, None, f"needs the optional extra: pip install 'stairbot[{extra}]'")


def default_jobs() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (
        os.cpu_count() or 1)


@contextmanager
def open_executor(jobs: int, dask: str | None = None) -> Iterator[tuple[Executor, str]]:
    """An executor and a label for it.  Raises ExtraMissing without Dask."""
    if dask is None:
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(["stairbot.sweep.worker", "stairbot.run.runner",
                                    "stairbot.fakes.sim"])
        pool = ProcessPoolExecutor(jobs, mp_context=ctx, initializer=ignore_sigint)
        try:
            yield pool, f"local process pool, {jobs} worker(s)"
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ExtraMissing("--dask", "dask") from None
    cluster = None
    if dask == "local":
        # The scheduler and workers listen on loopback only (Dask's default for
        # a LocalCluster, said here so that no config changes it), no dashboard.
        cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None, silence_logs=40)
        client = Client(cluster)
        label = f"Dask LocalCluster, {jobs} worker(s)"
    else:
        try:
            client = Client(dask, timeout=10)
        except OSError as exc:
            raise SpecError("--dask", None, f"cannot reach the scheduler {dask}: {exc}") from None
        label = f"Dask scheduler {dask}, {len(client.scheduler_info()['workers'])} worker(s)"
    try:
        yield client.get_executor(pure=False), label
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


@dataclass
class Outcome:
    """What a sweep did this time: records written, and whether Ctrl-C ended it."""

    ran: int = 0
    interrupted: bool = False
    wall_s: float = 0.0
    label: str = ""
    records: list[dict[str, Any]] = field(default_factory=list)


def run_cases(cases: list[Case], store: ResultStore, executor: Executor,
              on_record: Callable[[dict[str, Any]], None], jobs: int) -> Outcome:
    """Run every case not yet in ``store`` on ``executor``, writing each record
    as it ends.  Returns when all ran, or after Ctrl-C once the running ones
    are written."""
    out = Outcome()
    t0 = time.perf_counter()
    # A seeded shuffle: a sweep stopped early has run a uniform sample of its
    # cases, not the first rows of its grid (the order never changes a result).
    order = [c for c in cases if c.index not in store.done]
    random.Random(store.spec.hash).shuffle(order)
    todo = iter(order)
    pending: dict[Future[dict[str, Any]], Case] = {}
    limit = max(1, 2 * jobs)

    def fill() -> None:
        while len(pending) < limit:
            case = next(todo, None)
            if case is None:
                return
            pending[executor.submit(run_case, case)] = case

    def collect(futures: set[Future[dict[str, Any]]]) -> None:
        for fut in futures:
            case = pending.pop(fut)
            if fut.cancelled():
                continue
            try:
                record = fut.result()
            except Exception as exc:  # noqa: BLE001 - the worker process itself died
                record = {"case": case.index, "axes": case.axes, "facts": case.facts,
                          "verdict": "error", "why": f"worker failed: {type(exc).__name__}: "
                          f"{exc}", "result": None, "wall_s": None}
            store.append(record, case)
            out.ran += 1
            out.records.append(record)
            on_record(record)

    try:
        fill()
        while pending:
            done, _ = wait(set(pending), return_when=FIRST_COMPLETED)
            collect(done)
            fill()
    except KeyboardInterrupt:
        out.interrupted = True
        for fut in list(pending):
            if fut.cancel():
                pending.pop(fut)
        try:
            while pending:  # the running cases finish and are kept
                done, _ = wait(set(pending), return_when=FIRST_COMPLETED)
                collect(done)
        except KeyboardInterrupt:  # a second Ctrl-C: leave them
            pass
    out.wall_s = time.perf_counter() - t0
    return out
