"""Toroidal (Fisher) capillary bridges: the meridian a circular arc, at fixed volume.

The bridge between two equal spheres (or a sphere and a plane) whose meridian is a circle
meeting each solid at its contact angle (Fisher 1926); the half-filling angle b follows
from the volume, the force from the contact line (Weigert & Ripperger 1999) or the neck.
Force as a positive attractive magnitude (N), vectorised over the gap S (m); angles in
radians; bad inputs raise :class:`~wetcontact.errors.InputError`. Accuracy: within about
10 % of the exact Young-Laplace bridge for small bridges (Lian et al. 1993). The registered
model ``toroidal`` is in :mod:`wetcontact.reduced_models.capillary`.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from wetcontact.errors import InputError, SolverError
from wetcontact.reduced_models._checks import angle, positive
from wetcontact.reduced_models._checks import gap as _gap

__all__ = [
    "ToroidalBridge",
    "toroidal_bridge",
    "toroidal_force_sphere_sphere",
    "toroidal_force_sphere_wall",
    "toroidal_volume",
]


class ToroidalBridge(NamedTuple):
    """Geometry and force of a toroidal bridge (arrays over the gaps).

    Attributes
    ----------
    filling_angle
        Half-filling angle b on the sphere (rad).
    meridian_radius
        r1, radius of the circular meridian (m).
    neck_radius
        r2, radius of the toroid's neck (m).
    suction
        u = sigma (1/r1 - 1/r2) (Pa), positive when the liquid is below gas pressure.
    force
        Attractive force (N) by the chosen method.
    """

    filling_angle: np.ndarray
    meridian_radius: np.ndarray
    neck_radius: np.ndarray
    suction: np.ndarray
    force: np.ndarray


def _toroid(b: np.ndarray, gap: np.ndarray, radius: float, theta_s: float, theta_w: float,
            kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """r1, xc (centre distance from the axis), zc, zs for filling angle b (arrays)."""
    cap = radius * (1.0 - np.cos(b))
    if kind == "sphere-sphere":
        zs = 0.5 * gap + cap                      # contact height above the mid-plane
        r1 = zs / np.cos(b + theta_s)             # = (2R(1 - cos b) + a)/(2 cos(b + theta))
        zc = np.zeros_like(r1)
    else:
        zs = gap + cap                            # contact height above the wall
        r1 = zs / (np.cos(theta_w) + np.cos(theta_s + b))
        zc = r1 * np.cos(theta_w)
    xc = radius * np.sin(b) + r1 * np.sin(b + theta_s)
    return r1, xc, zc, zs


def _half_circle_integral(z: np.ndarray, r1: np.ndarray) -> np.ndarray:
    """Antiderivative of sqrt(r1^2 - z^2)."""
    w = np.clip(z / r1, -1.0, 1.0)
    return 0.5 * (z * np.sqrt(np.maximum(r1**2 - z**2, 0.0)) + r1**2 * np.arcsin(w))


def toroidal_volume(filling_angle: Any, gap: Any, radius: float, theta_s: float,
                    theta_w: float | None = None, kind: str = "sphere-sphere") -> np.ndarray:
    r"""Liquid volume of a toroidal bridge with half-filling angle b (closed form).

    The meridian is a circular arc of radius r1 centred at distance x_c from the axis;
    the volume is :math:`\pi\int x(z)^2 dz` between the wall (or the mid-plane) and the
    contact line, :math:`x(z) = x_c - \sqrt{r_1^2 - (z - z_c)^2}`, minus the immersed sphere
    cap :math:`\pi h^2 (3R - h)/3`, h = R(1 - cos b); doubled for two equal spheres.
    Meridian (Fisher 1926; Weigert & Ripperger 1999, eqs. 5-6 for two spheres):
    two spheres ``r1 = (2R(1 - cos b) + a)/(2 cos(b + theta))``; sphere-wall
    ``r1 = (a + R(1 - cos b))/(cos theta_w + cos(b + theta_s))``, both
    ``x_c = R sin b + r1 sin(b + theta_s)``.

    Parameters
    ----------
    filling_angle
        b (rad).
    gap
        Surface gap a (m), >= 0.
    radius
        Sphere radius R (m).
    theta_s, theta_w
        Contact angles (rad) on the sphere(s) and on the wall (sphere-wall only).
    kind
        ``"sphere-sphere"`` (equal spheres) or ``"sphere-wall"``.

    Returns
    -------
    numpy.ndarray
        Volume V (m^3); meaningful where the neck radius x_c - r1 is positive.
    """
    b = np.asarray(filling_angle, dtype=float)
    a = np.asarray(gap, dtype=float)
    tw = theta_s if theta_w is None else theta_w
    r1, xc, zc, zs = _toroid(b, a, radius, theta_s, tw, kind)
    lo, hi = -zc, zs - zc                      # integration limits relative to the centre
    integral = ((xc**2 + r1**2) * (hi - lo) - (hi**3 - lo**3) / 3.0
                - 2.0 * xc * (_half_circle_integral(hi, r1) - _half_circle_integral(lo, r1)))
    h = radius * (1.0 - np.cos(b))
    v = np.pi * integral - np.pi * h**2 * (3.0 * radius - h) / 3.0
    return 2.0 * v if kind == "sphere-sphere" else v


def _max_filling_angle(theta_s: float, theta_w: float, kind: str) -> float:
    if kind == "sphere-sphere":
        return min(0.5 * np.pi - theta_s, 0.5 * np.pi)
    return min(np.pi - theta_w - theta_s, 0.5 * np.pi)


def _solve_filling_angle(volume: float, gap: float, radius: float, theta_s: float,
                         theta_w: float, kind: str) -> float:
    """Smallest b with toroidal_volume(b) = V and a positive neck radius (bracketed root)."""
    bmax = _max_filling_angle(theta_s, theta_w, kind)
    if bmax <= 0.0:
        raise InputError(f"contact angles ({theta_s:.6g}, {theta_w:.6g}) rad leave no "
                         "concave toroidal bridge; allowed: theta_s + theta_w < pi")
    grid = np.linspace(bmax * 1e-4, bmax * (1.0 - 1e-9), 600)
    r1, xc, _, _ = _toroid(grid, np.full_like(grid, gap), radius, theta_s, theta_w, kind)
    vol = toroidal_volume(grid, gap, radius, theta_s, theta_w, kind)
    ok = (xc - r1) > 0.0
    f = np.where(ok, vol - volume, -np.inf)
    # a sign change between two grid points that both have a positive neck radius; the
    # volume is not meaningful (and may change sign) where the neck radius is negative
    idx = np.nonzero((f[:-1] < 0.0) & ok[:-1] & (f[1:] >= 0.0) & ok[1:])[0]
    if idx.size == 0:
        raise SolverError(
            f"toroidal: no bridge of volume {volume:.6g} m3 at gap {gap:.6g} m "
            f"(R = {radius:.6g} m); the volume exceeds the toroid's maximum "
            f"{np.nanmax(np.where(ok, vol, np.nan)) if ok.any() else 0.0:.6g} m3 "
            "or the gap is beyond the toroid's existence")
    i = int(idx[0])
    from scipy.optimize import brentq  # here, not at import: `solve` with a closure starts fast

    def resid(b: float) -> float:
        return float(toroidal_volume(b, gap, radius, theta_s, theta_w, kind)) - volume

    return float(brentq(resid, grid[i], grid[i + 1], xtol=1e-14, rtol=1e-13, maxiter=200))


def toroidal_bridge(gap: Any, volume: float, radius: float, surface_tension: float,
                    theta_s: float, theta_w: float | None = None,
                    kind: str = "sphere-sphere", method: str = "boundary") -> ToroidalBridge:
    r"""Toroidal (Fisher) bridge at fixed volume: filling angle, curvatures and force.

    For each gap the half-filling angle b is found from the volume by a bracketed root
    find (Brent) of :func:`toroidal_volume`. Suction ``u = sigma (1/r1 - 1/r2)``,
    neck radius ``r2 = x_c - r1`` (Weigert & Ripperger 1999, eqs. 5, 6, 22). Force:

    - ``method="boundary"`` (at the contact line on the sphere, Weigert & Ripperger eq. 21):
      :math:`F = 2\pi\sigma R\sin b\,\sin(b + \theta_s) + \pi R^2 \sin^2 b\; u`
    - ``method="gorge"`` (at the neck, Fisher 1926):
      :math:`F = 2\pi\sigma r_2 + \pi r_2^2 u`

    The toroid is not an exact Young-Laplace surface, so the two differ; only the gorge
    method gives Fisher's zero-gap result :math:`2\pi R\sigma/(1 + \tan(b/2))`
    (theta = 0). Lian et al. (1993) put the toroidal error within about 10 % of the exact
    solution for small bridges.

    Parameters
    ----------
    gap
        Surface gaps (m), >= 0.
    volume
        Bridge volume V (m^3), > 0.
    radius
        Sphere radius R (m); unequal spheres: pass R_eff = 2 R1 R2/(R1 + R2) (Derjaguin).
    surface_tension
        sigma (N/m).
    theta_s, theta_w
        Contact angle on the sphere(s), and on the wall for ``kind="sphere-wall"``
        (defaults to theta_s), radians.
    kind
        ``"sphere-sphere"`` or ``"sphere-wall"``.
    method
        ``"boundary"`` or ``"gorge"``.

    Returns
    -------
    ToroidalBridge
        Arrays over the gaps; ``force`` is the attractive magnitude (N).

    Raises
    ------
    InputError
        Bad inputs.
    SolverError
        No toroidal bridge with this volume at some gap (volume too large for the toroid).
    """
    a = np.atleast_1d(_gap(gap))
    v = float(positive("volume", volume, "m^3"))
    r = float(positive("radius", radius, "m"))
    sig = float(positive("surface_tension", surface_tension, "N/m"))
    ts = float(angle("theta_s", theta_s))
    tw = ts if theta_w is None else float(angle("theta_w", theta_w))
    if kind not in ("sphere-sphere", "sphere-wall"):
        raise InputError(f"kind = {kind!r}; allowed: 'sphere-sphere', 'sphere-wall'")
    if method not in ("boundary", "gorge"):
        raise InputError(f"method = {method!r}; allowed: 'boundary', 'gorge'")
    b = np.array([_solve_filling_angle(v, float(ai), r, ts, tw, kind) for ai in a])
    r1, xc, _, _ = _toroid(b, a, r, ts, tw, kind)
    r2 = xc - r1
    u = sig * (1.0 / r1 - 1.0 / r2)
    if method == "boundary":
        f = 2.0 * np.pi * sig * r * np.sin(b) * np.sin(b + ts) + np.pi * (r * np.sin(b)) ** 2 * u
    else:
        f = 2.0 * np.pi * sig * r2 + np.pi * r2**2 * u
    return ToroidalBridge(b, r1, r2, u, f)


def toroidal_force_sphere_sphere(gap: Any, volume: float, radius: float,
                                 surface_tension: float, theta: float,
                                 method: str = "boundary") -> np.ndarray:
    """Toroidal force between two equal spheres (N, attractive); see :func:`toroidal_bridge`.

    Unequal spheres: radius = 2 R1 R2/(R1 + R2) (Derjaguin). Validity: small bridges
    (V/R^3 below about 0.1), concave meridian (theta + b < pi/2).
    """
    return toroidal_bridge(gap, volume, radius, surface_tension, theta, theta,
                           "sphere-sphere", method).force


def toroidal_force_sphere_wall(gap: Any, volume: float, radius: float,
                               surface_tension: float, theta_s: float, theta_w: float,
                               method: str = "boundary") -> np.ndarray:
    """Toroidal force between a sphere and a plane (N, attractive); see
    :func:`toroidal_bridge`. Validity: small bridges, theta_s + b + theta_w < pi."""
    return toroidal_bridge(gap, volume, radius, surface_tension, theta_s, theta_w,
                           "sphere-wall", method).force
