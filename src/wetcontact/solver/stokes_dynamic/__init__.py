r"""Dynamic liquid bridge between a sphere and a wall (issue 57; not yet a registered model):
free-surface Stokes flow at a finite capillary number Ca = eta v / sigma.

Equations (units R = sigma = eta = 1; axisymmetric, meridian half-plane r >= 0):
``-div(-p I + 2 e(u)) = 0``, ``div u = 0`` in the liquid; on the free surface Gamma the
traction ``sigma n = -kappa n`` (kappa the total curvature, weakly: the Laplace-Beltrami
form with its hoop term, :mod:`.step`), no tangential traction, and the kinematic condition
``dx/dt . n = u . n``; on the solids the normal velocity of the solid and Navier slip
(lengths b); at each contact line the static contact angle as the natural condition of the
free energy ``A - cos theta A_wet``. The sphere's gap follows a prescribed history S(t).

Discretisation: Taylor-Hood P2/P1 on an ALE mesh of second-order triangles (scikit-fem;
the forms of :mod:`wetcontact.solver.stokes`), surface tension at the new position
(Baensch 2001) on a domain extrapolated to the new time, BDF2 in time (declared order 2,
:data:`ORDER`; the force of a step is the force at its end time), volume
restored every step by a normal shift of the surface, gmsh remeshing from the surface when
the elements degrade (:mod:`.run`). Initial shape: the static meniscus
(:mod:`wetcontact.solver.meniscus`) at the start gap, or any given meridian.

Accuracy (tests/solver/stokes_dynamic; V/R^3 = 1e-3, 20 deg, b = 1e-3 R, S/R = 0.02-0.03):
a static meniscus is an equilibrium to 2e-6 in force; a perturbed bridge relaxes to it
(force 1e-5, neck 3e-7, shape 2e-6 R); volume kept to 1e-13 relative, remeshing included;
the O(Ca) force excess at Ca = 1e-3 is the quasi-static ``stokes`` viscous force within
0.8 % (-25.90 against -25.7 at dt = 0.1 and 0.2 eta R/sigma, which agree to 4e-5);
observed time order 2.0 (ratios 4.0 of successive differences).

Limits (what is not done yet): two spheres; the pinch itself (remeshing refines the whole
mesh to the neck's size, so a neck below about 0.02 R costs minutes; the rupture distance
and Papageorgiou's law are not checked); a dynamic contact angle; SI units, a
:class:`~wetcontact.models.Model` and the store.

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
from wetcontact.solver.stokes_dynamic.step import StepSolution, Wetting, solve_step

__all__ = [
    "ORDER",
    "PAPAGEORGIOU",
    "Domain",
    "DynamicRun",
    "MeshOptions",
    "Pinch",
    "StepSolution",
    "locate_pinch",
    "Stepping",
    "Wetting",
    "run",
    "solve_step",
    "static_profile",
]
