"""Generator of the shipped ``calibrated-capillary`` closure
(``python -m wetcontact.generate calibrated-capillary``).

The closure's form and coordinates are in :mod:`wetcontact.reduced_models.calibrated_capillary`.
Here every tensor Chebyshev-Lobatto node of (w,) a, b (b within a theta piece) is one
volume-controlled
``meniscus`` branch (:func:`~wetcontact.solver.meniscus.force_separation_curve`), solved at
the gap nodes ``c`` of its own rupture distance; the coefficients follow by a discrete
cosine transform (interpolation, exact at the nodes). Sphere pairs are split in theta at the
angle where the equal-sphere branch's end changes from a fold to a bifurcation (a kink of
S_c at r = 1), located by bisection at Lobatto nodes in ln V (:func:`fit_split`); a wall
with two angles at the sphere angle where S_c's top over the wall angle becomes a jump
(:func:`fit_onset`) and at 35 deg, each table with its ridge (:func:`fit_ridge`). The
held-out design is seeded and disjoint from the nodes: random bridges, each with its
rupture distance and the force at random fractions of it, solved by the same ``meniscus``
branch machinery at those points; sphere pairs also on a stress stratum of nearly equal
spheres around the split angle (:data:`NEAR_EQUAL`). The nodes, the coefficients and their
compressed forms are in :mod:`wetcontact.generate.calibrated_capillary_series`, the
held-out designs and strata in :mod:`wetcontact.generate.calibrated_capillary_strata`.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.branch_cache import NodeCache
from wetcontact.errors import InputError, SolverError
from wetcontact.generate.calibrated_capillary_series import (  # re-exported
    FACTOR_LEFT_AXES,  # noqa: F401
    FACTOR_TOL,  # noqa: F401
    TRAIN_TOL,  # noqa: F401
    TRAINS,  # noqa: F401
    WALL_TRAINS,
    factor_table,
    gauss,  # noqa: F401
    lobatto,
    lobatto_coefficients,
    train_fits,  # noqa: F401
    train_of,  # noqa: F401
    train_piece,
    tt_svd,  # noqa: F401
)
from wetcontact.generate.calibrated_capillary_strata import (  # re-exported
    CORNER_FRACTIONS,
    CORNER_LEVELS,
    NEAR_EQUAL,  # noqa: F401
    NEAR_RIDGE_DEG,  # noqa: F401
    RIDGE_ONSET,  # noqa: F401
    RIDGE_TOP_BAND_DEG,  # noqa: F401
    RIDGE_WINDOW_FLOOR_DEG,  # noqa: F401
    WALL_STRATA,
    corner_design,
    held_out_design,
    ridge_window_band,  # noqa: F401
)
from wetcontact.generate.workers import map_jobs as _map_jobs
from wetcontact.reduced_models import calibrated_capillary as cc

PIECES: dict[str, list[dict[str, Any]]] = {
    "sphere-wall": [{"theta_deg": [0.0, 70.0], "nodes": [10, 15, 19]}],
    "sphere-sphere": [{"theta_deg": [0.0, None], "nodes": [13, 9, 11, 19]},
                      {"theta_deg": [None, 70.0], "nodes": [13, 9, 13, 19]}],
    cc.WALL_TWO_ANGLES: [{"theta_deg": [0.0, None], "nodes": [10, 9, 23, 19],
                          "theta_map": cc.RIDGE_QUADRATIC},
                         {"theta_deg": [None, cc.RIDGE_TOP_DEG], "nodes": [10, 9, 27, 19],
                          "theta_map": cc.RIDGE_QUADRATIC}],
}
"""Theta pieces per kind (``None``: the split angle, or the ridge on a wall with two angles)
and their Lobatto nodes per axis ((w,) a = ln v, b = theta within the piece, c = gap; two
angles on a wall: a, b1 = the sphere's angle within its band, b2 = the wall's angle within
the piece, c). Sphere pairs have 13 nodes in w: along the radius ratio at V* = 0.1 they
interpolate S_c to 1.5e-5 (17 to 5e-7). The two-angle wall table's piece above the ridge
has 27 Gauss nodes in b2 in every band: past the ridge near the onset angle the force's
approach to rupture changes within hundredths of a degree (the stratum
``held_out_ridge_onset_rupture``: 4.5e-4 at 0.999 S_c). ``docs/calibrated_capillary.md``
has how the counts were chosen."""
TWO_ANGLE_BANDS_DEG: tuple[tuple[float | None, float | None], ...] = (
    (0.0, None), (None, 35.0), (35.0, 70.0))
"""The sphere angle's ranges (``bands``) of the two-angle wall table, each a
table of its own (ridge series and pieces); ``None`` is the onset angle theta_on(V)
(:func:`fit_onset`), where S_c's jump at the ridge's top appears (29.9 deg at v = 1e-4 down
to 19.2 at 0.08). The ridge's locus has a kink of its curvature there (v = 0.08: its
second derivative drops from 0.021 to 0.0095 per deg, the slope continuous), and a series
across it converges slowly: one range over [0, 35] deg missed the true top by up to
1.2e-2 deg (v = 0.08, theta_s = 21 deg), one over [0, 70] by 1.6e-2. On either side the
locus is smooth (v = 0.08, 9 nodes: 2.2e-7 deg above the onset, 5e-5 below, where every
top is a smooth maximum and the pieces meet in the flat of S_c). 35 deg stays a break: the
upper table is the former upper half's (when there were two bands), its nodes reused."""
SPLIT_NODES = 7
"""Lobatto nodes in ln v of the split angle (equal spheres: fold below, bifurcation above)."""
SPLIT_BRACKET_DEG = (24.0, 36.0)
SPLIT_TOL_DEG = 2e-3


