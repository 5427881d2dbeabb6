"""The main job (``wetcontact run``): reference curves, error tables and the report.

For every case in ``cases/`` and every registered model that applies to it, the force
curve is computed and saved to ``<out>/reference.h5`` as soon as it is done (a killed run
keeps what it finished). Then ``<out>`` receives one plot and one CSV of the curves per
case, the closure comparison table (Markdown and CSV), the sections of every study in
:mod:`wetcontact.tables`, and ``README.md`` that ties them together with the command and
environment that made them. Everything in ``<out>`` is regenerated; nothing is edited by
hand.
"""

from __future__ import annotations

import contextlib
import csv
import ctypes
import ctypes.util
import errno
import importlib
import importlib.util
import json
import math
import os
import platform
import shutil
import sys
import time
from collections.abc import Collection, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wetcontact.compare import CSV_FIELDS, compare, reference_for
from wetcontact.errors import InputError, SolverError
from wetcontact.fileio import fsync_dir, safe_stem
from wetcontact.models import ForceCurve, get_model, load_all, provenance
from wetcontact.progress import Ticker
from wetcontact.scene import Scene, load_case
from wetcontact.store import Store, code_version
from wetcontact.sweep import Outcome, Point, SweepResult, sweep
from wetcontact.tables import StudyContext

PRESET_OF_MODE = {"quick": "fast", "default": "default", "full": "accurate"}
# Study sections, in report order; a module that is not present is skipped.
SECTIONS = ("lubrication", "stokes", "thinfilm", "capillary_closures", "calibration",
            "collisions", "division", "dynamic_rupture")
DEFAULT_BENCH = Path("benchmarks/results/thinfilm.json")
DEFAULT_CALIBRATION = Path("benchmarks/results/calibration")
PROGRESS_EVERY_S = float(os.environ.get("WETCONTACT_PROGRESS_S", "5"))
TIMINGS = "timings.json"
"""The report's wall times (sweeps, sections, total), beside its README and not committed,
so that a rerun on unchanged code leaves the README as it was."""


@dataclass
class CaseResult:
    """Curves computed for one case, and the models that failed with their messages."""

    scene: Scene
    curves: dict[str, ForceCurve]
    failures: dict[str, str]


@dataclass
class RunStats:
    """What the sweeps of one run did: every computed key once, the reused, the failed."""

    computed: list[str] = field(default_factory=list)
    reused: int = 0
    failed: int = 0
    stages: list[tuple[str, int, float]] = field(default_factory=list)

    def add(self, stage: str, result: SweepResult) -> None:
        """Count the distinct points of one sweep (a duplicate point is one outcome)."""
        seen: dict[str, Outcome] = {o.key: o for o in result.outcomes}
        self.computed += [k for k, o in seen.items() if o.status == "computed"]
        self.reused += sum(o.status == "reused" for o in seen.values())
        self.failed += sum(o.status == "failed" for o in seen.values())
        self.stages.append((stage, len(seen), result.wall_time_s))

    @property
    def computed_twice(self) -> list[str]:
        """Keys computed more than once in this run (must be empty)."""
        return sorted({k for k in self.computed if self.computed.count(k) > 1})


def load_cases(folder: Path) -> list[Scene]:
    """Every ``*.toml`` in ``folder``, validated; an :class:`InputError` if there is none."""
    files = sorted(Path(folder).glob("*.toml"))
    if not files:
        raise InputError(f"{folder}: no case files (*.toml); run from the repository root or "
                         "pass --cases")
    scenes = [load_case(f) for f in files]
    names = [s.name for s in scenes]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise InputError(f"{folder}: case names must be unique; repeated: {sorted(dup)}")
    stems = [safe_stem(n) for n in names]
    if len(set(stems)) != len(stems):  # pragma: no cover - safe_stem hashes altered names
        raise InputError(f"{folder}: two case names map to one file name")
    return scenes


QUICK_GAPS = 8
"""Gaps per case in a smoke run (``--quick``): the case's first and last and evenly spaced
ones between (the Stokes bridges of the unequal-sphere and unequal-angle cases took about
a minute each on their 40 gaps)."""


