r"""Calibrated closure of the liquid division at rupture: ``calibrated_transfer_fraction``.

``f``, the fraction of a ruptured bridge's liquid that body 1 keeps (body 2 keeps
``1 - f``), as the ``meniscus`` model's ``transfer_fraction`` gives it
(:func:`wetcontact.solver.meniscus.division.transfer_fraction`: the critical bridge of the
volume-controlled branch cut at its neck; PHYSICS.md section 7).

Domain: a sphere and a wall, or two spheres of radius ratio ``R_l/R_s`` in [1, 10];
receding contact angles theta1, theta2 in [0, 70] deg; ``V* = V/R_s^3`` in [1e-4, 0.1]
(``R_s`` the smaller sphere, the sphere on a wall); no gravity. Outside: InputError.

Form: with the smaller sphere as body ``s`` (angle theta_s) and the other as ``l``,
``f = f_s`` or ``1 - f_s``, so swapping the bodies gives ``1 - f`` exactly. ``f_s`` jumps
across the surface ``theta_l = K(theta_s, V*, xi) >= theta_s``, ``xi = (1 - R_s/R_l)^(1/3)``
(0: equal spheres, 1: a wall), where the fold of the branch changes side; on both sides it
approaches its limit like ``d^(1/3)``, ``d = |theta_l - K|`` (between equal spheres it is
continuous, ``f_s - 1/2 ~ sign(eps) |eps|^(1/3)``). ``K`` is a tensor Chebyshev series in
(theta_s, ln V*, xi); each side of the jump has its own tensor Chebyshev series with a
coordinate linear in ``d^(1/3)``:

.. math::
    f_s = \sum C^{\pm}_{ijkl}\, T_i(\cdot) T_j(\cdot) T_k(\cdot) T_l(s).

Values at tensor Chebyshev-Lobatto points from ``meniscus`` at its fast preset, built by
``python -m wetcontact.generate transfer-fraction`` into ``data/transfer_fraction.json``
(generation record and held-out table: ``data/transfer_fraction_record.json``). The
coordinates of each side and the band are in the guide (``docs/reference/division.md``).

Within ``d_min`` of the jump (``band_deg`` in the data, 0.2 deg) the closure answers ``NaN``
and, with ``return_reason=True``, the reason (:data:`BAND_REASON`).

Accuracy: absolute error against ``meniscus`` (default preset) outside the band, on 200
seeded held-out points (the report's ``division_closure_heldout.csv``): max 6.4e-4, mean
1.5e-4, p95 4.1e-4; on 200 more drawn by the tests: max 6.5e-4. The largest errors sit at
theta_s below a few degrees and within a few degrees of the jump. Cost: about 0.6 us a
point in one vectorised call on 1e4 or 1e5 points, one BLAS thread
(``benchmarks/bench_division.py``); a third of it is the one matrix product of a side's table
with its points' weight products (:func:`tensor_eval`: a multiply-add per node value and
point, 5 355 below the jump and 2 925 above), most of the rest the barycentric weights.
"""

from __future__ import annotations

import json
from functools import lru_cache
from typing import Any, NoReturn

import numpy as np

from wetcontact.errors import InputError
from wetcontact.reduced_models import DATA_DIR

__all__ = ["calibrated_transfer_fraction", "TRANSFER_FILE", "SCHEMA_VERSION"]

TRANSFER_FILE = "transfer_fraction.json"
"""The package data of the closure (coefficients as node values)."""
RECORD_FILE = "transfer_fraction_record.json"
"""Its generation record: command, node counts, timings, the held-out table."""
SCHEMA_VERSION = 1

V_RANGE = (1e-4, 0.1)
"""V* = V/R_s^3."""
RATIO_MAX = 10.0
THETA_MAX = 70.0
"""deg."""
CHUNK = 2048
"""Points evaluated together: the lower side holds 85 + 63 weight products and 63 partial
sums a point (2048 points: 3.5 MB, in cache; 8192 or the whole batch at once are
memory-bound, up to 2x slower); fewer points pay numpy's per-call overhead (1024: 1.2x)."""
BAND_REASON = "within the band at the jump of the division (|theta_l - K| < d_min)"


