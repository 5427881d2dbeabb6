"""A sphere-wall bridge stretched to rupture at Ca = 0.01 (issue 57's benchmark).

V/R^3 = 1e-3, contact angles 20 deg, slip lengths 1e-3 R, from S/R = 0.02 at constant
speed (Ca = eta v/sigma = 0.01), default mesh options, the steps of the rupture runs'
default preset (:data:`wetcontact.solver.stokes_dynamic.rupture.PRESETS`: the neck's local
error controlled, at most 5 % of the neck per step), stopped when the neck is 1.1 % of its
start and the pinch located from the neck's last decade (``locate_pinch``). The same run
at the accurate preset estimates the time error of the rupture distance. Reported beside
the static fold of ``meniscus`` and Pitois et al.'s (2001) ``S_c (1 + Ca^1/2)``; the goal is
<= 120 s on 2 cores for the default run.

Writes ``benchmarks/results/stokes_dynamic.json``. Run:
``.venv/bin/python benchmarks/bench_stokes_dynamic.py``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import write_json  # noqa: E402

from wetcontact.solver.meniscus import Bridge, rupture_distance  # noqa: E402
from wetcontact.solver.stokes_dynamic import (  # noqa: E402
    PAPAGEORGIOU,
    Stepping,
    Wetting,
    locate_pinch,
    run,
)
from wetcontact.solver.stokes_dynamic.rupture import PRESETS, gap_step  # noqa: E402

CA = 0.01
VOLUME = 1e-3
THETA = math.radians(20.0)
SLIP = 1e-3
GAP0 = 0.02


def stretch(preset: str, static_gap: float) -> dict:
    wet = Wetting(THETA, THETA, SLIP, SLIP)
    steps = PRESETS[preset]
    ds = gap_step(preset, static_gap)
    r = run(VOLUME, GAP0, CA, wet, Stepping(dt=ds / CA, gap_end=0.5, neck_stop=0.011,
                                            neck_step=steps.neck_step,
                                            tolerance=steps.tolerance))
    p = locate_pinch(r)
    every = max(1, r.time.size // 200)
    return {"preset": preset, "ds": ds, "neck_step": steps.neck_step,
            "tolerance": steps.tolerance, "wall_time_s": r.wall_time, "steps": r.steps,
            "remeshes": r.remeshes, "elements_end": r.diagnostics["elements"],
            "stopped": r.stopped, "rupture_gap": p.gap, "pinch_time": p.time,
            "neck_slope": p.slope, "neck_slope_spread": p.spread,
            "neck_window": list(p.radii),
            "volume_error_max": float(np.abs(r.volume / VOLUME - 1).max()),
            "history": {"time": r.time[::every].tolist(), "gap": r.gap[::every].tolist(),
                        "force": r.force[::every].tolist(),
                        "neck_radius": r.neck_radius[::every].tolist()}}


def main() -> None:
    br = Bridge(radius=1.0, contact_angle1=THETA, contact_angle2=THETA, surface_tension=1.0)
    sc = rupture_distance(br, VOLUME)
    default = stretch("default", sc)
    print(f"default: rupture S/R = {default['rupture_gap']:.6f} ({default['rupture_gap'] / sc:.4f}"
          f" S_c) in {default['wall_time_s']:.1f} s, {default['steps']} steps, "
          f"{default['remeshes']} remeshes, {default['elements_end']:.0f} elements", flush=True)
    fine = stretch("accurate", sc)
    print(f"accurate: rupture S/R = {fine['rupture_gap']:.6f} in {fine['wall_time_s']:.1f} s",
          flush=True)
    path = write_json("stokes_dynamic", {
        "case": {"ca": CA, "volume": VOLUME, "theta_deg": 20.0, "slip": SLIP, "gap0": GAP0},
        "static_fold": sc, "pitois": sc * (1 + math.sqrt(CA)),
        "papageorgiou_slope": PAPAGEORGIOU,
        "default": default, "fine": fine,
        "rupture_over_static_fold": default["rupture_gap"] / sc,
        "rupture_time_error_estimate": abs(default["rupture_gap"] - fine["rupture_gap"]),
        "goal_wall_time_s": 120.0,
        "conclusion": (f"rupture at {default['rupture_gap'] / sc:.3f} S_c (Pitois "
                       f"{1 + math.sqrt(CA):.3f}) in {default['wall_time_s']:.0f} s; the "
                       f"default and accurate presets differ by "
                       f"{abs(default['rupture_gap'] - fine['rupture_gap']):.1e} R")})
    print(path)


if __name__ == "__main__":
    main()