def quick_gaps(scene: Scene) -> Scene:
    """``scene`` with at most :data:`QUICK_GAPS` of its gaps, the first and last kept."""
    if len(scene.gaps) <= QUICK_GAPS:
        return scene
    idx = np.unique(np.round(np.linspace(0, len(scene.gaps) - 1, QUICK_GAPS)).astype(int))
    return scene.with_gaps([scene.gaps[i] for i in idx])


def case_points(scenes: list[Scene], preset: str) -> list[Point]:
    """Every registered model that applies to each scene, at ``preset`` where it has it;
    not a model whose force depends on the motion's history (``Model.selectable`` False:
    ``stokes-dynamic``), which runs by name (``compare --models``)."""
    models = load_all()
    return [Point(sc, m.name, preset) for sc in scenes for m in models.values()
            if m.selectable and m.applicable(sc) is None]


def case_results(scenes: list[Scene], points: list[Point], result: SweepResult
                 ) -> list[CaseResult]:
    """The swept curves (and failures) grouped by case."""
    by_key = {o.key: o for o in result.outcomes}
    res = {sc.name: CaseResult(sc, {}, {}) for sc in scenes}
    for p in points:
        o = by_key[p.key]
        if o.curve is not None:
            res[p.scene.name].curves[p.model] = o.curve
        else:
            res[p.scene.name].failures[p.model] = o.reason
    return list(res.values())


# ---- closure comparison -----------------------------------------------------------------


def error_rows(results: list[CaseResult], compared: Collection[str] | None = None
               ) -> list[dict[str, object]]:
    """One row per (case, component, closure): :func:`wetcontact.compare.compare` against the
    case's reference (the highest ``reference_rank`` among its curves).

    ``compared``: the models to compare, at any fidelity level (``wetcontact compare
    --models``); by default every closure (level 0) present.
    """
    rows: list[dict[str, object]] = []
    for res in results:
        for comp in ("viscous", "capillary"):
            ref_name = reference_for(res.curves, comp)
            if ref_name is None:
                continue
            for name, curve in res.curves.items():
                if (name == ref_name or getattr(curve, f"force_{comp}") is None
                        or (get_model(name).level != 0 if compared is None
                            else name not in compared)):
                    continue
                rows.append(compare(curve, res.curves[ref_name], comp).as_row())
    return rows


