"""Rabinovich et al. (2005) and Lambert et al. (2008) capillary forces (parabolic gap).

The force of a bridge whose immersion height d on the sphere(s) follows from the volume in
the parabolic-gap approximation: Rabinovich et al. (2005) for two spheres and for a sphere
and a plane; Lambert et al. (2008) the first term of Rabinovich's force. Force as a
positive attractive magnitude (N), vectorised over the gap S (m); angles in radians; bad
inputs raise :class:`~wetcontact.errors.InputError`. The registered models ``rabinovich``
and ``lambert`` are in :mod:`wetcontact.reduced_models.capillary`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.reduced_models._checks import angle, positive
from wetcontact.reduced_models._checks import gap as _gap

__all__ = [
    "lambert_force_sphere_sphere",
    "lambert_force_sphere_wall",
    "rabinovich_force_sphere_sphere",
    "rabinovich_force_sphere_wall",
    "rabinovich_immersion_height",
]


def rabinovich_immersion_height(gap: Any, volume: Any, radius: Any,
                                kind: str = "sphere-sphere") -> np.ndarray:
    r"""Immersion height d of the sphere(s) in a bridge of volume V (parabolic gap).

    Two spheres (Rabinovich et al. 2005, eq. 20): volume of the gap
    :math:`h = H + \rho^2/R` up to :math:`\rho^2 = 2Rd` gives
    :math:`d = (H/2)(-1 + \sqrt{1 + 2V/(\pi R H^2)})`.
    Sphere-plane (:math:`h = H + \rho^2/(2R)`):
    :math:`d = H(-1 + \sqrt{1 + V/(\pi R H^2)})`.
    Evaluated in the cancellation-free form :math:`q/(\sqrt{H^2 + q} + H)`, finite at H = 0.
    """
    h = _gap(gap)
    v = positive("volume", volume, "m^3")
    r = positive("radius", radius, "m")
    if kind == "sphere-sphere":
        q = 2.0 * v / (np.pi * r)
        return 0.5 * q / (np.sqrt(h**2 + q) + h)
    if kind == "sphere-wall":
        q = v / (np.pi * r)
        return q / (np.sqrt(h**2 + q) + h)
    raise InputError(f"kind = {kind!r}; allowed: 'sphere-sphere', 'sphere-wall'")


def lambert_force_sphere_sphere(gap: Any, volume: Any, radius: Any, surface_tension: Any,
                                theta: Any) -> np.ndarray:
    r"""Lambert et al. (2008): first term of Rabinovich et al. (2005), two spheres.

    .. math:: F = \frac{2\pi R\sigma\cos\theta}{1 + H/(2d)}

    d from :func:`rabinovich_immersion_height` (P. Lambert, A. Chau, A. Delchambre,
    S. Regnier, Langmuir 24, 3157 (2008), eq. 65). R: equal spheres' radius, unequal
    spheres R = 2 R1 R2/(R1 + R2) (Derjaguin). Exact contact limit 2 pi R sigma cos theta
    at H = 0 for any V.

    Returns
    -------
    numpy.ndarray
        Attractive force (N). Validity: Derjaguin/parabolic-gap approximation, small V*
        and H << R.
    """
    h = _gap(gap)
    sig = positive("surface_tension", surface_tension, "N/m")
    th = angle("theta", theta)
    r = positive("radius", radius, "m")
    d = rabinovich_immersion_height(h, volume, r, "sphere-sphere")
    return 2.0 * np.pi * r * sig * np.cos(th) / (1.0 + h / (2.0 * d))


def lambert_force_sphere_wall(gap: Any, volume: Any, radius: Any, surface_tension: Any,
                              theta_s: Any, theta_w: Any) -> np.ndarray:
    r"""Lambert et al. (2008) / Rabinovich first term, sphere-plane.

    .. math:: F = \frac{2\pi R\sigma(\cos\theta_s + \cos\theta_w)}{1 + H/d},
              \quad d = H(-1 + \sqrt{1 + V/(\pi R H^2)})

    i.e. :math:`2\pi R\sigma(\cos\theta_s + \cos\theta_w)(1 - H/\sqrt{H^2 + V/(\pi R)})`,
    the two-sphere formula with the Derjaguin radius 2R (the same as haloless/StupidCFD's
    ``DerjaguinRadius`` for a flat). Exact contact limit 2 pi R sigma (cos theta_s +
    cos theta_w) at H = 0.
    """
    h = _gap(gap)
    sig = positive("surface_tension", surface_tension, "N/m")
    ts = angle("theta_s", theta_s)
    tw = angle("theta_w", theta_w)
    r = positive("radius", radius, "m")
    d = rabinovich_immersion_height(h, volume, r, "sphere-wall")
    return 2.0 * np.pi * r * sig * (np.cos(ts) + np.cos(tw)) / (1.0 + h / d)


def rabinovich_force_sphere_sphere(gap: Any, volume: Any, radius: Any,
                                   surface_tension: Any, theta: Any) -> np.ndarray:
    r"""Rabinovich et al. (2005), two spheres, both terms.

    .. math::
        F = \frac{2\pi R\sigma\cos\theta}{1 + H/(2d)}
            + 2\pi R\sigma\sin\alpha\,\sin(\theta + \alpha), \quad
        \alpha = \sqrt{(H/R)(-1 + \sqrt{1 + 2V/(\pi R H^2)})} = \sqrt{2d/R}

    (Y. I. Rabinovich, M. S. Esayanur, B. M. Moudgil, Langmuir 21, 10992 (2005), eqs. 19,
    20, A3). R as :func:`lambert_force_sphere_sphere`. At H -> 0 the second term tends to
    :math:`2\pi R\sigma\sin\alpha_0\sin(\theta + \alpha_0)`,
    :math:`\alpha_0 = (2V^*/\pi)^{1/4}` (Yade sets alpha = 0 at H = 0, a discontinuity);
    it vanishes for V -> 0, recovering 2 pi R sigma cos theta.

    Returns
    -------
    numpy.ndarray
        Attractive force (N). Validity: small bridges, H << R (parabolic gap).
    """
    h = _gap(gap)
    sig = positive("surface_tension", surface_tension, "N/m")
    th = angle("theta", theta)
    r = positive("radius", radius, "m")
    d = rabinovich_immersion_height(h, volume, r, "sphere-sphere")
    alpha = np.sqrt(2.0 * d / r)
    first = 2.0 * np.pi * r * sig * np.cos(th) / (1.0 + h / (2.0 * d))
    return first + 2.0 * np.pi * r * sig * np.sin(alpha) * np.sin(th + alpha)


def rabinovich_force_sphere_wall(gap: Any, volume: Any, radius: Any, surface_tension: Any,
                                 theta_s: Any, theta_w: Any) -> np.ndarray:
    r"""Rabinovich et al. (2005), sphere-plane: Lambert's term plus the contact-line term.

    .. math::
        F = \frac{2\pi R\sigma(\cos\theta_s + \cos\theta_w)}{1 + H/d}
            + 2\pi R\sigma\sin\alpha\,\sin(\theta_s + \alpha),\quad \alpha = \sqrt{2d/R}

    with the sphere-plane d of :func:`rabinovich_immersion_height` (wetted radius
    :math:`\rho^2 = 2Rd` on the sphere of radius R). The first term is the sphere-plane
    form of Rabinovich et al. (2005) (= the two-sphere form with Derjaguin radius 2R).
    The second term's sphere-plane alpha is derived here from the same parabolic geometry;
    substituting 2R into the two-sphere alpha, as a code reusing the two-sphere function
    with R = 2R would, gives alpha half as large.
    """
    h = _gap(gap)
    sig = positive("surface_tension", surface_tension, "N/m")
    ts = angle("theta_s", theta_s)
    tw = angle("theta_w", theta_w)
    r = positive("radius", radius, "m")
    d = rabinovich_immersion_height(h, volume, r, "sphere-wall")
    alpha = np.sqrt(2.0 * d / r)
    first = 2.0 * np.pi * r * sig * (np.cos(ts) + np.cos(tw)) / (1.0 + h / d)
    return first + 2.0 * np.pi * r * sig * np.sin(alpha) * np.sin(ts + alpha)