def _volume_nodes(n: int) -> np.ndarray:
    lo, hi = math.log(cc.V_RANGE[0]), math.log(cc.V_RANGE[1])
    return np.exp(0.5 * (lobatto(n) * (hi - lo) + lo + hi))


def _branch_ends(radius2: float | None, v: float, theta1_deg: float,
                 theta2_deg: float) -> Any:
    """The volume-controlled ``meniscus`` branch of a bridge (R = 1, sigma = 1), solved only
    at contact and at its end (its ``end`` and ``rupture_distance``)."""
    from wetcontact.solver.meniscus import Bridge, force_separation_curve

    br = Bridge(radius=1.0, radius2=radius2, contact_angle1=math.radians(theta1_deg),
                contact_angle2=math.radians(theta2_deg), surface_tension=1.0)
    return force_separation_curve(br, v, fractions=np.array([0.0, 1.0]))


def branch_end(theta_deg: float, v: float) -> str:
    """How the equal-sphere bridge's stable branch ends: ``fold`` or ``bifurcation``."""
    return _branch_ends(1.0, v, theta_deg, theta_deg).end


def bisect_change(above: Callable[[float], bool], bracket: tuple[float, float], tol: float,
                   what: str, v: float) -> float:
    """The angle (deg) where ``above(angle)`` turns true, bisected to ``tol`` within
    ``bracket`` (false at its lower end, true at its upper; else an error naming ``what``
    and the volume ``v``): the split and the onset angle's search, and a sphere pair's
    onset (:func:`wetcontact.generate.calibrated_capillary_pairs.pair_onset`)."""
    lo, hi = bracket
    if above(lo) or not above(hi):
        raise RuntimeError(f"calibrated-capillary: {what} not bracketed by {bracket} deg at "
                           f"V* = {v:.4g}")
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if above(mid) else (mid, hi)
    return 0.5 * (lo + hi)


def _split_job(v: float) -> float:
    """Bisection for the angle where the end changes from fold to bifurcation (to
    :data:`SPLIT_TOL_DEG`)."""
    return bisect_change(lambda t: branch_end(t, v) == "bifurcation", SPLIT_BRACKET_DEG,
                          SPLIT_TOL_DEG, "fold/bifurcation change", v)


def fit_split(workers: int = 2, cache_dir: Path | None = None) -> dict[str, Any]:
    """Chebyshev coefficients (in the volume coordinate a) of the split angle (deg)."""
    return _angle_series(_split_job, SPLIT_NODES, "split", None, SPLIT_TOL_DEG,
                         "split angle", workers, cache_dir)


def _angle_series(job, n: int, key: str, tol_key: float | None, tol: float, label: str,
                  workers: int, cache_dir: Path | None) -> dict[str, Any]:
    """An angle (deg) as a Chebyshev series in the volume coordinate a: ``job(v)`` at ``n``
    Lobatto nodes in ln v, through the node cache (lines ``key|v[|tol_key]``)."""
    vs = _volume_nodes(n)
    tail = "" if tol_key is None else f"|{tol_key}"
    th = np.array(_cached_map(job, list(vs), lambda v: f"{key}|{v!r}{tail}",
                              lambda v, t: (t, []), lambda v, got: got[0],
                              workers, label, cache_dir))
    return {"chebyshev": lobatto_coefficients(th).tolist(), "at_nodes_deg": th.tolist(),
            "v_nodes": vs.tolist(), "tolerance_deg": tol}


SphereRange = tuple[float | None, float | None]
"""A range of the sphere's angle (deg); ``None``: the onset angle (a series in ln V)."""
RIDGE_NODES = (10, 9)
"""Lobatto nodes in (a, b1) of the ridge angle of a wall with two angles (per band)."""
RIDGE_BRACKET_DEG = (-2.0, 45.0)
"""Where the ridge is sought: the sphere's angle plus these (the wall's angle clipped to
[0, :data:`~wetcontact.reduced_models.calibrated_capillary.RIDGE_TOP_DEG`])."""
RIDGE_TOL_DEG = 1e-6


def wall_rupture(v: float, theta_sphere_deg: float, theta_wall_deg: float) -> float:
    """``meniscus`` rupture distance S_c/R of a bridge of volume v R^3 between a sphere
    and a wall."""
    return _branch_ends(None, v, theta_sphere_deg, theta_wall_deg).rupture_distance


