r"""The calibrated capillary closure's evaluation (:func:`table_star`), standalone: it
imports only numpy, the standard library and :mod:`.coordinates` (likewise), so that
``wetcontact export python`` ships this module's source, with that of :mod:`.coordinates`,
as the exported module's evaluator. The shipped table and the package's calls of it are in
:mod:`.shipped` (:func:`~wetcontact.reduced_models.calibrated_capillary.shipped.force_star`).

Each piece of a table is a tensor Chebyshev series in the coordinates of
:mod:`~wetcontact.reduced_models.calibrated_capillary.coordinates`. A point is evaluated in
the band (:func:`band_index`) and the piece that hold its angles; their ends are Chebyshev
series themselves: the onset angle (:data:`ONSET_KEY`, in a, or in (w, a) for sphere pairs)
and the split or ridge angle (``theta_split``, :func:`theta_split_deg`).

The force table is stored in low-rank form: its unfolding over the first two axes ((a, b)
on a wall, (w, a) for sphere pairs) against the rest is a truncated SVD,
``C^F_{IJ} = sum_{k<r} L_{Ik} R_{kJ}``, with the smallest rank r whose change of the
exponent stays below 5e-5 on a seeded probe (5 % of the force goal), so that a point costs
``r (P_left + P_right)`` multiply-adds instead of the table's size (:func:`low_rank_rows`).
The two-angle tables evaluate each piece's rupture table and this low-rank force as tensor
trains (:data:`TRAIN_FIELDS`, :func:`train_sum`; Oseledets 2011): on a wall 0.56-0.74 of
the low-rank form's multiply-adds, between spheres 0.23-0.40.

Precision (:data:`PRECISIONS`). By default (``"mixed"``, the fast and default presets) the
force's table is summed in single precision, its cores or factors and Chebyshev rows
rounded to float32 as they are summed, so that the products move half the bytes. The
rupture distance's tables, the ridge and onset series (which decide a point's band and
piece), the coordinates and exp stay in float64, so S_c, and with it which gaps a bridge
spans, is bitwise that of ``"double"`` (the accurate preset, what the exported closures
compute). The force moves by at most 6.7e-6 relative (1/150 of the force goal) on 1e5
seeded points.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from wetcontact.reduced_models.calibrated_capillary.coordinates import (
    ANGLE_TOL,
    PAIR_TWO_ANGLES,
    TWO_ANGLE_TABLES,
    WALL_TWO_ANGLES,
    Lead,
    _take,
    gap_coordinate,
    lead_list,
    piece_coordinate,
    piece_range,
    ratio_coordinate,
    sphere_coordinate,
    volume_coordinate,
)

PRECISIONS = ("mixed", "double")
"""How :func:`table_star` sums the force's table (a two-angle table's tensor train,
:data:`TRAIN_FIELDS`, a one-angle table's low-rank sum, :func:`low_rank_rows`):
``"mixed"`` (the default) in single precision, from its Chebyshev rows and cores or
factors rounded to it, ``"double"`` in double. Everything else (the coordinates, the
rupture distance's tables, the ridge and onset series, exp, the result) is double either
way, so S_c is the same in both. Single precision moves the force by at most 6.7e-6
relative (measured; the tests hold it under 2e-5, 1/50 of the force goal) and cuts the
cost by about a fifth (wall, two angles), a third (sphere pairs, two angles), a quarter
(wall, one angle) and a seventh (sphere pairs, one angle): the module's notes,
"Precision"."""


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
    and 1024 points at a time.
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


def train_shape(train: dict[str, Any]) -> tuple[int, ...]:
    """The dense table's shape of a tensor train (:func:`train_sum`), in the table's axis
    order: core k carries axis ``order[k]``, its middle size that axis's length."""
    n = [0] * len(train["order"])
    for g, ax in zip(train["cores"], train["order"], strict=True):
        n[ax] = int(g.shape[1])
    return tuple(n)


def reduced_star(kind: str, ratio: np.ndarray | None) -> np.ndarray | float:
    """R*/R_s: 1 on a wall, r/(1 + r) for a sphere pair."""
    return 1.0 if kind in ("sphere-wall", WALL_TWO_ANGLES) else ratio / (1.0 + ratio)


def table_star(lookup: Callable[[str], dict[str, Any]], kind: str, v: np.ndarray,
               theta: np.ndarray, s: np.ndarray, ratio: np.ndarray | None = None,
               chunk: int | None = None, entry: dict[str, Any] | None = None,
               theta_wall: np.ndarray | None = None, precision: str = "mixed"
               ) -> tuple[np.ndarray, np.ndarray]:
    """Attractive force ``F/(2 pi sigma R_s)`` at gap ``s = S/R_s`` (0 at and beyond
    rupture) and the rupture distance ``S_c/R_s``, in one pass (the Chebyshev rows of
    (w,) a, b serve both tables), from the tables ``lookup(kind)`` returns (the package's
    :func:`~wetcontact.reduced_models.calibrated_capillary.shipped.force_star` looks up its
    shipped table; the exported numpy module, its own copy).

    Each point is evaluated in the theta piece that contains it: between equal spheres the
    rupture distance has a kink where the branch's end changes from a fold to a
    symmetry-breaking bifurcation (theta about 30-31 deg, moving with V), so sphere pairs
    carry two tables, below and above that angle (``theta_split``). The force exponent is
    the rank-r sum :func:`low_rank_rows` (cost ``r (P_left + P_right)`` multiply-adds a
    point), or, for a piece that carries them (the two-angle tables'), its tensor trains
    (:func:`train_sum`). ``entry``: one kind's table (default: ``lookup(kind)``).

    On a wall, ``theta_wall`` (rad) gives the wall its own angle (``theta`` is then the
    sphere's): points whose two angles differ by more than :data:`ANGLE_TOL` are evaluated
    in the two-angle table :data:`WALL_TWO_ANGLES` (in the band that holds the sphere's
    angle, :func:`band_index`: sphere angle ``b1`` over the band, and the wall angle within
    the pieces that meet at the band's ridge), the others in the
    one-angle table (``entry``, if given, is the one-angle table), and the Derjaguin
    prefactor is ``cos theta_s + cos theta_w``.

    ``precision`` (:data:`PRECISIONS`): ``"mixed"`` sums the force's tensor train in single
    precision (everything else, S_c and the result included, in double); ``"double"`` sums
    every table in double precision (any other value counts as ``"double"``: the caller
    checks it)."""
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
                f[mask], s_c[mask] = table_star(
                    lookup, k, v[mask], theta[mask], s[mask],
                    None if ratio is None else ratio[mask], chunk=chunk,
                    entry=entry if k == kind else None,
                    theta_wall=None if k == kind else tw[mask], precision=precision)
        return f.reshape(shape), s_c.reshape(shape)
    e = lookup(kind) if entry is None else entry
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
    if force_train is None:  # the low-rank factors
        left, right = np.asarray(piece["force_left"]), np.asarray(piece["force_right"])
        dims = (*left.shape[:-1], *right.shape[1:])  # the force table's axes
        k = left.ndim - 1
        left_d, right_d = left.astype(dtype, copy=False), right.astype(dtype, copy=False)
    else:
        dims = train_shape(force_train)
    if rup_train is None:
        rup = np.asarray(piece["rupture"])
        rup2 = rup.reshape(-1, rup.shape[-1]).T
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
