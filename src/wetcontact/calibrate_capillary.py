"""Generator of the shipped ``calibrated-capillary`` closure
(``python -m wetcontact.calibrate capillary``).

The closure's form and coordinates are in :mod:`wetcontact.reduced_models.calibrated_capillary`.
Here every tensor Chebyshev-Lobatto node of (w,) a, b is one volume-controlled
``meniscus`` branch (:func:`~wetcontact.solver.meniscus.force_separation_curve`), solved at
the gap nodes ``c`` of its own rupture distance; the coefficients follow by a discrete
cosine transform (interpolation, exact at the nodes). The held-out design is seeded and
disjoint from the nodes: random bridges, each with its rupture distance and the force at
random fractions of it, solved by the same ``meniscus`` branch machinery at those points.
"""

from __future__ import annotations

import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np
from scipy.fft import dctn

from wetcontact.reduced_models import calibrated_capillary as cc

NODES = {"sphere-wall": (10, 15, 19), "sphere-sphere": (9, 10, 17, 19)}
"""Lobatto nodes per axis: ((w,) a = ln v, b = theta, c = gap)."""


def lobatto(n: int) -> np.ndarray:
    """Chebyshev-Lobatto points ``-cos(pi k/(n-1))`` on [-1, 1], increasing."""
    return -np.cos(np.pi * np.arange(n) / (n - 1))


def lobatto_coefficients(values: np.ndarray) -> np.ndarray:
    """Chebyshev coefficients of the tensor interpolant through values at
    :func:`lobatto` points (a type-I DCT on each axis)."""
    c = dctn(values[tuple(slice(None, None, -1) for _ in values.shape)], type=1)
    for ax, n in enumerate(values.shape):
        c = c / (n - 1)
        for end in (0, -1):
            idx = [slice(None)] * values.ndim
            idx[ax] = end
            c[tuple(idx)] /= 2.0
    return c


def _axis_values(kind: str, nodes: tuple[int, ...]) -> list[np.ndarray]:
    """Physical values at the nodes: (ratio,) v, theta (rad)."""
    ends = [(math.log(cc.V_RANGE[0]), math.log(cc.V_RANGE[1])), cc.THETA_RANGE_DEG]
    if kind == "sphere-sphere":
        ends = [(0.0, cc.W_MAX), *ends]
    vals = [0.5 * (lobatto(n) * (hi - lo) + lo + hi) for n, (lo, hi) in zip(nodes, ends,
                                                                             strict=False)]
    vals[-2] = np.exp(vals[-2])
    vals[-1] = np.radians(vals[-1])
    if kind == "sphere-sphere":
        vals[0] = np.exp(vals[0] ** 3)
    return vals


def solve_branch(kind: str, ratio: float | None, v: float, theta: float,
                 c_nodes: np.ndarray) -> tuple[float, np.ndarray]:
    """``meniscus`` at one bridge (R_s = 1, sigma = 1): S_c and the reduced force
    ``F/(2 pi sigma R* 2 cos theta)`` at the gap coordinates ``c_nodes``."""
    from wetcontact.solver.meniscus import Bridge, force_separation_curve

    br = Bridge(radius=1.0, radius2=ratio, contact_angle1=theta, contact_angle2=theta,
                surface_tension=1.0)
    rho = cc.reduced_star(kind, ratio)
    eps = math.sqrt(v / (math.pi * rho))
    order = np.argsort(-np.asarray(c_nodes))  # c = 1 is S = 0

    def fractions(s_c: float) -> np.ndarray:
        f = cc.gap_from_coordinate(c_nodes[order], s_c, eps) / s_c
        f[0], f[-1] = max(f[0], 0.0), 1.0
        return f

    cur = force_separation_curve(br, v, fractions=fractions)
    q = np.empty(len(c_nodes))
    q[order] = -cur.force / (2.0 * math.pi * rho * 2.0 * math.cos(theta))
    return cur.rupture_distance, q


def _node_job(args: tuple) -> tuple[tuple[int, ...], float, np.ndarray]:
    idx, kind, ratio, v, theta, c_nodes = args
    s_c, q = solve_branch(kind, ratio, v, theta, c_nodes)
    return idx, s_c, q