def golden_top(rupture: Callable[[float], float], lo: float, hi: float, where: str,
               angle: str, tol: float = RIDGE_TOL_DEG) -> tuple[float, float]:
    """The angle (deg) in [lo, hi] where ``rupture(angle)`` peaks, and the width of the
    bracket it was found in: golden-section search (Kiefer 1953) for the maximum, to
    ``tol``.

    The search needs no derivative and converges on the peak also where the top is a jump
    or a cusp (the left limit is the maximum). Within about 1e-6 deg of a jump the fold
    refinement may fail (:class:`~wetcontact.errors.SolverError`); the point is then moved
    by 1 % of the bracket, and if that fails too the search stops with the bracket it has.
    ``where`` and ``angle`` name the bridge and the searched angle in the errors: no
    rupture distance at the first two points, or a top within ten tolerances of the
    bracket's ends (not inside it)."""
    g = 0.5 * (math.sqrt(5.0) - 1.0)

    def at(x: float, width: float) -> tuple[float, float] | None:
        for dx in (0.0, 0.01 * width, -0.01 * width):
            try:
                return x + dx, rupture(x + dx)
            except SolverError:
                continue
        return None

    first = at(hi - g * (hi - lo), hi - lo), at(lo + g * (hi - lo), hi - lo)
    if None in first:
        raise SolverError(f"calibrated-capillary: no rupture distance at {where} inside the "
                          f"{angle}'s bracket")
    (x1, f1), (x2, f2) = first
    a, b = lo, hi
    while b - a > tol:
        if f1 >= f2:
            b, x2, f2 = x2, x1, f1
            got = at(b - g * (b - a), b - a)
            if got is None or not a < got[0] < x2:
                break
            x1, f1 = got
        else:
            a, x1, f1 = x1, x2, f2
            got = at(a + g * (b - a), b - a)
            if got is None or not x1 < got[0] < b:
                break
            x2, f2 = got
    top = 0.5 * (a + b)
    if min(top - lo, hi - top) < 10 * max(tol, b - a):
        raise RuntimeError(f"calibrated-capillary: the rupture distance's ridge at {where} "
                           f"is not inside the bracket [{lo:.4g}, {hi:.4g}] deg of the "
                           f"{angle}")
    return top, b - a


def _ridge_job(args: tuple[float, float]) -> tuple[float, float]:
    """The wall angle (deg) of the rupture distance's ridge at (v, theta_sphere), and the
    width of the bracket it was found in: :func:`golden_top` over the wall angle in the
    sphere's angle plus :data:`RIDGE_BRACKET_DEG` (to :data:`RIDGE_TOL_DEG`).

    S_c rises to the ridge and falls beyond it; at larger sphere angles the top is a jump
    (S_c jumps down by up to about 1e-3 where the branch from contact comes to end at the
    other of two nearby folds)."""
    v, ts = args
    lo = max(0.0, ts + RIDGE_BRACKET_DEG[0])
    hi = min(cc.RIDGE_TOP_DEG, ts + RIDGE_BRACKET_DEG[1])
    return golden_top(lambda x: wall_rupture(v, ts, x), lo, hi,
                      f"V* = {v:.4g}, sphere angle {ts:.4g} deg", "wall angle")


def fit_ridge(workers: int = 2, cache_dir: Path | None = None,
              theta_range: SphereRange = cc.THETA_RANGE_DEG,
              onset: dict[str, Any] | None = None) -> dict[str, Any]:
    """Chebyshev coefficients in (a, b1) of the ridge's wall angle (deg), at Lobatto nodes
    (:data:`RIDGE_NODES`), b1 the sphere's angle over ``theta_range`` (deg; an end
    ``None`` is the onset series ``onset``, :func:`sphere_angle_grid`)."""
    vs = _volume_nodes(RIDGE_NODES[0])
    ts = sphere_angle_grid(vs, RIDGE_NODES[1], theta_range, onset)
    jobs = [(float(v), float(t)) for v, row in zip(vs, ts, strict=True) for t in row]
    # a cached line holds the bracket's width (a line written before the width was kept
    # holds none: that search could only end at the tolerance)
    got = _cached_map(_ridge_job, jobs, lambda j: f"ridge|{j[0]!r}|{j[1]!r}|{RIDGE_TOL_DEG}",
                      lambda j, r: (r[0], [r[1]]),
                      lambda j, got: (got[0], float(got[1][0]) if len(got[1]) else RIDGE_TOL_DEG),
                      workers, "ridge angle", cache_dir)
    th = np.reshape([t for t, _ in got], RIDGE_NODES)
    return {"chebyshev": lobatto_coefficients(th).tolist(), "at_nodes_deg": th.tolist(),
            "v_nodes": vs.tolist(), "theta_sphere_nodes_deg": ts.tolist(),
            "tolerance_deg": RIDGE_TOL_DEG,
            "bracket_max_deg": max(w for _, w in got)}


ONSET_NODES = 10
"""Lobatto nodes in ln v of the onset angle (where S_c's jump at the ridge's top appears)."""
ONSET_BRACKET_DEG = (10.0, 35.0)
"""Where the onset angle is sought: a smooth top at the first, a jump at the second."""
ONSET_TOL_DEG = 0.01
ONSET_PROBE_DEG = 1e-5
"""The rupture distance's slope toward the ridge's top is measured over this (deg)."""
ONSET_SLOPE = 1e-2
"""Slope (relative, per deg) of S_c just short of the ridge's top above which the top is a
jump. A smooth maximum gives about 3 x curvature x probe: 2e-7 at v = 0.1, theta_s = 10
deg, rising to 2.3e-3 at 0.05 deg short of the onset (v = 0.08, theta_s = 19.1 deg: the
maximum sharpens as the two folds near each other). A jump is reached at a finite slope:
1.2e-2 at 19.15, 2.5e-2 at 19.2, 0.08-0.2 at 35 deg. So the onset is located to about
0.05 deg; the locus's curvature changes there by about 0.012 per deg (v = 0.08), so a
split that far off leaves about 1.5e-5 deg in the ridge series."""


def top_is_jump(v: float, theta_sphere_deg: float) -> bool:
    r"""Whether S_c's top over the wall angle is a jump at (v, theta_s) (deg): the ridge
    (:func:`_ridge_job`, the left end of its bracket theta^*) is reached at a finite slope,
    :math:`(S_c(\theta^* - h) - S_c(\theta^* - 2h)) / (h S_c(\theta^* - h))` above
    :data:`ONSET_SLOPE` with h = :data:`ONSET_PROBE_DEG`, rather than at the zero slope of
    a smooth maximum."""
    top, width = _ridge_job((v, theta_sphere_deg))
    return left_slope(lambda x: wall_rupture(v, theta_sphere_deg, x), top,
                      width) > ONSET_SLOPE