def write_error_table(rows: list[dict[str, object]], out: Path) -> str:
    """Write ``closure_errors.csv`` and return the Markdown table."""
    cols = list(CSV_FIELDS)
    with open(out / "closure_errors.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols)
        w.writeheader()
        w.writerows(rows)
    lines = ["| case | component | closure | reference | max | mean | 95th pct | spurious |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['component']} | {r['closure']} | {r['reference']} "
                     f"| {_pct(r['max_rel_error'])} | {_pct(r['mean_rel_error'])} "
                     f"| {_pct(r['p95_rel_error'])} | {r['spurious']} |")
    return "\n".join(lines)


def _pct(x: object) -> str:
    x = float(x)  # type: ignore[arg-type]
    return "n/a" if not np.isfinite(x) else f"{100 * x:.3g} %"


# ---- per-case outputs -------------------------------------------------------------------


def scene_label(sc: Scene) -> str:
    """One line with what sets a case's forces: geometry, liquid amount, angles, speed."""
    geom = (f"R = {sc.radius:g} m" if sc.kind == "sphere-wall"
            else f"R1 = {sc.radius:g} m, R2 = {sc.radius2:g} m")
    if sc.amount == "film":
        amount = f"film delta = {sc.film_thickness:g} m"
    elif sc.amount == "bridge":
        amount = f"bridge V = {sc.bridge_volume:g} m^3"
    else:
        amount = "immersed"
    th = (f", theta = {math.degrees(sc.contact_angle_sphere):g}/"
          f"{math.degrees(sc.contact_angle_wall):g} deg" if sc.amount != "immersed" else "")
    return f"{sc.kind}, {geom}, {amount}{th}, v = {sc.velocity:g} m/s"


def case_figure(res: CaseResult):
    """Signed F of every model against the gap, one panel per force component.

    The force axis is signed (:func:`~wetcontact.plotting.signed_axis`): symmetric-
    logarithmic (logarithmic in |F| on both sides of a shaded linear band around zero)
    when the forces span two decades or more, linear otherwise. F > 0 (pushes the
    surfaces apart) lies above the zero line, F < 0 (attraction) below it, a change of
    sign crosses it, and F = 0 (no liquid, past rupture) is drawn on it. Every model has
    its own colour, marker and dash pattern, the same in both panels; the markers of the
    models in a panel are staggered along the gaps so that coinciding curves all show.
    """
    from matplotlib.lines import Line2D

    from wetcontact.plotting import pyplot, signed_axis, styles

    plt = pyplot()
    names = sorted(res.curves)
    st = styles(names)
    comps = [c for c in ("viscous", "capillary")
             if any(getattr(cv, f"force_{c}") is not None for cv in res.curves.values())]
    fig, axes = plt.subplots(len(comps), 1, figsize=(9.0, 3.4 * len(comps) + 1.0),
                             sharex=True, squeeze=False, layout="constrained")
    for ax, comp in zip(axes[:, 0], comps, strict=True):
        drawn = [n for n in names if getattr(res.curves[n], f"force_{comp}") is not None]
        forces = [getattr(res.curves[n], f"force_{comp}") for n in drawn]
        handles = []
        for k, (name, f) in enumerate(zip(drawn, forces, strict=True)):
            g, sty = res.curves[name].gap, st[name]
            ax.plot(g, f, ls=sty["linestyle"], color=sty["color"], lw=1.3, label=name)
            every = max(len(drawn), int(np.ceil(g.size / 12)))
            start = (k * every) // len(drawn) % every  # distinct per model in the panel
            pick = slice(start % max(g.size, 1), None, every)  # at least one marker each
            ax.plot(g[pick], f[pick], ls="none", ms=4.5, marker=sty["marker"],
                    color=sty["color"])
            handles.append(Line2D([], [], ls=sty["linestyle"], color=sty["color"],
                                  marker=sty["marker"], ms=4.5, lw=1.3, label=name))
        ax.set_xscale("log")
        lin = signed_axis(ax, forces)
        ax.set_ylabel(f"F {comp} (N)\n> 0 apart, < 0 attraction")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(handles=handles, fontsize=6.5, ncol=1,
                  loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                  title=None if lin is None else f"grey band: linear, |F| < {lin:.0e} N",
                  title_fontsize=6.5)
    axes[-1, 0].set_xlabel("surface gap S (m)")
    sc = res.scene
    fig.suptitle(f"{sc.name}\n{scene_label(sc)}", fontsize=8)
    return fig


def write_case_outputs(res: CaseResult, out: Path) -> str:
    """``curves/<stem>.png`` (signed F against the gap, every model) and ``curves/<stem>.csv``;
    the stem is :func:`~wetcontact.fileio.safe_stem` of the case name (returned)."""
    from wetcontact.plotting import save

    folder = out / "curves"
    folder.mkdir(parents=True, exist_ok=True)
    stem = safe_stem(res.scene.name)
    save(case_figure(res), folder / f"{stem}.png")
    with open(folder / f"{stem}.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["model", "gap_m", "force_viscous_N", "force_capillary_N", "force_total_N"])
        for name, c in sorted(res.curves.items()):
            for i in range(c.gap.size):
                w.writerow([name, f"{c.gap[i]:.9e}",
                            "" if c.force_viscous is None else f"{c.force_viscous[i]:.9e}",
                            "" if c.force_capillary is None else f"{c.force_capillary[i]:.9e}",
                            f"{c.force_total[i]:.9e}"])
    return stem


# ---- one case: wetcontact compare -------------------------------------------------------


@dataclass
class CaseComparison:
    """What :func:`compare_case` did for one case.

    Attributes
    ----------
    result
        The curves computed (or reused) and the models that failed, with their messages.
    rows
        The closure error table (one :meth:`~wetcontact.compare.Comparison.as_row` per
        component and compared model).
    table
        The same rows as a Markdown table.
    references
        Force component -> the reference model the rows compare against.
    not_applicable
        Model -> why it does not apply to the case (named models, or every registered one).
    files
        The files written: the table's CSV, the case's figure and curves, the store.
    counts
        Curves ``computed``, ``reused`` and ``failed``, and the sweep's ``wall_time_s``.
    """

    result: CaseResult
    rows: list[dict[str, object]]
    table: str
    references: dict[str, str]
    not_applicable: dict[str, str]
    files: list[Path]
    counts: dict[str, float]


def compare_case(case: Path, out: Path, models: Sequence[str] | None = None,
                 preset: str = "default", workers: int | None = None,
                 progress: bool = True) -> CaseComparison:
    """The closure error table and figure of one case (``wetcontact compare``).

    The same data path as :func:`run_all` for the case alone, without the studies: the
    points of :func:`case_points` (every model that applies, or the named ones and the
    case's reference for each force component they model) swept into ``out/reference.h5``
    (a rerun reuses its curves), then :func:`write_case_outputs` and
    :func:`write_error_table` into ``out``.

    Parameters
    ----------
    case
        A TOML case file.
    out
        Output folder (created).
    models
        Models to compare (any fidelity level); ``None``: every closure that applies. A
        named model that does not apply is listed in ``not_applicable``, not an error.
    preset
        Resolution preset of the solvers (``fast``, ``default``, ``accurate``).
    workers, progress
        As for :func:`~wetcontact.sweep.sweep`.

    Raises
    ------
    InputError
        An unknown model or preset; none of the named models applies to the case, or
        none that does has a reference model for its force component there.
    """
    from wetcontact.models import PRESETS

    if preset not in PRESETS:
        raise InputError(f"--preset = {preset!r}; allowed: " + ", ".join(PRESETS))
    scene = load_case(case)
    registered = load_all()
    names = list(dict.fromkeys(models)) if models is not None else sorted(registered)
    if models is not None and not names:
        raise InputError("--models: no model named; allowed: a comma-separated list of "
                         "models (see `wetcontact models`)")
    for name in names:
        if name not in registered:
            raise InputError(f"--models: model = {name!r}; allowed: "
                             + ", ".join(sorted(registered)))
    not_applicable = {n: why for n in names
                      if (why := registered[n].applicable(scene)) is not None}
    points = case_points([scene], preset)
    compared: list[str] | None = None
    if models is not None:  # a named model runs even where the report leaves it out
        have = {p.model for p in points}
        points += [Point(scene, n, preset) for n in names
                   if n not in have and n not in not_applicable]
        compared = [n for n in names if n not in not_applicable]
        refs = set()
        for comp in ("viscous", "capillary"):
            serves = [n for n in compared if registered[n].component in (comp, "both")]
            ranked = [(registered[p.model].reference_rank.get(comp, 0), p.model)
                      for p in points]
            best = max((r for r in ranked if r[0] > 0), default=None)
            if best is not None and serves:
                refs.add(best[1])
            elif best is None:
                for n in serves:
                    not_applicable[n] = (f"no reference model for the {comp} force applies "
                                         f"to case {scene.name!r}: nothing to compare it with")
        compared = [n for n in compared if n not in not_applicable]
        if not compared:
            raise InputError(f"{case}: none of the named models can be compared on case "
                             f"{scene.name!r}: " + "; ".join(not_applicable.values()))
        points = [p for p in points if p.model in set(compared) | refs]
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    store = Store(out / "reference.h5")
    swept = sweep(points, store, workers=workers, progress=progress)
    res = case_results([scene], points, swept)[0]
    stem = write_case_outputs(res, out)
    rows = error_rows([res], compared=compared)
    table = write_error_table(rows, out)
    references = {c: ref for c in ("viscous", "capillary")
                  if (ref := reference_for(res.curves, c)) is not None}
    counts = {s: swept.count(s) for s in ("computed", "reused", "failed")}
    files = [out / "closure_errors.csv", out / "curves" / f"{stem}.png",
             out / "curves" / f"{stem}.csv", store.path]
    return CaseComparison(res, rows, table, references, not_applicable, files,
                          {**counts, "wall_time_s": round(swept.wall_time_s, 3)})


# ---- the job ----------------------------------------------------------------------------


class _Heartbeat:
    """A line on stderr every ``every`` seconds saying what the run is doing (when stderr is
    not a terminal: logs and CI see progress; a terminal has the sweep's bar), written by
    a :class:`~wetcontact.progress.Ticker`.

    While a sweep runs the line counts its points, ``wetcontact run: stage 1 (cases and
    studies): 12/40 points (30 s)``: the sweep reports them through :meth:`points`.
    """

    def __init__(self, enabled: bool, every: float | None = None):
        self.enabled = enabled and not sys.stderr.isatty()
        self._phase, self.t0 = "starting", time.perf_counter()
        self.every = PROGRESS_EVERY_S if every is None else every
        self.count: tuple[int, int] | None = None  # (done, total) of the current sweep
        self._ticker = Ticker(lambda: self.line() + "\n", self.every)

    @property
    def phase(self) -> str:
        """What the run is doing; setting it forgets the last phase's point count."""
        return self._phase

    @phase.setter
    def phase(self, text: str) -> None:
        self._phase, self.count = text, None

    def points(self, done: int, total: int) -> None:
        """The current sweep's progress (its ``on_progress``)."""
        self.count = (done, total)

    def line(self) -> str:
        """The progress line, without its newline."""
        count = self.count
        done = "" if count is None else f": {count[0]}/{count[1]} points"
        return f"wetcontact run: {self._phase}{done} ({time.perf_counter() - self.t0:.0f} s)"

    def __enter__(self) -> _Heartbeat:
        if self.enabled:
            self._ticker.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._ticker.stop()


@contextlib.contextmanager
def _locked(out: Path) -> Iterator[None]:
    """Hold ``.<out>.lock`` beside ``out``; a second run on the same folder exits 2."""
    import fcntl

    lock = out.parent / f".{out.name}.lock"
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise InputError(f"{out}: another 'wetcontact run' is writing this report; wait "
                             "for it or pass another --out") from None
        try:
            yield
        finally:
            # removed while still held, so no empty lock file is left behind; a run that
            # opened this file meanwhile fails to lock it (non-blocking) as it should, and
            # one that comes after creates a new file
            with contextlib.suppress(OSError):
                os.unlink(lock)
    finally:
        os.close(fd)


def _remove_lock_file(lock: Path) -> None:
    """Delete the store's released lock file before the report is swapped in, so that no
    empty ``reference.h5.lock`` is left in it; kept if another process holds it. Only for
    the staging folder's store, which no other process writes while this run holds the
    report's lock (a writer waiting on a lock file would otherwise lock the deleted one)."""
    import fcntl

    try:
        fd = os.open(lock, os.O_RDWR)
    except OSError:
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        os.unlink(lock)
    except OSError:  # held by another process (BlockingIOError), or already gone
        pass
    finally:
        os.close(fd)


_RENAME_EXCHANGE = 2


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two directories (Linux ``renameat2(RENAME_EXCHANGE)``); False when
    the system cannot."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd = -100
    rc = fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), _RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(b))


