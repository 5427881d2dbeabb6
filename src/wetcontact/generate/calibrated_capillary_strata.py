"""The held-out designs of the calibrated capillary tables
(:mod:`wetcontact.generate.calibrated_capillary`): seeded bridges disjoint from the nodes,
each with its rupture distance and the force at fractions of it, and the stress strata
where a tensor interpolant errs most.

- The uniform design (:func:`held_out_design`): v log-uniform over the domain, the angles
  uniform, the radius ratio log-uniform, gaps at uniform fractions of S_c in [0, 0.999].
- Nearly equal spheres around the split angle (:data:`NEAR_EQUAL`), where the fold of
  unequal spheres unfolds the equal spheres' bifurcation.
- With two angles, the other angle near the ridge of S_c (:data:`NEAR_RIDGE_DEG`), at its
  sharp top (:data:`RIDGE_TOP_BAND_DEG`), at sphere angles where its jump appears
  (:data:`RIDGE_ONSET`) and within the ridge's window (:func:`ridge_window_band`): the
  two-angle wall table's strata are :data:`WALL_STRATA`, the sphere pairs'
  ``calibrated_capillary_pairs.PAIR_STRATA``.
- The corners (:func:`corner_design`): every combination of both ends and the middle of
  each axis (:data:`CORNER_LEVELS`), at gaps toward rupture (:data:`CORNER_FRACTIONS`),
  where an error of S_c is amplified by the fold's square root.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from wetcontact.reduced_models import calibrated_capillary as cc

NEAR_EQUAL = {"radius_ratio": (1.0, 1.1), "theta_deg": (20.0, 45.0)}
"""The stress stratum of sphere pairs: nearly equal spheres around the split angle, where
the fold of unequal spheres unfolds the equal spheres' bifurcation."""


NEAR_RIDGE_DEG = 3.0
"""The stress stratum of a wall with two angles: the wall angle within this of the rupture
distance's ridge (where the pieces meet)."""
RIDGE_TOP_BAND_DEG = (1e-4, cc.RIDGE_TOP_ZONE_DEG)
"""The ridge-top stratum of a wall with two angles: the wall angle's distance from the
ridge log-uniform in this range (deg), on either side: the sharp top of S_c, which a
uniform draw over :data:`NEAR_RIDGE_DEG` rarely comes close to."""
RIDGE_WINDOW_FLOOR_DEG = 1e-7
"""The ridge-window stratum's least distance from the ridge series (deg)."""


def ridge_window_band(kind: str) -> tuple[float, float]:
    """The ridge-window stratum's range of distances (deg) from a two-angle table's ridge
    series, log-uniform on either side: :data:`RIDGE_WINDOW_FLOOR_DEG` to the table's
    :data:`~wetcontact.reduced_models.calibrated_capillary.RIDGE_WINDOW_DEG`, where the true
    ridge may lie on the other side of the point, so that the table evaluates the other
    side of S_c's jump (the ridge-top stratum starts at 1e-4 deg)."""
    return (RIDGE_WINDOW_FLOOR_DEG, cc.RIDGE_WINDOW_DEG[kind])


RIDGE_ONSET = {"theta_sphere_deg": (17.5, 35.0), "theta_wall_deg_from_ridge": (1e-4, 3e-2)}
"""The ridge-onset stratum of a wall with two angles: the sphere angles where the jump of
S_c at the ridge's top appears (the onset angle theta_on(V) runs from 29.9 to 18.1 deg),
with the wall angle's distance from the table's ridge series log-uniform in the second
range (deg), on either side: where a series that does not follow the locus's curvature
kink at the onset misses the true top (one table over [0, 35] deg: by up to 1.2e-2 deg,
and 1.5e-3 off the rupture distance here), so that the table evaluates the other side's
arm. The ridge-top stratum, over all sphere angles and out to 0.3 deg, rarely lands in
that sliver. Its maximum has a long tail (of that table: the worst of 60 bridges was
1.3e-3, of 200 others 1.7e-3), so it has twice the uniform design's bridges."""