def left_slope(rupture: Callable[[float], float], top: float, width: float,
               h: float = ONSET_PROBE_DEG) -> float:
    r"""Relative slope (per deg) of ``rupture`` just short of a top found by
    :func:`golden_top` (``top`` and its bracket's ``width``):
    :math:`(S(\theta_l - h) - S(\theta_l - 2h)) / (h S(\theta_l - h))`, theta_l the
    bracket's left end."""
    left = top - 0.5 * width
    s1 = rupture(left - h)
    s2 = rupture(left - 2.0 * h)
    return (s1 - s2) / (h * s1)


def _onset_job(v: float) -> float:
    """Bisection for the onset angle at ``v`` (to :data:`ONSET_TOL_DEG`)."""
    return bisect_change(lambda t: top_is_jump(v, t), ONSET_BRACKET_DEG, ONSET_TOL_DEG,
                          "the ridge's jump onset", v)


def fit_onset(workers: int = 2, cache_dir: Path | None = None) -> dict[str, Any]:
    """Chebyshev coefficients (in the volume coordinate a) of the onset angle (deg): the
    sphere angle above which S_c's top over the wall angle is a jump (:func:`top_is_jump`),
    where the ridge's locus has a kink of its curvature."""
    return _angle_series(_onset_job, ONSET_NODES, "onset", ONSET_TOL_DEG, ONSET_TOL_DEG,
                         "onset angle", workers, cache_dir)


def sphere_angle_grid(vs: np.ndarray, n: int, theta_range: SphereRange,
                      onset: dict[str, Any] | None = None) -> np.ndarray:
    """The sphere angle's Lobatto nodes (deg) over ``theta_range`` at each volume ``vs``,
    shape (len(vs), n): an end ``None`` is the onset angle, the series ``onset`` evaluated
    as the model does (:func:`~wetcontact.reduced_models.calibrated_capillary.onset_deg`),
    so that the nodes lie where the model maps them."""
    lo, hi = cc.sphere_range({cc.ONSET_KEY: onset}, {"theta_sphere_deg": theta_range},
                             cc.volume_coordinate(np.asarray(vs, dtype=float)))
    return 0.5 * (lobatto(n)[None, :] * (hi - lo)[:, None] + lo[:, None] + hi[:, None])


BRANCHES = {"solved": 0, "reused": 0}
"""Branch jobs of this process: solved, and reused from the :class:`NodeCache` (the
generator records both, so that its wall time is read with them)."""


def _cached_map(fn, jobs: list, key, pack, unpack, workers: int, label: str,
                cache_dir: Path | None) -> list:
    """:func:`_map_jobs` through the :class:`NodeCache`: a job whose ``key(job)`` is cached
    is not rerun (``unpack(job, (s_c, q))`` rebuilds its result); each new result is kept
    as it arrives (``pack(job, result) -> (s_c, q)``)."""
    cache = NodeCache(cache_dir)
    got = [cache.get(key(j)) for j in jobs]
    todo = [j for j, g in zip(jobs, got, strict=True) if g is None]
    BRANCHES["reused"] += len(jobs) - len(todo)
    BRANCHES["solved"] += len(todo)
    fresh = iter(_map_jobs(fn, todo, workers, f"{label} ({len(jobs) - len(todo)} reused)",
                           on_result=lambda j, r: cache.put(key(j), *pack(j, r))))
    return [next(fresh) if g is None else unpack(j, g) for j, g in zip(jobs, got, strict=True)]


def solve_branch(kind: str, ratio: float | None, v: float, theta: float,
                 c_nodes: np.ndarray, theta2: float | None = None,
                 n_elements: int | None = None) -> tuple[float, np.ndarray]:
    """``meniscus`` at one bridge (R_s = 1, sigma = 1): S_c and the reduced force
    ``F/(2 pi sigma R* (cos theta + cos theta2))`` at the gap coordinates ``c_nodes``
    (``theta2``: the other solid's angle, default ``theta``; ``n_elements``: the meridian's
    elements, default ``meniscus``'s, twice that where a fold is too hard for them)."""
    from wetcontact.solver.meniscus import DEFAULT_ELEMENTS, Bridge, force_separation_curve

    n_elements = DEFAULT_ELEMENTS if n_elements is None else int(n_elements)

    theta2 = theta if theta2 is None else theta2
    br = Bridge(radius=1.0, radius2=ratio, contact_angle1=theta, contact_angle2=theta2,
                surface_tension=1.0)
    rho = cc.reduced_star(kind, ratio)
    eps = math.sqrt(v / (math.pi * rho))
    order = np.argsort(-np.asarray(c_nodes))  # c = 1 is S = 0

    def fractions(s_c: float) -> np.ndarray:
        f = cc.gap_from_coordinate(c_nodes[order], s_c, eps) / s_c
        f[0], f[-1] = max(f[0], 0.0), 1.0
        return f

    try:
        cur = force_separation_curve(br, v, fractions=fractions, n_elements=n_elements)
    except SolverError:  # a harder fold: the finer discretisation (more accurate anyway)
        cur = force_separation_curve(br, v, fractions=fractions,
                                     n_elements=2 * n_elements)
    q = np.empty(len(c_nodes))
    q[order] = -cur.force / (2.0 * math.pi * rho * (math.cos(theta) + math.cos(theta2)))
    return cur.rupture_distance, q


