r"""Sphere pairs with two contact angles: the ridge of the rupture distance and its top's
kind, the measurements behind the design of a ``calibrated-capillary`` table for them
(issue 11; findings in ``docs/notes/sphere_pair_two_angles.md``).

A bridge between a small sphere (radius R_s = 1, contact angle theta1) and a large one
(radius r = R_l/R_s, angle theta2) ruptures at S_c(r, v, theta1, theta2). Over theta2 at
fixed theta1, S_c rises to a top at theta2^* and falls beyond it, as over the wall's angle
on a wall (:func:`wetcontact.calibrate_capillary._ridge_job`, which the search here
shares: :func:`~wetcontact.calibrate_capillary.golden_top`). The top is one of three
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

import math
from dataclasses import dataclass

from wetcontact import calibrate_capillary as gen
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
    (:func:`~wetcontact.calibrate_capillary.golden_top` to ``tol`` over ``theta_deg`` plus
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
        :func:`~wetcontact.calibrate_capillary.left_slope` at h and at
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
    :func:`~wetcontact.calibrate_capillary.golden_top`.

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


def pair_top(ratio: float, v: float, theta1_deg: float) -> TopShape:
    """The ridge over the large sphere's angle at theta1 (:func:`pair_ridge`) and its
    :func:`top_shape`."""
    top, width = pair_ridge(ratio, v, theta1_deg)
    return top_shape(lambda x: pair_rupture(ratio, v, theta1_deg, x), top, width)


def pair_onset(ratio: float, v: float, lo: float, hi: float,
               tol: float = 0.5) -> float:
    """Bisection (to ``tol``, deg) for the small sphere's angle in [lo, hi] above which the
    top over the large sphere's angle is not smooth (:func:`pair_top`); the top must be
    smooth at ``lo`` and not at ``hi`` (the generator's
    :func:`~wetcontact.calibrate_capillary.bisect_change`)."""
    return gen.bisect_change(lambda t: pair_top(ratio, v, t).kind != "smooth", (lo, hi),
                              tol, f"the pair's onset at radius ratio {ratio:.6g}", v)
