"""Cost of the division of the liquid at rupture (``meniscus``, ``transfer_fraction``).

For each configuration (sphere-wall; sphere pairs of radius ratio R2/R1 = 1, 10 and 0.1;
V/R_small^3 = 1e-4, 1e-2, 0.1; contact angles (theta1, theta2) = (0, 0), (20, 50), (70, 10)
deg; and equal spheres at 50/50 deg, where the branch ends at the symmetry-breaking
bifurcation) at the default preset (128 elements):

1. the wall time of :func:`~wetcontact.solver.meniscus.division.transfer_fraction` (the
   branch from contact to rupture, then the cut), median of 5 runs after one warm-up;
2. the wall time of the cut alone (:func:`divide_branch` on a computed branch), median of 20;
3. the fraction beside the published rules (reduced_models/division.py: even split,
   MercuryDPM, Shi & McCarthy read backwards), for orientation (the report's table of their
   errors is not made here);
4. the cusp of the fraction near symmetry: equal spheres, theta2 = 35 deg, theta1 scanned
   over 0-70 deg (V/R^3 = 10^-2.5): ``f - 1/2 ~ sign(eps) |eps|^(1/3)``;
5. the per-point cost of the calibrated closure
   (:func:`~wetcontact.reduced_models.transfer_fraction.calibrated_transfer_fraction`, one
   vectorised call on N seeded points over its domain, N = 1e3, 1e4, 1e5): median of 7 runs
   after one warm-up, divided by N. ``--closure`` measures only this and keeps the rest of
   the JSON.

Writes ``benchmarks/results/division.json`` and ``division.png``. Run:
``.venv/bin/python benchmarks/bench_division.py`` (``--chart`` redraws from the JSON).
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

# one BLAS thread (before numpy loads): the closure's matrix products on two threads, with
# the other core busy, ran five times slower than on one
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import main_or_chart, median_time, save_chart, write_json  # noqa: E402

from wetcontact.reduced_models.division import (  # noqa: E402
    calibrated_transfer_fraction,
    even_split_fraction,
    mercurydpm_fraction,
    shi_mccarthy_fraction,
)
from wetcontact.solver.meniscus.division import divide_branch, transfer_fraction  # noqa: E402
from wetcontact.solver.meniscus.geometry import DEFAULT_ELEMENTS, Bridge  # noqa: E402
from wetcontact.solver.meniscus.solve import _branch_for  # noqa: E402

KINDS = {"wall": None, "pair 1": 1.0, "pair 10": 10.0, "pair 0.1": 0.1}
VOLUMES = (1e-4, 1e-2, 0.1)
ANGLES = ((0.0, 0.0), (20.0, 50.0), (70.0, 10.0))


def bridge(r2: float | None, th1: float, th2: float) -> Bridge:
    return Bridge(radius=1.0, radius2=r2, contact_angle1=math.radians(th1),
                  contact_angle2=math.radians(th2), surface_tension=1.0)


def configurations() -> list[tuple[str, float | None, float, float, float]]:
    out = [(k, r2, v, th1, th2) for k, r2 in KINDS.items() for v in VOLUMES
           for th1, th2 in ANGLES]
    out.append(("pair 1", 1.0, 10**-2.5, 50.0, 50.0))  # the bifurcation end
    return out


def closure_cost(sizes: tuple[int, ...] = (1000, 10_000, 100_000)) -> dict:
    """Per-point wall time of the calibrated closure, one vectorised call per size."""
    rng = np.random.default_rng(56)
    out = {}
    for n in sizes:
        r1 = np.full(n, 1e-3)
        r2 = 1e-3 * np.exp(rng.uniform(0.0, math.log(10.0), n))
        r2[: n // 4] = np.inf  # a quarter on a wall
        v = 1e-9 * np.exp(rng.uniform(math.log(1e-4), math.log(0.1), n))
        t1, t2 = rng.uniform(0, 70, n), rng.uniform(0, 70, n)
        args = (r1, r2, v, t1, t2)
        med, f = median_time(lambda args=args: calibrated_transfer_fraction(*args),
                             repeats=7)
        out[str(n)] = {"median_s": med, "per_point_us": 1e6 * med / n,
                       "nan_fraction": float(np.mean(np.isnan(f)))}
        print(f"closure: {n} points, {1e6 * med / n:.3f} us a point", flush=True)
    c = c_cost()
    if c is not None:
        out["c_per_call_us"] = c
        print(f"closure in C: {c:.3f} us a call", flush=True)
    return out


C_MAIN = r"""
int main(void)
{
    const int n = 200000;
    double acc = 0.0, r2;
    clock_t c0 = clock();
    int i;
    for (i = 0; i < n; ++i) {
        r2 = (i % 4 == 0) ? INFINITY : 1e-3 * exp(2.302585092994046 * FRAC(i * 0.6180339887));
        acc += wc_transfer_fraction(1e-3, r2, 1e-13 * exp(6.907755278982137
                                    * FRAC(i * 0.4142135623730951)),
                                    70.0 * FRAC(i * 0.7320508075688772),
                                    70.0 * FRAC(i * 0.2360679774997897));
    }
    printf("%.6g %.17g\n", (double)(clock() - c0) / CLOCKS_PER_SEC / n, acc);
    return 0;
}
"""


def c_cost() -> float | None:
    """Median CPU time of one ``wc_transfer_fraction`` call (us), ``cc -O2``, 2e5 calls over
    the domain (every input varying, a quarter on a wall; NaN in the band kept), 3 runs;
    None without a C compiler."""
    import shutil
    import subprocess
    import tempfile

    from wetcontact.export.transfer_fraction import c_text

    cc = shutil.which("cc")
    if cc is None:
        return None
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "tf.c"
        src.write_text("#include <math.h>\n#include <stdio.h>\n#include <time.h>\n"
                       "#define WC_PI 3.14159265358979323846\n"
                       "#define FRAC(x) ((x) - floor(x))\n" + c_text() + C_MAIN)
        exe = Path(tmp) / "tf"
        subprocess.run([cc, "-std=c99", "-O2", "-o", str(exe), str(src), "-lm"], check=True)
        runs = [float(subprocess.run([str(exe)], check=True, capture_output=True,
                                     text=True).stdout.split()[0]) for _ in range(3)]
    return 1e6 * float(np.median(runs))


def closure_only() -> None:
    """Measure the closure's cost and keep the rest of the stored JSON."""
    from _common import RESULTS

    data = json.loads((RESULTS / "division.json").read_text())
    data.pop("machine", None)
    data.pop("cpu_count", None)
    data["closure_cost"] = closure_cost()
    write_json("division", data)