def swap_in(staging: Path, out: Path) -> None:
    """Replace the folder ``out`` by ``staging`` so that a reader, or a run killed at any
    moment, sees either the whole old report or the whole new one.

    With ``renameat2(RENAME_EXCHANGE)`` the swap is one atomic step; elsewhere ``out`` is
    first renamed to ``.<out>.old`` (restored by the next run if the kill came between the
    two renames, see :func:`_recover`).
    """
    old = out.parent / f".{out.name}.old"
    if not out.exists():
        os.rename(staging, out)
    elif _exchange(staging, out):
        shutil.rmtree(staging)
    else:
        shutil.rmtree(old, ignore_errors=True)
        os.rename(out, old)
        os.rename(staging, out)
        shutil.rmtree(old)
    fsync_dir(out.parent)


def _recover(out: Path) -> None:
    """Undo a swap killed between its two renames (``out`` gone, ``.<out>.old`` there)."""
    old = out.parent / f".{out.name}.old"
    if old.exists() and not out.exists():
        os.rename(old, out)
    shutil.rmtree(old, ignore_errors=True)


def _sections() -> list[tuple[str, object]]:
    out = []
    for name in SECTIONS:
        mod_name = f"wetcontact.tables.{name}"
        if importlib.util.find_spec(mod_name) is not None:
            out.append((name, importlib.import_module(mod_name)))
    return out


