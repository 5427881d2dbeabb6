"""Lubrication model: time per gap, a batched 1000-gap curve, and error against time.

Writes ``benchmarks/results/lubrication.json`` and ``lubrication.png``. Run:
``/work/venv/bin/python benchmarks/bench_lubrication.py``. Timings are medians of a few
runs on a shared machine: read them as orders of magnitude.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, main_or_chart, median_time, write_json  # noqa: E402

from wetcontact.models import load_all  # noqa: E402
from wetcontact.scene import scene_from_dict  # noqa: E402
from wetcontact.solver.lubrication import GapProfile, quadrature_force  # noqa: E402

R, ETA, V, DELTA = 1.0e-3, 1.0e-3, 0.1, 1.0e-4


def scene(gaps: list[float]):
    return scene_from_dict({
        "name": "bench-lubrication",
        "geometry": {"kind": "sphere-wall", "radius": R},
        "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0},
        "amount": {"film_thickness": DELTA},
        "motion": {"velocity": V, "gaps": gaps},
    })


def main() -> None:
    model = load_all()["lubrication"]
    one = scene([1e-6])
    t_gap, _ = median_time(lambda: model.force(one), repeats=21, warmup=3)
    gaps = np.geomspace(1e-7, 9e-5, 1000).tolist()
    curve_scene = scene(gaps)
    t_curve, curve = median_time(lambda: model.force(curve_scene), repeats=5, warmup=1)

    # reference by adaptive quadrature for a few gaps of the curve
    picks = [0, 333, 666, 999]
    refs = []
    for i in picks:
        prof = GapProfile.sphere_wall(gaps[i], R)
        rw = math.sqrt(prof.xi_of_edge_gap(np.array([DELTA]))[0])
        refs.append(quadrature_force(prof.h, rw, ETA, V, math.sqrt(2 * R * gaps[i])))
    curve_err = max(abs(curve.force_viscous[i] / r - 1) for i, r in zip(picks, refs, strict=True))

    # error against time at several resolutions (S/R = 1e-3, delta/R = 0.1: hardest range)
    gap = 1e-6
    prof = GapProfile.sphere_wall(gap, R)
    rw = math.sqrt(prof.xi_of_edge_gap(np.array([DELTA]))[0])
    ref = quadrature_force(prof.h, rw, ETA, V, math.sqrt(2 * R * gap))
    sweep = []
    for levels in (1, 2, 3):
        for n in (8, 16, 32, 48, 64, 128, 256):
            t, c = median_time(lambda n=n, levels=levels: model.force(one, n=n, levels=levels),
                               repeats=7, warmup=1)
            err = abs(c.force_viscous[0] / ref - 1)
            sweep.append({"levels": levels, "n": n, "time_s": t, "rel_error": err})
    data = {
        "model": "lubrication",
        "case": "sphere-wall, exact gap, film delta/R = 0.1, no slip, approach",
        "preset": "default (n=48, levels=3, order 6)",
        "time_per_gap_s": t_gap,
        "curve_1000_gaps_s": t_curve,
        "curve_max_rel_error_vs_quadrature": curve_err,
        "single_gap_rel_error_vs_quadrature": abs(model.force(one).force_viscous[0] / ref - 1),
        "error_vs_time": sweep,
        "note": "median wall times on 2 shared cores; noisy",
    }
    path = write_json("lubrication", data)
    _chart(sweep, RESULTS / "lubrication.png")
    print(f"wrote {path}: {t_gap * 1e3:.3f} ms/gap, {t_curve:.3f} s per 1000-gap curve, "
          f"curve error {curve_err:.2e}")


def _chart(sweep: list[dict], path: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(5, 4))
    for levels, mark in zip((1, 2, 3), ("o-", "s--", "^-."), strict=True):
        pts = [s for s in sweep if s["levels"] == levels]
        ax.loglog([p["time_s"] for p in pts], [max(p["rel_error"], 1e-16) for p in pts], mark,
                  label=f"levels={levels} (order {2 * levels})")
        for p in pts[::2]:  # n, the radial cells, at every other point
            ax.annotate(f"{p['n']}", (p["time_s"], max(p["rel_error"], 1e-16)), fontsize=6,
                        textcoords="offset points", xytext=(3, 3))
    ax.set_xlabel("wall time per gap (s)")
    ax.set_ylabel("relative error vs quadrature (labels: n)")
    ax.set_title("lubrication, sphere-wall film delta/R = 0.1,\nS/R = 1e-3: work-precision",
                 fontsize=10)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main_or_chart("lubrication", main,
                  lambda d: _chart(d["error_vs_time"], RESULTS / "lubrication.png"))
