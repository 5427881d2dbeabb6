r"""Every row of a Yade capillary file against an independent shooting solution.

Independent of :mod:`wetcontact.solver.meniscus` (nothing imported from it; the rows'
own values serve only as starting guesses and integration bounds). Units as in the files:
lengths over the large radius R2 (sphere 2, radius 1), the small sphere 1 of radius
``a = 1/r`` above it, suction ``u`` over ``sigma/R2``.

**Profile.** From the contact line on sphere 1 (half-filling angle delta1, centre of sphere 1
at the origin, contact point ``(a sin delta1, -a cos delta1)``, tangent angle
``psi = delta1 + theta``) the meridian of the liquid-gas interface runs downwards,
``dr/ds = -cos psi``, ``dz/ds = -sin psi``, ``dpsi/ds = u + sin(psi)/r`` (Young-Laplace,
PHYSICS.md section 2; the signs as in tests/solver/shooting.py). For ``u >= 0`` (every row of
a file) ``dpsi/ds > 0``, so psi is the independent variable:

    ds/dpsi = r / (u r + sin psi),
    d(r, z)/dpsi = -(cos psi, sin psi) ds/dpsi,
    dv/dpsi = pi r^2 sin psi ds/dpsi,                       (volume of revolution)
    d(nn11)/dpsi = pi r sin^2(psi) ds/dpsi,  d(nn33)/dpsi = 2 pi r cos^2(psi) ds/dpsi,

(the normal is ``(sin psi, -cos psi)``: ``nn11 = pi \int r n_r^2 ds``,
``nn33 = 2 pi \int r n_z^2 ds``, Duriez & Wan 2017). The profile meets sphere 2 (centre on the
axis, radius 1) with contact angle theta where ``psi = pi - theta - asin(r)``, whatever the
position of sphere 2: the event fixes delta2 = asin(r), the centre of sphere 2 at
``z - cos(delta2)`` and so the gap ``D = -a - z + cos(delta2) - 1``. The volume is
``v - cap(delta1, a) - cap(delta2, 1)``, the force (attraction, over ``2 pi sigma R2``)
``F* = a sin(delta1) sin(delta1 + theta) + u (a sin delta1)^2 / 2``, which the exact profile
carries unchanged to every cross-section (``r sin(psi) + u r^2/2``: checked at sphere 2 as
the integration's self-check).

**Solve at the row's (D*, u*).** The gap as a function of delta1 at fixed u is one
initial-value problem per value; the secant iteration on ``D(delta1) = D*`` from the row's
delta1 gives the exact bridge at the row's grid point, and its delta1, delta2, V*, F*, nn11*,
nn33* are compared with the row's. The suction is checked at the row's (D*, V*) (the
volume-controlled reading of a row): ``u(D*, V*) = u* + (V* - V(D*, u*)) / (dV/du)_D``
with the derivative from a second exact solve at ``u* (1 + 1e-6)`` (linearisation error
of order (1e-6)^2).

**Integrator.** The 12-stage 8th-order Runge-Kutta tableau of Dormand & Prince (DOP853, the
coefficients scipy ships), fixed steps in psi, vectorised over all rows; the event by Newton
on the last step's length. Its own error is measured by halving the step (``steps``
against ``2 steps``) and reported beside the row errors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate._ivp.dop853_coefficients import N_STAGES, A, B, C

_A, _B, _C = A[:N_STAGES, :N_STAGES], B, C[:N_STAGES]

QUANTITIES = ("F*", "V*", "u*", "delta1", "delta2", "nn11*", "nn33*")
U_FLOOR = 0.002   # u* floor of the suction's relative error: the first positive grid suction


def _rhs(psi, y, u):
    r = y[0]
    sp, cp = np.sin(psi), np.cos(psi)
    ds = r / (u * r + sp)
    return np.stack([-cp * ds, -sp * ds, math.pi * r * r * sp * ds,
                     math.pi * r * sp * sp * ds, 2.0 * math.pi * r * cp * cp * ds])


def _step(psi, y, h, u):
    """One DOP853 step (8th order) of size h (arrays: one per row)."""
    k = [_rhs(psi, y, u)]
    for s in range(1, N_STAGES):
        dy = sum(_A[s, j] * k[j] for j in range(s) if _A[s, j] != 0.0)
        k.append(_rhs(psi + _C[s] * h, y + h * dy, u))
    return y + h * sum(_B[j] * k[j] for j in range(N_STAGES) if _B[j] != 0.0)


def _event(psi, y, theta):
    return psi + np.arcsin(np.minimum(y[0], 1.0)) + theta - math.pi


def _cap(phi, R):
    c = np.cos(phi)
    return math.pi * R**3 * (1 - c) ** 2 * (2 + c) / 3.0


@dataclass(frozen=True)
class Shot:
    """Exact bridges (arrays over rows) from given (u*, delta1): the gap and the rest."""

    D: np.ndarray
    delta1: np.ndarray
    delta2: np.ndarray
    V: np.ndarray
    F: np.ndarray
    F_end: np.ndarray       # the force through the cross-section at sphere 2
    nn11: np.ndarray
    nn33: np.ndarray
    hit: np.ndarray         # the event was found inside the integration range


def shoot(a: float, theta: float, u: np.ndarray, delta1: np.ndarray, psi_end: np.ndarray,
          steps: int = 200) -> Shot:
    """Integrate the profile from the contact line on sphere 1 to the contact on sphere 2.

    ``psi_end`` must lie beyond the contact on sphere 2 (``pi - theta - delta2``) and below
    ``pi - theta`` (where the zero-suction profile turns vertical and ds/dpsi diverges).
    """
    u = np.asarray(u, float)
    d1 = np.asarray(delta1, float)
    psi0 = d1 + theta
    h = (np.asarray(psi_end, float) - psi0) / steps
    y = np.stack([a * np.sin(d1), -a * np.cos(d1), np.zeros_like(d1), np.zeros_like(d1),
                  np.zeros_like(d1)])
    psi = psi0.copy()
    g = _event(psi, y, theta)
    y_k, psi_k = y.copy(), psi.copy()          # last node before the event
    found = g >= 0.0                           # (never at the start: g0 < 0)
    for _ in range(steps):
        y_new = _step(psi, y, h, u)
        psi_new = psi + h
        g_new = _event(psi_new, y_new, theta)
        cross = (~found) & (g_new >= 0.0)
        y_k[:, cross], psi_k[cross] = y[:, cross], psi[cross]
        found |= cross
        y_k[:, ~found], psi_k[~found] = y_new[:, ~found], psi_new[~found]
        y, psi = y_new, psi_new
        if found.all():
            break
    # Newton on the length of the last step: g(psi_k + t) = 0, g' = 1 + r'/sqrt(1 - r^2)
    t = np.zeros_like(psi)
    for _ in range(30):
        ye = _step(psi_k, y_k, t, u)
        ge = _event(psi_k + t, ye, theta)
        dr = _rhs(psi_k + t, ye, u)[0]
        dg = 1.0 + dr / np.sqrt(np.maximum(1.0 - ye[0] ** 2, 1e-300))
        dt = -ge / dg
        t = np.clip(t + dt, 0.0, h)
        if np.all(np.abs(dt) <= 1e-16 * np.maximum(1.0, np.abs(psi_k))):
            break
    ye = _step(psi_k, y_k, t, u)
    psi_e = psi_k + t
    r, z, v, n11, n33 = ye
    d2 = np.arcsin(np.minimum(r, 1.0))
    D = -a - z + np.cos(d2) - 1.0
    rho1 = a * np.sin(d1)
    return Shot(D=D, delta1=d1, delta2=d2, V=v - _cap(d1, a) - _cap(d2, 1.0),
                F=rho1 * np.sin(d1 + theta) + 0.5 * u * rho1**2,
                F_end=r * np.sin(psi_e) + 0.5 * u * r * r, nn11=n11, nn33=n33,
                hit=found & (np.abs(_event(psi_e, ye, theta)) < 1e-10))


def solve_at(a: float, theta: float, D: np.ndarray, u: np.ndarray, delta1: np.ndarray,
             delta2: np.ndarray, steps: int = 200, maxit: int = 40) -> tuple[Shot, np.ndarray]:
    """Exact bridges at the gaps D and suctions u: secant on D(delta1) = D from the given
    delta1. Returns the shot and a mask of the rows where it converged
    (|D(delta1) - D| <= 1e-13 and the last delta1 step <= 1e-13 rad)."""
    D = np.asarray(D, float)
    u = np.asarray(u, float)
    psi_end = math.pi - theta - 0.5 * np.asarray(delta2, float)
    x0 = np.asarray(delta1, float).copy()
    x1 = x0 * (1.0 + 1e-7)
    f0 = shoot(a, theta, u, x0, psi_end, steps).D - D
    ok = np.zeros(x0.shape, bool)
    act = np.arange(x0.size)                   # rows still iterating
    for _ in range(maxit):
        s1 = shoot(a, theta, u[act], x1[act], psi_end[act], steps)
        f1 = s1.D - D[act]
        a0, a1, g0 = x0[act], x1[act], f0[act]
        den = np.where(f1 != g0, f1 - g0, 1.0)
        x2 = np.where(f1 != g0, a1 - f1 * (a1 - a0) / den, a1)
        x2 = np.clip(x2, 0.5 * a1, np.minimum(1.5 * a1, 0.5 * math.pi))
        done = (np.abs(f1) <= 1e-13) & (np.abs(x2 - a1) <= 1e-13) & s1.hit
        x0[act], f0[act], x1[act] = a1, f1, x2
        ok[act[done]] = True
        act = act[~done]
        if act.size == 0:
            break
    sol = shoot(a, theta, u, x1, psi_end, steps)
    ok = ok & sol.hit & (np.abs(sol.D - D) <= 1e-12)
    return sol, ok


def check_rows(ratio: float, theta: float, rows: np.ndarray, steps: int = 200) -> dict:
    """Relative errors of every row against the exact bridge at its (D*, u*).

    ``rows``: (n, 8) file rows (D*, u*, V*, F*, delta1 deg, delta2 deg, nn11*, nn33*).
    Returns arrays (one per row) ``err`` (dict over :data:`QUANTITIES`: relative errors;
    the suction's over ``max(u*, U_FLOOR)``), ``converged``, ``d_residual`` (the gap error of
    the row's own (u*, delta1): D(delta1) - D*), ``self_check`` (relative force difference
    between the two ends of the exact profile) and ``step_check`` (max relative change of
    any quantity when the integration step is halved).
    """
    rows = np.asarray(rows, float)
    a = 1.0 / ratio
    D, u, V, F = rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3]
    d1, d2 = np.radians(rows[:, 4]), np.radians(rows[:, 5])
    nn11, nn33 = rows[:, 6], rows[:, 7]
    own = shoot(a, theta, u, d1, math.pi - theta - 0.5 * d2, steps)
    sol, ok = solve_at(a, theta, D, u, d1, d2, steps)
    fine, ok_f = solve_at(a, theta, D, u, sol.delta1, sol.delta2, 2 * steps)
    du = 1e-6 * np.maximum(u, U_FLOOR)
    up, ok_u = solve_at(a, theta, D, u + du, sol.delta1, sol.delta2, steps)
    dVdu = (up.V - sol.V) / du
    u_vol = u + (V - sol.V) / dVdu
    err = {"F*": np.abs(F / sol.F - 1), "V*": np.abs(V / sol.V - 1),
           "u*": np.abs(u_vol - u) / np.maximum(u, U_FLOOR),
           "delta1": np.abs(d1 / sol.delta1 - 1), "delta2": np.abs(d2 / sol.delta2 - 1),
           "nn11*": np.abs(nn11 / sol.nn11 - 1), "nn33*": np.abs(nn33 / sol.nn33 - 1)}
    step_check = np.max(np.abs(np.stack([
        fine.F / sol.F - 1, fine.V / sol.V - 1, fine.delta1 / sol.delta1 - 1,
        fine.delta2 / sol.delta2 - 1, fine.nn11 / sol.nn11 - 1, fine.nn33 / sol.nn33 - 1])),
        axis=0)
    return {"err": err, "converged": ok & ok_f & ok_u, "d_residual": own.D - D,
            "self_check": np.abs(sol.F_end / sol.F - 1), "step_check": step_check,
            "dD_ddelta1": _slope(a, theta, u, sol, steps)}


def _slope(a, theta, u, sol: Shot, steps: int) -> np.ndarray:
    """dD/d(delta1) at fixed u* on the exact bridge (its sign tells the branch: the stable,
    large-volume side of the fold has dD/d(delta1) < 0)."""
    h = 1e-6 * sol.delta1
    psi_end = math.pi - theta - 0.5 * sol.delta2
    return (shoot(a, theta, u, sol.delta1 + h, psi_end, steps).D - sol.D) / h
