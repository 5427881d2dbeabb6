"""Offline builder of the dynamic rupture table and its closure (``dynamic_rupture.json``).

Solves :func:`wetcontact.solver.stokes_dynamic.rupture.dynamic_rupture` (a bridge stretched
at constant speed to its pinch, default preset) on the fit grid :func:`fit_cases` and on
seeded held-out cases :func:`held_out_cases`, each result (or the reason a run failed)
appended to a JSON-lines cache in ``$XDG_CACHE_HOME/wetcontact`` as it arrives, so a killed
build loses nothing; then fits :mod:`wetcontact.reduced_models.dynamic_rupture`'s form to
the fit grid and measures it on the held-out cases. Run:
``python -m wetcontact.generate dynamic-rupture --workers N``.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.branch_cache import append_row, cache_file, read_rows
from wetcontact.errors import InputError, SolverError
from wetcontact.generate.workers import map_jobs
from wetcontact.reduced_models import DATA_DIR
from wetcontact.reduced_models import dynamic_rupture as dr
from wetcontact.solver.stokes_dynamic.rupture import (
    PAIR_THETA_MAX,
    START,
    RuptureCase,
    dynamic_rupture,
)

CAS = (1e-4, 1e-3, 1e-2, 0.1, 0.3)
VOLUMES = (1e-4, 1e-3, 1e-2)
THETAS = (10.0, 30.0, 50.0)
PAIR_THETAS = (10.0, 20.0, PAIR_THETA_MAX)
HELD_OUT = 12
SEED = 57
EDGE_CASES = (("wall", 1e-2, 0.1, 30.0), ("wall", 0.3, 0.1, 30.0), ("wall", 1e-4, 0.1, 10.0),
              ("wall", 1e-2, 1e-3, 60.0), ("wall", 0.1, 1e-3, 60.0),
              ("pair", 1e-2, 0.1, 30.0), ("pair", 0.3, 0.1, 10.0),
              ("pair", 1e-2, 1e-2, 20.0, 1e-3, 10.0))
"""Runs at the edges of the method's validity (V/R^3 = 0.1, 60 deg on a wall, Ca = 0.3 at
the largest volume, a sphere on one ten times larger), outside the closure's domain: the
stability map, not the fit."""
UNEQUAL_RATIOS = (2.0, 4.0)
"""R2/R of the unequal pairs: the upper (moving, unit) sphere is the smaller, so that the
volumes in R^3 stay in the solver's range; the closure's rho = R/R2 is 0.5 and 0.25."""
UNEQUAL_CAS = (1e-4, 1e-2, 0.3)
UNEQUAL_VOLUMES = (1e-3, 1e-2)
"""V/R*^3 of the unequal pairs (R* = 2 R R2/(R + R2))."""
UNEQUAL_THETAS = (10.0, PAIR_THETA_MAX)
UNEQUAL_HELD_OUT = 4
SOURCES = ("solver/meniscus", *(f"solver/stokes_dynamic/{m}.py" for m in
                                ("domain", "step", "run", "pinch", "rupture")))
"""What a run depends on (the cache file is per version of these sources)."""


def unequal_case(ca: float, volume_star: float, theta_deg: float, radius_ratio: float
                 ) -> RuptureCase:
    """The pair of spheres R and ``radius_ratio`` R holding ``V = volume_star R*^3``
    (:func:`~wetcontact.reduced_models.dynamic_rupture.effective_radius`)."""
    rs = dr.effective_radius(radius_ratio)
    return RuptureCase("pair", ca, round(float(volume_star * rs**3), 10), theta_deg,
                       radius_ratio=radius_ratio)


def fit_cases() -> list[RuptureCase]:
    """The fit grid: both kinds, Ca in :data:`CAS`, V/R^3 in :data:`VOLUMES`, theta in
    :data:`THETAS` (a wall) or :data:`PAIR_THETAS` (equal spheres); and unequal spheres
    (:data:`UNEQUAL_RATIOS`, :data:`UNEQUAL_CAS`, :data:`UNEQUAL_VOLUMES`,
    :data:`UNEQUAL_THETAS`)."""
    return ([RuptureCase(k, ca, v, th) for k, ths in (("wall", THETAS), ("pair", PAIR_THETAS))
             for ca in CAS for v in VOLUMES for th in ths]
            + [unequal_case(ca, v, th, q) for q in UNEQUAL_RATIOS for ca in UNEQUAL_CAS
               for v in UNEQUAL_VOLUMES for th in UNEQUAL_THETAS])


def held_out_cases(n: int = HELD_OUT, seed: int = SEED) -> list[RuptureCase]:
    """Seeded cases between the grid's: log-uniform Ca and V over the grid's ranges,
    uniform theta over the kind's range, the kinds alternating."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        ca = float(np.exp(rng.uniform(math.log(CAS[0]), math.log(CAS[-1]))))
        v = float(np.exp(rng.uniform(math.log(VOLUMES[0]), math.log(VOLUMES[-1]))))
        u = float(rng.uniform(0.0, 1.0))
        kind = "wall" if i % 2 == 0 else "pair"
        ths = THETAS if kind == "wall" else PAIR_THETAS
        th = ths[0] + u * (ths[-1] - ths[0])
        out.append(RuptureCase(kind, round(ca, 8), round(v, 8), round(th, 4)))
    return out


