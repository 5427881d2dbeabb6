"""Many impacts of one geometry at once: restitution maps over St, vectorised.

For the impulse contact, without far-field or tangential terms and with a static rupture,
the time drops out of the normal motion. With the gap x as the variable, ``u = ln x``,
the approach speed v obeys

    m dv/du = x (f1(x) + F_c(x) / v)        (approach, u falling from ln x0 to ln x_r)
    m dw/du = x (-f1(x) + F_c(x) / w)       (rebound, w = -v, u rising to ln S_c)

with the same force tables as :func:`wetcontact.collide.collide`. Impacts that differ only
in speed and mass share the tables and one grid in u, so the classical fourth-order
Runge-Kutta scheme (declared order :data:`ORDER`, checked in the tests) advances all of them
with array arithmetic; the forces at the grid's nodes and midpoints are evaluated once.
An approach whose speed falls to zero sticks (arrested); a rebound whose speed falls to
zero before the rupture distance (and the start gap) sticks (captured).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wetcontact.collide.case import CollisionCase
from wetcontact.collide.equations import _Impact, _Mode
from wetcontact.errors import InputError

#: declared order of the gap-stepping scheme (classical Runge-Kutta)
ORDER = 4
#: default steps in ln x per leg
STEPS = 128


@dataclass(frozen=True)
class BatchResult:
    """Restitution of many impacts.

    Attributes
    ----------
    velocity, mass
        Each impact's approach speed (m/s) and effective mass (kg).
    stokes_number
        ``m v / (6 pi eta R*^2)`` with the particles' mass.
    restitution
        ``e = -v_R/v0`` at the start gap; 0 for a stick.
    contact_velocity
        Speed at the roughness gap (0: arrested before contact).
    stick
        True where the sphere sticks.
    models
        The force models used.
    """

    velocity: np.ndarray
    mass: np.ndarray
    stokes_number: np.ndarray
    restitution: np.ndarray
    contact_velocity: np.ndarray
    stick: np.ndarray
    models: dict[str, str | None]


class _Leg:
    """One leg in u with its forces at the RK4 nodes and midpoints."""

    def __init__(self, imp: _Impact, x0: float, x1: float, n: int, mode: _Mode,
                 sign: float) -> None:
        u0, u1 = math.log(x0), math.log(x1)
        self.h = (u1 - u0) / n
        x = np.exp(u0 + self.h * 0.5 * np.arange(2 * n + 1))
        # the ends exactly as given: exp(log(x)) may round past a reach or the roughness
        # gap, where a force switches off
        x = np.clip(x, min(x0, x1), max(x0, x1))
        x[0], x[-1] = x0, x1
        self.n = n
        # f1 is the viscous force per unit speed; the sign of the speed matters only for
        # cavitation (no viscous force while the gap opens)
        v_probe = 1.0 if sign > 0 else -1.0
        self.xf1 = x * np.array([imp.viscous_unit(xi, v_probe, mode) for xi in x])
        self.xfc = x * np.array([imp.capillary(xi, v_probe, mode) for xi in x])

    def run(self, v: np.ndarray, m: np.ndarray, sign: float) -> np.ndarray:
        """Advance the speeds ``v`` (>= 0) across the leg; 0 marks an arrest. One impact
        runs on Python floats (a thirtieth of the cost of one-element arrays)."""
        if v.size == 1:
            return np.array([self._run_one(float(v.reshape(-1)[0]),
                                           float(m.reshape(-1)[0]), sign)]).reshape(v.shape)
        h, a, c = self.h, self.xf1, self.xfc
        v = np.where(v > 0.0, v, 0.0)
        inv_m = 1.0 / m

        def rate(k: int, vv: np.ndarray) -> np.ndarray:
            safe = np.where(vv > 0.0, vv, np.inf)
            return inv_m * (sign * a[k] + c[k] / safe)

        for i in range(self.n):
            k = 2 * i
            k1 = rate(k, v)
            k2 = rate(k + 1, v + 0.5 * h * k1)
            k3 = rate(k + 1, v + 0.5 * h * k2)
            k4 = rate(k + 2, v + h * k3)
            v = v + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            v = np.where(v > 0.0, v, 0.0)
        return v

    def _run_one(self, v: float, m: float, sign: float) -> float:
        """:meth:`run` for one impact, the same scheme on floats."""
        h, inv_m = self.h, 1.0 / m
        a = (sign * self.xf1).tolist()
        c = self.xfc.tolist()
        for i in range(self.n):
            if v <= 0.0:
                return 0.0
            k = 2 * i
            k1 = inv_m * (a[k] + c[k] / v)
            vv = v + 0.5 * h * k1
            k2 = inv_m * (a[k + 1] + (c[k + 1] / vv if vv > 0.0 else 0.0))
            vv = v + 0.5 * h * k2
            k3 = inv_m * (a[k + 1] + (c[k + 1] / vv if vv > 0.0 else 0.0))
            vv = v + h * k3
            k4 = inv_m * (a[k + 2] + (c[k + 2] / vv if vv > 0.0 else 0.0))
            v = v + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        return max(v, 0.0)


#: the force tables at the legs' nodes, per geometry (a map varies only speed and mass)
_SETUPS: dict[tuple, tuple[_Impact, dict[tuple, _Leg]]] = {}
SETUP_CACHE = 64


def _setup(case: CollisionCase, viscous: str | None, capillary: str | None
           ) -> tuple[_Impact, dict[tuple, _Leg]]:
    from dataclasses import replace

    key = (case.with_(velocity=1.0, solid=replace(case.solid, density=1.0),
                      solid2=replace(case.solid2, density=1.0)), viscous, capillary)
    if key not in _SETUPS:
        if len(_SETUPS) >= SETUP_CACHE:
            _SETUPS.pop(next(iter(_SETUPS)))
        _SETUPS[key] = (_Impact(case, viscous, capillary, 1e-10), {})
    return _SETUPS[key]


def _leg(legs: dict[tuple, _Leg], imp: _Impact, x0: float, x1: float, n: int, mode: _Mode,
         sign: float) -> _Leg:
    key = (x0, x1, n, mode.name, sign)
    if key not in legs:
        legs[key] = _Leg(imp, x0, x1, n, mode, sign)
    return legs[key]


def restitution_map(case: CollisionCase, velocity: np.ndarray | float | None = None,
                    density: np.ndarray | float | None = None, viscous: str | None = None,
                    capillary: str | None = None, steps: int = STEPS) -> BatchResult:
    """Restitution of impacts that differ only in speed and particle density.

    Parameters
    ----------
    case
        The geometry, liquid, contact and phases (``contact.model = "impulse"``, static
        rupture, no gravity, buoyancy, added mass, drag or tangential motion).
    velocity, density
        Approach speeds (m/s) and particle densities (kg/m^3), broadcast together; the
        case's where None.
    viscous, capillary
        Force models as in :func:`wetcontact.collide.collide`.
    steps
        RK4 steps in ln x per leg (error O(steps^-4)).

    Returns
    -------
    BatchResult

    Raises
    ------
    InputError
        A case the batch does not model (it names :func:`~wetcontact.collide.collide`).
    """
    imp_t = case.impact
    extra = [k for k in ("gravity", "buoyancy", "added_mass", "drag") if getattr(imp_t, k)]
    if (case.contact_model != "impulse" or case.rupture != "static" or extra
            or imp_t.tangential_velocity or imp_t.spin):
        raise InputError("restitution_map: impulse contact, static rupture, no far-field or "
                         "tangential terms only; use wetcontact.collide.collide for "
                         + (", ".join(extra) or f"contact.model = {case.contact_model!r}, "
                            f"rupture = {case.rupture!r} or an oblique impact"))
    if not isinstance(steps, int) or steps < 8:
        raise InputError(f"restitution_map: steps = {steps!r}; allowed: an integer >= 8")
    imp, legs = _setup(case, viscous, capillary)
    v0 = np.asarray(imp_t.velocity if velocity is None else velocity, dtype=float)
    rho = np.asarray(case.solid.density if density is None else density, dtype=float)
    v0, rho = np.broadcast_arrays(v0, rho)
    if np.any(~np.isfinite(v0) | (v0 <= 0)) or np.any(~np.isfinite(rho) | (rho <= 0)):
        raise InputError("restitution_map: velocity and density must be finite and > 0")
    sc = case.scene
    vol1 = 4.0 / 3.0 * math.pi * sc.radius ** 3
    m1 = rho * vol1
    if sc.kind == "sphere-wall":
        mass = m1
    else:
        m2 = case.solid2.density * 4.0 / 3.0 * math.pi * float(sc.radius2) ** 3
        mass = m1 * m2 / (m1 + m2)
    x0, x_r = imp.x0, imp.x_r
    # approach: free flight down to the liquid, then the liquid down to contact
    top = min(x0, imp.h_app)
    v = v0.copy()
    if top > x_r:
        v = _leg(legs, imp, top, x_r, steps, _Mode("penetration"), 1.0).run(v, mass, 1.0)
    v_contact = v.copy()
    w = imp.e_dry * v
    # rebound: to the start gap (where e is read) and on to the rupture distance
    end = imp.s_static if sc.amount != "immersed" else x0
    mode = _Mode("bridge", after_contact=True)
    w_start = w
    x_prev = x_r
    span = math.log(end / x_r)
    for lev in sorted({min(x0, end), end}):
        if lev > x_prev:
            n = max(8, round(steps * math.log(lev / x_prev) / span))
            w = _leg(legs, imp, x_prev, lev, n, mode, -1.0).run(w, mass, -1.0)
            x_prev = lev
        if lev == min(x0, end):
            w_start = w.copy()
    stick = (v_contact <= 0.0) | (w <= 0.0) | (w_start <= 0.0)
    e = np.where(stick, 0.0, w_start / v0)
    st = mass * v0 / (6.0 * math.pi * sc.viscosity * imp.r_star ** 2)
    return BatchResult(v0, mass, st, e, v_contact, stick,
                       {"viscous": imp.models.get("viscous"),
                        "capillary": imp.models.get("capillary")})
