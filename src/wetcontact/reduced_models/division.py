r"""Published rules for the division of a bridge's liquid at rupture (PHYSICS.md section 7).

Each function returns ``f``, the fraction of the ruptured bridge's liquid that body 1 keeps
(body 2 keeps ``1 - f``), as a numpy array broadcast over its inputs: the quantity of the
reference ``transfer_fraction`` of the ``meniscus`` model
(:func:`wetcontact.solver.meniscus.division.transfer_fraction`: the critical bridge cut at
its neck), so that the two can be compared side by side. SI units; ``radius2 = None`` is a
wall. None of these rules depends on the contact angles, which decide the division of the
reference (body 1 keeps 0.02-0.98 over angles 0-70 deg); invalid inputs raise
:class:`~wetcontact.errors.InputError`.

Sources (the code as published):

* Yade, ``LiqControl`` (``pkg/dem/ViscoelasticCapillarPM.cpp``, liquid migration of Mani et
  al. 2013): a new bridge records the two contributions ``Vf1 = Vf2 = Vb/2`` (unless
  ``particleconserve``, then each body's own contribution) and a ruptured bridge returns
  them, so by default each body gets half.
* LIGGGHTS, ``cohesion_model_easo_capillary_viscous.h`` (``surfacesClose``, case iii: "assume
  liquid distributes evenly"): ``0.5 volBond`` to each particle; its cohesion skips walls.
* MercuryDPM, ``LiquidMigrationWilletInteraction::rupture``: half to each particle of a
  pair; with a wall the particle takes the whole bridge (part of it may go on to the
  particle's other bridges), the wall nothing.
* Shi & McCarthy (2008), Powder Technol. 184, 64: the liquid a particle gives to a new
  bridge, ``V_i,b = V_i (1 - sqrt(1 - R_j^2/(R_i + R_j)^2))/2`` (the film on the cap of
  particle i facing particle j; LIGGGHTS builds its bridges so).

Beside them, the closure calibrated to the reference over the issue's domain,
:func:`~wetcontact.reduced_models.transfer_fraction.calibrated_transfer_fraction` (its form,
domain, band and accuracy in :mod:`wetcontact.reduced_models.transfer_fraction`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.reduced_models._checks import positive
from wetcontact.reduced_models.transfer_fraction import calibrated_transfer_fraction

__all__ = [
    "calibrated_transfer_fraction",
    "even_split_fraction",
    "mercurydpm_fraction",
    "shi_mccarthy_fraction",
    "shi_mccarthy_share",
]


def _radii(radius1: Any, radius2: Any) -> tuple[np.ndarray, np.ndarray | None]:
    r1 = positive("radius1", radius1, "m")
    if radius2 is None:
        return r1, None
    return r1, positive("radius2", radius2, "m")


def even_split_fraction(radius1: Any, radius2: Any = None) -> np.ndarray:
    r"""Even split: each body keeps half of the ruptured bridge.

    .. math:: f = 1/2

    Source: Yade ``LiqControl`` (default, ``particleconserve = False``: the bridge's
    ``Vf1 = Vf2 = V_b/2`` return to the two bodies at rupture) and LIGGGHTS
    ``cohesion_model_easo_capillary_viscous.h`` ("assume liquid distributes evenly",
    ``0.5 volBond`` to each particle).

    Parameters
    ----------
    radius1, radius2
        Radii (m), > 0; ``radius2 = None`` for a wall. Only their shape is used.

    Returns
    -------
    numpy.ndarray
        f = 0.5 on body 1, broadcast over the radii.
    """
    r1, r2 = _radii(radius1, radius2)
    shape = r1.shape if r2 is None else np.broadcast_shapes(r1.shape, r2.shape)
    return np.full(shape, 0.5)


def mercurydpm_fraction(radius1: Any, radius2: Any = None) -> np.ndarray:
    r"""MercuryDPM's rule: half to each particle, nothing to a wall.

    .. math:: f = 1/2 \ \text{(two spheres)},\qquad f = 1 \ \text{(sphere 1 on a wall)}

    Source: MercuryDPM ``LiquidMigrationWilletInteraction::rupture``
    (Kernel/Interactions/AdhesiveForceInteractions/LiquidMigrationWilletInteraction.cc):
    between two particles each gets ``0.5 liquidBridgeVolume_``; when the other body is a
    wall the particle takes ``liquidBridgeVolume_`` whole (or passes a share, the species'
    distribution coefficient, to its other bridges: still its own liquid).

    Parameters
    ----------
    radius1, radius2
        Radii (m), > 0; ``radius2 = None`` for a wall (body 2).

    Returns
    -------
    numpy.ndarray
        f on body 1 (the sphere when the other body is a wall).
    """
    r1, r2 = _radii(radius1, radius2)
    if r2 is None:
        return np.ones(r1.shape)
    return np.full(np.broadcast_shapes(r1.shape, r2.shape), 0.5)


def shi_mccarthy_share(radius_i: Any, radius_j: Any) -> np.ndarray:
    r"""Share of particle i's liquid that goes into a bridge with particle j.

    .. math:: c_{ij} = \frac{1}{2}\left(1 - \sqrt{1 - \frac{R_j^2}{(R_i + R_j)^2}}\right)
              = \frac{x}{2 (1 + \sqrt{1 - x})},\quad x = \frac{R_j^2}{(R_i + R_j)^2}

    (the second form, free of cancellation when ``R_j << R_i``): the area fraction of the
    cap of sphere i inside the cone from its centre tangent to sphere j, the film on which
    forms the bridge. Source: Shi & McCarthy (2008), Powder Technol. 184, 64,
    ``V_i,b = c_ij V_i``; LIGGGHTS ``cohesion_model_easo_capillary_viscous.h``.
    ``radius_j = inf`` (a wall) gives 1/2.
    """
    ri = positive("radius_i", radius_i, "m")
    rj = np.asarray(radius_j, dtype=float)
    if np.any(np.isnan(rj)) or np.any(rj <= 0.0):
        rj = positive("radius_j", radius_j, "m")  # raises, naming the value
    with np.errstate(invalid="ignore"):
        x = np.where(np.isinf(rj), 1.0, (rj / (ri + rj)) ** 2)
    return x / (2.0 * (1.0 + np.sqrt(1.0 - x)))


def shi_mccarthy_fraction(radius1: Any, radius2: Any = None, liquid1: Any = None,
                          liquid2: Any = None) -> np.ndarray:
    r"""Shi & McCarthy's bridge rule read backwards: each body takes back its share.

    .. math:: f = \frac{c_{12} V_1}{c_{12} V_1 + c_{21} V_2},\qquad
              c_{ij} = \frac{1}{2}\left(1 - \sqrt{1 - \frac{R_j^2}{(R_i + R_j)^2}}\right)

    Interpretation: Shi & McCarthy (2008, Powder Technol. 184, 64) give the liquid each
    particle brings to a *new* bridge, ``V_i,b = c_ij V_i`` (:func:`shi_mccarthy_share`);
    their rule, and LIGGGHTS which implements it, split a *ruptured* bridge evenly
    (:func:`even_split_fraction`). Read as a rule for the division, the liquid of a
    ruptured bridge returns to the two bodies in the proportion in which they would form
    it, ``V_1,b : V_2,b``: the film on the cap of each body facing the other. It depends
    on the radius ratio (and on how much liquid each body carries), not on the angles.
    ``V_i`` is the liquid on particle i: by default films of equal thickness,
    ``V_i ~ R_i^2``, so that ``f = R_1^2 c_12/(R_1^2 c_12 + R_2^2 c_21)``: 1/2 for equal
    spheres, 2/3 on the smaller sphere for a very unequal pair and on a sphere facing a
    wall (``R_2 -> inf``: ``R_2^2 c_21 -> R_1^2/4``).

    Parameters
    ----------
    radius1, radius2
        Radii (m), > 0; ``radius2 = None`` for a wall.
    liquid1, liquid2
        Liquid carried by each body before the bridge formed (any common unit), > 0; both
        or neither (then equal film thickness). Not with a wall.

    Returns
    -------
    numpy.ndarray
        f on body 1.
    """
    r1, r2 = _radii(radius1, radius2)
    if (liquid1 is None) != (liquid2 is None) or (r2 is None and liquid1 is not None):
        raise InputError("shi_mccarthy_fraction: give both liquid1 and liquid2 (between two "
                         "spheres) or neither (films of equal thickness)")
    if r2 is None:
        return np.full(r1.shape, 2.0 / 3.0)
    if liquid1 is None:
        v1, v2 = r1**2, r2**2
    else:
        v1, v2 = positive("liquid1", liquid1), positive("liquid2", liquid2)
    b1 = shi_mccarthy_share(r1, r2) * v1
    b2 = shi_mccarthy_share(r2, r1) * v2
    return b1 / (b1 + b2)