NODE_NUDGE_RAD = 1e-6
"""A two-angle node whose branch end is too degenerate to bracket (the wall angle within
about 1e-6 deg of the ridge's top) is solved this far to either side and averaged."""


def _node_job(args: tuple) -> tuple[tuple[int, ...], float, np.ndarray]:
    idx, kind, ratio, v, theta, c_nodes, theta2 = args
    try:
        s_c, q = solve_branch(kind, ratio, v, theta, c_nodes, theta2)
    except SolverError:
        if theta2 is None:
            raise
        sides = [solve_branch(kind, ratio, v, theta, c_nodes, theta2 + d)
                 for d in (-NODE_NUDGE_RAD, NODE_NUDGE_RAD)]
        sys.stderr.write(f"calibrated-capillary: node {idx} solved {NODE_NUDGE_RAD:g} rad to "
                         "either side of its wall angle (degenerate end)\n")
        s_c, q = 0.5 * (sides[0][0] + sides[1][0]), 0.5 * (sides[0][1] + sides[1][1])
    return idx, s_c, q


def piece_jobs(kind: str, piece: dict[str, Any], split: dict[str, Any] | None,
               theta_range: SphereRange = cc.THETA_RANGE_DEG,
               onset: dict[str, Any] | None = None
               ) -> tuple[list[tuple], np.ndarray, bool]:
    """The node jobs of one theta piece (:func:`fit_piece`'s: one ``meniscus`` branch each,
    :func:`_node_job`), the volumes at its a nodes and whether its own angle sits at Gauss
    points."""
    nodes = tuple(piece["nodes"])
    c_nodes = lobatto(nodes[-1])
    two = kind == cc.WALL_TWO_ANGLES
    i_a = 1 if kind == "sphere-sphere" else 0
    vs = _volume_nodes(nodes[i_a])
    a = cc.volume_coordinate(vs)
    t_s = sphere_angle_grid(vs, nodes[1], theta_range, onset) if two else None
    lead_shape = nodes[:2] if two else (nodes[i_a],)

    def lead(idx: tuple[int, ...]) -> tuple[int, ...]:
        return idx[:2] if two else (idx[i_a],)

    if split is None:
        sp = None
    elif two:
        sp = cc.chebyshev_tensor(np.asarray(split["chebyshev"]),
                                 list(np.meshgrid(a, lobatto(nodes[1]), indexing="ij")))
    else:
        sp = cc.chebyshev_tensor(np.asarray(split["chebyshev"]), [a])
    lo, hi = (np.full(lead_shape, e) if e is not None else sp for e in piece["theta_deg"])
    # the piece's angle at Gauss points where a piece ends at the split angle: there,
    # between equal spheres, fold and bifurcation coincide and the branch's end is
    # degenerate (on a wall, the ridge of S_c)
    gauss_b = None in piece["theta_deg"]
    b = gauss(nodes[-2]) if gauss_b else lobatto(nodes[-2])
    ratios = ([None] if kind != "sphere-sphere" else
              list(np.exp((0.5 * (lobatto(nodes[0]) + 1.0) * cc.W_MAX) ** 3)))
    jobs = []
    for idx in np.ndindex(*nodes[:-1]):
        li, i_b = lead(idx), idx[-1]
        theta = math.radians(float(cc.piece_angle(piece, b[i_b], lo[li], hi[li])))
        ratio = None if kind != "sphere-sphere" else float(ratios[idx[0]])
        if two:  # the sphere's angle on axis b1, the wall's in the piece
            jobs.append((idx, kind, ratio, float(vs[idx[0]]), math.radians(t_s[idx[:2]]),
                         c_nodes, theta))
        else:
            jobs.append((idx, kind, ratio, float(vs[idx[i_a]]), theta, c_nodes, None))
    return jobs, vs, gauss_b


def fit_piece(kind: str, piece: dict[str, Any], split: dict[str, Any] | None,
              workers: int = 2, cache_dir: Path | None = None,
              theta_range: SphereRange = cc.THETA_RANGE_DEG,
              onset: dict[str, Any] | None = None) -> dict[str, Any]:
    """Coefficients of one theta piece from ``meniscus`` at its tensor nodes.

    The lead axes are (a,) on a wall, (w, a) for sphere pairs and (a, b1) on a wall with
    two angles; the piece's own angle (the one angle, or the wall's) follows them, mapped
    from its range at that lead node (an end may be the split angle or the ridge), linearly
    or, with ``theta_map``, quadratically toward the ridge
    (:func:`~wetcontact.reduced_models.calibrated_capillary.piece_angle`)."""
    nodes = tuple(piece["nodes"])
    i_a = 1 if kind == "sphere-sphere" else 0
    jobs, vs, gauss_b = piece_jobs(kind, piece, split, theta_range, onset)
    rup = np.empty(nodes[:-1])
    q = np.empty(nodes)
    results = _cached_map(_node_job, jobs, NodeCache.key, lambda j, r: (r[1], r[2]),
                          lambda j, got: (j[0], *got), workers,
                          f"calibrated-capillary {kind} theta {piece['theta_deg']}", cache_dir)
    for idx, s_c, qq in results:
        rup[idx] = math.log(s_c / vs[idx[i_a]] ** (1.0 / 3.0))
        q[idx] = np.log(qq)
    left, right, err = factor_table(lobatto_coefficients(q, (q.ndim - 2,) if gauss_b else ()))
    return {"theta_deg": piece["theta_deg"], "nodes": list(nodes),
            **({"theta_map": piece["theta_map"]} if "theta_map" in piece else {}),
            "theta_points": "gauss" if gauss_b else "lobatto",
            "rupture": lobatto_coefficients(rup, (rup.ndim - 1,) if gauss_b else ()).tolist(),
            "force_left": left.tolist(), "force_right": right.tolist(),
            "force_rank": int(left.shape[-1]), "force_factor_change": err}


