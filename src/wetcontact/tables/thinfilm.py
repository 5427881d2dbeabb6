"""Report section: thin-film force curves of the film cases against the viscous closures.

For each film case in ``cases/`` (``*film*.toml``, amount = film) the ``thinfilm`` model
(default: wetting meniscus with the case's contact angle) is run from S = delta to the
smallest gap; its viscous part is compared with the Reynolds closure ``6 pi eta R^2 v/S``
and the finite-film closure ``6 pi eta R^2 v/S (1 - S/delta)^2`` (Pitois et al. 2000,
PHYSICS.md section 1), its capillary part with the sphere-plane contact limit
``-2 pi R sigma (cos theta_s + 1)`` (the film wets the wall; PHYSICS.md section 2) that DEM
capillary closures reduce to at contact. With the case's particle density the sphere is
also run under its own inertia (speed at the smallest gap, minimum gap reached). Cases
outside the thin-film validity are listed with the solver's reason. Also written: the
stability map (largest stable dt against dr of the explicit and implicit integrators,
from ``benchmarks/results/thinfilm.json`` when present, else a small computation), the
convergence of the force in the wetting width lambda (from the same JSON) and the
validity region in (delta/R, Ca).
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

from wetcontact.errors import ValidityError
from wetcontact.models import MODELS, load_all
from wetcontact.scene import Scene, load_case
from wetcontact.solver import thinfilm as tf

ROOT = Path(__file__).resolve().parents[3]


def _closures(scene: Scene, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Reynolds and finite-film viscous closures (N) at gaps ``s``; capillary contact limit."""
    assert scene.film_thickness is not None
    reyn = 6 * math.pi * scene.viscosity * scene.radius**2 * scene.velocity / s
    cap = -2 * math.pi * scene.radius * scene.surface_tension * (
        math.cos(scene.contact_angle_sphere) + 1.0)
    return reyn, reyn * (1 - s / scene.film_thickness) ** 2, cap


def _case_rows(scene: Scene, quick: bool) -> tuple[list[dict], str | None, dict]:
    model = MODELS["thinfilm"]
    try:
        model.check(scene)
    except ValidityError as exc:
        return [], exc.reason, {}
    gaps = scene.gap_array
    if quick:
        gaps = np.geomspace(gaps.max(), gaps.min(), 10)
    preset = "fast" if quick else "default"
    curve = model.force(scene, gaps=gaps, preset=preset)
    inertial: dict = {}
    if scene.particle_density is not None and not quick:
        ic = model.force(scene, gaps=gaps, preset=preset, inertia=True)
        inertial = {"v_end": float(ic.extras["sphere_speed"][-1]),
                    "reached_all": bool(np.all(ic.extras["reached"] == 1.0)),
                    "min_gap": float(ic.diagnostics["min_gap_m"]),
                    "mass": float(ic.diagnostics["mass_kg"])}
    reyn, fin, cap = _closures(scene, curve.gap)
    rows = []
    for i, s in enumerate(curve.gap):
        fv = curve.force_viscous[i]
        if fv <= 0:
            continue  # first touch: no wetted zone yet
        rows.append({"case": scene.name, "gap_m": s, "S_over_delta": s / scene.film_thickness,
                     "force_thinfilm_N": curve.force_total[i], "force_viscous_N": fv,
                     "force_capillary_N": curve.force_capillary[i],
                     "wetted_radius_m": curve.extras["wetted_radius"][i],
                     "err_reynolds": reyn[i] / fv - 1, "err_finite_film": fin[i] / fv - 1,
                     "err_capillary_contact": cap / curve.force_capillary[i] - 1,
                     "volume_drift": curve.diagnostics["volume_drift"],
                     "wall_time_s": curve.diagnostics["wall_time_s"]})
    return rows, None, inertial


def _bench() -> dict | None:
    """The thin-film benchmark's results (``benchmarks/results/thinfilm.json``), if run."""
    path = ROOT / "benchmarks" / "results" / "thinfilm.json"
    return json.loads(path.read_text()) if path.exists() else None


def _stability(bench: dict | None) -> list[dict]:
    if bench is not None:
        return bench["stability"]["rows"]
    rows = []
    for n in (16, 32, 64):
        free = tf._leveling_problem(n)
        h0 = free.film_thickness * (1 + 1e-3 * np.cos(np.pi * free.r_c / free.domain))
        dt_e = tf.explicit_stable_dt(free, h0, steps=200, bisections=16, lo=1e-12, hi=1.0)
        dt_i = tf.implicit_stable_dt(free, h0, [dt_e * 10.0**k for k in (2, 4, 6)], steps=5)
        rows.append({"cells": n, "dr_free_m": free.dr, "explicit_free_dt_s": dt_e,
                     "implicit_free_dt_s": dt_i})
    return rows


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


def _plots(out: Path, stab: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    dr = [r["dr_free_m"] for r in stab]
    a.loglog(dr, [r["explicit_free_dt_s"] for r in stab], "o-", label="explicit Euler")
    a.loglog(dr, [r["implicit_free_dt_s"] for r in stab], "s--",
             label="Newton backward Euler (largest tried)")
    a.loglog(dr, stab[0]["explicit_free_dt_s"] * (np.array(dr) / dr[0]) ** 4, "k:",
             label="dr^4")
    a.set_xlabel("dr (m)")
    a.set_ylabel("largest stable dt (s)")
    a.legend(fontsize=7)
    a.set_title("stability (free water film, 10 um)")
    dr_r = np.geomspace(1e-3, 0.5, 120)
    ca = np.geomspace(1e-6, 10, 120)
    ok = np.array([[tf.validity_reason(x, c, 3 * c / x**2) is None for x in dr_r] for c in ca])
    b.contourf(dr_r, ca, ok.astype(float), levels=[-0.5, 0.5, 1.5],
               colors=["#f4b6b6", "#b6e3b6"])
    b.set_xscale("log")
    b.set_yscale("log")
    b.set_xlabel("delta/R")
    b.set_ylabel("Ca = eta v/sigma")
    b.set_title("thin-film validity (green: runs; red: refused)")
    fig.tight_layout()
    fig.savefig(out / "thinfilm_stability_validity.png", dpi=110)
    plt.close(fig)
    with (out / "thinfilm_validity.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["delta_over_R", "Ca", "valid", "reason"])
        for x in dr_r[::10]:
            for c in ca[::10]:
                reason = tf.validity_reason(x, c, 3 * c / x**2)
                w.writerow([f"{x:.4g}", f"{c:.4g}", reason is None, reason or ""])


def section(out: Path, quick: bool) -> str:
    """Write the thin-film CSV/PNG files into ``out``; return the Markdown section."""
    load_all()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    cases = sorted((ROOT / "cases").glob("*film*.toml"))
    scenes = [sc for sc in (load_case(p) for p in cases) if sc.amount == "film"]
    rows: list[dict] = []
    refused: list[tuple[str, str]] = []
    inertial: dict[str, dict] = {}
    for sc in scenes:
        r, reason, ine = _case_rows(sc, quick)
        rows.extend(r)
        if reason:
            refused.append((sc.name, reason))
        if ine:
            inertial[sc.name] = {**ine, "v0": sc.velocity}
    if rows:
        with (out / "thinfilm_closure_errors.csv").open("w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    bench = _bench()
    stab = _stability(bench)
    _plots(out, stab)

    md = ["## Thin film: sphere squeezing a liquid layer (model `thinfilm`)", "",
          "Thin-film solver (wetting meniscus) along the penetration: viscous part against "
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
    md.extend(_width_study(bench))
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
