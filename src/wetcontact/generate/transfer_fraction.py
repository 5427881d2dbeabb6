"""Generator of the ``calibrated_transfer_fraction`` closure (``data/transfer_fraction.json``
and its record ``data/transfer_fraction_record.json``):
``python -m wetcontact.generate transfer-fraction``.

The form is in :mod:`wetcontact.reduced_models.transfer_fraction`. Steps (one process; every
``meniscus`` solve kept in the user cache, :class:`~wetcontact.branch_cache.NodeCache`
``transfer_fraction-*.jsonl``, so that a killed run loses nothing):

1. the jump ``K(theta_s, y, xi)``: at each tensor Chebyshev-Lobatto node, bisection of
   ``f_s - 1/2`` in theta_l from ``theta_s`` up to 89.5 deg, to :data:`JUMP_TOL` deg
   (``K = theta_s`` between equal spheres, by symmetry);
2. ``theta_e(y, xi)``, where the series of K in theta_s reaches 70 deg (a root of the
   interpolant at the node's y, xi);
3. ``f_s`` at the nodes of the two side tables (``meniscus`` at its fast preset, 64
   elements); a node of the lower table whose theta_l would be negative (the lower side is
   empty or inside the band there: equal spheres at theta_s = 0) is filled by the
   Chebyshev series along theta_s through the other nodes;
4. the held-out table: a seeded Latin hypercube over the whole domain (bodies in either
   order), the reference ``meniscus`` at its default preset (128 elements), the closure's
   absolute error: max, mean, p95, where the max sits, the points in the band.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.branch_cache import NodeCache
from wetcontact.reduced_models import DATA_DIR
from wetcontact.reduced_models import transfer_fraction as tf

NODES = {"theta": 17, "y": 5, "xi": 9, "s": 7,
         "v": 9, "xi_upper": 5, "s_upper": 13,
         "theta_jump": 9, "y_jump": 5, "xi_jump": 9}
"""Chebyshev-Lobatto points per axis: the lower table (theta_s, ln V*, xi, the side
coordinate s), the upper table (v = theta_s/theta_e, ln V*, ``xi_upper``, ``s_upper``) and
the jump K (``theta_jump``, ``y_jump``, ``xi_jump``). Each grid nests in the finer ones of
its axis. Where the counts come from (held-out errors at other grids): near the jump f_s
turns over theta_s within about 10 deg (9 points along theta_s: 4e-3); K between 5 points
along xi is 0.02 deg off, which the steep f_s near the jump turns into 2e-3; along the
upper side f_s rises from 1/2 to 0.95 over 50 deg, which 7 points follow to 1.2e-3; 9
points along ln V* instead of 5 change the held-out max by 2e-6 and cost 30 % more."""
BAND_DEG = 0.2
"""d_min: the half-width of the band at the jump where the closure does not answer (deg)."""
JUMP_TOL = 5e-4
"""Bisection width of the jump (deg)."""
THETA_TOP = 89.5
"""Largest theta_l searched for the jump (deg)."""
FAST, DEFAULT = 64, 128
"""Elements of the meniscus meridian: the nodes (fast preset), the held-out reference."""
HELD_OUT = 200
SEED = 57
"""Seed of the held-out points (not 56: the errors at those points placed the nodes)."""


class Solver:
    """``f_s`` of one configuration (body 1 the smaller sphere of radius 1, body 2 of radius
    ``1/x`` or a wall), cached in the user cache."""

    def __init__(self, cache: NodeCache | None = None):
        self.cache = cache or NodeCache(prefix="transfer_fraction")
        self.solves = 0
        self.calls = 0
        self.seconds = 0.0
        self.near = {self._near(key): key for key in self.cache.rows}

    @staticmethod
    def _near(key: str) -> str:
        """The key with its angles to 1e-9 deg: a node whose angle was computed in another
        order of operations (another array layout, another process) is found again."""
        x, v, th_s, th_l, n = key.split("|")
        a, b = (float(t.removeprefix("np.float64(").removesuffix(")")) for t in (th_s, th_l))
        return f"{x}|{v}|{a:.9f}|{b:.9f}|{n}"

    def __call__(self, x: float, vstar: float, th_s: float, th_l: float,
                 n_elements: int = FAST) -> float:
        from wetcontact.solver.meniscus.division import transfer_fraction
        from wetcontact.solver.meniscus.geometry import Bridge

        key = f"{x!r}|{vstar!r}|{th_s!r}|{th_l!r}|{n_elements}"
        self.calls += 1
        got = self.cache.get(key) or self.cache.get(self.near.get(self._near(key), ""))
        if got is not None:
            return float(got[1][0])
        t0 = time.perf_counter()
        b = Bridge(radius=1.0, radius2=None if x == 0.0 else 1.0 / x,
                   contact_angle1=math.radians(th_s), contact_angle2=math.radians(th_l),
                   surface_tension=1.0)
        d = transfer_fraction(b, vstar, n_elements=n_elements)
        self.seconds += time.perf_counter() - t0
        self.solves += 1
        self.cache.put(key, d.rupture_distance, [d.fraction])
        self.near[self._near(key)] = key
        return d.fraction


def ratio_of(xi: float) -> float:
    """r_s/r_l = 1 - xi^3 (0: a wall)."""
    return float(max(1.0 - xi**3, 0.0)) if xi < 1.0 else 0.0


def find_jump(solve: Solver, x: float, vstar: float, th_s: float, guess: float) -> float:
    """theta_l where ``f_s`` crosses 1/2 (deg), bisected to :data:`JUMP_TOL` from a
    bracket around ``guess``."""
    def above(t: float) -> bool:
        return solve(x, vstar, th_s, t) > 0.5

    g = min(max(guess, th_s), THETA_TOP)
    if above(g):
        hi, step, lo = g, 1.0, None
        while lo is None:
            t = max(hi - step, th_s)
            if not above(t):
                lo = t
            elif t == th_s:
                return th_s  # no lower side
            else:
                hi, step = t, 2 * step
    else:
        lo, step, hi = g, 1.0, None
        while hi is None:
            t = min(lo + step, THETA_TOP)
            if above(t):
                hi = t
            elif t == THETA_TOP:
                raise RuntimeError(f"no jump below {THETA_TOP} deg (x {x}, V* {vstar}, "
                                   f"theta_s {th_s})")
            else:
                lo, step = t, 2 * step
    while hi - lo > JUMP_TOL:
        mid = 0.5 * (lo + hi)
        if above(mid):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def grids() -> dict[str, np.ndarray]:
    """Node coordinates: theta_s (deg), y = ln V*, xi, v, s (unit)."""
    y_lo, y_hi = (math.log(v) for v in tf.V_RANGE)
    return {"theta": tf.from_unit(tf.lobatto(NODES["theta"]), 0.0, tf.THETA_MAX),
            "theta_jump": tf.from_unit(tf.lobatto(NODES["theta_jump"]), 0.0, tf.THETA_MAX),
            "v": tf.from_unit(tf.lobatto(NODES["v"]), 0.0, 1.0),
            "y": tf.from_unit(tf.lobatto(NODES["y"]), y_lo, y_hi),
            "y_jump": tf.from_unit(tf.lobatto(NODES["y_jump"]), y_lo, y_hi),
            "xi": tf.from_unit(tf.lobatto(NODES["xi"]), 0.0, 1.0),
            "xi_upper": tf.from_unit(tf.lobatto(NODES["xi_upper"]), 0.0, 1.0),
            "xi_jump": tf.from_unit(tf.lobatto(NODES["xi_jump"]), 0.0, 1.0),
            "s": tf.lobatto(NODES["s"]), "s_upper": tf.lobatto(NODES["s_upper"])}


def jump_table(solve: Solver, g: dict[str, np.ndarray], log: Any = print,
               part: tuple[int, int] = (0, 1)) -> np.ndarray:
    """K at the nodes (theta_jump, y_jump, xi_jump), deg; with ``part = (i, n)`` only the
    xi nodes ``j`` with ``j % n == i`` (NaN elsewhere)."""
    nt, ny, nx = len(g["theta_jump"]), len(g["y_jump"]), len(g["xi_jump"])
    k = np.full((nt, ny, nx), np.nan)
    for jx, xi in enumerate(g["xi_jump"]):
        if jx % part[1] != part[0]:
            continue
        x = ratio_of(float(xi))
        for jy, y in enumerate(g["y_jump"]):
            prev = None
            for it, th in enumerate(g["theta_jump"]):
                if xi == 0.0:
                    k[it, jy, jx] = th
                    continue
                guess = th + (1.0 if prev is None else prev - g["theta_jump"][it - 1])
                k[it, jy, jx] = prev = find_jump(solve, x, math.exp(y), float(th), guess)
            log(f"  jump xi {xi:.3f} y {y:.2f}: K {np.round(k[:, jy, jx], 3).tolist()} "
                f"({solve.solves} solves, {solve.seconds:.0f} s)")
    return k


def theta_end(k: np.ndarray, g: dict[str, np.ndarray]) -> np.ndarray:
    """theta_e(y, xi): the root of the series of K in theta_s at 70 deg (70 if none)."""
    from scipy.optimize import brentq

    n = k.shape[0]
    out = np.empty(k.shape[1:])
    for jy in range(k.shape[1]):
        for jx in range(k.shape[2]):
            col = k[:, jy, jx]

            def kk(th: float, col: np.ndarray = col) -> float:
                w = tf.bary_weights(tf.to_unit(np.array([th]), 0.0, tf.THETA_MAX), n)
                return float((w @ col)[0])

            out[jy, jx] = (tf.THETA_MAX if kk(tf.THETA_MAX) <= tf.THETA_MAX
                           else brentq(lambda t: kk(t) - tf.THETA_MAX, 0.0, tf.THETA_MAX,
                                       xtol=1e-12))
    return out


def _fill_along_theta(t: np.ndarray) -> np.ndarray:
    """Missing (NaN) lower-table nodes: the Chebyshev series along theta_s through the
    others of their line."""
    out = t.copy()
    n = t.shape[0]
    u = tf.lobatto(n)
    for idx in np.ndindex(t.shape[1:]):
        col = t[(slice(None), *idx)]
        bad = np.isnan(col)
        if bad.any() and not bad.all():
            c = np.polynomial.chebyshev.chebfit(u[~bad], col[~bad], int((~bad).sum()) - 1)
            out[(slice(None), *idx)] = np.where(bad, np.polynomial.chebyshev.chebval(u, c),
                                                col)
    return out


def _on_jump_grid(k: np.ndarray, te: np.ndarray, g: dict[str, np.ndarray], jy: int,
                  jx: int) -> tuple[np.ndarray, float]:
    """(K along theta_s at the side tables' theta nodes, theta_e) at their y node ``jy``
    and the jump's xi node ``jx``: the jump table's own values where its grids have that
    node (the Lobatto grids are nested), else its series."""
    step = (len(g["y"]) - 1) // (len(g["y_jump"]) - 1)
    if jy % step == 0:
        col, t_e = k[:, jy // step, jx], float(te[jy // step, jx])
    else:
        y_lo, y_hi = (math.log(v) for v in tf.V_RANGE)
        w = tf.bary_weights(tf.to_unit(np.array([g["y"][jy]]), y_lo, y_hi),
                            len(g["y_jump"]))
        col, t_e = k[:, :, jx] @ w[0], float(te[:, jx] @ w[0])
    step_t = (len(g["theta"]) - 1) // (len(g["theta_jump"]) - 1)
    w_t = tf.bary_weights(tf.to_unit(g["theta"], 0.0, tf.THETA_MAX), len(col))
    series = w_t @ col
    return np.array([col[i // step_t] if i % step_t == 0 else series[i]
                     for i in range(len(g["theta"]))]), t_e


def side_tables(solve: Solver, k: np.ndarray, te: np.ndarray, g: dict[str, np.ndarray],
                log: Any = print, part: tuple[int, int] = (0, 1)
                ) -> tuple[np.ndarray, np.ndarray, int]:
    """The lower and the upper table's node values, and how many lower nodes were filled;
    with ``part = (i, n)`` only the lines (xi node ``jx``, y node ``jy``) with
    ``(jx * ny + jy) % n == i`` of each table."""
    nt, ny, nx, ns = len(g["theta"]), len(g["y"]), len(g["xi"]), len(g["s"])
    lower = np.full((nt, ny, nx, ns), np.nan)
    upper = np.full((len(g["v"]), ny, len(g["xi_upper"]), len(g["s_upper"])), np.nan)
    nj = len(g["xi_jump"]) - 1
    for jx, xi in enumerate(g["xi"]):
        x = ratio_of(float(xi))
        for jy, y in enumerate(g["y"]):
            if (jx * ny + jy) % part[1] != part[0]:
                continue
            col = _on_jump_grid(k, te, g, jy, jx * nj // (nx - 1))[0]
            for it, th in enumerate(g["theta"]):
                kn = col[it]
                for js, s in enumerate(g["s"]):
                    tl = kn - float(tf.side_distance(s, kn, BAND_DEG))
                    if -1e-9 * max(kn, 1.0) < tl < 0.0:  # theta_l = 0 at s = 1, rounded
                        tl = 0.0
                    if tl >= 0.0:
                        lower[it, jy, jx, js] = solve(x, math.exp(y), float(th), tl)
        log(f"  lower xi {xi:.3f} ({solve.solves} solves, {solve.seconds:.0f} s)")
    g_j = {**g, "theta": g["theta_jump"]}
    for jx, xi in enumerate(g["xi_upper"]):
        x = ratio_of(float(xi))
        for jy, y in enumerate(g["y"]):
            if (jx * ny + jy) % part[1] != part[0]:
                continue
            col_j, te_n = _on_jump_grid(k, te, g_j, jy, jx * nj // (len(g["xi_upper"]) - 1))
            for iv, v in enumerate(g["v"]):
                th = float(v * te_n)
                w = tf.bary_weights(tf.to_unit(np.array([th]), 0.0, tf.THETA_MAX),
                                    len(col_j))
                kq = float((w @ col_j)[0])
                dmax = BAND_DEG + float(tf.upper_width(kq))
                for js, s in enumerate(g["s_upper"]):
                    tl = kq + float(tf.side_distance(s, dmax, BAND_DEG))
                    upper[iv, jy, jx, js] = solve(x, math.exp(y), th, tl)
        log(f"  upper xi {xi:.3f} ({solve.solves} solves, {solve.seconds:.0f} s)")
    filled = int(np.isnan(lower).sum())
    return _fill_along_theta(lower), upper, filled


def held_out_points(n: int = HELD_OUT, seed: int = SEED) -> list[dict[str, Any]]:
    """A seeded Latin hypercube over the domain: a wall (a quarter of the points) or R_l/R_s
    log-uniform in [1, 10], body 1 the smaller or the larger, theta1, theta2 in [0, 70] deg,
    ln V* uniform; R_small = 1 mm."""
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=6, seed=seed).random(n)
    lo, hi = (math.log(v) for v in tf.V_RANGE)
    pts = []
    for row in u:
        wall = row[0] < 0.25
        ratio = math.exp(math.log(tf.RATIO_MAX) * (row[0] - 0.25) / 0.75) if not wall else None
        small_first = row[1] < 0.5
        rs = 1e-3
        rl = None if wall else rs * ratio
        r1, r2 = (rs, rl) if (small_first or wall) else (rl, rs)
        pts.append({"r1": r1, "r2": r2, "volume": math.exp(lo + (hi - lo) * row[2]) * rs**3,
                    "theta1_deg": 70.0 * row[3], "theta2_deg": 70.0 * row[4]})
    return pts


def reference(p: dict[str, Any], solve: Solver) -> float:
    """``meniscus``'s transfer_fraction of a held-out point (default preset), body 1 as
    given."""
    r1, r2 = p["r1"], p["r2"]
    rs = r1 if r2 is None else min(r1, r2)
    swap = r2 is not None and r1 > r2
    x = 0.0 if r2 is None else min(r1, r2) / max(r1, r2)
    th_s, th_l = ((p["theta2_deg"], p["theta1_deg"]) if swap
                  else (p["theta1_deg"], p["theta2_deg"]))
    f_s = solve(x, p["volume"] / rs**3, th_s, th_l, n_elements=DEFAULT)
    return 1.0 - f_s if swap else f_s


def held_out_table(points: list[dict[str, Any]], refs: list[float],
                   table: tf.Table | None = None) -> dict[str, Any]:
    """Closure against the references: max, mean, p95 (outside the band), where the max
    sits, and the points in the band."""
    f = np.array([tf.calibrated_transfer_fraction(p["r1"], p["r2"], p["volume"],
                                                  p["theta1_deg"], p["theta2_deg"],
                                                  table=table) for p in points])
    ref = np.asarray(refs)
    ok = np.isfinite(f)
    err = np.abs(f - ref)
    e = err[ok]
    i = int(np.flatnonzero(ok)[np.argmax(e)])
    return {"points": len(points), "in_band": int((~ok).sum()), "max": float(e.max()),
            "mean": float(e.mean()), "p95": float(np.percentile(e, 95)),
            "max_at": {**points[i], "f_ref": float(ref[i]), "f": float(f[i])}}


def _part(job: tuple[str, int, int, int]) -> tuple[int, float]:
    """One worker's share of a step (``jump``, ``sides`` or ``held-out``): the xi nodes (or
    held-out points) ``j % n == i``, solved into the shared cache; (solves, seconds)."""
    step, i, n, n_held_out = job
    solve, g = Solver(), grids()
    quiet = lambda *_: None  # noqa: E731
    if step == "held-out":
        for p in held_out_points(n_held_out)[i::n]:
            reference(p, solve)
    else:
        k = jump_table(solve, g, quiet, part=(i, n) if step == "jump" else (0, 1))
        if step == "sides":
            side_tables(solve, k, theta_end(k, g), g, quiet, part=(i, n))
    return solve.solves, solve.seconds


def _in_workers(step: str, workers: int, n_held_out: int, log: Any) -> None:
    """Solve a step's nodes on ``workers`` processes (each appends to the cache file)."""
    from concurrent.futures import ProcessPoolExecutor

    t0 = time.perf_counter()
    with ProcessPoolExecutor(workers) as ex:
        done = list(ex.map(_part, [(step, i, workers, n_held_out) for i in range(workers)]))
    log(f"  {step}: {sum(d[0] for d in done)} solves on {workers} processes, "
        f"{time.perf_counter() - t0:.0f} s")


