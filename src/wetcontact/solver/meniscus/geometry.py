"""Geometry of a bridge: the solids (:class:`Bridge`, dimensionless :class:`_Geo`) and the
toroidal (circular-arc) initial guess.

The contact lines: on sphere 1 (centre ``(0, S + R1)``) at half-filling angle ``phi1``,
``r = R1 sin phi1``, ``z = S + R1 (1 - cos phi1)``, ``psi = phi1 + theta1``; on sphere 2
(centre ``(0, -R2)``) ``r = R2 sin phi2``, ``z = -R2 (1 - cos phi2)``,
``psi = pi - phi2 - theta2``; on a wall ``z = 0``, ``psi = pi - theta_w`` (PHYSICS.md
section 2). Sphere caps inside the bridge: ``V_cap = pi R^3 (1 - cos phi)^2 (2 + cos phi)/3``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import brentq

from wetcontact.errors import InputError
from wetcontact.scene import Scene

if TYPE_CHECKING:
    from wetcontact.solver.meniscus.young_laplace import _Disc

THETA_MAX = math.radians(150.0)
DEFAULT_ELEMENTS = 128
PHI_MAX = math.radians(70.0)  # largest half-filling angle accepted (else volume too large)




@dataclass(frozen=True)
class Bridge:
    """The solids and the liquid of a bridge (SI units, radians).

    Attributes
    ----------
    radius
        Radius R1 of the upper sphere (m), or ``None`` for a plate (analytic checks).
    radius2
        Radius R2 of the lower sphere (m), or ``None`` for a wall (plate).
    contact_angle1, contact_angle2
        Contact angle on the upper solid and on the lower solid, in [0, 150 deg].
    surface_tension
        sigma (N/m).
    gravity, density
        g (m/s^2, along -z) and liquid density (kg/m^3); gravity is off by default.
    """

    radius: float | None
    radius2: float | None = None
    contact_angle1: float = 0.0
    contact_angle2: float = 0.0
    surface_tension: float = 0.072
    gravity: float = 0.0
    density: float = 0.0

    def __post_init__(self) -> None:
        for name in ("radius", "radius2"):
            val = getattr(self, name)
            if val is not None and not (math.isfinite(val) and val > 0):
                raise InputError(f"meniscus: {name} = {val!r}; allowed: > 0 m or None")
        for name in ("contact_angle1", "contact_angle2"):
            val = getattr(self, name)
            if not (math.isfinite(val) and 0.0 <= val <= THETA_MAX):
                raise InputError(
                    f"meniscus: {name} = {math.degrees(val):.6g} deg; allowed: [0, 150] deg"
                )
        if not (math.isfinite(self.surface_tension) and self.surface_tension > 0):
            raise InputError(f"meniscus: surface_tension = {self.surface_tension!r}; "
                             "allowed: > 0 N/m")
        if self.gravity < 0 or self.density < 0:
            raise InputError("meniscus: gravity and density must be >= 0")

    @classmethod
    def from_scene(cls, scene: Scene) -> Bridge:
        """The bridge of a :class:`~wetcontact.scene.Scene` (sphere 1 on top)."""
        return cls(
            radius=scene.radius,
            radius2=scene.radius2 if scene.kind == "sphere-sphere" else None,
            contact_angle1=scene.contact_angle_sphere,
            contact_angle2=scene.contact_angle_wall,
            surface_tension=scene.surface_tension,
            gravity=scene.gravity,
            density=scene.density,
        )

    def length_scale(self, volume: float | None) -> float:
        """The unit of length inside the solver: R1, else R2, else V^(1/3)."""
        if self.radius is not None:
            return self.radius
        if self.radius2 is not None:
            return self.radius2
        if volume is None:
            raise InputError("meniscus: a plate-plate bridge needs the volume as length scale")
        return volume ** (1.0 / 3.0)

    def _geo(self, ell: float) -> _Geo:
        return _Geo(
            rt=None if self.radius is None else self.radius / ell,
            rb=None if self.radius2 is None else self.radius2 / ell,
            tht=self.contact_angle1, thb=self.contact_angle2,
            bo=self.density * self.gravity * ell**2 / self.surface_tension,
        )


@dataclass(frozen=True)
class _Geo:
    """Dimensionless solids (lengths over ell, pressure over sigma/ell)."""

    rt: float | None
    rb: float | None
    tht: float
    thb: float
    bo: float
    immersed: bool = False
    """Allow a negative gap S: the sphere dips below the lower plane (a bridge on a
    liquid film's surface, the inner meniscus of ``thinfilm``)."""

    # contact-line position and tangent angle on each solid, with d/dc --------------
    def top(self, c: float, s: float) -> tuple[np.ndarray, np.ndarray]:
        if self.rt is None:
            return np.array([c, s, self.tht]), np.array([1.0, 0.0, 0.0])
        R = self.rt
        return (np.array([R * math.sin(c), s + R * (1 - math.cos(c)), c + self.tht]),
                np.array([R * math.cos(c), R * math.sin(c), 1.0]))

    def bottom(self, c: float) -> tuple[np.ndarray, np.ndarray]:
        if self.rb is None:
            return np.array([c, 0.0, math.pi - self.thb]), np.array([1.0, 0.0, 0.0])
        R = self.rb
        return (np.array([R * math.sin(c), -R * (1 - math.cos(c)), math.pi - c - self.thb]),
                np.array([R * math.cos(c), -R * math.sin(c), -1.0]))

    @staticmethod
    def cap(c: float, R: float | None) -> tuple[float, float]:
        """Volume of the sphere cap inside the bridge and its derivative in c."""
        if R is None:
            return 0.0, 0.0
        cc = math.cos(c)
        return (math.pi * R**3 * (1 - cc) ** 2 * (2 + cc) / 3.0,
                math.pi * R**3 * math.sin(c) ** 3)

    @staticmethod
    def wetted(c: float, R: float | None) -> tuple[float, float]:
        """Wetted solid area and its derivative in c."""
        if R is None:
            return math.pi * c * c, 2 * math.pi * c
        return 2 * math.pi * R * R * (1 - math.cos(c)), 2 * math.pi * R * R * math.sin(c)

    def valid_c(self, c: float, R: float | None) -> bool:
        return c > 0 and (R is None or c < math.pi)






# ---------------------------------------------------------------------------------------
# Initial guess: a circular meridian (toroidal approximation)
# ---------------------------------------------------------------------------------------

_GL_X, _GL_W = np.polynomial.legendre.leggauss(24)
_GL_X = 0.5 * (_GL_X + 1.0)
_GL_W = 0.5 * _GL_W


def _sinc(x: np.ndarray) -> np.ndarray:
    return np.sinc(np.asarray(x) / math.pi)


def _arc(p0: np.ndarray, p1: np.ndarray, t: np.ndarray):
    """Circular arc from p0=(r, z, psi0) to the point of p1 with mean-angle chord."""
    dpsi = p1[2] - p0[2]
    chord = math.hypot(p1[0] - p0[0], p1[1] - p0[1])
    L = chord / float(_sinc(0.5 * dpsi))
    mean = p0[2] + 0.5 * dpsi * t
    fac = L * t * _sinc(0.5 * dpsi * t)
    return p0[0] + fac * np.cos(mean), p0[1] + fac * np.sin(mean), p0[2] + dpsi * t, L


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _bottom_for(g: _Geo, p1: np.ndarray) -> float | None:
    """Lower contact parameter whose chord to p1 points along the mean tangent angle."""

    def gfun(c: float) -> float:
        b, _ = g.bottom(c)
        return _wrap(math.atan2(p1[1] - b[1], p1[0] - b[0]) - 0.5 * (b[2] + p1[2]))

    if g.rb is None:
        m = 0.5 * (math.pi - g.thb + p1[2])
        sm = math.sin(m)
        if abs(sm) < 1e-12:
            return None
        c = p1[0] - (p1[1]) * math.cos(m) / sm
        return c if c > 0 else None
    grid = np.linspace(1e-4, 0.95 * math.pi, 60)
    vals = np.array([gfun(c) for c in grid])
    for i in range(grid.size - 1):
        if vals[i] == 0:
            return float(grid[i])
        if vals[i] * vals[i + 1] < 0 and abs(vals[i] - vals[i + 1]) < math.pi:
            return brentq(gfun, grid[i], grid[i + 1], xtol=1e-12)
    return None


def _arc_state(g: _Geo, c1: float, S: float):
    p1, _ = g.top(c1, S)
    c2 = _bottom_for(g, p1)
    if c2 is None or not g.valid_c(c2, g.rb):
        return None
    p0, _ = g.bottom(c2)
    r, z, psi, L = _arc(p0, p1, _GL_X)
    if np.min(r) <= 0 or L <= 0:
        return None
    V = math.pi * L * np.sum(_GL_W * r * r * np.sin(psi)) - g.cap(c1, g.rt)[0] - g.cap(c2, g.rb)[0]
    return c2, p0, p1, V


def _c1_range(g: _Geo) -> np.ndarray:
    if g.rt is None:
        return np.geomspace(0.02, 50.0, 80)
    hi = min(0.5 * math.pi + 0.3, math.pi - 1e-3)
    return np.geomspace(2e-3, hi, 80)


def _guess(d: _Disc, g: _Geo, S: float, V: float | None = None,
           P: float | None = None) -> np.ndarray | None:
    """Toroidal (circular-arc) guess with volume V (or pressure P), the largest c1 root."""
    grid = _c1_range(g)
    vals = []
    for c1 in grid:
        st = _arc_state(g, float(c1), S)
        if st is None:
            vals.append(np.nan)
            continue
        if V is not None:
            vals.append(st[3] - V)
        else:
            r, z, psi, L = _arc(st[1], st[2], np.array([0.5]))
            vals.append(((st[2][2] - st[1][2]) / L + math.sin(psi[0]) / r[0]) - P)
    vals = np.array(vals)
    c1 = None
    for i in range(grid.size - 2, -1, -1):
        a, b = vals[i], vals[i + 1]
        if np.isfinite(a) and np.isfinite(b) and a * b <= 0:
            if V is not None:
                f = lambda c: _arc_state(g, c, S)[3] - V  # noqa: E731
                try:
                    c1 = brentq(f, grid[i], grid[i + 1], xtol=1e-10)
                except (ValueError, TypeError):
                    c1 = 0.5 * (grid[i] + grid[i + 1])
            else:
                c1 = float(grid[i] - a * (grid[i + 1] - grid[i]) / (b - a))
            break
    if c1 is None:
        return None
    return _guess_at(d, g, S, c1, P)


def _guess_at(d: _Disc, g: _Geo, S: float, c1: float,
              P: float | None = None) -> np.ndarray | None:
    """Toroidal guess with half-filling angle ``c1`` on sphere 1 at gap ``S``."""
    st = _arc_state(g, c1, S)
    if st is None:
        return None
    c2, p0, p1, _ = st
    r, z, psi, L = _arc(p0, p1, d.t)
    rm, zm, pm, _ = _arc(p0, p1, np.array([0.5]))
    x = np.zeros(d.m)
    x[:d.n], x[d.n:2 * d.n], x[2 * d.n:3 * d.n] = r, z, psi
    x[d.iL] = L
    x[d.iP] = (p1[2] - p0[2]) / L + math.sin(pm[0]) / rm[0] if P is None else P
    x[d.ic1], x[d.ic2], x[d.iS] = c1, c2, S
    return x