def unequal_held_out_cases(n: int = UNEQUAL_HELD_OUT, seed: int = SEED) -> list[RuptureCase]:
    """Seeded unequal pairs between the grid's: log-uniform Ca, V/R*^3 and R2/R over the
    grid's ranges, uniform theta."""
    rng = np.random.default_rng(seed + 1)
    out = []
    for _ in range(n):
        ca = float(np.exp(rng.uniform(math.log(UNEQUAL_CAS[0]), math.log(UNEQUAL_CAS[-1]))))
        v = float(np.exp(rng.uniform(math.log(UNEQUAL_VOLUMES[0]),
                                     math.log(UNEQUAL_VOLUMES[-1]))))
        q = float(np.exp(rng.uniform(0.0, math.log(UNEQUAL_RATIOS[-1]))))
        th = float(rng.uniform(UNEQUAL_THETAS[0], UNEQUAL_THETAS[-1]))
        out.append(unequal_case(round(ca, 8), round(v, 8), round(th, 4), round(q, 4)))
    return out


class RunCache:
    """Results of finished runs, one JSON line each (``key``, ``result`` or ``error``)."""

    def __init__(self, folder: Path | None = None):
        self.path = cache_file("dynamic_rupture", SOURCES, folder)
        self.rows: dict[str, dict[str, Any]] = {}
        self.refresh()

    def refresh(self) -> None:
        """Read the file again (another process may have added runs)."""
        self.rows.update((row["key"], row) for row in read_rows(self.path))

    @staticmethod
    def key(case: RuptureCase, preset: str) -> str:
        return json.dumps([asdict(case), preset], sort_keys=True)

    def put(self, row: dict[str, Any]) -> None:
        self.rows[row["key"]] = row
        append_row(self.path, row)


def solve_case(job: tuple[RuptureCase, str]) -> dict[str, Any]:
    """One run on a worker: ``{key, case, preset, result}`` or ``{..., error}``."""
    case, preset = job
    row: dict[str, Any] = {"key": RunCache.key(case, preset), "case": asdict(case),
                           "preset": preset}
    try:
        row["result"] = asdict(dynamic_rupture(case, preset))
    except SolverError as exc:
        row["error"] = str(exc)
    return row


def solve_all(cases: list[RuptureCase], workers: int, preset: str = "default",
              cache: RunCache | None = None) -> list[dict[str, Any]]:
    """Rows of ``cases``, from the cache or solved on ``workers`` processes (each appended
    to the cache as it arrives)."""
    cache = cache or RunCache()
    cache.refresh()
    todo = [(c, preset) for c in cases if RunCache.key(c, preset) not in cache.rows]
    if todo:
        map_jobs(solve_case, todo, workers, "dynamic-rupture",
                 on_result=lambda _job, row: cache.put(row))
    return [cache.rows[RunCache.key(c, preset)] for c in cases]


