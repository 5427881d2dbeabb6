"""Regeneration from scratch: what each shipped table costs, and where the time goes.

``python -m wetcontact.generate all`` rebuilds the package data (``generate/__main__.py``).
This benchmark does not run it (about 13 h for the two-angle sphere-pair table alone);
it counts, from the generators' own job builders and the shipped tables, the ``meniscus``
solves a from-scratch build needs, and times a small seeded sample of each kind of solve at
the preset the generator uses (a node branch at 19 gaps, a rupture-only branch, one search
of each kind), in an empty node cache (a temporary ``XDG_CACHE_HOME``). What it writes is
labelled:

- ``measured``: the sampled seconds per solve (median over the sample) and per search job
  (a sample of one or two jobs: their spread is the searches' own, several-fold);
- ``recorded``: wall times the package data's generation records state (tables built in
  one process: calibrated-viscous, bounds);
- ``projected``: solves x sampled seconds, single-core, and on N = 1, 2, 4 workers by
  Amdahl's law, ``T(N) = serial + parallel / N``, where the parallel part is the stages
  whose jobs run on ``--workers`` processes or Dask workers today (the capillary tables'
  node solves, searches and held-out bridges; the transfer fraction's solves) and the
  serial part everything else (tables built in one process; the tensor-train fits,
  recorded).

What would make it cheaper, measured on a seeded sample of the pair table's own nodes:
how far the node values (log S_c and log of the reduced force at the 19 gap nodes, what
the tables interpolate) move when the meridian has fewer elements than ``meniscus``'s
default 128, against what the solve then costs; and the overhead of the node solves on a
local Dask cluster of one worker (``--dask``). From the shipped coefficients (no solve):
how many nodes each axis of each piece needs for its Chebyshev tail to fall under 1e-5
and 1e-6 (twice the largest tail sum over the other axes: the interpolation error a piece
with that many nodes on that axis would add); the pair table's pieces on Smolyak sparse
grids in (w, a, b1) (points, and the coefficients' mass they drop); and how far series
from every other node of the onset and the ridge are from the searched values at the
others (the brackets nested searches could start from).

Writes ``benchmarks/results/regeneration.json``. Run:
``python benchmarks/bench_regeneration.py`` (about 10 minutes on the shared 2-core
machine; ``--quick``: no onset searches, about 5 minutes).
"""

from __future__ import annotations

import json
import math
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
# an empty node cache: "from scratch" (the user's cache is never read or written)
os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="wetcontact-regen-")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_json  # noqa: E402

from wetcontact.errors import SolverError  # noqa: E402
from wetcontact.generate import calibrated_capillary as gen  # noqa: E402
from wetcontact.generate import calibrated_capillary_pairs as p2  # noqa: E402
from wetcontact.reduced_models import DATA_DIR  # noqa: E402
from wetcontact.reduced_models import calibrated_capillary as cc  # noqa: E402

SEED = 54
NODE_SAMPLE = 8
"""Node solves timed per capillary kind (seeded among the table's own nodes)."""
ELEMENT_SAMPLE = 12
"""Pair-table nodes on which the node values are compared across element counts."""
ELEMENTS = (256, 128, 96, 64, 48)
WORKERS = (1, 2, 4)
BUDGET_S = 3600.0
"""The acceptance line: every table from scratch within 1 h on 2 cores."""
CAPILLARY = ("sphere-wall", "sphere-sphere", cc.WALL_TWO_ANGLES, cc.PAIR_TWO_ANGLES)


def shipped() -> dict[str, Any]:
    return json.loads((DATA_DIR / cc.CAPILLARY_FILE).read_text())


def node_jobs(data: dict[str, Any], kind: str) -> list[tuple]:
    """Every node job of a shipped capillary table, built as its generator builds them."""
    e = data[kind]
    jobs: list[tuple] = []
    if kind == cc.PAIR_TWO_ANGLES:
        for i, b in enumerate(e["bands"]):
            for spec, nodes in zip(p2.PAIR_PIECES, p2.pair_band_nodes(i), strict=True):
                jobs += p2.pair_piece_jobs(spec, nodes[3], e[cc.ONSET_KEY], b["theta_split"],
                                           nodes[0], tuple(b["theta_sphere_deg"]))[0]
    elif kind == cc.WALL_TWO_ANGLES:
        for i, b in enumerate(e["bands"]):
            for spec in gen.band_pieces(kind, i):
                jobs += gen.piece_jobs(kind, spec, b["theta_split"],
                                       tuple(b["theta_sphere_deg"]), e.get(cc.ONSET_KEY))[0]
    else:
        for spec in gen.PIECES[kind]:
            jobs += gen.piece_jobs(kind, spec, e["theta_split"])[0]
    return jobs


