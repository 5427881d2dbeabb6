"""Parameter sweeps: solve many (scene, model) points into the reference store on Dask.

``sweep(points, store)`` solves every point not yet in the store and returns one
:class:`Outcome` per point. The work runs on dask.distributed: a local cluster of worker
processes by default, or an existing cluster given by its scheduler address (started with
``dask scheduler`` / ``dask worker``, or by dask-jobqueue on SLURM/PBS). Workers only
compute and return :class:`~wetcontact.models.ForceCurve` objects; this process (the
client) is the only one that writes the store, in batches of a few seconds
(:class:`~wetcontact.store.BatchWriter`), holding the store's write lock for the whole
sweep.

- A point already in the store under the same content key (scene, model, settings, code
  version) is reused, never recomputed; a point whose model failed or refused it before
  is reported failed with the stored reason (``retry_failed=True`` solves it again).
- A point that fails (``SolverError``), is refused (``InputError``, ``ValidityError``) or
  raises anything else is recorded with its reason and never stops the sweep. Refusals
  and solver failures are stored as failure records; an unexpected exception or a lost
  worker is not (the next run tries again).
- Cheap models are batched many points per task (closures up to 2000, ``lubrication``
  up to 50, field solvers one), with at least about four tasks per worker.
- Small sweeps run in this process without a cluster: ``workers=0``, or ``workers=None``
  when the estimated work (:func:`estimated_seconds`) is below :data:`IN_PROCESS_BELOW`
  seconds. Starting and stopping a local cluster costs 3.5-6 s on 2 shared cores
  (``benchmarks/bench_sweep.py``: start 2.2-4.5 s, stop 1.3 s), more than such a sweep
  takes; a task's round trip costs about 4 ms.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import signal
import sys
import threading
import time
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Literal

from wetcontact.errors import InputError, SolverError
from wetcontact.models import ForceCurve, get_model
from wetcontact.progress import Ticker
from wetcontact.scene import Scene
from wetcontact.store import BatchWriter, Store, code_version, curve_key

Status = Literal["computed", "reused", "failed"]

IN_PROCESS_BELOW = 5.0
"""Estimated serial seconds under which ``workers=None`` runs in this process."""

# Points per task and estimated seconds per point, by fidelity level (closures,
# lubrication, thin film, FEM); the estimates only choose in-process vs cluster.
_BATCH = {0: 2000, 1: 50, 2: 1, 3: 1}
_SECONDS = {0: 2e-3, 1: 0.05, 2: 5.0, 3: 1.0}


@dataclass(frozen=True)
class Point:
    """One unit of work: a scene solved by one model at one preset.

    Attributes
    ----------
    scene
        The scene (its gaps are the gaps solved).
    model
        Registered model name.
    preset
        Resolution preset; a model without it runs at ``"default"``.
    settings
        Extra keyword settings passed to ``model.force`` (e.g. ``inertia=True``); they are
        part of the content key.
    axes
        The study-axis values that made this point (field path -> value), for tables and
        ``export csv``; not part of the key.
    collision
        A :class:`~wetcontact.collide.CollisionCase` (its ``scene`` is ``scene``): the point
        is one impact, ``model`` names its force set (``"reference"`` or a DEM code's,
        :data:`wetcontact.collide.record.FORCE_SET_NAMES`), and its curve is the
        collision's one-row record (:mod:`wetcontact.collide.record`).
    """

    scene: Scene
    model: str
    preset: str = "default"
    settings: Mapping[str, Any] = field(default_factory=dict)
    axes: Mapping[str, Any] = field(default_factory=dict)
    collision: Any = None

    @property
    def run_preset(self) -> str:
        """The preset actually run: ``preset`` if the model has it, else ``"default"``."""
        if self.collision is not None:
            return "default"
        m = get_model(self.model)
        return self.preset if self.preset in m.presets else "default"

    @cached_property
    def run_settings(self) -> dict[str, Any]:
        """The settings the curve will carry (known before the solve)."""
        if self.collision is not None:
            from wetcontact.collide.record import settings_for

            return settings_for(self.collision, self.model, **dict(self.settings))
        return get_model(self.model).settings_for(self.run_preset, **dict(self.settings))

    @property
    def stored_model(self) -> str:
        """The model name the curve carries (``collide/<force set>`` for a collision)."""
        if self.collision is not None:
            from wetcontact.collide.record import PREFIX

            return PREFIX + self.model
        return self.model

    @property
    def level(self) -> int:
        """Fidelity level (0 closures ... 3 FEM) that sets the batch size; a collision
        counts as level 1 (its force tables take 0.01-1 s)."""
        return 1 if self.collision is not None else get_model(self.model).level

    @cached_property
    def key(self) -> str:
        """Content key in the store (scene, model, settings, code version); computed once
        per point (hashing a scene costs about 0.5 ms)."""
        return curve_key(self.scene, self.stored_model, self.run_settings)


@dataclass(frozen=True)
class Outcome:
    """What happened to one point: its curve (None when it failed) and why.

    ``curve`` is also None for a point that succeeded when the sweep ran with
    ``keep_curves=False``; :meth:`SweepResult.curve` then reads it from the store.
    """

    point: Point
    key: str
    status: Status
    curve: ForceCurve | None = None
    reason: str = ""


@dataclass
class SweepResult:
    """All outcomes of a sweep, in the order of the points given.

    Attributes
    ----------
    outcomes
        One per point given (duplicates share the outcome of their key).
    store
        Path of the store.
    wall_time_s
        Wall time of the whole sweep (s), cluster start-up included.
    executor
        ``"in-process"``, ``"local-cluster:<N>"`` or the scheduler address.
    tasks
        Number of tasks submitted.
    write_time_s
        Time spent writing the store (s).
    """

    outcomes: list[Outcome]
    store: str
    wall_time_s: float
    executor: str = "in-process"
    tasks: int = 0
    write_time_s: float = 0.0
    _by_key: dict[str, Outcome] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self._by_key = {o.key: o for o in self.outcomes}

    def count(self, status: Status) -> int:
        """Number of distinct points (keys) with ``status``."""
        return sum(o.status == status for o in self._by_key.values())

    def curve(self, point: Point) -> ForceCurve | None:
        """The curve of ``point`` (None if it failed or is not part of this sweep)."""
        out = self._by_key.get(point.key)
        if out is None or out.status == "failed":
            return None
        return out.curve if out.curve is not None else Store(self.store).load(out.key)

    def summary(self, study: str = "") -> dict[str, Any]:
        """The ``sweep --json`` object: study, points, computed, reused, failed, store,
        wall_time_s."""
        return {"study": study, "points": len(self._by_key),
                "computed": self.count("computed"), "reused": self.count("reused"),
                "failed": self.count("failed"), "store": self.store,
                "wall_time_s": round(self.wall_time_s, 3)}


def solve_point(point: Point) -> ForceCurve:
    """Solve one point (what a worker runs)."""
    if point.collision is not None:
        from wetcontact.collide.record import solve

        return solve(point.collision, point.model, **dict(point.settings))
    return get_model(point.model).force(point.scene, preset=point.run_preset,
                                        **dict(point.settings))


# A worker's answer per point: (curve, reason, persist the failure?).
_Answer = tuple[ForceCurve | None, str, bool]


def solve_batch(points: Sequence[Point]) -> tuple[str, list[_Answer]]:
    """Solve a batch of points; return this process's code version and one answer each.

    A refusal or bad value (:class:`InputError`) and a solver failure
    (:class:`SolverError`) are answers to keep; any other exception is a bug or an
    accident of the machine and is reported without being kept.
    """
    answers: list[_Answer] = []
    for p in points:
        try:
            answers.append((solve_point(p), "", False))
        except (InputError, SolverError) as exc:
            answers.append((None, str(exc) or type(exc).__name__, True))
        except Exception as exc:  # noqa: BLE001 - one bad point never stops a sweep
            answers.append((None, f"unexpected {type(exc).__name__}: {exc}", False))
    return code_version(), answers


def estimated_seconds(points: Sequence[Point]) -> float:
    """Rough serial wall time of ``points`` (s), from each model's fidelity level."""
    return sum(_SECONDS.get(p.level, 1.0) for p in points)


