r"""Finite-element Young-Laplace liquid bridge: the capillary reference (model ``meniscus``).

The static, axisymmetric liquid bridge between a sphere and a wall, or between two spheres
of unequal radii (and, for analytic checks, between two parallel plates), with a contact
angle on each solid; volume-controlled (given V) or suction-controlled (given the Laplace
pressure).

Equations
---------
The meridian is the curve ``(r(s), z(s))``, ``s`` the arc length from the contact line on
the lower solid (a wall at ``z = 0`` or sphere 2, centre ``(0, -R2)``) to the contact line on
sphere 1 (centre ``(0, S + R1)``), ``psi`` the angle of the tangent. Young-Laplace
(PHYSICS.md section 2, liquid on the axis side, pressure ``dp = p_liquid - p_gas``,
``Bo = rho g l^2 / sigma`` for an optional gravity along ``-z``):

.. math::
    r' = \cos\psi,\quad z' = \sin\psi,\quad
    \psi' = \frac{\Delta p - \rho g z}{\sigma} - \frac{\sin\psi}{r}.

Boundary conditions (contact lines are unknowns): on sphere 1 at half-filling angle
``phi1``: ``r = R1 sin phi1``, ``z = S + R1 (1 - cos phi1)``, ``psi = phi1 + theta1``; on
sphere 2 at ``phi2``: ``r = R2 sin phi2``, ``z = -R2 (1 - cos phi2)``,
``psi = pi - phi2 - theta2``; on the wall at wetted radius ``r_w``: ``z = 0``,
``psi = pi - theta_w``. The volume constraint

.. math:: V = \int \pi r^2 \, dz - V_{cap}(\phi_1, R_1) - V_{cap}(\phi_2, R_2),\qquad
          V_{cap}(\phi, R) = \pi R^3 (1-\cos\phi)^2 (2+\cos\phi)/3,

closes the system with ``dp`` as its multiplier (or ``dp`` is given: suction control).

Discretisation
--------------
The normalised arc length ``t = s/L`` in [0, 1] (``L`` an unknown) is meshed with
scikit-fem's :class:`~skfem.MeshLine`; ``r``, ``z``, ``psi`` are continuous P2 fields
(:class:`~skfem.ElementLineP2`) and the first-order system is tested with discontinuous P1
functions under the two-point Gauss rule (a continuous Petrov-Galerkin cG(2)/dG(1) method,
equivalent to two-stage Gauss collocation). Its nodal values converge at order 4
(Hairer, Norsett & Wanner, *Solving ODEs I*, sec. II.7); the force, the pressure and the
filling angles inherit it. The unknowns ``(r, z, psi, L, dp, phi1, phi2|r_w, S)`` are
solved by Newton's method with a backtracking line search on a sparse Jacobian.

Force (PHYSICS.md section 2, Lambert et al. 2008): the axial cut force
``G = 2 pi sigma r sin(psi) - pi r^2 (dp - rho g z)`` is a first integral (with gravity
``dG/dz = rho g pi r^2``). It is evaluated at the contact line on sphere 1, at the lower
contact line and at the neck (where ``psi = pi/2``, from a quintic Hermite reconstruction
through the order-4 vertex values); their relative spread is reported as a self-check.
The free energy is ``E = sigma (A - cos(theta1) A1 - cos(theta2) A2)`` (A the liquid-gas
area, A1, A2 the wetted solid areas); ``dE/dS`` at fixed V is computed by implicit
differentiation of the discrete system.

Rupture and stability
---------------------
The force-separation curve is followed by pseudo-arclength continuation in ``S`` from
``S = 0``; rupture is the turning point ``dS = 0`` (located to machine precision as the
root of ``dS/dphi1`` on the branch). By Maddocks (1987, Arch. Ration. Mech. Anal. 99, 301)
the number of negative eigenvalues of the constrained second variation (axisymmetric
perturbations, fixed volume) changes by one exactly at a simple fold of this branch, which
is where ``det J`` changes sign; ``stability`` is +1 on the branch connected to ``S = 0``
before the fold and -1 after it.

Layout: :mod:`.geometry` (solids), :mod:`.young_laplace` (residual, Jacobian, closings,
Newton), :mod:`.guess` (the toroidal guess), :mod:`.continuation` (volume- and
suction-controlled, folds, stability), :mod:`.post` (forces, extras, profile), :mod:`.solve`
(the public solves), :mod:`.suction` (the public suction-controlled API,
:class:`SuctionBridges`), :mod:`.model` (the registered model).
"""

from wetcontact.solver.meniscus.geometry import DEFAULT_ELEMENTS, PHI_MAX, THETA_MAX, Bridge
from wetcontact.solver.meniscus.model import MeniscusModel
from wetcontact.solver.meniscus.post import (
    BridgeSolution,
    energy_derivative,
    meniscus_profile,
    shape_rate,
)
from wetcontact.solver.meniscus.solve import (
    SeparationCurve,
    force_separation_curve,
    rupture_distance,
    solve_suction,
    solve_volume,
)
from wetcontact.solver.meniscus.suction import SuctionBridges

__all__ = [
    "DEFAULT_ELEMENTS",
    "PHI_MAX",
    "THETA_MAX",
    "Bridge",
    "BridgeSolution",
    "SeparationCurve",
    "MeniscusModel",
    "SuctionBridges",
    "energy_derivative",
    "force_separation_curve",
    "meniscus_profile",
    "rupture_distance",
    "shape_rate",
    "solve_suction",
    "solve_volume",
]
