r"""The dynamic division of the liquid at the pinch: the volume on each side of the neck.

When the neck of a dynamic bridge pinches, the liquid below the neck's plane stays on the
lower solid (the wall, or the lower sphere of radius R2) and the rest on the sphere. With
the free surface ``(r(s), z(s))`` from the lower contact line (s = 0) to the neck (``s_n``,
the narrowest point, below the sphere's apex),

.. math::
    V_{wall} = \int_0^{s_n} \pi\, r^2\, \frac{dz}{ds}\, ds - R_2^3 V_{cap}(\phi_2),
    \qquad V_{sphere} = V - V_{wall},

(``V_cap`` the lower sphere's cap above its contact line, :mod:`.domain`; none on a wall)
on the P2 surface (Gauss quadrature, the element holding the neck cut at the neck). At a
run's last state the neck is about 1 % of its start, so the cut differs from the pinch's by
the liquid in that last thread (about ``pi h^2`` times its length). Between two equal
spheres the division is 1/2 by symmetry (:data:`~.domain.MeshOptions` ``plane="symmetry"``).
The quasi-static counterpart is ``meniscus``'s ``transfer_fraction`` (the fold shape cut at
its neck; :mod:`wetcontact.solver.meniscus.division`).
"""

from __future__ import annotations

import numpy as np

from wetcontact.errors import SolverError
from wetcontact.solver.stokes_dynamic.domain import (
    cap_volume,
    lower_angle,
    neck_point,
    p2_shape,
)
from wetcontact.solver.stokes_dynamic.run import DynamicRun

_GAUSS = np.polynomial.legendre.leggauss(8)


def _volume_to(e: np.ndarray, upto: np.ndarray) -> float:
    """sum over P2 elements ``e`` (2, 3, N) of int_0^{upto_k} pi r^2 dz/dxi dxi."""
    x, w = _GAUSS
    total = 0.0
    for k in range(e.shape[2]):
        if upto[k] <= 0.0:
            continue
        xi = 0.5 * upto[k] * (x + 1.0)
        n, dn = p2_shape(xi)
        r = n.T @ e[0][:, k]
        dz = dn.T @ e[1][:, k]
        total += float(np.pi * np.sum(r * r * dz * w) * 0.5 * upto[k])
    return total


def wall_side_volume(run: DynamicRun) -> tuple[float, float]:
    """``(V_wall, V)`` at the run's last state: the liquid below the neck's plane (the
    lower solid's share at the pinch) and the whole volume, units R^3 (the run's own
    units)."""
    d = run.domain
    xs = d.surface_xy
    _, zn, k, xi_n = neck_point(xs)
    if zn >= d.gap:
        raise SolverError(f"stokes-dynamic: the neck (z = {zn:.4g} R) is not below the "
                          f"sphere's apex (S = {d.gap:.4g} R)")
    e = np.stack([xs[:, 0:-1:2], xs[:, 2::2], xs[:, 1::2]], axis=1)  # (2, 3, N)
    upto = np.where(np.arange(e.shape[2]) < k, 1.0, 0.0)
    upto[k] = xi_n
    below = _volume_to(e, upto)
    if d.radius2 is not None:
        below -= d.radius2**3 * cap_volume(float(lower_angle(xs[:, :1], d.radius2)[0]))
    return below, d.volume()


def wall_fraction(run: DynamicRun) -> float:
    """The fraction of the bridge's liquid the lower solid keeps at the pinch (the sphere
    keeps ``1 -`` it)."""
    vw, v = wall_side_volume(run)
    return vw / v
