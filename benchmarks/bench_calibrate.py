"""Calibrated closures: evaluation cost per point (1e5 points) and regeneration time.

Writes ``benchmarks/results/calibrate.json`` and ``calibrate.png``. Run:
``python benchmarks/bench_calibrate.py``. Medians of a few runs on a shared 2-core
machine: read them as orders of magnitude. Costs per point are measured with one BLAS
thread (one core, in child processes; ``seconds_per_point``: the median over
:data:`COST_RUNS` runs of each run's median of 7, their range and the runs in
``seconds_per_point_runs``) and with the default threads
(``seconds_per_point_default_blas_threads``, one run). The shipped ``calibrated-viscous`` table is
regenerated into a temporary file (the package data is not touched); the bound tables'
regeneration time is the one recorded in ``bounds.json`` when it was generated, and so is
``calibrated-capillary``'s (``wall_time_s`` of its package data, written by
``python -m wetcontact.generate calibrated-capillary`` on 2 processes; ``--regenerate-capillary``
times the generator's tables afresh, from an empty node cache, into a temporary file:
``--kinds=sphere-wall,sphere-sphere`` the one-angle tables, about 20 minutes; by default
the two-angle wall table too, hours; ``--regenerated-out=FILE`` keeps what it wrote). The
two-angle pair table's time is the sum of the resumed runs that built it, recorded in
``results/pair_table_stages.json`` (about 7.8 h on 2 processes; not rerun here). Each
calibrated-capillary table is timed at the default precision (the force's table summed in
single precision) and at the accurate preset (every table in double), in alternating
rounds of the same run.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, alternating_medians, median_time, write_json  # noqa: E402

from wetcontact import calibrate as cal  # noqa: E402
from wetcontact.models import load_all  # noqa: E402
from wetcontact.reduced_models import bounds  # noqa: E402
from wetcontact.reduced_models import calibrated_capillary as ccap  # noqa: E402
from wetcontact.reduced_models.calibrated import immersed_lambda, viscous_table  # noqa: E402
from wetcontact.reduced_models.viscous import brenner_lambda, schaeffer_lambda  # noqa: E402

N = 100_000


def costs() -> dict[str, float]:
    """Seconds per point of each closure, vectorised over 1e5 points (median of 7)."""
    load_all()
    rng = np.random.default_rng(1)
    table = viscous_table()
    assert table is not None, "run python -m wetcontact.generate calibrated-viscous first"
    s = np.exp(rng.uniform(np.log(1e-5), np.log(100), N))
    film = {"gap": rng.uniform(0.01, 0.95, N) * 1e-5, "edge_gap": np.full(N, 1e-5),
            "r_star": np.full(N, 1e-3), "viscosity": np.full(N, 1e-3),
            "velocity": np.full(N, 0.1), "kappa": np.ones(N)}
    vol = np.exp(rng.uniform(np.log(1e-13), np.log(1e-10), N))
    bridge = {"gap": rng.uniform(0, 1e-4, N), "volume": vol, "r_closure": np.full(N, 1e-3),
              "radius": np.full(N, 1e-3), "sigma": np.full(N, 0.072),
              "theta": rng.uniform(0, 0.8, N)}
    k_film = np.asarray(table["film"]["coefficients"])
    cases = {
        "calibrated-viscous (immersed wall, Chebyshev)":
            lambda: immersed_lambda(s, "sphere-wall", table),
        "calibrated-viscous (film factor)": lambda: cal.finite_liquid_form(k_film, film),
        "schaeffer (published fit)": lambda: schaeffer_lambda(s),
        "willett form (48 coefficients)":
            lambda: cal.willett_form(cal.WILLETT_PUBLISHED.ravel(), bridge),
        "bagheri form (23 coefficients)":
            lambda: cal.bagheri_form(cal.BAGHERI_PUBLISHED, bridge),
        "mikami form (8 coefficients)":
            lambda: cal.mikami_form(np.array(cal.FAMILIES["mikami-pw"].published), bridge),
    }
    per_point = {}
    for name, fn in cases.items():
        t, _ = median_time(fn, repeats=7, warmup=1)
        per_point[name] = t / N
    cap = ccap.capillary_table()
    if cap is not None:
        v = np.exp(rng.uniform(np.log(1e-4), np.log(0.1), N))
        th = np.radians(rng.uniform(0, 70, N))
        ratio = np.exp(rng.uniform(0, np.log(10), N))
        # one angle on both solids, then each solid with its own (a wall's, two spheres')
        for kind, table in (("sphere-wall", "sphere-wall"), ("sphere-sphere", "sphere-sphere"),
                            ("sphere-wall", ccap.WALL_TWO_ANGLES),
                            ("sphere-sphere", ccap.PAIR_TWO_ANGLES)):
            if table not in cap:
                continue
            rr = ratio if kind == "sphere-sphere" else None
            t2 = None if table == kind else np.radians(rng.uniform(0, 70, N))
            _, sc = ccap.force_star(kind, v, th, np.zeros(N), rr, theta_wall=t2)
            gap = rng.uniform(0, 1.0, N) * sc
            label = kind if t2 is None else f"{kind}, two angles"
            # the default precision and the accurate preset's (every table in double, what
            # the exports compute), in alternating rounds: their ratio is this run's
            got = alternating_medians({p: lambda kind=kind, rr=rr, gap=gap, t2=t2, p=p:
                                       ccap.force_star(kind, v, th, gap, rr, theta_wall=t2,
                                                       precision=p)
                                       for p in ("mixed", "double")})
            for precision, t in got.items():
                extra = ", accurate preset" if precision == "double" else ""
                per_point[f"calibrated-capillary {label}{extra} (force and S_c)"] = t / N
    s_small = s[:1000]
    t, _ = median_time(lambda: brenner_lambda(s_small), repeats=3, warmup=1)
    per_point["brenner (exact series, 1e3 points)"] = t / s_small.size
    return per_point


CAP_KINDS = ("sphere-wall", "sphere-sphere", ccap.WALL_TWO_ANGLES, ccap.PAIR_TWO_ANGLES)


COST_RUNS = 5
"""Runs of :func:`costs` whose medians are taken: the shared machine's speed drifted by up
to 1.5x between runs minutes apart (2026-11-28: the two-angle sphere-pair table 1.37 to
2.12 us in five runs within an hour), more than within one run's seven repeats."""