def held_out_design(kind: str, n: int, gaps_per: int, seed: int,
                    near_equal: bool = False, near_ridge: dict[str, Any] | None = None,
                    ridge_band: tuple[float, float] | None = None,
                    theta_range: tuple[float, float] | None = None,
                    theta2_range: tuple[float, float] | None = None,
                    v_range: tuple[float, float] | None = None,
                    fractions: tuple[float, ...] | None = None) -> list[dict[str, Any]]:
    """Seeded bridges (v log-uniform, theta uniform, ratio log-uniform; in the
    :data:`NEAR_EQUAL` ranges if ``near_equal``) with ``gaps_per`` uniform fractions of the
    rupture distance in [0, 0.999] each. With two angles (a wall's, or the large sphere's)
    the other angle is uniform too, or, given a table ``near_ridge``, within
    :data:`NEAR_RIDGE_DEG` of its ridge, uniformly, or (``ridge_band``, deg) at a distance
    log-uniform in that band on either side (redrawn until inside the domain).
    ``theta_range`` (deg): the (small sphere's) angle's range, default the whole domain's;
    ``theta2_range`` (deg) the other angle's, ``v_range`` the volume's (V/R_s^3);
    ``fractions``: these fractions of the rupture distance on every bridge instead of
    random ones (``gaps_per`` ignored)."""
    rng = np.random.default_rng(seed)
    r_hi = NEAR_EQUAL["radius_ratio"][1] if near_equal else cc.RATIO_RANGE[1]
    th = (NEAR_EQUAL["theta_deg"] if near_equal else
          cc.THETA_RANGE_DEG if theta_range is None else theta_range)
    out = []
    while len(out) < n:
        row = {"v": float(np.exp(rng.uniform(*np.log(v_range or cc.V_RANGE)))),
               "theta_deg": float(rng.uniform(*th)),
               "ratio": (float(np.exp(rng.uniform(0.0, math.log(r_hi))))
                         if kind in ("sphere-sphere", cc.PAIR_TWO_ANGLES) else None),
               "theta_wall_deg": None,
               "fractions": (list(fractions) if fractions is not None else
                             np.sort(rng.uniform(0.0, 0.999, gaps_per)).tolist())}
        if kind in (cc.WALL_TWO_ANGLES, cc.PAIR_TWO_ANGLES):
            tw = rng.uniform(*(theta2_range or cc.THETA_RANGE_DEG))
            if near_ridge is not None:
                d = (rng.choice([-1.0, 1.0]) * math.exp(rng.uniform(*np.log(ridge_band)))
                     if ridge_band else rng.uniform(-NEAR_RIDGE_DEG, NEAR_RIDGE_DEG))
                tw = float(cc.ridge_deg(row["v"], row["theta_deg"], near_ridge,
                                        row["ratio"])) + d
                if not cc.THETA_RANGE_DEG[0] <= tw <= cc.THETA_RANGE_DEG[1]:
                    continue
            row["theta_wall_deg"] = float(tw)
        out.append(row)
    return out


CORNER_LEVELS = {"v": (cc.V_RANGE[0], math.sqrt(cc.V_RANGE[0] * cc.V_RANGE[1]), cc.V_RANGE[1]),
                 "theta_deg": (cc.THETA_RANGE_DEG[0], 0.5 * sum(cc.THETA_RANGE_DEG),
                               cc.THETA_RANGE_DEG[1]),
                 "ratio": (cc.RATIO_RANGE[0], math.sqrt(cc.RATIO_RANGE[0] * cc.RATIO_RANGE[1]),
                           cc.RATIO_RANGE[1])}