def _arrays(rows: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    """The closure's coordinates of the rows that reached the pinch: ``volume`` is V*
    (V/R*^3 of a pair), ``rho`` the radius ratio <= 1."""
    ok = [r for r in rows if "result" in r]
    wall = np.array([r["case"]["kind"] == "wall" for r in ok], dtype=bool)
    q = np.array([r["case"].get("radius_ratio", 1.0) for r in ok], dtype=float)
    v = np.array([r["case"]["volume"] for r in ok], dtype=float)
    vp, rho = dr.pair_coordinates(v, q)
    return {"wall": wall, "ca": np.array([r["case"]["capillary_number"] for r in ok]),
            "volume": np.where(wall, v, vp), "rho": np.where(wall, 1.0, rho),
            "theta": np.array([r["case"]["theta_deg"] for r in ok]),
            "ratio": np.array([r["result"]["ratio"] for r in ok])}


def held_out_errors(coef: dict[str, Any], rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Relative error of the closure's ratio S_c(Ca)/S_c on ``rows`` (and Pitois')."""
    a = _arrays(rows)
    fit = dr.ratio_form(coef, a["wall"], a["ca"], a["volume"], a["theta"], a["rho"])
    pit = 1.0 + np.sqrt(a["ca"])
    e, ep = np.abs(fit / a["ratio"] - 1.0), np.abs(pit / a["ratio"] - 1.0)
    i = int(np.argmax(e))
    return {"points": int(e.size), "max": float(e.max()), "mean": float(e.mean()),
            "p95": float(np.percentile(e, 95)), "pitois_max": float(ep.max()),
            "pitois_mean": float(ep.mean()),
            "max_at": {"kind": "wall" if a["wall"][i] else "pair", "ca": float(a["ca"][i]),
                       "volume": float(a["volume"][i]), "theta_deg": float(a["theta"][i]),
                       "rho": float(a["rho"][i])}}


def generate_dynamic_rupture(out: Path | None = None, workers: int = 1,
                             log: Any = print) -> dict[str, Any]:
    """Solve the grid and the held-out cases, fit, write the data and return it."""
    t0 = time.perf_counter()
    cache = RunCache()
    log(f"dynamic-rupture: {len(fit_cases())} grid and {HELD_OUT + UNEQUAL_HELD_OUT} held-out "
        f"runs, cache {cache.path}")
    grid = solve_all(fit_cases(), workers, cache=cache)
    held = solve_all(held_out_cases() + unequal_held_out_cases(), workers, cache=cache)
    edge = solve_all([RuptureCase(*c) for c in EDGE_CASES], workers, cache=cache)
    failed = [r for r in grid + held + edge if "error" in r]
    a = _arrays(grid)
    if a["ca"].size < 10:
        raise InputError(f"dynamic-rupture: {a['ca'].size} grid runs reached the pinch; at "
                         "least 10 to fit")
    coef = dr.fit_form(a["wall"], a["ca"], a["volume"], a["theta"], a["ratio"], rho=a["rho"])
    coef_ab = dr.fit_form(a["wall"], a["ca"], a["volume"], a["theta"], a["ratio"],
                          names=("a", "b"))
    data = {"schema_version": dr.SCHEMA_VERSION, "coefficients": coef,
            "coefficients_ab": coef_ab,
            "domain": {"capillary_number": [CAS[0], CAS[-1]],
                       "volume": [VOLUMES[0], VOLUMES[-1]],
                       "theta_deg": {"wall": [THETAS[0], THETAS[-1]],
                                     "pair": [PAIR_THETAS[0], PAIR_THETAS[-1]]},
                       "rho": [1.0 / UNEQUAL_RATIOS[-1], 1.0],
                       "kinds": ["wall", "pair"]},
            "fit": held_out_errors(coef, grid), "held_out": held_out_errors(coef, held),
            "fit_ab": held_out_errors(coef_ab, grid),
            "held_out_ab": held_out_errors(coef_ab, held),
            "start_over_static": START, "preset": "default",
            "command": "python -m wetcontact.generate dynamic-rupture",
            "wall_time_s": round(time.perf_counter() - t0, 1),
            "runs_wall_time_s": round(sum(r["result"].get("wall_time", 0.0)
                                          for r in grid + held + edge if "result" in r), 1),
            "runs": [{"case": r["case"], **({"result": r["result"]} if "result" in r
                                             else {"error": r["error"]}),
                      "held_out": len(grid) <= i < len(grid) + len(held),
                      "edge": i >= len(grid) + len(held)}
                     for i, r in enumerate(grid + held + edge)]}
    path = out or DATA_DIR / dr.DATA_FILE
    path.write_text(json.dumps(data, indent=1) + "\n")
    ho = data["held_out"]
    log(f"dynamic-rupture: fit {coef}; held-out max {ho['max']:.3g}, mean {ho['mean']:.3g} "
        f"(Pitois max {ho['pitois_max']:.3g}); {len(failed)} runs failed; {path}")
    return data