def one_thread_costs(runs: int = COST_RUNS) -> tuple[dict[str, float], list[dict[str, float]]]:
    """:func:`costs` in ``runs`` child processes one after the other, whose BLAS runs on one
    thread: the cost per point on one core, and steadier on a shared machine (two BLAS
    threads contending with another job made the small matrix products of
    calibrated-capillary 10-20x slower). Returns the median over the runs of each run's
    median, and the runs."""
    env = {**os.environ, **{k: "1" for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                              "MKL_NUM_THREADS")}}
    got = []
    for _ in range(runs):
        out = subprocess.run([sys.executable, __file__, "--costs-json"], env=env,
                             check=True, capture_output=True, text=True).stdout
        got.append(json.loads(out.strip().splitlines()[-1]))
    return {k: float(np.median([g[k] for g in got])) for k in got[0]}, got


def regenerated_kinds() -> list[str]:
    """The tables ``--regenerate-capillary`` regenerates: ``--kinds=K1,K2`` or all the
    generator writes; an unknown one ends the benchmark before anything is timed."""
    from wetcontact.generate.calibrated_capillary import KINDS

    kinds = next((a.split("=", 1)[1].split(",") for a in sys.argv
                  if a.startswith("--kinds=")), list(KINDS))
    if set(kinds) - set(KINDS):
        sys.exit(f"bench_calibrate: --kinds={','.join(kinds)}: the generator writes "
                 + ", ".join(KINDS))
    return kinds