def _batches(points: Sequence[Point], workers: int) -> list[list[Point]]:
    """Tasks: points of one fidelity level together, at most ``_BATCH[level]`` per task
    and at most ``n / (4 workers)`` so every worker gets several tasks."""
    by_level: dict[int, list[Point]] = {}
    for p in points:
        by_level.setdefault(p.level, []).append(p)
    out: list[list[Point]] = []
    for level, pts in sorted(by_level.items()):
        size = max(1, min(_BATCH.get(level, 1), math.ceil(len(pts) / (4 * max(workers, 1)))))
        out += [pts[i:i + size] for i in range(0, len(pts), size)]
    # expensive tasks first so the slowest do not trail at the end
    return out[::-1]


class _Progress:
    """A tqdm bar on a terminal, else a line on stderr every ``every`` seconds (a
    :class:`~wetcontact.progress.Ticker`, so a long point does not silence it).

    The closing count (the bar left on a terminal, a last line in a log) is left out when
    every point failed, unless the log already has progress lines: the sweep's error
    says so, in one stderr line.
    """

    def __init__(self, total: int, enabled: bool, every: float = 5.0,
                 on_progress: Callable[[int, int], None] | None = None):
        self.total, self.done, self.enabled, self.every = total, 0, enabled, every
        self.on_progress = on_progress
        self.counts = {"computed": 0, "reused": 0, "failed": 0}
        self.t0 = time.monotonic()
        self.bar = None
        self.lines = 0
        self.ticker: Ticker | None = None
        if enabled and sys.stderr.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc="sweep", unit="pt", file=sys.stderr)
        elif enabled:
            self.ticker = Ticker(self._text, every).start()

    def update(self, status: Status, n: int = 1) -> None:
        self.done += n
        self.counts[status] += n
        if self.on_progress is not None:
            self.on_progress(self.done, self.total)
        if self.bar is not None:
            self.bar.update(n)
            self.bar.set_postfix(self.counts, refresh=False)

    def _text(self) -> str:
        c = self.counts
        self.lines += 1
        return (f"sweep: {self.done}/{self.total} points (computed {c['computed']}, "
                f"reused {c['reused']}, failed {c['failed']}), "
                f"{time.monotonic() - self.t0:.0f} s\n")

    def line(self) -> None:
        """Write the progress line now."""
        sys.stderr.write(self._text())
        sys.stderr.flush()

    def close(self, count: bool = True) -> None:
        """Stop the lines; leave the closing count (``count=False``: not, as when the
        sweep ends in an error, whose one line is then the last word)."""
        if self.ticker is not None:
            self.ticker.stop()
        failed = not count or (self.total > 0 and self.counts["failed"] == self.total)
        if self.bar is not None:
            self.bar.leave = not failed  # erased when every point failed
            self.bar.close()
        elif self.enabled and (self.lines or not failed):
            self.line()


