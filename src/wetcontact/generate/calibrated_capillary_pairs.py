r"""Generator of ``calibrated-capillary``'s two-angle sphere-pair table
(``python -m wetcontact.generate calibrated-capillary --kind sphere-sphere-two-angles``,
:func:`generate_pair_table`), and the band refits of either two-angle table
(:func:`refine_band`); it builds on :mod:`wetcontact.generate.calibrated_capillary`.

Sphere pairs with two contact angles: the ridge of the rupture distance and its top's
kind, the measurements behind the design of a ``calibrated-capillary`` table for them
(issue 11; findings in ``docs/notes/sphere_pair_two_angles.md``).

A bridge between a small sphere (radius R_s = 1, contact angle theta1) and a large one
(radius r = R_l/R_s, angle theta2) ruptures at S_c(r, v, theta1, theta2). Over theta2 at
fixed theta1, S_c rises to a top at theta2^* and falls beyond it, as over the wall's angle
on a wall (:func:`wetcontact.generate.calibrated_capillary._ridge_job`, which the search here
shares: :func:`~wetcontact.generate.calibrated_capillary.golden_top`). The top is one of three
kinds (:func:`top_shape`):

* ``smooth``: a smooth maximum, S_c - S_top ~ -delta^2 (delta = theta2 - theta2^*);
* ``jump``: S_c rises to the top at a finite slope and drops across it (the stable
  branch from contact ends at one of two nearby folds, and which one changes at the top);
* ``cusp``: equal spheres (r = 1) at theta1 above the fold/bifurcation angle: at theta2 =
  theta1 the branch ends at a symmetry-breaking bifurcation, which an angle difference
  unfolds into a fold at S_b - k |delta|^(2/3) (continuous, the slope infinite).

A smooth top is told from the others by how the left slope of S_c at a distance h short
of it scales with h: as h (smooth), h^0 (jump) and h^(-1/3) (cusp); a cusp from a jump by
whether S_c drops across the top. Between unequal spheres the top is a jump, of a size
that vanishes as (ln r)^1.6-2 as r -> 1 (and toward the angle where the top stops being
smooth); there both its sides are cusp-like, further from r = 1 a finite slope short of
it and a fold's square root past it (the notes give the measured sizes).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.generate import calibrated_capillary as gen
from wetcontact.reduced_models import calibrated_capillary as cc

PAIR_BRACKET_DEG = (-10.0, 45.0)
"""Where the ridge over one sphere's angle is sought: the other's angle plus these (deg),
clipped to [0, :data:`~wetcontact.reduced_models.calibrated_capillary.RIDGE_TOP_DEG`]."""
PROBE_DEG = gen.ONSET_PROBE_DEG
"""Distance h (deg) short of and past the top at which :func:`top_shape` probes S_c."""
PROBE_FAR = 8.0
"""The left slope is also taken at this multiple of h (its ratio gives the exponent)."""
SMOOTH_EXPONENT = -0.5
"""Exponent p of the left slope's growth toward the top, ``slope ~ h^(-p)``, below which a
top is a smooth maximum (p = -1 there, 0 at a jump, 1/3 at a cusp)."""
CUSP_DROP = 0.25
"""A top that is not smooth is a cusp when S_c drops across it (over 2h) by less than this
fraction of its rise over the last h short of it (0 at a symmetric cusp), a jump
otherwise. Between nearly equal spheres a small jump (1e-6 of S_c at r = 1.03) sits
between two cusp-like sides (|delta|^(2/3) down to 1e-6 deg): the kind is then the one
seen at the scale h (``jump`` from r = 1.03 at v = 0.01, h = 1e-5 deg)."""


def pair_rupture(ratio: float, v: float, theta1_deg: float, theta2_deg: float) -> float:
    """``meniscus`` rupture distance S_c/R_s of a bridge of volume v R_s^3 between spheres
    of radii R_s and ``ratio`` R_s with contact angles theta1 (small) and theta2 (large)."""
    return gen._branch_ends(ratio, v, theta1_deg, theta2_deg).rupture_distance


def pair_ridge(ratio: float, v: float, theta_deg: float, over: str = "large",
               bracket: tuple[float, float] = PAIR_BRACKET_DEG,
               tol: float = gen.RIDGE_TOL_DEG) -> tuple[float, float]:
    """The angle (deg) that maximises S_c over one sphere's angle with the other's fixed at
    ``theta_deg``, and the width of the bracket it was found in
    (:func:`~wetcontact.generate.calibrated_capillary.golden_top` to ``tol`` over ``theta_deg`` plus
    ``bracket``): ``over="large"`` searches theta2^*(theta1), ``"small"`` theta1^*(theta2)."""
    lo = max(0.0, theta_deg + bracket[0])
    hi = min(cc.RIDGE_TOP_DEG, theta_deg + bracket[1])
    if over == "large":
        def rupture(x: float) -> float:
            return pair_rupture(ratio, v, theta_deg, x)
        names = ("small sphere's angle", "large sphere's angle")
    elif over == "small":
        def rupture(x: float) -> float:
            return pair_rupture(ratio, v, x, theta_deg)
        names = ("large sphere's angle", "small sphere's angle")
    else:
        raise ValueError(f"over must be 'large' or 'small', not {over!r}")
    return gen.golden_top(rupture, lo, hi,
                          f"V* = {v:.4g}, radius ratio {ratio:.6g}, {names[0]} "
                          f"{theta_deg:.4g} deg", names[1], tol)


@dataclass(frozen=True)
class TopShape:
    """S_c about its top over one angle (relative quantities, slopes per deg).

    Attributes
    ----------
    top, width
        The top (deg) and the width of its bracket.
    s_top
        S_c/R_s just short of the top (at its bracket's left end less h).
    slope, slope_far
        :func:`~wetcontact.generate.calibrated_capillary.left_slope` at h and at
        :data:`PROBE_FAR` h.
    exponent
        p in ``slope ~ h^(-p)`` from the two: -1 smooth, 0 jump, 1/3 cusp.
    drop
        ``1 - S(right + h)/S(left - h)``: what S_c loses across the top over 2h.
    jump
        The drop extrapolated to h = 0: the left side linearly, the right side as a
        square root (a fold's), ``S(0+) = 2 S(h) - S(4h)``; relative to S_top.
    kind
        ``smooth`` (``exponent`` below :data:`SMOOTH_EXPONENT`), else ``cusp`` (``drop``
        below :data:`CUSP_DROP` times the rise over the last h) or ``jump``.
    """

    top: float
    width: float
    s_top: float
    slope: float
    slope_far: float
    exponent: float
    drop: float
    jump: float
    kind: str


def top_shape(rupture, top: float, width: float, h: float = PROBE_DEG) -> TopShape:
    r"""The kind of a top of ``rupture`` (deg -> S_c) found by
    :func:`~wetcontact.generate.calibrated_capillary.golden_top`.

    With theta_l, theta_r the ends of the top's bracket, the left slope
    :math:`s(h) = (S(\theta_l - h) - S(\theta_l - 2h)) / (h S(\theta_l - h))` grows as
    :math:`h^{-p}` toward the top: p = -1 at a smooth maximum (``S ~ -delta^2``), 0 where S_c
    jumps (a finite slope), 1/3 at a cusp (``S ~ -|delta|^{2/3}``), so that
    :math:`p = \log(s(h)/s(8h))/\log 8` tells a smooth top from the others, and the drop
    across the top, :math:`1 - S(\theta_r + h)/S(\theta_l - h)`, a cusp (where the two sides
    are alike) from a jump (:data:`CUSP_DROP`). The jump across the top is
    extrapolated from :math:`\theta_l - h, \theta_l - 2h` (linearly) and
    :math:`\theta_r + h, \theta_r + 4h` (as a square root, a fold's side)."""
    left, right = top - 0.5 * width, top + 0.5 * width
    s1, s2 = rupture(left - h), rupture(left - 2.0 * h)  # also the drop's and jump's
    r1, r4 = rupture(right + h), rupture(right + 4.0 * h)
    slope = (s1 - s2) / (h * s1)  # gen.left_slope at h, from the values already solved
    slope_far = gen.left_slope(rupture, top, width, PROBE_FAR * h)
    if slope > 0.0 and slope_far > 0.0:
        p = math.log(slope / slope_far) / math.log(PROBE_FAR)
    else:  # a flat or noisy top: no growth toward it
        p = -1.0
    drop = 1.0 - r1 / s1
    kind = ("smooth" if p < SMOOTH_EXPONENT else
            "cusp" if abs(drop) < CUSP_DROP * slope * h else "jump")
    return TopShape(top=top, width=width, s_top=s1, slope=slope, slope_far=slope_far,
                    exponent=p, drop=drop,
                    jump=((2.0 * s1 - s2) - (2.0 * r1 - r4)) / s1, kind=kind)


def pair_top(ratio: float, v: float, theta1_deg: float,
             ridge_tol: float = gen.RIDGE_TOL_DEG) -> TopShape:
    """The ridge over the large sphere's angle at theta1 (:func:`pair_ridge`, to
    ``ridge_tol``) and its :func:`top_shape`."""
    top, width = pair_ridge(ratio, v, theta1_deg, tol=ridge_tol)
    return top_shape(lambda x: pair_rupture(ratio, v, theta1_deg, x), top, width)


def pair_onset(ratio: float, v: float, lo: float, hi: float,
               tol: float = 0.5, ridge_tol: float = gen.RIDGE_TOL_DEG) -> float:
    """Bisection (to ``tol``, deg) for the small sphere's angle in [lo, hi] above which the
    top over the large sphere's angle is not smooth (:func:`pair_top`); the top must be
    smooth at ``lo`` and not at ``hi`` (the generator's
    :func:`~wetcontact.generate.calibrated_capillary.bisect_change`)."""
    return gen.bisect_change(lambda t: pair_top(ratio, v, t, ridge_tol).kind != "smooth",
                             (lo, hi),
                              tol, f"the pair's onset at radius ratio {ratio:.6g}", v)


# ---- the table: onset, ridge and pieces on nested Chebyshev grids ---------------------------

PAIR_TWO_ANGLES = cc.PAIR_TWO_ANGLES
"""Table key of two spheres with two different contact angles (the model's)."""
STAGES: dict[str, dict[str, Any]] = {
    "coarse": {"w": 5, "a": 5, "b1": 5, "b2": (5, 3)},
    "medium": {"w": 9, "a": 9, "b1": 9, "b2": (15, 9)},
    "full": {"w": 9, "a": 9, "b1": 9, "b2": (23, 27)},
}
"""Node counts per stage: w, a, b1 on Chebyshev-Lobatto points (5 of them are every other
of 9: nested), b2 on Chebyshev-Gauss points below and above the ridge (5 of them are every
third of 15, 3 every third of 9 and 9 every third of 27: nested). The full stage is the
shipped table (with ``calibrated_capillary.BAND_NODES``' exceptions): the medium stage's 9
b2 nodes above the ridge left one held-out force point 1.06e-3 off (theta2 0.023 deg past
the ridge on the top's jump side, between its first two nodes), and its 15 below the
ridge S_c 2.5e-4 off toward theta2 = 0 at theta1 = 70 deg (the force 4.9e-3 at 0.999 S_c;
hence 23 above the onset, and below it 13 w nodes in the piece below the ridge;
docs/notes/sphere_pair_two_angles.md). Every node of
a stage is a node of the next, with the same floats (:func:`ratio_nodes`,
:func:`~wetcontact.generate.calibrated_capillary._volume_nodes`, and the band ends and ridge taken
at their own nodes, not from a series), so that the node cache keeps what a coarser
stage solved; except the full stage's 23 b2 nodes below the ridge, which do not nest the
medium stage's 15 (a full stage solves its lower pieces afresh). The gap axis has
:data:`GAP_NODES` Lobatto nodes at every stage, as every shipped table."""
GAP_NODES = 19
PAIR_BANDS_DEG = gen.TWO_ANGLE_BANDS_DEG
"""The small sphere's angle ranges (deg), as on the wall: [0, theta_on(r, V)],
[theta_on, 35], [35, 70]."""
PAIR_RIDGE_BRACKET_DEG = (-2.0, 45.0)
"""The ridge is sought over the large sphere's angle in theta1 plus these (deg): it lies
0 to 32 deg above theta1 (docs/notes/sphere_pair_two_angles.md)."""
PAIR_RIDGE_TOL_DEG = (1e-4, 1e-5, 1e-5)
"""The ridge search's tolerance per band (deg): below the onset the top is a smooth
maximum (S_c flat across it, the series' own error there is larger); above it S_c jumps
(by up to 9e-4 at r = 10, v = 0.1) and the pieces must meet at the top."""
PAIR_RIDGE_W = (9, 17, 17)
"""Lobatto nodes of w in each band's ridge series at the full stage (the onset's 9 and
the pieces' ratio nodes among them). Above the onset S_c jumps at the ridge (by up to
9.2e-4), and a point between the series and the true top is evaluated on the jump's other
side; with 9 nodes the series was off by up to 6.3e-4 deg between them where the jump
exceeds 1e-4 (1.4e-3 deg near the onset, where it is below 2e-5; golden-section searches,
V* = 0.1), with 17 by up to 1.3e-5 (171 points). Between the a nodes the
band from the onset to 35 deg is still off by up to 5e-4 deg near the onset, where the
jump vanishes (6.5e-5 where it exceeds 1e-4; the band 35-70 deg by 9.6e-6): see
``calibrated_capillary.RIDGE_WINDOW_DEG``. Below the onset the top is a smooth maximum:
its side does not matter."""
PAIR_ONSET_TOL_DEG = 0.05
"""The onset's bisection tolerance (deg). The ridge's locus has a kink of its curvature
there; on a wall (0.012 per deg at v = 0.08) a band end 0.05 deg off leaves about 1.5e-5
deg in the ridge series, and the jump that far above the onset is about 3e-8 of S_c (the
wall's growth, 1.1e-5 (theta - theta_on)^1.93)."""
PAIR_ONSET_PROBE_TOL_DEG = 1e-5
"""The ridge's tolerance in the onset's searches (the kind probes sit 1e-5 deg short of
its bracket)."""


def ratio_nodes(n: int) -> np.ndarray:
    """The radius ratios at the ``n`` Lobatto nodes of ``w = (ln r)^(1/3)`` (the one-angle
    pair table's expression, so that nested stages give the same floats)."""
    return np.exp((0.5 * (gen.lobatto(n) + 1.0) * cc.W_MAX) ** 3)


def onset_bracket(v: float) -> tuple[float, float]:
    """Where the pair's onset is sought at volume ``v`` (deg): it falls with r from the
    equal spheres' split angle theta_s(V) (the one-angle pair table's series) toward the
    wall's onset theta_on(V) (the two-angle wall table's), r = 10 being 0-1.1 deg above
    it; the bracket is [theta_on - 1.5, theta_s + 0.5]."""
    a = cc.volume_coordinate(np.array([v]))
    t_s = float(cc.theta_split_deg(cc._entry("sphere-sphere"), a)[0])
    t_on = float(cc.onset_deg(cc._entry(cc.WALL_TWO_ANGLES), a)[0])
    return t_on - 1.5, t_s + 0.5


def split_at(v: np.ndarray) -> np.ndarray:
    """The equal spheres' split angle theta_s(V) (deg) from the shipped one-angle pair
    table: the pair's onset at r = 1."""
    return cc.theta_split_deg(cc._entry("sphere-sphere"), cc.volume_coordinate(v))


def _pair_onset_job(args: tuple[float, float]) -> float:
    """The onset (deg) at (ratio, v): :func:`pair_onset` from :func:`onset_bracket` to
    :data:`PAIR_ONSET_TOL_DEG` (from [8, 36] deg if that is not a bracket)."""
    ratio, v = args
    try:
        return pair_onset(ratio, v, *onset_bracket(v), tol=PAIR_ONSET_TOL_DEG,
                          ridge_tol=PAIR_ONSET_PROBE_TOL_DEG)
    except RuntimeError:
        return pair_onset(ratio, v, 8.0, 36.0, tol=PAIR_ONSET_TOL_DEG,
                          ridge_tol=PAIR_ONSET_PROBE_TOL_DEG)


def fit_pair_onset(nw: int, na: int, workers: int = 2,
                   cache_dir: Path | None = None) -> dict[str, Any]:
    """The onset theta_on(w, a) (deg) at the (nw, na) Lobatto nodes and its Chebyshev
    coefficients: at r = 1 (w's first node) the split angle (:func:`split_at`), elsewhere
    :func:`_pair_onset_job`, through the node cache (lines ``pair-onset|r|v|tol``)."""
    rs, vs = ratio_nodes(nw), gen._volume_nodes(na)
    jobs = [(float(r), float(v)) for r in rs[1:] for v in vs]
    got = gen._cached_map(_pair_onset_job, jobs,
                          lambda j: f"pair-onset|{j[0]!r}|{j[1]!r}|{PAIR_ONSET_TOL_DEG}",
                          lambda j, t: (t, []), lambda j, got: got[0], workers,
                          "pair onset angle", cache_dir)
    th = np.vstack([split_at(vs), np.reshape(got, (nw - 1, na))])
    return {"chebyshev": gen.lobatto_coefficients(th).tolist(), "at_nodes_deg": th.tolist(),
            "ratio_nodes": rs.tolist(), "v_nodes": vs.tolist(),
            "tolerance_deg": PAIR_ONSET_TOL_DEG}


def nested_gauss(n: int) -> np.ndarray:
    """Chebyshev-Gauss points ``sin(pi (2k + 1 - n)/(2n))`` on (-1, 1), increasing: the
    :func:`~wetcontact.generate.calibrated_capillary.gauss` points, with the fraction reduced before
    it is rounded, so that every third point of 3n is bit for bit a point of n."""
    from fractions import Fraction

    return np.array([math.sin(math.pi * float(Fraction(2 * k + 1 - n, 2 * n)))
                     for k in range(n)])


def small_angle_grid(onset: dict[str, Any], rng: gen.SphereRange, nb1: int) -> np.ndarray:
    """The small sphere's angle (deg) at the (w, a, b1) Lobatto nodes of a band ``rng``:
    mapped linearly from the band's range at each (w, a) node, an end ``None`` being the
    onset's own value at that node (``onset["at_nodes_deg"]``: the lead grid is the
    onset's), shape (nw, na, nb1)."""
    at = np.asarray(onset["at_nodes_deg"])
    lo, hi = (at if e is None else np.full(at.shape, float(e)) for e in rng)
    return 0.5 * (gen.lobatto(nb1) * (hi - lo)[..., None] + (lo + hi)[..., None])


def _pair_ridge_job(args: tuple[float, float, float, float]) -> tuple[float, float]:
    """:func:`pair_ridge` at (ratio, v, theta1 deg) to ``tol`` over
    :data:`PAIR_RIDGE_BRACKET_DEG`: the top and its bracket's width."""
    ratio, v, t1, tol = args
    return pair_ridge(ratio, v, t1, bracket=PAIR_RIDGE_BRACKET_DEG, tol=tol)


RIDGE_NEAR_DEG = 0.01
"""Half-width (deg) of the bracket in which the ridge is sought at the w nodes a band's
ridge series adds to the onset's (:data:`PAIR_RIDGE_W`), about the coarser series' value
there: that series was off by up to 1.6e-3 deg at the added nodes (40 of them searched;
1.4e-3 at 91 midpoints), so the top lies well inside; a top within ten
tolerances of the bracket's ends (:func:`~wetcontact.generate.calibrated_capillary.golden_top`'s
error) is sought again over :data:`PAIR_RIDGE_BRACKET_DEG`."""


def _pair_ridge_near_job(args: tuple[float, float, float, float, float]
                         ) -> tuple[float, float]:
    """:func:`pair_ridge` at (ratio, v, theta1 deg) to ``tol`` within :data:`RIDGE_NEAR_DEG`
    of ``guess`` (deg), else (a top near that bracket's ends, or no bridge at its first
    points) over :data:`PAIR_RIDGE_BRACKET_DEG`: the top and its bracket's width."""
    ratio, v, t1, tol, guess = args
    near = (guess - t1 - RIDGE_NEAR_DEG, guess - t1 + RIDGE_NEAR_DEG)
    try:
        return pair_ridge(ratio, v, t1, bracket=near, tol=tol)
    except RuntimeError:  # a top at the bracket's end, or SolverError: no bridge there
        return pair_ridge(ratio, v, t1, bracket=PAIR_RIDGE_BRACKET_DEG, tol=tol)


def onset_nodes(onset: dict[str, Any], nw: int) -> tuple[np.ndarray, np.ndarray]:
    """The radius ratios at the ``nw`` Lobatto nodes of w and the onset angle (deg) there at
    the onset's volume nodes, shape (nw, na): the onset's own node values where its nodes
    are among them (``nw - 1`` a multiple of its count less one: the same floats, so that
    the node cache keeps what was solved there), its series elsewhere, as the model maps a
    point."""
    at = np.asarray(onset["at_nodes_deg"])
    rs, vs = ratio_nodes(nw), np.asarray(onset["v_nodes"])
    if nw == at.shape[0]:
        return rs, at
    w, a = np.meshgrid(cc.ratio_coordinate(rs), cc.volume_coordinate(vs), indexing="ij")
    on = np.array(cc.onset_deg({cc.ONSET_KEY: onset}, [w, a]))
    step, rem = divmod(nw - 1, at.shape[0] - 1)
    if rem == 0:
        on[::step] = at
    return rs, on


def fit_pair_ridge(onset: dict[str, Any], rng: gen.SphereRange, nb1: int, tol: float,
                   workers: int = 2, cache_dir: Path | None = None,
                   nw: int | None = None, coarse: dict[str, Any] | None = None
                   ) -> dict[str, Any]:
    """The ridge theta2*(w, a, b1) (deg) of a band at its Lobatto nodes (the onset's (w, a)
    grid times ``nb1``) and its Chebyshev coefficients, through the node cache (lines
    ``pair-ridge|r|v|theta1|tol``).

    ``nw``: more Lobatto nodes of w than the onset's, nesting them (``nw - 1`` a multiple of
    their count less one). The ridge at the onset's nodes is then the one above; at the
    others (their small sphere's angles from :func:`onset_nodes`) it is sought within
    :data:`RIDGE_NEAR_DEG` of that series' value (lines
    ``pair-ridge-near|r|v|theta1|tol``, :func:`_pair_ridge_near_job`: the guess only
    places the bracket, and the top is the same to ``tol``). ``coarse``: that series at
    the onset's nodes as a table holds it (:func:`refine_band`), else
    sought."""
    n0 = len(onset["ratio_nodes"])
    if nw is not None and nw != n0:
        step, rem = divmod(nw - 1, n0 - 1)
        if rem or step < 1:
            raise ValueError(f"fit_pair_ridge: nw = {nw} does not nest the onset's {n0} "
                             "w nodes; allowed: 1 + k (n - 1), k >= 1")
        if coarse is None:
            coarse = fit_pair_ridge(onset, rng, nb1, tol, workers, cache_dir)
        rs, on = onset_nodes(onset, nw)
        vs = np.asarray(onset["v_nodes"])
        t1 = small_angle_grid({"at_nodes_deg": on}, rng, nb1)
        w = cc.ratio_coordinate(rs)
        a = cc.volume_coordinate(vs)
        th = np.empty(t1.shape)
        th[::step] = coarse["at_nodes_deg"]
        new = [i for i in range(nw) if i % step]
        ww, aa, bb = np.meshgrid(w[new], a, gen.lobatto(nb1), indexing="ij")
        guess = cc.theta_split_deg({"theta_split": coarse}, [ww, aa], bb)
        jobs = [(float(rs[i]), float(vs[j]), float(t1[i, j, k]), tol,
                 float(guess[n, j, k]))
                for n, i in enumerate(new) for j, k in np.ndindex(t1.shape[1:])]
        got = gen._cached_map(
            _pair_ridge_near_job, jobs,
            lambda j: f"pair-ridge-near|{j[0]!r}|{j[1]!r}|{j[2]!r}|{j[3]}",
            lambda j, r: (r[0], [r[1]]), lambda j, got: (got[0], float(got[1][0])),
            workers, f"pair ridge {list(rng)} at {nw} w nodes", cache_dir)
        th[new] = np.reshape([t for t, _ in got], (len(new), *t1.shape[1:]))
        return {"chebyshev": gen.lobatto_coefficients(th).tolist(),
                "at_nodes_deg": th.tolist(), "theta_small_nodes_deg": t1.tolist(),
                "ratio_nodes": rs.tolist(), "tolerance_deg": tol,
                "bracket_max_deg": max(coarse["bracket_max_deg"],
                                       max(wd for _, wd in got)),
                "near_deg": RIDGE_NEAR_DEG}
    rs, vs = np.asarray(onset["ratio_nodes"]), np.asarray(onset["v_nodes"])
    t1 = small_angle_grid(onset, rng, nb1)
    jobs = [(float(rs[i]), float(vs[j]), float(t1[i, j, k]), tol)
            for i, j, k in np.ndindex(t1.shape)]
    got = gen._cached_map(_pair_ridge_job, jobs,
                          lambda j: f"pair-ridge|{j[0]!r}|{j[1]!r}|{j[2]!r}|{j[3]}",
                          lambda j, r: (r[0], [r[1]]),
                          lambda j, got: (got[0], float(got[1][0])), workers,
                          f"pair ridge {list(rng)}", cache_dir)
    th = np.reshape([t for t, _ in got], t1.shape)
    return {"chebyshev": gen.lobatto_coefficients(th).tolist(), "at_nodes_deg": th.tolist(),
            "theta_small_nodes_deg": t1.tolist(), "tolerance_deg": tol,
            "bracket_max_deg": max(w for _, w in got)}


PAIR_TOP_DEG = 70.5
"""The piece above the ridge ends at this plus the ridge's offset from theta1
(:data:`~wetcontact.reduced_models.calibrated_capillary.UPPER_PAST_RIDGE`): past the
domain's 70 deg (by a margin for the model's check's rounding) and past the ridge."""
PAIR_PIECES = ({"theta_deg": [0.0, None], "theta_map": cc.RIDGE_QUADRATIC},
               {"theta_deg": [None, PAIR_TOP_DEG], "theta_map": cc.RIDGE_QUADRATIC,
                cc.UPPER_PAST_RIDGE: True})
"""The large sphere's angle's pieces: below and above the ridge, each quadratic toward
it. The first reaches past 70 deg where the ridge does (to 82 deg); the second's upper end
follows the ridge (the wall's fixed 90 deg gave repulsive forces near contact at v = 0.1,
theta1 = 65-70 deg between nearly equal spheres: no logarithm)."""
PAIR_FACTOR_LEFT_AXES = 3
"""The force tables are factorised as (w, a, b1) against (b2, c): at the full stage
729 + 285 (or 171) per rank, against 81 + 2 565 for (w, a) against the rest."""


def lead_grid(onset: dict[str, Any], ridge: dict[str, Any], band_deg: gen.SphereRange,
              nw: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The radius ratios, volumes, small sphere's angles (deg, (nw, na, nb1)) and ridge
    (deg, the same shape) at a piece's (w, a, b1) nodes when it has ``nw`` ratio nodes
    where the band's ridge series has others: the band's range (``band_deg``) and the
    ridge from the onset's and the ridge's series at the ``nw`` Lobatto nodes of w, as the
    model maps a point (so that the piece interpolates what the model evaluates), the
    volumes and b1 nodes the ridge's."""
    rs, on = onset_nodes(onset, nw)
    vs = np.asarray(onset["v_nodes"])
    nb1 = np.shape(ridge["theta_small_nodes_deg"])[2]
    w, a = np.meshgrid(cc.ratio_coordinate(rs), cc.volume_coordinate(vs), indexing="ij")
    t1 = small_angle_grid({"at_nodes_deg": on}, band_deg, nb1)
    shape = t1.shape
    b1 = np.broadcast_to(gen.lobatto(nb1), shape)
    top = cc.theta_split_deg({"theta_split": ridge},
                             [np.broadcast_to(w[..., None], shape),
                              np.broadcast_to(a[..., None], shape)], b1)
    return rs, vs, t1, np.asarray(top).reshape(shape)


def pair_piece_jobs(piece: dict[str, Any], nb2: int, onset: dict[str, Any],
                    ridge: dict[str, Any], nw: int | None = None,
                    band_deg: gen.SphereRange | None = None
                    ) -> tuple[list[tuple], np.ndarray, tuple[int, ...]]:
    """The node jobs of one piece of a two-angle pair table (:func:`fit_pair_piece`'s: one
    ``meniscus`` branch each, :func:`~wetcontact.generate.calibrated_capillary._node_job`),
    the volumes at its a nodes and the shape of its (w, a, b1, b2) grid."""
    vs = np.asarray(onset["v_nodes"])
    t1 = np.asarray(ridge["theta_small_nodes_deg"])
    top = np.asarray(ridge["at_nodes_deg"])
    nw = len(onset["ratio_nodes"]) if nw is None else nw
    rs = ratio_nodes(nw)
    step, rem = divmod(t1.shape[0] - 1, nw - 1)
    if rem == 0:  # the ridge's w nodes nest the piece's: its own values there
        t1, top = t1[::step], top[::step]
    else:
        if band_deg is None:
            raise ValueError("fit_pair_piece: other ratio nodes than the ridge's need the "
                             "band's range (band_deg)")
        rs, vs, t1, top = lead_grid(onset, ridge, band_deg, nw)
    b2, c_nodes = nested_gauss(nb2), gen.lobatto(GAP_NODES)
    lo, hi = ((top if e is None else np.full(top.shape, float(e)))
              for e in piece["theta_deg"])
    if piece.get(cc.UPPER_PAST_RIDGE):
        hi = hi + (top - t1)
    jobs = []
    for idx in np.ndindex(*t1.shape, nb2):
        lead = idx[:3]
        t2 = float(cc.piece_angle(piece, b2[idx[3]], lo[lead], hi[lead]))
        jobs.append((idx, "sphere-sphere", float(rs[idx[0]]), float(vs[idx[1]]),
                     math.radians(t1[lead]), c_nodes, math.radians(t2)))
    return jobs, vs, (*t1.shape, nb2)


def fit_pair_piece(piece: dict[str, Any], nb2: int, onset: dict[str, Any],
                   ridge: dict[str, Any], workers: int = 2,
                   cache_dir: Path | None = None, nw: int | None = None,
                   band_deg: gen.SphereRange | None = None) -> dict[str, Any]:
    """One piece's rupture and force tables over (w, a, b1, b2, c) from ``meniscus`` at
    its nodes: b2 at ``nb2`` :func:`nested_gauss` points of the large sphere's angle,
    mapped within the piece at each (w, a, b1) node from the ridge's own value there
    (:func:`~wetcontact.reduced_models.calibrated_capillary.piece_angle`). ``nw``: ratio
    nodes other than the onset's; where the ridge's w nodes nest them, the ridge's own
    values there, else its series, in the band ``band_deg`` (:func:`lead_grid`;
    the jobs: :func:`pair_piece_jobs`)."""
    jobs, vs, shape = pair_piece_jobs(piece, nb2, onset, ridge, nw, band_deg)
    rup, q = np.empty(shape), np.empty((*shape, GAP_NODES))
    results = gen._cached_map(gen._node_job, jobs, gen.NodeCache.key,
                              lambda j, r: (r[1], r[2]), lambda j, got: (j[0], *got),
                              workers, f"pair piece {piece['theta_deg']}", cache_dir)
    for idx, s_c, qq in results:
        rup[idx] = math.log(s_c / vs[idx[1]] ** (1.0 / 3.0))
        q[idx] = np.log(qq)
    left, right, err = gen.factor_table(gen.lobatto_coefficients(q, (3,)),
                                        PAIR_FACTOR_LEFT_AXES)
    return {"theta_deg": piece["theta_deg"], "nodes": list(q.shape),
            "theta_map": piece["theta_map"], "theta_points": "gauss",
            **({cc.UPPER_PAST_RIDGE: True} if piece.get(cc.UPPER_PAST_RIDGE) else {}),
            "rupture": gen.lobatto_coefficients(rup, (3,)).tolist(),
            "force_left": left.tolist(), "force_right": right.tolist(),
            "force_rank": int(left.shape[-1]), "force_factor_change": err}


def fit_pair_table(stage: str = "coarse", workers: int = 2,
                   cache_dir: Path | None = None) -> dict[str, Any]:
    """The two-angle sphere-pair table at ``stage`` (:data:`STAGES`): the onset series
    theta_on(w, a), and per band (:data:`PAIR_BANDS_DEG`) its ridge series theta2*(w, a,
    b1) and the two pieces over (w, a, b1, b2, c)."""
    st = STAGES[stage]
    onset = fit_pair_onset(st["w"], st["a"], workers, cache_dir)
    bands = []
    for i, (rng, tol) in enumerate(zip(PAIR_BANDS_DEG, PAIR_RIDGE_TOL_DEG, strict=True)):
        ridge = fit_pair_ridge(onset, rng, st["b1"], tol, workers, cache_dir,
                               PAIR_RIDGE_W[i] if stage == "full" else None)
        nodes = (pair_band_nodes(i) if stage == "full"
                 else [[st["w"], st["a"], st["b1"], n, GAP_NODES] for n in st["b2"]])
        bands.append({"theta_sphere_deg": list(rng), "theta_split": ridge,
                      "pieces": [gen.train_piece(fit_pair_piece(p, n[3], onset, ridge,
                                                                workers, cache_dir, n[0],
                                                                rng))
                                 for p, n in zip(PAIR_PIECES, nodes, strict=True)]})
    return {"stage": stage, cc.ONSET_KEY: onset, "bands": bands}


_NEAR = {"theta2_deg_from_ridge": [-gen.NEAR_RIDGE_DEG, gen.NEAR_RIDGE_DEG]}
_ONSET_SPHERE_DEG = (17.5, 35.0)
LOW_ANGLES_DEG = (0.0, 15.0)
LOW_ANGLES_V = (0.01, 0.1)
"""The low-angle stratum of the two-angle pair table: both angles in ``LOW_ANGLES_DEG``
(deg), V/R_s^3 log-uniform in ``LOW_ANGLES_V``: below the onset and the ridge (band 0's
lower piece) S_c oscillates in the radius ratio between too few ratio nodes (with 9: by up
to 2.1e-4 at r = 1.63, V* = 0.1, theta = 0 and 3 deg, the force at 0.999 S_c by up to
3e-3), where neither the uniform design (its 0.999 S_c gaps rare) nor the corners (angles
0, 35, 70 deg) land. With the piece's 13 ratio nodes its maxima are S_c 3.5e-5 and the
force 7.8e-4 (r = 1.02, angles 12.5 and 14.4 deg, 0.999 S_c); the record is in
``docs/calibrated_capillary.md``."""
PAIR_STRATA: dict[str, dict[str, Any]] = {
    "held_out": {"seed": 2621},
    "held_out_near_ridge": {"seed": 2622, "near_ridge": True, "part": 3, "stratum": _NEAR},
    "held_out_ridge_top": {
        "seed": 2623, "ridge_band": gen.RIDGE_TOP_BAND_DEG, "part": 2,
        "stratum": {"theta2_deg_from_ridge_abs_log_uniform": list(gen.RIDGE_TOP_BAND_DEG)}},
    "held_out_ridge_onset": {
        "seed": 2624, "ridge_band": (1e-4, 3e-2), "scale": 2,
        "theta_range": _ONSET_SPHERE_DEG,
        "stratum": {"theta_sphere_deg": list(_ONSET_SPHERE_DEG),
                    "theta2_deg_from_ridge_abs_log_uniform": [1e-4, 3e-2]}},
    "held_out_near_equal": {
        "seed": 2625, "near_equal": True, "near_ridge": True, "part": 3,
        "stratum": {"radius_ratio": list(gen.NEAR_EQUAL["radius_ratio"]),
                    "theta_sphere_deg": list(gen.NEAR_EQUAL["theta_deg"]), **_NEAR}},
    "held_out_low_angles": {
        "seed": 2626, "part": 2, "theta_range": LOW_ANGLES_DEG,
        "theta2_range": LOW_ANGLES_DEG, "v_range": LOW_ANGLES_V,
        "fractions": gen.CORNER_FRACTIONS,
        "stratum": {"theta_sphere_deg": list(LOW_ANGLES_DEG),
                    "theta2_deg": list(LOW_ANGLES_DEG), "v": list(LOW_ANGLES_V)}},
    "held_out_ridge_onset_rupture": {
        "seed": 2628, "ridge_band": gen.RIDGE_TOP_BAND_DEG, "theta_range": _ONSET_SPHERE_DEG,
        "fractions": gen.CORNER_FRACTIONS,
        "stratum": {"theta_sphere_deg": list(_ONSET_SPHERE_DEG),
                    "theta2_deg_from_ridge_abs_log_uniform": list(gen.RIDGE_TOP_BAND_DEG)}},
    "held_out_ridge_window": {
        "seed": 2627, "ridge_band": gen.ridge_window_band(PAIR_TWO_ANGLES), "part": 2,
        "fractions": gen.CORNER_FRACTIONS,
        "stratum": {"theta2_deg_from_ridge_abs_log_uniform":
                    list(gen.ridge_window_band(PAIR_TWO_ANGLES))}},
}
"""The two-angle pair table's held-out design (against ``meniscus``), as the wall's: a
uniform one and its stress strata, the large sphere's angle within
:data:`~wetcontact.generate.calibrated_capillary.NEAR_RIDGE_DEG` of the table's ridge, at a
log-uniform distance from it (its top), at the small sphere's angles where the top's jump
appears (the onset runs from 31 deg at r = 1 to 16.6 at r = 10, v = 0.1), and nearly
equal spheres (r < 1.1, theta1 20-45 deg) near the ridge, where both sides of the top are
a cusp's (|delta|^(2/3)) rather than a jump's; and both angles low at large volumes
(:data:`LOW_ANGLES_DEG`), at the corner stratum's gaps up to 0.999 S_c (where the lower
piece below the onset had 9 ratio nodes); at the small sphere's angles where the jump
appears, 1e-4 to 0.3 deg from the ridge, at the same gaps (the wall's force near rupture
past the ridge was under-resolved there, unseen at random gaps); and within the ridge's window
(:func:`~wetcontact.generate.calibrated_capillary.ridge_window_band`), at the same gaps, where the
ridge series (off by up to 6.3e-4 deg at V* = 0.1 between its nodes with 9 w nodes; with
17 up to 5e-4 deg between its a nodes near the onset) may put a point on the other side
of S_c's jump. ``part``: the
uniform count over this, ``scale``: times it; ``stratum``: what the table records (the
wall's names; the model applies a stratum with ``theta_sphere_deg`` only to small-sphere
angles inside it)."""


def pair_held_out(entry: dict[str, Any], n: int = 120, workers: int = 2,
                  cache_dir: Path | None = None) -> dict[str, dict[str, Any]]:
    """The held-out tables of a two-angle pair table (``entry``) per stratum of
    :data:`PAIR_STRATA` and its corner stratum
    (:func:`~wetcontact.generate.calibrated_capillary.strata_held_out`)."""
    return gen.strata_held_out(PAIR_TWO_ANGLES, PAIR_STRATA, entry, n, workers, cache_dir)


def pair_band_nodes(band: int) -> list[list[int]]:
    """The node counts of each piece of band ``band`` of the two-angle sphere-pair table at
    :data:`STAGES`' full stage (w, a, b1, b2, c), with the generator's
    :data:`~wetcontact.generate.calibrated_capillary.BAND_NODES`'."""
    st = STAGES["full"]
    over = gen.BAND_NODES.get(cc.PAIR_TWO_ANGLES, {}).get(band, {})
    return [list(over.get(j, [st["w"], st["a"], st["b1"], nb2, GAP_NODES]))
            for j, nb2 in enumerate(st["b2"])]


def refine_band(kind: str, band: int | Sequence[int], out: Path | None = None,
                workers: int = 2, cache_dir: Path | None = None) -> dict[str, Any]:
    """Fit again the pieces of band ``band`` (or of each band of a sequence, in turn) of
    the two-angle table ``kind`` in the file ``out`` (default the package data) whose node
    counts differ from their specification (``calibrated_capillary.band_pieces``,
    :func:`pair_band_nodes`),
    from the band's own ridge series and the table's onset series as the file holds them
    (no onset search; a ridge search only at the w nodes
    :data:`PAIR_RIDGE_W` adds to a pair band's ridge, whose pieces keep their
    nodes: a fit from scratch computes the same series), rebuild their tensor trains and
    write the table back with its held-out tables measured again, once; returns the
    table's entry (``refine_band``: each refitted band's wall time and branches, without
    the held-out tables', ``held_out_wall_time_s``). What ``calibrated_capillary.fit_kind``
    and :func:`fit_pair_table` would fit from scratch, without their searches. It lives here,
    above both tables' generators, because a pair band needs this module's pieces."""
    out = Path(out) if out else Path(cc.__file__).parents[1] / "data" / cc.CAPILLARY_FILE
    data = json.loads(out.read_text())
    if kind not in (cc.WALL_TWO_ANGLES, cc.PAIR_TWO_ANGLES) or kind not in data:
        raise InputError(f"{out}: field {kind!r} missing or not a two-angle table; allowed: "
                         f"{cc.WALL_TWO_ANGLES}, {cc.PAIR_TWO_ANGLES}")
    entry = data[kind]
    onset = entry.get(cc.ONSET_KEY)
    records = {}
    bands = [band] if isinstance(band, int) else list(band)
    for k_band in bands:
        t0 = time.perf_counter()
        start = dict(gen.BRANCHES)
        b = entry["bands"][k_band]
        rng = tuple(b["theta_sphere_deg"])
        pieces = list(b["pieces"])
        if kind == cc.WALL_TWO_ANGLES:
            for i, spec in enumerate(gen.band_pieces(kind, k_band)):
                if list(pieces[i]["nodes"]) != spec["nodes"]:
                    pieces[i] = gen.train_piece(gen.fit_piece(kind, spec, b["theta_split"],
                                                              workers, cache_dir, rng, onset),
                                                fields=gen.WALL_TRAINS)
        else:
            ridge = b["theta_split"]
            if np.shape(ridge["at_nodes_deg"])[0] != PAIR_RIDGE_W[k_band]:
                # nested w nodes: the pieces' nodes keep their angles; only the series changes
                b = {**b, "theta_split": fit_pair_ridge(
                    onset, rng, np.shape(ridge["at_nodes_deg"])[2], ridge["tolerance_deg"],
                    workers, cache_dir, PAIR_RIDGE_W[k_band], ridge)}
            for i, (spec, nodes) in enumerate(zip(PAIR_PIECES, pair_band_nodes(k_band),
                                                  strict=True)):
                if list(pieces[i]["nodes"]) != nodes:
                    pieces[i] = gen.train_piece(fit_pair_piece(spec, nodes[3], onset,
                                                               b["theta_split"], workers,
                                                               cache_dir, nodes[0], rng))
        entry["bands"][k_band] = {**b, "pieces": pieces}
        records[str(k_band)] = {"wall_time_s": round(time.perf_counter() - t0, 1),
                                "branches": {k: gen.BRANCHES[k] - start[k] for k in gen.BRANCHES}}
    entry = {k: v for k, v in entry.items() if not k.startswith("held_out")}
    data[kind] = entry
    gen._write(out, data)
    t0 = time.perf_counter()
    arrays = cc.as_arrays({kind: entry})[kind]
    if kind == cc.PAIR_TWO_ANGLES:
        entry.update(pair_held_out(arrays, 120, workers, cache_dir))
    else:
        entry.update(gen._wall_two_held_out(arrays, 120, workers, cache_dir))
    held = round(time.perf_counter() - t0, 1)
    entry.setdefault("refine_band", {}).update(
        {k: {**r, "held_out_wall_time_s": held} for k, r in records.items()})
    data[kind] = entry
    gen._write(out, data)
    return entry


def generate_pair_table(stage: str = "coarse", out: Path | None = None, workers: int = 2,
                        n_held_out: int = 120, cache_dir: Path | None = None,
                        retrain: bool = False) -> dict[str, Any]:
    """Fit the two-angle pair table at ``stage`` and its held-out tables, and write it
    into ``out`` (a copy of the package data's file, or that file itself: other kinds are
    kept as they are). ``retrain``: keep the fit ``out`` holds (no node solved), build its
    pieces' tensor trains again (:func:`train_piece`) and measure its held-out tables again
    (``stage`` is then the one ``out`` holds)."""
    t0 = time.perf_counter()
    start = dict(gen.BRANCHES)
    out = Path(out) if out else Path(cc.__file__).parents[1] / "data" / cc.CAPILLARY_FILE
    data = json.loads(out.read_text()) if out.is_file() else {}
    if retrain:
        if PAIR_TWO_ANGLES not in data:
            raise InputError(f"{out}: field '{PAIR_TWO_ANGLES}' missing: nothing to retrain; "
                             "allowed: a table file that holds the two-angle pair table")
        old = data[PAIR_TWO_ANGLES]
        entry = {k: old[k] for k in ("stage", cc.ONSET_KEY)}
        entry["bands"] = [{**b, "pieces": [gen.train_piece(p) for p in b["pieces"]]}
                          for b in old["bands"]]
    else:
        entry = fit_pair_table(stage, workers, cache_dir)
    entry["train_time_s" if retrain else "fit_time_s"] = round(time.perf_counter() - t0, 1)
    entry.update(pair_held_out(cc.as_arrays({"e": entry})["e"], n_held_out, workers,
                               cache_dir))
    t = round(time.perf_counter() - t0, 1)
    branches = {k: gen.BRANCHES[k] - start[k] for k in gen.BRANCHES}
    if retrain:  # the fit's own record stays; the retrain's beside it
        entry.update({k: old[k] for k in ("fit_time_s", "wall_time_s", "branches",
                                          "refine_band") if k in old},
                     retrain_wall_time_s=t, retrain_branches=branches)
    else:
        entry.update(wall_time_s=t, branches=branches)
    data[PAIR_TWO_ANGLES] = entry
    gen._write(out, data)
    return entry
