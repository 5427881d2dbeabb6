r"""Dynamic liquid bridge between a sphere and a wall, two equal spheres (the half above
the shear-free mid-plane, ``MeshOptions(plane="symmetry")``) or two unequal spheres (the
whole bridge, ``MeshOptions(radius2=...)``): free-surface Stokes flow at a finite capillary
number Ca = eta v / sigma; the registered model ``stokes-dynamic`` (:mod:`.model`).

Equations (units R = sigma = eta = 1; axisymmetric, meridian half-plane r >= 0):
``-div(-p I + 2 e(u)) = 0``, ``div u = 0`` in the liquid; on the free surface the traction
``sigma n = -kappa n`` (the weak Laplace-Beltrami form with its hoop term, :mod:`.step`),
the kinematic condition ``dx/dt . n = u . n``; Navier slip (lengths b) on the solids; the
contact angles as natural conditions at the lines (static, or Cox-Voinov's dynamic angle),
or pinned lines; the gap follows a given S(t).

Discretisation: Taylor-Hood P2/P1 on an ALE mesh of second-order triangles (scikit-fem),
variable-step BDF2 on a domain extrapolated to the new time with Baensch's (2001)
semi-implicit curvature (:data:`ORDER` = 2 in time, :data:`SPACE_ORDER` in the element
size; ``force[k]`` is the force at ``time[k]``),
volume restored each step, gmsh remeshing from the surface's own nodes with elements of
``w(z)/n_neck`` across the local radius w (small only at the neck), gmsh in a worker
process with a timeout (stop reason ``"mesh"``), steps controlled by the neck's local error
and its relative change per step, and the pinch located from the neck's late linear law
(:func:`locate_pinch`).

Accuracy (tests/solver/stokes_dynamic; V/R^3 = 1e-3, 20 deg, b = 1e-3 R, from S/R = 0.02):
a static meniscus is an equilibrium to 2e-6 in force; a perturbed bridge relaxes to it
(force 1e-5); volume kept to 1e-13; observed time order 2.0 (difference ratios 3.96, 4.04);
the O(Ca) force excess at Ca = 1e-3 is the quasi-static ``stokes`` force within 0.8 %; at
Ca = 1e-4 the force is ``meniscus`` plus Ca times ``stokes`` within 1.7e-5 up to S/R =
0.08 (1.4e-4 at 0.105, near the fold). The rupture distance (:mod:`.rupture`; V/R^3 =
1e-3, 30 deg, default preset): 1.1868 S_c at Ca = 1e-2 (S_c the static fold; Pitois:
1.10), 1.0254 at 1e-4, 1.00024 at 1e-8 (the delay past the fold falls like about 3
Ca^(1/2) S_c); the liquid each side of the pinch: :mod:`.division`. The neck's pinch-off
rate against Papageorgiou (1995): ``benchmarks/bench_pinch.py``.
Equal spheres: static force to 1e-6, O(Ca) excess 0.5 % from ``stokes``, rupture 1.165 S_c.
Unequal spheres (R and R/2 or 2R, 30 deg): static force to 7e-7, O(Ca) excess 0.45 % from
``stokes``; the whole bridge between equal spheres ruptures within 8e-5 of the half; spheres
R, 2R and R, R/2 (the same bridge scaled) agree on S_c(Ca)/S_c within 5e-6.

Contact lines: static angles (default), Cox-Voinov's dynamic angle or pinned lines
(:class:`.step.Wetting`; tests/solver/stokes_dynamic/test_stokes_dynamic_lines.py).

Limits: angles up to 30 deg between spheres (:data:`.rupture.PAIR_THETA_MAX`), R2/R in
0.1-10; Ca up to 0.3 (:mod:`.rupture`).

Sources: Baensch (2001, Numer. Math. 88, 203), semi-implicit curvature; Ganesan & Tobiska
(2008), the axisymmetric Laplace-Beltrami form; Navier (1823); Pitois, Moucheront &
Chateau (2001), the dynamic rupture law; Papageorgiou (1995), viscous pinch-off.
"""

from wetcontact.solver.stokes_dynamic.domain import Domain, MeshOptions
from wetcontact.solver.stokes_dynamic.pinch import PAPAGEORGIOU, Pinch, locate_pinch
from wetcontact.solver.stokes_dynamic.run import (
    ORDER,
    DynamicRun,
    Stepping,
    run,
    static_profile,
)
from wetcontact.solver.stokes_dynamic.rupture import (
    RuptureCase,
    RuptureResult,
    dynamic_rupture,
)
from wetcontact.solver.stokes_dynamic.step import StepSolution, Wetting, solve_step

SPACE_ORDER = 1.4
"""Observed order of the force in the element size (every size of :class:`MeshOptions`
scaled together; sphere-wall, V/R^3 = 1e-3, 20 deg, slip 1e-3 R, Ca = 1e-2 at S/R =
0.02): successive differences fall at 1.48 and 1.41 over four meshes, each halving the
sizes, from 155 to 3 382 elements. Taylor-Hood's order 3 for smooth flow is limited by the
contact lines, wedge corners of a slip wall and a free surface where the flow is singular.
At the default mesh the force is within 1.0e-5 of the finest's (relative 2.7e-6)."""

__all__ = [
    "ORDER",
    "PAPAGEORGIOU",
    "Domain",
    "DynamicRun",
    "MeshOptions",
    "Pinch",
    "RuptureCase",
    "RuptureResult",
    "SPACE_ORDER",
    "dynamic_rupture",
    "StepSolution",
    "locate_pinch",
    "Stepping",
    "Wetting",
    "run",
    "solve_step",
    "static_profile",
]