def sweep(points: Sequence[Point], store: Store, workers: int | None = None,
          scheduler: str | None = None, progress: bool = True, *,
          retry_failed: bool = False, keep_curves: bool = True,
          lock_timeout: float | None = None,
          on_progress: Callable[[int, int], None] | None = None) -> SweepResult:
    """Solve every point not yet in ``store``, save each curve, return all outcomes.

    Parameters
    ----------
    points
        The work; duplicates (same key) are solved once.
    store
        The reference store; only this process writes it, holding its lock throughout.
    workers
        Local worker processes: ``None`` one per core (or in this process when the
        estimated work is under :data:`IN_PROCESS_BELOW` s), ``0`` in this process.
    scheduler
        Address ``tcp://host:port`` of a running Dask scheduler instead of a local cluster.
    progress
        Show a progress bar on a terminal, a line every few seconds otherwise.
    retry_failed
        Solve again the points whose failure is recorded in the store.
    keep_curves
        Keep the curves in the result (``False`` for very large sweeps: curves are read
        from the store on demand by :meth:`SweepResult.curve`).
    lock_timeout
        Seconds to wait for another writer of the store (default: the store's).
    on_progress
        Called with (points done, distinct points) as each point is reused, found failed
        or solved (``wetcontact run`` shows the count in its progress lines).

    Raises
    ------
    StoreBusyError
        Another process holds the store past ``lock_timeout``.
    InputError
        ``workers`` negative, or the scheduler cannot be reached.
    """
    t0 = time.perf_counter()
    if workers is not None and (isinstance(workers, bool) or workers < 0):
        raise InputError(f"workers = {workers!r}; allowed: an integer >= 0")
    unique: dict[str, Point] = {}
    keys = []
    for p in points:
        k = p.key
        keys.append(k)
        unique.setdefault(k, p)
    done: dict[str, Outcome] = {}
    bw = BatchWriter(store)
    executor, n_tasks = "in-process", 0
    with store.writer(lock_timeout):
        store.check_writable()  # before any point is computed
        stored = set(store.keys())
        known_failures = {} if retry_failed else store.failures()
        prog = _Progress(len(unique), progress, on_progress=on_progress)
        if on_progress is not None:
            on_progress(0, len(unique))
        reused = [k for k in unique if k in stored]
        curves = store.load_many(reused) if keep_curves else {}
        for k in reused:
            done[k] = Outcome(unique[k], k, "reused", curves.get(k))
        prog.update("reused", len(reused))
        for k in unique:
            if k not in done and k in known_failures:
                done[k] = Outcome(unique[k], k, "failed", None, known_failures[k])
                prog.update("failed")
        todo = [p for k, p in unique.items() if k not in done]

        def record(p: Point, k: str, answer: _Answer) -> None:
            curve, reason, keep = answer
            if curve is not None:
                bw.add(p.scene, curve, key=k)
                done[k] = Outcome(p, k, "computed", curve if keep_curves else None)
                prog.update("computed")
            else:
                if keep:
                    bw.add_failure(k, p.scene, p.stored_model, p.run_settings, reason)
                done[k] = Outcome(p, k, "failed", None, reason)
                prog.update("failed")
            bw.maybe_flush()

        try:
            if todo:
                local = scheduler is None and (workers == 0 or (
                    workers is None and estimated_seconds(todo) < IN_PROCESS_BELOW))
                with bw.background():  # a finished point is written while the next runs
                    if local:
                        for p in todo:
                            record(p, p.key, solve_batch([p])[1][0])
                    else:
                        executor, n_tasks = _run_dask(todo, workers, scheduler, record)
        finally:
            try:
                bw.flush()
            except BaseException:  # a failed write (a full disk): stop the lines, no count
                prog.close(count=False)
                raise
            prog.close()
    outcomes = [done[k] for k in keys]
    return SweepResult(outcomes, str(store.path), time.perf_counter() - t0, executor,
                       n_tasks, bw.write_time)


