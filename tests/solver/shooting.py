"""Independent ODE-shooting solution of the axisymmetric liquid bridge (test reference).

Written separately from ``wetcontact.solver.meniscus`` (nothing imported from it). Units:
lengths over the radius R1 of the upper sphere (centre at z = S + 1), pressures over
sigma/R1, forces over sigma R1. The lower solid is a wall (z = 0) or a sphere of radius R2
with centre (0, -R2).

From the contact line on the upper sphere (half-filling angle phi1, tangent angle
psi = phi1 + theta1) integrate downwards in arc length sigma

    dr/dsigma = -cos psi,  dz/dsigma = -sin psi,  dpsi/dsigma = -(P - sin(psi)/r),
    dv/dsigma = pi r^2 sin psi   (v: volume of revolution between the two contact heights)

with scipy's DOP853 until the tangent angle meets the contact condition of the lower solid
(wall: psi = pi - theta2; sphere: psi = pi - phi2(r, z) - theta2): an event transversal to
the curve even for zero contact angle, where the curve is tangent to the solid. The miss
distance from the lower solid (or, for contact angles >= 20 deg, where the curve crosses the
solid transversally and the integration stops on it, the angle error) and the volume error
are driven to zero by a root find on (phi1, P).
The attractive force is 2 pi sin(phi1) sin(phi1 + theta1) - pi sin^2(phi1) P.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar, root


@dataclass(frozen=True)
class Shot:
    phi1: float
    pressure: float
    force: float
    gap: float
    end_r: float
    end_z: float
    residual: float


def _cap(phi: float, R: float) -> float:
    c = math.cos(phi)
    return math.pi * R**3 * (1 - c) ** 2 * (2 + c) / 3.0


def _integrate(phi1: float, P: float, S: float, th1: float, th2: float, R2: float | None,
               necks: bool = False):
    """(miss, V, r, z) at the lower solid; with ``necks`` also the states ``(r, z, v)``
    where r has an interior minimum (psi rising through pi/2 on the way down)."""
    r0, z0 = math.sin(phi1), S + 1 - math.cos(phi1)
    psi0 = phi1 + th1

    def rhs(_s, y):
        r, _z, psi, _v = y
        return [-math.cos(psi), -math.sin(psi), -(P - math.sin(psi) / r),
                math.pi * r * r * math.sin(psi)]

    # contact angles >= 20 deg: the curve crosses the solid transversally, so stop on the
    # solid and drive the angle error to zero (robust for profiles with an inflection);
    # small angles: stop on the angle (the curve is nearly tangent to the solid there).
    by_position = th2 >= math.radians(20.0)
    if R2 is None:
        def hit(_s, y):
            return y[1] if by_position else y[2] - (math.pi - th2)
    else:
        def hit(_s, y):
            if by_position:
                return math.hypot(y[0], y[1] + R2) - R2
            return y[2] - (math.pi - math.atan2(y[0], y[1] + R2) - th2)
    hit.terminal = True

    def axis(_s, y):
        return y[0] - 1e-9
    axis.terminal = True
    def neck(_s, y):
        return y[2] - 0.5 * math.pi
    neck.direction = 1.0
    length = 20.0 * (abs(r0) + abs(z0) + 1.0)
    sol = solve_ivp(rhs, (0.0, length), [r0, z0, psi0, 0.0], method="DOP853", rtol=1e-13,
                    atol=1e-15, events=(hit, axis, neck) if necks else (hit, axis))
    if sol.t_events[0].size == 0:
        return None
    r, z, psi, v = sol.y_events[0][0]
    if R2 is None:
        miss = psi - (math.pi - th2) if by_position else z
        cap2 = 0.0
    else:
        phi2 = math.atan2(r, z + R2)
        miss = (psi - (math.pi - phi2 - th2) if by_position
                else math.hypot(r, z + R2) - R2)
        cap2 = _cap(phi2, R2)
    V = v - _cap(phi1, 1.0) - cap2
    if necks:
        found = [(y[0], y[1], y[3]) for y in sol.y_events[2]]
        return miss, V, r, z, (v, found)
    return miss, V, r, z


def force_of(phi1: float, P: float, th1: float) -> float:
    """Attractive force over sigma R1 at the contact line on sphere 1 (PHYSICS.md)."""
    return (2 * math.pi * math.sin(phi1) * math.sin(phi1 + th1)
            - math.pi * math.sin(phi1) ** 2 * P)


def shoot_volume(V: float, S: float, th1: float, th2: float, R2: float | None,
                 guess: tuple[float, float]) -> Shot:
    """Bridge of volume V at gap S: root of (miss, volume error) in (phi1, P)."""
    def fun(u):
        out = _integrate(u[0], u[1], S, th1, th2, R2)
        if out is None:
            return [1.0, 1.0]
        return [out[0], (out[1] - V) / V]

    sol = root(fun, np.array(guess, dtype=float), method="hybr", tol=1e-14)
    phi1, P = sol.x
    res = float(np.max(np.abs(fun(sol.x))))
    out = _integrate(phi1, P, S, th1, th2, R2)
    return Shot(phi1, P, force_of(phi1, P, th1), S, out[2], out[3], res)


def shoot_phi(V: float, phi1: float, th1: float, th2: float, R2: float | None,
              guess: tuple[float, float]) -> Shot:
    """Bridge of volume V with half-filling angle phi1: root in (S, P)."""
    def fun(u):
        out = _integrate(phi1, u[1], u[0], th1, th2, R2)
        if out is None:
            return [1.0, 1.0]
        return [out[0], (out[1] - V) / V]

    sol = root(fun, np.array(guess, dtype=float), method="hybr", tol=1e-14)
    S, P = sol.x
    res = float(np.max(np.abs(fun(sol.x))))
    return Shot(phi1, P, force_of(phi1, P, th1), S, 0.0, 0.0, res)


def shoot_rupture(V: float, th1: float, th2: float, R2: float | None,
                  phi_bracket: tuple[float, float], guess: tuple[float, float]) -> Shot:
    """Turning point: the largest gap S(phi1) over phi1 in ``phi_bracket``."""
    state = {"g": guess}

    def neg_gap(phi):
        shot = shoot_phi(V, phi, th1, th2, R2, state["g"])
        if shot.residual > 1e-9:
            return 1.0
        state["g"] = (shot.gap, shot.pressure)
        return -shot.gap

    res = minimize_scalar(neg_gap, bounds=phi_bracket, method="bounded",
                          options={"xatol": 1e-9})
    return shoot_phi(V, float(res.x), th1, th2, R2, state["g"])


# ---- division of the liquid at rupture ------------------------------------------------


@dataclass(frozen=True)
class Split:
    """The critical bridge cut at its neck: V1 on sphere 1 (above), V2 on the lower solid."""

    phi1: float
    pressure: float
    gap: float
    volume1: float
    volume2: float
    neck_r: float
    neck_z: float
    neck: str          # "interior", "contact1" or "contact2"
    residual: float

    @property
    def fraction(self) -> float:
        return self.volume1 / (self.volume1 + self.volume2)


def _slab_sphere1(S: float, a: float, b: float) -> float:
    """Volume of sphere 1 (R = 1, pole at z = S) between the heights a < b: with the height
    above the pole y, the cross-section is pi (2 y - y^2)."""
    ya, yb = max(a - S, 0.0), max(b - S, 0.0)
    return math.pi * (yb * yb - ya * ya - (yb**3 - ya**3) / 3.0)


def _slab_sphere2(R2: float, a: float, b: float) -> float:
    """Volume of sphere 2 (pole at z = 0, below it) between the heights a < b: with the depth
    below the pole w, the cross-section is pi (2 R2 w - w^2)."""
    wa, wb = max(-b, 0.0), max(-a, 0.0)
    return math.pi * (R2 * (wb * wb - wa * wa) - (wb**3 - wa**3) / 3.0)


def split_at_neck(V: float, phi1: float, P: float, S: float, th1: float, th2: float,
                  R2: float | None, residual: float = 0.0) -> Split:
    """Integrate the bridge (phi1, P, S) from sphere 1 down to the lower solid and cut it at
    the plane of the smallest r: an interior minimum (an event of the integration) or a
    contact line. Each side keeps the revolution volume between its contact line and the
    plane minus the solid inside that slab."""
    miss, vol, r_end, z_end, (v_total, found) = _integrate(phi1, P, S, th1, th2, R2,
                                                           necks=True)
    z_top = S + 1 - math.cos(phi1)
    cands = [(math.sin(phi1), z_top, 0.0, "contact1"), (r_end, z_end, v_total, "contact2")]
    cands += [(r, z, v, "interior") for r, z, v in found]
    r_n, z_n, v_above, where = min(cands, key=lambda c: c[0])
    solid_above = _slab_sphere1(S, max(z_n, S), z_top)
    solid_below = _slab_sphere1(S, S, max(z_n, S))
    if R2 is not None:
        solid_above += _slab_sphere2(R2, max(z_n, z_end), 0.0)
        solid_below += _slab_sphere2(R2, z_end, min(z_n, 0.0))
    v1 = v_above - solid_above
    v2 = (v_total - v_above) - solid_below
    return Split(phi1, P, S, v1, v2, r_n, z_n, where, max(residual, abs(miss),
                                                          abs(vol - V) / V))


def shoot_pressure(V: float, P: float, th1: float, th2: float, R2: float | None,
                   guess: tuple[float, float]) -> Shot:
    """Bridge of volume V at pressure P: root of (miss, volume error) in (phi1, S)."""
    def fun(u):
        out = _integrate(u[0], P, u[1], th1, th2, R2)
        if out is None:
            return [1.0, 1.0]
        return [out[0], (out[1] - V) / V]

    sol = root(fun, np.array(guess, dtype=float), method="hybr", tol=1e-14)
    phi1, S = sol.x
    res = float(np.max(np.abs(fun(sol.x))))
    return Shot(phi1, P, force_of(phi1, P, th1), S, 0.0, 0.0, res)


def shoot_fold(V: float, th1: float, th2: float, R2: float | None,
               p_bracket: tuple[float, float], guess: tuple[float, float],
               step: float = 1e-4) -> Shot:
    """Turning point of the family S(P) at fixed V, parametrised by the pressure (regular
    through the fold, where phi1 can turn back close by: zero angle on a wall): the gap is
    largest where dS/dP = 0, the derivative by the fourth-order central difference of step
    ``step`` times the bracket's scale (error ~1e-12: the gap of one shot is exact to
    ~1e-14) and its root found by brentq to 1e-13. ``guess`` is (phi1, S)."""
    state = {"g": guess}
    h = step * max(abs(p_bracket[0]), abs(p_bracket[1]), 1.0)

    def gap(P: float) -> float:
        shot = shoot_pressure(V, P, th1, th2, R2, state["g"])
        if shot.residual > 1e-10:
            raise RuntimeError(f"shooting failed at P = {P!r} ({shot.residual:.2g})")
        state["g"] = (shot.phi1, shot.gap)
        return shot.gap

    def slope(P: float) -> float:
        return (8 * (gap(P + h) - gap(P - h)) - (gap(P + 2 * h) - gap(P - 2 * h))) / (12 * h)

    P = brentq(slope, *p_bracket, xtol=1e-13, rtol=1e-13)
    gap(P)
    return shoot_pressure(V, P, th1, th2, R2, state["g"])


def fold_split(V: float, th1: float, th2: float, R2: float | None,
               p_bracket: tuple[float, float], guess: tuple[float, float]) -> Split:
    """The division of the liquid at rupture: the fold bridge cut at its neck (the fold by
    :func:`shoot_fold`, ``p_bracket`` around its pressure, ``guess`` = (phi1, S))."""
    shot = shoot_fold(V, th1, th2, R2, p_bracket, guess)
    return split_at_neck(V, shot.phi1, shot.pressure, shot.gap, th1, th2, R2, shot.residual)
