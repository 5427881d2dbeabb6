"""Thin-film solver benchmark: force error against wall time, and the stability study.

Writes ``benchmarks/results/thinfilm.json`` and ``thinfilm.png``:

1. Work-precision: a full penetration run (S = delta -> 0.01 delta, 40 log-spaced gaps) of a
   2 mm glass bead (0.5 m/s) on a 100 um water film, own BDF2 integrator. Wetting
   meniscus (theta_s = 20 deg): the resolution is the wetting width lambda = 0.2, 0.1,
   0.05, 0.025 with the cells that resolve it (:func:`thinfilm.auto_cells`); the model
   converges at first order in lambda, so the reference is the first-order Richardson
   extrapolation 2 F(0.025) - F(0.05), and each error is the maximum difference of the
   total force from it relative to |F_visc| + |F_cap| of the reference (the total
   changes sign). Tangential contact: cells 150 ... 1200 against a 2400-cell run. The
   time is one wall-clock run (2 shared cores: noisy). Also the step counts of both
   integrators over Ca* = 1 ... 1000 (robustness).
2. Stability: the largest stable fixed time step of py-pde's explicit Euler and of a
   Newton backward-Euler step against the cell width, on a perturbed flat film (the
   capillary operator, explicit limit ~ dr^4) and with the sphere pressed in (penalty).

Run: ``/work/venv/bin/python benchmarks/bench_thinfilm.py [--quick]``.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from _common import RESULTS, write_json

from wetcontact.models import observed_order
from wetcontact.solver import thinfilm as tf

R, DELTA, V, ETA, SIGMA = 1e-3, 1e-4, 0.5, 1e-3, 0.072


def water_problem(cells: int, contact: str = "meniscus", velocity: float = V,
                  delta: float = DELTA, wetting_width: float = 0.05) -> tf.FilmProblem:
    """2 mm glass bead, 100 um water film, 0.5 m/s (Ca* = 2.1), default penalty and domain,
    theta_s = 20 deg (the glass-2mm-water-film case)."""
    return tf.FilmProblem(radius=R, viscosity=ETA, surface_tension=SIGMA, density=998.0,
                          gravity=0.0, film_thickness=delta, velocity=velocity, cells=cells,
                          domain=3.0 * math.sqrt(4 * R * delta), penetration=1e-3,
                          contact=contact, angle_sphere=math.radians(20.0),
                          wetting_width=wetting_width)


def _run(cells: int, contact: str, lam: float, gaps: np.ndarray, rtol: float) -> dict:
    t0 = time.perf_counter()
    res = tf.implicit_run(water_problem(cells, contact, wetting_width=lam), gaps, rtol=rtol)
    wall = time.perf_counter() - t0
    print(f"{contact} cells {cells} lambda {lam}: {wall:.1f} s, {res.steps} steps, "
          f"drift {res.volume_drift:.1e}", flush=True)
    return {"wall_time_s": wall, "steps": res.steps, "volume_drift": res.volume_drift,
            "force": np.array([s.force_viscous + s.force_capillary for s in res.snapshots]),
            "scale": np.array([abs(s.force_viscous) + abs(s.force_capillary)
                               for s in res.snapshots]),
            "wetted_radius": [s.wetted_radius for s in res.snapshots]}


def _errors(runs: dict, keys: list, fref: np.ndarray, scale: np.ndarray) -> list[dict]:
    out = []
    for key in keys:
        cells, lam = key
        err = float(np.max(np.abs(runs[key]["force"][1:] - fref[1:]) / scale[1:]))
        out.append({"cells": cells, "wetting_width": lam, "dr_m": water_problem(cells).dr,
                    "error": err, "wall_time_s": runs[key]["wall_time_s"],
                    "steps": runs[key]["steps"], "volume_drift": runs[key]["volume_drift"]})
    return out


def work_precision(widths: list[float], n_gaps: int) -> dict:
    """Wetting meniscus: lambda refined with its resolution; Richardson reference."""
    gaps = np.geomspace(DELTA, 0.01 * DELTA, n_gaps)
    keys = [(tf.auto_cells(R, DELTA, lam), lam) for lam in widths]
    runs = {k: _run(k[0], "meniscus", k[1], gaps, 1e-4) for k in keys}
    fine, second = runs[keys[-1]], runs[keys[-2]]
    fref = 2.0 * fine["force"] - second["force"]
    out = _errors(runs, keys, fref, fine["scale"])
    order = observed_order([o["wetting_width"] for o in out], [o["error"] for o in out])
    return {"contact": "meniscus", "gaps_m": gaps.tolist(),
            "reference": "2 F(lambda_min) - F(2 lambda_min) (first order in lambda)",
            "reference_force_N": fref.tolist(), "runs": out, "observed_order": order,
            "order_variable": "wetting_width"}


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
    return {"rows": rows, "explicit_free_slope": slope,
            "note": "implicit values are the largest dt tried (up to 1e8 x explicit); "
                    "all tried steps were stable"}


def chart(data: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    for key, mark in (("work_precision", "o-"), ("work_precision_tangential", "s--")):
        wp = data[key]["runs"]
        var = data[key]["order_variable"]
        a.loglog([r["wall_time_s"] for r in wp], [r["error"] for r in wp], mark,
                 label=f"{data[key]['contact']} (order {data[key]['observed_order']:.2f} "
                       f"in {var})")
        for r in wp:
            tag = (f"{r['cells']}" if var == "dr" else
                   f"lambda {r['wetting_width']:g}, {r['cells']}")
            a.annotate(tag, (r["wall_time_s"], r["error"]), fontsize=7)
    a.axvline(30.0, color="k", ls=":", lw=0.8)
    a.legend(fontsize=7)
    a.set_xlabel("wall time of a full penetration run (s)")
    a.set_ylabel("max |F - F_ref|/(|F_visc| + |F_cap|)")
    a.set_title("thinfilm work-precision (water film, BDF2)")
    rows = data["stability"]["rows"]
    dr = [r["dr_free_m"] for r in rows]
    b.loglog(dr, [r["explicit_free_dt_s"] for r in rows], "o-", label="explicit Euler, free")
    b.loglog(dr, [r["implicit_free_dt_s"] for r in rows], "s--",
             label="Newton backward Euler, free (>=)")
    drw = [r["dr_wet_m"] for r in rows]
    b.loglog(drw, [r["explicit_wet_dt_s"] for r in rows], "^-", label="explicit, sphere in")
    b.loglog(drw, [r["implicit_wet_dt_s"] for r in rows], "v--",
             label="Newton BE, sphere in (>=)")
    b.set_xlabel("dr (m)")
    b.set_ylabel("largest stable dt (s)")
    b.legend(fontsize=7)
    b.set_title(f"explicit slope {data['stability']['explicit_free_slope']:.2f}")
    fig.tight_layout()
    fig.savefig(RESULTS / "thinfilm.png", dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    if args.quick:
        wp = work_precision([0.3, 0.2, 0.1], 20)
        wpt = work_precision_cells([75, 150, 300, 600], 1200, 20)
        rb = robustness([1.0, 100.0])
        st = stability([16, 32, 64])
    else:
        wp = work_precision([0.2, 0.1, 0.05, 0.025], 40)
        wpt = work_precision_cells([150, 300, 600, 1200], 2400, 40)
        rb = robustness([1.0, 10.0, 100.0, 1000.0])
        st = stability([16, 32, 64, 128])
    data = {"work_precision": wp, "work_precision_tangential": wpt, "robustness": rb,
            "stability": st,
            "note": "2 CPU cores shared with another developer: timings are noisy"}
    write_json("thinfilm", data)
    chart(data)


if __name__ == "__main__":
    main()