def search_jobs(kind: str) -> dict[str, int]:
    """The searches a from-scratch build runs (each a job of many rupture-only solves)."""
    if kind == "sphere-sphere":
        return {"split": gen.SPLIT_NODES}
    if kind == cc.WALL_TWO_ANGLES:
        return {"onset": gen.ONSET_NODES,
                "ridge": len(gen.TWO_ANGLE_BANDS_DEG) * math.prod(gen.RIDGE_NODES)}
    if kind == cc.PAIR_TWO_ANGLES:
        st = p2.STAGES["full"]
        lead = st["w"] * st["a"] * st["b1"]
        near = sum((nw - st["w"]) * st["a"] * st["b1"] for nw in p2.PAIR_RIDGE_W)
        return {"onset": (st["w"] - 1) * st["a"], "ridge": len(p2.PAIR_BANDS_DEG) * lead,
                "ridge_near": near}
    return {}


def held_out_bridges(entry: dict[str, Any]) -> int:
    return sum(v["bridges"] for k, v in entry.items() if k.startswith("held_out"))


class Counted:
    """``gen._branch_ends`` with a call counter (the searches' rupture-only solves)."""

    def __init__(self) -> None:
        self.calls = 0
        self.inner = gen._branch_ends

    def __call__(self, *args: Any) -> Any:
        self.calls += 1
        return self.inner(*args)


def time_search(counted: Counted, fn: Any, job: Any) -> dict[str, Any]:
    """One search job's seconds and rupture-only solves (and its error, if it fails: the
    generator's own node would not, this sample's may)."""
    counted.calls = 0
    t0 = time.perf_counter()
    try:
        fn(job)
    except (RuntimeError, SolverError) as exc:
        return {"seconds": round(time.perf_counter() - t0, 2), "solves": counted.calls,
                "failed": f"{type(exc).__name__}: {exc}"}
    return {"seconds": round(time.perf_counter() - t0, 2), "solves": counted.calls}


def sample_searches(data: dict[str, Any], quick: bool) -> dict[str, Any]:
    """One or two jobs of each search, timed and counted (measured)."""
    counted = Counted()
    gen._branch_ends = counted
    try:
        e = data[cc.PAIR_TWO_ANGLES]
        on = e[cc.ONSET_KEY]
        rs, vs = np.asarray(on["ratio_nodes"]), np.asarray(on["v_nodes"])
        out: dict[str, Any] = {"split": [time_search(counted, gen._split_job, 0.01)]}
        out["sphere-wall-two-angles ridge"] = [
            time_search(counted, gen._ridge_job, (0.01, 40.0)),
            time_search(counted, gen._ridge_job, (0.001, 10.0))]
        ridge = []
        for band, (i, j, k) in ((0, (5, 2, 4)), (1, (3, 4, 3))):
            b = e["bands"][band]["theta_split"]
            t1 = float(np.asarray(b["theta_small_nodes_deg"])[i, j, k])
            ridge.append(time_search(counted, p2._pair_ridge_job,
                                     (float(rs[i]), float(vs[j]), t1,
                                      p2.PAIR_RIDGE_TOL_DEG[band])))
        out["sphere-sphere-two-angles ridge"] = ridge
        # a w node the band's 17-node ridge series adds to the onset's 9 (odd index), its
        # guess off the top by the 9-node series' measured error there (1.6e-3 deg)
        b = e["bands"][1]["theta_split"]
        r17 = np.asarray(b["ratio_nodes"])
        near = []
        for i, j, k in ((7, 4, 3), (3, 6, 6)):
            top = float(np.asarray(b["at_nodes_deg"])[i, j, k])
            t1 = float(np.asarray(b["theta_small_nodes_deg"])[i, j, k])
            near.append(time_search(counted, p2._pair_ridge_near_job,
                                    (float(r17[i]), float(vs[j]), t1,
                                     p2.PAIR_RIDGE_TOL_DEG[1], top + 1.6e-3)))
        out["sphere-sphere-two-angles ridge_near"] = near
        if not quick:
            v_on = float(gen._volume_nodes(gen.ONSET_NODES)[5])  # one of the generator's
            out["sphere-wall-two-angles onset"] = [time_search(counted, gen._onset_job, v_on)]
            out["sphere-sphere-two-angles onset"] = [time_search(
                counted, p2._pair_onset_job, (float(rs[4]), float(vs[4])))]
    finally:
        gen._branch_ends = counted.inner
    return out