def lobatto(n: int) -> np.ndarray:
    """Chebyshev-Lobatto points on [-1, 1], ascending: ``-cos(pi j/(n - 1))``."""
    return -np.cos(np.pi * np.arange(n) / (n - 1))


LOBATTO_BASES: dict[int, tuple[np.ndarray, np.ndarray]] = {}
"""The nodes and base weights of :func:`lobatto_basis` by count, filled on first use (a
plain dict: the exported numpy module imports nothing beyond numpy, math and typing)."""


def lobatto_basis(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``n`` Chebyshev-Lobatto nodes (:func:`lobatto`) and their barycentric base
    weights ``(-1)^j``, halved at the two ends (Berrut & Trefethen 2004, eq. 5.4), made once
    per count (:data:`LOBATTO_BASES`) and read-only."""
    if n not in LOBATTO_BASES:
        nodes = lobatto(n)
        base = np.ones(n)
        base[1::2] = -1.0
        base[0] *= 0.5
        base[-1] *= 0.5
        nodes.flags.writeable = base.flags.writeable = False
        LOBATTO_BASES[n] = nodes, base
    return LOBATTO_BASES[n]


def to_unit(x: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Linear map of [lo, hi] onto [-1, 1]."""
    return (2.0 * np.asarray(x, dtype=float) - (lo + hi)) / (hi - lo)


def from_unit(t: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Inverse of :func:`to_unit`."""
    return 0.5 * (np.asarray(t, dtype=float) * (hi - lo) + (lo + hi))


def upper_width(k: np.ndarray) -> np.ndarray:
    """``(u + sqrt(u^2 + 4))/2``, ``u = 70 - K`` (deg): the range of the distance above the
    jump, ``70 - K`` where that is large, kept positive (a smooth function of K) beyond."""
    u = THETA_MAX - np.asarray(k, dtype=float)
    return 0.5 * (u + np.sqrt(u * u + 4.0))


def side_coordinate(d: np.ndarray, d_max: np.ndarray, d_min: float) -> np.ndarray:
    """s in [-1, 1], linear in ``d^(1/3)`` over ``[d_min^(1/3), d_max^(1/3)]``."""
    a = d_min ** (1.0 / 3.0)
    b = np.cbrt(np.maximum(d_max, d_min * (1.0 + 1e-9)))
    return 2.0 * (np.cbrt(d) - a) / (b - a) - 1.0


def side_distance(s: np.ndarray, d_max: np.ndarray, d_min: float) -> np.ndarray:
    """Inverse of :func:`side_coordinate`."""
    a = d_min ** (1.0 / 3.0)
    b = np.cbrt(np.maximum(d_max, d_min * (1.0 + 1e-9)))
    return (a + 0.5 * (np.asarray(s) + 1.0) * (b - a)) ** 3


def node_weights(x: np.ndarray, n: int) -> np.ndarray:
    """Barycentric weights (n, N) of the Chebyshev-Lobatto interpolant at the points ``x``
    in [-1, 1], one column a point: ``c_j = (b_j/(x - x_j)) / sum_k b_k/(x - x_k)`` (second
    barycentric form, Berrut & Trefethen 2004, eq. 4.2; nodes ``x_j`` and base weights
    ``b_j`` of :func:`lobatto_basis`). A point on a node gets that node's value exactly (a
    one-hot column); NaN gives a NaN column. Points along the last axis, so that each pass
    is one long vectorised loop."""
    x = np.atleast_1d(np.asarray(x, dtype=float))
    nodes, base = lobatto_basis(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = x[None, :] - nodes[:, None]
        np.divide(base[:, None], c, out=c)
        total = c.sum(axis=0)
        c *= 1.0 / total
    bad = ~np.isfinite(total)  # on a node (an infinite term), or NaN
    if bad.any():
        hit = x[None, bad] == nodes[:, None]
        c[:, bad] = np.where(hit.any(axis=0, keepdims=True), hit, np.nan)
    return c


def bary_weights(x: np.ndarray, n: int) -> np.ndarray:
    """Barycentric weights (N, n) of the Chebyshev-Lobatto interpolant at the points ``x``
    in [-1, 1], one row a point: :func:`node_weights` transposed (a view)."""
    return node_weights(x, n).T


def outer_rows(weights: list[np.ndarray], out: np.ndarray) -> np.ndarray:
    """The products ``W0[i, p] W1[j, p] ...`` of per-axis weights (n_a, N), row
    ``(i, j, ...)`` in C order (the column-wise Kronecker or Khatri-Rao product), into
    ``out`` (n_0 n_1 ..., N); one axis: its weights themselves."""
    rows = weights[0]
    for i, w in enumerate(weights[1:], start=2):
        shape = (rows.shape[0], w.shape[0], rows.shape[1])
        last = out.reshape(shape) if i == len(weights) else None
        rows = np.multiply(rows[:, None, :], w[None, :, :], out=last).reshape(-1, shape[2])
    return rows


def tensor_eval(values: np.ndarray, weights: list[np.ndarray]) -> np.ndarray:
    """``sum values[i, j, ...] W0[i, p] W1[j, p] ...`` for every point p (weights (n_a, N)
    per axis a, as :func:`node_weights`): with the axes in two groups, ``L`` the products
    of the first half's weights and ``R`` of the others' (:func:`outer_rows`), ``sum_r
    (T^T L)[r, p] R[r, p]``, the table ``T`` reshaped to a matrix. Its matrix product (all
    points at once, in BLAS) does the bulk of the work. Exact to rounding: the sums are
    ordered differently from a nested loop's, at 1e-16 relative. Two axes or more.

    ``L``, ``R`` and ``T^T L`` share one block of memory: as separate arrays of under 1 MB
    each, glibc handed the freed memory back after every chunk and faulted it in again in
    the next (2.3x the cost a point at 1e4 points in a fresh process); one block of a few
    MB raises its thresholds so that the memory is kept and reused."""
    split, points = values.ndim // 2, weights[0].shape[1]
    n_left, n_right = int(np.prod(values.shape[:split])), int(np.prod(values.shape[split:]))
    block = np.empty((n_left + 2 * n_right, points))
    left = outer_rows(weights[:split], block[:n_left])
    right = outer_rows(weights[split:], block[n_left:n_left + n_right])
    m = np.matmul(values.reshape(n_left, n_right).T, left, out=block[n_left + n_right:])
    return np.einsum("rp,rp->p", m, right)


def coordinates(r1: Any, r2: Any, volume: Any, theta1_deg: Any, theta2_deg: Any
                ) -> tuple[np.ndarray, ...]:
    """Check the inputs and return ``(y, xi, theta_s, theta_l, swapped)`` broadcast
    together: ``swapped`` where body 1 is the larger sphere or the wall. Inputs all in the
    domain (:func:`canonical`'s ``inside``) take no further pass; otherwise
    :func:`domain_error` names the input and its allowed range."""
    args = [np.inf if a is None else np.asarray(a, dtype=float)
            for a in (r1, r2, volume, theta1_deg, theta2_deg)]
    try:
        y, xi, th_s, th_l, swapped, inside = canonical(*np.broadcast_arrays(*args))
    except ValueError:  # shapes that do not broadcast: domain_error says which error first
        inside = np.array(False)
    if not np.all(inside):
        domain_error(r1, r2, volume, theta1_deg, theta2_deg)
    return y, xi, th_s, th_l, swapped


def domain_error(r1: Any, r2: Any, volume: Any, theta1_deg: Any, theta2_deg: Any) -> NoReturn:
    """Raise the InputError that names the first input outside the domain (NaN, radii,
    two walls, radius ratio, V*, each angle, in that order)."""
    def arr(name: str, value: Any) -> np.ndarray:
        a = np.asarray(value, dtype=float)
        if np.any(np.isnan(a)):
            raise InputError(f"calibrated_transfer_fraction: {name} is NaN; allowed: "
                             "finite values")
        return a

    a1 = np.inf if r1 is None else arr("r1", r1)
    a2 = np.inf if r2 is None else arr("r2", r2)
    v, t1, t2 = arr("volume", volume), arr("theta1_deg", theta1_deg), arr("theta2_deg",
                                                                         theta2_deg)
    a1, a2, v, t1, t2 = np.broadcast_arrays(a1, a2, v, t1, t2)
    if np.any(a1 <= 0) or np.any(a2 <= 0):
        raise InputError("calibrated_transfer_fraction: radii must be > 0 m (r2 = None or "
                         "inf for a wall)")
    if np.any(np.isinf(a1) & np.isinf(a2)):
        raise InputError("calibrated_transfer_fraction: two walls; allowed: a sphere and a "
                         "wall, or two spheres")
    rs, rl = np.minimum(a1, a2), np.maximum(a1, a2)
    ratio = rl / rs
    pair = np.isfinite(ratio)
    if np.any(pair & (ratio > RATIO_MAX * (1 + 1e-12))):
        bad = float(np.max(np.where(pair, ratio, 0.0)))
        raise InputError(f"calibrated_transfer_fraction: radius ratio {bad:.6g}; allowed: "
                         f"[1, {RATIO_MAX:g}] between two spheres, or a wall (r2 = None or "
                         "inf); outside, use meniscus")
    vstar = v / rs**3
    lo, hi = V_RANGE
    if np.any(vstar < lo * (1 - 1e-12)) or np.any(vstar > hi * (1 + 1e-12)):
        raise InputError(f"calibrated_transfer_fraction: V/R_small^3 outside [{lo:g}, {hi:g}] "
                         f"(given {float(np.min(vstar)):.6g}-{float(np.max(vstar)):.6g}); "
                         "outside, use meniscus")
    for name, t in (("theta1_deg", t1), ("theta2_deg", t2)):
        if np.any(t < 0.0) or np.any(t > THETA_MAX):
            raise InputError(f"calibrated_transfer_fraction: {name} outside [0, "
                             f"{THETA_MAX:g}] deg (receding); outside, use meniscus")
    # the checks above name the input; this keeps them one rule with canonical's
    raise InputError("calibrated_transfer_fraction: outside the domain; use meniscus")




def evaluate(t: dict[str, Any], y: np.ndarray, xi: np.ndarray, th_s: np.ndarray,
             th_l: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(f_s, in_band)`` at canonical coordinates (1-D arrays) from the tables ``t``
    (``jump``, ``theta_end``, ``lower``, ``upper`` as arrays, ``band_deg``, ``y_range``):
    K, the side, the side's series; NaN in the band. The weights of an axis are made once
    per node count: at every point for K, at the side's points only for the side's own axes.
    Exported verbatim into the numpy module (:mod:`wetcontact.export.transfer_fraction`)."""
    band, (y_lo, y_hi) = t["band_deg"], t["y_range"]
    jump, lower, upper, end = t["jump"], t["lower"], t["upper"], t["theta_end"]
    units = {"t": to_unit(th_s, 0.0, THETA_MAX), "y": to_unit(y, y_lo, y_hi),
             "x": 2.0 * xi - 1.0}
    rows: dict[str, np.ndarray] = {}  # the points of each side
    made: dict[tuple[str, int, str], np.ndarray] = {}

    def w(axis: str, n: int, side: str = "all") -> np.ndarray:  # an axis' weights, once
        if (axis, n, side) not in made:
            every = made.get((axis, n, "all"))
            made[axis, n, side] = (
                node_weights(units[axis], n) if side == "all"
                else np.take(every, rows[side], axis=1) if every is not None
                else node_weights(units[axis][rows[side]], n))
        return made[axis, n, side]

    k = tensor_eval(jump, [w("t", jump.shape[0]), w("y", jump.shape[1]),
                           w("x", jump.shape[2])])
    f = np.full(y.shape, np.nan)
    in_band = np.abs(th_l - k) < band
    rows["lo"] = lo = np.flatnonzero((th_l < k) & ~in_band)
    rows["hi"] = hi = np.flatnonzero((th_l > k) & ~in_band)
    if lo.size:
        k_lo = k[lo]
        s = side_coordinate(k_lo - th_l[lo], k_lo, band)
        f[lo] = tensor_eval(lower, [w("t", lower.shape[0], "lo"), w("y", lower.shape[1], "lo"),
                                    w("x", lower.shape[2], "lo"),
                                    node_weights(np.clip(s, -1.0, 1.0), lower.shape[3])])
    if hi.size:
        k_hi = k[hi]
        te = tensor_eval(end, [w("y", end.shape[0], "hi"), w("x", end.shape[1], "hi")])
        s = side_coordinate(th_l[hi] - k_hi, band + upper_width(k_hi), band)
        f[hi] = tensor_eval(upper, [
            node_weights(np.clip(to_unit(th_s[hi] / te, 0.0, 1.0), -1.0, 1.0),
                         upper.shape[0]),
            w("y", upper.shape[1], "hi"), w("x", upper.shape[2], "hi"),
            node_weights(np.clip(s, -1.0, 1.0), upper.shape[3])])
    exact = (xi == 0.0) & (th_s == th_l)  # equal spheres, equal angles: 1/2 by symmetry
    f[exact], in_band[exact] = 0.5, False
    return f, in_band


def canonical(r1: np.ndarray, r2: np.ndarray, volume: np.ndarray, theta1_deg: np.ndarray,
              theta2_deg: np.ndarray) -> tuple[np.ndarray, ...]:
    """``(y, xi, theta_s, theta_l, swapped, inside)`` of broadcast float arrays (``inf`` a
    wall): body s the smaller sphere (between equal spheres the one with the smaller angle,
    so that swapping the bodies gives ``1 - f`` exactly), ``swapped`` where that is body 2,
    ``inside`` where the point is in the domain. Exported verbatim (as :func:`evaluate`)."""
    swapped = (r1 > r2) | ((r1 == r2) & (theta1_deg > theta2_deg))
    rs, rl = np.minimum(r1, r2), np.maximum(r1, r2)
    with np.errstate(divide="ignore", invalid="ignore"):
        vstar = volume / rs**3
        ratio = rl / rs
    inside = ((rs > 0) & np.isfinite(rs) & (rl > 0) & ((ratio <= RATIO_MAX * (1 + 1e-12))
                                                      | np.isinf(rl))
              & (vstar >= V_RANGE[0] * (1 - 1e-12)) & (vstar <= V_RANGE[1] * (1 + 1e-12))
              & (theta1_deg >= 0.0) & (theta1_deg <= THETA_MAX)
              & (theta2_deg >= 0.0) & (theta2_deg <= THETA_MAX))
    th_s = np.where(swapped, theta2_deg, theta1_deg)
    th_l = np.where(swapped, theta1_deg, theta2_deg)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = np.cbrt(np.clip(1.0 - rs / rl, 0.0, 1.0))
        y = np.log(np.clip(vstar, V_RANGE[0], V_RANGE[1]))
    return y, xi, th_s, th_l, swapped, inside


class Table:
    """The closure's tables read from the package data (node values on tensor
    Chebyshev-Lobatto grids)."""

    def __init__(self, data: dict[str, Any]):
        if data.get("schema_version") != SCHEMA_VERSION:
            raise InputError(f"{TRANSFER_FILE}: schema_version {data.get('schema_version')}; "
                             f"this code reads {SCHEMA_VERSION}")
        self.tables = {"band_deg": float(data["band_deg"]),
                       "y_range": tuple(float(v) for v in data["y_range"]),
                       **{k: np.asarray(data[k], dtype=float)
                          for k in ("jump", "theta_end", "lower", "upper")}}
        self.band = self.tables["band_deg"]

    def evaluate(self, y: np.ndarray, xi: np.ndarray, th_s: np.ndarray, th_l: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`evaluate` with these tables."""
        return evaluate(self.tables, y, xi, th_s, th_l)


@lru_cache(maxsize=1)
def load_table() -> Table:
    """The shipped table (read once)."""
    path = DATA_DIR / TRANSFER_FILE
    if not path.is_file():
        raise InputError(f"calibrated_transfer_fraction: {path} is missing; build it with "
                         "`python -m wetcontact.generate transfer-fraction`")
    return Table(json.loads(path.read_text()))


def calibrated_transfer_fraction(r1: Any, r2: Any, volume: Any, theta1_deg: Any,
                                 theta2_deg: Any, *, return_reason: bool = False,
                                 table: Table | None = None) -> Any:
    r"""Fraction of a ruptured bridge's liquid that body 1 keeps (calibrated to ``meniscus``).

    .. math:: f = f_s(\ln V^*, \theta_s, \theta_l, \xi)\ \text{(body 1 the smaller sphere)},
              \qquad f = 1 - f_s \ \text{(body 1 the larger one)},

    ``f_s`` the tensor Chebyshev tables on the two sides of the jump ``theta_l = K`` (module
    docstring: the form, the band, the source). Body 2 keeps ``1 - f``.

    Parameters
    ----------
    r1, r2
        Radii of body 1 and body 2 (m); ``None`` or ``inf`` is a wall (one of them at most).
        Radius ratio in [1, 10] between spheres.
    volume
        Bridge volume V (m^3): ``V/R_small^3`` in [1e-4, 0.1].
    theta1_deg, theta2_deg
        Receding contact angles on body 1 and body 2 (deg), each in [0, 70].
    return_reason
        Also return, per point, ``""`` or why the value is NaN (the band at the jump).
    table
        The tables (default: the package data).

    Returns
    -------
    numpy.ndarray or float
        f (broadcast over the inputs; a float for scalar inputs); NaN within ``d_min`` of
        the jump, but exactly 1/2 for equal spheres with equal angles (by symmetry). With
        ``return_reason``: ``(f, reasons)``.

    Raises
    ------
    InputError
        Outside the domain (named, with the allowed range): use ``meniscus`` there.

    Notes
    -----
    Accuracy (absolute, against ``meniscus``, outside the band): held-out max 6.4e-4, mean
    1.5e-4 (``data/transfer_fraction_record.json``).
    """
    y, xi, th_s, th_l, swapped = coordinates(r1, r2, volume, theta1_deg, theta2_deg)
    shape = y.shape
    tab = table or load_table()
    y, xi, th_s, th_l = (a.ravel() for a in (y, xi, th_s, th_l))
    f_s, band = np.empty(y.size), np.empty(y.size, dtype=bool)
    for i in range(0, y.size, CHUNK):  # chunks: the contractions' temporaries stay in cache
        c = slice(i, i + CHUNK)
        f_s[c], band[c] = tab.evaluate(y[c], xi[c], th_s[c], th_l[c])
    f = np.where(swapped.ravel(), 1.0 - f_s, f_s).reshape(shape)
    out: Any = float(f) if f.ndim == 0 else f
    if not return_reason:
        return out
    reasons = np.where(band.reshape(shape), BAND_REASON, "")
    return out, (str(reasons) if reasons.ndim == 0 else reasons)
