"""Report section: thin-film force curves of the film cases against the viscous closures.

For each film case given to ``wetcontact run`` (amount = film) the ``thinfilm`` model
(default: wetting meniscus with the case's contact angle) is run from S = delta to the
smallest gap; its viscous part is compared with the Reynolds closure ``6 pi eta R^2 v/S``
and the finite-film closure ``6 pi eta R^2 v/S (1 - S/delta)^2`` (Pitois et al. 2000,
PHYSICS.md section 1), its capillary part with the sphere-plane contact limit
``-2 pi R sigma (cos theta_s + 1)`` (the film wets the wall; PHYSICS.md section 2) that DEM
capillary closures reduce to at contact (all errors: the signed error of
:func:`wetcontact.compare.compare`, closure/thinfilm - 1). With the case's particle
density the sphere is also run under its own inertia (speed at the smallest gap, minimum
gap reached). Cases outside the thin-film validity are listed with the solver's reason.
Also written: the stability map (largest stable dt against dr of the explicit and
implicit integrators) and
the convergence of the force in the wetting width lambda, both from the benchmark JSON
given to ``run`` (``--bench``, default ``benchmarks/results/thinfilm.json``; without it the
section says so), and the validity region in (delta/R, Ca) from the model's ``check``.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.compare import compare
from wetcontact.errors import InputError, ValidityError
from wetcontact.models import closure_curve, get_model
from wetcontact.scene import Scene, scene_from_dict
from wetcontact.sweep import Point, SweepResult
from wetcontact.tables import StudyContext

CLOSURES = ("reynolds", "reynolds-finite")


def load_bench(path: str | Path) -> dict[str, Any]:
    """The thin-film benchmark's results (``benchmarks/results/thinfilm.json``)."""
    path = Path(path)
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: not a readable benchmark JSON ({exc}); run "
                         "benchmarks/bench_thinfilm.py or pass --bench") from None


def _film_scenes(ctx: StudyContext) -> list[Scene]:
    return [sc for sc in ctx.scenes if sc.amount == "film"]


def _refusal(scene: Scene) -> str | None:
    """Why the thin-film model refuses ``scene`` (its ValidityError's reason), or None."""
    try:
        get_model("thinfilm").check(scene)
    except ValidityError as exc:
        return exc.reason
    return None


def _case_points(scene: Scene, ctx: StudyContext) -> dict[str, Point]:
    """The thin-film run (and inertial run) of a film case and the closures on its gaps."""
    if ctx.quick:
        scene = scene.with_gaps(np.geomspace(scene.gap_array.max(), scene.gap_array.min(),
                                             10).tolist())
    preset = "fast" if ctx.quick else "default"
    pts = {"thinfilm": Point(scene, "thinfilm", preset)}
    if scene.particle_density is not None and not ctx.quick:
        pts["inertial"] = Point(scene, "thinfilm", preset, settings={"inertia": True})
    pts.update({c: Point(scene, c) for c in CLOSURES})
    return pts


def points(ctx: StudyContext) -> list[Point]:
    """Every film case the thin-film model accepts, with the closures on the same gaps."""
    return [p for sc in _film_scenes(ctx) if _refusal(sc) is None
            for p in _case_points(sc, ctx).values()]


def _contact_limit(scene: Scene, curve: Any) -> Any:
    """The capillary contact limit ``-2 pi R sigma (cos theta_s + 1)`` as a curve."""
    cap = -2 * math.pi * scene.radius * scene.surface_tension * (
        math.cos(scene.contact_angle_sphere) + 1.0)
    return closure_curve(scene.with_gaps(curve.gap.tolist()), "contact-limit",
                         capillary=np.full(curve.gap.shape, cap))


def _case_rows(scene: Scene, result: SweepResult, ctx: StudyContext) -> tuple[list[dict], dict]:
    pts = _case_points(scene, ctx)
    curve = result.curve(pts["thinfilm"])
    if curve is None:
        return [], {}
    inertial: dict = {}
    ic = result.curve(pts["inertial"]) if "inertial" in pts else None
    if ic is not None:
        inertial = {"v_end": float(ic.extras["sphere_speed"][-1]),
                    "reached_all": bool(np.all(ic.extras["reached"] == 1.0)),
                    "min_gap": float(ic.diagnostics["min_gap_m"]),
                    "mass": float(ic.diagnostics["mass_kg"])}
    reyn, fin = (compare(result.curve(pts[c]), curve, "viscous") for c in CLOSURES)
    cap = compare(_contact_limit(scene, curve), curve, "capillary")
    rows = []
    for i, s in enumerate(curve.gap):
        fv = curve.force_viscous[i]
        if fv <= 0:
            continue  # first touch: no wetted zone yet
        rows.append({"case": scene.name, "gap_m": s, "S_over_delta": s / scene.film_thickness,
                     "force_thinfilm_N": curve.force_total[i], "force_viscous_N": fv,
                     "force_capillary_N": curve.force_capillary[i],
                     "wetted_radius_m": curve.extras["wetted_radius"][i],
                     "err_reynolds": reyn.signed_at(s), "err_finite_film": fin.signed_at(s),
                     "err_capillary_contact": cap.signed_at(s),
                     "volume_drift": curve.diagnostics["volume_drift"]})
    return rows, inertial