def sample_nodes(jobs: list[tuple], n: int, rng: np.random.Generator) -> dict[str, Any]:
    """Seconds per node solve at the generator's preset (default elements) and at 64."""
    pick = rng.choice(len(jobs), min(n, len(jobs)), replace=False)
    t128, t64 = [], []
    for k in pick:
        _, kind, r, v, t1, c, t2 = jobs[k]
        for el, acc in ((None, t128), (64, t64)):
            t0 = time.perf_counter()
            gen.solve_branch(kind, r, v, t1, c, t2, n_elements=el)
            acc.append(time.perf_counter() - t0)
    return {"sampled": len(pick), "s_per_solve": statistics.median(t128),
            "s_per_solve_64_elements": statistics.median(t64),
            "s_per_solve_all": [round(t, 3) for t in t128]}


def sample_rupture_only(jobs: list[tuple], n: int, rng: np.random.Generator) -> float:
    """Median seconds of a rupture-only branch (the searches' unit) at n of the nodes."""
    ts = []
    for k in rng.choice(len(jobs), min(n, len(jobs)), replace=False):
        _, kind, r, v, t1, c, t2 = jobs[k]
        t0 = time.perf_counter()
        gen._branch_ends(r, v, math.degrees(t1), math.degrees(t1 if t2 is None else t2))
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def element_study(jobs: list[tuple], n: int, rng: np.random.Generator) -> dict[str, Any]:
    """Node values at fewer (and more) elements than the default, on n pair-table nodes:
    the largest change of log S_c and of log q (q the reduced force at the 19 gap nodes)
    against the default 128, and the median seconds per solve."""
    rows = {el: {"seconds": [], "d_log_sc": [], "d_log_q": []} for el in ELEMENTS}
    for k in rng.choice(len(jobs), n, replace=False):
        _, kind, r, v, t1, c, t2 = jobs[k]
        got = {}
        for el in ELEMENTS:
            t0 = time.perf_counter()
            got[el] = gen.solve_branch(kind, r, v, t1, c, t2, n_elements=el)
            rows[el]["seconds"].append(time.perf_counter() - t0)
        for el in ELEMENTS:
            rows[el]["d_log_sc"].append(abs(math.log(got[el][0] / got[128][0])))
            rows[el]["d_log_q"].append(float(np.max(np.abs(np.log(got[el][1] / got[128][1])))))
    return {str(el): {"s_per_solve": statistics.median(r["seconds"]),
                      "max_d_log_sc": max(r["d_log_sc"]), "max_d_log_q": max(r["d_log_q"])}
            for el, r in rows.items()} | {"nodes": n}


def coefficient_tails(data: dict[str, Any]) -> dict[str, Any]:
    """Per piece of each capillary table: the nodes each axis needs for twice its largest
    Chebyshev tail sum (over the other axes) to fall under 1e-5 and 1e-6, for the rupture
    and the force tables together, and the node solves (lead-grid points) that implies."""
    out = {}
    for kind in CAPILLARY:
        e = data[kind]
        bands = e["bands"] if "bands" in e else [{"pieces": e["pieces"]}]
        for i, b in enumerate(bands):
            for j, p in enumerate(b["pieces"]):
                left = np.asarray(p["force_left"])
                force = np.tensordot(left, np.asarray(p["force_right"]),
                                     axes=([left.ndim - 1], [0]))
                row: dict[str, Any] = {"nodes": p["nodes"],
                                       "solves_now": math.prod(p["nodes"][:-1])}
                for tol in (1e-5, 1e-6):
                    need = [max(a, b) for a, b in zip(
                        [*axis_need(np.asarray(p["rupture"]), tol), 0],
                        axis_need(force, tol), strict=True)]
                    row[f"nodes_for_{tol:g}"] = need
                    row[f"solves_for_{tol:g}"] = math.prod(need[:-1])
                out[f"{kind} band {i} piece {j}"] = row
    return out


