"""Work-precision of the axisymmetric Stokes FEM (model ``stokes``) against Brenner's series.

Writes ``benchmarks/results/stokes.json`` and ``stokes.png``:

* ``work_precision``: for S/R = 1e-3, 1e-2, 0.1, 1 and five mesh levels (``coarse``, the
  presets ``fast``, ``default``, ``accurate``, and ``fine``), the relative error of the force
  against Brenner (1961) and the wall time of one ``model.force`` call: median of
  ``--repeats`` warm calls (mesh cached, as in a sweep) and the first, cold call (gmsh
  meshing included);
* ``acceptance``: relative errors of the presets ``fast`` and ``accurate`` for
  S/R in {1e-4, 1e-3, 1e-2, 0.1, 1, 10}: sphere-wall against Brenner, two equal spheres
  (symmetry half domain and full mesh) against the two-sphere series, with times;
* ``isolated``: the isolated sphere against 6 pi eta R v (container factor applied).

``--part slip`` (kept in the same JSON, other sections untouched; chart ``stokes_slip.png``):

* ``slip_study``: sphere-wall at S/R = 1e-2 and 1e-3, slip length b/S from 1e-2 to 1e2 on both
  surfaces and on the wall only: F/F(b = 0) against Vinogradova's (1995) factor f*(S, b), and
  the time per gap;
* ``basset_order``: an isolated slipping sphere (b = R) under uniform refinement against
  Basset's drag, with the observed order;
* ``unequal``: two unequal spheres (R2/R = 0.5, 2, 5) from S/R = 1e-3 to 1: the remainder
  after Jeffrey & Onishi's singular terms and the cost per gap (cold: meshing included).

Run: ``python benchmarks/bench_stokes.py [--quick] [--repeats N] [--part all|slip]``. The
machine is shared: timings are noisy, the median damps that.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, median_time, write_json  # noqa: E402

from wetcontact.meshes.builders import Resolution  # noqa: E402
from wetcontact.meshes.cache import get_mesh  # noqa: E402
from wetcontact.models import get_model, provenance  # noqa: E402
from wetcontact.reduced_models.viscous import brenner_lambda, two_sphere_lambda  # noqa: E402
from wetcontact.scene import scene_from_dict  # noqa: E402
from wetcontact.solver.stokes import Stokes, container_factor, solve_stokes  # noqa: E402

R, ETA, V = 1.0e-3, 1.0e-3, 0.1
LEVELS = {
    "coarse": {"n_gap": 2, "h_sphere": 0.12, "growth": 0.4, "far": 1.0e3, "n_film": 3},
    **Stokes.presets,
    "fine": {"n_gap": 10, "h_sphere": 0.015, "growth": 0.06, "far": 1.0e3, "n_film": 10},
}


def scene(kind: str, s: float):
    return scene_from_dict({
        "name": f"bench-{kind}-{s:g}", "geometry": {"kind": kind, "radius": R},
        "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0},
        "amount": {"immersed": True}, "motion": {"velocity": V, "gaps": [s * R]}})


def exact(kind: str, s: float) -> float:
    if kind == "sphere-wall":
        return 6 * math.pi * ETA * R * V * float(brenner_lambda(s))
    return 6 * math.pi * ETA * R * (V / 2) * float(two_sphere_lambda(s))


def run_one(kind: str, s: float, level: dict, repeats: int, method: str = "symmetry") -> dict:
    model = get_model("stokes")
    sc = scene(kind, s)
    t0 = time.perf_counter()
    curve = model.force(sc, preset="default", method=method, **level)
    cold = time.perf_counter() - t0
    warm, curve = median_time(lambda: model.force(sc, preset="default", method=method, **level),
                              repeats=repeats, warmup=0)
    ref = exact(kind, s)
    return {"kind": kind, "method": method, "s_over_r": s,
            "error": float(curve.force_viscous[0] / ref - 1),
            "error_traction": float(curve.extras["force_traction"][0] / ref - 1),
            "time_s": warm, "time_cold_s": cold, "dofs": curve.diagnostics["dofs"][0],
            "elements": curve.diagnostics["elements"][0]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two gaps, three levels, 2 repeats")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--part", choices=("all", "slip"), default="all",
                    help="'slip': only the slip, Basset and unequal-sphere sections")
    args = ap.parse_args()
    repeats = 2 if args.quick else args.repeats
    if args.part == "slip":
        slip_part(args.quick, repeats)
        return
    gaps = [1e-3, 0.1] if args.quick else [1e-3, 1e-2, 0.1, 1.0]
    levels = (["coarse", "fast", "default"] if args.quick else list(LEVELS))
    import os

    os.environ.setdefault("WETCONTACT_CACHE", tempfile.mkdtemp(prefix="wetcontact-bench-"))

    wp = []
    for s in gaps:
        for name in levels:
            row = {"level": name, **run_one("sphere-wall", s, LEVELS[name], repeats)}
            wp.append(row)
            print(f"S/R={s:g} {name:9s} err={row['error']:+.2e} t={row['time_s']:.3f}s "
                  f"(cold {row['time_cold_s']:.2f}s) dofs={row['dofs']}", flush=True)

    acc = []
    acc_gaps = [1e-3, 0.1] if args.quick else [1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0]
    for preset in ("fast", "accurate"):
        for kind, method in (("sphere-wall", "symmetry"), ("sphere-sphere", "symmetry"),
                             ("sphere-sphere", "full")):
            for s in acc_gaps:
                row = {"preset": preset, **run_one(kind, s, Stokes.presets[preset],
                                                   max(1, repeats // 2 + 1), method)}
                acc.append(row)
                print(f"{preset:8s} {kind:13s} {method:8s} S/R={s:g} err={row['error']:+.2e} "
                      f"t={row['time_s']:.3f}s", flush=True)

    res = Resolution(h_sphere=0.05, growth=0.15, far=1.0e4)
    sol = solve_stokes(get_mesh("isolated_sphere", res=res), {"sphere": -1.0})
    k = container_factor(1.0 / res.far)
    isolated = {"far_over_r": res.far, "container_factor": k,
                "error_uncorrected": sol.force_reaction / (6 * math.pi) - 1,
                "error_corrected": sol.force_reaction / (6 * math.pi * k) - 1,
                "error_traction_corrected": sol.force_traction / (6 * math.pi * k) - 1}
    print("isolated", isolated, flush=True)

    path = write_json("stokes", {"benchmark": "stokes", "repeats": repeats,
                                 "levels": {k: LEVELS[k] for k in levels},
                                 "work_precision": wp, "acceptance": acc,
                                 "isolated": isolated, "provenance": provenance(),
                                 "note": "shared 2-core machine: timings noisy"})
    plot(wp, RESULTS / "stokes.png")
    print("wrote", path)


def slip_scene(s: float, b_sphere: float, b_wall: float, kind: str = "sphere-wall",
               radius2: float | None = None):
    geo = {"kind": kind, "radius": R} | ({"radius2": radius2 * R} if radius2 else {})
    return scene_from_dict({
        "name": "bench-slip", "geometry": geo, "amount": {"immersed": True},
        "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0,
                   "slip_length_sphere": b_sphere * R, "slip_length_wall": b_wall * R},
        "motion": {"velocity": V, "gaps": [s * R]}})


def jeffrey_onishi(beta: float, xi: float) -> float:
    """Singular terms of X11A (Jeffrey & Onishi 1984): g1/xi + g2 ln(1/xi) + g3 xi ln(1/xi)."""
    g1 = 2 * beta**2 / (1 + beta) ** 3
    g2 = beta * (1 + 7 * beta + beta**2) / (5 * (1 + beta) ** 3)
    g3 = (1 + 18 * beta - 29 * beta**2 + 18 * beta**3 + beta**4) / (42 * (1 + beta) ** 3)
    return g1 / xi + (g2 + g3 * xi) * math.log(1 / xi)


def slip_part(quick: bool, repeats: int) -> None:
    """Slip-length study, Basset refinement and unequal spheres, merged into stokes.json."""
    import json
    import os

    from wetcontact.models import observed_order
    from wetcontact.reduced_models.viscous import slip_factor

    os.environ.setdefault("WETCONTACT_CACHE", tempfile.mkdtemp(prefix="wetcontact-bench-"))
    model = get_model("stokes")
    presets = ["fast"] if quick else ["fast", "default"]
    ratios = [1e-2, 1.0, 1e2] if quick else [1e-2, 1e-1, 0.3, 1.0, 3.0, 10.0, 1e2]
    study = []
    for preset in presets:
        for s in ([1e-2] if quick else [1e-2, 1e-3]):
            f0 = model.force(slip_scene(s, 0, 0), preset=preset).force_viscous[0]
            for both in (True, False):
                for q in ratios:
                    b = q * s
                    sc = slip_scene(s, b if both else 0.0, b)
                    t, c = median_time(lambda sc=sc, p=preset: model.force(sc, preset=p),
                                       repeats=max(1, repeats // 2), warmup=1)
                    fstar = float(slip_factor(s, b, 2 if both else 1))
                    row = {"preset": preset, "s_over_r": s, "b_over_s": q,
                           "surfaces": 2 if both else 1, "f_over_noslip": c.force_viscous[0] / f0,
                           "vinogradova": fstar,
                           "deviation": c.force_viscous[0] / f0 / fstar - 1, "time_s": t}
                    study.append(row)
                    print(f"slip {preset} S/R={s:g} b/S={q:g} n={row['surfaces']} "
                          f"F/F0={row['f_over_noslip']:.4f} f*={fstar:.4f} t={t:.2f}s", flush=True)

    basset = []
    for f in ([1.0, 2.0] if quick else [1.0, 1.5, 2.0, 3.0]):
        res = Resolution(h_sphere=0.2 / f, growth=0.6 / f, far=1.0e4)
        sol = solve_stokes(get_mesh("isolated_sphere", res=res), {"sphere": -1.0},
                           slip={"sphere": 1.0})
        lam = 3.0 / 4.0
        k = 1 + 2.25 * lam / res.far
        basset.append({"h": 0.2 / f, "dofs": sol.ndofs,
                       "error": sol.force_reaction / (6 * math.pi * lam * k) - 1})
        print("basset", basset[-1], flush=True)
    order = observed_order([r["h"] for r in basset], [r["error"] for r in basset])

    unequal = []
    for beta in ([2.0] if quick else [0.5, 2.0, 5.0]):
        for s in ([1e-3, 0.1] if quick else [1e-3, 1e-2, 0.1, 1.0]):
            for preset in presets:
                sc = slip_scene(s, 0, 0, kind="sphere-sphere", radius2=beta)
                t0 = time.perf_counter()
                model.force(sc, preset=preset)
                cold = time.perf_counter() - t0
                t, c = median_time(lambda sc=sc, p=preset: model.force(sc, preset=p),
                                   repeats=max(1, repeats // 2), warmup=0)
                xi = 2 * s / (1 + beta)
                f = c.force_viscous[0] / (6 * math.pi * ETA * R * V)
                row = {"beta": beta, "s_over_r": s, "preset": preset, "f_over_6pi": f,
                       "jo_remainder": f - jeffrey_onishi(beta, xi), "time_s": t,
                       "time_cold_s": cold, "dofs": c.diagnostics["dofs"][0]}
                unequal.append(row)
                print(f"unequal beta={beta:g} S/R={s:g} {preset} rest={row['jo_remainder']:.4f}"
                      f" t={t:.2f}s cold={cold:.2f}s", flush=True)

    path = RESULTS / "stokes.json"
    data = json.loads(path.read_text()) if path.exists() else {"benchmark": "stokes"}
    data.update({"slip_study": study, "basset_order": {"rows": basset, "observed_order": order},
                 "unequal": unequal, "slip_note": "shared 2-core machine under heavy load "
                 "(7 helpers): timings noisy, medians of few repeats", "slip_quick": quick})
    write_json("stokes", data)
    plot_slip(study, RESULTS / "stokes_slip.png")
    print("observed order (Basset, slip b = R):", order)


def plot_slip(study: list[dict], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.2))
    pre = "default" if any(r["preset"] == "default" for r in study) else "fast"
    for s in sorted({r["s_over_r"] for r in study}):
        for n, mk in ((2, "o"), (1, "s")):
            rows = [r for r in study if r["s_over_r"] == s and r["surfaces"] == n
                    and r["preset"] == pre]
            x = [r["b_over_s"] for r in rows]
            ax.semilogx(x, [r["f_over_noslip"] for r in rows], mk,
                        label=f"FEM S/R = {s:g}, slip on {n}")
            if s == min(r["s_over_r"] for r in study):
                ax.semilogx(x, [r["vinogradova"] for r in rows], "k-", lw=0.8,
                            label="Vinogradova f*" if n == 2 else None)
    ax.set_xlabel("slip length b / S")
    ax.set_ylabel("F / F(no slip)")
    ax.set_title(f"Navier slip, sphere-wall (preset {pre})")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot(wp: list[dict], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.2))
    for s in sorted({r["s_over_r"] for r in wp}):
        rows = [r for r in wp if r["s_over_r"] == s]
        ax.loglog([r["time_s"] for r in rows], [abs(r["error"]) for r in rows], "o-",
                  label=f"S/R = {s:g}")
        for r in rows:
            ax.annotate(r["level"], (r["time_s"], abs(r["error"])), fontsize=6)
    ax.axhline(1e-5, color="k", lw=0.5, ls="--")
    ax.axhline(1e-3, color="k", lw=0.5, ls=":")
    ax.set_xlabel("wall time per configuration (s, median, mesh cached)")
    ax.set_ylabel("|F / F_Brenner - 1|")
    ax.set_title("Stokes FEM (P2/P1, axisymmetric): work-precision")
    ax.legend(fontsize=8)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
