r"""Chebyshev nodes and coefficients of the calibrated capillary tables, and their
compressed forms (:mod:`wetcontact.generate.calibrated_capillary`).

- Nodes: Chebyshev-Lobatto points ``-cos(pi k/(n-1))`` (:func:`lobatto`) or Chebyshev-Gauss
  points ``-cos(pi (k + 1/2)/n)`` (:func:`gauss`); the tensor interpolant's coefficients
  follow by a type-I (Lobatto) or type-II (Gauss) discrete cosine transform per axis
  (:func:`lobatto_coefficients`), exact at the nodes.
- Low-rank form of the force table (:func:`factor_table`): the truncated SVD of its
  unfolding over the first two axes against the rest,
  ``C_{IJ} = sum_{k<r} L_{Ik} R_{kJ}`` (Eckart & Young 1936), at the smallest rank whose
  sum changes by at most :data:`FACTOR_TOL` (5 % of the 1e-3 force goal) on a probe of the
  Lobatto grid and seeded uniform points.
- Tensor trains (:func:`tt_svd`, :func:`train_of`, :func:`train_piece`): sequential
  truncated SVDs of the unfoldings (Oseledets 2011, SIAM J. Sci. Comput. 33, 2295,
  algorithm 1), dropping singular values of 2-norm up to :data:`TRAIN_TOL`, over the axis
  order with the fewest multiply-adds a point; the model evaluates them
  (:func:`~wetcontact.reduced_models.calibrated_capillary.train_sum`).
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from scipy.fft import dct

from wetcontact.reduced_models import calibrated_capillary as cc


def lobatto(n: int) -> np.ndarray:
    """Chebyshev-Lobatto points ``-cos(pi k/(n-1))`` on [-1, 1], increasing."""
    return -np.cos(np.pi * np.arange(n) / (n - 1))


def gauss(n: int) -> np.ndarray:
    """Chebyshev-Gauss points ``-cos(pi (k + 1/2)/n)`` on (-1, 1), increasing (no endpoint)."""
    return -np.cos(np.pi * (np.arange(n) + 0.5) / n)


def lobatto_coefficients(values: np.ndarray, gauss_axes: tuple[int, ...] = ()) -> np.ndarray:
    """Chebyshev coefficients of the tensor interpolant through values at :func:`lobatto`
    points (a type-I DCT on each axis), or at :func:`gauss` points on ``gauss_axes`` (a
    type-II DCT there)."""
    c = values[tuple(slice(None, None, -1) for _ in values.shape)]
    for ax, n in enumerate(values.shape):
        idx0 = [slice(None)] * values.ndim
        idx0[ax] = 0
        if ax in gauss_axes:
            c = dct(c, type=2, axis=ax) / n
            c[tuple(idx0)] /= 2.0
        else:
            c = dct(c, type=1, axis=ax) / (n - 1)
            idx1 = list(idx0)
            idx1[ax] = -1
            c[tuple(idx0)] /= 2.0
            c[tuple(idx1)] /= 2.0
    return c


FACTOR_TOL = 5e-5
"""Largest change of the force exponent (a relative change of the force) that the low-rank
form may make on its probe: 5 % of the 1e-3 force goal."""
FACTOR_LEFT_AXES = 2
"""Axes on the left of the factorised unfolding: (a, b) on a wall, (w, a) for pairs."""


def factor_table(coef: np.ndarray, n_left: int = FACTOR_LEFT_AXES, tol: float = FACTOR_TOL,
                 n_probe: int = 20000, seed: int = 0
                 ) -> tuple[np.ndarray, np.ndarray, float]:
    """Low-rank form of a tensor Chebyshev table: ``C_{IJ} = sum_{k<r} L_{Ik} R_{kJ}``.

    ``(L, R)`` is the truncated SVD (Eckart & Young 1936) of the unfolding of ``coef``
    over its first ``n_left`` axes (I) against the rest (J), at the smallest rank r whose
    sum changes by at most ``tol`` at every probe point: the Chebyshev-Lobatto grid of the
    table's shape and ``n_probe`` seeded uniform points in [-1, 1]^d.

    Returns
    -------
    left, right, err
        ``left`` of shape (*coef.shape[:n_left], r), ``right`` (r, *coef.shape[n_left:]),
        and the largest change on the probe.
    """
    sh = coef.shape
    u, sv, vt = np.linalg.svd(coef.reshape(int(np.prod(sh[:n_left])), -1),
                              full_matrices=False)
    rng = np.random.default_rng(seed)
    grid = np.meshgrid(*(lobatto(m) for m in sh), indexing="ij")
    pts = [np.concatenate([g.ravel(), rng.uniform(-1.0, 1.0, n_probe)]) for g in grid]
    a = cc._outer_rows(pts[:n_left], sh[:n_left]) @ (u * sv)
    b = cc._outer_rows(pts[n_left:], sh[n_left:]) @ vt.T
    terms = a * b  # the rank-one terms at each probe point
    full = terms.sum(axis=1)
    # change of the sum when truncated after k terms, for every k
    change = np.abs(full[:, None] - np.cumsum(terms, axis=1)).max(axis=0)
    r = int(np.argmax(change <= tol)) + 1 if np.any(change <= tol) else sv.size
    return ((u[:, :r] * sv[:r]).reshape(*sh[:n_left], r), vt[:r].reshape(r, *sh[n_left:]),
            float(change[r - 1]))


WALL_TRAINS = ("force_train",)
"""The tensor trains a two-angle wall piece carries (:func:`train_piece`): its force table's,
0.56-0.74 of the low-rank form's multiply-adds. On the probe :func:`factor_table` chose the
rank on they change the force sum by at most 9.1e-5 (7.2e-5 on the grid short of S_c), the
held-out maxima by at most 6e-6. Its rupture table stays dense: a train would save nothing
measurable (0.70 against 0.71 us a point) and would break the bands' join, where both tables
interpolate the same nodes and S_c is continuous to round-off (a train moved it by up to
1.5e-6 there)."""


TRAIN_TOL = {"rupture_train": 1e-6, "force_train": 1e-5}
"""Truncation of each piece's tensor trains (:func:`tt_svd`): the 2-norm of the singular values
dropped at each unfolding of the Chebyshev coefficient tensor. Measured against the fit
(``benchmarks/bench_pair_tt.py``): the force moves by at most 1.1e-4 on the cost benchmark's
points, the held-out maxima by at most 1.3e-5, and a point costs 1.34 us instead of 4.05. On
the probe the force factors' rank was chosen on (:func:`factor_table`: the Lobatto grid and
20 000 uniform points) the force sum changes by up to 1.6e-4 short of the rupture distance,
and 9.4e-4 at it (c = -1, where no held-out point goes); the rupture sum by up to 1.1e-5.
Trains held to 5e-5 / 5e-6 there cost 1.56 us a point, with the same held-out maxima. The
two-angle wall table's force trains are built at the same tolerance (:data:`WALL_TRAINS`)."""