def axis_need(coef: np.ndarray, tol: float) -> list[int]:
    need = []
    for ax in range(coef.ndim):
        a = np.moveaxis(np.abs(coef), ax, 0)
        tail = np.cumsum(a[::-1], axis=0)[::-1]  # tail[m] = sum over j >= m
        m = next((m for m in range(1, a.shape[0]) if 2.0 * tail[m].max() <= tol), a.shape[0])
        need.append(m)
    return need


def _level(i: int) -> int:
    """Clenshaw-Curtis level of Chebyshev index i (levels 0, 1, 2, 3 hold 1, 3, 5, 9 nodes)."""
    return 0 if i == 0 else max(1, math.ceil(math.log2(i)))


def _delta(level: int) -> int:
    """Nodes a nested Lobatto level adds to the one below it."""
    return 1 if level == 0 else 2 if level == 1 else 2 ** (level - 1)


def sparse_lead(data: dict[str, Any]) -> dict[str, Any]:
    """The two-angle pair table's pieces on a Smolyak sparse grid in their lead axes (w, a,
    b1) instead of the tensor grid (b2 and c kept whole): per total level L, the lead
    points (nested Lobatto) and twice the largest sum of the shipped coefficients a sparse
    grid of that level drops (rupture and force): the error it would add, estimated."""
    out = {}
    for i, b in enumerate(data[cc.PAIR_TWO_ANGLES]["bands"]):
        for j, p in enumerate(b["pieces"]):
            left = np.asarray(p["force_left"])
            force = np.tensordot(left, np.asarray(p["force_right"]),
                                 axes=([left.ndim - 1], [0]))
            lv = [np.array([_level(k) for k in range(n)]) for n in p["nodes"][:3]]
            total = np.add.outer(np.add.outer(lv[0], lv[1]), lv[2])
            rows = []
            for level in range(4, int(total.max()) + 1):
                drop = total > level
                pts = sum(math.prod(_delta(x) for x in ls)
                          for ls in np.ndindex(*(int(v.max()) + 1 for v in lv))
                          if sum(ls) <= level)
                rows.append({"level": level, "lead_points": pts,
                             "rupture_added": float(2 * np.abs(np.asarray(p["rupture"]))[
                                 drop].sum(axis=0).max()),
                             "force_added": float(2 * np.abs(force)[drop].sum(axis=0).max())})
            out[f"band {i} piece {j}"] = {"lead_points_now": math.prod(p["nodes"][:3]),
                                          "levels": rows}
    return out


