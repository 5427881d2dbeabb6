r"""Division of a bridge's liquid between the two bodies at rupture (physics notes section 7).

A volume-controlled bridge pulled apart slowly follows its stable branch to the rupture
distance ``S_c`` (the fold, or the symmetry-breaking bifurcation between equal spheres
with equal angles). The critical bridge is cut at its **neck**, the plane ``z = z_n`` where
the meridian ``r(z)`` is smallest, and each body keeps the liquid on its side:

.. math::
    V_1 = \int_{z_n}^{z_{c1}} \pi r^2\, dz - V_{solid}(z > z_n),\qquad
    V_2 = \int_{z_{c2}}^{z_n} \pi r^2\, dz - V_{solid}(z < z_n),\qquad
    f = \frac{V_1}{V_1 + V_2},

``z_c1``, ``z_c2`` the contact-line heights on body 1 (the upper sphere) and body 2 (sphere
2 or the wall), ``V_solid`` the part of the spheres' caps inside the bridge on that side
(caps of height h: ``pi h^2 (3R - h)/3``). ``f`` stays on body 1, ``1 - f`` on body 2. The
quasi-static limit of stretching and pinch-off (Darabi et al. 2010, Chem. Eng. Sci. 65,
4472); equal spheres with equal angles give 1/2.

Numerics: the FE meridian of :mod:`.young_laplace`; the neck from the solver's quintic
Hermite reconstruction (:mod:`.post`); the solver's Gauss rule on whole elements and an
8-point Gauss-Legendre rule on the two parts of the neck's element. Order 4
(``MeniscusModel.extras_convergence_data``).

Limits: where ``r(z)`` has no interior minimum on one side (``phi + theta`` above 90 deg
at rupture) or a contact line is narrower than the neck, the cut is at that contact line
and that body keeps nothing (``f = 0`` or 1, ``neck = "contact1"``/``"contact2"``),
continuously. Near symmetry ``f - 1/2 ~ eps^(1/3)`` (``eps`` the angle difference). The
dynamics after the last stable shape are not modelled; the angles are the receding ones.
Domain checked against an ODE shooting solution (tests/solver/test_division.py): radius
ratios 1-10, angles 0-70 deg, V/R_small^3 in [1e-4, 0.1]. In full: the guide's *Solver
notes* (``docs/solvers.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.meniscus.continuation import _Branch, _on_branch
from wetcontact.solver.meniscus.geometry import DEFAULT_ELEMENTS, Bridge, _Geo
from wetcontact.solver.meniscus.post import _quintic_min
from wetcontact.solver.meniscus.solve import _branch_for
from wetcontact.solver.meniscus.young_laplace import _Disc, _fields

BIFURCATION_STEP = 1e-4
"""Relative distance below a symmetry-breaking bifurcation of the two stable bridges whose
division is extrapolated to it (:func:`divide_branch`): 1e-6 leaves 1e-10 of the singular
mode's noise in ``f``, 1e-4 below 1e-11."""

_GL_U, _GL_W = np.polynomial.legendre.leggauss(8)
_GL_U = 0.5 * (_GL_U + 1.0)
_GL_W = 0.5 * _GL_W


@dataclass(frozen=True)
class Division:
    """How the liquid of a bridge divides at rupture (SI units).

    Attributes
    ----------
    fraction
        ``f = V1/(V1 + V2)``, the fraction of the liquid body 1 (the upper sphere) keeps;
        body 2 (the lower sphere or the wall) keeps ``1 - f``.
    volume1, volume2
        V1, V2 (m^3): the liquid on body 1's and on body 2's side of the neck plane.
    volume
        The bridge volume V (m^3) the bridge was solved for.
    rupture_distance
        S_c (m): the gap of the critical bridge.
    neck_radius, neck_height
        Radius of the cut (m) and its height z_n (m; z = 0 is the wall or the apex of
        sphere 2, sphere 1's lowest point is at z = S_c).
    neck
        ``"interior"`` (a minimum of r(z) between the contact lines), ``"contact1"`` or
        ``"contact2"`` (the meridian is narrowest at a contact line: f = 0 or 1).
    end
        How the stable branch ends: ``"fold"`` or ``"bifurcation"``.
    """

    fraction: float
    volume1: float
    volume2: float
    volume: float
    rupture_distance: float
    neck_radius: float
    neck_height: float
    neck: str
    end: str


