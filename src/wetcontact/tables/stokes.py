"""Error table: viscous closures against the axisymmetric Stokes FEM reference.

Two studies, both for a sphere approaching a wall (R = 1 mm, eta = 1 mPa s, v = 0.1 m/s;
the relative errors do not depend on these by linearity):

* **immersed**, S/R in [1e-4, 10]: the FEM (``stokes``) against Brenner's exact series (its
  own accuracy), and the Reynolds closure, the Cox-Brenner inner expansion and, when it is
  registered, the level-1 ``lubrication`` model against the FEM;
* **film** of thickness delta (flat free surface outside the sphere), S/delta in [0.01, 0.9]
  at delta/R = 0.01, plus the limit delta/R -> 0 at S/delta = 0.5: the Reynolds closure, the
  finite-liquid closure ``reynolds-finite`` (factor (1 - S/delta)^2, Pitois et al. 2000) and
  ``lubrication`` against the FEM.

Error = closure / FEM - 1. ``section(out, quick)`` writes ``stokes_errors.csv`` into ``out``
and returns the Markdown section. The FEM uses the ``default`` preset (``fast`` with
``quick``); the accurate sweep is in ``benchmarks/bench_stokes.py``.
"""

from __future__ import annotations

import csv
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import InputError, ValidityError
from wetcontact.models import load_all
from wetcontact.reduced_models.viscous import brenner_lambda
from wetcontact.scene import Scene, scene_from_dict

R, ETA, V = 1.0e-3, 1.0e-3, 0.1
CLOSURES = ("reynolds", "cox-brenner", "reynolds-finite", "lubrication")


def _scene(gaps: list[float], film: float | None = None) -> Scene:
    return scene_from_dict({
        "name": "stokes-table" if film is None else f"stokes-table-film-{film:g}",
        "geometry": {"kind": "sphere-wall", "radius": R},
        "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0},
        "amount": {"immersed": True} if film is None else {"film_thickness": film},
        "motion": {"velocity": V, "gaps": gaps},
    })


def _closure(models: dict[str, Any], name: str, scene: Scene) -> np.ndarray:
    """Closure force (N) at the scene's gaps; NaN where the model is absent or not valid."""
    n = scene.gap_array.size
    if name not in models:
        return np.full(n, np.nan)
    try:
        return np.asarray(models[name].force(scene).force_viscous, dtype=float)
    except (ValidityError, InputError):
        return np.full(n, np.nan)


def _fmt(x: float) -> str:
    return "n/a" if not np.isfinite(x) else f"{x:+.2e}"


def section(out: Path, quick: bool) -> str:
    """Write ``stokes_errors.csv`` into ``out`` and return the Markdown section."""
    t0 = time.perf_counter()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    models = load_all()
    fem = models["stokes"]
    preset = "fast" if quick else "default"
    rows: list[dict[str, Any]] = []

    s_imm = [1e-3, 0.1, 1.0] if quick else [1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0]
    sc = _scene([s * R for s in s_imm])
    f_fem = fem.force(sc, preset=preset)
    exact = 6 * math.pi * ETA * R * V * brenner_lambda(np.array(s_imm))
    closures = {c: _closure(models, c, sc) for c in CLOSURES}
    for i, s in enumerate(s_imm):
        f = f_fem.force_viscous[i]
        rows.append({"case": "immersed", "s_over_r": s, "delta_over_r": "", "s_over_delta": "",
                     "force_fem": f, "fem_vs_exact": f / exact[i] - 1,
                     **{f"err_{c}": closures[c][i] / f - 1 for c in CLOSURES}})

    studies: list[tuple[float, list[float]]] = []
    ratios = [0.1, 0.5, 0.9] if quick else [0.01, 0.1, 0.3, 0.5, 0.7, 0.9]
    studies.append((0.01, ratios))
    for d in ([0.04] if quick else [0.1, 0.03, 0.003]):
        studies.append((d, [0.5]))
    for d, rs in studies:
        sc = _scene([r * d * R for r in rs], film=d * R)
        f_fem = fem.force(sc, preset=preset)
        closures = {c: _closure(models, c, sc) for c in CLOSURES}
        for i, r in enumerate(rs):
            f = f_fem.force_viscous[i]
            rows.append({"case": "film", "s_over_r": r * d, "delta_over_r": d,
                         "s_over_delta": r, "force_fem": f, "fem_vs_exact": float("nan"),
                         **{f"err_{c}": closures[c][i] / f - 1 for c in CLOSURES}})

    path = out / "stokes_errors.csv"
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        for row in rows:
            w.writerow({k: (f"{v:.8e}" if isinstance(v, float) else v) for k, v in row.items()})

    lines = [
        "## Viscous closures against the Stokes FEM",
        "",
        f"Sphere approaching a wall; error = closure / FEM - 1; FEM preset `{preset}` "
        f"(its own error against Brenner's exact series in the first column). "
        f"CSV: `{path.name}`.",
        "",
        "| case | S/R | delta/R | S/delta | FEM vs exact | Reynolds | Cox-Brenner | "
        "(1-S/H)^2 finite liquid | lubrication |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        dr = "" if row["delta_over_r"] == "" else f"{row['delta_over_r']:g}"
        sd = "" if row["s_over_delta"] == "" else f"{row['s_over_delta']:g}"
        lines.append(
            f"| {row['case']} | {row['s_over_r']:.3g} | {dr} | {sd} | "
            f"{_fmt(row['fem_vs_exact'])} | {_fmt(row['err_reynolds'])} | "
            f"{_fmt(row['err_cox-brenner'])} | {_fmt(row['err_reynolds-finite'])} | "
            f"{_fmt(row['err_lubrication'])} |")
    imm = [r for r in rows if r["case"] == "immersed"]
    worst = max(abs(r["err_reynolds"]) for r in imm if r["s_over_r"] <= 0.1)
    film = [r for r in rows if r["case"] == "film" and r["delta_over_r"] == 0.01]
    fl = [abs(r["err_reynolds-finite"]) for r in film if np.isfinite(r["err_reynolds-finite"])]
    lines += ["", (f"Immersed: the Reynolds closure is within {100 * worst:.1f} % of the FEM for "
                   f"S/R <= 0.1 and fails beyond; in a film (delta/R = 0.01) the finite-liquid "
                   f"factor stays within {100 * max(fl):.0f} % of the FEM over S/delta in "
                   f"[{film[0]['s_over_delta']:g}, {film[-1]['s_over_delta']:g}] "
                   f"({time.perf_counter() - t0:.0f} s).") if fl else
              f"Immersed: Reynolds within {100 * worst:.1f} % for S/R <= 0.1."]
    return "\n".join(lines) + "\n"
