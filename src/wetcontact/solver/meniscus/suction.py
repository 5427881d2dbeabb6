"""Suction-controlled bridges between two spheres: the public API of suction control.

A :class:`SuctionBridges` is the discretised bridge between a small sphere of radius
``1/ratio`` (sphere 1) and a large one of radius 1 (sphere 2), both with one contact angle,
in the large sphere's units (lengths over R2, pressures over sigma/R2: the gap ``D* = D/R2``,
the suction ``u* = -dp R2/sigma``), on ``n_elements`` P2 elements. A bridge is a *state*: the
solver's unknowns as an array, opaque to the caller, read through the methods here. What
it offers: the toroidal guess at a filling angle, Newton at a fixed gap with the suction, the
filling angle or the sum of the two filling angles prescribed, the first stable bridge at a
suction (:func:`~wetcontact.solver.meniscus.continuation.suction_start`), the stable branch
at a suction from its start to its fold and the bridges on it at given gaps
(:func:`~wetcontact.solver.meniscus.continuation.suction_branch`,
:func:`~wetcontact.solver.meniscus.continuation.suction_at_gaps`), a state carried to a finer
mesh, and the quantities of a state (volume, force, filling angles, interface terms).
:mod:`wetcontact.export.yade` builds Yade's capillary files with it.
"""

from __future__ import annotations

import math

import numpy as np

from wetcontact.errors import SolverError
from wetcontact.solver.meniscus.continuation import (
    SuctionBranch,
    suction_at_gaps,
    suction_branch,
    suction_start,
)
from wetcontact.solver.meniscus.geometry import PHI_MAX, _Geo
from wetcontact.solver.meniscus.guess import _guess_at
from wetcontact.solver.meniscus.post import interface_terms
from wetcontact.solver.meniscus.young_laplace import Fixed, Linear, _disc, _newton, _volume