def validity_map(delta_over_r: np.ndarray, ca: np.ndarray) -> list[list[str | None]]:
    """The thin-film model's verdict on a (Ca, delta/R) grid, through its public ``check``.

    Each point is a scene with R = sigma = eta = 1 (so Ca = v and
    Ca* = 3 Ca/(delta/R)^2 exactly); entry [i][j] is the refusal reason at
    (ca[i], delta_over_r[j]) or None where the model runs.
    """
    base = {"name": "validity-map", "geometry": {"kind": "sphere-wall", "radius": 1.0},
            "liquid": {"viscosity": 1.0, "surface_tension": 1.0, "density": 1000.0}}
    out = []
    for c in ca:
        row = []
        for x in delta_over_r:
            sc = scene_from_dict({**base, "amount": {"film_thickness": float(x)},
                                  "motion": {"velocity": float(c), "gaps": [0.5 * float(x)]}})
            row.append(_refusal(sc))
        out.append(row)
    return out


def _sharp_study(bench: dict | None) -> list[str]:
    """Markdown lines: the sharp contact's work-precision and slow-approach check."""
    if bench is None or "sharp" not in bench:
        return []
    sw = bench["sharp"]
    md = ["Sharp contact (`benchmarks/bench_thinfilm.py`, water case, full penetration): "
          f"error of the total force against {sw['reference_cells']} film cells, observed "
          f"order {sw['observed_order']:.2f} in the film cells.", "",
          "| film cells | max error | wall time (s) |", "|---|---|---|"]
    md += [f"| {r['cells']} | {100 * r['error']:.3f} % | {r['wall_time_s']:.1f} |"
           for r in sw["runs"]]
    md.append("")
    rows = bench.get("slow_approach", {}).get("rows", [])
    if rows:
        by_ca: dict[float, list[float]] = {}
        for r in rows:
            by_ca.setdefault(r["ca_star"], []).append(r["ratio_minus_1"])
        md.append("Capillary part against the finite-element bridge on the bare wall holding "
                  "the same wetted volume: " + "; ".join(
                      f"Ca* = {ca:.2g}: {100 * min(v):+.1f} to {100 * max(v):+.1f} %"
                      for ca, v in sorted(by_ca.items())) + " (the film left under the "
                  "meniscus foot vanishes as Ca* -> 0).")
        md.append("")
    return md


def _width_study(bench: dict | None) -> list[str]:
    """Markdown lines: force error against the wetting width lambda (benchmark JSON)."""
    if bench is None:
        return []
    wp = bench.get("work_precision", {})
    if wp.get("order_variable") != "wetting_width":
        return []
    md = ["Contact regularisation (`benchmarks/bench_thinfilm.py`, water case, full "
          "penetration): error of the total force against the lambda -> 0 extrapolation, "
          f"observed order {wp['observed_order']:.2f} in lambda.", "",
          "| lambda | cells | max error | wall time (s) |", "|---|---|---|---|"]
    md += [f"| {r['wetting_width']:g} | {r['cells']} | {100 * r['error']:.2f} % | "
           f"{r['wall_time_s']:.1f} |" for r in wp["runs"]]
    return [*md, ""]