def main() -> None:
    if "--costs-json" in sys.argv:
        print(json.dumps(costs()))
        return
    kinds = regenerated_kinds() if "--regenerate-capillary" in sys.argv else None  # fail fast
    per_point, runs = one_thread_costs()
    per_point_threads = costs()
    cap = ccap.capillary_table()

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        data = cal.generate_calibrated_viscous(Path(tmp) / "cv.json")
        regen = time.perf_counter() - t0
    viscous_table.cache_clear()
    path = bounds.resources.files("wetcontact.reduced_models") / "data" / bounds.DATA_FILE
    bounds_time = json.loads(path.read_text()).get("wall_time_s") if path.is_file() else None
    held = {f"immersed {k}": v["held_out"]["max"] for k, v in data["immersed"].items()}
    held["film (vs stokes, flat top)"] = data["film"]["held_out"]["after"]["max"]
    for k, v in data["bridge"].items():
        held[f"bridge {k} (vs lubrication)"] = v["held_out"]["after"]["max"]
    cap_regen = {"recorded_wall_time_s": cap.get("wall_time_s"),
                 "recorded_branches": cap.get("branches"),
                 "fit_time_s": {k: cap[k].get("fit_time_s") for k in CAP_KINDS
                                if k in cap}} if cap else None
    previous = RESULTS / "calibrate.json"
    if cap_regen is not None and previous.is_file():
        # the package data's own time may be a rerun on cached branches: keep the last
        # from-scratch measurement (--regenerate-capillary) beside it
        last = json.loads(previous.read_text()).get("regenerate_calibrated_capillary") or {}
        scratch = last.get("measured_wall_time_s", last.get("last_from_scratch_s"))
        if scratch is not None:
            cap_regen["last_from_scratch_s"] = scratch
            for k in ("measured_kinds", "measured_fit_time_s", "measured_branches"):
                if k in last:  # what that from-scratch run regenerated
                    cap_regen[f"last_from_scratch_{k.removeprefix('measured_')}"] = last[k]
    stages = RESULTS / "pair_table_stages.json"
    if cap_regen is not None and ccap.PAIR_TWO_ANGLES in cap and stages.is_file():
        # the two-angle pair table was built over several resumed runs: their recorded
        # sum, not a measurement of this run
        cap_regen["pair_two_angles_stage_runs_s"] = {
            **stage_sums(json.loads(stages.read_text())),
            "source": f"benchmarks/results/{stages.name}"}
    if kinds is not None:
        from wetcontact.generate.calibrated_capillary import generate_calibrated_capillary

        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            done = generate_calibrated_capillary(Path(tmp) / "cc.json", kinds=tuple(kinds),
                                                 workers=2, cache_dir=Path(tmp))  # scratch
            cap_regen = {**(cap_regen or {}),
                         "measured_wall_time_s": time.perf_counter() - t0, "workers": 2,
                         "measured_kinds": kinds,
                         "measured_fit_time_s": {k: done[k].get("fit_time_s") for k in kinds},
                         "measured_branches": done.get("branches")}
            for k in [k for k in cap_regen if k.startswith("last_from_scratch")]:
                del cap_regen[k]  # this run is the last from scratch now
            keep = next((a.split("=", 1)[1] for a in sys.argv
                         if a.startswith("--regenerated-out=")), None)
            if keep:  # to compare with the package data
                Path(keep).write_text((Path(tmp) / "cc.json").read_text())
        ccap.capillary_table.cache_clear()
    out = {"points": N, "seconds_per_point": per_point,
           "seconds_per_point_runs": {
               "what": f"each of {len(runs)} one-thread runs' medians of 7, one after "
                       "the other; seconds_per_point is their median",
               "min": {k: min(r[k] for r in runs) for k in per_point},
               "max": {k: max(r[k] for r in runs) for k in per_point},
               "runs": runs},
           "seconds_per_point_default_blas_threads": per_point_threads,
           "regenerate_calibrated_viscous_s": regen,
           "regenerate_bounds_s_recorded": bounds_time,
           "calibrated_viscous_held_out_max": held,
           "regenerate_calibrated_capillary": cap_regen,
           "calibrated_capillary_held_out_max": {
               f"{k} {p}": cap[k]["held_out"][p]["max"] for k in CAP_KINDS
               if k in cap for p in ("rupture_distance", "force")} if cap else None}
    write_json("calibrate", out)
    chart(per_point, regen, out["seconds_per_point_runs"])
    chart_work_precision(out)
    print(json.dumps(out, indent=1))


def stage_sums(record: dict) -> dict[str, int]:
    """The two-angle pair table's generator time (s) from its recorded runs
    (``results/pair_table_stages.json``): per stage the sum of its runs, each run its
    logged wall time or else the sum of its logged phases; the total adds the coarse
    stage's approximate phases and is rounded to 100 s."""
    def run_s(run: dict) -> float:
        return run.get("wall_time_s", sum(run["phases_s"].values()))

    medium = sum(run_s(r) for r in record["medium"])
    full = sum(run_s(r) for r in record["full"])
    coarse = sum(v for v in record["coarse"].values() if isinstance(v, int | float))
    return {"medium_sum_s": round(medium), "full_sum_s": round(full),
            "total_about_s": int(round(coarse + medium + full, -2))}