def _merged(*results: SweepResult) -> SweepResult:
    return SweepResult([o for r in results for o in r.outcomes], results[0].store,
                       sum(r.wall_time_s for r in results))


def build(scenes: list[Scene], out: Path, store: Store, mode: str, ctx: StudyContext,
          progress: bool = True, beat: _Heartbeat | None = None) -> tuple[Path, RunStats]:
    """Sweep the report's studies into ``store`` and render the report into ``out``.

    Stage 1 sweeps the cases (every applicable model) and every section's ``points``;
    stage 2 the sections' ``derived_points`` (axes computed from stage-1 curves). The
    renderers then take the curves from the sweep results; nothing is solved twice (the
    store's content key: a point of stage 2 already swept in stage 1 is reused).
    """
    beat = beat or _Heartbeat(False)
    stats = RunStats()
    sections = _sections()
    cpoints = case_points(scenes, PRESET_OF_MODE[mode])
    stage1 = cpoints + [p for _, mod in sections for p in mod.points(ctx)]
    beat.phase = "stage 1 (cases and studies)"  # the count: distinct points, solved once
    bar = progress and not beat.enabled  # on a non-terminal the heartbeat prints instead
    r1 = sweep(stage1, store, progress=bar, on_progress=beat.points)
    stats.add("cases and studies", r1)
    stage2 = [p for _, mod in sections if hasattr(mod, "derived_points")
              for p in mod.derived_points(ctx, r1)]
    beat.phase = "stage 2 (derived axes)"
    r2 = sweep(stage2, store, progress=bar, on_progress=beat.points) if stage2 else None
    if r2 is not None:
        stats.add("derived axes", r2)
    result = r1 if r2 is None else _merged(r1, r2)

    beat.phase = "drawing the case plots"
    results = case_results(scenes, cpoints, r1)
    stems = {r.scene.name: write_case_outputs(r, out) for r in results}
    table = write_error_table(error_rows(results), out)
    rendered, failed = [], []
    timings: dict[str, dict[str, float]] = {
        "sweeps_s": {name: round(t, 3) for name, _, t in stats.stages}, "sections_s": {}}
    for name, mod in sections:
        beat.phase = f"rendering the {name} section"
        ts = time.perf_counter()
        try:
            md = mod.section(out, result, ctx)
        except Exception as exc:  # noqa: BLE001 - report it, write the rest
            failed.append(f"{name}: {type(exc).__name__}: {exc}")
            md = f"## {name}\n\nThis section failed: {exc}\n"
        timings["sections_s"][name] = round(time.perf_counter() - ts, 3)
        rendered.append(md.rstrip())

    failures = [f"{r.scene.name} / {m}: {msg}" for r in results for m, msg in r.failures.items()]
    readme = _readme(results, stems, table, rendered, failures, mode, stats, ctx)
    path = out / "README.md"
    path.write_text(readme)
    # wall times change with every run: beside the report, in a file that is not committed
    (out / TIMINGS).write_text(json.dumps(
        {**timings, "total_s": round(time.perf_counter() - beat.t0, 3),
         "curves": {"computed": len(stats.computed), "reused": stats.reused,
                    "failed": stats.failed, "computed_twice": stats.computed_twice},
         "git_commit": provenance()["git_commit"]}, indent=1) + "\n")
    if failed or failures:
        raise SolverError(f"{len(failures)} curve(s) and {len(failed)} report section(s) "
                          f"failed (listed in {path}): " + "; ".join(failed + failures)[:500])
    return path, stats