"""The corner stratum's levels per axis: both ends of the domain and its (geometric) middle.
A seeded uniform design seldom lands near a corner of the box, where a tensor interpolant
errs most (a small sphere at 70 deg against a solid at 0 deg: S_c 1-2.5e-4 off, five times
the uniform design's maximum on a wall)."""
CORNER_FRACTIONS = (1e-6, 0.5, 0.9, 0.99, 0.999)
"""Gaps of each corner bridge, in fractions of its rupture distance: at contact and toward
rupture, where an error of S_c is amplified by the fold's square root."""


def corner_design(kind: str) -> list[dict[str, Any]]:
    """The corner stratum's bridges of a table: every combination of :data:`CORNER_LEVELS`
    (volume, angle or angles, radius ratio between spheres) at the gaps
    :data:`CORNER_FRACTIONS`; with two angles only combinations whose angles differ (equal
    ones are the one-angle table's)."""
    pair = kind in ("sphere-sphere", cc.PAIR_TWO_ANGLES)
    two = kind in (cc.WALL_TWO_ANGLES, cc.PAIR_TWO_ANGLES)
    lv = CORNER_LEVELS
    out = []
    for v, th, th2, ratio in itertools.product(lv["v"], lv["theta_deg"],
                                               lv["theta_deg"] if two else (None,),
                                               lv["ratio"] if pair else (None,)):
        if two and th == th2:
            continue
        out.append({"v": float(v), "theta_deg": float(th), "ratio": ratio,
                    "theta_wall_deg": None if th2 is None else float(th2),
                    "fractions": list(CORNER_FRACTIONS)})
    return out


WALL_STRATA: dict[str, dict[str, Any]] = {
    "held_out": {"seed": 2611, "least": 1},
    "held_out_near_ridge": {
        "seed": 2613, "near_ridge": True, "part": 3,
        "stratum": {"theta_wall_deg_from_ridge": [-NEAR_RIDGE_DEG, NEAR_RIDGE_DEG]}},
    "held_out_ridge_top": {
        "seed": 2614, "ridge_band": RIDGE_TOP_BAND_DEG, "part": 2,
        "stratum": {"theta_wall_deg_from_ridge_abs_log_uniform": list(RIDGE_TOP_BAND_DEG)}},
    "held_out_ridge_onset": {
        "seed": 2615, "ridge_band": RIDGE_ONSET["theta_wall_deg_from_ridge"], "scale": 2,
        "theta_range": RIDGE_ONSET["theta_sphere_deg"],
        "stratum": {"theta_sphere_deg": list(RIDGE_ONSET["theta_sphere_deg"]),
                    "theta_wall_deg_from_ridge_abs_log_uniform":
                    list(RIDGE_ONSET["theta_wall_deg_from_ridge"])}},
    "held_out_ridge_onset_rupture": {
        "seed": 2617, "ridge_band": RIDGE_TOP_BAND_DEG,
        "theta_range": RIDGE_ONSET["theta_sphere_deg"], "fractions": CORNER_FRACTIONS,
        "stratum": {"theta_sphere_deg": list(RIDGE_ONSET["theta_sphere_deg"]),
                    "theta_wall_deg_from_ridge_abs_log_uniform": list(RIDGE_TOP_BAND_DEG)}},
    "held_out_ridge_window": {
        "seed": 2616, "ridge_band": ridge_window_band(cc.WALL_TWO_ANGLES), "part": 2,
        "fractions": CORNER_FRACTIONS,
        "stratum": {"theta_wall_deg_from_ridge_abs_log_uniform":
                    list(ridge_window_band(cc.WALL_TWO_ANGLES))}},
}
"""The two-angle wall table's held-out design (against ``meniscus``): the uniform design
and the strata near the ridge, at its top, where its jump appears (at random gaps, and at
the corners' gaps to 0.999 S_c over the ridge's top) and within the ridge's window
(:func:`ridge_window_band`, at the corners' gaps); the corner stratum besides
(:func:`strata_held_out`)."""
