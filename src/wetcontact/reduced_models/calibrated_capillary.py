r"""Calibrated capillary closure (level 0, ``calibrated-capillary``): tensor Chebyshev
interpolants of the ``meniscus`` force and rupture distance, one contact angle per pair, or
two (a sphere's and a wall's, or each sphere's).

Scope
-----
A pendular bridge of volume V between a sphere and a wall, or two spheres of radii
``R_s <= R_l`` (radius ratio ``r = R_l/R_s`` in [1, 10]), with ``v = V/R_s^3`` in
[1e-4, 0.1] and **the same** contact angle theta in [0, 70 deg] on both solids (what Yade's
capillary law and Willett's fit assume), or two: on a wall, the sphere's angle theta_s and
the wall's theta_w, between spheres, the small sphere's theta1 and the large one's theta2,
each in [0, 70 deg]; no gravity, any gap up to rupture. Outside, the model refuses and
names ``meniscus``.

Form
----
Rupture distance and force, with ``R* = R_s R_l/(R_s + R_l)`` (``R* = R`` on a wall) and
``rho = R*/R_s``:

.. math::
    S_c = R_s\, v^{1/3} \exp\Big(\sum_{ij} C^{rup}_{ij\ldots} T_i(a) T_j(b) \ldots\Big),\qquad
    F = 2\pi\sigma R^* (2\cos\theta)\,
        \exp\Big(\sum_{ijk} C^{F}_{ijk\ldots} T_i(a) T_j(b) T_k(c) \ldots\Big),

the Derjaguin force at contact times a smooth correction (Derjaguin 1934; PHYSICS.md
section 2). The coordinates, each mapped to [-1, 1]: ``a`` from ln v, ``b`` from theta
(within its piece, below),
``w = (ln r)^(1/3)`` for sphere pairs (between equal spheres a symmetry-breaking
bifurcation ends the branch at larger angles; a small inequality of the radii unfolds it
into a fold at ``S_b - k (ln r)^(2/3)``, so ``S_c`` is smooth in w, not in r), and ``c``
from the gap,

.. math::
    z = \sqrt{1 - \ln(1 + S/\varepsilon)/\ln(1 + S_c/\varepsilon)},\qquad
    \varepsilon = \sqrt{V/(\pi R^*)},

which resolves both the drop of the force over the bridge's thin-gap height ``epsilon``
(Willett et al. 2000 scale their gap by it) and the square-root shape of the branch at its
fold (``F - F_c ~ sqrt(S_c - S)``).

Between equal spheres the stable branch ends at a fold below an angle theta_s(V) of about
30-31 deg and at a symmetry-breaking bifurcation above it (Maddocks 1987), so S_c has a
kink there; sphere pairs therefore carry two tables, theta in [0, theta_s(V)] and
[theta_s(V), 70 deg], b mapped within each, and theta_s as a Chebyshev series in ``a``
(located by bisection on the branch's end). The coefficients interpolate ``meniscus`` at
tensor Chebyshev-Lobatto points (:mod:`wetcontact.generate.calibrated_capillary`); the package
data ``data/calibrated_capillary.json`` holds them with their held-out error tables.

Two angles on a wall (table ``sphere-wall-two-angles``): the prefactor is ``2 pi sigma R
(cos theta_s + cos theta_w)``. As theta_w grows, S_c rises to a ridge and falls beyond it,
at ``theta_w*(V, theta_s)``, 1.5-34 deg above theta_s (rising with V, falling with
theta_s). The table is three tables (``bands``) in the
sphere's angle: [0, theta_on(V)], [theta_on(V), 35] and [35, 70] deg, theta_on the onset
angle below (a point at an end belongs to the lower table, :func:`band_index`). Each has
coordinates a, b1 from theta_s over its range at the point's V (:func:`sphere_range`,
:func:`sphere_coordinate`), b2 from theta_w within its piece, and c. In each the wall
angle's pieces are [0, theta_w*] and [theta_w*, 90 deg] (the second reaches past 70 deg so
that it is never empty: theta_w* is up to about 85 deg), with theta_w* a tensor Chebyshev
series in (a, b1) of that table located by a golden-section search for the maximum of S_c
to 1e-6 deg (:func:`wetcontact.generate.calibrated_capillary.fit_ridge`). Within each piece b2
is quadratic toward the ridge (:func:`piece_coordinate`), so that the nodes cluster there and
a square-root side of the top is linear in b2.

The ridge's top changes its shape at theta_on(V), and this is why the table is split
there. Below it the top is a smooth maximum (v = 1e-3, theta_s = 20 deg: S_c drops by 3e-7
at 0.01 deg from the top, as the square of the distance). Above it S_c **jumps** at the
top: the stable branch from contact ends at one of two nearby folds (nearing one, the
contact line recedes on the sphere and advances on the wall; nearing the other, the
reverse), and which one it reaches changes at theta_w*. From below, S_c rises to the jump
at a finite slope; above, it starts lower and falls like a square root (v = 0.082, theta_s
= 50 deg: down by 7.7e-4 of S_c within 5e-5 deg, then by another 3.9e-4 over 2.5e-4 deg).
The jump grows from the onset as about (theta_s - theta_on)^2 (v = 0.08: 1.1e-5
(theta_s - theta_on)^1.93, to 1.2e-3 of S_c at v = 0.1, theta_s = 44 deg). theta_on falls
from 29.9 deg at v = 1e-4 to 18.1 at 0.1 (:data:`ONSET_KEY`, a Chebyshev series in a
located by bisection at 10 nodes, :func:`wetcontact.generate.calibrated_capillary.fit_onset`).
There the ridge's locus has a kink of its curvature (v = 0.08: the second derivative drops from
0.021 to 0.0095 per deg, the slope continuous), which a series across it follows slowly:
one table over [0, 35] deg missed the true top by up to 1.2e-2 deg (v = 0.08, theta_s = 21
deg), so that between its series and the true top it evaluated the other side's arm
(held-out where the jump appears, 240 bridges: 1.5e-3 rupture distance, 9.8e-4 force);
one over [0, 70] deg by 1.6e-2. Split at the onset (and with 23 and 27 b2 nodes below
and above the ridge since 2026-11-27/28), held-out maxima (rupture distance / force; goals
5e-4 / 1e-3) are 1.2e-5 / 2.0e-5 uniformly, 4.4e-5 / 4.0e-5 within :data:`RIDGE_ZONE_DEG`
of the ridge, 2.0e-5 / 6.2e-5 within :data:`RIDGE_TOP_ZONE_DEG`, 2.2e-5 / 3.1e-4 where the
jump appears (theta_s 17.5-35 deg, 1e-4 to 3e-2 deg from the series; 9.1e-5 / 4.5e-4 out
to 0.3 deg at gaps to 0.999 S_c); the closure's :meth:`CalibratedCapillary.bound_floor`
still claims no less than its held-out maxima near the ridge.

The ridge's window. A jump sits where the true top is, the table's where its series is; a
point between the two is evaluated on the other side of the jump, its S_c off by up to the
jump (:data:`RIDGE_JUMP_MAX`). The series' error, measured on 2026-11-28, sets the
window's half-width per table (:data:`RIDGE_WINDOW_DEG`: 5e-5 deg on a wall, 2e-3 deg
between spheres, 4e-5 deg between spheres at theta1 above 35 deg, :data:`RIDGE_WINDOW_TOP`,
since their ridge series above the onset has 17 w nodes, 9 before: off by 6.2e-4 deg
there; from the onset to 35 deg it is still off by up to 5e-4 deg between its a nodes).
Its held-out stratum ``held_out_ridge_window`` (log-uniform from 1e-7 deg to the edge of
:data:`RIDGE_WINDOW_DEG`, to 0.999 S_c): on a wall 1.5e-4 / 9.7e-4 (rupture distance /
force; 1.1e-4 / 1.8e-3 before its piece above the ridge had 27 b2 nodes), between spheres
3.8e-4 / 7.6e-4 (3.8e-4 / 7.7e-4 with 9 w nodes, when 1e-4 deg below the series at r = 3.16,
V* = 0.1, theta1 = 50 deg, S_c was 8.1e-4 off). Within the window
:meth:`CalibratedCapillary.bound_floor` widens the rupture window to the largest jump and
floors the bound at the window stratum's maxima, times the margin.

Below the onset the ridge series converges slowly in b1
(last coefficients about 5e-4 deg), harmless where every top is a smooth maximum: S_c is
flat across it.

Two angles between spheres (table ``sphere-sphere-two-angles``, :data:`PAIR_TWO_ANGLES`;
:mod:`wetcontact.generate.calibrated_capillary_pairs`): the same structure with lead
coordinates (w, a) for (a,): theta1 the small sphere's angle, theta2 the large one's,
prefactor ``2 pi sigma R* (cos theta1 + cos theta2)``; three bands of theta1 whose onset
end is a 2-D series in (w, a), a 3-D ridge series theta2*(w, a, b1) per band, and the piece
above the ridge ending at
``70.5 + theta2* - theta1`` deg (:data:`UPPER_PAST_RIDGE`). Held-out maxima (rupture
distance / force): 2.5e-4 / 2.6e-4 uniformly, 7.6e-5 / 1.2e-4 within
:data:`RIDGE_ZONE_DEG` of the ridge, 8.6e-5 / 1.1e-4 at its top, 3.8e-5 / 4.2e-4 where
the jump appears, 1.1e-4 / 5.1e-5 between nearly equal spheres, 3.5e-5 / 7.8e-4 at both
angles 0-15 deg and V* 0.01-0.1, 3.4e-5 / 6.3e-4 at the domain's corners and 3.8e-4 /
7.6e-4 within :data:`RIDGE_WINDOW_DEG` of the series (the last three to 0.999 S_c; the
full stage of :data:`~wetcontact.generate.calibrated_capillary_pairs.STAGES`: 27 b2 nodes
above the ridge, 23
below it from the onset to 70 deg, 15 below the onset, where the piece below the ridge has
13 w nodes, ``calibrated_capillary.BAND_NODES``; the ridge series above the onset with 17
w nodes, ``calibrated_capillary_pairs.PAIR_RIDGE_W``).

The force table is stored in low-rank form: its unfolding over the first two axes
((a, b) on a wall, (w, a) for sphere pairs) against the rest is a truncated SVD,
``C^F_{IJ} = sum_{k<r} L_{Ik} R_{kJ}``, with the smallest rank r whose change of the
exponent stays below 5e-5 on a seeded probe (5 % of the force goal; the generator's
``FACTOR_TOL``). A point then costs ``r (P_left + P_right)`` multiply-adds instead of the
table's size (sphere pairs: about a third; :func:`low_rank_rows`). The two-angle tables
evaluate each piece's rupture table and this low-rank force as their tensor trains
(:data:`TRAIN_FIELDS`, :func:`train_sum`;
:data:`wetcontact.generate.calibrated_capillary.TRAIN_TOL`),
on a wall 0.56-0.74 of the low-rank form's multiply-adds, between spheres 0.23-0.40.

Precision. By default (``precision="mixed"``, the fast and default presets) the force's
table is summed in single precision: the two-angle tables' tensor train and the one-angle
tables' low-rank sum (since 2026-11-27), their cores or factors and Chebyshev rows rounded
to float32 as they are summed (:func:`train_sum`, :func:`low_rank_rows`), so that the
products and elementwise sums move half the bytes and fill twice the SIMD lanes. The
rupture distance's tables, the ridge and onset series (which decide a point's band and
piece), the coordinates and exp stay in float64, so S_c, and with it which gaps a bridge
spans, is bitwise that of ``precision="double"`` (the accurate preset, what the C header
and the numpy module compute). The force moves by at most 6.0e-6 (sphere pairs) and
5.3e-6 (a wall) relative with two angles, 6.7e-6 and 4.4e-6 with one, on 1e5 seeded
points: 1/150 of the 1e-3 force goal; the held-out tables above are measured at the
default. Single precision costs the one-angle tables 0.75 (wall) and 0.85 (sphere pairs)
of double in the same run (``benchmarks/bench_calibrate.py``). Summing the rupture trains
in float32 too saved about 0.06 us more a point but moved S_c by up to 3.3e-7, and with it
which gaps a bridge still spans, so it is not done (``docs/notes/sphere_pair_two_angles.md``,
"The force's train in single precision").
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from functools import cache
from importlib import resources
from typing import Any

import numpy as np

from wetcontact.errors import InputError, ValidityError
from wetcontact.models import ForceCurve, Model, register
from wetcontact.reduced_models.bounds import estimate_or_none
from wetcontact.scene import Scene

CAPILLARY_FILE = "calibrated_capillary.json"

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
RIDGE_ZONE_DEG = 3.0
"""Two angles on a wall: within this of the ridge the closure's bound is at least its
near-ridge held-out maximum (its stratum ``held_out_near_ridge``), whatever its sampled
bound table says (see the module's notes)."""
RIDGE_TOP_ZONE_DEG = 0.3
"""Two angles on a wall: within this of the ridge series lies the ridge's top (a jump of S_c
above the onset angle), the table's own held-out stratum ``held_out_ridge_top`` (and, at
sphere angles of 17.5-35 deg, ``held_out_ridge_onset`` and, at gaps to 0.999 S_c,
``held_out_ridge_onset_rupture``), see the module's notes."""
NEAR_RIDGE_MARGIN = 1.25
"""Factor on the near-ridge held-out maxima in :meth:`CalibratedCapillary.bound_floor`:
the bound tables' own margin (``wetcontact.generate.bounds.MARGIN``)."""
SPURIOUS = 1.0e3
"""The relative error claimed where the closure's force may exist while the reference's
does not (its rupture window, below its S_c): the bound tables' own
(``wetcontact.generate.bounds.SPURIOUS``)."""
RIDGE_WINDOW_DEG = {WALL_TWO_ANGLES: 5e-5, PAIR_TWO_ANGLES: 2e-3}
"""Per two-angle table, the half-width (deg) of the ridge's window: how far from the
table's ridge series the true ridge may lie, so that a point within it may be evaluated on
the wrong side of S_c's jump (above the onset angle); narrower in the sphere pairs' top
band (:data:`RIDGE_WINDOW_TOP`, :func:`ridge_window_deg`). Measured on 2026-11-28 by
golden-section searches for the true top (to 1e-6 deg) between the series' nodes: the
wall's series (10 x 9 nodes, each to 1e-6 deg) is off by up to 1.3e-5 deg (in the band
from the onset to 35 deg; within 1e-6 above it). The sphere pairs' (each node to 1e-5
deg; 17 x 9 x 9 nodes in (w, a, b1) above the onset since 2026-11-28, 9 x 9 x 9 before)
between the onset and 35 deg: between its a nodes off by up to 5.0e-4 deg near the onset
(where the jump is below 1e-6 of S_c; 3.4e-4 where it exceeds 1e-5, 1.9e-4 where 3e-5,
6.5e-5 where 1e-4), between its w nodes by up to 1.3e-5 (6.3e-4 where the jump exceeds
1e-4 and 1.4e-3 near the onset with 9 w nodes); 76 points. Above 35 deg see
:data:`RIDGE_WINDOW_TOP`. The half-widths are four times the largest offsets. See the
module's notes."""
RIDGE_WINDOW_TOP = {PAIR_TWO_ANGLES: (35.0, 4e-5)}
"""Per two-angle table, a (small) sphere angle (deg) and the ridge window's half-width
(deg) above it: between spheres, in the band from 35 to 70 deg (no onset within it, and
its ridge series with 17 w nodes since 2026-11-28), the series is off by up to 9.6e-6 deg
(63 golden-section tops between its w, a and b1 nodes; 6.2e-4 deg with 9 w nodes)."""


def ridge_window_deg(table: str, theta_sphere_deg: float) -> float:
    """The ridge window's half-width (deg) of the two-angle table ``table`` at the (small)
    sphere's angle (deg): :data:`RIDGE_WINDOW_DEG`, or :data:`RIDGE_WINDOW_TOP`'s above its
    angle."""
    top = RIDGE_WINDOW_TOP.get(table)
    if top is not None and theta_sphere_deg > top[0]:
        return top[1]
    return RIDGE_WINDOW_DEG[table]


RIDGE_JUMP_MAX = 1.2e-3
"""The largest jump of S_c at the ridge's top over the two-angle domain, relative: 1.15e-3
measured on a wall (V* = 0.1, theta_s = 44 deg), 9.2e-4 between spheres (r = 10, V* = 0.1,
theta1 = 44 deg), rounded up. Within :data:`RIDGE_WINDOW_DEG` of the ridge the rupture
distance may be off by this much."""
RIDGE_STRATA = {RIDGE_ZONE_DEG: ("held_out_near_ridge",),
                RIDGE_TOP_ZONE_DEG: ("held_out_near_ridge", "held_out_ridge_top",
                                     "held_out_ridge_onset", "held_out_ridge_onset_rupture")}
"""Per zone around the ridge (its half-width, deg), the held-out strata whose maxima floor
the closure's bound there (the narrowest zone that contains the point applies; a stratum
whose ``stratum`` names a ``theta_sphere_deg`` range only at sphere angles inside it:
``held_out_ridge_onset``, where the jump at the top appears, 17.5-35 deg)."""
ANGLE_TOL = 1e-9
"""Two contact angles closer than this (rad) count as one."""
PRECISIONS = ("mixed", "double")
"""How :func:`force_star` sums the force's table (a two-angle table's tensor train,
:data:`TRAIN_FIELDS`, a one-angle table's low-rank sum, :func:`low_rank_rows`):
``"mixed"`` (the default) in single precision, from its Chebyshev rows and cores or
factors rounded to it, ``"double"`` in double. Everything else (the coordinates, the
rupture distance's tables, the ridge and onset series, exp, the result) is double either
way, so S_c is the same in both. Single precision moves the force by at most 6.7e-6
relative (measured; the tests hold it under 2e-5, 1/50 of the force goal) and cuts the
cost by about a fifth (wall, two angles), a third (sphere pairs, two angles), a quarter
(wall, one angle) and a seventh (sphere pairs, one angle): the module's notes,
"Precision"."""


@cache
def capillary_table() -> dict[str, Any] | None:
    """The shipped table, or ``None`` before ``python -m wetcontact.generate
    calibrated-capillary``."""
    path = resources.files("wetcontact.reduced_models") / "data" / CAPILLARY_FILE
    return as_arrays(json.loads(path.read_text())) if path.is_file() else None


TABLE_FIELDS = ("rupture", "force_left", "force_right")
"""A piece's coefficient arrays (the force as the two factors of its low-rank form)."""
TRAIN_FIELDS = ("rupture_train", "force_train")
"""A piece's tensor trains of its rupture and force tables, where it has them (the
two-angle tables, a wall's and sphere pairs'): what is evaluated; the arrays above are the
fit they were built from (:func:`wetcontact.generate.calibrated_capillary.train_piece`)."""


def as_arrays(table: dict[str, Any]) -> dict[str, Any]:
    """A copy of the table with each piece's coefficient lists as float arrays (the
    argument is left as it was)."""
    def entry(e: Any) -> Any:
        if isinstance(e, dict) and "bands" in e:  # a wall with two angles
            return {**e, "bands": [entry(h) for h in e["bands"]]}
        if not isinstance(e, dict) or "pieces" not in e:
            return e
        return {**e, "pieces": [{**p, **{n: np.asarray(p[n], dtype=float)
                                        for n in TABLE_FIELDS if n in p},
                                 **{n: {**p[n], "cores": [np.asarray(c, dtype=float)
                                                          for c in p[n]["cores"]]}
                                    for n in TRAIN_FIELDS if n in p}}
                                for p in e["pieces"]]}
    return {k: entry(e) for k, e in table.items()}


def _map(x: np.ndarray, lo: Any, hi: Any) -> np.ndarray:
    return (2.0 * x - lo - hi) / (hi - lo)


def volume_coordinate(v: np.ndarray) -> np.ndarray:
    """``a`` in [-1, 1] from ln v over :data:`V_RANGE`."""
    return _map(np.log(v), math.log(V_RANGE[0]), math.log(V_RANGE[1]))


def ratio_coordinate(ratio: np.ndarray) -> np.ndarray:
    """``w`` in [-1, 1] from (ln r)^(1/3) over :data:`RATIO_RANGE`."""
    return _map(np.cbrt(np.log(ratio)), 0.0, W_MAX)


def theta_split_deg(entry: dict[str, Any], a: Lead,
                    b1: np.ndarray | None = None) -> np.ndarray | None:
    """Where a table's pieces meet (deg), or ``None`` when it has one piece: between equal
    spheres the angle where the branch's end changes from fold to bifurcation, a series in
    the volume coordinate ``a``; with two angles the other solid's angle of the rupture
    distance's ridge, a series in the lead coordinates (``a``, or ``[w, a]`` for sphere
    pairs) and the (small) sphere angle's coordinate ``b1``."""
    ts = entry.get("theta_split")
    if ts is None:
        return None
    coef = np.asarray(ts["chebyshev"])
    coords = lead_list(a) + ([] if b1 is None else [np.asarray(b1, dtype=float)])
    return chebyshev_tensor(coef, coords[-coef.ndim:])


def table_pieces(entry: dict[str, Any]) -> list[dict[str, Any]]:
    """A table's pieces in evaluation order (a wall with two angles: its bands' in turn)."""
    if "bands" in entry:
        return [p for band in entry["bands"] for p in band["pieces"]]
    return list(entry["pieces"])


ONSET_KEY = "theta_sphere_split"
"""The two-angle table's field with the sphere angle (deg) where the ridge's jump appears,
a Chebyshev series in the volume coordinate ``a``: a band's end given as ``None``."""


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


def onset_deg(entry: dict[str, Any], a: Lead) -> np.ndarray:
    """The (small) sphere angle (deg) where the jump of S_c at the ridge's top appears, at
    lead coordinates ``a`` (:data:`Lead`): the two-angle table's series :data:`ONSET_KEY`,
    in a on a wall, in (w, a) for sphere pairs."""
    series = entry.get(ONSET_KEY)
    if series is None:
        raise ValueError("calibrated-capillary: a band bounded by the onset angle in a "
                         f"table without {ONSET_KEY!r}")
    coef = np.asarray(series["chebyshev"])
    if coef.ndim == 2:
        return _series_2d(coef, *lead_list(a)[-2:])
    return chebyshev_tensor(coef, lead_list(a)[-coef.ndim:])


def _series_2d(coef: np.ndarray, x: np.ndarray, y: np.ndarray, chunk: int = 8192
               ) -> np.ndarray:
    """``sum_i (sum_j C_ij T_j(y)) T_i(x)``, the terms added in the order of j within a
    row and the rows in the order of i: each point alike, whatever the batch (a BLAS
    product's last bit depends on it, and a point exactly at the onset angle must fall in
    the same band in every call and in the exports, which add in this order). ``chunk``
    points at a time, in place (the same operations, so the same values)."""
    xf, yf = x.ravel(), y.ravel()
    out = np.empty(xf.size)
    for lo in range(0, xf.size, chunk):
        sl = slice(lo, min(xf.size, lo + chunk))
        rx, ry = _cheb_rows(xf[sl], coef.shape[0]), _cheb_rows(yf[sl], coef.shape[1])
        acc, row, term = np.zeros(rx.shape[1]), np.empty(rx.shape[1]), np.empty(rx.shape[1])
        for i in range(coef.shape[0]):
            row[:] = 0.0
            for j in range(coef.shape[1]):
                np.add(row, np.multiply(coef[i, j], ry[j], out=term), out=row)
            np.add(acc, np.multiply(row, rx[i], out=term), out=acc)
        out[sl] = acc
    return out.reshape(x.shape)


def sphere_range(entry: dict[str, Any], band: dict[str, Any], a: Lead,
                 onset: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A band's range of the (small) sphere's angle (deg) at lead coordinates ``a``
    (:data:`Lead`): its ends, a number, or ``None`` for the onset angle (``onset``, the
    points' own, or else :func:`onset_deg`)."""
    shape = lead_list(a)[0].shape
    if onset is None and None in band["theta_sphere_deg"]:
        onset = onset_deg(entry, a)
    lo, hi = (onset if x is None else np.full(shape, float(x))
              for x in band["theta_sphere_deg"])
    return lo, hi


def _band_onset(entry: dict[str, Any], a: Lead | None) -> np.ndarray | None:
    """The onset angle (deg) at lead coordinates ``a`` where a band of the table ends
    there, else ``None``."""
    if any(None in band["theta_sphere_deg"] for band in entry["bands"]):
        return onset_deg(entry, a)
    return None


def band_index(entry: dict[str, Any], theta_sphere_deg: np.ndarray,
               a: Lead | None = None, onset: np.ndarray | None = None) -> np.ndarray:
    """Which band of a two-angle table (``entry["bands"]``) each (small) sphere angle (deg)
    falls in: the first whose upper end (at the lead coordinates ``a``, needed where an end
    is the onset angle, unless given its values there, ``onset``) is at or above it (-1
    past the last)."""
    t = np.asarray(theta_sphere_deg, dtype=float)
    if onset is None:
        onset = _band_onset(entry, a)
    out = np.full(t.shape, -1)
    for k, band in reversed(list(enumerate(entry["bands"]))):
        hi = band["theta_sphere_deg"][1]
        out[t <= (onset if hi is None else hi)] = k
    return out


def sphere_coordinate(band: dict[str, Any], theta_sphere_deg: np.ndarray,
                      lo: Any = None, hi: Any = None) -> np.ndarray:
    """b1: the sphere's angle (deg) mapped linearly from its band's range to [-1, 1] (the
    range per point, ``lo`` and ``hi``, where an end is the onset angle:
    :func:`sphere_range`)."""
    if lo is None or hi is None:
        lo, hi = band["theta_sphere_deg"]
    return _map(np.asarray(theta_sphere_deg, dtype=float), lo, hi)


def ridge_deg(v: Any, theta_sphere_deg: Any, entry: dict[str, Any] | None = None,
              ratio: Any = None) -> np.ndarray:
    """The other solid's angle (deg) at the ridge of S_c with two angles, at ``v`` and the
    (small) sphere's angle (deg): the split series of the two-angle table's band that holds
    the sphere's angle (``entry``: that table, default the shipped one: the wall's, or,
    given the radius ratio ``ratio``, the sphere pairs')."""
    if entry is None:
        entry = _entry(WALL_TWO_ANGLES if ratio is None else PAIR_TWO_ANGLES)
    v, t, r = np.broadcast_arrays(np.asarray(v, dtype=float),
                                  np.asarray(theta_sphere_deg, dtype=float),
                                  np.asarray(1.0 if ratio is None else ratio, dtype=float))
    a, out = volume_coordinate(v.ravel()), np.full(v.size, np.nan)
    lead: Lead = a if ratio is None else [ratio_coordinate(r.ravel()), a]
    for band, m, b1 in _by_band(entry, t.ravel(), lead):
        out[m] = theta_split_deg(band, _take(lead, m), b1)
    return out.reshape(v.shape)


def _by_band(entry: dict[str, Any], theta_sphere_deg: np.ndarray, a: Lead
             ) -> Iterator[tuple[dict[str, Any], np.ndarray, np.ndarray]]:
    """Per band of a two-angle table that holds some of the (flat) sphere angles (deg; at
    lead coordinates ``a``, :data:`Lead`): the band, the indices of its points
    (:func:`band_index`) and their b1 (:func:`sphere_coordinate`). The onset angle is
    evaluated once, and the same values bound the bands and map b1."""
    onset = _band_onset(entry, a)
    which = band_index(entry, theta_sphere_deg, a, onset)
    for k, band in enumerate(entry["bands"]):
        m = np.flatnonzero(which == k)
        if m.size:
            yield band, m, sphere_coordinate(
                band, theta_sphere_deg[m],
                *sphere_range(entry, band, _take(a, m), None if onset is None else onset[m]))


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


def _cheb_rows(t: np.ndarray, n: int, dtype: Any = np.float64) -> np.ndarray:
    """``T_k(t)`` for k < n, shape (n, len(t)) (coefficient-major: each row contiguous),
    by the three-term recurrence ``T_k = 2 t T_{k-1} - T_{k-2}``, in ``dtype`` (``t``
    rounded to it first)."""
    t = np.asarray(t, dtype=dtype)
    out = np.empty((n, t.size), dtype=dtype)
    out[0] = 1.0
    if n > 1:
        out[1] = t
    t2 = 2.0 * t
    for k in range(2, n):
        np.multiply(t2, out[k - 1], out=out[k])
        out[k] -= out[k - 2]
    return out


def _outer(rows: list[np.ndarray]) -> np.ndarray:
    """Outer product of coefficient-major Chebyshev rows per point, shape
    (prod of their lengths, n points)."""
    out = rows[0]
    for m in rows[1:]:
        out = (out[:, None, :] * m[None, :, :]).reshape(-1, out.shape[-1])
    return out


def _outer_rows(pts: list[np.ndarray], shape: tuple[int, ...]) -> np.ndarray:
    """Rows ``T_i(x_1) T_j(x_2) ...`` over the leading axes, shape (n, prod(shape))."""
    return _outer([_cheb_rows(p, m) for p, m in zip(pts, shape, strict=True)]).T


def low_rank_rows(left: np.ndarray, right: np.ndarray, rows_left: np.ndarray,
                  rows_right: np.ndarray) -> np.ndarray:
    """``sum_k (sum_I L_{I k} T_I(x)) (sum_J R_{k J} T_J(y))`` per point: the tensor
    Chebyshev sum with coefficients ``C_{IJ} = sum_k L_{Ik} R_{kJ}`` (a truncated SVD of
    the table's (left axes) x (right axes) unfolding,
    :func:`wetcontact.generate.calibrated_capillary.factor_table`), from the points' outer
    Chebyshev rows over the left and right axes (coefficient-major, :func:`_outer`: shapes
    (P, n) and (Q, n)), in their precision (the factors given in it: :func:`_piece` rounds
    both to float32 by default)."""
    lf = left.reshape(-1, left.shape[-1])
    rf = right.reshape(right.shape[0], -1)
    return np.einsum("kj,kj->j", lf.T @ rows_left, rf @ rows_right)


def chebyshev_tensor(coef: np.ndarray, coords: list[np.ndarray], chunk: int = 4096
                     ) -> np.ndarray:
    """``sum C_{i..k} T_i(x_1) ... T_k(x_d)`` at points (x_1..x_d)[n], vectorised.

    The longest axis (the last, unless another is longer) is contracted by one matrix
    product, ``A[i..j, p] = sum_k C_{i..jk} T_k(x_{d,p})``, the others in turn from the
    last by an elementwise sum over the axis's Chebyshev rows, points last (cost
    ``prod(shape)`` multiply-adds a point, and ``prod(shape[:-1]) + prod(shape[:-2]) +
    ...`` elementwise: least with the longest axis first), ``chunk`` points at a time. The
    sphere pairs' ridge, 17 x 9 x 9: 243 ns a point against 418 with its last axis first
    and 1024 points at a time (2026-11-28).
    """
    coef = np.asarray(coef, dtype=float)
    pts = [np.ravel(np.asarray(x, dtype=float)) for x in coords]
    k = int(np.argmax(coef.shape))
    if coef.ndim > 1 and coef.shape[k] > coef.shape[-1]:
        perm = [i for i in range(coef.ndim) if i != k] + [k]
        coef, pts = coef.transpose(perm), [pts[i] for i in perm]
    n = pts[0].size
    out = np.empty(n)
    if coef.ndim == 1:  # term by term in the order of k: each point's value alike,
        # whatever the batch (a BLAS product's last bit depends on it, and a point exactly
        # at a split or onset angle must fall in the same piece in every call and export)
        rows = _cheb_rows(pts[0], coef.size)
        out = np.zeros(n)
        for c, row in zip(coef, rows, strict=True):
            out = out + c * row
        return out.reshape(np.shape(coords[0]))
    head = coef.reshape(-1, coef.shape[-1])  # (prod(others), n_last)
    for lo in range(0, n, chunk):
        sl = slice(lo, min(n, lo + chunk))
        acc = head @ _cheb_rows(pts[-1][sl], coef.shape[-1])
        for x, m in zip(pts[-2::-1], coef.shape[-2::-1], strict=True):
            acc = np.einsum("imp,mp->ip", acc.reshape(-1, m, acc.shape[-1]),
                            _cheb_rows(x[sl], m))
        out[sl] = acc[0]
    return out.reshape(np.shape(coords[0]))


def train_sum(train: dict[str, Any], rows: list[np.ndarray]) -> np.ndarray:
    r"""A tensor Chebyshev sum in tensor-train form at points, from the points'
    coefficient-major Chebyshev rows over the table's axes (:func:`_cheb_rows`):

    .. math::
        \sum_{i_1..i_d} C_{i_1..i_d} T_{i_1}(x_1) \cdots T_{i_d}(x_d), \qquad
        C_{i_{o_1} .. i_{o_d}} = G_1[i_{o_1}] \, G_2[i_{o_2}] \cdots G_d[i_{o_d}],

    each core ``G_k`` of shape (r_{k-1}, n_{o_k}, r_k) (r_0 = r_d = 1) carrying the table
    axis ``o_k = order[k]`` (Oseledets 2011, SIAM J. Sci. Comput. 33, 2295). Evaluated core
    by core over the batch, points last (each step's arrays contiguous along the points):
    ``V_k[r_k, p] = sum_{r, m} G_k[r, m, r_k] V_{k-1}[r, p] T_m(x_{o_k, p})``, as one
    matrix product and one elementwise sum over the axis's rows. The product comes first
    (``(G V)[m, r_k, p]``, then the sum over m) where r_k <= r_{k-1}, last (the rows'
    outer product with ``V``, ``[r, m, p]``, then the product) where r_k > r_{k-1}: the
    elementwise work a point is ``n_k min(r_{k-1}, r_k)``, the multiply-adds
    ``sum_k r_{k-1} n_k r_k`` either way. :data:`TRAIN_CHUNK` points at a time (twice
    as many in single precision: the same bytes).

    The sums are taken in the rows' precision (the cores rounded to it: single-precision
    rows, ``float32``, are contracted with float32 cores); the result is float64."""
    order = train["order"]
    cores = [g.astype(rows[0].dtype, copy=False) for g in train["cores"]]
    n = rows[0].shape[1]
    out = np.empty(n)
    batch = TRAIN_CHUNK * 8 // rows[0].itemsize  # as many bytes in single precision
    for lo in range(0, n, batch):
        sl = slice(lo, min(n, lo + batch))
        v = cores[0][0].T @ rows[order[0]][:, sl]  # (r_1, p)
        for g, ax in zip(cores[1:], order[1:], strict=True):
            r0, m, r1 = g.shape
            t = rows[ax][:, sl]
            if r1 <= r0:
                w = (g.reshape(r0, m * r1).T @ v).reshape(m, r1, -1)
                v = np.einsum("mrp,mp->rp", w, t)
            else:
                z = (v[:, None, :] * t[None, :, :]).reshape(r0 * m, -1)
                v = g.reshape(r0 * m, r1).T @ z
        out[sl] = v[0]
    return out


def train_dense(cores: list[np.ndarray], order: Any) -> np.ndarray:
    """The dense coefficient tensor of a tensor train (:func:`train_sum`), in the table's
    axis order: the cores contracted over their ranks, ``G_1 G_2 ... G_d`` (axes in
    ``order``), then transposed back."""
    out = cores[0][0]
    for g in cores[1:]:
        out = np.tensordot(out, g, axes=1)
    return out[..., 0].transpose(np.argsort(order))


def _entry(kind: str) -> dict[str, Any]:
    table = capillary_table()
    if table is None or kind not in table:
        raise ValidityError("calibrated-capillary", f"no {kind} coefficient table generated "
                            "(python -m wetcontact.generate calibrated-capillary)",
                            "meniscus")
    return table[kind]


def rupture_star(kind: str, v: np.ndarray, theta: np.ndarray,
                 ratio: np.ndarray | None = None, theta_wall: np.ndarray | None = None
                 ) -> np.ndarray:
    """Rupture distance S_c/R_s (``theta_wall``: the wall's own angle, see
    :func:`force_star`; in double precision whatever its ``precision``)."""
    v = np.asarray(v, dtype=float)
    return force_star(kind, v, theta, np.zeros(v.shape), ratio, theta_wall=theta_wall)[1]


def reduced_star(kind: str, ratio: np.ndarray | None) -> np.ndarray | float:
    """R*/R_s: 1 on a wall, r/(1 + r) for a sphere pair."""
    return 1.0 if kind in ("sphere-wall", WALL_TWO_ANGLES) else ratio / (1.0 + ratio)


def force_star(kind: str, v: np.ndarray, theta: np.ndarray, s: np.ndarray,
               ratio: np.ndarray | None = None, chunk: int | None = None,
               entry: dict[str, Any] | None = None, theta_wall: np.ndarray | None = None,
               precision: str = "mixed") -> tuple[np.ndarray, np.ndarray]:
    """Attractive force ``F/(2 pi sigma R_s)`` at gap ``s = S/R_s`` (0 at and beyond
    rupture) and the rupture distance ``S_c/R_s``, in one pass (the Chebyshev rows of
    (w,) a, b serve both tables).

    Each point is evaluated in the theta piece that contains it: between equal spheres the
    rupture distance has a kink where the branch's end changes from a fold to a
    symmetry-breaking bifurcation (theta about 30-31 deg, moving with V), so sphere pairs
    carry two tables, below and above that angle (``theta_split``). The force exponent is
    the rank-r sum :func:`low_rank_rows` (cost ``r (P_left + P_right)`` multiply-adds a
    point), or, for a piece that carries them (the two-angle tables'), its tensor trains
    (:func:`train_sum`). ``entry``: one kind's table (default: the shipped one).

    On a wall, ``theta_wall`` (rad) gives the wall its own angle (``theta`` is then the
    sphere's): points whose two angles differ by more than :data:`ANGLE_TOL` are evaluated
    in the two-angle table :data:`WALL_TWO_ANGLES` (in the band that holds the sphere's
    angle, :func:`band_index`: sphere angle ``b1`` over the band, and the wall angle within
    the pieces that meet at the band's ridge), the others in the
    one-angle table (``entry``, if given, is the one-angle table), and the Derjaguin
    prefactor is ``cos theta_s + cos theta_w``.

    ``precision`` (:data:`PRECISIONS`): ``"mixed"`` sums the force's tensor train in single
    precision (everything else, S_c and the result included, in double); ``"double"`` sums
    every table in double precision."""
    if precision not in PRECISIONS:
        raise InputError(f"calibrated-capillary: precision = {precision!r}; allowed: "
                         + ", ".join(PRECISIONS))
    v, theta, s = np.broadcast_arrays(np.asarray(v, float), np.asarray(theta, float),
                                      np.asarray(s, float))
    shape = v.shape
    v, theta, s = v.ravel(), theta.ravel(), s.ravel()
    if ratio is not None:
        ratio = np.broadcast_to(np.asarray(ratio, float), shape).ravel()
    if kind in TWO_ANGLE_TABLES and theta_wall is not None:
        tw = np.broadcast_to(np.asarray(theta_wall, float), shape).ravel()
        two = np.abs(tw - theta) > ANGLE_TOL
        f, s_c = np.empty(v.size), np.empty(v.size)
        for mask, k in ((~two, kind), (two, TWO_ANGLE_TABLES[kind])):
            if mask.any():
                f[mask], s_c[mask] = force_star(
                    k, v[mask], theta[mask], s[mask], None if ratio is None else ratio[mask],
                    chunk=chunk, entry=entry if k == kind else None,
                    theta_wall=None if k == kind else tw[mask], precision=precision)
        return f.reshape(shape), s_c.reshape(shape)
    e = _entry(kind) if entry is None else entry
    a = volume_coordinate(v)
    rho = np.broadcast_to(np.asarray(reduced_star(kind, ratio), dtype=float), (v.size,))
    dtype = np.float32 if precision == "mixed" else np.float64  # the trains' (_piece)
    if kind in (WALL_TWO_ANGLES, PAIR_TWO_ANGLES):
        if theta_wall is None:
            raise ValueError(f"calibrated-capillary: the {kind} table needs theta_wall")
        tw = np.broadcast_to(np.asarray(theta_wall, float), shape).ravel()
        ts = np.degrees(theta)
        lead: Lead = a if kind == WALL_TWO_ANGLES else [ratio_coordinate(ratio), a]
        f, s_c = np.full(v.size, np.nan), np.full(v.size, np.nan)
        for band, m, b1 in _by_band(e, ts, lead):  # each band: its own b1 range and ridge
            lm = _take(lead, m)
            f[m], s_c[m] = _pieces(band, [*lead_list(lm), b1], np.degrees(tw[m]),
                                   theta_split_deg(band, lm, b1), v[m], s[m], rho[m], chunk,
                                   ts[m], dtype)
        cos_sum = np.cos(theta) + np.cos(tw)
    else:
        lead = [a] if kind == "sphere-wall" else [ratio_coordinate(ratio), a]
        f, s_c = _pieces(e, lead, np.degrees(theta), theta_split_deg(e, a), v, s, rho, chunk,
                         dtype=dtype)
        cos_sum = 2.0 * np.cos(theta)
    return (f * cos_sum).reshape(shape), s_c.reshape(shape)


def _pieces(e: dict[str, Any], lead: list[np.ndarray], piece_deg: np.ndarray,
            split: np.ndarray | None, v: np.ndarray, s: np.ndarray, rho: np.ndarray,
            chunk: int | None, first_deg: np.ndarray | None = None, dtype: Any = np.float64
            ) -> tuple[np.ndarray, np.ndarray]:
    """``rho q`` and ``S_c/R_s`` from a table's pieces: the lead coordinates, the angle that
    the pieces divide (deg) mapped within its piece, and the gap coordinate; a point
    belongs to the first piece whose upper end is at or above its angle (``first_deg``:
    the sphere's angle, for a piece whose end follows the ridge, :func:`piece_range`).
    ``dtype``: the precision of the force's tensor-train sum (:func:`_piece`)."""
    n = v.size
    eps = np.sqrt(v / (np.pi * rho))
    f, s_c = np.full(n, np.nan), np.full(n, np.nan)
    todo = np.ones(n, dtype=bool)
    for piece in e["pieces"]:
        lo, hi = piece_range(piece, split, n, first_deg)
        idx = np.flatnonzero(todo & (piece_deg <= hi))
        todo[idx] = False
        f[idx], s_c[idx] = _piece(piece, lo, hi, idx, lead, piece_deg, v, s, rho, eps, chunk,
                                  dtype)
    return f, s_c


def _piece(piece: dict[str, Any], lo: np.ndarray, hi: np.ndarray, idx: np.ndarray,
           lead: list[np.ndarray], piece_deg: np.ndarray, v: np.ndarray, s: np.ndarray,
           rho: np.ndarray, eps: np.ndarray, chunk: int | None, dtype: Any = np.float64
           ) -> tuple[np.ndarray, np.ndarray]:
    """``rho q`` and ``S_c/R_s`` of the points ``idx`` from one piece's tables, ``chunk``
    points at a time (default :func:`piece_chunk`); by its tensor trains
    (:data:`TRAIN_FIELDS`, :func:`train_sum`) where it has them, else by the low-rank
    factors (:func:`low_rank_rows`); the force's sum in ``dtype`` (everything else, S_c
    included, in double precision)."""
    f, s_c = np.empty(idx.size), np.empty(idx.size)
    rup_train, force_train = (piece.get(n) for n in TRAIN_FIELDS)
    rup = np.asarray(piece["rupture"])
    left, right = np.asarray(piece["force_left"]), np.asarray(piece["force_right"])
    dims = (*left.shape[:-1], *right.shape[1:])  # the force table's axes
    k = left.ndim - 1
    rup2 = rup.reshape(-1, rup.shape[-1]).T
    if force_train is None:
        left_d, right_d = left.astype(dtype, copy=False), right.astype(dtype, copy=False)
    if chunk is None:
        chunk = 16 * TRAIN_CHUNK if force_train is not None else piece_chunk(dims, k)
    for j in range(0, idx.size, chunk):
        sl = idx[j:j + chunk]
        out = slice(j, j + sl.size)
        rows = [_cheb_rows(x[sl], m) for x, m in zip(lead, dims, strict=False)]
        rows.append(_cheb_rows(piece_coordinate(piece, piece_deg[sl], lo[sl], hi[sl]),
                               dims[len(lead)]))
        if rup_train is None:
            r_lead = _outer(rows[:len(lead)])
            sc = np.cbrt(v[sl]) * np.exp(np.einsum("ij,ij->j", rup2 @ r_lead, rows[-1]))
        else:
            sc = np.cbrt(v[sl]) * np.exp(train_sum(rup_train, rows))
        inside = s[sl] < sc
        c = gap_coordinate(np.where(inside, s[sl], 0.0), sc, eps[sl])
        if force_train is None:  # the low-rank force in ``dtype``: rows and factors rounded
            rows.append(_cheb_rows(c, dims[-1], dtype))
            low = [r.astype(dtype, copy=False) for r in rows]
            r_left = (r_lead.astype(dtype, copy=False) if k == len(lead) and rup_train is None
                      else _outer(low[:k]))
            q = np.exp(low_rank_rows(left_d, right_d, r_left, _outer(low[k:]))
                       .astype(np.float64))
        else:  # the force's train in ``dtype``: its rows rounded to it
            q = np.exp(train_sum(force_train, [*(r.astype(dtype, copy=False) for r in rows),
                                               _cheb_rows(c, dims[-1], dtype)]))
        f[out] = np.where(inside, rho[sl] * q, 0.0)
        s_c[out] = sc
    return f, s_c


TRAIN_CHUNK = 256
"""Points per product in :func:`train_sum` (its cores' products over the batch stay within
the L2 cache: at most about 500 numbers a point); a piece evaluated by its trains takes
its points sixteen such batches at a time (the per-chunk work outside the sums is then
spread over more points)."""
CHUNK_FLOATS = 2**18
"""The largest outer product of Chebyshev rows a chunk of points may build (floats, 2 MiB):
about the L2 cache of the machine the costs were measured on (AMD EPYC, 2 MiB for 2
cores), so that the matrix product reads it from cache."""


def piece_chunk(dims: tuple[int, ...], k: int) -> int:
    """Points per chunk for a piece whose force table has axes ``dims``, the first ``k``
    of them its low-rank left factor's: :data:`CHUNK_FLOATS` over the larger of the two
    outer products (:func:`low_rank_rows`), between 256 and 4096."""
    size = max(math.prod(dims[:k]), math.prod(dims[k:]))
    return int(min(4096, max(256, CHUNK_FLOATS // size)))


@register
class CalibratedCapillary(Model):
    """Calibrated capillary closure: ``meniscus`` interpolated to about 1e-4 (held-out
    tables in the package data), one contact angle per pair or two."""

    name = "calibrated-capillary"
    component = "capillary"
    level = 0
    validity = ("pendular bridge on a wall or between spheres of radius ratio 1-10, "
                "V/R_small^3 in [1e-4, 0.1], one contact angle in [0, 70] deg on both "
                "solids, or two, each in [0, 70] deg, no gravity; any gap (0 beyond its "
                "rupture distance)")
    reference = "calibrated here: tensor Chebyshev interpolation of meniscus"
    source = ("fitted here: tensor Chebyshev interpolation of this package's meniscus solver "
              "(Young-Laplace; no published form)")
    cost = 1e-6
    presets = {"fast": {"precision": "mixed"}, "default": {"precision": "mixed"},
               "accurate": {"precision": "double"}}
    """``precision`` (:data:`PRECISIONS`): how the force's table (a tensor train with two
    angles, a low-rank sum with one) is summed; ``accurate`` sums every table in double
    precision (what the exported closures compute), the others the force's in single
    precision."""

    def check(self, scene: Scene) -> None:
        if scene.amount != "bridge":
            raise ValidityError(self.name, f"needs a liquid bridge (amount = 'bridge'), got "
                                f"amount = {scene.amount!r}",
                                "brenner" if scene.amount == "immersed" else "thinfilm")
        _entry(scene.kind)
        th1, th2 = scene.contact_angle_sphere, scene.contact_angle_wall
        if abs(th1 - th2) > ANGLE_TOL:
            _entry(TWO_ANGLE_TABLES[scene.kind])
        for th, what in ((th1, "sphere"), (th2, "wall" if scene.kind == "sphere-wall"
                                           else "sphere 2")):
            deg = math.degrees(th)
            if not THETA_RANGE_DEG[0] <= deg <= THETA_RANGE_DEG[1] * (1 + 1e-12):
                raise ValidityError(self.name, f"contact angle {deg:.4g} deg ({what}) outside "
                                    f"the calibrated [0, {THETA_RANGE_DEG[1]:g}] deg",
                                    "meniscus")
        if scene.gravity > 0 and scene.density > 0:
            raise ValidityError(self.name, "calibrated without gravity", "meniscus")
        v, ratio = self._v_ratio(scene)
        if not V_RANGE[0] * (1 - 1e-9) <= v <= V_RANGE[1] * (1 + 1e-9):
            raise ValidityError(self.name, f"V/R_small^3 = {v:.4g} outside the calibrated "
                                f"[{V_RANGE[0]:g}, {V_RANGE[1]:g}]", "meniscus")
        if ratio is not None and ratio > RATIO_RANGE[1] * (1 + 1e-9):
            raise ValidityError(self.name, f"radius ratio {ratio:.4g} outside the calibrated "
                                f"[1, {RATIO_RANGE[1]:g}]", "meniscus")

    @staticmethod
    def _v_ratio(scene: Scene) -> tuple[float, float | None]:
        assert scene.bridge_volume is not None
        if scene.kind == "sphere-wall":
            return scene.bridge_volume / scene.radius**3, None
        assert scene.radius2 is not None
        rs, rl = sorted((scene.radius, scene.radius2))
        return scene.bridge_volume / rs**3, rl / rs

    def small_radius(self, scene: Scene) -> float:
        """R_s: the sphere's radius on a wall, the smaller radius of a pair."""
        return scene.small_radius

    def rupture_distance(self, scene: Scene) -> float:
        """S_c (m)."""
        v, ratio = self._v_ratio(scene)
        th, other = self._angles(scene)
        return float(rupture_star(scene.kind, np.array(v), np.array(th),
                                  None if ratio is None else np.array(ratio),
                                  theta_wall=other)
                     * self.small_radius(scene))

    def ridge_distance(self, scene: Scene) -> float | None:
        """How far (deg) the other solid's angle lies from the two-angle table's ridge
        series (:func:`ridge_deg`) at the scene's volume, ratio and (small) sphere angle;
        ``None`` with one angle."""
        th_s, th_w = self._angles(scene)
        if th_w is None or abs(th_s - th_w) <= ANGLE_TOL:
            return None
        v, ratio = self._v_ratio(scene)
        return abs(math.degrees(th_w) - float(ridge_deg(v, math.degrees(th_s), ratio=ratio)))

    def ridge_window(self, scene: Scene) -> float | None:
        """The half-width (deg) of the ridge's window at the scene's (small) sphere angle
        (:func:`ridge_window_deg`); ``None`` with one angle."""
        th_s, th_w = self._angles(scene)
        if th_w is None:
            return None
        return ridge_window_deg(TWO_ANGLE_TABLES[scene.kind], math.degrees(th_s))

    def in_ridge_window(self, scene: Scene, dist: float | None = None) -> bool:
        """Whether the scene lies within its table's ridge window of the ridge
        (:meth:`ridge_window`), where the table may evaluate the other side of S_c's jump
        (at any sphere angle: below the onset angle, where the top is smooth, the window
        costs only bound); ``dist``: its :meth:`ridge_distance`, if known."""
        if dist is None:
            dist = self.ridge_distance(scene)
        return dist is not None and dist <= self.ridge_window(scene)

    def held_out_tables(self, scene: Scene
                        ) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
        """The package data's held-out tables that describe ``scene``: the geometry's (its
        uniform one and its stress strata that hold the scene's sphere angle, e.g. nearly
        equal spheres, or near the ridge with two angles), and the ridge zone's: with two
        angles (a wall, or sphere pairs) within :data:`RIDGE_ZONE_DEG` of the ridge, the strata
        of the narrowest zone of :data:`RIDGE_STRATA` that contains it and hold its sphere
        angle (within :data:`RIDGE_TOP_ZONE_DEG`: the ridge's top, and at 17.5-35 deg where
        its jump appears; within :data:`RIDGE_WINDOW_DEG`: those and the table's
        ``held_out_ridge_window``); empty elsewhere."""
        th_s, _ = self._angles(scene)
        dist = self.ridge_distance(scene)
        two = dist is not None
        e = _entry(TWO_ANGLE_TABLES[scene.kind] if two else scene.kind)
        ts = math.degrees(th_s)

        def applies(k: str) -> bool:  # a stratum of some sphere angles only
            if k not in e:
                return False
            lo, hi = e[k].get("stratum", {}).get("theta_sphere_deg", THETA_RANGE_DEG)
            return lo <= ts <= hi

        geometry = [e["held_out"], *(e[k] for k in sorted(e)
                                     if k.startswith("held_out_") and applies(k))]
        if dist is None:
            return geometry, []
        zones = [z for z in RIDGE_STRATA if dist <= z]
        if not zones:
            return geometry, []
        names = RIDGE_STRATA[min(zones)] + (("held_out_ridge_window",)
                                            if self.in_ridge_window(scene, dist) else ())
        return geometry, [e[k] for k in names if k in e and applies(k)]

    def rupture_window(self, scene: Scene) -> float:
        """``w``, the rupture window's half-width over S_c (:meth:`bound_floor`): the
        largest held-out error of the rupture distance among the tables that describe the
        scene (:meth:`held_out_tables`), at least :data:`RIDGE_JUMP_MAX` within the ridge's
        window, times :data:`NEAR_RIDGE_MARGIN`."""
        geometry, ridge = self.held_out_tables(scene)
        return NEAR_RIDGE_MARGIN * max(
            [ho["rupture_distance"]["max"] for ho in geometry + ridge]
            + ([RIDGE_JUMP_MAX] if self.in_ridge_window(scene) else []))

    def bound_floor(self, scene: Scene, rupture_distance: float | None = None
                    ) -> np.ndarray:
        """Smallest error bound this closure may claim at each of the scene's gaps, where
        its sampled bound tables cannot be trusted to have found its worst (0 elsewhere).

        - Its **rupture window**: within ``w S_c`` of its own rupture distance, ``w`` the
          held-out maximum of the rupture distance's error (:meth:`held_out_tables`) times
          :data:`NEAR_RIDGE_MARGIN` (:meth:`rupture_window`), the bridge may or may not
          exist: below S_c the closure's force may be spurious (:data:`SPURIOUS`), above
          it the closure's 0 may miss a force (relative error 1, times the margin).
        - With two angles (a wall or sphere pairs) within :data:`RIDGE_ZONE_DEG` of the
          ridge, where the table is coarser: at the gaps below the window, the largest
          held-out force error of the zone's strata among points where the closure's
          bridge exists
          (``force_attached``), and its rupture distance's maximum, times the margin.
        - Within :data:`RIDGE_WINDOW_DEG` of the ridge, where the table may evaluate the
          other side of S_c's jump, ``w`` is at least :data:`RIDGE_JUMP_MAX` times the
          margin.
        """
        gap = scene.gap_array
        sc = self.rupture_distance(scene) if rupture_distance is None else rupture_distance
        _, ridge = self.held_out_tables(scene)
        w = self.rupture_window(scene)
        out = np.zeros(gap.shape)
        if ridge:
            out[:] = NEAR_RIDGE_MARGIN * max(
                max(ho.get("force_attached", ho["force"])["max"], ho["rupture_distance"]["max"])
                for ho in ridge)
        out[(gap >= sc * (1.0 - w)) & (gap < sc)] = SPURIOUS
        out[(gap >= sc) & (gap <= sc * (1.0 + w))] = NEAR_RIDGE_MARGIN
        return out

    @staticmethod
    def _angles(scene: Scene) -> tuple[float, float | None]:
        """The (small) sphere's angle and the other solid's (rad): on a wall the sphere's
        and the wall's; for a sphere pair the smaller sphere's (sphere 1's at equal radii)
        and the larger one's, or ``None`` when the two are one angle."""
        th1, th2 = scene.contact_angle_sphere, scene.contact_angle_wall
        if scene.kind == "sphere-wall":
            return th1, th2
        if abs(th1 - th2) <= ANGLE_TOL:
            return th1, None
        assert scene.radius2 is not None
        return (th2, th1) if scene.radius2 < scene.radius else (th1, th2)

    def _force(self, scene: Scene, preset: str, precision: str = "mixed", **opts: Any
               ) -> ForceCurve:
        rs = self.small_radius(scene)
        v, ratio = self._v_ratio(scene)
        gap = scene.gap_array
        th, other = self._angles(scene)
        f, s_c = force_star(scene.kind, v, th, gap / rs, ratio, theta_wall=other,
                            precision=precision)
        sc = float(s_c.flat[0]) * rs
        force = 2.0 * np.pi * scene.surface_tension * rs * f
        est = estimate_or_none(self.name, "capillary", scene, sc)
        if est is not None:
            est = np.maximum(est, self.bound_floor(scene, sc))
        diag = {}
        dist = self.ridge_distance(scene)
        if self.in_ridge_window(scene, dist):
            window = self.ridge_window(scene)
            diag["ridge_window"] = (
                f"the other solid's angle is {dist:.3g} deg from the table's ridge series, "
                f"within its error ({window:g} deg): the table may evaluate the other side "
                f"of S_c's jump, so S_c may be off by up to {RIDGE_JUMP_MAX:g} and the force "
                "near rupture spurious or missing; the error bound says so (meniscus "
                "resolves it)")
        return ForceCurve(case=scene.name, model=self.name, gap=gap, force_viscous=None,
                          force_capillary=-force,
                          extras={"rupture_distance": np.full(gap.shape, sc)},
                          error_estimate=est, diagnostics=diag)