def transfer_fraction(bridge: Bridge, volume: float,
                      n_elements: int = DEFAULT_ELEMENTS) -> Division:
    r"""Division of the liquid at rupture: the critical bridge cut at its neck.

    .. math:: f = \frac{V_1}{V_1 + V_2},\qquad
              V_1 = \int_{z_n}^{z_{c1}} \pi r^2\, dz - V_{solid}(z > z_n)

    on the critical (fold) bridge of the volume-controlled branch, ``z_n`` the height where
    its meridian ``r(z)`` is smallest (module docstring: the model, its source and its
    limits; PHYSICS.md section 7).

    Parameters
    ----------
    bridge
        The solids and the receding contact angles; ``radius`` (body 1, the upper sphere)
        must be a sphere, ``radius2`` a sphere or ``None`` for a wall.
    volume
        Bridge volume V (m^3), > 0.
    n_elements
        Elements of the FE meridian (order 4: 64, 128, 256 are the model's presets).

    Returns
    -------
    Division
        ``fraction`` (on body 1), ``volume1``, ``volume2`` (m^3), the neck and the rupture
        distance.
    """
    if bridge.radius is None:
        raise InputError("meniscus: transfer_fraction needs a sphere as body 1 (radius), "
                         "the bridge's rupture is followed from contact")
    br, ell = _branch_for(bridge, volume, n_elements)
    return divide_branch(br, ell)


def divide_branch(br: _Branch, ell: float = 1.0) -> Division:
    """:func:`transfer_fraction` of a computed branch (lengths in units of ``ell``).

    At a fold the critical bridge is the branch's ``x_fold``. At a symmetry-breaking
    bifurcation the Jacobian is singular along the asymmetric mode, so the computed bridge
    there carries an undetermined asymmetric part (the Newton residual over the vanishing
    eigenvalue: 1e-7 in ``f`` at 128 elements); the division is then the limit along the
    stable branch, ``2 f(S_b (1 - delta)) - f(S_b (1 - 2 delta))``, ``delta`` =
    :data:`BIFURCATION_STEP` (exactly 1/2 for a symmetric pair, whatever ``delta``).
    """
    d, g = br.d, br.g
    if br.end != "bifurcation":
        return divide(d, g, br.x_fold, ell, br.end)
    s_b = br.S_fold
    near = []
    for k in (1, 2):
        nw = _on_branch(br, s_b * (1.0 - k * BIFURCATION_STEP))
        if not nw.converged:
            raise SolverError("meniscus: no stable bridge next to the symmetry-breaking "
                              "bifurcation for the division")
        near.append(divide(d, g, nw.x, ell, br.end))
    at = divide(d, g, br.x_fold, ell, br.end)
    v = at.volume
    f = min(max(2.0 * near[0].fraction - near[1].fraction, 0.0), 1.0)
    return replace(at, fraction=f, volume1=f * v, volume2=v - f * v)


def divide(d: _Disc, g: _Geo, x: np.ndarray, ell: float = 1.0, end: str = "fold"
           ) -> Division:
    """Cut the dimensionless bridge ``x`` at its neck (:func:`transfer_fraction`); lengths
    are returned times ``ell``."""
    r, z, psi = _fields(d, x)
    if np.any(np.sin(d.at_q(psi)) <= 0.0):
        raise SolverError("meniscus: the meridian of the critical bridge is not monotone in "
                          "z; its neck plane is not defined")
    L, c1, c2, S = (float(x[k]) for k in (d.iL, d.ic1, d.ic2, d.iS))
    k, u, r_n, z_n, where = _neck_cut(d, g, x)
    # revolution volume pi \int r^2 dz = pi L \int r^2 sin(psi) dt per element: the solver's
    # Gauss rule (its volume constraint) on whole elements, 8 points on the cut element
    rq, pq = d.at_q(r), d.at_q(psi)
    per_el = (math.pi * L * d.w * rq * rq * np.sin(pq)).reshape(d.n_el, -1).sum(axis=1)
    lo_part, hi_part = _split_element(d, r, psi, L, k, u)
    if lo_part + hi_part > 0.0:  # the cut element's share of the discrete volume
        lo_part, hi_part = (per_el[k] * p / (lo_part + hi_part) for p in (lo_part, hi_part))
    below = float(np.sum(per_el[:k])) + lo_part
    above = float(np.sum(per_el[k + 1:])) + hi_part
    # the solids inside the bridge, on each side of the cut: sphere 1's cap from its pole
    # (z = S) up to its contact line, sphere 2's from its pole (z = 0) down to its own
    sol_above = sol_below = 0.0
    if g.rt is not None:
        q, h = _cap_heights(g.rt, c1, z_n - S)
        sol_below += _cap_volume(g.rt, q)
        sol_above += _cap_volume(g.rt, h) - _cap_volume(g.rt, q)
    if g.rb is not None:
        q, h = _cap_heights(g.rb, c2, -z_n)
        sol_above += _cap_volume(g.rb, q)
        sol_below += _cap_volume(g.rb, h) - _cap_volume(g.rb, q)
    v1, v2 = above - sol_above, below - sol_below
    total = v1 + v2
    if not (total > 0.0 and min(v1, v2) >= -1e-12 * total):
        raise SolverError(f"meniscus: division of the critical bridge failed (V1 = {v1:.3g}, "
                          f"V2 = {v2:.3g})")
    v1, v2 = max(v1, 0.0), max(v2, 0.0)
    vol = float(above + below - g.cap(c1, g.rt)[0] - g.cap(c2, g.rb)[0])
    return Division(fraction=v1 / (v1 + v2), volume1=v1 * ell**3, volume2=v2 * ell**3,
                    volume=vol * ell**3, rupture_distance=S * ell, neck_radius=r_n * ell,
                    neck_height=z_n * ell, neck=where, end=end)