class SuctionBridges:
    """Bridges between spheres of radii ``1/ratio`` and 1 with ``contact_angle`` (rad) on
    both, at controlled suction, on ``n_elements`` P2 elements (units: the large sphere's
    radius and the surface tension)."""

    def __init__(self, ratio: float, contact_angle: float, n_elements: int) -> None:
        self.ratio = float(ratio)
        self.contact_angle = float(contact_angle)
        self._d = _disc(int(n_elements))
        self._g = _Geo(1.0 / ratio, 1.0, contact_angle, contact_angle, 0.0)

    @property
    def n_elements(self) -> int:
        """Elements of the discretisation."""
        return int(self._d.n_el)

    @property
    def max_filling(self) -> float:
        """Largest admitted half-filling angle on the small sphere (rad):
        ``min(90 deg - theta, PHI_MAX)``."""
        return min(0.5 * math.pi - self.contact_angle, PHI_MAX)

    def refined(self, n_elements: int) -> SuctionBridges:
        """The same spheres and angle on ``n_elements`` elements."""
        return SuctionBridges(self.ratio, self.contact_angle, n_elements)

    # ---- reading a state ---------------------------------------------------------------

    def gap(self, x: np.ndarray) -> float:
        """The gap D* of a state."""
        return x[self._d.iS]

    def suction(self, x: np.ndarray) -> float:
        """The suction u* = -dp of a state."""
        return -float(x[self._d.iP])

    def filling(self, x: np.ndarray) -> float:
        """The half-filling angle on the small sphere (rad)."""
        return float(x[self._d.ic1])

    def volume(self, x: np.ndarray) -> float:
        """The bridge volume V* of a state."""
        return _volume(self._d, self._g, x)

    def quantities(self, x: np.ndarray) -> tuple[float, float, float, float, float, float]:
        """``(V*, F*, delta1, delta2, nn11*, nn33*)`` of a state: the volume, the attraction
        at the small sphere's contact line over ``2 pi sigma R2`` (> 0 attracts), the
        half-filling angles on the small and the large sphere (rad) and the 11 and 33 terms
        of the integral of ``n n`` over the liquid-gas interface
        (:func:`~wetcontact.solver.meniscus.post.interface_terms`)."""
        d, g = self._d, self._g
        c1, c2, P = float(x[d.ic1]), float(x[d.ic2]), float(x[d.iP])
        rho1 = g.rt * math.sin(c1)
        f = rho1 * math.sin(c1 + g.tht) - 0.5 * rho1 * rho1 * P
        nn11, nn33 = interface_terms(d, x)
        return float(_volume(d, g, x)), f, c1, c2, nn11, nn33

    # ---- solving -----------------------------------------------------------------------

    def guess(self, gap: float, filling: float) -> np.ndarray | None:
        """The toroidal guess with half-filling angle ``filling`` on the small sphere at
        ``gap``; ``None`` where the circular arc does not close."""
        return _guess_at(self._d, self._g, gap, filling)

    def solve(self, x0: np.ndarray, gap: float, *, suction: float | None = None,
              filling: float | None = None, filling_sum: float | None = None,
              maxit: int = 30) -> np.ndarray | None:
        """Newton from ``x0`` at ``gap`` with exactly one of: the suction, the half-filling
        angle on the small sphere, or the sum of the two half-filling angles prescribed;
        the state, or ``None`` if it did not converge."""
        d = self._d
        if (suction is None) + (filling is None) + (filling_sum is None) != 2:
            raise ValueError("give exactly one of suction, filling, filling_sum")
        if suction is not None:
            first: Fixed | Linear = Fixed(d.iP, -suction)
        elif filling is not None:
            first = Fixed(d.ic1, filling)
        else:
            a = np.zeros(d.m)
            a[d.ic1] = a[d.ic2] = 1.0
            first = Linear(a, filling_sum)
        nw = _newton(d, self._g, x0, (first, Fixed(d.iS, gap)), maxit=maxit)
        return nw.x if nw.converged else None

    def start(self, suction: float, near: np.ndarray) -> np.ndarray | None:
        """The first stable bridge at ``suction``: at contact if its filling angle is at
        most :attr:`max_filling`, else at that angle; ``near`` a nearby state (the start at
        a neighbouring suction); ``None`` if none is found."""
        return suction_start(self._d, self._g, -suction, near, self.max_filling)

    def branch(self, suction: float, start: np.ndarray) -> SuctionBranch:
        """The stable branch at ``suction`` from ``start`` to its fold (``S_start``,
        ``S_fold``, ``points``, ``solves``)."""
        return suction_branch(self._d, self._g, -suction, start)

    @staticmethod
    def at_gaps(branch: SuctionBranch, gaps: np.ndarray) -> list[np.ndarray]:
        """The stable bridges of ``branch`` at ``gaps`` (each in [S_start, S_fold])."""
        return suction_at_gaps(branch, gaps)

    def transfer(self, coarse: SuctionBridges, x: np.ndarray) -> np.ndarray:
        """A state of ``coarse`` (same spheres, a coarser mesh) on this discretisation: its
        P2 fields evaluated at this mesh's nodes (exact interpolation), the scalar unknowns
        copied."""
        dc, df = coarse._d, self._d
        t = dc.t[dc.sorted]                        # coarse nodes 0, h/2, h, ... (sorted)
        h = 1.0 / dc.n_el
        k = np.minimum((df.t / h).astype(int), dc.n_el - 1)
        xi = df.t / h - k
        w = (2 * (xi - 0.5) * (xi - 1), -4 * xi * (xi - 1), 2 * xi * (xi - 0.5))
        if not np.allclose(t[2 * k] + 0.5 * h, t[2 * k + 1]):
            raise SolverError("meniscus: unexpected node layout in the mesh transfer")
        out = np.empty(df.m)
        for f in range(3):
            fc = x[f * dc.n:(f + 1) * dc.n][dc.sorted]
            out[f * df.n:(f + 1) * df.n] = w[0] * fc[2 * k] + w[1] * fc[2 * k + 1] \
                + w[2] * fc[2 * k + 2]
        out[3 * df.n:] = x[3 * dc.n:]
        return out