def _map_jobs(fn, jobs: list, workers: int, label: str) -> list:
    """``fn`` over jobs on ``workers`` processes, a progress line on stderr every 10 %."""
    out, t0, step = [], time.perf_counter(), max(1, len(jobs) // 10)
    pool = ProcessPoolExecutor(max_workers=workers) if workers > 1 else None
    try:
        it = pool.map(fn, jobs, chunksize=4) if pool else map(fn, jobs)
        for k, r in enumerate(it, 1):
            out.append(r)
            if k % step == 0 or k == len(jobs):
                sys.stderr.write(f"{label}: {k}/{len(jobs)} branches, "
                                 f"{time.perf_counter() - t0:.0f} s\n")
                sys.stderr.flush()
    finally:
        if pool:
            pool.shutdown()
    return out


def fit_kind(kind: str, nodes: tuple[int, ...] | None = None, workers: int = 2
             ) -> dict[str, Any]:
    """Coefficients of one kind from ``meniscus`` at the tensor nodes."""
    nodes = nodes or NODES[kind]
    vals = _axis_values(kind, nodes[:-1])
    c_nodes = lobatto(nodes[-1])
    grid = np.meshgrid(*vals, indexing="ij")
    jobs = []
    for idx in np.ndindex(*nodes[:-1]):
        p = [g[idx] for g in grid]
        ratio = float(p[0]) if kind == "sphere-sphere" else None
        jobs.append((idx, kind, ratio, float(p[-2]), float(p[-1]), c_nodes))
    rup = np.empty(nodes[:-1])
    q = np.empty(nodes)
    for idx, s_c, qq in _map_jobs(_node_job, jobs, workers, f"calibrated-capillary {kind}"):
        v = grid[-2][idx]
        rup[idx] = math.log(s_c / v ** (1.0 / 3.0))
        q[idx] = np.log(qq)
    return {"nodes": list(nodes), "rupture": lobatto_coefficients(rup).tolist(),
            "force": lobatto_coefficients(q).tolist()}


def held_out_design(kind: str, n: int, gaps_per: int, seed: int) -> list[dict[str, Any]]:
    """Seeded bridges (v log-uniform, theta uniform, ratio log-uniform) with ``gaps_per``
    uniform fractions of the rupture distance in [0, 0.999] each."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        row = {"v": float(np.exp(rng.uniform(*np.log(cc.V_RANGE)))),
               "theta_deg": float(rng.uniform(*cc.THETA_RANGE_DEG)),
               "ratio": (float(np.exp(rng.uniform(0.0, math.log(cc.RATIO_RANGE[1]))))
                         if kind == "sphere-sphere" else None),
               "fractions": np.sort(rng.uniform(0.0, 0.999, gaps_per)).tolist()}
        out.append(row)
    return out


def _held_job(args: tuple) -> tuple[float, np.ndarray, np.ndarray]:
    from wetcontact.solver.meniscus import Bridge, force_separation_curve

    ratio, v, theta, fr = args
    br = Bridge(radius=1.0, radius2=ratio, contact_angle1=theta, contact_angle2=theta,
                surface_tension=1.0)
    cur = force_separation_curve(br, v, fractions=np.append(fr, 1.0))
    return cur.rupture_distance, cur.gap[:-1], -cur.force[:-1] / (2.0 * math.pi)


def held_out(kind: str, n: int = 120, gaps_per: int = 8, seed: int = 2611,
             workers: int = 2) -> dict[str, Any]:
    """Held-out error table of the shipped table against ``meniscus`` (relative errors of
    the rupture distance and of the force, max / mean / 95th percentile, where the maximum
    sits)."""
    design = held_out_design(kind, n, gaps_per, seed)
    jobs = [(d["ratio"], d["v"], math.radians(d["theta_deg"]), np.array(d["fractions"]))
            for d in design]
    res = _map_jobs(_held_job, jobs, workers, f"held-out {kind}")
    e_rup, e_f, where_r, where_f = [], [], [], []
    for d, (s_c, gaps, f) in zip(design, res, strict=True):
        ratio = None if d["ratio"] is None else np.array(d["ratio"])
        th = math.radians(d["theta_deg"])
        sc_hat = float(cc.rupture_star(kind, np.array(d["v"]), np.array(th), ratio))
        e_rup.append(abs(sc_hat / s_c - 1.0))
        where_r.append({k: d[k] for k in ("v", "theta_deg", "ratio") if d[k] is not None})
        f_hat, _ = cc.force_star(kind, np.full(gaps.shape, d["v"]), np.full(gaps.shape, th),
                              gaps, None if ratio is None else np.full(gaps.shape, ratio))
        e_f.extend(np.abs(f_hat / f - 1.0))
        where_f += [{**where_r[-1], "s_over_sc": float(x)} for x in d["fractions"]]

    def table(err: list[float], where: list[dict]) -> dict[str, Any]:
        e = np.asarray(err)
        return {"points": int(e.size), "max": float(e.max()), "mean": float(e.mean()),
                "p95": float(np.percentile(e, 95)), "max_at": where[int(np.argmax(e))]}

    return {"seed": seed, "reference": "meniscus (default elements)",
            "bridges": n, "rupture_distance": table(e_rup, where_r),
            "force": table(e_f, where_f)}


def generate_calibrated_capillary(out: Any = None, kinds: tuple[str, ...] = (
        "sphere-wall", "sphere-sphere"), workers: int = 2, n_held_out: int = 120
        ) -> dict[str, Any]:
    """Write ``data/calibrated_capillary.json``: per kind the tensor coefficients, their
    nodes and the held-out error table, and the wall time."""
    import json
    from pathlib import Path

    t0 = time.perf_counter()
    out = Path(out) if out else Path(cc.__file__).parent / "data" / cc.CAPILLARY_FILE
    old = json.loads(out.read_text()) if out.is_file() else {}
    data: dict[str, Any] = {
        "generated_by": "python -m wetcontact.calibrate capillary",
        "form": "see wetcontact.reduced_models.calibrated_capillary",
        "domain": {"v": list(cc.V_RANGE), "theta_deg": list(cc.THETA_RANGE_DEG),
                   "radius_ratio": list(cc.RATIO_RANGE)},
        "goals": {"force": 1e-3, "rupture_distance": 5e-4}}
    for kind in ("sphere-wall", "sphere-sphere"):
        if kind not in kinds:
            if kind in old:
                data[kind] = old[kind]
            continue
        t1 = time.perf_counter()
        data[kind] = fit_kind(kind, workers=workers)
        data[kind]["fit_time_s"] = round(time.perf_counter() - t1, 1)
        # the held-out check evaluates the new coefficients through the package reader
        tmp = {**data, kind: data[kind]}
        out.write_text(json.dumps(tmp) + "\n")
        cc.capillary_table.cache_clear()
        data[kind]["held_out"] = held_out(kind, n=n_held_out, workers=workers)
    data["wall_time_s"] = round(time.perf_counter() - t0, 1)
    out.write_text(json.dumps(data) + "\n")
    cc.capillary_table.cache_clear()
    return data
