r"""Thin-film solver: a sphere squeezing a liquid layer with a free surface (level 2).

Modules: :mod:`.problem` (the film problem: grid, mobility, pressure, wetting),
:mod:`.forces` (force split of a state), :mod:`.integrate` (BDF2/Newton stepper, error
control, inertia; scipy BDF), :mod:`.leveling` (free-film references: J0 leveling rate,
stable time steps), :mod:`.sharp` (the sharp wetting contact, the default: the
finite-element meniscus joined to the film), :mod:`.model` (the registered ``thinfilm``
Model).

Physics
-------
A liquid film of thickness :math:`\delta` lies on a wall; a rigid sphere of radius R
approaches it at speed v(t) (positive = approach). Under the lubrication approximation
(:math:`\delta \ll R`, small slopes) the liquid is described by one field, the thickness
h(r, t) of liquid on the wall, obeying the conservation law

.. math::
    \partial_t h + \frac{1}{r}\partial_r (r q) = 0, \qquad q = -M(h)\, \partial_r p,

with the mobility of a film with a no-slip wall and a stress-free surface,
:math:`M = h^3/(3\eta)`, where the surface is free, and of a gap with no slip on wall and
sphere, :math:`M = g^3/(12\eta)`, where the liquid fills the gap. The sphere is an obstacle:
:math:`h \le g(r, t) = S(t) + r^2/(2R)` (parabolic gap; or the exact sphere gap
:math:`S + R - \sqrt{R^2 - r^2}`), :math:`dS/dt = -v`. The pressure is

.. math::
    p = -\sigma \nabla^2 h + \rho g_{\rm acc} h + p_c, \qquad
    p_c = k\,\max(0, h - g), \quad k = \frac{P_{\rm ref}(S)}{\varepsilon S},\quad
    P_{\rm ref} = \frac{3\eta v R}{S^2} + \frac{\sigma}{R} + \rho g_{\rm acc}\delta,

i.e. the Laplace pressure of the free surface (small-slope curvature), hydrostatics, and a
penalty contact pressure that keeps the liquid out of the sphere. :math:`P_{\rm ref}` is
the pressure scale at the centre (Reynolds, :math:`p(0) \approx 3\eta v R/S^2`), so the
penalty lets the liquid penetrate the sphere by a relative amount of order
:math:`\varepsilon` (the one numerical parameter of the contact formulation; the
tests show the force converging as :math:`\varepsilon \to 0`, first order).
Where the liquid touches the sphere the total p is the physical lubrication
pressure; the split into a "Laplace" and a "contact" part has no meaning there. The
mobility switches to the confined value on the faces where the face thickness reaches the
gap (a C1 ramp over :math:`g(1-\varepsilon) \le h \le g`, which vanishes with the
penalty), and uses :math:`\min(h, g)` so the penetration does not bias the flux.

Contact at the wetted edge (setting ``contact``):

- ``"sharp"`` (default, :mod:`.sharp`): the contact line is sharp and the meniscus is the
  full Young-Laplace surface. The liquid under the sphere is split at the foot a(t), the
  minimum of the liquid surface around the sphere: inside it a quasi-static
  finite-element bridge (:mod:`wetcontact.solver.meniscus`) of uniform pressure p_e from
  its contact line on the sphere (angle theta_s, wetted radius r_c an unknown) down to the
  film at height h_b, which it meets tangentially, with the Reynolds squeeze flow in the
  wetted gap (viscous part in closed form); outside it the film equation above with
  h'(a) = 0, p(a) = p_e, on a grid moving with a (arbitrary Lagrangian-Eulerian). The
  liquid volume closes the system to round-off. No penalty, no wetting width: no
  regularisation parameter; the wetted zone is not gridded, so every gap S > 0 is
  resolved. Checked in the tests against an independent shooting bridge of the same
  volume and, in the slow approach, against the finite-element bridge on the bare wall
  holding the same wetted volume (figures: ``benchmarks/bench_thinfilm.py``). Needs
  theta_s < 90 deg (a sucking meniscus); the inner meniscus is quasi-static with the
  static contact angle, so its capillary part carries an error of order
  Ca = eta v/sigma.
- ``"meniscus"``: a wetting liquid, regularised (with the penalty obstacle). Where the
  liquid fills the gap it replaces the free surface and the dry sphere by a wetted
  sphere, a free-energy gain :math:`W = \sigma(\cos\theta_s + \cos\theta_w)` per unit
  area (Young), added as
  :math:`E_w = -\int W f(h/g)\,dA` with f the wetted fraction, a C1 step over
  :math:`1 - \lambda \le h/g \le 1` (``wetting_width`` lambda, the one numerical
  parameter of this contact; a diffuse-interface regularisation in the spirit of
  disjoining-pressure contact-angle models, Schwartz & Eley 1998, J. Colloid Interface
  Sci. 202, 173). Its pressure :math:`p_w = -W f'(h/g)/g` is the matched inner
  meniscus: filling the gap at the edge over dA takes the volume :math:`(g - h_o)dA`,
  so the edge pressure is
  :math:`-W/(g - h_o)`, the two-plate Laplace pressure of a meniscus spanning the local
  gap (Fisher 1926). theta_s is the scene's sphere angle; on the film side theta_w = 0
  (the wall under a film is wet; ``wall_angle = "scene"`` uses the scene's wall angle).
  The capillary force is then suction. As :math:`\lambda \to 0` the zone collapses to a
  sharp contact line where the film leaves the sphere with the slope jump
  :math:`\sqrt{2W/\sigma}` (the small-slope Young condition of an adhesive obstacle
  problem); the model converges to that limit at first order in lambda when the grid
  resolves the zone (:func:`auto_cells`, cells ~ sqrt(R/delta)/lambda). Model error,
  apart from lambda: the small-slope film cannot represent the inner meniscus, whose
  slopes are of order one (the reason for ``"sharp"``).
  With
  :math:`\theta_s = \pi, \theta_w = 0` (W = 0) the dynamics are exactly those of the
  tangential contact.
- ``"tangential"``: the film meets the sphere tangentially (h = g and h' = g' at the
  wetted radius), the only contact a graph :math:`h(r) \le g(r)` with small slopes can
  make without an inner region: a non-wetting (180 deg) contact, contact angles unused;
  its capillary part is the rim's positive Laplace pressure.

Force on the sphere (axial, positive = pushing the surfaces apart):

.. math::
    F = 2\pi \int_0^{r_w} p\, r\, dr = F_{\rm cap} + F_{\rm visc},\qquad
    F_{\rm cap} = \pi r_w^2\, p(r_w),\qquad F_{\rm visc} = 2\pi\int_0^{r_w} (p - p(r_w))\,r\,dr,

the capillary part being the meniscus (Laplace) pressure at the wetted edge acting on the
wetted area (negative = suction), the viscous part the squeeze pressure above it. Limits
(PHYSICS.md sections 1 and 3): in the slow limit (capillary number
:math:`Ca^* = 3\eta v R^2/(\sigma\delta^2)` small) the film stays flat and the wetted
zone obeys the Reynolds equation, :math:`F_{\rm visc} = 6\pi\eta v\int_0^{r_w} r^3/g^3 dr`;
in the fast limit the squeezed liquid piles up at the contact line,
:math:`r_w \to \sqrt{4R(\delta - S)}` and
:math:`F \to 6\pi\eta R^2 v/S\,(1 - S/H)^2`, :math:`H = 2\delta - S` (Pitois et al. 2000).
A small J0(k r) mode of a flat film decays at :math:`\sigma\delta^3k^4/(3\eta)` (+
:math:`\rho g\delta^3 k^2/(3\eta)`).

Numerics
--------
Penalty contacts (the sharp contact's numerics: :mod:`.sharp`): conservative finite volumes
on [0, L], L = ``domain_factor`` times the pile-up wetted radius :math:`\sqrt{4R\delta}`:
uniform cells of width dr, or (the presets) a graded grid with the uniform fine cells out
to ``fine_factor`` times :math:`\sqrt{4R\delta}` (the contact zone and the whole path of
the contact line) and cells growing by 3 % beyond (:func:`graded_faces`); py-pde's
:class:`~pde.grids.PolarSymGrid` only carries the cell values for its solvers. The
Laplacian and the flux are built on cell faces, so :math:`\sum_i V_i\,\dot h_i = 0` to
round-off and the liquid volume is conserved by any linear multistep/Newton integrator.
Boundary conditions: symmetry at r = 0; h' = 0 and zero flux at r = L (a closed dish, large
enough that the displaced volume raises the far film by under 3 % of :math:`\delta` at the
default size). Declared spatial order 2 (force and decay rate). Time integration: py-pde's
:class:`~pde.solvers.ScipySolver` with BDF and the pentadiagonal Jacobian sparsity pattern
(implicit, stable far beyond the explicit limit :math:`\Delta t \propto dr^4`); py-pde's
explicit Euler/RK and fixed-point implicit Euler are kept for the stability comparison,
together with :func:`newton_euler_step`, a backward-Euler step solved by Newton's method on
the same sparse Jacobian. The default integrator is :func:`implicit_run`: variable-step
BDF2 with Newton on the banded Jacobian and the gap S as the clock; it also couples the
sphere's inertia, m dv/dt = -F.

Honest limits (penalty contacts; the sharp contact integrates the wetted zone in closed
form): the squeeze pressure at gap S lives within :math:`r \lesssim \sqrt{2RS}`;
a preset refuses gaps where this spans fewer than 4 cells (:func:`smallest_resolved_gap`,
``ValidityError`` naming ``lubrication``). The error estimate of the model compares the run
with a second one at half the contact resolution (lambda doubled) and scales the
difference as Richardson's estimate for the observed order, with a safety factor.

Declared order: 2, measured in :meth:`ThinFilm.convergence_data` on the decay rate of a
J0 mode against the analytic leveling rate (the spatial operator's order against an exact
reference, cheap enough for the generic test). The work-precision of the force along a
full penetration (in lambda and in the cells) is measured by
``benchmarks/bench_thinfilm.py`` (``benchmarks/results/thinfilm.json``).

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
