r"""The calibrated capillary closure's domain and its coordinates, each mapped to [-1, 1].

- ``a`` from ln v over :data:`V_RANGE`; for sphere pairs ``w`` from ``(ln r)^(1/3)`` over
  :data:`RATIO_RANGE`: between equal spheres a symmetry-breaking bifurcation ends the branch
  at larger angles, and a small inequality of the radii unfolds it into a fold at
  ``S_b - k (ln r)^(2/3)``, so S_c is smooth in w, not in r.
- ``b`` from an angle within its piece (:func:`piece_coordinate`): linear, or quadratic
  toward the ridge (:data:`RIDGE_QUADRATIC`), so that the nodes cluster there and a
  square-root side of the ridge's top is linear in b; ``b1`` from the (small) sphere's angle
  within its band (:func:`sphere_coordinate`).
- ``c = 2 z - 1`` from the gap (:func:`gap_coordinate`),

.. math::
    z = \sqrt{1 - \ln(1 + S/\varepsilon)/\ln(1 + S_c/\varepsilon)},\qquad
    \varepsilon = \sqrt{V/(\pi R^*)},

  which resolves both the drop of the force over the bridge's thin-gap height epsilon
  (Willett et al. 2000 scale their gap by it) and the square-root shape of the branch at its
  fold (``F - F_c ~ sqrt(S_c - S)``).

Pieces and bands. Between equal spheres the stable branch ends at a fold below an angle
theta_s(V) of about 30-31 deg and at a symmetry-breaking bifurcation above it (Maddocks
1987), so S_c has a kink there and a sphere-pair table has two pieces in theta. With two
angles S_c rises to a ridge in the other solid's angle, theta_w*(V, theta_s), 1.5-34 deg
above the sphere's, and falls beyond it; above an onset angle theta_on(V) of the sphere's
(29.9 deg at v = 1e-4 to 18.1 at 0.1) it jumps at the ridge's top (the branch ends at one of
two nearby folds, and which one changes there). A two-angle table is therefore three bands
in the (small) sphere's angle, [0, theta_on], [theta_on, 35] and [35, 70] deg, each with two
pieces in the other angle that meet at the ridge: up to :data:`RIDGE_TOP_DEG` on a wall, up
to ``70.5 + theta2* - theta1`` between spheres (:data:`UPPER_PAST_RIDGE`). The series that
place these ends are evaluated in :mod:`~wetcontact.reduced_models.calibrated_capillary.kernel`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

V_RANGE = (1e-4, 0.1)
"""V/R_small^3."""
THETA_RANGE_DEG = (0.0, 70.0)
"""The one contact angle of the pair, or each of the two on a wall (deg)."""
RATIO_RANGE = (1.0, 10.0)
"""R_large/R_small of a sphere pair."""
W_MAX = math.log(RATIO_RANGE[1]) ** (1.0 / 3.0)
WALL_TWO_ANGLES = "sphere-wall-two-angles"
"""Table key of a sphere and a wall with two different contact angles."""
PAIR_TWO_ANGLES = "sphere-sphere-two-angles"
"""Table key of two spheres with two different contact angles (theta1 the small sphere's,
theta2 the large one's; its lead coordinates are (w, a) where the wall's are (a,))."""
TWO_ANGLE_TABLES = {"sphere-wall": WALL_TWO_ANGLES, "sphere-sphere": PAIR_TWO_ANGLES}
"""The two-angle table of each geometry."""
RIDGE_TOP_DEG = 90.0
"""Upper end of the wall angle's second piece (two angles on a wall): beyond the ridge,
which reaches about 85 deg at the sphere angle 70 deg and v = 0.1."""


ANGLE_TOL = 1e-9
"""Two contact angles closer than this (rad) count as one."""


def _map(x: np.ndarray, lo: Any, hi: Any) -> np.ndarray:
    return (2.0 * x - lo - hi) / (hi - lo)


def volume_coordinate(v: np.ndarray) -> np.ndarray:
    """``a`` in [-1, 1] from ln v over :data:`V_RANGE`."""
    return _map(np.log(v), math.log(V_RANGE[0]), math.log(V_RANGE[1]))


def ratio_coordinate(ratio: np.ndarray) -> np.ndarray:
    """``w`` in [-1, 1] from (ln r)^(1/3) over :data:`RATIO_RANGE`."""
    return _map(np.cbrt(np.log(ratio)), 0.0, W_MAX)


Lead = np.ndarray | list[np.ndarray]
"""The lead coordinates of a two-angle table's points: the volume coordinate ``a`` (a
wall), or the list ``[w, a]`` (a sphere pair)."""


def lead_list(lead: Lead) -> list[np.ndarray]:
    """The lead coordinates as a list of float arrays (``a`` alone: ``[a]``)."""
    if isinstance(lead, list | tuple):
        return [np.asarray(x, dtype=float) for x in lead]
    return [np.asarray(lead, dtype=float)]


def _take(lead: Lead, m: np.ndarray) -> Lead:
    """The lead coordinates of the points ``m``."""
    return [x[m] for x in lead] if isinstance(lead, list | tuple) else lead[m]


def sphere_coordinate(band: dict[str, Any], theta_sphere_deg: np.ndarray,
                      lo: Any = None, hi: Any = None) -> np.ndarray:
    """b1: the sphere's angle (deg) mapped linearly from its band's range to [-1, 1] (the
    range per point, ``lo`` and ``hi``, where an end is the onset angle:
    :func:`sphere_range`)."""
    if lo is None or hi is None:
        lo, hi = band["theta_sphere_deg"]
    return _map(np.asarray(theta_sphere_deg, dtype=float), lo, hi)


UPPER_PAST_RIDGE = "upper_past_ridge"
"""A piece's flag (the pair table's piece above the ridge): its upper end is
``theta_deg[1] + theta2* - theta1`` (deg), its number plus the ridge's offset from the
small sphere's angle. It is at or past both the domain's 70 deg and the ridge and smooth in
the lead coordinates, where a fixed 90 deg (the wall's) would reach angle sums at which the
force near contact between nearly equal spheres turns repulsive (v = 0.1, theta1 = 65,
theta2 = 86.7 deg), so that its logarithm has no table."""


def piece_range(piece: dict[str, Any], split: np.ndarray | None, n: int,
                first_deg: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A piece's theta range (deg) per point: a number, or ``None`` for the split angle;
    with :data:`UPPER_PAST_RIDGE` the upper end moves with the ridge ``split`` and the
    (small) sphere's angle ``first_deg``."""
    ends = []
    for e in piece["theta_deg"]:
        if e is None:
            if split is None:
                raise ValueError("calibrated-capillary: a piece bounded by the split angle "
                                 "in a table without one")
            ends.append(np.asarray(split, dtype=float))
        else:
            ends.append(np.full(n, float(e)))
    if piece.get(UPPER_PAST_RIDGE):
        if split is None or first_deg is None:
            raise ValueError("calibrated-capillary: a piece whose upper end follows the "
                             "ridge needs the ridge and the sphere's angle")
        ends[1] = ends[1] + (np.asarray(split, dtype=float) - first_deg)
    return ends[0], ends[1]


RIDGE_QUADRATIC = "ridge-quadratic"
"""A piece's ``theta_map`` whose angle coordinate is quadratic toward its end at the ridge
(:func:`piece_coordinate`)."""


def piece_coordinate(piece: dict[str, Any], theta_deg: np.ndarray, lo: np.ndarray,
                     hi: np.ndarray) -> np.ndarray:
    r"""``b`` in [-1, 1] of the angle (deg) within its piece [lo, hi]: linear, or, for a
    piece with ``theta_map`` :data:`RIDGE_QUADRATIC` (two angles on a wall), quadratic
    toward its end at the ridge,

    .. math::
        \theta = \theta^* - (\theta^* - lo) \big(\tfrac{1 - b}{2}\big)^2 \ \text{(below)},
        \qquad \theta = \theta^* + (hi - \theta^*) \big(\tfrac{1 + b}{2}\big)^2
        \ \text{(above)},

    so that a top of S_c like ``S* - k sqrt|theta - theta*|`` is linear in b and a smooth
    maximum stays smooth; the nodes cluster at the ridge. An angle past the ridge end (by
    rounding only: points are assigned to pieces by the same series) gets the end's b."""
    ends = piece["theta_deg"]
    if piece.get("theta_map") != RIDGE_QUADRATIC or None not in ends:
        return _map(theta_deg, lo, hi)
    if ends[1] is None:  # the ridge is the upper end
        return 1.0 - 2.0 * np.sqrt(np.clip((hi - theta_deg) / (hi - lo), 0.0, None))
    return 2.0 * np.sqrt(np.clip((theta_deg - lo) / (hi - lo), 0.0, None)) - 1.0


def piece_angle(piece: dict[str, Any], b: np.ndarray, lo: Any, hi: Any) -> np.ndarray:
    """The angle (deg) at coordinate ``b`` of a piece: the inverse of
    :func:`piece_coordinate`."""
    ends = piece["theta_deg"]
    if piece.get("theta_map") != RIDGE_QUADRATIC or None not in ends:
        return 0.5 * (b * (hi - lo) + lo + hi)
    if ends[1] is None:
        return hi - (hi - lo) * (0.5 * (1.0 - b)) ** 2
    return lo + (hi - lo) * (0.5 * (1.0 + b)) ** 2


def gap_coordinate(s: np.ndarray, s_c: np.ndarray, eps: np.ndarray) -> np.ndarray:
    """``c = 2 z - 1`` with ``z = sqrt(1 - ln(1 + S/eps)/ln(1 + S_c/eps))`` (S, S_c, eps in
    one unit); S = 0 maps to 1, the rupture distance to -1."""
    ratio = np.log1p(s / eps) / np.log1p(s_c / eps)
    return 2.0 * np.sqrt(np.clip(1.0 - ratio, 0.0, 1.0)) - 1.0


def gap_from_coordinate(c: np.ndarray, s_c: float, eps: float) -> np.ndarray:
    """The gap at coordinate ``c``: the inverse of :func:`gap_coordinate`."""
    z = 0.5 * (np.asarray(c) + 1.0)
    return eps * np.expm1((1.0 - z**2) * math.log1p(s_c / eps))
