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

``--part bridge`` (kept in the same JSON; chart ``stokes_bridge.png``), quasi-static liquid
bridges (theta = 20 deg on both solids, slip 1 nm = 1e-6 R on both, R = 1 mm):

* ``bridge_cost``: every preset, sphere-wall and two equal spheres, S/R = 1e-3 and 1e-2:
  wall time of one gap (three meniscus solves, gmsh meshing and the Stokes solve: every
  bridge mesh is new), dofs, and the difference from ``accurate``;
* ``film_cost``: the flat-top film domain at every preset, cold (meshing included), with the
  difference from ``accurate`` (also alone: ``--part film``);
* ``bridge_vs_lubrication``: V/R^3 in {1e-4, 1e-3, 1e-2} and S/R from 1e-4 to 3e-2 at the
  default preset: F_stokes over the Reynolds force of the same wetted radius (the sphere's
  contact radius, pressure released there, same slip), over the ``lubrication`` model
  (wetted radius from the volume) and over ``reynolds-finite`` (Pitois' factor), and the
  Huh-Scriven contact-line slope of each bridge;
* ``bridge_slip``: S/R = 1e-3 and 1e-2, V/R^3 = 1e-3, b/R from 1e-3 to 1e-7 on both solids:
  F - F_lub against ln(1/b) and its slope against the Huh-Scriven / Cox prediction.

Run: ``python benchmarks/bench_stokes.py [--quick] [--repeats N] [--part all|slip|bridge|cost|film]
[--amount all|bridge|film]``.
The machine is shared: timings are noisy, the median damps that.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402
from _common import RESULTS, median_time, write_json  # noqa: E402

from wetcontact.meshes.builders import Resolution  # noqa: E402
from wetcontact.meshes.cache import get_mesh  # noqa: E402
from wetcontact.models import get_model, provenance  # noqa: E402
from wetcontact.plotting import signed_axis  # noqa: E402
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
            "time_s": warm, "repeats": repeats, "time_cold_s": cold,
            "dofs": curve.diagnostics["dofs"][0],
            "elements": curve.diagnostics["elements"][0]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two gaps, three levels, 2 repeats")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--part", choices=("all", "slip", "bridge", "cost", "film", "chart"),
                    default="all",
                    help="'slip': only the slip, Basset and unequal-sphere sections; "
                    "'bridge': only the liquid-bridge sections; 'cost': median cost per gap "
                    "of bridges and films at the default preset (run it on a quiet machine); "
                    "'film': only the film presets' agreement (film_cost); 'chart': redraw "
                    "the three charts from the JSON, running nothing")
    ap.add_argument("--amount", choices=("all", "bridge", "film"), default="all",
                    help="with --part cost: only these cases (their rows are replaced in "
                    "the JSON, the others kept)")
    args = ap.parse_args()
    repeats = 2 if args.quick else args.repeats
    if args.part == "chart":
        data = json.loads((RESULTS / "stokes.json").read_text())
        plot(data["work_precision"], RESULTS / "stokes.png")
        plot_slip(data["slip_study"], RESULTS / "stokes_slip.png")
        plot_bridge(data["bridge_vs_lubrication"], data["bridge_slip"],
                    RESULTS / "stokes_bridge.png")
        return
    if args.part == "bridge":
        bridge_part(args.quick)
        return
    if args.part == "slip":
        slip_part(args.quick, repeats)
        return
    if args.part == "film":
        film_part(args.quick)
        return
    if args.part == "cost":
        cost_part(repeats, args.amount)
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
                           "deviation": c.force_viscous[0] / f0 / fstar - 1, "time_s": t,
                           "repeats": max(1, repeats // 2)}
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
                       "repeats": max(1, repeats // 2),
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


TH_BRIDGE = 20.0
B_BRIDGE = 1e-9


def bridge_scene(kind: str, s: float, vol: float, b: float = B_BRIDGE, radius2: float = 1.0):
    geo = {"kind": kind, "radius": R} | (
        {"radius2": radius2 * R} if kind == "sphere-sphere" else {})
    return scene_from_dict({
        "name": f"bench-bridge-{kind}-{s:g}-{vol:g}", "geometry": geo,
        "amount": {"bridge_volume": vol * R**3},
        "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0,
                   "contact_angle": TH_BRIDGE, "slip_length_sphere": b,
                   "slip_length_wall": b},
        "motion": {"velocity": V, "gaps": [s * R]}})


def _lub_same_radius(kind: str, s: float, rc: float, b: float) -> float:
    """Reynolds force (units eta R v) of the wetted radius rc/R, pressure released there."""
    from wetcontact.solver.lubrication import GapProfile, solve_reynolds

    prof = (GapProfile.sphere_wall(s, 1.0) if kind == "sphere-wall"
            else GapProfile.sphere_sphere(s, 1.0, 1.0))
    sol = solve_reynolds(prof, viscosity=1.0, velocity=1.0, wetted_radius=rc,
                         slip_lengths=(b, b))
    return float(sol.force_viscous[0])


def film_presets(quick: bool) -> list[dict]:
    """Every preset on the flat-top film domain, cold (meshing included): the benchmark's
    films (delta = 2S, S/R = 1e-3, 1e-2, 0.1) and delta/R = 1e-3, 1e-2, 0.1 at
    S/delta = 0.95, where the film-top corner weighs most; force and difference from
    ``accurate``."""
    import os

    model = get_model("stokes")
    unit = ETA * R * V
    cases = ([(2e-2, 0.5)] if quick else
             [(2 * s, 0.5) for s in (1e-3, 1e-2, 0.1)] + [(d, 0.95) for d in (1e-3, 1e-2, 0.1)])
    film = []
    for d, x in cases:
        s = x * d
        sc = scene_from_dict({
            "name": "bench-film", "geometry": {"kind": "sphere-wall", "radius": R},
            "amount": {"film_thickness": d * R},
            "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0},
            "motion": {"velocity": V, "gaps": [s * R]}})
        rows = {}
        for preset in ("fast", "default", "accurate"):
            os.environ["WETCONTACT_CACHE"] = tempfile.mkdtemp(prefix="wetcontact-bench-")
            t0 = time.perf_counter()
            c = model.force(sc, preset=preset)
            rows[preset] = (time.perf_counter() - t0, c)
        acc = rows["accurate"][1].force_viscous[0]
        for preset, (t, c) in rows.items():
            film.append({"s_over_r": s, "film_over_r": d, "preset": preset,
                         "time_cold_s": t, "dofs": c.diagnostics["dofs"][0],
                         "f_over_unit": c.force_viscous[0] / unit,
                         "diff_from_accurate": c.force_viscous[0] / acc - 1,
                         "film_top": c.settings["film_top"],
                         "film_corner": c.settings["film_corner"]})
            print("film", film[-1], flush=True)
    return film


def film_part(quick: bool) -> None:
    """Only the ``film_cost`` section (the preset agreement on films), other sections kept."""
    import json

    path = RESULTS / "stokes.json"
    data = json.loads(path.read_text()) if path.exists() else {"benchmark": "stokes"}
    data["film_cost"] = film_presets(quick)
    data["film_note"] = ("shared 2-core machine (other agents running): timings loaded")
    write_json("stokes", data)


def bridge_part(quick: bool) -> None:
    """Bridge cost per gap, film cost, comparison with lubrication, slip-length study."""
    import json
    import os

    from wetcontact.solver.meniscus import Bridge
    from wetcontact.solver.stokes.bridge import contact_line_slope, solve_bridge

    os.environ.setdefault("WETCONTACT_CACHE", tempfile.mkdtemp(prefix="wetcontact-bench-"))
    model = get_model("stokes")
    unit = ETA * R * V
    cost = []
    for kind, q in (("sphere-wall", 1.0), ("sphere-sphere", 1.0), ("sphere-sphere", 2.0)):
        for s in ([1e-3] if quick else [1e-3, 1e-2]):
            sc = bridge_scene(kind, s, 1e-3, radius2=q)
            rows = {}
            for preset in ("fast", "default", "accurate"):
                t0 = time.perf_counter()
                c = model.force(sc, preset=preset)
                rows[preset] = (time.perf_counter() - t0, c)
            acc = rows["accurate"][1].force_viscous[0]
            for preset, (t, c) in rows.items():
                row = {"kind": kind, "r2_over_r": q, "method": c.diagnostics["method"],
                       "s_over_r": s, "v_over_r3": 1e-3, "preset": preset,
                       "time_s": t, "dofs": c.diagnostics["dofs"][0],
                       "f_over_unit": c.force_viscous[0] / unit,
                       "diff_from_accurate": c.force_viscous[0] / acc - 1,
                       "reaction_over_dissipation": c.extras["force_reaction"][0]
                       / c.force_viscous[0] - 1}
                cost.append(row)
                print(f"bridge {kind} R2/R={q:g} S/R={s:g} {preset:8s} t={t:.2f}s "
                      f"dofs={row['dofs']} "
                      f"diff={row['diff_from_accurate']:+.1e}", flush=True)

    film = film_presets(quick)

    comp = []
    lub_model, rf_model = get_model("lubrication"), get_model("reynolds-finite")
    vols = [1e-3] if quick else [1e-4, 1e-3, 1e-2]
    gaps = [1e-3, 1e-2] if quick else [1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2]
    for vol in vols:
        for s in gaps:
            sc = bridge_scene("sphere-wall", s, vol)
            c = model.force(sc, preset="default")
            f = c.force_viscous[0]
            if f == 0.0:
                continue  # past rupture
            br = Bridge.from_scene(sc)
            fl = solve_bridge(br, s * R, vol * R**3, (B_BRIDGE, B_BRIDGE),
                              Resolution(n_gap=4, h_sphere=0.05, growth=0.06, far=1e3),
                              contact_size=2 * B_BRIDGE / R)
            rc = fl.motion.contact_radius[1]
            same = _lub_same_radius("sphere-wall", s, rc, B_BRIDGE / R) * unit
            row = {"v_over_r3": vol, "s_over_r": s, "f_over_unit": f / unit,
                   "over_lub_same_radius": f / same,
                   "hs_slope_over_f": contact_line_slope(fl.motion, math.radians(TH_BRIDGE),
                                                         math.radians(TH_BRIDGE)) * unit / f,
                   "contact_radius": rc, "contact_speed": list(fl.motion.contact_speed)}
            for name, m in (("lubrication", lub_model), ("reynolds-finite", rf_model)):
                why = m.applicable(sc)
                row[f"over_{name}"] = (None if why else
                                       f / float(m.force(sc, preset="default").force_viscous[0]))
            comp.append(row)
            print(f"V={vol:g} S/R={s:g} F/F_lub(rc)={row['over_lub_same_radius']:.4f} "
                  f"lubrication={row['over_lubrication']} "
                  f"reynolds-finite={row['over_reynolds-finite']}", flush=True)

    slip = []
    for s in ([1e-3] if quick else [1e-3, 1e-2]):
        for b in ([1e-4, 1e-6] if quick else [1e-3, 1e-4, 1e-5, 1e-6, 1e-7]):
            br = Bridge(radius=1.0, contact_angle1=math.radians(TH_BRIDGE),
                        contact_angle2=math.radians(TH_BRIDGE), surface_tension=1.0)
            t0 = time.perf_counter()
            fl = solve_bridge(br, s, 1e-3, (b, b),
                              Resolution(n_gap=4, h_sphere=0.05, growth=0.06, far=1e3),
                              contact_size=max(2 * b, 1e-7))
            t = time.perf_counter() - t0
            lub = _lub_same_radius("sphere-wall", s, fl.motion.contact_radius[1], b)
            slip.append({"s_over_r": s, "b_over_r": b, "f": fl.force, "f_lub": lub,
                         "excess": fl.force - lub, "time_s": t,
                         "hs_slope": contact_line_slope(fl.motion, math.radians(TH_BRIDGE),
                                                        math.radians(TH_BRIDGE))})
            print(f"slip S/R={s:g} b/R={b:g} F={fl.force:.6g} F_lub={lub:.6g} "
                  f"HS slope={slip[-1]['hs_slope']:.4g} t={t:.2f}s", flush=True)
    for s in sorted({r["s_over_r"] for r in slip}):
        rows = sorted((r for r in slip if r["s_over_r"] == s), key=lambda r: -r["b_over_r"])
        for a, c in zip(rows, rows[1:], strict=False):
            c["measured_slope"] = (c["excess"] - a["excess"]) / math.log(a["b_over_r"]
                                                                        / c["b_over_r"])
            c["slope_ratio"] = c["measured_slope"] / c["hs_slope"]

    path = RESULTS / "stokes.json"
    data = json.loads(path.read_text()) if path.exists() else {"benchmark": "stokes"}
    data.update({"bridge_cost": cost, "film_cost": film, "bridge_vs_lubrication": comp,
                 "bridge_slip": slip, "bridge_quick": quick,
                 "bridge_note": "shared 2-core machine (other agents running): timings "
                 "loaded; theta = 20 deg, b = 1 nm = 1e-6 R unless stated"})
    write_json("stokes", data)
    plot_bridge(comp, slip, RESULTS / "stokes_bridge.png")


def cost_part(repeats: int, amount: str = "all") -> None:
    """Median wall time per gap at the default preset, meshing included (goal 2 s), of the
    bridges (V/R^3 = 1e-3, 20 deg, 1 nm slip) and films (delta = 2S) of ``bridge_part``,
    each solved ``repeats`` times with a cold mesh cache; the load average is recorded.
    ``amount`` ``"bridge"`` or ``"film"``: only those cases, whose rows replace theirs in
    the JSON (the other rows are kept)."""
    import json
    import os
    import statistics

    model = get_model("stokes")
    model.force(bridge_scene("sphere-wall", 1e-2, 1e-3), preset="fast")  # imports, JIT
    rows = []
    cases = [("bridge", kind, q, s) for kind, q in (("sphere-wall", 1.0),
                                                    ("sphere-sphere", 1.0),
                                                    ("sphere-sphere", 2.0))
             for s in (1e-3, 1e-2)] + [("film", "sphere-wall", 1.0, s)
                                       for s in (1e-3, 1e-2, 0.1)]
    cases = [c for c in cases if amount in ("all", c[0])]
    for amount_i, kind, q, s in cases:
        if amount_i == "bridge":
            sc = bridge_scene(kind, s, 1e-3, radius2=q)
        else:
            sc = scene_from_dict({
                "name": "bench-film", "geometry": {"kind": "sphere-wall", "radius": R},
                "amount": {"film_thickness": 2 * s * R},
                "liquid": {"viscosity": ETA, "surface_tension": 0.072, "density": 998.0},
                "motion": {"velocity": V, "gaps": [s * R]}})
        times = []
        load = os.getloadavg()[0]
        for _ in range(repeats):
            os.environ["WETCONTACT_CACHE"] = tempfile.mkdtemp(prefix="wetcontact-bench-")
            t0 = time.perf_counter()
            model.force(sc, preset="default")
            times.append(time.perf_counter() - t0)
        rows.append({"amount": amount_i, "kind": kind, "r2_over_r": q, "s_over_r": s,
                     "median_s": statistics.median(times), "min_s": min(times),
                     "max_s": max(times), "repeats": repeats, "load_average_1min": load})
        print(rows[-1], flush=True)
    path = RESULTS / "stokes.json"
    data = json.loads(path.read_text()) if path.exists() else {"benchmark": "stokes"}
    kept = [r for r in data.get("cost_per_gap_default", [])
            if amount != "all" and r["amount"] != amount]
    data["cost_per_gap_default"] = kept + rows
    write_json("stokes", data)


def plot_bridge(comp: list[dict], slip: list[dict], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.6), layout="constrained")
    styles = ["o-", "s--", "^:"]
    signed = []
    for i, vol in enumerate(sorted({r["v_over_r3"] for r in comp})):
        rows = [r for r in comp if r["v_over_r3"] == vol]
        x = [r["s_over_r"] for r in rows]
        y1 = np.array([r["over_lub_same_radius"] - 1 for r in rows])
        y2 = np.array([r["over_reynolds-finite"] - 1 if r["over_reynolds-finite"]
                       else np.nan for r in rows])
        signed += [y1, y2]
        a1.plot(x, y1, styles[i % 3], color=f"C{i}", label=f"V/R^3 = {vol:g}: F/F_lub(r_c) - 1")
        a1.plot(x, y2, styles[(i + 1) % 3], color=f"C{i}", mfc="none", alpha=0.7,
                label=f"V/R^3 = {vol:g}: F/F_reynolds-finite - 1")
    a1.set_xscale("log")
    lin = signed_axis(a1, signed)  # signed: a difference that changes sign crosses zero
    a1.axhline(0.01, color="k", lw=0.8, ls="-.", label="±1 %")
    a1.axhline(-0.01, color="k", lw=0.8, ls="-.")
    a1.set_xlabel("S / R")
    a1.set_ylabel("relative difference (signed)" + ("" if lin is None else
                                                     f"; linear within {lin:.0e}"))
    a1.set_title("Stokes bridge vs lubrication (sphere-wall, 20 deg, b = 1e-6 R)", fontsize=9)
    a1.legend(fontsize=6)
    for i, s in enumerate(sorted({r["s_over_r"] for r in slip})):
        rows = sorted((r for r in slip if r["s_over_r"] == s), key=lambda r: -r["b_over_r"])
        x = [math.log(1 / r["b_over_r"]) for r in rows]
        y = [r["excess"] / r["hs_slope"] for r in rows]
        a2.plot(x, y, styles[i % 3], color=f"C{i + 3}", ms=9 - 4 * i, lw=3 - 1.5 * i,
                mfc="none" if i else None, label=f"FEM S/R = {s:g}")
        a2.plot(x, [y[-1] + (xx - x[-1]) for xx in x], "k-" if i == 0 else "k--",
                lw=0.8, label=f"Huh-Scriven slope 1, S/R = {s:g}")
    a2.set_xlabel("ln(R / b)")
    a2.set_ylabel("(F - F_lub) / [sum 2 pi r_cl U_cl^2 f(theta)]")
    a2.set_title("moving contact lines: slip-length log law (V/R^3 = 1e-3)", fontsize=9)
    a2.legend(fontsize=7)
    fig.savefig(out, dpi=120)
    plt.close(fig)


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
            ax.semilogx(x, [r["f_over_noslip"] for r in rows], mk, mfc="none" if n == 1 else None,
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
    for i, s in enumerate(sorted({r["s_over_r"] for r in wp})):
        rows = [r for r in wp if r["s_over_r"] == s]
        ax.loglog([r["time_s"] for r in rows], [abs(r["error"]) for r in rows],
                  ["o-", "s--", "^-.", "D:"][i % 4], label=f"S/R = {s:g}")
        for r in rows:
            ax.annotate(r["level"], (r["time_s"], abs(r["error"])), fontsize=6,
                        textcoords="offset points", xytext=(4, 3))
    ax.axhline(1e-5, color="k", lw=0.5, ls="--", label="1e-5")
    ax.axhline(1e-3, color="k", lw=0.5, ls=":", label="1e-3")
    ax.set_xlabel("wall time per configuration (s, median, mesh cached)")
    ax.set_ylabel("|F / F_Brenner - 1| (labels: mesh level)")
    ax.set_title("Stokes FEM (P2/P1, axisymmetric), immersed sphere-wall:\n"
                 "work-precision against Brenner's series", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
