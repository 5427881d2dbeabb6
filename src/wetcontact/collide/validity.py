"""Where a collision's physics stops: each note names the model that would apply."""

from __future__ import annotations

import math

from wetcontact.collide.case import CollisionCase

#: squeeze-flow Reynolds number above which the film's inertia matters
REYNOLDS_LIMIT = 1.0
#: elasticity parameter above which the surfaces deform before they touch
ELASTICITY_LIMIT = 1.0


def squeeze_reynolds(case: CollisionCase, gap: float) -> float:
    """Reynolds number of the squeeze flow at ``gap``: ``rho v r_w / eta (S / r_w)`` with
    the lubrication radius ``r_w = sqrt(2 R* S)``, i.e. ``rho v S^(3/2) / (eta sqrt(2 R*))``
    (the inertia of the radial flow against its viscous stress)."""
    sc = case.scene
    return sc.density * case.impact.velocity * gap ** 1.5 / (
        sc.viscosity * math.sqrt(2.0 * sc.reduced_radius))


def elasticity_parameter(case: CollisionCase, gap: float) -> float | None:
    """``eps = 4 theta eta v0 R*^(3/2) / x0^(5/2)``, theta = sum (1 - nu_i^2)/(pi E_i)
    (Davis, Serayssol & Hinch 1986), at the gap ``x0``; None without Young's moduli."""
    s1, s2 = case.solid, case.solid2
    if s1.youngs_modulus is None or s2.youngs_modulus is None:
        return None
    theta = ((1 - s1.poisson_ratio ** 2) / (math.pi * s1.youngs_modulus)
             + (1 - s2.poisson_ratio ** 2) / (math.pi * s2.youngs_modulus))
    sc = case.scene
    return 4.0 * theta * sc.viscosity * case.impact.velocity * sc.reduced_radius ** 1.5 / (
        gap ** 2.5)


def validity_notes(case: CollisionCase, start_gap: float) -> list[str]:
    """Notes where the collision leaves the physics it models (empty inside it)."""
    notes = []
    sc = case.scene
    re = squeeze_reynolds(case, start_gap)
    if re > REYNOLDS_LIMIT:
        notes.append(f"squeeze-flow Reynolds number {re:.3g} > {REYNOLDS_LIMIT:g} at the start "
                     "gap: the liquid's inertia is left out (quasi-steady Stokes forces); a "
                     "Navier-Stokes film model applies")
    eps = elasticity_parameter(case, case.roughness)
    if eps is not None and eps > ELASTICITY_LIMIT:
        notes.append(f"elasticity parameter {eps:.3g} > {ELASTICITY_LIMIT:g} at the roughness "
                     "gap: the surfaces deform before they touch; an elastohydrodynamic "
                     "model applies (Davis, Serayssol & Hinch 1986)")
    if sc.amount == "film" and float(sc.film_thickness) > sc.radius:
        notes.append("film thicker than the sphere's radius: the sphere is immersed, not "
                     "squeezing a film; use amount.immersed")
    if sc.amount == "immersed" and not case.impact.added_mass:
        notes.append("immersed without added mass: the liquid's inertia "
                     "(rho_f V/2) is left out; set impact.added_mass")
    return notes
