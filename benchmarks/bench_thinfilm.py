"""Thin-film solver benchmark: force error against wall time, and the stability study.

Writes ``benchmarks/results/thinfilm.json`` and ``thinfilm.png``:

1. Work-precision: a full penetration run (S = delta -> 0.01 delta, 40 log-spaced gaps) of a
   2 mm glass bead (0.5 m/s) on a 100 um water film, own BDF2 integrator. Wetting
   meniscus (theta_s = 20 deg): the resolution is the wetting width lambda = 0.2, 0.1,
   0.05, 0.025 with the cells that resolve it (:func:`thinfilm.auto_cells`) on the graded
   grid the model uses (fine out to 1.3 sqrt(4 R delta), 3 % growth beyond); lambda = 0.05
   also on the old uniform grid (same session, for the speed-up). The model converges at
   first order in lambda, so the reference is the first-order Richardson extrapolation
   2 F(0.025) - F(0.05), and each error is the maximum difference of the total force from
   it relative to |F_visc| + |F_cap| of the reference (the total changes sign). For each
   lambda also the model's two-resolution error estimate (lambda against 2 lambda) and its
   ratio to the actual error per gap (>= 1: the estimate bounds it). Tangential contact:
   cells 150 ... 1200 against a 2400-cell run (uniform). The time is one wall-clock run.
   Also the step counts of both integrators over Ca* = 1 ... 1000 (robustness).
2. Presets: median wall time of the ``thinfilm`` model (the run and its error-estimate
   companion) on the case file ``cases/glass-2mm-water-film.toml``, and the largest
   difference between the presets' forces along the penetration.
The machine has 2 cores shared with 5 other jobs while this runs: timings are noisy.
3. Stability: the largest stable fixed time step of py-pde's explicit Euler and of a
   Newton backward-Euler step against the cell width, on a perturbed flat film (the
   capillary operator, explicit limit ~ dr^4) and with the sphere pressed in (penalty).

4. The sharp contact (the model's default since issue 13): work-precision over the film cells
   (64 bridge elements, rtol 1e-4) against 480 cells, 128 elements, rtol 1e-5; and the
   slow-approach check, the capillary part against the finite-element bridge on the bare
   wall holding the same wetted volume, over Ca* = 2e-4 ... 2 (``--sharp-only`` reruns
   these and the presets into the existing JSON, keeping the penalty contacts' studies).

Run: ``/work/venv/bin/python benchmarks/bench_thinfilm.py [--quick | --sharp-only]``.
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np
from _common import RESULTS, write_json

from wetcontact.models import MODELS, load_all, observed_order
from wetcontact.scene import load_case
from wetcontact.solver import thinfilm as tf
from wetcontact.solver.thinfilm.model import SAFETY_FACTOR

CASE = RESULTS.parents[1] / "cases" / "glass-2mm-water-film.toml"
FINE_FACTOR, GROWTH = 1.3, 1.03

R, DELTA, V, ETA, SIGMA = 1e-3, 1e-4, 0.5, 1e-3, 0.072


def water_problem(cells: int, contact: str = "meniscus", velocity: float = V,
                  delta: float = DELTA, wetting_width: float = 0.05,
                  graded: bool = False) -> tf.FilmProblem:
    """2 mm glass bead, 100 um water film, 0.5 m/s (Ca* = 2.1), default penalty and domain,
    theta_s = 20 deg (the glass-2mm-water-film case). ``graded``: the model's graded grid
    whose fine cells are those of ``cells`` uniform cells."""
    length = 3.0 * math.sqrt(4 * R * delta)
    fine = FINE_FACTOR * math.sqrt(4 * R * delta) if graded else None
    if graded:
        cells = tf.graded_cells(length / cells, length, fine, GROWTH)
    return tf.FilmProblem(radius=R, viscosity=ETA, surface_tension=SIGMA, density=998.0,
                          gravity=0.0, film_thickness=delta, velocity=velocity, cells=cells,
                          domain=length, penetration=1e-3, contact=contact,
                          angle_sphere=math.radians(20.0), wetting_width=wetting_width,
                          fine_radius=fine, growth=GROWTH)


def _run(cells: int, contact: str, lam: float, gaps: np.ndarray, rtol: float,
         graded: bool = False) -> dict:
    prob = water_problem(cells, contact, wetting_width=lam, graded=graded)
    t0 = time.perf_counter()
    res = tf.implicit_run(prob, gaps, rtol=rtol)
    wall = time.perf_counter() - t0
    print(f"{contact} cells {prob.cells} lambda {lam} graded {graded}: {wall:.1f} s, "
          f"{res.steps} steps, drift {res.volume_drift:.1e}", flush=True)
    return {"wall_time_s": wall, "steps": res.steps, "volume_drift": res.volume_drift,
            "cells_total": prob.cells,
            "force": np.array([s.force_viscous + s.force_capillary for s in res.snapshots]),
            "scale": np.array([abs(s.force_viscous) + abs(s.force_capillary)
                               for s in res.snapshots]),
            "wetted_radius": [s.wetted_radius for s in res.snapshots]}


def _errors(runs: dict, keys: list, fref: np.ndarray, scale: np.ndarray) -> list[dict]:
    out = []
    for key in keys:
        cells, lam = key[:2]
        err = float(np.max(np.abs(runs[key]["force"][1:] - fref[1:]) / scale[1:]))
        out.append({"cells": cells, "cells_total": runs[key]["cells_total"],
                    "wetting_width": lam, "dr_m": water_problem(cells).dr,
                    "error": err, "wall_time_s": runs[key]["wall_time_s"],
                    "steps": runs[key]["steps"], "volume_drift": runs[key]["volume_drift"]})
    return out


def work_precision(widths: list[float], n_gaps: int) -> dict:
    """Wetting meniscus on the graded grid: lambda refined with its resolution; Richardson
    reference; the model's error estimate against the actual error; lambda = 0.05 on the
    uniform grid for the speed-up."""
    gaps = np.geomspace(DELTA, 0.01 * DELTA, n_gaps)
    all_w = sorted({*widths, min(2 * max(widths), 0.5)}, reverse=True)
    keys = [(tf.auto_cells(R, DELTA, lam), lam, True) for lam in all_w]
    runs = {k: _run(k[0], "meniscus", k[1], gaps, 1e-4, graded=True) for k in keys}
    fine, second = runs[keys[-1]], runs[keys[-2]]
    fref = 2.0 * fine["force"] - second["force"]
    out = _errors(runs, keys[1:], fref, fine["scale"])
    for row, key, coarse in zip(out, keys[1:], keys[:-1], strict=True):
        sc = runs[key]["scale"][1:]
        est = SAFETY_FACTOR * np.abs(runs[key]["force"] - runs[coarse]["force"])[1:] / sc
        actual = np.abs(runs[key]["force"] - fref)[1:] / sc
        row["estimate_max"] = float(np.max(est))
        row["estimate_over_actual_min"] = float(np.min(est / actual))
        print(f"lambda {row['wetting_width']}: error {row['error']:.3f}, estimate max "
              f"{row['estimate_max']:.3f}, min ratio {row['estimate_over_actual_min']:.2f}")
    mid = widths[len(widths) // 2] if 0.05 not in widths else 0.05
    uni = _run(tf.auto_cells(R, DELTA, mid), "meniscus", mid, gaps, 1e-4, graded=False)
    graded_mid = runs[(tf.auto_cells(R, DELTA, mid), mid, True)]
    uniform = {"wetting_width": mid, "cells": uni["cells_total"],
               "wall_time_s": uni["wall_time_s"], "steps": uni["steps"],
               "graded_cells": graded_mid["cells_total"],
               "graded_wall_time_s": graded_mid["wall_time_s"],
               "max_difference_graded_vs_uniform": float(np.max(
                   np.abs(graded_mid["force"] - uni["force"])[1:] / uni["scale"][1:]))}
    print(uniform, flush=True)
    order = observed_order([o["wetting_width"] for o in out], [o["error"] for o in out])
    return {"contact": "meniscus", "grid": f"graded, fine to {FINE_FACTOR} sqrt(4 R delta), "
            f"growth {GROWTH}", "gaps_m": gaps.tolist(),
            "reference": "2 F(lambda_min) - F(2 lambda_min) (first order in lambda)",
            "reference_force_N": fref.tolist(), "runs": out, "observed_order": order,
            "order_variable": "wetting_width", "uniform_vs_graded": uniform,
            "estimate": f"{SAFETY_FACTOR} |F(lambda) - F(2 lambda)| / (|F_visc| + |F_cap|)"}


def presets(repeats: int, names: tuple[str, ...] = ("fast", "default", "accurate")) -> dict:
    """Median wall time of the model's presets on the water case file (with the error
    estimate's companion run), and the largest difference between the presets' forces."""
    load_all()
    model, scene = MODELS["thinfilm"], load_case(CASE)
    out: dict = {"case": CASE.name, "repeats": repeats}
    curves = {}
    for name in names:
        reps = 1 if name == "accurate" else repeats
        times = []
        for _ in range(reps):
            t0 = time.perf_counter()
            curves[name] = model.force(scene, preset=name)
            times.append(time.perf_counter() - t0)
        c = curves[name]
        out[name] = {"median_wall_time_s": float(np.median(times)), "wall_times_s": times,
                     "repeats": reps,
                     "cells": c.diagnostics["cells"],
                     "smallest_resolved_gap_m": c.diagnostics["smallest_resolved_gap_m"],
                     "error_estimate_max": float(np.max(c.error_estimate))}
        print(name, out[name], flush=True)
    if "accurate" not in curves:
        return out
    acc = curves["accurate"]
    scale = np.abs(acc.force_viscous) + np.abs(acc.force_capillary)
    for name in ("fast", "default"):
        out[name]["max_difference_to_accurate"] = float(np.max(
            np.abs(curves[name].force_total - acc.force_total)[1:] / scale[1:]))
    return out


def work_precision_cells(cells_list: list[int], ref_cells: int, n_gaps: int,
                         contact: str = "tangential") -> dict:
    """Grid refinement against a finer run (tangential contact: no lambda)."""
    gaps = np.geomspace(DELTA, 0.01 * DELTA, n_gaps)
    keys = [(n, 0.05) for n in [*cells_list, ref_cells]]
    runs = {k: _run(k[0], contact, k[1], gaps, 1e-5 if k[0] == ref_cells else 1e-4)
            for k in keys}
    ref = runs[keys[-1]]
    out = _errors(runs, keys[:-1], ref["force"], ref["scale"])
    order = observed_order([o["dr_m"] for o in out], [o["error"] for o in out])
    return {"contact": contact, "gaps_m": gaps.tolist(), "reference_cells": ref_cells,
            "reference_wall_time_s": ref["wall_time_s"],
            "reference_force_N": ref["force"].tolist(), "runs": out,
            "observed_order": order, "order_variable": "dr"}


def robustness(ca_stars: list[float], cells: int = 300) -> dict:
    """Steps and wall time of both integrators over Ca* (tangential contact, delta = 10 um)."""
    rows = []
    d = 1e-5
    for ca in ca_stars:
        v = ca * SIGMA * d**2 / (3 * ETA * R**2)
        prob = water_problem(cells, "tangential", velocity=v, delta=d)
        gaps = np.geomspace(d, 0.01 * d, 20)
        row: dict = {"ca_star": ca, "cells": cells}
        for name, run in (("bdf2", lambda p, g: tf.implicit_run(p, g, rtol=1e-4)),
                          ("scipy_bdf", lambda p, g: tf.penetration_run(p, g, rtol=1e-7))):
            t0 = time.perf_counter()
            res = run(prob, gaps)
            row[name] = {"wall_time_s": time.perf_counter() - t0, "steps": res.steps,
                         "force_N": [s.force_viscous + s.force_capillary
                                     for s in res.snapshots]}
        fa, fb = np.array(row["bdf2"]["force_N"][1:]), np.array(row["scipy_bdf"]["force_N"][1:])
        row["max_rel_difference"] = float(np.max(np.abs(fa / fb - 1)))
        print(ca, {k: row[k]["steps"] for k in ("bdf2", "scipy_bdf")},
              f"{row['max_rel_difference']:.1e}", flush=True)
        rows.append(row)
    return {"rows": rows}


def stability(cells_list: list[int]) -> dict:
    rows = []
    for n in cells_list:
        free = tf.leveling_problem(n)
        h0 = free.film_thickness * (1 + 1e-3 * np.cos(np.pi * free.r_c / free.domain))
        dt_e = tf.explicit_stable_dt(free, h0, steps=400, bisections=24, lo=1e-12, hi=10.0)
        dt_i = tf.implicit_stable_dt(free, h0, [dt_e * 10.0**k for k in range(1, 9)],
                                     steps=10)
        # sphere pressed in (S = delta/2), water case, the penalty-stiffened operator
        wet = water_problem(n, "tangential")
        t_half = 0.5 * DELTA / V
        h_w = tf.newton_euler_step(wet, np.full(n, DELTA), 0.0, t_half)
        dt_ew = tf.explicit_stable_dt(wet, h_w, steps=200, bisections=24, lo=1e-20,
                                      hi=1e-6, t0=t_half)
        dt_iw = tf.implicit_stable_dt(wet, h_w, [dt_ew * 10.0**k for k in range(1, 9)],
                                      steps=5, t0=t_half)
        rows.append({"cells": n, "dr_free_m": free.dr, "explicit_free_dt_s": dt_e,
                     "implicit_free_dt_s": dt_i, "dr_wet_m": wet.dr,
                     "explicit_wet_dt_s": dt_ew, "implicit_wet_dt_s": dt_iw})
        print(rows[-1], flush=True)
    slope = observed_order([r["dr_free_m"] for r in rows],
                           [r["explicit_free_dt_s"] for r in rows])
    return {"rows": rows, "explicit_free_slope": slope, "note": stability_note(rows)}


def stability_note(rows: list[dict]) -> str:
    """What the implicit columns mean, with the ratios the rows hold (dt_explicit x 10^k,
    k = 1..8, were tried; the largest that stayed bounded is recorded, 0 if none did)."""
    def ratios(kind: str) -> str:
        out = []
        for r in rows:
            ri, re = r[f"implicit_{kind}_dt_s"], r[f"explicit_{kind}_dt_s"]
            out.append(f"{r['cells']} cells: " + ("none" if ri == 0 else f"{ri / re:.0e}"))
        return ", ".join(out)

    return ("implicit values: the largest of dt_explicit x 10^k (k = 1..8) for which Newton "
            "backward Euler stayed bounded, 0 if none did (not even 10 x explicit); free "
            f"film {ratios('free')}; sphere pressed in {ratios('wet')} (x explicit)")


def _sharp_problem(cells: int, elements: int, velocity: float = V) -> tf.SharpFilm:
    return tf.SharpFilm(radius=R, viscosity=ETA, surface_tension=SIGMA, density=998.0,
                        gravity=0.0, film_thickness=DELTA, velocity=velocity,
                        domain=3.0 * math.sqrt(4 * R * DELTA),
                        angle_sphere=math.radians(20.0), cells=cells, n_elements=elements)


def sharp_work_precision(cells_list: list[int], n_gaps: int, ref_cells: int = 480) -> dict:
    """The sharp contact (default): film cells (64 bridge elements, rtol 1e-4) against a
    finer run (``ref_cells``, 128 elements, rtol 1e-5); full penetration of the water case."""
    gaps = np.geomspace(DELTA, 0.01 * DELTA, n_gaps)

    def run(cells: int, elements: int, rtol: float) -> dict:
        t0 = time.perf_counter()
        res = tf.sharp_run(_sharp_problem(cells, elements), gaps, rtol=rtol)
        wall = time.perf_counter() - t0
        f = np.array([s.force_viscous + s.force_capillary for s in res.snapshots])
        sc = np.array([abs(s.force_viscous) + abs(s.force_capillary) for s in res.snapshots])
        print("sharp", cells, elements, rtol, f"{wall:.1f} s", res.steps, flush=True)
        return {"force": f, "scale": sc, "wall_time_s": wall, "steps": res.steps,
                "volume_drift": res.volume_drift}

    ref = run(ref_cells, 128, 1e-5)
    rows = []
    for n in cells_list:
        r = run(n, 64, 1e-4)
        err = float(np.max(np.abs(r["force"] - ref["force"])[1:] / ref["scale"][1:]))
        rows.append({"cells": n, "error": err, "wall_time_s": r["wall_time_s"],
                     "steps": r["steps"], "volume_drift": r["volume_drift"]})
    order = observed_order([1.0 / r["cells"] for r in rows], [r["error"] for r in rows])
    return {"contact": "sharp", "gaps_m": gaps.tolist(), "reference_cells": ref_cells,
            "reference_force_N": ref["force"].tolist(),
            "reference_wall_time_s": ref["wall_time_s"], "runs": rows,
            "observed_order": order, "order_variable": "film cells"}


def slow_approach(speeds: list[float], cells: int = 80) -> dict:
    """Capillary part of the sharp contact against the finite-element bridge on the bare
    wall holding the same wetted volume (all the liquid inside the meniscus foot), water
    case at decreasing speed; gaps 0.5, 0.1, 0.01 delta."""
    from wetcontact.solver.meniscus import Bridge, solve_volume

    bridge = Bridge(radius=R, contact_angle1=math.radians(20.0), contact_angle2=0.0,
                    surface_tension=SIGMA)
    gaps = DELTA * np.array([1.0, 0.5, 0.1, 0.01])
    rows = []
    for v in speeds:
        res = tf.sharp_run(_sharp_problem(cells, 64, v), gaps, rtol=1e-4)
        for sn in res.snapshots[1:]:
            d = res.details[sn.gap]
            wetted = math.pi * d["foot_radius"] ** 2 * d["foot_height"] + d["bridge_volume"]
            ref = solve_volume(bridge, sn.gap, wetted)
            rows.append({"velocity": v, "ca_star": 3 * ETA * v * R**2 / (SIGMA * DELTA**2),
                         "gap_m": sn.gap, "force_capillary_N": sn.force_capillary,
                         "bridge_force_N": ref.force,
                         "ratio_minus_1": sn.force_capillary / ref.force - 1.0,
                         "foot_height_m": d["foot_height"], "foot_radius_m": d["foot_radius"]})
            print(rows[-1], flush=True)
    return {"rows": rows}


def chart(data: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b, c) = plt.subplots(1, 3, figsize=(16, 5.2), layout="constrained")
    for key, mark, off in (("work_precision", "o-", (-4, 6)),
                           ("work_precision_tangential", "s--", (5, -3))):
        wp = data[key]["runs"]
        var = data[key]["order_variable"]
        a.loglog([r["wall_time_s"] for r in wp], [r["error"] for r in wp], mark,
                 label=f"{data[key]['contact']} (order {data[key]['observed_order']:.2f} "
                       f"in {var}; labels: " + ("film cells)" if var == "dr" else
                                                "lambda / R, cells in all)"))
        for i, r in enumerate(wp):
            tag = (f"{r['cells']}" if var == "dr" else
                   f"{r['wetting_width']:g}, {r['cells_total']}")
            dy = off[1] if var != "dr" else (7 if i % 2 else -9)  # alternate: points close
            a.annotate(tag, (r["wall_time_s"], r["error"]), fontsize=7,
                       textcoords="offset points", xytext=(off[0], dy),
                       ha="right" if var != "dr" else "left")
    uni = data["work_precision"]["uniform_vs_graded"]
    a.plot([uni["wall_time_s"]], [next(r["error"] for r in data["work_precision"]["runs"]
                                      if r["wetting_width"] == uni["wetting_width"])],
           "kx", label=f"uniform grid, lambda {uni['wetting_width']:g} ({uni['cells']} cells)")
    if "sharp" in data:
        sw = data["sharp"]
        a.loglog([r["wall_time_s"] for r in sw["runs"]], [r["error"] for r in sw["runs"]],
                 "D-", color="tab:green",
                 label=f"sharp contact (order {sw['observed_order']:.2f} in film cells)")
        for r in sw["runs"]:
            a.annotate(f"{r['cells']}", (r["wall_time_s"], r["error"]), fontsize=7,
                       textcoords="offset points", xytext=(5, 0), va="center")
    a.axvline(30.0, color="k", ls=":", lw=0.8, label="30 s a run")
    a.legend(fontsize=6.5, loc="lower right")  # below 1e-3 past 10 s: no points there
    a.set_xlabel("wall time of a full penetration run (s)")
    a.set_ylabel("max |F - F_ref|/(|F_visc| + |F_cap|)")
    a.set_ylim(3e-6, 0.5)
    a.set_title("work-precision: 2 mm bead, 100 um water film, 0.5 m/s", fontsize=10)
    rows = data["stability"]["rows"]
    dr = [r["dr_free_m"] for r in rows]
    b.loglog(dr, [r["explicit_free_dt_s"] for r in rows], "o-", label="explicit Euler, free")
    b.loglog(dr, [r["implicit_free_dt_s"] for r in rows], "s--",
             label="Newton backward Euler, free (>=)")
    drw = np.array([r["dr_wet_m"] for r in rows])
    b.loglog(drw, [r["explicit_wet_dt_s"] for r in rows], "^-.", label="explicit, sphere in")
    iw = np.array([r["implicit_wet_dt_s"] for r in rows])
    b.loglog(drw[iw > 0], iw[iw > 0], "v:", label="Newton BE, sphere in (>=)")
    for x, r in zip(drw[iw == 0], [r for r in rows if r["implicit_wet_dt_s"] == 0],
                    strict=True):  # none of 10-1e8 x explicit stayed bounded: no point
        b.annotate("Newton BE: none\nof 10-1e8 x\nexplicit stable", (x, r["explicit_wet_dt_s"]),
                   textcoords="offset points", xytext=(0, 14), ha="center", fontsize=6,
                   color="C3", arrowprops={"arrowstyle": "->", "color": "C3", "lw": 0.8})
    b.set_xlabel("dr (m)")
    b.set_ylabel("largest stable dt (s)")
    b.legend(fontsize=7)
    b.set_title(f"penalty film stability, water case: explicit slope "
                f"{data['stability']['explicit_free_slope']:.2f}\n(free: 10 um film, no "
                "sphere; sphere in: S = delta/2)", fontsize=10)
    if "slow_approach" in data:
        rows = data["slow_approach"]["rows"]
        for g, mark in zip(sorted({r["gap_m"] for r in rows}, reverse=True), ("o-", "s--", "^:"),
                           strict=False):
            sel = [r for r in rows if r["gap_m"] == g]
            c.semilogx([r["ca_star"] for r in sel], [100 * r["ratio_minus_1"] for r in sel],
                       mark, label=f"S = {g / DELTA:g} delta")
        c.axhline(1.0, color="k", ls=":", lw=0.8)
        c.axhline(0.0, color="k", lw=0.5)
        c.set_xlabel("Ca* = 3 eta v R^2/(sigma delta^2)")
        c.set_ylabel("F_cap / F_bridge(same wetted volume) - 1 (%)")
        c.set_title("sharp contact vs FE bridge of the wetted volume\n(water case, slow "
                    "approach)", fontsize=10)
        c.legend(fontsize=7)
    fig.savefig(RESULTS / "thinfilm.png", dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--chart", action="store_true",
                    help="redraw the chart from the existing JSON (the stability note is "
                         "recomputed from its rows); nothing is run")
    ap.add_argument("--presets-only", action="store_true",
                    help="rerun only the preset timings into the existing JSON")
    ap.add_argument("--sharp-only", action="store_true",
                    help="rerun the presets and the sharp-contact studies into the existing "
                         "JSON (the penalty contacts' studies are kept)")
    args = ap.parse_args()
    if args.chart:
        data = json.loads((RESULTS / "thinfilm.json").read_text())
        data["stability"]["note"] = stability_note(data["stability"]["rows"])
        (RESULTS / "thinfilm.json").write_text(json.dumps(data, indent=2, default=float))
        chart(data)
        return
    if args.sharp_only:
        data = json.loads((RESULTS / "thinfilm.json").read_text())
        data["presets"] = presets(3)
        data["sharp"] = sharp_work_precision([20, 40, 80, 160], 40)
        data["slow_approach"] = slow_approach([0.5, 0.05, 5e-3, 5e-4, 5e-5])
        data.pop("cpu_count", None)
        data["note"] = ("2 CPU cores shared with other jobs: timings are noisy. presets, "
                        "sharp and slow_approach: the sharp contact (default); "
                        "work_precision*, robustness, stability: the penalty contacts")
        write_json("thinfilm", data)
        chart(data)
        return
    if args.presets_only:
        data = json.loads((RESULTS / "thinfilm.json").read_text())
        data["presets"] = presets(3)
        data.pop("cpu_count", None)
        write_json("thinfilm", data)
        chart(data)
        return
    if args.quick:
        wp = work_precision([0.2, 0.1], 20)
        pr = presets(1, ("fast",))
        wpt = work_precision_cells([75, 150, 300, 600], 1200, 20)
        rb = robustness([1.0, 100.0])
        st = stability([16, 32, 64])
    else:
        wp = work_precision([0.2, 0.1, 0.05, 0.025], 40)
        pr = presets(3)
        wpt = work_precision_cells([150, 300, 600, 1200], 2400, 40)
        rb = robustness([1.0, 10.0, 100.0, 1000.0])
        st = stability([16, 32, 64, 128])
    data = {"work_precision": wp, "presets": pr, "work_precision_tangential": wpt,
            "robustness": rb, "stability": st,
            "note": "2 CPU cores shared with 5 other jobs while it ran: timings are noisy"}
    write_json("thinfilm", data)
    chart(data)


if __name__ == "__main__":
    main()