def chart(per_point: dict[str, float], regen: float,
          spread: dict[str, Any] | None = None) -> None:
    """``calibrate.png``: each closure's cost a point; ``spread`` (``min`` and ``max`` per
    closure over the runs) as whiskers."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    names = list(per_point)
    fig, ax = plt.subplots(figsize=(12, 5))
    accurate = ["accurate preset" in n for n in names]
    xerr = None
    if spread:  # whiskers from the fastest to the slowest run
        xerr = [[(per_point[n] - spread["min"][n]) * 1e9 for n in names],
                [(spread["max"][n] - per_point[n]) * 1e9 for n in names]]
    ax.barh(names, [per_point[n] * 1e9 for n in names],
            color=["C1" if a else "C0" for a in accurate],
            hatch=["//" if a else "" for a in accurate], edgecolor="k", lw=0.5,
            xerr=xerr, error_kw={"ecolor": "0.25", "capsize": 3, "lw": 1})
    goal = ax.axvline(1000.0, color="C3", ls="--", lw=1.2)
    ax.legend([Patch(facecolor="C0", edgecolor="k"),
               Patch(facecolor="C1", hatch="//", edgecolor="k"), goal],
              ["default preset", "accurate preset (every table in double)",
               "calibrated-capillary goal, 1 us"], loc="lower right", fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("ns per point (vectorised, 1e5 points, one BLAS thread; brenner: 1e3 "
                  "points)\n" + ("bar: median over runs; whiskers: fastest and slowest run"
                                 if spread else ""))
    ax.set_title(f"closure evaluation cost per point\n(calibrated-viscous regenerated in "
                 f"{regen:.0f} s;\ncalibrated-capillary: all inputs vary per point)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(RESULTS / "calibrate.png", dpi=110)
    plt.close(fig)


TABLE_MARKERS = ("D", "s", "^", "v")
"""calibrate_wp.png's marker per calibrated-capillary table (in :data:`CAP_KINDS`' order):
tables of about the same cost and error stay apart (the square hollow and larger: the
one-angle sphere pairs and the wall with two angles have cost and error alike)."""


def chart_work_precision(rec: dict) -> None:
    """``calibrate_wp.png``: held-out max error of each capillary closure against its cost a
    point, published and refitted coefficients and the shipped tables, with the FE
    reference (`meniscus`, per configuration, from ``meniscus.json``) for scale. The
    errors are the committed held-out tables' (``results/calibration/*.json`` and this
    file's ``calibrated_capillary_held_out_max``), each on its own family's domain."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cost = rec["seconds_per_point"]
    pts: list[tuple[str, float, float, str]] = []  # label, cost, error, style
    for fam, form in (("willett", "willett form (48 coefficients)"),
                      ("bagheri", "bagheri form (23 coefficients)"),
                      ("mikami-pp", "mikami form (8 coefficients)"),
                      ("mikami-pw", "mikami form (8 coefficients)")):
        path = RESULTS / "calibration" / f"{fam}.json"
        if not path.is_file() or form not in cost:
            continue
        held = json.loads(path.read_text())["held_out"]
        pts.append((f"{fam}, published", cost[form], held["before"]["max"], "x"))
        pts.append((f"{fam}, refitted", cost[form], held["after"]["max"], "o"))
    cap = rec.get("calibrated_capillary_held_out_max") or {}
    for kind, marker in zip(CAP_KINDS, TABLE_MARKERS, strict=False):
        label = kind.replace("-two-angles", ", two angles")
        key = next((k for k in cost if k.startswith(f"calibrated-capillary {label} (")), None)
        if key and f"{kind} force" in cap:
            pts.append((f"calibrated-capillary, {kind}", cost[key], cap[f"{kind} force"],
                        marker))
    fig, ax = plt.subplots(figsize=(9.5, 5.2), layout="constrained")
    colour: dict[str, str] = {}
    for label, c, e, m in pts:  # one colour a family: published x, refitted o; each table
        fam = label.split(",")[0] if m not in TABLE_MARKERS else label  # its own marker
        col = colour.setdefault(fam, f"C{len(colour) % 10}")
        ax.loglog(c, e, m, ms=11 if m == "s" else 7, color=col,
                  mfc="none" if m in ("o", "s") else None, mew=1.5 if m == "s" else None,
                  label=label)
    men = RESULTS / "meniscus.json"
    if men.is_file():
        rows = json.loads(men.read_text())["fe_single"]
        by_n: dict[int, list] = {}
        for r in rows:
            by_n.setdefault(r["n_elements"], []).append(r)
        ns = sorted(by_n)
        ax.loglog([float(np.median([r["wall_time_s"] for r in by_n[n]])) for n in ns],
                  [max(max(r["error"] for r in by_n[n]), 1e-16) for n in ns], "k*-",
                  label="meniscus FE per configuration, 32-256 elements\n(error against "
                        "512 elements)")
    ax.axhline(1e-3, color="C3", ls="--", lw=1, label="calibrated-capillary force goal, 1e-3")
    ax.axvline(1e-6, color="C3", ls=":", lw=1, label="cost goal, 1 us a point")
    ax.set_xlabel("cost per point (s; closures vectorised over 1e5 points, one BLAS thread;\n"
                  "median of the runs, calibrate.png gives their range)")
    ax.set_ylabel("held-out max relative force error")
    ax.set_title("capillary force: held-out error against cost, reference meniscus\n"
                 "(each on its own domain: mikami-pw a wall, the other families equal "
                 "spheres,\ncalibrated-capillary as named, sphere pairs R2/R1 1-10)",
                 fontsize=9)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.savefig(RESULTS / "calibrate_wp.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    if "--chart" in sys.argv:  # redraw from the results written before
        rec = json.loads((RESULTS / "calibrate.json").read_text())
        chart(rec["seconds_per_point"], rec["regenerate_calibrated_viscous_s"],
              rec.get("seconds_per_point_runs"))
        chart_work_precision(rec)
    else:
        main()