def tt_svd(coef: np.ndarray, tol: float,
           max_ranks: list[int] | None = None) -> list[np.ndarray]:
    """Tensor-train cores ``G_k`` (r_{k-1}, n_k, r_k) of ``coef`` by sequential truncated
    SVDs of its unfoldings (Oseledets 2011, SIAM J. Sci. Comput. 33, 2295, algorithm 1),
    each dropping the trailing singular values whose 2-norm is at most ``tol`` (and those
    beyond ``max_ranks[k]``, if given); the last core carries the singular values."""
    cores, rank, rest = [], 1, np.asarray(coef, dtype=float)
    for k, n_k in enumerate(coef.shape[:-1]):
        u, sv, vt = np.linalg.svd(rest.reshape(rank * n_k, -1), full_matrices=False)
        tail = np.sqrt(np.cumsum(sv[::-1] ** 2))[::-1]  # 2-norm of sv[j:]
        keep = max(1, int(np.sum(tail > tol)))
        if max_ranks is not None:
            keep = max(1, min(keep, max_ranks[k]))
        cores.append(u[:, :keep].reshape(rank, n_k, keep))
        rest, rank = sv[:keep, None] * vt[:keep], keep
    cores.append(rest.reshape(rank, coef.shape[-1], 1))
    return cores


def train_of(coef: np.ndarray, tol: float,
             order: tuple[int, ...] | None = None) -> dict[str, Any]:
    """The tensor train of ``coef`` over the axis order with the fewest multiply-adds a
    point (all orders tried; or over ``order``), as a piece stores it
    (:func:`~wetcontact.reduced_models.calibrated_capillary.train_sum`)."""
    def cost(order: tuple[int, ...]) -> int:
        return sum(g.size for g in tt_svd(coef.transpose(order), tol))

    if order is None:
        order = min(itertools.permutations(range(coef.ndim)), key=cost)
    cores = tt_svd(coef.transpose(order), tol)
    return {"order": list(order), "tol": tol, "ranks": [g.shape[2] for g in cores[:-1]],
            "cores": [g.tolist() for g in cores]}


TRAINS = ("rupture_train", "force_train")
"""The trains a piece may carry, in the order they are built and evaluated."""


def train_fits(piece: dict[str, Any], fields: tuple[str, ...] = TRAINS
               ) -> dict[str, np.ndarray]:
    """The Chebyshev coefficient tensors a piece's trains (those of ``fields``) are built
    from, by train field: its rupture table, and the product of its low-rank force
    factors."""
    make = {"rupture_train": lambda: np.asarray(piece["rupture"], dtype=float),
            "force_train": lambda: np.tensordot(np.asarray(piece["force_left"], dtype=float),
                                                np.asarray(piece["force_right"], dtype=float),
                                                1)}
    return {k: make[k]() for k in fields}


def train_piece(piece: dict[str, Any],
                orders: dict[str, tuple[int, ...]] | None = None,
                fields: tuple[str, ...] = TRAINS) -> dict[str, Any]:
    """A piece with its rupture and force tables' tensor trains (:data:`TRAIN_TOL`; those
    of ``fields``) beside the fit they are built from (:func:`train_fits`), each over the
    cheapest axis order (:func:`train_of`) or the one ``orders`` gives it (by field)."""
    return {**piece, **{k: train_of(c, TRAIN_TOL[k], (orders or {}).get(k))
                        for k, c in train_fits(piece, fields).items()}}
