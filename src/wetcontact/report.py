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

import csv
import importlib
import importlib.util
import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from wetcontact.errors import InputError, SolverError
from wetcontact.models import ForceCurve, Model, load_all, provenance
from wetcontact.scene import Scene, load_case
from wetcontact.store import Store

PRESET_OF_MODE = {"quick": "fast", "default": "default", "full": "accurate"}
# Study sections, in report order; a module that is not present is skipped.
SECTIONS = ("lubrication", "stokes", "thinfilm", "capillary_closures")
# Reference model for a component, best first, when the exact series does not apply.
VISCOUS_REFERENCES = ("brenner", "stokes", "thinfilm", "lubrication")
CAPILLARY_REFERENCES = ("meniscus",)


@dataclass
class CaseResult:
    """Curves computed for one case, and the models that failed with their messages."""

    scene: Scene
    curves: dict[str, ForceCurve]
    failures: dict[str, str]


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
    return scenes


def compute_cases(scenes: list[Scene], store: Store, preset: str, resume: bool,
                  progress: bool = True) -> list[CaseResult]:
    """Every applicable model on every scene, each curve saved to ``store`` when done."""
    from tqdm import tqdm

    models = load_all()
    tasks = [(sc, m) for sc in scenes for m in models.values() if m.applicable(sc) is None]
    results = {sc.name: CaseResult(sc, {}, {}) for sc in scenes}
    bar = tqdm(tasks, desc="curves", unit="curve", file=sys.stderr,
                disable=None if progress else True)  # None: off when stderr is no TTY
    for sc, m in bar:
        bar.set_postfix_str(f"{sc.name[:28]} / {m.name}")
        res = results[sc.name]
        try:
            curve = _cached(store, sc, m, preset) if resume else None
            if curve is None:
                curve = m.force(sc, preset=_preset_for(m, preset))
                store.save(sc, curve)
            res.curves[m.name] = curve
        except Exception as exc:  # noqa: BLE001 - one failing model must not stop the job
            msg = str(exc) if isinstance(exc, SolverError | InputError) else (
                f"{type(exc).__name__}: {exc}")
            res.failures[m.name] = msg
            bar.write(f"wetcontact: {sc.name} / {m.name}: {msg}", file=sys.stderr)
    return list(results.values())


def _preset_for(model: Model, preset: str) -> str:
    return preset if preset in model.presets else "default"


def _cached(store: Store, sc: Scene, m: Model, preset: str) -> ForceCurve | None:
    settings = {"preset": _preset_for(m, preset), **m.presets[_preset_for(m, preset)]}
    return store.get(sc, m.name, settings)


# ---- closure comparison -----------------------------------------------------------------


def reference_for(res: CaseResult, component: str) -> str | None:
    """Name of the reference curve for a component, or ``None`` if none was computed."""
    names = VISCOUS_REFERENCES if component == "viscous" else CAPILLARY_REFERENCES
    return next((n for n in names if n in res.curves), None)


def error_rows(results: list[CaseResult]) -> list[dict[str, object]]:
    """One row per (case, component, closure): error statistics against the reference.

    Relative error ``|F - F_ref| / |F_ref|`` over the gaps where the reference force is not
    zero; gaps where the reference is zero (no liquid, past rupture) but the closure is not
    are counted as ``spurious``.
    """
    models = load_all()
    rows: list[dict[str, object]] = []
    for res in results:
        for comp in ("viscous", "capillary"):
            ref_name = reference_for(res, comp)
            if ref_name is None:
                continue
            ref = getattr(res.curves[ref_name], f"force_{comp}")
            scale = np.max(np.abs(ref))
            nz = np.abs(ref) > 1e-12 * scale if scale > 0 else np.zeros(ref.shape, bool)
            for name, curve in res.curves.items():
                f = getattr(curve, f"force_{comp}")
                if name == ref_name or f is None or models[name].level != 0:
                    continue
                rel = np.abs(f[nz] - ref[nz]) / np.abs(ref[nz])
                rows.append({
                    "case": res.scene.name, "component": comp, "closure": name,
                    "reference": ref_name, "points": int(nz.sum()),
                    "max_rel_error": float(rel.max()) if rel.size else float("nan"),
                    "mean_rel_error": float(rel.mean()) if rel.size else float("nan"),
                    "p95_rel_error": float(np.percentile(rel, 95)) if rel.size else float("nan"),
                    "spurious": int(np.sum(~nz & (np.abs(f) > 0))),
                })
    return rows


def write_error_table(rows: list[dict[str, object]], out: Path) -> str:
    """Write ``closure_errors.csv`` and return the Markdown table."""
    cols = ["case", "component", "closure", "reference", "points", "max_rel_error",
            "mean_rel_error", "p95_rel_error", "spurious"]
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


