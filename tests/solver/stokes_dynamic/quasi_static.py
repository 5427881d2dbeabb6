"""Shared references of the stokes-dynamic tests: the quasi-static ``stokes`` bridge's
viscous force per unit speed, and the check that a static meniscus is at rest."""

from __future__ import annotations

import numpy as np
import pytest

from wetcontact.models import get_model
from wetcontact.scene import scene_from_dict
from wetcontact.solver.stokes_dynamic import Domain, Wetting, solve_step


def viscous_per_speed(gap: float, volume: float, theta_deg: float,
                      radius2: float | None = None) -> float:
    """The quasi-static ``stokes`` bridge's viscous force per unit separation speed, units
    eta R (R = 1 mm, eta = 1 mPa s, 0.1 m/s apart; slip lengths 1e-3 R on both solids):
    a sphere on a wall, or two spheres (``radius2`` = R2/R). ``gap`` S/R, ``volume``
    V/R^3."""
    R = 1e-3
    geometry = ({"kind": "sphere-wall", "radius": R} if radius2 is None
                else {"kind": "sphere-sphere", "radius": R, "radius2": radius2 * R})
    scene = scene_from_dict({
        "name": "dynamic-check", "geometry": geometry,
        "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
                   "contact_angle": theta_deg, "slip_length_sphere": 1e-3 * R,
                   "slip_length_wall": 1e-3 * R},
        "amount": {"bridge_volume": volume * R**3},
        "motion": {"velocity": -0.1, "gaps": [gap * R]}})
    return float(get_model("stokes").force(scene).force_viscous[0]) / (1e-3 * R * 0.1)


def assert_at_rest(dom: Domain, wet: Wetting, static_force: float) -> None:
    """One step at rest from a static meniscus (``dt`` 0 and 0.1): the force is the static
    one within 1e-5, the lower solid takes the opposite force, and the spurious velocity is
    below 1e-4 sigma/eta."""
    for dt in (0.0, 1e-1):
        sol = solve_step(dom, dt, 0.0, wet)
        assert sol.force == pytest.approx(static_force, rel=1e-5)
        assert sol.force_wall == pytest.approx(-sol.force, rel=1e-12)
        assert np.abs(sol.u).max() < 1e-4