def run_all(cases: Path = Path("cases"), out: Path | None = None, mode: str = "default",
            resume: bool = False, progress: bool = True,
            bench: Path | None = DEFAULT_BENCH,
            calibration: Path | None = DEFAULT_CALIBRATION) -> Path:
    """Regenerate ``out`` from the cases; return the path of ``out/README.md``.

    The report is built in ``.<out>.partial`` beside ``out`` (with its store) and swapped in
    when complete: a run killed at any moment leaves the old report whole. Two runs on one
    ``out`` at once: the second exits with an :class:`InputError`.

    Parameters
    ----------
    cases
        Folder of TOML case files.
    out
        Output folder; default ``reports/``, or ``reports-quick/`` for ``mode="quick"`` (a
        smoke run never overwrites the committed report unless asked to).
    mode
        ``"quick"`` (fast presets, smoke studies), ``"default"`` or ``"full"`` (accurate).
    resume
        Reuse the curves of a killed run (its ``.<out>.partial`` store) or of ``out``'s
        ``reference.h5`` instead of recomputing them.
    bench
        The thin-film benchmark's JSON (stability map, wetting-width study); the default is
        relative to the working directory (the repository root); ``None`` or a missing
        default file: the section says the benchmark was not given.
    calibration
        Folder of calibration JSONs (``wetcontact calibrate`` outputs) for the held-out
        tables; relative to the working directory like ``bench``; ``None`` or a missing
        default folder: the section says none was given. The shipped closure's table is
        the package's own data.
    """
    if mode not in PRESET_OF_MODE:
        raise InputError(f"mode = {mode!r}; allowed: " + ", ".join(PRESET_OF_MODE))
    if out is None:
        out = Path("reports-quick" if mode == "quick" else "reports")
    from wetcontact.tables.thinfilm import load_bench

    bench_data = None
    if bench is not None and (Path(bench).exists() or Path(bench) != DEFAULT_BENCH):
        bench_data = load_bench(bench)
    from wetcontact.reduced_models import DATA_DIR
    from wetcontact.tables.calibration import load_calibrations, load_json

    cal_data: tuple = ()
    if calibration is not None and (Path(calibration).is_dir()
                                    or Path(calibration) != DEFAULT_CALIBRATION):
        if not Path(calibration).is_dir():
            raise InputError(f"calibration folder {calibration}: not a folder; allowed: the "
                             "folder of wetcontact calibrate's JSON outputs")
        cal_data = load_calibrations(calibration)
    viscous_path = DATA_DIR / "calibrated_viscous.json"
    capillary_path = DATA_DIR / "calibrated_capillary.json"
    scenes = load_cases(cases)
    if mode == "quick":
        scenes = [quick_gaps(sc) for sc in scenes]
    out = Path(out).absolute()
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: exists and is not a folder")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"--out {out}: cannot create its parent ({exc.strerror})") from None
    ctx = StudyContext(quick=mode == "quick", scenes=tuple(scenes), bench=bench_data,
                       bench_path="" if bench_data is None else str(bench),
                       calibration=cal_data, calibrated_viscous=load_json(viscous_path),
                       calibrated_viscous_path="wetcontact/" + viscous_path.relative_to(
                           DATA_DIR.parents[1]).as_posix(),
                       calibrated_capillary=(load_json(capillary_path)
                                             if capillary_path.is_file() else None),
                       calibrated_capillary_path="wetcontact/" + capillary_path.relative_to(
                           DATA_DIR.parents[1]).as_posix())
    with _locked(out), _Heartbeat(progress) as beat:
        _recover(out)
        staging = out.parent / f".{out.name}.partial"
        if not resume:
            shutil.rmtree(staging, ignore_errors=True)
        staging.mkdir(exist_ok=True)
        for stale in (p for p in staging.iterdir() if p.name != "reference.h5"):
            shutil.rmtree(stale) if stale.is_dir() else stale.unlink()
        store_path = staging / "reference.h5"
        if resume and not store_path.exists() and (out / "reference.h5").exists():
            shutil.copyfile(out / "reference.h5", store_path)
        store = Store(store_path)
        try:
            path, _ = build(scenes, staging, store, mode, ctx, progress, beat)
        except SolverError:
            beat.phase = "swapping the report in"
            _remove_lock_file(store.lock_path)
            swap_in(staging, out)  # a complete report that lists its failures
            raise
        beat.phase = "swapping the report in"
        _remove_lock_file(store.lock_path)
        swap_in(staging, out)
    return out / path.name