def _plots(out: Path, stab: list[dict] | None) -> None:
    from wetcontact.plotting import save

    dr_r = np.geomspace(1e-3, 0.5, 120)
    ca = np.geomspace(1e-6, 10, 120)
    reasons = validity_map(dr_r, ca)
    save(stability_figure(stab, dr_r, ca, reasons), out / "thinfilm_stability_validity.png")
    with (out / "thinfilm_validity.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["delta_over_R", "Ca", "valid", "reason"])
        for j, x in list(enumerate(dr_r))[::10]:
            for i, c in list(enumerate(ca))[::10]:
                reason = reasons[i][j]
                w.writerow([f"{x:.4g}", f"{c:.4g}", reason is None, reason or ""])


def stability_figure(stab: list[dict] | None, dr_r: np.ndarray, ca: np.ndarray,
                     reasons: list[list[str | None]]):
    """Largest stable dt against dr (benchmark rows) and the validity map in (delta/R, Ca)."""
    from matplotlib.ticker import NullFormatter

    from wetcontact.plotting import pyplot

    plt = pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    if stab:
        dr = [r["dr_free_m"] for r in stab]
        a.loglog(dr, [r["explicit_free_dt_s"] for r in stab], "o-", label="explicit Euler")
        a.loglog(dr, [r["implicit_free_dt_s"] for r in stab], "s--",
                 label="Newton backward Euler (largest tried)")
        a.loglog(dr, stab[0]["explicit_free_dt_s"] * (np.array(dr) / dr[0]) ** 4, "k:",
                 label="dr^4")
        a.legend(fontsize=7)
    else:
        a.text(0.5, 0.5, "no benchmark results given\n(benchmarks/bench_thinfilm.py)",
               ha="center", va="center", transform=a.transAxes)
    a.xaxis.set_minor_formatter(NullFormatter())  # minor labels overlapped
    a.set_xlabel("dr (m)")
    a.set_ylabel("largest stable dt (s)")
    a.set_title("stability (free water film, 10 um)")
    ok = np.array([[r is None for r in row] for row in reasons])
    b.contourf(dr_r, ca, ok.astype(float), levels=[-0.5, 0.5, 1.5],
               colors=["#f4b6b6", "#b6e3b6"])
    b.set_xscale("log")
    b.set_yscale("log")
    b.set_xlabel("delta/R")
    b.set_ylabel("Ca = eta v/sigma")
    b.set_title("thin-film validity (green: runs; red: refused)")
    fig.tight_layout()
    return fig


def section(out: Path, result: SweepResult, ctx: StudyContext) -> str:
    """Write the thin-film CSV/PNG files into ``out``; return the Markdown section."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows: list[dict] = []
    refused: list[tuple[str, str]] = []
    inertial: dict[str, dict] = {}
    for sc in _film_scenes(ctx):
        reason = _refusal(sc)
        if reason:
            refused.append((sc.name, reason))
            continue
        r, ine = _case_rows(sc, result, ctx)
        rows.extend(r)
        if ine:
            inertial[sc.name] = {**ine, "v0": sc.velocity}
    if rows:
        with (out / "thinfilm_closure_errors.csv").open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    bench = ctx.bench
    stab = bench["stability"]["rows"] if bench is not None else None
    _plots(out, stab)

    md = ["## Thin film: sphere squeezing a liquid layer (model `thinfilm`)", "",
          "Thin-film solver (sharp wetting contact: the finite-element meniscus joined to "
          "the film at its minimum) along the penetration: viscous part against "
          "the Reynolds closure and the finite-film closure 6 pi eta R^2 v/S (1 - S/delta)^2, "
          "capillary part against the contact limit -2 pi R sigma (cos theta_s + 1) "
          "(error = closure/thinfilm - 1; full table in `thinfilm_closure_errors.csv`).", "",
          "| case | S/delta | F total (N) | F_cap (N) | r_w (um) | Reynolds err | "
          "finite-film err | contact-limit err |", "|---|---|---|---|---|---|---|---|"]
    for name in dict.fromkeys(r["case"] for r in rows):
        sub = [r for r in rows if r["case"] == name]
        pick = sorted({0, len(sub) // 4, len(sub) // 2, 3 * len(sub) // 4, len(sub) - 1})
        for i in pick:
            r = sub[i]
            md.append(f"| {name} | {r['S_over_delta']:.3f} | {r['force_thinfilm_N']:.3e} | "
                      f"{r['force_capillary_N']:.3e} | "
                      f"{1e6 * r['wetted_radius_m']:.0f} | {100 * r['err_reynolds']:+.1f} % | "
                      f"{100 * r['err_finite_film']:+.1f} % | "
                      f"{100 * r['err_capillary_contact']:+.1f} % |")
    for name, reason in refused:
        md.append(f"| {name} | refused: {reason} | | | | | | |")
    md.append("")
    for name, ine in inertial.items():
        stop = ("reaches every gap" if ine["reached_all"] else
                f"stops at S = {1e6 * ine['min_gap']:.2f} um")
        md.append(f"Inertial run, {name} (m = {1e6 * ine['mass']:.2f} mg, v0 = {ine['v0']:g} "
                  f"m/s): {stop}; speed at the smallest gap {ine['v_end']:.3f} m/s.")
        md.append("")
    md.extend(_sharp_study(bench))
    md.extend(_width_study(bench))
    if bench is None:
        md += ["No thin-film benchmark results were given (`wetcontact run --bench`, from "
               "`benchmarks/bench_thinfilm.py`): no stability map or wetting-width study.", ""]
    md.append("Stability and validity: `thinfilm_stability_validity.png`, "
              "`thinfilm_validity.csv`.")
    if rows:
        worst_r = max(abs(r["err_reynolds"]) for r in rows)
        worst_f = max(abs(r["err_finite_film"]) for r in rows)
        worst_c = max(abs(r["err_capillary_contact"]) for r in rows)
        small = [r for r in rows if r["S_over_delta"] <= 0.1]
        tail = ""
        if small:
            tail = (f"; for S <= 0.1 delta the errors are at most "
                    f"{100 * max(abs(r['err_reynolds']) for r in small):.0f} % and "
                    f"{100 * max(abs(r['err_finite_film']) for r in small):.0f} %")
        md.append("")
        md.append(f"Conclusion: along the whole penetration the Reynolds closure errs by up "
                  f"to {100 * worst_r:.0f} % and the finite-film closure by up to "
                  f"{100 * worst_f:.0f} % on the viscous part{tail}; the capillary contact "
                  f"limit errs by up to {100 * worst_c:.0f} % on the meniscus suction.")
    return "\n".join(md) + "\n"
