"""Where the generators' jobs run: this process (``--workers 1``), a pool of local processes
(``--workers N``), or the workers of a Dask cluster, the sweep's machinery
(:func:`wetcontact.sweep.dask_client`): a local cluster of ``--workers`` processes
(``--dask``) or a running scheduler (``--scheduler ADDR``, its workers started with ``dask
worker ADDR`` on any machine that has the same code installed).

A job is a picklable module-level function and its argument; the results come back in job
order, and each is handed to ``on_result`` as it arrives (the node cache keeps it there, so
that a run that is killed resumes where it stopped, whichever way it ran).
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

from wetcontact.errors import InputError


@dataclass(frozen=True)
class DaskWorkers:
    """The workers of an open Dask client (``label``: ``local-cluster:N`` or the scheduler's
    address)."""

    client: Any
    label: str

    def count(self) -> int:
        """Workers the scheduler has now (at least 1)."""
        return max(1, len(self.client.scheduler_info().get("workers", {})))


Workers = int | DaskWorkers
"""Processes on this machine (1: this process), or Dask workers."""


@contextlib.contextmanager
def open_workers(workers: int, scheduler: str | None = None, dask: bool = False
                 ) -> Iterator[Workers]:
    """``workers`` as it is, or (``dask`` or ``scheduler``) a Dask client on a local cluster
    of ``workers`` processes or at ``scheduler``, open for the whole run and closed after
    it. The workers must run this code: a worker whose
    :func:`~wetcontact.store.code_version` differs is refused (an :class:`InputError`)."""
    if scheduler is None and not dask:
        yield workers
        return
    from wetcontact.store import code_version
    from wetcontact.sweep import dask_client

    with dask_client(workers, scheduler) as (client, label):
        mine = code_version()
        theirs = {w: v for w, v in client.run(code_version).items() if v != mine}
        if theirs:
            raise InputError(f"{label}: workers {sorted(theirs)} run wetcontact "
                             f"{sorted(set(theirs.values()))}, this client {mine}; allowed: "
                             "workers with the same code installed")
        yield DaskWorkers(client, label)


def chunk_size(n_jobs: int, n_workers: int) -> int:
    """Jobs per task: up to 4, fewer where they are few (the 10 onset searches, minutes
    each, took 4 + 4 + 2 chunks on 2 processes: a third of the time on one of them)."""
    return max(1, min(4, n_jobs // (8 * n_workers)))


def run_chunk(fn: Callable[[Any], Any], chunk: list) -> list:
    """``fn`` over one task's jobs (on a worker)."""
    return [fn(job) for job in chunk]


def map_jobs(fn: Callable[[Any], Any], jobs: list, workers: Workers, label: str,
             on_result: Callable[[Any, Any], None] | None = None) -> list:
    """``fn`` over ``jobs`` on ``workers``, a progress line on stderr every 10 %;
    ``on_result(job, result)`` sees each result as it arrives (in job order on local
    processes, in the order tasks finish on Dask). Returns the results in job order."""
    if isinstance(workers, DaskWorkers):
        return _map_dask(fn, jobs, workers, label, on_result)
    out, progress = [], _Progress(label, len(jobs))
    pool = ProcessPoolExecutor(max_workers=workers) if workers > 1 and len(jobs) > 1 else None
    try:
        chunk = chunk_size(len(jobs), workers)
        it = pool.map(fn, jobs, chunksize=chunk) if pool else map(fn, jobs)
        for job, r in zip(jobs, it, strict=True):
            out.append(r)
            if on_result is not None:
                on_result(job, r)
            progress.add(1)
    finally:
        if pool:
            pool.shutdown()
    return out


def _map_dask(fn: Callable[[Any], Any], jobs: list, workers: DaskWorkers, label: str,
              on_result: Callable[[Any, Any], None] | None) -> list:
    from distributed import as_completed

    size = chunk_size(len(jobs), workers.count())
    futures = {workers.client.submit(run_chunk, fn, jobs[s:s + size], pure=False): s
               for s in range(0, len(jobs), size)}
    out: list = [None] * len(jobs)
    progress = _Progress(f"{label} [{workers.label}]", len(jobs))
    for fut in as_completed(list(futures)):
        start = futures.pop(fut)
        got = fut.result()  # a job's error is raised here, as on local processes
        fut.release()
        for k, r in enumerate(got):
            out[start + k] = r
            if on_result is not None:
                on_result(jobs[start + k], r)
        progress.add(len(got))
    return out


class _Progress:
    """A line on stderr every 10 % of the jobs: ``label: k/n branches, t s``."""

    def __init__(self, label: str, n: int):
        self.label, self.n, self.k = label, n, 0
        self.step, self.t0 = max(1, n // 10), time.perf_counter()

    def add(self, m: int) -> None:
        before, self.k = self.k, self.k + m
        if self.k // self.step > before // self.step or self.k == self.n:
            sys.stderr.write(f"{self.label}: {self.k}/{self.n} branches, "
                             f"{time.perf_counter() - self.t0:.0f} s\n")
            sys.stderr.flush()
