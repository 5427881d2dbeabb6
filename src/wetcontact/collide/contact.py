"""Solid contact laws: impulse, damped Hertz and Thornton's elastic-plastic contact.

``impulse`` (the seed model, eqs. 1.4-1.6): at the roughness gap x_r the normal velocity
reverses and shrinks by e_dry in no time; the work of the contact is
``m* v_c^2 (1 - e_dry^2) / 2``.

``hertz``: over the overlap ``d = x_r - x > 0``,
``F = max(0, k d^(3/2) + alpha sqrt(m* k) d^(1/4) dd/dt)``, ``k = (4/3) E* R*^(1/2)``
(Hertz 1882; the damping of Tsuji et al. 1992). In the units ``d_s = (m* v^2/k)^(2/5)``,
``t_s = d_s / v`` the dry impact is ``d'' = -d^(3/2) - alpha d^(1/4) d'``, so its
restitution depends on alpha alone: :func:`hertz_damping` finds the alpha that gives e_dry
(bracketed root, to 1e-12). Undamped, the contact time is
``2.86827 (m*^2/(R* E*^2 v))^(1/5)``.

``thornton``: Hertz up to the yield force ``F_y`` where the mean pressure reaches
``p_y``, then ``F = F_y + pi p_y R* (d - d_y)``; unloading is Hertzian with the radius
``R_p = (4 E*/(3 F*)) ((2 F* + F_y)/(2 pi p_y))^(3/2)`` from the largest force F*, down to
the plastic overlap ``d_p`` (Thornton 1997, J. Appl. Mech. 64, 383). The yield pressure is
set so that the dry impact at the case's speed has e_dry (:func:`thornton_yield_pressure`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

from scipy.integrate import solve_ivp
from scipy.optimize import brentq

#: Hertz contact-time constant 2 (15/16)^(2/5) (2/5) B(2/5, 1/2)
HERTZ_TIME = 2.0 * (15.0 / 16.0) ** 0.4 * 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(
    0.9)


def effective_modulus(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """``E* = [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]^-1`` (Pa)."""
    return 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)


def _dry_rebound(alpha: float) -> float:
    """Restitution of the dimensionless damped Hertz impact ``d'' = -d^1.5 - a d^.25 d'``."""
    def rhs(_t: float, y: list[float]) -> list[float]:
        d, w = max(y[0], 0.0), y[1]
        return [w, -max(0.0, d ** 1.5 + alpha * d ** 0.25 * w)]

    def out(_t: float, y: list[float]) -> float:
        return y[0]

    out.terminal, out.direction = True, -1  # type: ignore[attr-defined]
    sol = solve_ivp(rhs, (0.0, 1e4), [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-14,
                    events=out, first_step=1e-6)
    return -float(sol.y_events[0][0][1]) if sol.y_events[0].size else 0.0


@lru_cache(maxsize=64)
def hertz_damping(e_dry: float) -> float:
    """The Tsuji damping factor alpha whose dry Hertz impact has restitution ``e_dry``."""
    if e_dry >= 1.0:
        return 0.0
    hi = 1.0
    while _dry_rebound(hi) > e_dry:
        hi *= 2.0
    return brentq(lambda a: _dry_rebound(a) - e_dry, 0.0, hi, xtol=1e-13, rtol=1e-13)


@dataclass(frozen=True)
class Thornton:
    """Thornton's elastic-plastic law for one pair (SI)."""

    e_star: float
    r_star: float
    p_y: float

    @property
    def d_y(self) -> float:
        """Overlap at first yield (m)."""
        return (math.pi * self.p_y / (2.0 * self.e_star)) ** 2 * self.r_star

    @property
    def f_y(self) -> float:
        """Force at first yield (N)."""
        return 4.0 / 3.0 * self.e_star * math.sqrt(self.r_star) * self.d_y ** 1.5

    def loading(self, d: float) -> float:
        """Force while the overlap grows (N)."""
        if d <= self.d_y:
            return 4.0 / 3.0 * self.e_star * math.sqrt(self.r_star) * max(d, 0.0) ** 1.5
        return self.f_y + math.pi * self.p_y * self.r_star * (d - self.d_y)

    def unloading(self, d_max: float) -> tuple[float, float]:
        """Unloading radius R_p and plastic overlap d_p after the largest overlap d_max."""
        f_max = self.loading(d_max)
        if d_max <= self.d_y:
            return self.r_star, 0.0
        r_p = (4.0 * self.e_star / (3.0 * f_max)) * (
            (2.0 * f_max + self.f_y) / (2.0 * math.pi * self.p_y)) ** 1.5
        d_p = d_max - (3.0 * f_max / (4.0 * self.e_star * math.sqrt(r_p))) ** (2.0 / 3.0)
        return r_p, d_p

    def unloading_force(self, d: float, r_p: float, d_p: float) -> float:
        """Force while the overlap shrinks (N)."""
        return 4.0 / 3.0 * self.e_star * math.sqrt(r_p) * max(d - d_p, 0.0) ** 1.5

    def dry_restitution(self, mass: float, v: float) -> float:
        """Restitution of a dry impact at speed ``v`` (m/s), integrated."""
        def load(_t: float, y: list[float]) -> list[float]:
            return [y[1], -self.loading(y[0]) / mass]

        def turn(_t: float, y: list[float]) -> float:
            return y[1]

        turn.terminal, turn.direction = True, -1  # type: ignore[attr-defined]
        t_end = 100.0 * max((mass ** 2 / (self.r_star * self.e_star ** 2 * v)) ** 0.2,
                            math.sqrt(mass / (math.pi * self.p_y * self.r_star)))
        a = solve_ivp(load, (0.0, t_end), [0.0, v], method="DOP853", rtol=1e-12,
                      atol=1e-20, events=turn)
        d_max = float(a.y_events[0][0][0])
        r_p, d_p = self.unloading(d_max)
        # elastic unloading from d_max to d_p: energy balance gives the speed exactly
        work = 8.0 / 15.0 * self.e_star * math.sqrt(r_p) * (d_max - d_p) ** 2.5
        return math.sqrt(2.0 * work / mass) / v


def thornton_yield_pressure(e_star: float, r_star: float, mass: float, v: float,
                            e_dry: float) -> float:
    """Yield pressure p_y (Pa) whose dry Thornton impact at ``v`` has ``e_dry``."""
    if e_dry >= 1.0:
        return math.inf
    # p_y at which the impact just yields: v_y = v, v_y = 3.194 (p_y^5 R*^3/(E*^4 m))^(1/2)
    coef = math.sqrt(16.0 / 15.0 * (math.pi / 2.0) ** 5)
    p_hi = (v * v / coef ** 2 * e_star ** 4 * mass / r_star ** 3) ** 0.2
    def miss(log_p: float) -> float:
        return Thornton(e_star, r_star, math.exp(log_p)).dry_restitution(mass, v) - e_dry

    lo = math.log(p_hi) - 2.0
    while miss(lo) > 0.0:
        lo -= 2.0
    return math.exp(brentq(miss, lo, math.log(p_hi), xtol=1e-13))
