r"""Post-processing of a converged bridge: forces, neck, areas, energy, profile.

Force (PHYSICS.md section 2, Lambert et al. 2008): the axial cut force
``G = 2 pi sigma r sin(psi) - pi r^2 (dp - rho g z)`` is a first integral (with gravity
``dG/dz = rho g pi r^2``), evaluated at the contact line on sphere 1, at the lower contact
line and at the neck (``psi = pi/2``, from a quintic Hermite reconstruction through the
order-4 vertex values); their relative spread is reported as a self-check. The free energy
is ``E = sigma (A - cos(theta1) A1 - cos(theta2) A2)``; ``dE/dS`` at fixed V follows by
implicit differentiation of the discrete system.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.solver.meniscus.geometry import Bridge, _Geo
from wetcontact.solver.meniscus.young_laplace import (
    Fixed,
    VolumeIs,
    _Disc,
    _disc,
    _fields,
    _newton,
    _volume,
)


@dataclass(frozen=True)
class BridgeSolution:
    """One static bridge (SI units, radians). ``exists = False`` means "no bridge".

    Attributes
    ----------
    exists
        True for a bridge; False beyond rupture or when none exists (forces 0, other
        quantities 0, ``message`` says why).
    gap, volume, laplace_pressure
        S (m), V (m^3), dp = p_liquid - p_gas (Pa; at z = 0 with gravity).
    force
        Axial force on sphere 1 (N), positive pushing the solids apart (attraction < 0).
    force_contact1, force_contact2, force_neck
        Attractive force (N, > 0 for attraction) evaluated at the contact line on sphere 1,
        at the lower contact line, and at the neck.
    force_spread
        (max - min)/|mean| of the three evaluations.
    neck_radius, filling_angle1, filling_angle2, wetted_radius
        y0 (m); half-filling angles on sphere 1 and 2 (rad, 0 if not a sphere); the
        wetted radius on a wall (m, 0 if not a wall).
    area, energy
        Liquid-gas area (m^2) and free energy E = sigma (A - cos th1 A1 - cos th2 A2) (J).
    stability
        +1 stable (branch from S = 0 before the fold), -1 unstable, 0 unknown.
    """

    exists: bool
    gap: float
    volume: float
    laplace_pressure: float = 0.0
    force: float = 0.0
    force_contact1: float = 0.0
    force_contact2: float = 0.0
    force_neck: float = 0.0
    force_spread: float = 0.0
    neck_radius: float = 0.0
    filling_angle1: float = 0.0
    filling_angle2: float = 0.0
    wetted_radius: float = 0.0
    area: float = 0.0
    energy: float = 0.0
    stability: float = 0.0
    iterations: int = 0
    message: str = ""
    state: Any = field(default=None, repr=False, compare=False)

    @property
    def suction(self) -> float:
        """u = -dp (Pa)."""
        return -self.laplace_pressure


@dataclass(frozen=True)
class _State:
    """Dimensionless converged solution with what is needed to post-process it."""

    x: np.ndarray
    n_el: int
    geo: _Geo
    ell: float
    sigma: float
    bridge: Bridge


def _quintic_min(y0, d0, dd0, y1, d1, dd1, h):
    """Minimiser (u in [0,1]) of the quintic Hermite interpolant on one element."""
    # coefficients in u of the quintic matching values, h-scaled first and second derivatives
    a0, a1, a2 = y0, d0 * h, 0.5 * dd0 * h * h
    A = np.array([[1, 1, 1], [3, 4, 5], [6, 12, 20]], dtype=float)
    rhs = np.array([y1 - a0 - a1 - a2, d1 * h - a1 - 2 * a2, dd1 * h * h - 2 * a2])
    a3, a4, a5 = np.linalg.solve(A, rhs)
    coef = np.array([a0, a1, a2, a3, a4, a5])
    der = np.polynomial.polynomial.polyder(coef)
    roots = np.polynomial.polynomial.polyroots(der)
    roots = roots[(np.abs(roots.imag) < 1e-9) & (roots.real >= -1e-9) & (roots.real <= 1 + 1e-9)]
    return coef, roots.real


def _neck(d: _Disc, g: _Geo, x: np.ndarray) -> tuple[float, float, bool]:
    """(neck radius, neck height, interior) from a quintic Hermite through vertex values."""
    r, z, psi = _fields(d, x)
    L, P = x[d.iL], x[d.iP]
    v = d.vertices  # vertex dofs ordered by t (scikit-fem numbers them first)
    rv, zv, pv = r[v], z[v], psi[v]
    pt = L * (P - g.bo * zv - np.sin(pv) / rv)
    rt_ = L * np.cos(pv)
    rtt = -L * np.sin(pv) * pt
    zt_ = L * np.sin(pv)
    ztt = L * np.cos(pv) * pt
    h = 1.0 / d.n_el
    best = (float(np.min(rv)), float(zv[np.argmin(rv)]), False)
    sgn = np.cos(pv)
    for i in np.flatnonzero(sgn[:-1] * sgn[1:] <= 0):
        coef, roots = _quintic_min(rv[i], rt_[i], rtt[i], rv[i + 1], rt_[i + 1], rtt[i + 1], h)
        for u in roots:
            rn = float(np.polynomial.polynomial.polyval(u, coef))
            if rn < best[0] or not best[2]:
                cz, _ = _quintic_min(zv[i], zt_[i], ztt[i], zv[i + 1], zt_[i + 1], ztt[i + 1], h)
                best = (rn, float(np.polynomial.polynomial.polyval(u, cz)), True)
    return best


def interface_terms(d: _Disc, x: np.ndarray) -> tuple[float, float]:
    r"""The 11 and 33 terms of ``\int n n dA`` over the liquid-gas interface (axis 3 along
    the line of centres), in the solver's length unit squared.

    With the meridian tangent ``(cos psi, sin psi)`` in ``(r, z)`` the normal is
    ``(sin psi, -cos psi)``, ``dA = 2 pi r ds``:
    ``nn11 = pi \int r sin^2(psi) ds``, ``nn33 = 2 pi \int r cos^2(psi) ds``, and
    ``2 nn11 + nn33`` is the area (Duriez & Wan 2017, Acta Geotech. 12; Yade's capillary
    files). Gauss quadrature of the P2 fields (order 4).
    """
    r, _, psi = _fields(d, x)
    rq, pq = d.at_q(r), d.at_q(psi)
    L = float(x[d.iL])
    s2 = np.sin(pq) ** 2
    nn11 = math.pi * L * float(np.sum(d.w * rq * s2))
    nn33 = 2 * math.pi * L * float(np.sum(d.w * rq * (1.0 - s2)))
    return nn11, nn33


def _post(st: _State, stability: float = 0.0, iterations: int = 0) -> BridgeSolution:
    d, g, x = _disc(st.n_el), st.geo, st.x
    ell, sig = st.ell, st.sigma
    L, P, c1, c2, S = x[d.iL], x[d.iP], x[d.ic1], x[d.ic2], x[d.iS]
    top, _ = g.top(c1, S)
    bot, _ = g.bottom(c2)

    def cut(p: np.ndarray) -> float:
        return 2 * math.pi * p[0] * math.sin(p[2]) - math.pi * p[0] ** 2 * (P - g.bo * p[1])

    cap1, cap2 = g.cap(c1, g.rt)[0], g.cap(c2, g.rb)[0]
    V = _volume(d, g, x)
    vrev = V + cap1 + cap2
    f1 = cut(top) - g.bo * cap1
    # with gravity G(top) = G(bottom) + Bo * Vrev: refer every evaluation to sphere 1
    f2 = cut(bot) + g.bo * (vrev - cap1)
    yn, zn, interior = _neck(d, g, x)
    evals = [f1, f2]
    fn = 2 * math.pi * yn - math.pi * yn**2 * (P - g.bo * zn)
    if interior and g.bo == 0.0:
        evals.append(fn)
    spread = (max(evals) - min(evals)) / max(abs(np.mean(evals)), 1e-300)
    r = x[:d.n]
    rq = d.Q0 @ r
    A = 2 * math.pi * L * float(np.sum(d.w * rq))
    A1, A2 = g.wetted(c1, g.rt)[0], g.wetted(c2, g.rb)[0]
    E = A - math.cos(g.tht) * A1 - math.cos(g.thb) * A2
    fs = sig * ell
    return BridgeSolution(
        exists=True, gap=S * ell, volume=V * ell**3, laplace_pressure=P * sig / ell,
        force=-f1 * fs, force_contact1=f1 * fs, force_contact2=f2 * fs,
        force_neck=(fn if interior else f1) * fs, force_spread=float(spread),
        neck_radius=yn * ell,
        filling_angle1=c1 if g.rt is not None else 0.0,
        filling_angle2=c2 if g.rb is not None else 0.0,
        wetted_radius=c2 * ell if g.rb is None else 0.0,
        area=A * ell**2, energy=E * sig * ell**2, stability=stability,
        iterations=iterations, state=st,
    )


def _no_bridge(gap: float, volume: float, why: str) -> BridgeSolution:
    return BridgeSolution(exists=False, gap=gap, volume=volume, message="no bridge: " + why)


def _gap_derivative(st: _State) -> tuple[_Disc, _Geo, np.ndarray, np.ndarray]:
    """``dx/dS`` of a solution at fixed volume by implicit differentiation of the discrete
    system, ``J dx/dS = e_S`` (J with the closings V fixed, S fixed); with d, g and x."""
    d, g, x = _disc(st.n_el), st.geo, st.x
    V = _volume(d, g, x)
    nw = _newton(d, g, x, (VolumeIs(V), Fixed(d.iS, float(x[d.iS]))))
    rhs = np.zeros(d.m)
    rhs[-1] = 1.0
    return d, g, x, nw.lu.solve(rhs)


def energy_derivative(sol: BridgeSolution) -> float:
    """dE/dS at fixed volume (N) by implicit differentiation of the discrete system.

    For an exact solution ``-dE/dS`` equals ``force`` (attraction < 0).
    """
    st = sol.state
    if st is None:
        raise InputError("meniscus: energy_derivative needs an existing bridge")
    d, g, x, dx = _gap_derivative(st)
    # gradient of E = A - cos th1 A1 - cos th2 A2
    L, c1, c2 = x[d.iL], x[d.ic1], x[d.ic2]
    rq = d.Q0 @ x[:d.n]
    gE = np.zeros(d.m)
    gE[:d.n] = d.Q0.T @ (2 * math.pi * L * d.w)
    gE[d.iL] = 2 * math.pi * float(np.sum(d.w * rq))
    gE[d.ic1] = -math.cos(g.tht) * g.wetted(c1, g.rt)[1]
    gE[d.ic2] = -math.cos(g.thb) * g.wetted(c2, g.rb)[1]
    return float(gE @ dx) * st.sigma * st.ell


def meniscus_profile(sol: BridgeSolution, n: int | None = None) -> dict[str, np.ndarray]:
    """The meridian curve of a bridge, for the Stokes solver's bridge domain.

    Returns a dict of arrays (SI): ``s`` arc length from the lower contact line, ``r``,
    ``z`` (z = 0 is the wall or the apex of sphere 2, sphere 1's lowest point is at
    z = gap), ``psi`` tangent angle (rad), plus scalars ``gap``, ``radius``, ``radius2``
    (0 for a wall), ``filling_angle1``, ``filling_angle2``, ``wetted_radius`` as 0-d arrays.
    With ``n`` the curve is resampled at ``n`` points uniform in s (P2 interpolation),
    otherwise the FE nodes are returned.
    """
    st = sol.state
    if not sol.exists or st is None:
        raise InputError(f"meniscus: no profile to export ({sol.message or 'no bridge'})")
    d, x, ell = _disc(st.n_el), st.x, st.ell
    L = x[d.iL]
    t, rr, zz, pp = _resample(d, x, n)
    b = st.bridge
    return {
        "s": t * L * ell, "r": rr * ell, "z": zz * ell, "psi": pp,
        "gap": np.asarray(sol.gap), "radius": np.asarray(b.radius or 0.0),
        "radius2": np.asarray(b.radius2 or 0.0),
        "filling_angle1": np.asarray(sol.filling_angle1),
        "filling_angle2": np.asarray(sol.filling_angle2),
        "wetted_radius": np.asarray(sol.wetted_radius),
    }


def _resample(d: Any, x: np.ndarray, n: int | None) -> tuple[np.ndarray, ...]:
    """(t, r, z, psi) of the P2 fields of ``x``: the FE nodes, or ``n`` points uniform in t."""
    r, z, psi = _fields(d, x)
    if n is None:
        o = d.sorted
        return d.t[o], r[o], z[o], psi[o]
    t = np.linspace(0.0, 1.0, int(n))
    e = np.minimum((t * d.n_el).astype(int), d.n_el - 1)
    u = t * d.n_el - e
    phi = np.stack([(1 - u) * (1 - 2 * u), u * (2 * u - 1), 4 * u * (1 - u)])
    idx = np.stack([e, e + 1, d.n_el + 1 + e])  # vertices, then midpoints (scikit-fem)
    return (t, *(np.sum(phi * f[idx], axis=0) for f in (r, z, psi)))


def shape_rate(sol: BridgeSolution, n: int | None = None) -> dict[str, np.ndarray]:
    """Rate of change of the meridian with the gap at fixed volume, ``dX/dS`` (dimensionless).

    By implicit differentiation of the discrete system (as :func:`energy_derivative`):
    ``J dx/dS = e_S``, J the Jacobian with the closing conditions V fixed and S fixed.
    Returns ``dr``, ``dz`` (d r/dS, d z/dS at fixed normalised arc length t, on the points of
    :func:`meniscus_profile` with the same ``n``) and ``t``. The normal velocity of the
    static family, ``n . dX/dS``, does not depend on the parametrisation; it grows like
    ``(S_c - S)^(-1/2)`` towards the rupture fold, where J becomes singular.
    """
    st = sol.state
    if not sol.exists or st is None:
        raise InputError("meniscus: shape_rate needs an existing bridge")
    d, _, _, dx = _gap_derivative(st)
    t, dr, dz, _ = _resample(d, dx, n)
    return {"t": t, "dr": dr, "dz": dz}