def generate_transfer_fraction(out: Path | None = None, record: Path | None = None,
                               n_held_out: int = HELD_OUT, log: Any = print,
                               workers: int = 1) -> dict[str, Any]:
    """Build the tables, write the package data and its record; return the record. With
    ``workers > 1`` the jump, the side tables and the held-out references are solved on
    that many processes first (split by xi node), then assembled from the cache."""
    t0 = time.perf_counter()
    if workers > 1:
        for step in ("jump", "sides", "held-out"):
            _in_workers(step, workers, n_held_out, log)
    solve = Solver()
    g = grids()
    log(f"transfer-fraction: nodes {NODES}, cache {solve.cache.path}")
    k = jump_table(solve, g, log)
    te = theta_end(k, g)
    lower, upper, filled = side_tables(solve, k, te, g, log)
    data = {"schema_version": tf.SCHEMA_VERSION, "band_deg": BAND_DEG,
            "y_range": [math.log(v) for v in tf.V_RANGE], "nodes": NODES,
            "axes": {"jump": ["theta_s", "y", "xi"], "theta_end": ["y", "xi"],  # xi_jump
                     "lower": ["theta_s", "y", "xi", "s"], "upper": ["v", "y", "xi", "s"]},
            "jump": np.round(k, 10).tolist(), "theta_end": np.round(te, 10).tolist(),
            "lower": np.round(lower, 12).tolist(), "upper": np.round(upper, 12).tolist()}
    out = out or DATA_DIR / tf.TRANSFER_FILE
    out.write_text(json.dumps(data, separators=(",", ":")) + "\n")
    build_s = time.perf_counter() - t0
    table = tf.Table(data)
    pts = held_out_points(n_held_out)
    t1 = time.perf_counter()
    refs = []
    for i, p in enumerate(pts):
        refs.append(reference(p, solve))
        if (i + 1) % 50 == 0:
            log(f"  held-out {i + 1}/{len(pts)}")
    ho = held_out_table(pts, refs, table)
    rec = {"command": "python -m wetcontact.generate transfer-fraction",
           "file": out.name, "nodes": NODES, "band_deg": BAND_DEG, "jump_tol_deg": JUMP_TOL,
           "node_elements": FAST, "reference_elements": DEFAULT,
           "lower_nodes_filled": filled, "solve_calls": solve.calls,
           "solves_this_run": solve.solves, "solve_time_this_run_s": round(solve.seconds, 1),
           "build_wall_time_this_run_s": round(build_s, 1),
           "note": "solves found in the user cache (NodeCache transfer_fraction-*) are not "
                   "solved again: the times are this run's; from scratch, solve_calls "
                   "solves (0.15-0.3 s each at 64 elements on the shared 2-core machine)",
           "held_out": {**ho, "seed": SEED, "reference": "meniscus transfer_fraction, "
                        f"{DEFAULT} elements (default preset)",
                        "wall_time_s": round(time.perf_counter() - t1, 1)},
           "held_out_points": [{**p, "f_ref": r} for p, r in zip(pts, refs, strict=True)]}
    rec_path = record or (out.parent / tf.RECORD_FILE)
    rec_path.write_text(json.dumps(rec, indent=1) + "\n")
    log(f"transfer-fraction: held-out max {ho['max']:.3g}, mean {ho['mean']:.3g}, p95 "
        f"{ho['p95']:.3g} ({ho['in_band']} of {ho['points']} in the band); "
        f"{build_s:.0f} s build")
    return rec
