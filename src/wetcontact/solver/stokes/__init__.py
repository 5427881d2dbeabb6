"""Axisymmetric Stokes flow by Taylor-Hood finite elements (model ``stokes``): a package,
:mod:`.solve` for now (being split into forms, solve and model)."""

from wetcontact.solver.stokes.solve import *  # noqa: F403
from wetcontact.solver.stokes.solve import (  # noqa: F401
    MIN_GAP,
    Stokes,
    StokesSolution,
    container_factor,
    gap_elements,
    solve_stokes,
)