NO_WORKER_LIMIT = 120.0
"""Seconds a sweep waits with no Dask worker connected before it gives up on the points
left (they are reported failed, not stored; what was computed is in the store)."""


def watch_workers(client: Any, futures: Sequence[Any], lost: list[str],
                  stop: threading.Event, limit: float = NO_WORKER_LIMIT,
                  poll: float = 5.0) -> None:
    """Cancel ``futures`` once the scheduler has had no worker for ``limit`` seconds,
    with the reason in ``lost`` (run in a thread until ``stop``). A sweep whose workers
    all died waited forever, printing progress (a durability audit)."""
    since: float | None = None
    while not stop.wait(poll):
        try:
            n = len(client.nthreads())
        except Exception:  # noqa: BLE001 - the scheduler may be briefly unreachable
            continue
        if n:
            since = None
            continue
        if since is None:
            since = time.monotonic()
            sys.stderr.write(f"wetcontact: sweep: no Dask worker is connected; waiting up "
                             f"to {limit:.0f} s for one (start `dask worker "
                             "<scheduler address>`)\n")
        elif time.monotonic() - since >= limit:
            lost.append(f"no Dask worker for {limit:.0f} s (every worker left the "
                        "scheduler); rerun the sweep with workers to compute this point")
            client.cancel(list(futures))
            return


def _run_dask(todo: list[Point], workers: int | None, scheduler: str | None,
              record: Callable[[Point, str, _Answer], None]) -> tuple[str, int]:
    """Run ``todo`` on a local cluster or at ``scheduler``; feed each answer to ``record``."""
    from distributed import as_completed

    with dask_client(workers, scheduler, len(todo)) as (client, label):
        n = max(1, len(client.scheduler_info().get("workers", {})))
        tasks = _batches(todo, n)
        mine = code_version()
        futures = {client.submit(solve_batch, b, pure=False): b for b in tasks}
        lost: list[str] = []
        stop = threading.Event()
        watch = threading.Thread(target=watch_workers, daemon=True,
                                 args=(client, list(futures), lost, stop))
        watch.start()
        try:
            _collect(futures, as_completed(futures), mine, lost, record)
        finally:
            stop.set()
            watch.join()
        return label, len(tasks)


def _collect(futures: dict[Any, list[Point]], done: Any, mine: str, lost: list[str],
             record: Callable[[Point, str, _Answer], None]) -> None:
    """Feed the answers of the ``done`` futures (as they complete) to ``record``."""
    for fut in done:
        batch = futures.pop(fut)
        try:
            theirs, answers = fut.result()
        except Exception as exc:  # noqa: BLE001 - a lost worker fails its points only
            why = lost[0] if lost else (f"task failed on the cluster: "
                                        f"{type(exc).__name__}: {exc}")
            answers = [(None, why, False)] * len(batch)
        else:
            if theirs != mine:
                answers = [(None, f"worker runs wetcontact {theirs}, this client "
                            f"{mine}: install the same code on the workers", False)
                           ] * len(batch)
        fut.release()
        for p, a in zip(batch, answers, strict=True):
            record(p, p.key, a)


