"""The dynamic rupture distance: its Ca -> 0 limit, and error against time of the presets.

1. **Ca -> 0.** A sphere on a wall, V/R^3 = 1e-3, 30 deg, stretched at Ca = 1e-8 .. 1e-3
   (default preset) from 0.2 S_c to its pinch: the slowest runs' distance from the static
   fold of ``meniscus`` (issue 57: within 1e-3), and ``S_c(Ca)/S_c = 1 + delta_0 + a Ca^b``
   fitted through all runs (least squares) and through the three at Ca = 1e-6 .. 1e-4
   (exact); ``delta_0`` is how far the fitted limit is from the static fold.
2. **Presets.** The same bridge at Ca = 1e-2 and 1e-4, and two equal spheres at Ca = 1e-2,
   at the fast, default and accurate presets (:data:`~wetcontact.solver.stokes_dynamic.
   rupture.PRESETS`: error tolerances 4e-6, 2e-6, 3e-7): each preset's difference from the
   accurate one (for the accurate one itself, the default's difference, a bound on its
   error since the error falls with the tolerance) and its wall time.
3. **Force.** The registered model ``stokes-dynamic`` on an SI scene (R = 1 mm, sphere on a
   wall, V/R^3 = 1e-3, 20 deg, Ca = 1e-2 from 0.022 R) at the three presets: the force at
   0.03-0.11 R (up to the static fold, 0.1104 R) and each preset's difference from the
   accurate one.

Runs go through the generator's cache (:class:`wetcontact.generate.dynamic_rupture.RunCache`):
a run the generator or an earlier benchmark already made is not made again (its wall time
is the one recorded then). Writes ``benchmarks/results/dynamic_rupture.json`` and
``dynamic_rupture.png``. Run: ``.venv/bin/python benchmarks/bench_dynamic_rupture.py``
(``--chart`` redraws from the JSON).
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from scipy.optimize import OptimizeWarning, curve_fit  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import main_or_chart, save_chart, write_json  # noqa: E402

from wetcontact.generate.dynamic_rupture import RunCache, solve_all  # noqa: E402
from wetcontact.solver.stokes_dynamic.rupture import RuptureCase  # noqa: E402

LIMIT_CAS = (1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3)
PRESET_CASES = (RuptureCase("wall", 1e-2, 1e-3, 30.0), RuptureCase("wall", 1e-4, 1e-3, 30.0),
                RuptureCase("pair", 1e-2, 1e-3, 30.0))
PRESETS = ("fast", "default", "accurate")


def _row(r: dict) -> dict:
    if "error" in r:
        return {"case": r["case"], "preset": r["preset"], "error": r["error"]}
    return {"case": r["case"], "preset": r["preset"], **r["result"]}


def limit(cache: RunCache) -> dict:
    rows = [_row(solve_all([RuptureCase("wall", ca, 1e-3, 30.0)], 1, cache=cache)[0])
            for ca in LIMIT_CAS]
    ca = np.array([r["case"]["capillary_number"] for r in rows])
    ratio = np.array([r["ratio"] for r in rows])

    def form(c, d0, a, b):
        return 1.0 + d0 + a * c**b

    (d0, a, b), cov = curve_fit(form, ca, ratio, p0=(0.0, 1.0, 0.4))
    low = (ca >= 1e-6) & (ca <= 1e-4)
    with warnings.catch_warnings():  # three points, three coefficients: no covariance
        warnings.simplefilter("ignore", OptimizeWarning)
        (d3, a3, b3), _ = curve_fit(form, ca[low], ratio[low], p0=(0.0, 1.0, 0.5))
    slowest = int(np.argmin(ca))
    return {"runs": rows, "slowest": {"capillary_number": float(ca[slowest]),
                                      "ratio": float(ratio[slowest])},
            "fit": {"delta_0": float(d0), "a": float(a), "b": float(b),
                                  "delta_0_sd": float(math.sqrt(cov[0, 0]))},
            "fit_low": {"delta_0": float(d3), "a": float(a3), "b": float(b3),
                        "through": [float(c) for c in ca[low]]},
            "goal": 1e-3}


def presets(cache: RunCache) -> list[dict]:
    out = []
    for case in PRESET_CASES:
        rows = [_row(solve_all([case], 1, preset=p, cache=cache)[0]) for p in PRESETS]
        g = np.array([r["gap"] for r in rows])
        err = [abs(g[0] / g[2] - 1.0), abs(g[1] / g[2] - 1.0), abs(g[1] / g[2] - 1.0)]
        out.append({"case": rows[0]["case"], "static_gap": rows[0]["static_gap"],
                    "presets": [{"preset": pr, "gap": r["gap"], "ratio": r["ratio"],
                                 "error": e, "steps": r["steps"],
                                 "wall_time_s": r["wall_time"]}
                                for pr, r, e in zip(PRESETS, rows, err, strict=True)]})
    return out


FORCE_GAPS = (0.03, 0.05, 0.07, 0.09, 0.10, 0.105, 0.11)


def force_presets() -> dict:
    from wetcontact.models import get_model
    from wetcontact.scene import scene_from_dict

    R, eta, sigma, ca = 1e-3, 0.1, 0.02, 1e-2
    sc = scene_from_dict({
        "name": "dynamic-presets", "geometry": {"kind": "sphere-wall", "radius": R},
        "liquid": {"viscosity": eta, "surface_tension": sigma, "density": 1000.0,
                   "contact_angle": 20.0, "slip_length_sphere": 1e-3 * R,
                   "slip_length_wall": 1e-3 * R},
        "amount": {"bridge_volume": 1e-3 * R**3},
        "motion": {"velocity": -ca * sigma / eta, "gaps": [g * R for g in FORCE_GAPS]}})
    model = get_model("stokes-dynamic")
    curves = {p: model.force(sc, preset=p, start=0.022) for p in PRESETS}
    acc = curves["accurate"].force_total
    return {"gaps_over_R": list(FORCE_GAPS), "capillary_number": ca,
            "presets": [{"preset": p, "force_N": c.force_total.tolist(),
                         "error": np.abs(c.force_total / acc - 1.0).tolist(),
                         "wall_time_s": c.diagnostics["wall_time_s"]}
                        for p, c in curves.items()]}


def main() -> None:
    cache = RunCache()
    lim = limit(cache)
    f = lim["fit"]
    f3 = lim["fit_low"]
    slow = lim["slowest"]
    print(f"Ca -> 0: S_c(Ca)/S_c = {slow['ratio']:.5f} at Ca = {slow['capillary_number']:g}; "
          f"fit 1 + {f['delta_0']:.2e} (sd {f['delta_0_sd']:.1e}) + {f['a']:.3g} "
          f"Ca^{f['b']:.3f}; through Ca = 1e-6 .. 1e-4: 1 + {f3['delta_0']:.2e} + "
          f"{f3['a']:.3g} Ca^{f3['b']:.3f}", flush=True)
    pre = presets(cache)
    for p in pre:
        c = p["case"]
        print(f"{c['kind']} Ca {c['capillary_number']:g}: "
              + ", ".join(f"{q['preset']} {q['error']:.2e} ({q['wall_time_s']:.0f} s)"
                          for q in p["presets"]), flush=True)
    force = force_presets()
    for q in force["presets"]:
        print(f"force, {q['preset']}: largest difference from accurate {max(q['error']):.1e} "
              f"({q['wall_time_s']:.0f} s)", flush=True)
    data = {"limit": lim, "presets": pre, "force": force,
            "conclusion": (f"at Ca = {slow['capillary_number']:g} the rupture distance is "
                           f"{slow['ratio']:.5f} S_c (goal: the static fold within 1e-3); "
                           f"the fitted Ca -> 0 limit is {1 + f['delta_0']:.5f} S_c (sd "
                           f"{f['delta_0_sd']:.1e}; {1 + f3['delta_0']:.5f} through the three "
                           "runs at Ca = 1e-6 .. 1e-4); presets (difference from the accurate "
                           "one, fast and default): "
                           + "; ".join(f"{p['case']['kind']} Ca {p['case']['capillary_number']:g}"
                                       f" {p['presets'][0]['error']:.1e} and "
                                       f"{p['presets'][1]['error']:.1e}" for p in pre)
                           + "; force at 0.03-0.11 R, Ca = 1e-2: default within "
                           f"{max(force['presets'][1]['error']):.1e} of accurate, fast "
                           f"{max(force['presets'][0]['error']):.1e}")}
    write_json("dynamic_rupture", data)
    chart(data)


def chart(data: dict) -> None:
    from wetcontact.plotting import pyplot, styles

    plt = pyplot()
    force = data.get("force")
    fig, axes = plt.subplots(1, 3 if force else 2, figsize=(16 if force else 11, 4.4),
                             layout="constrained")
    ax1, ax2 = axes[0], axes[1]
    lim = data["limit"]
    ca = np.array([r["case"]["capillary_number"] for r in lim["runs"]])
    ratio = np.array([r["ratio"] for r in lim["runs"]])
    f = lim["fit"]
    names = ["stokes-dynamic runs", "fit 1 + d0 + a Ca^b", "Pitois 2001, 1 + Ca^1/2"]
    st = styles(names + [f"{p['case']['kind']} Ca {p['case']['capillary_number']:g}"
                         for p in data["presets"]])
    cc = np.geomspace(ca.min(), ca.max(), 100)
    ax1.plot(ca, ratio - 1, ms=7, label=names[0], **{**st[names[0]], "linestyle": "none"})
    ax1.plot(cc, f["delta_0"] + f["a"] * cc ** f["b"], label=f"{names[1]}: d0 = "
             f"{f['delta_0']:.1e}, b = {f['b']:.3f}", **{**st[names[1]], "marker": None})
    if "fit_low" in lim:
        f3 = lim["fit_low"]
        ax1.plot(cc, f3["delta_0"] + f3["a"] * cc ** f3["b"], color="0.35", lw=1.0, ls=":",
                 label=f"the same through Ca = 1e-6 .. 1e-4: d0 = {f3['delta_0']:.1e}, b = "
                       f"{f3['b']:.3f}")
    ax1.plot(cc, np.sqrt(cc), label=names[2], **{**st[names[2]], "marker": None})
    ax1.axhline(1e-3, color="0.5", lw=0.8, ls=":")
    ax1.set_xscale("log")
    ax1.set_yscale("log")
    ax1.set_xlabel("Ca = eta v / sigma")
    ax1.set_ylabel("S_c(Ca)/S_c - 1")
    ax1.set_title("sphere on a wall, V/R^3 = 1e-3, 30 deg: the Ca -> 0 limit", fontsize=9)
    ax1.legend(fontsize=8)
    for p in data["presets"]:
        name = f"{p['case']['kind']} Ca {p['case']['capillary_number']:g}"
        t = [q["wall_time_s"] for q in p["presets"]]
        e = [max(q["error"], 1e-7) for q in p["presets"]]
        ax2.plot(t, e, label=name, **st[name])
        for k, (q, ti, ei) in enumerate(zip(p["presets"], t, e, strict=True)):
            ax2.annotate(q["preset"], (ti, ei), fontsize=7, xytext=(4, 4 - 12 * (k % 2)),
                         textcoords="offset points")
    from matplotlib.ticker import NullFormatter

    ax2.set_xscale("log")
    ax2.set_yscale("log")
    ax2.xaxis.set_minor_formatter(NullFormatter())
    ax2.set_xlabel("wall time of the run (s)")
    ax2.set_ylabel("|S_c(Ca) / S_c(Ca, accurate) - 1|\n(accurate: default's difference)")
    ax2.set_title("presets fast, default, accurate: V/R^3 = 1e-3, 30 deg", fontsize=9)
    ax2.legend(fontsize=8)
    ax2.grid(True, alpha=0.3)
    if force:
        ax3 = axes[2]
        fst = styles([f"force, {q['preset']}" for q in force["presets"][:2]])
        for q in force["presets"][:2]:
            name = f"force, {q['preset']}"
            ax3.plot(force["gaps_over_R"], np.maximum(q["error"], 1e-8),
                     label=f"{name} ({q['wall_time_s']:.0f} s)", **fst[name])
        ax3.axhline(1e-3, color="0.5", lw=0.8, ls=":")
        ax3.set_yscale("log")
        ax3.set_xlabel("S/R (static fold at 0.1104)")
        ax3.set_ylabel("|F / F(accurate) - 1|")
        ax3.set_title("force presets: wall, 20 deg, V/R^3 = 1e-3, Ca = 1e-2", fontsize=9)
        ax3.legend(fontsize=8)
        ax3.grid(True, alpha=0.3)
    fig.suptitle("Dynamic rupture distance (stokes-dynamic, bridge stretched from 0.2 S_c at "
                 "constant speed)", fontsize=10)
    save_chart(fig, "dynamic_rupture")


if __name__ == "__main__":
    main_or_chart("dynamic_rupture", main, chart)
