"""Rupture-distance closures for a pendular liquid bridge (level 0).

Every function returns the surface gap S_c (m) at which a bridge of volume V ruptures, as a
numpy array broadcast over its inputs. SI units, contact angles in radians. Invalid inputs
(V <= 0, R <= 0, theta outside [0, pi)) raise :class:`~wetcontact.errors.InputError`
naming the value and the allowed range; no function returns NaN.

Which closure family is paired with which rupture criterion in DEM practice:
Willett forms and Bagheri -> :func:`willett_rupture_distance`; Mikami ->
:func:`mikami_rupture_distance_pp` / :func:`mikami_rupture_distance_pw`; toroidal,
Rabinovich, Lambert -> :func:`lian_rupture_distance`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from wetcontact.reduced_models._checks import angle, non_negative, positive

__all__ = [
    "lian_rupture_distance",
    "mikami_rupture_distance_pp",
    "mikami_rupture_distance_pw",
    "pitois_rupture_distance",
    "willett_rupture_distance",
]


def lian_rupture_distance(volume: Any, theta: Any) -> np.ndarray:
    r"""Rupture distance of Lian, Thornton & Adams (1993).

    .. math:: S_c = (1 + \theta/2)\, V^{1/3}

    Source: G. Lian, C. Thornton, M. J. Adams, J. Colloid Interface Sci. 161, 138 (1993),
    from toroidal/Young-Laplace solutions for two equal spheres; used in DEM also for
    sphere-wall contacts. Independent of the radius.

    Parameters
    ----------
    volume
        Bridge volume V (m^3), > 0.
    theta
        Contact angle (rad), in [0, pi); for two different angles pass their mean.

    Returns
    -------
    numpy.ndarray
        Rupture gap S_c (m). Validity: small bridges, V/R^3 below about 0.1, theta below
        about 50 deg (the range of the solutions it was fitted to).
    """
    v = positive("volume", volume, "m^3")
    th = angle("theta", theta)
    return (1.0 + 0.5 * th) * np.cbrt(v)


def willett_rupture_distance(volume: Any, radius: Any, theta: Any) -> np.ndarray:
    r"""Rupture distance of Willett et al. (2000), equal spheres.

    .. math:: S_c = R\,(1 + \theta/2)\,(V^{*1/3} + 0.1\,V^{*2/3}), \quad V^* = V/R^3

    Source: C. D. Willett, M. J. Adams, S. A. Johnson, J. P. K. Seville, Langmuir 16, 9396
    (2000), eq. 15; S_c is the full surface gap (as in Yade and MercuryDPM). Unequal
    spheres: pass R = 2 R1 R2/(R1 + R2); sphere-wall (Derjaguin): R = 2 R_sphere.
    (Willett's separate size-ratio correlation for unequal spheres is not implemented.)

    Parameters
    ----------
    volume
        Bridge volume V (m^3), > 0.
    radius
        Sphere radius R (m), > 0.
    theta
        Contact angle (rad), in [0, pi).

    Returns
    -------
    numpy.ndarray
        Rupture gap S_c (m). Validity: theta < 50 deg, V* < 0.1 (Willett's fit range).
    """
    v = positive("volume", volume, "m^3")
    r = positive("radius", radius, "m")
    th = angle("theta", theta)
    vs = v / r**3
    return r * (1.0 + 0.5 * th) * (np.cbrt(vs) + 0.1 * np.cbrt(vs) ** 2)


def _mikami_rupture(volume: Any, radius: Any, theta: Any, a: float, b: float,
                    p: float) -> np.ndarray:
    """``S_c = R (a theta + b) V*^p`` with checked inputs."""
    v = positive("volume", volume, "m^3")
    r = positive("radius", radius, "m")
    th = angle("theta", theta)
    return r * (a * th + b) * (v / r**3) ** p


def mikami_rupture_distance_pp(volume: Any, radius: Any, theta: Any) -> np.ndarray:
    r"""Rupture distance of Mikami, Kamiya & Horio (1998), particle-particle.

    .. math:: S_c = R\,(0.62\,\theta + 0.99)\, V^{*0.34}, \quad V^* = V/R^3

    Source: T. Mikami, H. Kamiya, M. Horio, Chem. Eng. Sci. 53, 1927 (1998), regression of
    Young-Laplace solutions; coefficients as quoted in PHYSICS.md (marked "check") and in
    public code (haloless/StupidCFD ``BridgeRuptureMikami.m``); the original paper was not
    available to confirm them. Unequal spheres: R = 2 R1 R2/(R1 + R2) (Derjaguin).

    Parameters
    ----------
    volume, radius, theta
        V (m^3) > 0, R (m) > 0, contact angle (rad) in [0, pi).

    Returns
    -------
    numpy.ndarray
        Rupture gap S_c (m).
    """
    return _mikami_rupture(volume, radius, theta, 0.62, 0.99, 0.34)


def mikami_rupture_distance_pw(volume: Any, radius: Any, theta: Any) -> np.ndarray:
    r"""Rupture distance of Mikami, Kamiya & Horio (1998), particle-wall.

    .. math:: S_c = R\,(0.22\,\theta + 0.95)\, V^{*0.32}, \quad V^* = V/R^3

    Source and caveat as :func:`mikami_rupture_distance_pp`; R is the sphere radius.

    Parameters
    ----------
    volume, radius, theta
        V (m^3) > 0, R (m) > 0, contact angle (rad) in [0, pi).

    Returns
    -------
    numpy.ndarray
        Rupture gap S_c (m).
    """
    return _mikami_rupture(volume, radius, theta, 0.22, 0.95, 0.32)


def pitois_rupture_distance(volume: Any, theta: Any, capillary_number: Any) -> np.ndarray:
    r"""Dynamic rupture distance of Pitois, Moucheront & Chateau (2001).

    .. math:: S_c = (1 + \theta/2)\,(1 + \mathrm{Ca}^{1/2})\, V^{1/3},
              \quad \mathrm{Ca} = \eta v / \sigma

    Source: O. Pitois, P. Moucheront, X. Chateau, Eur. Phys. J. B 23, 79 (2001), in the form
    quoted in the wet-collision literature (PHYSICS.md); v is the separation speed. At
    Ca = 0 it is Lian's static distance (:func:`lian_rupture_distance`).

    Parameters
    ----------
    volume
        Bridge volume V (m^3), > 0.
    theta
        Contact angle (rad), in [0, pi).
    capillary_number
        Ca = eta |v| / sigma, >= 0.

    Returns
    -------
    numpy.ndarray
        Rupture gap S_c (m).
    """
    ca = non_negative("capillary_number", capillary_number)
    return lian_rupture_distance(volume, theta) * (1.0 + np.sqrt(ca))