def main() -> None:
    if "--closure" in sys.argv:
        closure_only()
        return
    t0 = time.perf_counter()
    rows = []
    for kind, r2, v_star, th1, th2 in configurations():
        small = 1.0 if r2 is None else min(1.0, r2)
        V = v_star * small**3
        b = bridge(r2, th1, th2)
        med, div = median_time(lambda b=b, V=V: transfer_fraction(b, V), repeats=5)
        br, ell = _branch_for(b, V, DEFAULT_ELEMENTS)
        cut, _ = median_time(lambda br=br, ell=ell: divide_branch(br, ell), repeats=20)
        rules = {"even_split": float(even_split_fraction(1.0, r2)),
                 "mercurydpm": float(mercurydpm_fraction(1.0, r2)),
                 "shi_mccarthy": float(shi_mccarthy_fraction(1.0, r2))}
        rows.append({"kind": kind, "radius_ratio": r2, "v_star": v_star, "theta1_deg": th1,
                     "theta2_deg": th2, "fraction": div.fraction, "neck": div.neck,
                     "end": div.end, "time_s": med, "cut_time_s": cut,
                     "continuation_points": len(br.xs), "rules": rules})
        print(f"{kind:8s} V* {v_star:.0e} theta {th1:4.0f}/{th2:4.0f}: f {div.fraction:.6f} "
              f"({div.end}), {med * 1e3:7.1f} ms, cut {cut * 1e3:.2f} ms", flush=True)
    scan = np.linspace(0.0, 70.0, 29)
    v0 = 10**-2.5
    cusp = [transfer_fraction(bridge(1.0, float(t), 35.0), v0).fraction for t in scan]
    times = np.array([r["time_s"] for r in rows])
    data = {"n_elements": DEFAULT_ELEMENTS, "preset": "default", "rows": rows,
            "time_s": {"median": float(np.median(times)), "min": float(times.min()),
                       "max": float(times.max())},
            "cut_time_s_median": float(np.median([r["cut_time_s"] for r in rows])),
            "cusp_scan": {"radius_ratio": 1.0, "v_star": v0, "theta2_deg": 35.0,
                          "theta1_deg": scan.tolist(), "fraction": cusp},
            "closure_cost": closure_cost(),
            "wall_time_s": round(time.perf_counter() - t0, 1),
            "note": "timings on 2 cores shared with other jobs (loaded); one process, "
                    "one BLAS thread not enforced"}
    write_json("division", data)
    chart(data)
    print(f"transfer_fraction at the default preset: median {np.median(times) * 1e3:.0f} ms "
          f"({times.min() * 1e3:.0f}-{times.max() * 1e3:.0f} ms) per configuration; the cut "
          f"alone {data['cut_time_s_median'] * 1e3:.2f} ms")


