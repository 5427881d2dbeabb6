"""Seeded scan for points where ``calibrated-capillary`` errs above the bound it reports.

The closure's relative capillary error against ``meniscus`` (default preset, the bound
tables' reference; the shooting solution of ``tests/solver/shooting.py`` agrees with it to
1e-10) is compared with the bound the closure reports (its ``error_estimate``: the bound
table's bin, floored by :meth:`CalibratedCapillary.bound_floor`, what ``select.choose``
reads) at every gap of seeded scenes with two contact angles:

- ``top``: sphere pairs with both angles uniform in 55-70 deg, R2/R1 log-uniform in 1-3,
  V/R_small^3 log-uniform over [1e-4, 0.1] (issue 58's first open break);
- ``low-pair`` and ``low-wall``: the (small) sphere's angle uniform in 0-20 deg, the other
  solid's angle 3-8 deg above or below the two-angle table's ridge
  (``calibrated_capillary.ridge_deg``), just outside its ridge zone
  (``RIDGE_ZONE_DEG``) where :meth:`bound_floor` floors the bound; pairs R2/R1 1-10.

Each scene is measured at S/S_c = the middle of each bin of
``generate.bounds.CC_S_OVER_SC_EDGES`` below 1 and at 0.05-0.95 in steps of 0.05. Prints
every gap with error > bound and, per region, how many scenes broke and the largest ratio;
``--json PATH`` writes the failing points.

Run: ``PYTHONPATH=src python benchmarks/scan_cc_bound_breaks.py [--n 60] [--seed 58]
[--regions top low-pair low-wall]``.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.generate.bounds import CC_S_OVER_SC_EDGES, make_scene, rel_error
from wetcontact.models import get_model, load_all
from wetcontact.reduced_models import calibrated_capillary as cc
from wetcontact.reduced_models.calibrated_capillary import RIDGE_ZONE_DEG, ridge_deg

R = 1.0e-3
EDGES = np.asarray(CC_S_OVER_SC_EDGES)
X = np.unique(np.round(np.concatenate([0.5 * (EDGES[:-1] + EDGES[1:])[EDGES[1:] <= 1.0],
                                       np.arange(0.05, 0.951, 0.05)]), 12))
"""S/S_c of every scene."""
OFFSET_DEG = (RIDGE_ZONE_DEG, RIDGE_ZONE_DEG + 5.0)
"""How far from the ridge (deg) the low-angle regions put the other solid's angle."""


def scenes(region: str, n: int, seed: int
           ) -> Iterator[tuple[str, float, float, tuple[float, float]]]:
    """``n`` seeded scenes of ``region``: (kind, R2/R1 (1 on a wall), V*, the (small)
    sphere's angle and the other solid's (deg))."""
    rng = np.random.default_rng([seed, {"top": 1, "low-pair": 2, "low-wall": 3}[region]])
    lv = np.log(cc.V_RANGE)
    for _ in range(n):
        if region == "top":
            ratio = float(np.exp(rng.uniform(0.0, math.log(3.0))))
            v = float(np.exp(rng.uniform(*lv)))
            yield "sphere-sphere", ratio, v, (float(rng.uniform(55.0, 70.0)),
                                              float(rng.uniform(55.0, 70.0)))
            continue
        kind = "sphere-sphere" if region == "low-pair" else "sphere-wall"
        ratio = 1.0 if kind == "sphere-wall" else float(
            np.exp(rng.uniform(0.0, math.log(cc.RATIO_RANGE[1]))))
        v = float(np.exp(rng.uniform(*lv)))
        th1 = float(rng.uniform(0.0, 20.0))
        side = 1.0 if rng.uniform() < 0.5 else -1.0
        off = float(rng.uniform(*OFFSET_DEG))
        ridge = float(ridge_deg(v, th1, ratio=ratio if kind == "sphere-sphere" else None))
        th2 = ridge + side * off
        if not 0.0 <= th2 <= cc.THETA_RANGE_DEG[1]:
            th2 = ridge - side * off
        yield kind, ratio, v, (th1, float(np.clip(th2, *cc.THETA_RANGE_DEG)))


def measure(kind: str, ratio: float, v: float, angles: tuple[float, float]
            ) -> dict[str, Any] | None:
    """Error against ``meniscus`` and the reported bound at :data:`X` S_c, or ``None``
    where the closure refuses the scene."""
    model, men = get_model("calibrated-capillary"), get_model("meniscus")
    r2 = None if kind == "sphere-wall" else R * ratio
    base = make_scene(kind, {"bridge_volume": v * R**3}, [1e-6], r2, angles)
    if model.applicable(base) is not None:
        return None
    sc = model.rupture_distance(base)
    scene = make_scene(kind, {"bridge_volume": v * R**3}, X * sc, r2, angles)
    curve = model.force(scene)
    err = rel_error(curve.force_capillary, men.force(scene).force_capillary)
    bound = np.asarray(curve.error_estimate, dtype=float)
    return {"kind": kind, "ratio": ratio, "v_star": v, "angles_deg": list(angles),
            "ridge_distance_deg": model.ridge_distance(scene), "s_c": sc, "x": X.tolist(),
            "error": err.tolist(), "bound": bound.tolist()}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=60)
    p.add_argument("--seed", type=int, default=58)
    p.add_argument("--regions", nargs="+", default=["top", "low-pair", "low-wall"])
    p.add_argument("--json", type=Path)
    args = p.parse_args()
    load_all()
    found = []
    for region in args.regions:
        t0, broke, worst = time.perf_counter(), 0, 0.0
        for i, (kind, ratio, v, angles) in enumerate(scenes(region, args.n, args.seed)):
            got = measure(kind, ratio, v, angles)
            if got is None:
                continue
            err, bound = np.asarray(got["error"]), np.asarray(got["bound"])
            bad = err > bound
            worst = max(worst, float(np.max(err / bound)))
            if bad.any():
                broke += 1
                found.append({"region": region, "scene": i, **got})
                for j in np.flatnonzero(bad):
                    print(f"{region} #{i}: r = {ratio!r}, V* = {v!r}, angles = {angles!r} "
                          f"(ridge {got['ridge_distance_deg']:.3g} deg away), S/S_c = "
                          f"{X[j]:g}: error {err[j]:.3g}, bound {bound[j]:.3g} "
                          f"({err[j] / bound[j]:.2f}x)", flush=True)
        print(f"{region}: {broke} of {args.n} scenes above the bound, largest error/bound "
              f"{worst:.2f}, {time.perf_counter() - t0:.0f} s", flush=True)
    if args.json:
        args.json.write_text(json.dumps(found, indent=1) + "\n")


if __name__ == "__main__":
    main()