def _readme(results: list[CaseResult], stems: dict[str, str], table: str, sections: list[str],
            failures: list[str], mode: str, stats: RunStats, ctx: StudyContext) -> str:
    prov = provenance()
    lines = [
        "# wetcontact reference report",
        "",
        "Generated by `wetcontact run"
        + {"quick": " --quick", "full": " --full", "default": ""}[mode]
        + "`; never edited by hand. Forces are axial forces on the sphere in newtons, "
        "positive when they push the surfaces apart.",
        "",
        "## Cases and force curves",
        "",
        "| case | kind | amount | models | plot | data |",
        "|---|---|---|---|---|---|",
    ]
    for r in results:
        n, stem = r.scene.name, stems[r.scene.name]
        lines.append(f"| {n} | {r.scene.kind} | {r.scene.amount} | "
                     f"{', '.join(sorted(r.curves))} | [png](curves/{stem}.png) | "
                     f"[csv](curves/{stem}.csv) |")
    lines += [
        "",
        "## Closure errors against the reference of each case",
        "",
        "Reference: the curve of the highest `reference_rank` the models declare: the exact "
        "series (`brenner`) for immersed sphere-wall and equal-sphere "
        "cases, else the highest-fidelity solver that ran (`stokes`, `thinfilm`, "
        "`lubrication` for the viscous force; `meniscus` for the capillary force). "
        "Relative errors over the gaps where the reference is non-zero; `spurious` counts "
        "gaps where the reference is zero (no liquid there, or past rupture) but the closure "
        "is not. Data: [closure_errors.csv](closure_errors.csv).",
        "",
        table if "|" in table.splitlines()[-1] and len(table.splitlines()) > 2
        else "No case had both a closure and a reference curve.",
        "",
    ]
    if failures:
        lines += ["## Models that failed", ""] + [f"- {f}" for f in failures] + [""]
    lines += sections
    lines += [
        "",
        "## Provenance",
        "",
        f"- command: `{' '.join(['wetcontact'] + sys.argv[1:]) if sys.argv else 'wetcontact run'}`",
        f"- wetcontact {prov['wetcontact']}, source hash `{code_version()}` (the store's "
        "code version: the same sources give the same report)",
        f"- Python {prov['python']} on {platform.machine()} with "
        + ", ".join(f"{k} {prov[k]}" for k in ("numpy", "scipy", "scikit_fem", "py_pde", "gmsh",
                                              "meshio", "h5py")),
        f"- thin-film benchmark: `{ctx.bench_path}`" if ctx.bench_path else
        "- thin-film benchmark: not given (no stability map or wetting-width study)",
        "- sweeps: " + "; ".join(f"{name}: {n} points" for name, n, _ in stats.stages)
        + f"; {stats.failed} failed",
        f"- wall times of the sweeps, the sections and the run, and how many curves were "
        f"computed or reused from the store: `{TIMINGS}` (not committed: they change with "
        "every run); every curve with its settings and provenance is in `reference.h5`, "
        "the store the run writes beside this file (not committed either: a binary that "
        "every run rewrites; `wetcontact run` rebuilds it, `--resume` reuses it).",
        "",
    ]
    return "\n".join(lines)