def nested_series(data: dict[str, Any]) -> dict[str, Any]:
    """How far the pair table's onset and ridge series from every other node (5 Lobatto
    nodes an axis, nested in 9) are from the searched values at the other nodes (deg): the
    bracket a search there could start from instead of the full one."""
    lob5, lob9 = gen.lobatto(5), gen.lobatto(9)
    p = np.ones((9, 5))
    for j, xj in enumerate(lob5):
        for m, xm in enumerate(lob5):
            if m != j:
                p[:, j] *= (lob9 - xm) / (xj - xm)

    def up(a: np.ndarray) -> np.ndarray:
        for ax in range(a.ndim):
            a = np.moveaxis(np.tensordot(p, np.moveaxis(a, ax, 0), axes=(1, 0)), 0, ax)
        return a

    e = data[cc.PAIR_TWO_ANGLES]
    on = np.asarray(e[cc.ONSET_KEY]["at_nodes_deg"])
    out = {"onset_max_deg": float(np.abs(up(on[::2, ::2]) - on).max())}
    for i, b in enumerate(e["bands"]):
        r = np.asarray(b["theta_split"]["at_nodes_deg"])
        r = r[::(r.shape[0] - 1) // 8]
        out[f"ridge band {i} max_deg"] = float(np.abs(up(r[::2, ::2, ::2]) - r).max())
    return out


def dask_sample(jobs: list[tuple], n: int, rng: np.random.Generator) -> dict[str, Any]:
    """n node jobs in this process and on a local Dask cluster of one worker (the
    generator's --dask): the cluster's start and the per-job overhead (measured; a
    2-core machine shared with other work cannot time 2 and 4 workers fairly)."""
    from wetcontact.generate.workers import map_jobs, open_workers

    pick = [jobs[k] for k in rng.choice(len(jobs), n + 2, replace=False)]
    warm, pick = pick[:2], pick[2:]  # a fresh worker's imports and first-call caches
    map_jobs(gen._node_job, warm, 1, "in process, warm-up")
    t0 = time.perf_counter()
    map_jobs(gen._node_job, pick, 1, "in process")
    here = time.perf_counter() - t0
    t0 = time.perf_counter()
    with open_workers(1, dask=True) as workers:
        start = time.perf_counter() - t0
        t1 = time.perf_counter()
        map_jobs(gen._node_job, warm, workers, "dask, warm-up")
        warm_s = time.perf_counter() - t1
        t1 = time.perf_counter()
        map_jobs(gen._node_job, pick, workers, "dask")
        there = time.perf_counter() - t1
    return {"jobs": n, "in_process_s": round(here, 2), "dask_1_worker_s": round(there, 2),
            "cluster_start_s": round(start, 2), "dask_warm_up_2_jobs_s": round(warm_s, 2)}


def amdahl(serial: float, parallel: float) -> dict[str, float]:
    return {str(n): round(serial + parallel / n, 1) for n in WORKERS}


def main() -> None:
    quick = "--quick" in sys.argv
    t_run = time.perf_counter()
    data = shipped()
    rng = np.random.default_rng(SEED)
    jobs = {k: node_jobs(data, k) for k in CAPILLARY}
    print({k: len(v) for k, v in jobs.items()}, flush=True)
    nodes = {k: sample_nodes(jobs[k], NODE_SAMPLE, rng) for k in CAPILLARY}
    print(nodes, flush=True)
    rupture_only = {k: sample_rupture_only(jobs[k], NODE_SAMPLE // 2, rng) for k in CAPILLARY}
    searches = sample_searches(data, quick)
    print(searches, flush=True)
    elements = element_study(jobs[cc.PAIR_TWO_ANGLES], ELEMENT_SAMPLE, rng)
    print(elements, flush=True)
    dask = dask_sample(jobs[cc.PAIR_TWO_ANGLES], 2 * NODE_SAMPLE, rng)
    print(dask, flush=True)
    tables: dict[str, Any] = {}
    for kind in CAPILLARY:
        s_node = nodes[kind]["s_per_solve"]
        stages = {"nodes": {"jobs": len(jobs[kind]), "solves": len(jobs[kind]),
                            "s_per_job_measured": s_node}}
        for name, n in search_jobs(kind).items():
            got = searches.get(name if name == "split" else f"{kind} {name}")
            if got is None:  # --quick: no onset search sampled
                stages[name] = {"jobs": n, "s_per_job_measured": None}
                continue
            per = statistics.mean(g["seconds"] for g in got)
            solves = statistics.mean(g["solves"] for g in got)
            stages[name] = {"jobs": n, "solves": round(n * solves),
                            "solves_per_job_measured": solves, "s_per_job_measured": per}
        n_ho = held_out_bridges(data[kind])
        stages["held_out"] = {"jobs": n_ho, "solves": n_ho, "s_per_job_measured": s_node}
        for st in stages.values():
            per = st["s_per_job_measured"]
            st["core_s_projected"] = None if per is None else round(st["jobs"] * per, 1)
        fits = data[kind].get("train_time_s", 0.0)
        parallel = sum(st["core_s_projected"] or 0.0 for st in stages.values())
        tables[f"calibrated-capillary {kind}"] = {
            "stages": stages, "rupture_only_s_per_solve_measured": rupture_only[kind],
            "solves_projected": sum(st.get("solves", 0) for st in stages.values()),
            "single_core_s_projected": round(parallel + fits, 1),
            "parallel_fraction_projected": round(parallel / (parallel + fits), 4),
            "workers_s_projected": amdahl(fits, parallel),
            "parallel_today": "process pool or Dask workers per stage, stages in turn",
            "resumable": "yes: every solved branch and search in the node cache"}
    viscous = json.loads((DATA_DIR / "calibrated_viscous.json").read_text())["wall_time_s"]
    bounds = json.loads((DATA_DIR / "bounds.json").read_text())["wall_time_s"]
    tf_rec = json.loads((DATA_DIR / "transfer_fraction_record.json").read_text())
    t_tf = sample_transfer_fraction(rng)
    for name, serial, what in (
            ("calibrated-viscous", viscous, "one process; not resumable"),
            ("bounds", bounds, "one process; not resumable")):
        tables[name] = {"single_core_s_recorded": serial, "parallel_fraction_projected": 0.0,
                        "workers_s_projected": amdahl(serial, 0.0), "parallel_today": what}
    t_tf_all = tf_rec["solve_calls"] * t_tf
    tables["transfer-fraction"] = {
        "solves": tf_rec["solve_calls"], "s_per_solve_measured_64_elements": t_tf,
        "single_core_s_projected": round(t_tf_all, 1), "parallel_fraction_projected": 1.0,
        "workers_s_projected": amdahl(0.0, t_tf_all),
        "parallel_today": "process pool (--workers N), each step's table lines split among "
                          "the processes; resumable (node cache)"}
    total = {str(n): round(sum(t["workers_s_projected"][str(n)] for t in tables.values()), 1)
             for n in WORKERS}
    core_s = sum(t.get("single_core_s_projected", t.get("single_core_s_recorded", 0.0))
                 for t in tables.values())
    nodes_64 = sum(len(jobs[k]) * nodes[k]["s_per_solve_64_elements"] for k in CAPILLARY)
    conclusion = {
        "all_on_2_workers_h_projected": round(total["2"] / 3600, 1),
        "budget_h_on_2_workers": BUDGET_S / 3600,
        "capillary_node_solves_alone_at_64_elements_on_2_workers_h_projected":
            round(nodes_64 / 2 / 3600, 1),
        "workers_for_1_h_at_perfect_scaling_projected": math.ceil(core_s / BUDGET_S),
        "speedup_needed_on_2_workers_projected": round(total["2"] / BUDGET_S, 1)}
    print(conclusion, flush=True)
    write_json("regeneration", {
        "conclusion": conclusion,
        "what": "from-scratch regeneration of every shipped table: solves counted from the "
                "generators' job builders, seconds per solve sampled (measured), times "
                "projected (single core, and on 1/2/4 workers by Amdahl's law)",
        "budget_s_on_2_cores": BUDGET_S,
        "all_workers_s_projected": total,
        "tables": tables,
        "searches_measured": searches,
        "node_solve_elements_measured": elements,
        "coefficient_tails": coefficient_tails(data),
        "pair_sparse_lead_grid": sparse_lead(data),
        "pair_nested_series": nested_series(data),
        "dask_measured": dask,
        "generate_all": {"exists": True, "command": "python -m wetcontact.generate all "
                         "[--workers N] [--dask | --scheduler ADDR]",
                         "dask": "the capillary tables' node solves and searches (--dask, "
                                 "--scheduler); the other tables in one process",
                         "resumable": "the capillary tables and transfer-fraction (node "
                                      "cache); calibrated-viscous and bounds start over"},
        "run_s": round(time.perf_counter() - t_run, 1),
        "quick": quick,
        "command": "python benchmarks/bench_regeneration.py" + (" --quick" if quick else "")})
    print(json.dumps({"all_workers_s_projected": total}))


def sample_transfer_fraction(rng: np.random.Generator, n: int = 4) -> float:
    """Median seconds of one transfer-fraction solve at its node preset (64 elements)."""
    from wetcontact.generate.transfer_fraction import FAST, Solver

    solve = Solver()
    ts = []
    for _ in range(n):
        t0 = time.perf_counter()
        solve(float(rng.uniform(0.1, 1.0)), float(10 ** rng.uniform(-3.5, -1.5)),
              float(rng.uniform(0, 60)), float(rng.uniform(0, 60)), FAST)
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


if __name__ == "__main__":
    main()
