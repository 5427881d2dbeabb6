"""Rupture of a volume-controlled bridge: fold or symmetry-breaking bifurcation.

Between equal spheres with equal contact angles the symmetric bridge can lose stability to
an up-down asymmetric mode (det J of the fixed-volume, fixed-gap system changes sign with S
still increasing; Maddocks 1987) before the fold of its branch. ``meniscus`` ruptures the
bridge at the first loss of stability; the literature's rupture distances of symmetric
solutions (e.g. Lian et al. 1993) are the fold. This benchmark measures

1. equal spheres, V/R^3 in {1e-4, 1e-3, 1e-2, 1e-1}, theta 0-70 deg: the rupture distance
   at the first loss of stability against the fold of the symmetric branch, and Lian's
   ``(1 + theta/2) V^(1/3)``;
2. the unfolding: theta1 = theta2 + eps turns the bifurcation into a fold at
   ``S_b - c eps^(2/3)``, so the rupture distance has a cusp along theta1 = theta2 (and
   near it for unequal radii, and for a sphere on a wall where no symmetry exists but the
   same cusp appears at theta1 about theta2 - 3 deg): a smooth closure cannot follow it;
3. the cost of a rupture search (median of 3) with and without the stability check.

Writes ``benchmarks/results/meniscus_rupture.json`` and ``meniscus_rupture.png``. Run:
``.venv/bin/python benchmarks/bench_meniscus_rupture.py`` (``--plot-only`` redraws the chart
from the JSON).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import RESULTS, median_time, write_json  # noqa: E402

from wetcontact.solver.meniscus.continuation import _branch  # noqa: E402
from wetcontact.solver.meniscus.geometry import Bridge  # noqa: E402
from wetcontact.solver.meniscus.solve import _prep  # noqa: E402

N_EL = 128
VOLUMES = (1e-4, 1e-3, 1e-2, 1e-1)
THETAS = (0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0)


def rupture(r2: float | None, th1: float, th2: float, v: float,
            bifurcations: bool = True) -> tuple[float, str]:
    """Rupture distance S_c/R1 (R1 = 1) and how the stable branch ends."""
    b = Bridge(radius=1.0, radius2=r2, contact_angle1=math.radians(th1),
               contact_angle2=math.radians(th2), surface_tension=1.0)
    d, g, _ = _prep(b, v, N_EL)
    br = _branch(d, g, v, bifurcations=bifurcations)
    return br.S_fold, br.end


def main() -> None:
    t0 = time.perf_counter()
    equal = []
    for v in VOLUMES:
        for th in THETAS:
            s_b, end = rupture(1.0, th, th, v)
            s_f, _ = rupture(1.0, th, th, v, bifurcations=False)
            lian = (1 + 0.5 * math.radians(th)) * v ** (1 / 3)
            equal.append({"v_star": v, "theta_deg": th, "rupture": s_b, "end": end,
                          "fold_of_symmetric_branch": s_f, "fold_over_rupture": s_f / s_b,
                          "lian": lian})
            print(f"V* {v:.0e} theta {th:4.0f}: S_c {s_b:.6f} ({end}), fold {s_f:.6f} "
                  f"(+{100 * (s_f / s_b - 1):.2f} %)", flush=True)
    v0 = 10**-2.5
    eps = np.array([0.125, 0.25, 0.5, 1.0, 2.0, 4.0])
    s_b = rupture(1.0, 50.0, 50.0, v0)[0]
    unfold = [rupture(1.0, 50.0 + e, 50.0, v0)[0] for e in eps]
    slope = float(np.polyfit(np.log(eps[:4]), np.log(s_b - np.array(unfold[:4])), 1)[0])
    scan_t1 = np.linspace(0.0, 70.0, 29)
    cusp = {}
    for label, r2 in (("equal spheres", 1.0), ("sphere-wall", None)):
        cusp[label] = [rupture(r2, float(t), 35.0, v0)[0] for t in scan_t1]
    cost = {}
    for label, flag in (("with stability check", True), ("fold only", False)):
        for th in (20.0, 50.0):
            med, _ = median_time(lambda th=th, flag=flag: rupture(1.0, th, th, v0, flag),
                                 repeats=3)
            cost[f"{label}, theta {th:.0f}"] = med
    data = {"n_elements": N_EL, "equal_spheres": equal,
            "unfolding": {"v_star": v0, "theta2_deg": 50.0, "eps_deg": eps.tolist(),
                          "rupture_bifurcation": s_b, "folds": unfold,
                          "log_log_slope": slope, "expected_slope": 2 / 3},
            "cusp_scan": {"v_star": v0, "theta2_deg": 35.0, "theta1_deg": scan_t1.tolist(),
                          **cusp},
            "cost_s": cost, "wall_time_s": round(time.perf_counter() - t0, 1),
            "note": "timings on 2 cores shared with other jobs (loaded)"}
    write_json("meniscus_rupture", data)
    plot(data)
    print(f"unfolding slope {slope:.4f} (2/3 expected); cost {cost}")


def plot(data: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6))
    styles = ["-", "--", "-.", ":"]
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for k, v in enumerate(VOLUMES):
        rows = [r for r in data["equal_spheres"] if r["v_star"] == v]
        th = [r["theta_deg"] for r in rows]
        ax[0].plot(th, [100 * (r["fold_over_rupture"] - 1) for r in rows], styles[k],
                   color=colours[k], marker="o", label=f"V/R$^3$ = {v:.0e}")
    ax[0].set_xlabel("contact angle (deg), both spheres")
    ax[0].set_ylabel("fold beyond the loss of stability (%)")
    ax[0].set_title("Equal spheres: the symmetric fold\nis not the rupture for larger angles")
    ax[0].legend()
    u = data["unfolding"]
    e = np.array(u["eps_deg"])
    ax[1].loglog(e, u["rupture_bifurcation"] - np.array(u["folds"]), "o-", color="tab:blue",
                 label="$S_b - S_{fold}(\\epsilon)$")
    ax[1].loglog(e, (u["rupture_bifurcation"] - u["folds"][2]) * (e / e[2]) ** (2 / 3), "--",
                 color="tab:gray", label="slope 2/3")
    ax[1].set_xticks(e, [f"{x:g}" for x in e])
    ax[1].xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax[1].set_xlabel("$\\epsilon = \\theta_1 - \\theta_2$ (deg)")
    ax[1].set_ylabel("$(S_b - S_c)/R$")
    ax[1].set_title(f"Unfolding, equal spheres, V/R$^3$ = 10$^{{-2.5}}$, "
                    f"$\\theta_2$ = 50 deg\nslope {u['log_log_slope']:.3f}")
    ax[1].legend()
    c = data["cusp_scan"]
    for (label, ls, col) in (("equal spheres", "-", "tab:blue"),
                             ("sphere-wall", "--", "tab:orange")):
        ax[2].plot(c["theta1_deg"], c[label], ls, color=col, marker=".", label=label)
    ax[2].axvline(35.0, color="gray", lw=0.8, ls=":")
    ax[2].set_xlabel("$\\theta_1$ (deg), sphere 1")
    ax[2].set_ylabel("rupture distance $S_c/R_1$")
    ax[2].set_title("Cusp of $S_c$ near $\\theta_1 = \\theta_2$\n"
                    "V/R$^3$ = 10$^{-2.5}$, $\\theta_2$ = 35 deg")
    ax[2].legend()
    fig.tight_layout()
    fig.savefig(RESULTS / "meniscus_rupture.png", dpi=110)


if __name__ == "__main__":
    if "--plot-only" in sys.argv:  # redraw from the saved JSON
        import json

        plot(json.loads((RESULTS / "meniscus_rupture.json").read_text()))
    else:
        main()
