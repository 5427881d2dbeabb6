"""Error table: the Reynolds and finite-liquid closures against the lubrication model.

For a sphere on a wall (exact cap gap, no slip, approach) with a film of thickness delta,
or a bridge holding V = pi R delta^2 (so that its parabolic edge gap at contact is delta),
over S/R in [1e-4, 0.1] and delta/R in [1e-3, 0.3]:

- Reynolds closure ``6 pi eta R^2 v / S`` (Adams & Perchard 1985);
- finite-liquid closure ``6 pi eta R^2 v / S (1 - S/H)^2`` (Pitois et al. 2000) with
  H = delta (film) or ``H = sqrt(S^2 + V/(pi R))`` (bridge);

each as the signed error ``F_closure / F_lubrication - 1`` of
:func:`wetcontact.compare.compare`. ``points(ctx)`` is the study, ``section`` renders it.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from wetcontact.compare import compare
from wetcontact.scene import Scene, scene_from_dict
from wetcontact.sweep import Point, SweepResult
from wetcontact.tables import StudyContext

R, ETA, V = 1.0e-3, 1.0e-3, 0.1
MODELS = ("lubrication", "reynolds", "reynolds-finite")


def _scene(gaps: np.ndarray, amount: dict[str, float]) -> Scene:
    return scene_from_dict({
        "name": "lubrication-table",
        "geometry": {"kind": "sphere-wall", "radius": R},
        "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0},
        "amount": amount,
        "motion": {"velocity": V, "gaps": [float(g) for g in gaps]},
    })


def _grid(quick: bool) -> list[tuple[str, float, Scene]]:
    """(case, delta/R, scene) of the study: film of thickness delta or bridge V = pi R delta^2."""
    s_over_r = np.geomspace(1e-4, 0.1, 4 if quick else 13)
    d_over_r = [1e-3, 1e-2, 0.3] if quick else [1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3]
    out = []
    for case in ("film", "bridge"):
        for d in d_over_r:
            delta = d * R
            gaps = s_over_r * R
            if case == "film":
                gaps = gaps[gaps < 0.999 * delta]
                if gaps.size == 0:
                    continue
                amount = {"film_thickness": delta}
            else:
                amount = {"bridge_volume": math.pi * R * delta**2}
            out.append((case, d, _scene(gaps, amount)))
    return out


def points(ctx: StudyContext) -> list[Point]:
    """The lubrication model and both closures on every scene of the grid."""
    return [Point(sc, m) for _, _, sc in _grid(ctx.quick) for m in MODELS]


def rows(result: SweepResult, ctx: StudyContext) -> list[dict[str, float | str]]:
    """One record per (case, delta/R, S/R): the model and both closures side by side."""
    out: list[dict[str, float | str]] = []
    for case, d, sc in _grid(ctx.quick):
        curve, rey, fin = (result.curve(Point(sc, m)) for m in MODELS)
        if curve is None or rey is None or fin is None:
            continue
        e_rey = compare(rey, curve, "viscous")
        e_fin = compare(fin, curve, "viscous")
        for i, s in enumerate(curve.gap):
            out.append({
                "case": case, "delta_over_R": d, "S_over_R": s / R,
                "wetted_radius_over_R": curve.extras["wetted_radius"][i] / R,
                "F_lubrication_N": curve.force_viscous[i],
                "F_reynolds_N": float(rey.force_viscous[i]),
                "F_finite_liquid_N": float(fin.force_viscous[i]),
                "err_reynolds": e_rey.signed_at(s),
                "err_finite_liquid": e_fin.signed_at(s),
                "model_error_estimate": float(curve.error_estimate[i]),
            })
    return out


def section(out: Path, result: SweepResult, ctx: StudyContext) -> str:
    """Write ``lubrication_errors.csv`` (and a PNG chart) into ``out``; return Markdown."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    recs = rows(result, ctx)
    path = out / "lubrication_errors.csv"
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(recs[0]))
        w.writeheader()
        w.writerows(recs)
    _chart(out / "lubrication_errors.png", recs)
    lines = [
        "## Viscous closures against the lubrication model (finite liquid)",
        "",
        "Sphere on a wall, exact cap gap, no slip; relative error F_closure/F_lubrication - 1 "
        f"over S/R in [1e-4, 0.1]; bridge V = pi R delta^2. Full grid: `{path.name}`; "
        "chart: `lubrication_errors.png`.",
        "",
        "| case | delta/R | S/R range | Reynolds: min .. max error | (1-S/H)^2: max abs error |",
        "|---|---|---|---|---|",
    ]
    worst_fin = 0.0
    for case in ("film", "bridge"):
        for d in sorted({r["delta_over_R"] for r in recs if r["case"] == case}):
            sel = [r for r in recs if r["case"] == case and r["delta_over_R"] == d]
            er = [float(r["err_reynolds"]) for r in sel]
            ef = max(abs(float(r["err_finite_liquid"])) for r in sel)
            worst_fin = max(worst_fin, ef)
            s_lo = min(float(r["S_over_R"]) for r in sel)
            s_hi = max(float(r["S_over_R"]) for r in sel)
            srange = f"{s_lo:.0e} .. {s_hi:.0e}"
            lines.append(f"| {case} | {d:g} | {srange} | {min(er):+.3g} .. {max(er):+.3g} "
                         f"| {ef:.3g} |")
    small = [abs(float(r["err_finite_liquid"])) for r in recs
             if float(r["S_over_R"]) <= 1e-3 and float(r["delta_over_R"]) <= 0.01]
    lines += ["", f"Conclusion: the Reynolds closure ignores the liquid amount and overestimates "
              f"the force without bound as S approaches the edge gap; (1 - S/H)^2 stays within "
              f"{max(small):.2g} for S/R <= 1e-3, delta/R <= 0.01, and within {worst_fin:.2g} "
              "over the whole grid (its error is the parabolic-gap approximation).", ""]
    return "\n".join(lines)


