"""Collisions: cost of one impact, of a 1e4-impact restitution map and of an e(St) curve
with the reference force set, and the restitution's error against time for the
integrators' tolerances. Writes benchmarks/results/collide.json and collide.png.

Run: ``python benchmarks/bench_collide.py`` (``--chart`` redraws from the JSON).
"""

from __future__ import annotations

import json
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, as the goals state

import numpy as np  # noqa: E402
from _common import RESULTS, machine, main_or_chart, median_time  # noqa: E402

from wetcontact.collide import collide  # noqa: E402
from wetcontact.collide import forces as collide_forces  # noqa: E402
from wetcontact.collide.batch import restitution_map  # noqa: E402
from wetcontact.models import load_all  # noqa: E402
from wetcontact.tables.collisions import film_case  # noqa: E402

NAME = "collide"


def main() -> None:
    load_all()
    case = film_case(5e-5, 100.0)
    closures = {"viscous": "reynolds-finite", "capillary": "willett"}
    out: dict = {"machine": machine(), "case": "2 mm glass bead on a 50 um water film, "
                 "theta 20 deg, e_dry 0.97, roughness 1e-4 R, St 100"}

    # one impact with closures: the event-driven integrator, tables built once per geometry
    def first() -> None:
        collide_forces._TABLES.clear()
        collide(case, trajectory=False, **closures)

    out["one_impact_closures_first_s"] = median_time(first, repeats=5)[0]
    out["one_impact_closures_s"] = median_time(
        lambda: collide(case, trajectory=False, **closures), repeats=7)[0]
    out["one_impact_map_s"] = median_time(
        lambda: restitution_map(case, **closures), repeats=7)[0]
    # a new speed at a geometry already set up (what a map or a DEM time step pays)
    rng = np.random.default_rng(1)
    out["one_impact_map_new_speed_s"] = median_time(
        lambda: restitution_map(case.with_(velocity=float(rng.uniform(0.05, 1.0))),
                                **closures), repeats=21)[0]
    mass = case.solid.density * 4 / 3 * np.pi * 1e-9
    speeds = np.geomspace(5.0, 1000.0, 10_000) * 6 * np.pi * 1e-3 * 1e-6 / mass
    out["map_1e4_closures_s"] = median_time(
        lambda: restitution_map(case, velocity=speeds, **closures), repeats=3)[0]
    out["map_1e4_reference_s"] = median_time(
        lambda: restitution_map(case, velocity=speeds), repeats=3)[0]

    # an e(St) curve of 50 impacts with the reference force set, force tables included
    sts = np.geomspace(5.0, 1000.0, 50)

    def curve() -> list[float]:
        collide_forces._TABLES.clear()
        return [collide(film_case(5e-5, float(st)), trajectory=False).restitution
                for st in sts]

    t0 = time.perf_counter()
    curve()
    out["curve_50_reference_s"] = time.perf_counter() - t0

    # error in e against time: rtol of the event-driven integrator, steps of the map
    stv = np.array([30.0, 60.0, 100.0, 300.0, 1000.0])
    cases = [film_case(5e-5, float(st)) for st in stv]
    exact = np.array([collide(c, rtol=1e-13, trajectory=False).restitution for c in cases])
    wp_collide = []
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10, 1e-12):
        t, res = median_time(lambda r=rtol: [collide(c, rtol=r, trajectory=False).restitution
                                             for c in cases], repeats=3)
        wp_collide.append({"rtol": rtol, "time_s": t / len(cases),
                           "error": float(np.max(np.abs(np.array(res) - exact)))})
    wp_map = []
    v = stv * 6 * np.pi * 1e-3 * 1e-6 / mass
    for steps in (16, 32, 64, 128, 256, 512):
        t, res = median_time(lambda s=steps: restitution_map(case, velocity=v, steps=s),
                             repeats=5)
        wp_map.append({"steps": steps, "time_s": t / len(cases),
                       "error": float(np.max(np.abs(res.restitution - exact)))})
    out["work_precision"] = {"collide": wp_collide, "restitution_map": wp_map}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"{NAME}.json").write_text(json.dumps(out, indent=1))
    chart(out)
    for k, val in out.items():
        if k.endswith("_s"):
            print(f"{k}: {val:.4g} s")


def chart(out: dict) -> None:
    from wetcontact.plotting import pyplot, save, styles

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    sty = styles(["collide (DOP853, events): rtol", "restitution_map (RK4 in ln x): steps"])
    for (key, label, param) in (("collide", "collide (DOP853, events): rtol", "rtol"),
                                ("restitution_map", "restitution_map (RK4 in ln x): steps",
                                 "steps")):
        rows = out["work_precision"][key]
        t = [r["time_s"] for r in rows]
        e = [max(r["error"], 1e-16) for r in rows]
        ax.plot(t, e, label=label, **sty[label])
        for r, ti, ei in zip(rows, t, e, strict=True):
            ax.annotate(f"{r[param]:g}", (ti, ei), fontsize=7, xytext=(3, 3),
                        textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per impact (s), tables built")
    ax.set_ylabel("max |e - e_exact| over St 30-1000")
    ax.set_title("Restitution error against time: 2 mm glass bead on a 50 um water film",
                 fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, RESULTS / f"{NAME}.png")


if __name__ == "__main__":
    main_or_chart(NAME, main, chart)