BAND_NODES: dict[str, dict[int, dict[int, list[int]]]] = {
    cc.PAIR_TWO_ANGLES: {0: {0: [13, 9, 9, 15, 19]}}}
"""Node counts that differ from :data:`PIECES` (or ``calibrated_capillary_pairs.STAGES``' full
stage) in one band of a two-angle table, ``{kind: {band: {piece: nodes}}}``. A band refitted
with other counts than its neighbour no longer interpolates the same nodes at their common
break, so S_c steps there (the band-join tests hold it: to 1e-9 on the wall, to the rupture
goal between spheres). The pieces below the ridge have 23 Gauss points in the other angle
(toward an angle of 0, S_c's curvature changes within 1-3 deg; 23 points resolve it to
1.4e-5 at theta_s = 70 deg, V* = 0.1); the sphere pairs' band below the onset keeps 15 there
(S_c is flat in theta2 toward 0) but has 13 ratio nodes below the ridge (with 9, S_c
oscillated in the radius ratio at both angles low and V* near 0.1 by up to 2.1e-4; with 13,
1.9e-5). Its small sphere's angles and ridge at those nodes come from the band's onset and
ridge series (``calibrated_capillary_pairs.lead_grid``), as the model maps a point; the piece
above the ridge and the other bands keep 9 w nodes. ``docs/calibrated_capillary.md`` has
the record of these counts."""


def band_pieces(kind: str, band: int) -> list[dict[str, Any]]:
    """The pieces' specifications (:data:`PIECES`) of band ``band`` of a two-angle wall
    table, with :data:`BAND_NODES`' node counts."""
    over = BAND_NODES.get(kind, {}).get(band, {})
    return [{**p, "nodes": list(over.get(i, p["nodes"]))} for i, p in enumerate(PIECES[kind])]


def fit_kind(kind: str, workers: int = 2, cache_dir: Path | None = None) -> dict[str, Any]:
    """Every theta piece of one kind (and the split angle for sphere pairs); a wall with two
    angles: per band of the sphere's angle (:data:`TWO_ANGLE_BANDS_DEG`) its ridge and
    pieces, b1 over the band, each piece with its force table's tensor train (what the
    model evaluates, :data:`WALL_TRAINS`)."""
    if kind == cc.WALL_TWO_ANGLES:
        onset = (fit_onset(workers, cache_dir)
                 if any(None in rng for rng in TWO_ANGLE_BANDS_DEG) else None)
        bands = []
        for i, rng in enumerate(TWO_ANGLE_BANDS_DEG):
            ridge = fit_ridge(workers, cache_dir, rng, onset)
            bands.append({"theta_sphere_deg": list(rng), "theta_split": ridge,
                           "pieces": [train_piece(fit_piece(kind, p, ridge, workers,
                                                            cache_dir, rng, onset),
                                                  fields=WALL_TRAINS)
                                      for p in band_pieces(kind, i)]})
        return {**({cc.ONSET_KEY: onset} if onset else {}), "bands": bands}
    split = None
    if any(None in p["theta_deg"] for p in PIECES[kind]):
        split = fit_split(workers, cache_dir)
    return {"theta_split": split,
            "pieces": [fit_piece(kind, p, split, workers, cache_dir) for p in PIECES[kind]]}


def _held_job(args: tuple) -> tuple[float, np.ndarray, np.ndarray]:
    from wetcontact.solver.meniscus import Bridge, force_separation_curve

    ratio, v, theta, fr, theta2 = args
    br = Bridge(radius=1.0, radius2=ratio, contact_angle1=theta,
                contact_angle2=theta if theta2 is None else theta2, surface_tension=1.0)
    cur = force_separation_curve(br, v, fractions=np.append(fr, 1.0))
    return cur.rupture_distance, cur.gap[:-1], -cur.force[:-1] / (2.0 * math.pi)


