"""Axisymmetric Stokes flow by Taylor-Hood finite elements: the viscous-force reference
(level 3, model ``stokes``).

Layout: :mod:`.forms` (the weak forms), :mod:`.solve` (the discrete problem on one mesh, the
force on the sphere; the equations, boundary conditions and accuracy), :mod:`.bridge` (the
quasi-static liquid bridge: the meniscus' motion and the flow in it), :mod:`.model` (the
registered model: meshes, presets, films and bridges). Each imports only those before it.
The forms and :func:`facet_basis` are public for the moving free-surface bridge
(:mod:`wetcontact.solver.stokes_dynamic`), which assembles its own system from them.
"""

from wetcontact.solver.stokes.forms import divergence_form, navier_slip_form, viscous_form
from wetcontact.solver.stokes.model import (
    DEFAULT_SLIP,
    FILM_TOPS,
    MIN_BRIDGE_SLIP,
    MIN_GAP,
    RADIUS_RATIO,
    Stokes,
    container_factor,
)
from wetcontact.solver.stokes.solve import (
    StokesSolution,
    SurfaceMotion,
    facet_basis,
    gap_elements,
    pinned_dofs,
    solve_stokes,
)

__all__ = [
    "DEFAULT_SLIP",
    "FILM_TOPS",
    "MIN_BRIDGE_SLIP",
    "MIN_GAP",
    "RADIUS_RATIO",
    "Stokes",
    "StokesSolution",
    "SurfaceMotion",
    "container_factor",
    "divergence_form",
    "facet_basis",
    "gap_elements",
    "navier_slip_form",
    "pinned_dofs",
    "solve_stokes",
    "viscous_form",
]