@contextlib.contextmanager
def dask_client(workers: int | None, scheduler: str | None, n_points: int = 1 << 30
                 ) -> Iterator[tuple[Any, str]]:
    """A Client on a new LocalCluster (closed on exit; no more worker processes than
    ``n_points``: 64 workers for 4 points took 56 s to start) or on an existing
    scheduler."""
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"--scheduler {scheduler}: cannot reach a Dask scheduler "
                             f"({type(exc).__name__}: {exc}); allowed: the tcp://HOST:PORT "
                             "a running `dask scheduler` prints") from None
        with client:
            try:
                client.wait_for_workers(1, timeout=60)
            except TimeoutError:
                raise InputError(f"--scheduler {scheduler}: no worker joined within 60 s; "
                                 "start `dask worker " + scheduler + "`") from None
            yield client, scheduler
        return
    n = max(1, min(workers or os.cpu_count() or 1, n_points))
    restore = _block_ctrl_c()
    try:
        with warnings.catch_warnings(), quiet_resource_tracker():
            # the scheduler's HTTP endpoint moves to a free port when 8787 is taken
            warnings.filterwarnings("ignore", message="Port .* is already in use")
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                   dashboard_address=None, host="127.0.0.1",
                                   silence_logs=logging.CRITICAL)
    except BaseException:
        restore()
        raise
    with cluster:
        restore()
        with Client(cluster) as client:
            client.run(ignore_ctrl_c)
            yield client, f"local-cluster:{n}"


def _block_ctrl_c() -> Callable[[], None]:
    """Ignore SIGINT while a local cluster starts (a few seconds); return the function
    that restores the handler.

    A Ctrl-C at a terminal goes to the whole process group: in the middle of
    ``LocalCluster(...)`` it left a half-started cluster and worker processes interrupted
    while importing, each printing a traceback. A process started while SIGINT is ignored
    keeps ignoring it (Python installs its own handler only over the default), so the
    workers never see a terminal's Ctrl-C; the sweep's process handles the next one and
    closes the cluster. Outside the main thread nothing changes.
    """
    if threading.current_thread() is not threading.main_thread():
        return lambda: None
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    return lambda: signal.signal(signal.SIGINT, old) and None


def ignore_ctrl_c() -> bool:
    """Run on each worker of a local cluster (``Client.run``): SIGINT ignored.

    A Ctrl-C at a terminal goes to the whole process group, the workers too: a worker
    interrupted while the sweep shut the cluster down printed its own traceback
    (``Process Dask Worker process (from Nanny): ... KeyboardInterrupt``). The sweep's
    process handles the Ctrl-C and closes the cluster, which stops the workers. Returns
    whether the handler could be set (only in a worker's main thread, where its event loop
    runs).
    """
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:  # not the main thread
        return False
    return True


#: the warnings filter (``PYTHONWARNINGS`` syntax) that silences the resource tracker
TRACKER_QUIET = "ignore:resource_tracker:UserWarning"


@contextlib.contextmanager
def quiet_resource_tracker() -> Iterator[None]:
    """While a local cluster starts, ``PYTHONWARNINGS`` also holds :data:`TRACKER_QUIET`.

    The cluster's worker processes are started by ``multiprocessing``, whose resource
    tracker (a process of its own, started then, with this environment) unlinks the
    semaphores of a process that is killed (SIGKILL, nothing can run in it) and then
    warns about them in two lines on stderr (``resource_tracker: There appear to be 12
    leaked semaphore objects to clean up at shutdown``). The semaphores are cleaned up all
    the same; only the warning is silenced. A SIGTERM or Ctrl-C shuts the cluster down
    and leaks nothing (:class:`wetcontact.cli.Terminated`).
    """
    old = os.environ.get("PYTHONWARNINGS")
    parts = [w for w in (old or "").split(",") if w]
    os.environ["PYTHONWARNINGS"] = ",".join([*parts, TRACKER_QUIET])
    try:
        yield
    finally:
        if old is None:
            os.environ.pop("PYTHONWARNINGS", None)
        else:
            os.environ["PYTHONWARNINGS"] = old
