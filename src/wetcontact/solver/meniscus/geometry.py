"""Geometry of a bridge: the solids (:class:`Bridge`, dimensionless :class:`_Geo`); the
toroidal (circular-arc) initial guess is in :mod:`.guess`.

The contact lines: on sphere 1 (centre ``(0, S + R1)``) at half-filling angle ``phi1``,
``r = R1 sin phi1``, ``z = S + R1 (1 - cos phi1)``, ``psi = phi1 + theta1``; on sphere 2
(centre ``(0, -R2)``) ``r = R2 sin phi2``, ``z = -R2 (1 - cos phi2)``,
``psi = pi - phi2 - theta2``; on a wall ``z = 0``, ``psi = pi - theta_w`` (PHYSICS.md
section 2). Sphere caps inside the bridge: ``V_cap = pi R^3 (1 - cos phi)^2 (2 + cos phi)/3``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wetcontact.errors import InputError
from wetcontact.scene import Scene

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