def _neck_cut(d: _Disc, g: _Geo, x: np.ndarray) -> tuple[int, float, float, float, str]:
    """(element, local coordinate u in [0, 1], r, z, where) of the smallest r on the
    meridian: the interior minima of the solver's quintic Hermite reconstruction
    (:func:`~wetcontact.solver.meniscus.post._quintic_min`, as in its ``_neck``) and the two
    contact lines."""
    r, z, psi = _fields(d, x)
    L, P = x[d.iL], x[d.iP]
    v = d.vertices
    rv, zv, pv = r[v], z[v], psi[v]
    pt = L * (P - g.bo * zv - np.sin(pv) / rv)
    rt, rtt = L * np.cos(pv), -L * np.sin(pv) * pt
    zt, ztt = L * np.sin(pv), L * np.cos(pv) * pt
    h = 1.0 / d.n_el
    best = min((float(rv[0]), 0, 0.0, float(zv[0]), "contact2"),
               (float(rv[-1]), d.n_el - 1, 1.0, float(zv[-1]), "contact1"))
    sgn = np.cos(pv)
    for i in np.flatnonzero(sgn[:-1] * sgn[1:] <= 0):
        coef, roots = _quintic_min(rv[i], rt[i], rtt[i], rv[i + 1], rt[i + 1], rtt[i + 1], h)
        curv = np.polynomial.polynomial.polyder(coef, 2)
        for uu in np.clip(roots, 0.0, 1.0):
            if np.polynomial.polynomial.polyval(uu, curv) <= 0:  # a maximum (a bulge)
                continue
            rn = float(np.polynomial.polynomial.polyval(uu, coef))
            if rn < best[0]:
                cz, _ = _quintic_min(zv[i], zt[i], ztt[i], zv[i + 1], zt[i + 1], ztt[i + 1], h)
                best = (rn, int(i), float(uu),
                        float(np.polynomial.polynomial.polyval(uu, cz)), "interior")
    rn, k, u, zn, where = best
    return k, u, rn, zn, where


def _split_element(d: _Disc, r: np.ndarray, psi: np.ndarray, L: float, k: int,
                   u: float) -> tuple[float, float]:
    """``pi L \\int r^2 sin(psi) dt`` over the parts ``[0, u]`` and ``[u, 1]`` of element
    ``k`` (P2 fields, 8-point Gauss-Legendre on each part)."""
    idx = (k, k + 1, d.n_el + 1 + k)  # its two vertices, then its midpoint (scikit-fem)
    h = 1.0 / d.n_el

    def part(a: float, b: float) -> float:
        if b <= a:
            return 0.0
        uu = a + (b - a) * _GL_U
        phi = np.stack([(1 - uu) * (1 - 2 * uu), uu * (2 * uu - 1), 4 * uu * (1 - uu)])
        rr = phi.T @ r[list(idx)]
        pp = phi.T @ psi[list(idx)]
        return math.pi * L * h * (b - a) * float(np.sum(_GL_W * rr * rr * np.sin(pp)))

    return part(0.0, u), part(u, 1.0)


def _cap_heights(R: float, c: float, depth: float) -> tuple[float, float]:
    """(q, h): the cap inside the bridge on a sphere of radius R with half-filling angle c
    has height ``h = R (1 - cos c) = 2 R sin^2(c/2)`` from the pole; the cut plane lies at
    ``depth`` from the pole into the sphere, clipped to [0, h]."""
    h = 2.0 * R * math.sin(0.5 * c) ** 2
    return min(max(depth, 0.0), h), h


def _cap_volume(R: float, h: float) -> float:
    r"""Volume of a spherical cap of height h: ``pi h^2 (3 R - h)/3`` (the solver's
    ``pi R^3 (1 - cos phi)^2 (2 + cos phi)/3`` with ``h = R (1 - cos phi)``, free of its
    cancellation at small phi)."""
    return math.pi * h * h * (3.0 * R - h) / 3.0
