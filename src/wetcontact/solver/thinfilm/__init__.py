r"""Thin-film solver: a sphere squeezing a liquid layer with a free surface (level 2).

A film of thickness :math:`\delta` lies on a wall; a rigid sphere of radius R approaches it
at speed v (positive = approach). In the lubrication approximation (:math:`\delta \ll R`,
small slopes) the film thickness h(r, t) obeys

.. math::
    \partial_t h + \frac{1}{r}\partial_r (r q) = 0, \qquad q = -M(h)\, \partial_r p,
    \qquad p = -\sigma \nabla^2 h + \rho g_{\rm acc} h,

with :math:`M = h^3/(3\eta)` under a free surface and :math:`M = g^3/(12\eta)` in the gap
:math:`g = S + r^2/(2R)` (or the exact sphere gap), :math:`dS/dt = -v`. The force on the
sphere is :math:`F = 2\pi\int_0^{r_w} p\,r\,dr = F_{\rm cap} + F_{\rm visc}`,
:math:`F_{\rm cap} = \pi r_w^2 p(r_w)` (negative = suction).

Contact at the wetted edge (``contact``): ``"sharp"`` (default, :mod:`.sharp`): the
finite-element Young-Laplace meniscus joined to the film at its foot, Reynolds flow in the
wetted gap, no regularisation parameter; needs theta_s < 90 deg, error of order
Ca = eta v/sigma from the quasi-static meniscus. ``"meniscus"``: a wetting liquid with a
penalty obstacle and a diffuse wetting zone of width lambda (first order in lambda;
Schwartz & Eley 1998). ``"tangential"``: a non-wetting (180 deg) tangential contact.

Numerics: conservative finite volumes on a graded grid (:func:`graded_faces`), volume
conserved to round-off; variable-step BDF2 with Newton on the banded Jacobian, the gap as
the clock, the sphere's inertia coupled (:func:`implicit_run`); py-pde's solvers kept for
comparison. Domain: presets refuse gaps whose squeeze zone spans fewer than 4 cells
(:func:`smallest_resolved_gap`). Declared order 2, on the decay rate of a J0 mode against
the analytic leveling rate (:meth:`ThinFilm.convergence_data`). Accuracy (sharp contact,
water case): the presets within 0.03 % of each other, ``error_estimate`` 0.3 % (default),
2.1 % (fast); ``benchmarks/bench_thinfilm.py``.

Modules: :mod:`.problem`, :mod:`.forces`, :mod:`.integrate`, :mod:`.leveling`,
:mod:`.sharp`, :mod:`.model` (the registered ``thinfilm``). The full formulation, limits
and checks: the guide's *Solver notes* (``docs/solvers.md``).

Sources: Oron, Davis & Bankoff (1997) Rev. Mod. Phys. 69, 931 (thin-film equation);
Pitois, Moucheront & Chateau (2000) J. Colloid Interface Sci. 231, 26 (finite-liquid
squeeze force); Kikuchi & Oden (1988) "Contact problems in elasticity" (penalty method).
"""

from wetcontact.solver.thinfilm.forces import Snapshot, snapshot
from wetcontact.solver.thinfilm.integrate import (
    RunResult,
    ThinFilmPDE,
    implicit_run,
    newton_euler_step,
    penetration_run,
)
from wetcontact.solver.thinfilm.leveling import (
    bessel_mode_decay,
    explicit_stable_dt,
    implicit_stable_dt,
    leveling_problem,
)
from wetcontact.solver.thinfilm.model import (
    CA_MAX,
    CA_STAR_MAX,
    CELLS_ACROSS_CONTACT,
    CELLS_PER_WIDTH,
    DELTA_OVER_R_MAX,
    ThinFilm,
    auto_cells,
    problem_from_scene,
    reduced_capillary_number,
    smallest_resolved_gap,
    sphere_mass,
    validity_reason,
)
from wetcontact.solver.thinfilm.problem import FilmProblem, graded_cells, graded_faces
from wetcontact.solver.thinfilm.sharp import InnerMeniscus, SharpFilm, sharp_run

_leveling_problem = leveling_problem  # old private name, still used by tables/thinfilm.py

__all__ = [
    "CA_MAX", "CA_STAR_MAX", "CELLS_ACROSS_CONTACT", "CELLS_PER_WIDTH", "DELTA_OVER_R_MAX",
    "FilmProblem", "InnerMeniscus", "RunResult", "SharpFilm", "Snapshot", "ThinFilm",
    "ThinFilmPDE", "auto_cells",
    "bessel_mode_decay", "explicit_stable_dt", "graded_cells", "graded_faces", "implicit_run",
    "implicit_stable_dt", "leveling_problem", "newton_euler_step", "penetration_run",
    "problem_from_scene", "reduced_capillary_number", "sharp_run", "smallest_resolved_gap",
    "snapshot",
    "sphere_mass", "validity_reason",
]