def chart(data: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = data["rows"]
    fig, ax = plt.subplots(1, 2, figsize=(14, 5.2), gridspec_kw={"width_ratios": [1.6, 1]})
    labels = [f"{r['kind']}, {r['v_star']:.0e}, {r['theta1_deg']:.0f}/{r['theta2_deg']:.0f}"
              for r in rows]
    kinds = list(dict.fromkeys(r["kind"] for r in rows))
    colours = [f"C{kinds.index(r['kind'])}" for r in rows]
    y = np.arange(len(rows))
    ax[0].barh(y, [1e3 * r["time_s"] for r in rows], color=colours, edgecolor="k",
               hatch=["//" if r["end"] == "bifurcation" else "" for r in rows])
    for k, r in enumerate(rows):
        ax[0].text(1e3 * r["time_s"], k, f" f = {r['fraction']:.3f}", va="center", fontsize=6)
    ax[0].set_yticks(y, labels, fontsize=6)
    ax[0].invert_yaxis()
    ax[0].set_xscale("log")
    ax[0].set_xlabel("wall time of transfer_fraction (ms), median of 5")
    med = data["time_s"]["median"]
    ax[0].set_title(f"meniscus at the default preset ({data['n_elements']} elements): median "
                    f"{1e3 * med:.0f} ms a configuration\n(hatched: bifurcation end; the cut "
                    f"alone {1e3 * data['cut_time_s_median']:.2f} ms)", fontsize=9)
    c = data["cusp_scan"]
    ax[1].plot(c["theta1_deg"], c["fraction"], "o-", ms=3, label="meniscus (FE, cut at neck)")
    ax[1].axhline(0.5, color="gray", ls="--", lw=0.8,
                  label="even split (Yade, LIGGGHTS, MercuryDPM pairs)")
    ax[1].axvline(c["theta2_deg"], color="gray", ls=":", lw=0.8)
    ax[1].set_xlabel("$\\theta_1$ (deg), sphere 1")
    ax[1].set_ylabel("fraction kept by sphere 1")
    ax[1].set_title(f"Equal spheres, $\\theta_2$ = {c['theta2_deg']:.0f} deg, V/R$^3$ = "
                    "10$^{-2.5}$:\nthe division depends on the angle difference, with a "
                    "cusp at 0", fontsize=9)
    ax[1].legend(fontsize=7)
    save_chart(fig, "division")


if __name__ == "__main__":
    main_or_chart("division", main, chart)
