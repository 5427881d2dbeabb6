r"""Finite-element Young-Laplace liquid bridge: the capillary reference (model ``meniscus``).

The static, axisymmetric liquid bridge between a sphere and a wall, or between two spheres
of unequal radii (and, for analytic checks, two parallel plates), with a contact angle on
each solid; volume-controlled (given V) or suction-controlled (given the Laplace pressure,
:class:`SuctionBridges`).

The meridian ``(r(s), z(s))``, ``s`` the arc length from the lower contact line to the one
on sphere 1, ``psi`` the tangent angle, obeys Young-Laplace (liquid on the axis side,
``dp = p_liquid - p_gas``, optional gravity along ``-z``):

.. math::
    r' = \cos\psi,\quad z' = \sin\psi,\quad
    \psi' = \frac{\Delta p - \rho g z}{\sigma} - \frac{\sin\psi}{r},

with the contact lines unknown (on sphere 1 ``psi = phi1 + theta1``, on sphere 2
``psi = pi - phi2 - theta2``, on the wall ``psi = pi - theta_w``) and the volume
``V = int pi r^2 dz - V_cap(phi1, R1) - V_cap(phi2, R2)`` closing the system with ``dp``
as its multiplier. Discretisation: continuous P2 fields in ``t = s/L`` tested with
discontinuous P1 under the two-point Gauss rule (two-stage Gauss collocation, order 4;
Hairer, Norsett & Wanner, *Solving ODEs I*, II.7), solved by Newton with a line search.

Force (Lambert et al. 2008): the first integral ``G = 2 pi sigma r sin(psi) - pi r^2 (dp -
rho g z)``, evaluated at both contact lines and the neck (their spread is a self-check).
Rupture: pseudo-arclength continuation in S from contact to the fold ``dS = 0``, or,
between equal spheres with equal angles, the symmetry-breaking bifurcation before it
(``diagnostics.rupture``); stability by the sign change of ``det J`` (Maddocks 1987,
Arch. Ration. Mech. Anal. 99, 301).

Domain: V/R^3 >= 2e-11, contact angles up to 150 deg, half-filling angle at contact up to
70 deg. Accuracy: within 4e-8 of an independent ODE shooting (rupture 6e-8), V* 1e-4 to
0.2, 0-60 deg; declared order 4. Formulation in full: the guide's *Solver notes*
(``docs/solvers.md``).

Layout: :mod:`.geometry`, :mod:`.young_laplace`, :mod:`.guess`, :mod:`.continuation`,
:mod:`.post`, :mod:`.solve` (the public solves), :mod:`.suction` (the public
suction-controlled API), :mod:`.division` (liquid division at rupture), :mod:`.model`.
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