def _chart(path: Path, recs: list[dict[str, float | str]]) -> None:
    from wetcontact.plotting import save

    save(chart_figure(recs), path)


def chart_figure(recs: list[dict[str, float | str]]):
    """|error| of both closures against S/R: one colour per delta/R (never repeated), the
    closure by line style and marker; a filled marker where the closure over-predicts
    (error > 0), an open one where it under-predicts."""
    from matplotlib.lines import Line2D

    from wetcontact.plotting import COLOURS, pyplot

    plt = pyplot()
    deltas = sorted({float(r["delta_over_R"]) for r in recs})
    colour = dict(zip(deltas, COLOURS, strict=False))
    kinds = (("err_finite_liquid", "(1-S/H)^2", "-", "o"), ("err_reynolds", "Reynolds", "--",
                                                            "s"))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
    for ax, case in zip(axes, ("film", "bridge"), strict=True):
        for d in deltas:
            sel = [r for r in recs if r["case"] == case and r["delta_over_R"] == d]
            if not sel:
                continue
            s = np.array([float(r["S_over_R"]) for r in sel])
            for col, _, ls, mk in kinds:
                e = np.array([float(r[col]) for r in sel])
                ax.loglog(s, np.abs(e) + 1e-16, ls, color=colour[d], lw=1)
                pos = e > 0
                ax.loglog(s[pos], np.abs(e[pos]) + 1e-16, mk, color=colour[d], ms=4, ls="none")
                ax.loglog(s[~pos], np.abs(e[~pos]) + 1e-16, mk, color=colour[d], ms=4,
                          ls="none", markerfacecolor="none")
        ax.set_title(f"{case} (R = {R * 1e3:g} mm, v = {V:g} m/s)", fontsize=9)
        ax.set_xlabel("S/R")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("|F_closure / F_lubrication - 1|")
    handles = [Line2D([], [], color=colour[d], lw=2, label=f"delta/R = {d:g}") for d in deltas]
    handles += [Line2D([], [], color="k", ls=ls, marker=mk, ms=4, label=lab)
                for _, lab, ls, mk in kinds]
    handles += [Line2D([], [], color="k", marker="o", ls="none", label="filled: over-predicts"),
                Line2D([], [], color="k", marker="o", ls="none", markerfacecolor="none",
                       label="open: under-predicts")]
    axes[1].legend(handles=handles, fontsize=6, loc="best")
    fig.tight_layout()
    return fig