def held_out(kind: str, n: int = 120, gaps_per: int = 8, seed: int = 2611,
             workers: int = 2, near_equal: bool = False, entry: dict[str, Any] | None = None,
             cache_dir: Path | None = None, near_ridge: bool = False,
             ridge_band: tuple[float, float] | None = None,
             theta_range: tuple[float, float] | None = None, corners: bool = False,
             theta2_range: tuple[float, float] | None = None,
             v_range: tuple[float, float] | None = None,
             fractions: tuple[float, ...] | None = None) -> dict[str, Any]:
    """Held-out error table of a table (``entry``: one kind's, default the shipped one)
    against ``meniscus`` (relative errors of the rupture distance and of the force, max /
    mean / 95th percentile, where the maximum sits; ``force_attached``: the force at the
    points where the closure's own bridge exists, short of its rupture distance).
    ``near_ridge``: a wall with two angles, the wall angle near the table's ridge
    (``ridge_band``: in a band of distances from it; ``theta_range``: the sphere angle's
    range; ``theta2_range``, ``v_range``, ``fractions``: see :func:`held_out_design`).
    ``corners``: the corner stratum's bridges (:func:`corner_design`) instead of a seeded
    design (``n``, ``gaps_per`` and ``seed`` ignored). The table records fixed gaps (the
    corners', or ``fractions``) under ``design``."""
    e = cc._entry(kind) if entry is None else entry
    if corners:
        design, gaps_per, seed = corner_design(kind), len(CORNER_FRACTIONS), None
        n = len(design)
    else:
        design = held_out_design(kind, n, gaps_per, seed, near_equal,
                                 e if near_ridge or ridge_band else None, ridge_band,
                                 theta_range, theta2_range, v_range, fractions)
        gaps_per = len(design[0]["fractions"])

    def rad(x: float | None) -> float | None:
        return None if x is None else math.radians(x)

    jobs = [(d["ratio"], d["v"], math.radians(d["theta_deg"]), np.array(d["fractions"]),
             rad(d["theta_wall_deg"])) for d in design]

    def key(job: tuple) -> str:
        ratio, v, theta, fr, theta2 = job
        other = "" if theta2 is None else f"|{theta2!r}"
        return f"held|{kind}|{ratio!r}|{v!r}|{theta!r}|{np.asarray(fr).tolist()!r}{other}"

    res = _cached_map(_held_job, jobs, key, lambda j, r: (r[0], np.append(r[1], r[2])),
                      lambda j, got: (got[0], got[1][:gaps_per], got[1][gaps_per:]), workers,
                      f"held-out {kind}", cache_dir)
    e_rup, e_f, where_r, where_f, attached = [], [], [], [], []
    for d, job, (s_c, gaps, f) in zip(design, jobs, res, strict=True):
        f_hat, sc_hat = cc.force_star(kind, d["v"], job[2], gaps, d["ratio"], entry=e,
                                      theta_wall=job[4])
        e_rup.append(abs(float(sc_hat[0]) / s_c - 1.0))
        where_r.append({k: d[k] for k in ("v", "theta_deg", "theta_wall_deg", "ratio")
                        if d[k] is not None})
        e_f.extend(np.abs(f_hat / f - 1.0))
        attached.extend(np.ravel(f_hat) > 0.0)
        where_f += [{**where_r[-1], "s_over_sc": float(x)} for x in d["fractions"]]

    def table(err: list[float], where: list[dict]) -> dict[str, Any]:
        e = np.asarray(err)
        return {"points": int(e.size), "max": float(e.max()), "mean": float(e.mean()),
                "p95": float(np.percentile(e, 95)), "max_at": where[int(np.argmax(e))]}

    att = np.flatnonzero(attached)
    return {"seed": seed, "reference": "meniscus (default elements)",
            "bridges": n,
            **({"design": {"corners": {k: list(v) for k, v in CORNER_LEVELS.items()},
                           "s_over_sc": list(CORNER_FRACTIONS)}} if corners else
               {"design": {"s_over_sc": list(fractions)}} if fractions is not None else {}),
            "rupture_distance": table(e_rup, where_r),
            "force": table(e_f, where_f),
            "force_attached": table([e_f[i] for i in att], [where_f[i] for i in att])}


def _write(out: Path, data: dict[str, Any]) -> None:
    out.write_text(json.dumps(data) + "\n")
    cc.capillary_table.cache_clear()


KINDS = ("sphere-wall", "sphere-sphere", cc.WALL_TWO_ANGLES)
"""The tables the generator writes."""