def write_case_outputs(res: CaseResult, out: Path) -> None:
    """``curves/<case>.png`` (|F| against gap, every model) and ``curves/<case>.csv``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = out / "curves"
    folder.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, c in sorted(res.curves.items()):
        for comp, style in (("viscous", "-"), ("capillary", "--")):
            f = getattr(c, f"force_{comp}")
            if f is not None and np.any(f != 0):
                ax.loglog(c.gap, np.abs(f), style, marker="." if c.gap.size < 50 else None,
                          label=f"{name} ({comp})")
    sc = res.scene
    ax.set_xlabel("surface gap S (m)")
    ax.set_ylabel("|axial force| (N)")
    ax.set_title(f"{sc.name}\n{sc.kind}, {sc.amount}, R = {sc.radius:g} m, v = {sc.velocity:g} "
                 "m/s", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(folder / f"{sc.name}.png", dpi=110)
    plt.close(fig)
    with open(folder / f"{sc.name}.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["model", "gap_m", "force_viscous_N", "force_capillary_N", "force_total_N"])
        for name, c in sorted(res.curves.items()):
            for i in range(c.gap.size):
                w.writerow([name, f"{c.gap[i]:.9e}",
                            "" if c.force_viscous is None else f"{c.force_viscous[i]:.9e}",
                            "" if c.force_capillary is None else f"{c.force_capillary[i]:.9e}",
                            f"{c.force_total[i]:.9e}"])


# ---- the job ----------------------------------------------------------------------------


def run_all(cases: Path = Path("cases"), out: Path = Path("reports"), mode: str = "default",
            resume: bool = False, progress: bool = True) -> Path:
    """Regenerate ``out`` from the cases; return the path of ``out/README.md``.

    Parameters
    ----------
    cases
        Folder of TOML case files.
    out
        Output folder (created).
    mode
        ``"quick"`` (fast presets, smoke studies), ``"default"`` or ``"full"`` (accurate).
    resume
        Reuse curves already in ``out/reference.h5`` instead of recomputing them.
    """
    if mode not in PRESET_OF_MODE:
        raise InputError(f"mode = {mode!r}; allowed: " + ", ".join(PRESET_OF_MODE))
    t0 = time.perf_counter()
    scenes = load_cases(cases)
    out.mkdir(parents=True, exist_ok=True)
    store_path = out / "reference.h5"
    if not resume and store_path.exists():
        store_path.unlink()
    store = Store(store_path)
    results = compute_cases(scenes, store, PRESET_OF_MODE[mode], resume, progress)
    for res in results:
        write_case_outputs(res, out)
    table = write_error_table(error_rows(results), out)

    sections, failed = [], []
    for name in SECTIONS:
        mod_name = f"wetcontact.tables.{name}"
        if importlib.util.find_spec(mod_name) is None:
            continue
        ts = time.perf_counter()
        try:
            md = importlib.import_module(mod_name).section(out, mode == "quick")
        except Exception as exc:  # noqa: BLE001 - report it, write the rest
            failed.append(f"{name}: {type(exc).__name__}: {exc}")
            md = f"## {name}\n\nThis section failed: {exc}\n"
        took = time.perf_counter() - ts
        sections.append(md.rstrip() + f"\n\n_Section computed in {took:.1f} s._")

    failures = [f"{r.scene.name} / {m}: {msg}" for r in results for m, msg in r.failures.items()]
    readme = _readme(results, table, sections, failures, mode, time.perf_counter() - t0)
    path = out / "README.md"
    path.write_text(readme)
    if failed or failures:
        raise SolverError(f"{len(failures)} curve(s) and {len(failed)} report section(s) "
                          f"failed (listed in {path}): " + "; ".join(failed + failures)[:500])
    return path


def _readme(results: list[CaseResult], table: str, sections: list[str], failures: list[str],
            mode: str, wall: float) -> str:
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
        n = r.scene.name
        lines.append(f"| {n} | {r.scene.kind} | {r.scene.amount} | "
                     f"{', '.join(sorted(r.curves))} | [png](curves/{n}.png) | "
                     f"[csv](curves/{n}.csv) |")
    lines += [
        "",
        "## Closure errors against the reference of each case",
        "",
        "Reference: the exact series (`brenner`) for immersed sphere-wall and equal-sphere "
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
        f"- wetcontact {prov['wetcontact']}, git commit `{prov['git_commit']}`",
        f"- Python {prov['python']} on {platform.machine()} with "
        + ", ".join(f"{k} {prov[k]}" for k in ("numpy", "scipy", "scikit_fem", "py_pde", "gmsh",
                                              "meshio", "h5py")),
        f"- total wall time {wall:.1f} s; every curve with its settings and provenance is in "
        "`reference.h5`.",
        "",
    ]
    return "\n".join(lines)
