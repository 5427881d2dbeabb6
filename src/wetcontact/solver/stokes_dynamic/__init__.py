"""Dynamic liquid bridge (model ``stokes-dynamic``, work in progress): free-surface Stokes
flow at a finite capillary number Ca = eta v / sigma.

Placeholder docstring: completed below once the solver is checked.
"""

from wetcontact.solver.stokes_dynamic.domain import Domain, MeshOptions
from wetcontact.solver.stokes_dynamic.run import (
    ORDER,
    DynamicRun,
    Stepping,
    run,
    static_profile,
)
from wetcontact.solver.stokes_dynamic.step import StepSolution, Wetting, solve_step

__all__ = [
    "ORDER",
    "Domain",
    "DynamicRun",
    "MeshOptions",
    "StepSolution",
    "Stepping",
    "Wetting",
    "run",
    "solve_step",
    "static_profile",
]
