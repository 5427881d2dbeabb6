"""Sweep throughput: meniscus and closure points on 1 and 2 local Dask workers, the
per-task overhead, the store's write rate, and the start-up time of ``wetcontact solve``.

Definitions
-----------
point
    One (scene, model) pair: one ForceCurve in the store.
meniscus point
    An equal-sphere pendular bridge (R = 50 um, water) with V/R^3 and the contact angle
    from a seeded Latin hypercube (V/R^3 in [1e-3, 0.05] log, theta in [0, 40] deg),
    solved by ``meniscus`` at the ``fast`` preset at 5 gaps (0.01 to 0.4 V^(1/3), all
    before rupture): a continuation to rupture plus 5 Newton solves.
closure point
    The same kind of bridge with 10 gaps, solved by one of five capillary closures
    (willett, willett-simple, bagheri, mikami, rabinovich); N points = N/5 scenes x 5.

Every sweep runs end to end through :func:`wetcontact.sweep.sweep` into a fresh store:
cluster start-up, task submission, the client's batched store writes. The speed-up is
the wall time on 1 worker over that on 2. The machine's 1-minute load average is
recorded beside each figure: on a shared machine the speed-up is bounded by the cores
the other processes leave free.

Run: ``python benchmarks/bench_sweep.py [--meniscus-points N] [--closure-points N]``
(defaults 2000 and 100000; 0 keeps that part's figures from the last JSON). Writes
``benchmarks/results/sweep.json`` and ``sweep.png``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, write_json  # noqa: E402

from wetcontact.scene import scene_from_dict  # noqa: E402
from wetcontact.store import Store  # noqa: E402
from wetcontact.study import latin_hypercube  # noqa: E402
from wetcontact.sweep import Point, sweep  # noqa: E402

R = 5.0e-5
CLOSURES = ("willett", "willett-simple", "bagheri", "mikami", "rabinovich")


def bridges(n: int, gap_fractions: list[float], seed: int) -> list:
    """``n`` bridge scenes over (V/R^3, theta) from a seeded Latin hypercube."""
    u = latin_hypercube(n, 2, seed)
    out = []
    for i, (a, b) in enumerate(u):
        v = 1e-3 * 50.0 ** a * R**3
        ell = v ** (1 / 3)
        out.append(scene_from_dict({
            "name": f"bench-bridge-{i}",
            "geometry": {"kind": "sphere-sphere", "radius": R},
            "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
                       "contact_angle": 40.0 * b},
            "amount": {"bridge_volume": v},
            "motion": {"velocity": 0.01, "gaps": [f * ell for f in gap_fractions]},
        }))
    return out


def load() -> float:
    return os.getloadavg()[0]


def run_sweep(points: list[Point], workers: int, tmp: Path) -> dict:
    store = Store(tmp / f"w{workers}-{time.monotonic_ns()}.h5")
    l0 = load()
    res = sweep(points, store, workers=workers, progress=True, keep_curves=False)
    assert res.count("failed") == 0, [o.reason for o in res.outcomes if o.reason][:3]
    return {"workers": workers, "points": len(points), "wall_time_s": res.wall_time_s,
            "points_per_s": len(points) / res.wall_time_s, "tasks": res.tasks,
            "executor": res.executor, "store_write_time_s": res.write_time_s,
            "store_mb": store.path.stat().st_size / 1e6, "load_before": l0,
            "load_after": load()}


def task_overhead(n_tasks: int = 1000) -> dict:
    """Round trip of empty tasks on a 2-worker local cluster, and its start/stop time."""
    import logging

    from distributed import Client, LocalCluster

    t0 = time.perf_counter()
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None, host="127.0.0.1", silence_logs=logging.CRITICAL)
    client = Client(cluster)
    t1 = time.perf_counter()
    rounds = []
    for _ in range(3):
        s = time.perf_counter()
        client.gather([client.submit(int, i, pure=False) for i in range(n_tasks)])
        rounds.append((time.perf_counter() - s) / n_tasks)
    t2 = time.perf_counter()
    client.close()
    cluster.close()
    return {"cluster_start_s": t1 - t0, "cluster_stop_s": time.perf_counter() - t2,
            "per_task_s_median": statistics.median(rounds), "tasks_per_round": n_tasks}


def write_rate(tmp: Path, batches: int = 8, batch: int = 1000) -> dict:
    """Batched atomic writes of closure curves into a growing store."""
    from wetcontact.models import get_model

    scenes = bridges(batches * batch, [1e-7 * k for k in range(1, 11)], seed=3)
    model = get_model("willett")
    curves = [(sc, model.force(sc)) for sc in scenes]
    store = Store(tmp / "write-rate.h5")
    rows = []
    for b in range(batches):
        t0 = time.perf_counter()
        store.save_many(curves[b * batch:(b + 1) * batch])
        dt = time.perf_counter() - t0
        rows.append({"curves_before": b * batch, "batch": batch, "seconds": dt,
                     "curves_per_s": batch / dt, "mb_after": store.path.stat().st_size / 1e6})
    return {"batches": rows, "bytes_per_curve": store.path.stat().st_size / (batches * batch)}


def startup(repeats: int = 9) -> dict:
    """Median start-to-exit time of ``wetcontact solve`` with a closure against the bare
    ``python -c "import numpy, scipy.sparse"``."""
    case = Path(__file__).resolve().parents[1] / "cases" / "brenner-immersed-sphere-wall.toml"
    cmds = {"import_numpy_scipy_sparse": [sys.executable, "-c", "import numpy, scipy.sparse"],
            "solve_closure": [sys.executable, "-m", "wetcontact.cli", "solve", str(case),
                              "--model", "brenner"]}
    out = {}
    for name, cmd in cmds.items():
        ts = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True)
            ts.append(time.perf_counter() - t0)
        out[name] = statistics.median(ts)
    out["ratio"] = out["solve_closure"] / out["import_numpy_scipy_sparse"]
    mods = subprocess.run([sys.executable, "-c", "import sys, runpy; sys.argv = ['w', 'solve', "
                           f"{str(case)!r}, '--model', 'brenner']\ntry:\n    runpy.run_module("
                           "'wetcontact.cli', run_name='__main__')\nexcept SystemExit:\n    pass\n"
                           "print([m for m in ('dask', 'distributed', 'skfem', 'pde', 'gmsh', "
                           "'matplotlib', 'h5py') if m in sys.modules])"],
                          capture_output=True, text=True, check=True).stdout.strip().splitlines()
    out["heavy_modules_imported_by_solve"] = mods[-1]
    return out


def chart(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2))
    kinds = [k for k in ("meniscus", "closures") if k in data]
    x = np.arange(len(kinds))
    for j, w in enumerate((1, 2)):
        vals = [next(r["points_per_s"] for r in data[k] if r["workers"] == w) for k in kinds]
        ax[0].bar(x + (j - 0.5) * 0.38, vals, 0.38, label=f"{w} worker{'s' * (w > 1)}")
    for i, k in enumerate(kinds):
        r1, r2 = (next(r for r in data[k] if r["workers"] == w) for w in (1, 2))
        gain = r1["wall_time_s"] / r2["wall_time_s"]
        writes = r2["store_write_time_s"] / r2["wall_time_s"]
        l1, l2 = r1["load_before"], r2["load_before"]
        # a speed-up is a ratio of two runs: only meaningful when both saw the same load
        fair = abs(l1 - l2) <= 1.0 and gain <= 2.0 * 1.1
        ax[0].annotate(f"x{gain:.2f}" + ("" if fair else " (not comparable)")
                       + f"\nload {l1:.1f} / {l2:.1f}\nwrites {writes:.0%}",
                       (i, max(r1["points_per_s"], r2["points_per_s"])), ha="center",
                       va="bottom", fontsize=8)
    ax[0].set_xticks(x, [f"{k}\n({data[k][0]['points']} points)" for k in kinds])
    ax[0].set_yscale("log")
    lo, hi = ax[0].get_ylim()
    ax[0].set_ylim(lo, hi * 30)  # room for the annotations
    ax[0].set_ylabel("points per second (end to end)")
    ax[0].set_title("sweep throughput, speed-up 1 -> 2 workers")
    ax[0].legend(fontsize=8, loc="upper left")
    wr = data["write_rate"]["batches"]
    ax[1].plot([b["mb_after"] for b in wr], [b["curves_per_s"] for b in wr], "o-")
    ax[1].set_xlabel("store size after the batch (MB)")
    ax[1].set_ylabel("curves written per second")
    ax[1].set_title(f"store: batches of {wr[0]['batch']} curves (copy + append)")
    ax[1].set_ylim(bottom=0)
    st, ov = data["startup"], data["task_overhead"]
    labels = ["import numpy,\nscipy.sparse", "solve\n(closure)", "cluster\nstart", "cluster\nstop"]
    vals = [st["import_numpy_scipy_sparse"], st["solve_closure"], ov["cluster_start_s"],
            ov["cluster_stop_s"]]
    ax[2].bar(labels, vals, color=["0.6", "C0", "C3", "C3"])
    ax[2].set_ylabel("seconds")
    ax[2].set_title(f"start-up; per task {ov['per_task_s_median'] * 1e3:.2f} ms")
    fig.suptitle(f"bench_sweep on {os.cpu_count()} cores (shared; load averages annotated)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meniscus-points", type=int, default=2000)
    ap.add_argument("--closure-points", type=int, default=100_000)
    ap.add_argument("--chart-only", action="store_true", help="redraw the chart from the JSON")
    args = ap.parse_args()
    if args.chart_only:
        chart(json.loads((RESULTS / "sweep.json").read_text()), RESULTS / "sweep.png")
        return
    data: dict = {"definitions": {
        "point": "one (scene, model) pair = one ForceCurve in the store",
        "meniscus": "equal-sphere bridge R = 50 um, LHS over V/R^3 in [1e-3, 0.05] (log) and "
                    "theta in [0, 40] deg, meniscus at preset fast, 5 gaps 0.01-0.4 V^(1/3)",
        "closures": "same bridges with 10 gaps, each scene solved by willett, willett-simple, "
                    "bagheri, mikami, rabinovich (N/5 scenes x 5 closures)"},
        "load_at_start": load()}
    with tempfile.TemporaryDirectory(prefix="bench-sweep-") as d:
        tmp = Path(d)
        data["startup"] = startup()
        print("startup", data["startup"], flush=True)
        data["task_overhead"] = task_overhead()
        print("overhead", data["task_overhead"], flush=True)
        data["write_rate"] = write_rate(tmp)
        print("write rate", data["write_rate"]["batches"][-1], flush=True)
        men = [Point(sc, "meniscus", "fast")
               for sc in bridges(args.meniscus_points, [0.01, 0.05, 0.1, 0.2, 0.4], seed=1)]
        clo = [Point(sc, m) for sc in bridges(args.closure_points // len(CLOSURES),
                                               list(np.geomspace(0.01, 0.4, 10)), seed=2)
               for m in CLOSURES]
        previous = (json.loads((RESULTS / "sweep.json").read_text())
                    if (RESULTS / "sweep.json").exists() else {})
        for name, pts in (("meniscus", men), ("closures", clo)):
            if not pts and name in previous:  # --<name>-points 0: keep the last run's figures
                data[name] = previous[name]
                data[f"{name}_speedup"] = previous[f"{name}_speedup"]
                data[f"{name}_from_previous_run"] = True
                continue
            data[name] = []
            for w in (1, 2):
                data[name].append(run_sweep(pts, w, tmp))
                print(name, data[name][-1], flush=True)
            data[f"{name}_speedup"] = (data[name][0]["wall_time_s"]
                                       / data[name][1]["wall_time_s"])
    data["load_at_end"] = load()
    print("json:", write_json("sweep", data))
    chart(data, RESULTS / "sweep.png")


if __name__ == "__main__":
    main()