def generate_calibrated_capillary(out: Any = None, kinds: tuple[str, ...] = KINDS,
        workers: int = 2, n_held_out: int = 120,
        cache_dir: Path | None = None, retrain: bool = False) -> dict[str, Any]:
    """Write ``data/calibrated_capillary.json``: per kind the tensor coefficients, their
    nodes and the held-out error table, and the wall time. Solved nodes are kept in a
    :class:`NodeCache` (``cache_dir``, default the user cache) and reused by a rerun.
    ``retrain``: keep the fit ``out`` holds for each of ``kinds`` (no node solved), build
    the two-angle wall table's tensor trains again (:data:`~wetcontact.reduced_models
    .calibrated_capillary.WALL_TWO_ANGLES`; the one-angle tables have none) and measure
    the held-out tables again (what a change of the closure's evaluation, not of its fit,
    calls for)."""
    t0 = time.perf_counter()
    start = dict(BRANCHES)
    out = Path(out) if out else Path(cc.__file__).parents[1] / "data" / cc.CAPILLARY_FILE
    old = json.loads(out.read_text()) if out.is_file() else {}
    data: dict[str, Any] = {
        "generated_by": "python -m wetcontact.generate calibrated-capillary",
        "form": "see wetcontact.reduced_models.calibrated_capillary",
        "domain": {"v": list(cc.V_RANGE), "theta_deg": list(cc.THETA_RANGE_DEG),
                   "radius_ratio": list(cc.RATIO_RANGE)},
        "goals": {"force": 1e-3, "rupture_distance": 5e-4}}
    for kind in (*KINDS, cc.PAIR_TWO_ANGLES):
        if kind not in kinds or kind not in KINDS:  # kept (calibrate_pairs2 writes pairs')
            if kind in old:
                data[kind] = old[kind]
            continue
        t1 = time.perf_counter()
        if retrain:
            data[kind] = _retrained(out, old, kind)
            if kind == cc.WALL_TWO_ANGLES:
                data[kind]["train_time_s"] = round(time.perf_counter() - t1, 1)
        else:
            data[kind] = fit_kind(kind, workers=workers, cache_dir=cache_dir)
            data[kind]["fit_time_s"] = round(time.perf_counter() - t1, 1)
        _write(out, data)
        entry = cc.as_arrays({kind: data[kind]})[kind]
        if kind == cc.WALL_TWO_ANGLES:
            data[kind].update(_wall_two_held_out(entry, n_held_out, workers, cache_dir))
        else:
            data[kind]["held_out"] = held_out(kind, n=n_held_out, workers=workers,
                                              entry=entry, cache_dir=cache_dir)
            if kind == "sphere-sphere":
                data[kind]["held_out_near_equal"] = {
                    **held_out(kind, n=max(n_held_out // 3, 8), seed=2612, workers=workers,
                               near_equal=True, entry=entry, cache_dir=cache_dir),
                    "stratum": NEAR_EQUAL}
            data[kind]["held_out_corners"] = held_out(kind, workers=workers, entry=entry,
                                                      cache_dir=cache_dir, corners=True)
        _write(out, data)
    branches = {k: BRANCHES[k] - start[k] for k in BRANCHES}
    if retrain:  # the fit's own record stays; the retrain's beside it
        data.update({k: old[k] for k in ("wall_time_s", "branches") if k in old},
                    retrain_wall_time_s=round(time.perf_counter() - t0, 1),
                    retrain_branches=branches)
    else:
        data.update(wall_time_s=round(time.perf_counter() - t0, 1), branches=branches)
    _write(out, data)
    return data


def strata_held_out(kind: str, strata: dict[str, dict[str, Any]], entry: dict[str, Any],
                    n: int, workers: int, cache_dir: Path | None) -> dict[str, dict[str, Any]]:
    """The held-out tables of a two-angle table (``entry``: its arrays) per stratum of
    ``strata`` (:data:`WALL_STRATA`, ``calibrated_capillary_pairs.PAIR_STRATA``: :func:`held_out`'s
    design arguments, with ``part``: the uniform count ``n`` over this, ``scale``: times it,
    ``least``: at least this many bridges (default 8), ``stratum``: what the table
    records), and its corner stratum (``held_out_corners``)."""
    out = {}
    for key, st in strata.items():
        m = max(st.get("least", 8), n // st.get("part", 1) * st.get("scale", 1))
        ho = held_out(kind, n=m, seed=st["seed"], workers=workers, entry=entry,
                      cache_dir=cache_dir, near_equal=st.get("near_equal", False),
                      near_ridge=st.get("near_ridge", False),
                      ridge_band=st.get("ridge_band"), theta_range=st.get("theta_range"),
                      theta2_range=st.get("theta2_range"), v_range=st.get("v_range"),
                      fractions=st.get("fractions"))
        out[key] = {**ho, **({"stratum": st["stratum"]} if "stratum" in st else {})}
    out["held_out_corners"] = held_out(kind, workers=workers, entry=entry,
                                       cache_dir=cache_dir, corners=True)
    return out


def _wall_two_held_out(entry: dict[str, Any], n_held_out: int, workers: int,
                       cache_dir: Path | None) -> dict[str, dict[str, Any]]:
    """The two-angle wall table's held-out tables (``entry``: its arrays): its
    :data:`WALL_STRATA` and its corner stratum."""
    return strata_held_out(cc.WALL_TWO_ANGLES, WALL_STRATA, entry, n_held_out, workers,
                           cache_dir)


CORNER_KINDS = (*KINDS, cc.PAIR_TWO_ANGLES)
"""The tables that carry a corner stratum (``held_out_corners``)."""


def add_corner_strata(out: Path | None = None, kinds: tuple[str, ...] = CORNER_KINDS,
                      workers: int = 2, cache_dir: Path | None = None) -> dict[str, Any]:
    """Measure the corner stratum (:func:`corner_design`) of each table in ``kinds`` that
    the file ``out`` (default the package data) holds, against ``meniscus``, and write it
    as the table's ``held_out_corners`` (no node solved, nothing else changed); returns the
    file's data. A table's held-out strata bound its rupture window
    (:meth:`~wetcontact.reduced_models.calibrated_capillary.CalibratedCapillary
    .bound_floor`), so the corner stratum widens it where S_c errs most."""
    out = Path(out) if out else Path(cc.__file__).parents[1] / "data" / cc.CAPILLARY_FILE
    data = json.loads(out.read_text())
    for kind in kinds:
        if kind not in data:
            continue
        entry = cc.as_arrays({kind: data[kind]})[kind]
        data[kind]["held_out_corners"] = held_out(kind, workers=workers, entry=entry,
                                                  cache_dir=cache_dir, corners=True)
        _write(out, data)
    return data


def _retrained(out: Path, old: dict[str, Any], kind: str) -> dict[str, Any]:
    """The table ``kind`` that ``old`` holds without its held-out tables (measured again by
    the caller): a one-angle table as it is (it has no tensor trains), the two-angle wall
    table with its pieces' tensor trains (:data:`WALL_TRAINS`) built again beside its fit."""
    if kind not in KINDS or kind not in old:
        raise InputError(f"{out}: field {kind!r} missing or not retrainable; allowed: a "
                         f"table file that holds the {kind} table")
    e = {k: v for k, v in old[kind].items() if not k.startswith("held_out")}
    if kind != cc.WALL_TWO_ANGLES:
        return e
    e["bands"] = [{**b, "pieces": [train_piece({k: v for k, v in p.items()
                                                if k not in cc.TRAIN_FIELDS},
                                               fields=WALL_TRAINS) for p in b["pieces"]]}
                  for b in e["bands"]]
    return e
