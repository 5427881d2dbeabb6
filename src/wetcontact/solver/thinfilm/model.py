"""The ``thinfilm`` Model: validity, presets, resolution and the force curve of a scene."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from wetcontact.errors import InputError, SolverError, ValidityError
from wetcontact.models import ForceCurve, Model, register
from wetcontact.scene import Scene
from wetcontact.solver.thinfilm.integrate import RunResult, implicit_run, penetration_run
from wetcontact.solver.thinfilm.leveling import bessel_mode_decay, leveling_problem
from wetcontact.solver.thinfilm.problem import FilmProblem, graded_cells
from wetcontact.solver.thinfilm.sharp import SharpFilm, sharp_run

# ---- validity limits (measured, see tables/thinfilm.py and the benchmark) ---------
DELTA_OVER_R_MAX = 0.12
"""Largest film thickness delta/R: the sphere slope at the pile-up wetted radius,
sqrt(4 delta/R), stays below 0.7 (lubrication error of order slope^2 ~ 0.5^2)."""
CA_MAX = 1.0
"""Largest capillary number eta v/sigma: the pile-up rim slope grows like (3 Ca)^(1/4)
(rim width delta (3 Ca)^(-1/4)), small slopes fail beyond Ca ~ 1."""
CA_STAR_MAX = 2.0e5
"""Largest reduced capillary number Ca* = 3 eta v R^2/(sigma delta^2) the default grid
resolves: the rim width sqrt(R delta) Ca*^(-1/4) must span several cells."""
CA_STAR_MIN_SHARP = 1.0e-4
"""Smallest Ca* the sharp contact takes. Below it the film relaxes much faster than the
sphere moves and its Newton steps fail until the step size underflows: measured on the
water case (R = 1 mm, theta 20 deg, gaps 5e-5 and 1e-6 m, fast and default presets) it
failed at Ca* = 8.3e-6, 2.1e-5 (delta = 0.1 mm) and 2.9e-5 (0.12 mm) and ran at 4.2e-5;
the slow-approach study runs down to 2e-4 (within 0.1 % of the FE bridge holding the
wetted volume there). The limit keeps a margin over the largest failure."""


CELLS_PER_WIDTH = 115.0
"""Resolution constant of :func:`auto_cells` (cells = 115 sqrt(R/delta)/lambda for the
default domain): 3600 cells at lambda = 0.1 on the water case, where doubling them moves
the force by under 0.3 %."""

CELLS_ACROSS_CONTACT = 4
"""Cells the contact zone r < sqrt(2 R S) must span at the smallest gap (see
:func:`smallest_resolved_gap`). Measured on the water case (fast preset, rtol 1e-4, S down
to 1e-10 m): the viscous part of the wetted zone against the Reynolds quadrature of the
same wetted radius is within 0.16 % at 4.3 cells, 0.3 % at 2.4, 1.6 % at 1.4, and falls
to -22 % and -42 % below one cell."""

SMALLEST_GAP_OVER_DELTA = 2.0e-3
"""Smallest gap S/delta the penalty contact resolves at any preset. Below about 1e-3 delta
the step control (which bounds the error of h) lets the penalty pressure k (h - g) err by up
to rtol/eps = 10 %: on the water case (default preset) the viscous force jumped by +28 to
+258 % between output gaps below 1.2e-7 m = 1.2e-3 delta, and once by +26 % at 9e-8 m. A
step tolerance relative to the penetration fixes it but was over 10x slower; until then
such gaps are refused (naming ``lubrication``) instead of returned wrong."""

ORDER_OF_CONTACT = {"meniscus": 1.0, "tangential": 0.7, "sharp": 1.0}
"""Convergence order of the force in the contact resolution (wetting width lambda for the
meniscus, dr for the tangential contact; measured by the benchmark, 1.13 and 0.7): the
two-resolution error estimate divides F(2x) - F(x) by 2^p - 1. The sharp contact's
companion run halves the film cells and the bridge's elements and relaxes rtol tenfold at
once; p = 1 there is a conservative declaration (its film is second order in space and
time, its bridge fourth order)."""

FIRST_DIP = 1e-2
"""The sharp contact's run starts at S = delta (1 - FIRST_DIP) from the flat film with the
zero-volume bridge (an initial condition, not a regularisation: the meniscus forms within
the first step). Measured on the water case (40 gaps, default resolution): against a start
at 1e-3 the force differs by 0.31 %, 0.085 %, 0.018 % at dips 3e-2, 1e-2, 3e-3 (at the first
gap after touch; under 0.02 % below S = 0.5 delta), order about 1.2. The error estimate's
companion run starts at 3 FIRST_DIP, so the estimate covers it (0.34 % there)."""

CONTACTS = ("sharp", "meniscus", "tangential")
"""``sharp`` (default): the quasi-static finite-element meniscus joined to the film at its
minimum (:mod:`.sharp`); ``meniscus``: the regularised wetting energy of width lambda;
``tangential``: the non-wetting tangential contact (both penalty obstacles)."""

SAFETY_FACTOR = 1.5
"""Factor on the two-resolution (Richardson) error estimate, as in Roache's grid
convergence index (J. Fluids Eng. 116, 405, 1994: 1.25 with three grids, 3 with two).
Checked per gap against the lambda -> 0 extrapolation of the water case by the benchmark:
at lambda = 0.05 (default) the estimate is at least 1.8 times the actual error; at
lambda = 0.1 and 0.2 it falls to 0.89 and 0.78 of it at the first gaps after touch, where
the contact is not yet in its asymptotic range (the estimate is then low, not bounding)."""


# ---- the model ----------------------------------------------------------------------


def reduced_capillary_number(scene: Scene) -> float:
    """Ca* = 3 eta v R^2/(sigma delta^2): squeeze rate over capillary leveling rate."""
    assert scene.film_thickness is not None
    return (3.0 * scene.viscosity * abs(scene.velocity) * scene.radius**2
            / (scene.surface_tension * scene.film_thickness**2))


def validity_reason(delta_over_r: float, ca: float, ca_star: float) -> str | None:
    """Why (delta/R, Ca, Ca*) is outside the thin-film validity, or ``None``."""
    if delta_over_r > DELTA_OVER_R_MAX:
        return (f"delta/R = {delta_over_r:.3g} > {DELTA_OVER_R_MAX} (sphere slope at the "
                f"wetted edge sqrt(4 delta/R) = {math.sqrt(4 * delta_over_r):.2f}: "
                "lubrication fails)")
    if ca > CA_MAX:
        return (f"Ca = eta v/sigma = {ca:.3g} > {CA_MAX} (the pile-up rim is steep, "
                "small-slope free surface fails)")
    if ca_star > CA_STAR_MAX:
        return (f"Ca* = 3 eta v R^2/(sigma delta^2) = {ca_star:.3g} > {CA_STAR_MAX:g} "
                "(rim narrower than the grid can resolve)")
    return None


def auto_cells(radius: float, film_thickness: float, wetting_width: float,
               domain_factor: float = 3.0) -> int:
    r"""Cells that resolve the diffuse contact zone of width :math:`\lambda`.

    The zone where :math:`1 - \lambda \le h/g \le 1` spans about
    :math:`\lambda g(r_w)/2 \sim \lambda\delta` in r (the film leaves the sphere with a
    slope of order :math:`\sqrt{2W/\sigma} \approx 2`), the domain
    :math:`L \propto \sqrt{R\delta}`, so the cells needed grow like
    :math:`\sqrt{R/\delta}/\lambda`:
    ``ceil(CELLS_PER_WIDTH * (domain_factor/3) * sqrt(R/delta) / lambda)``, at least 200.
    Measured (water case, delta/R = 0.1): at this resolution doubling the cells moves the
    forces by under 0.3 %; at half of it the integrator rejects most steps (a front
    crossing a cell at a time) and runs 4-10x slower. These are the cells of a uniform
    grid; a graded grid (``fine_factor``) keeps their width out to the fine radius only.
    """
    n = CELLS_PER_WIDTH * domain_factor / 3.0 * math.sqrt(radius / film_thickness)
    return max(200, math.ceil(n / wetting_width))


def smallest_resolved_gap(problem: FilmProblem) -> float:
    r"""Smallest surface gap S whose contact zone the grid of ``problem`` resolves.

    The squeeze pressure at gap S is concentrated within :math:`r \lesssim \sqrt{2RS}`
    (where the parabolic gap doubles); the grid resolves it while this radius spans
    :data:`CELLS_ACROSS_CONTACT` cells: :math:`S_{min} = r_N^2/(2R)`, :math:`r_N` the
    N-th face from the axis. Below it the force is wrong without a warning (42 % low at
    0.4 cells), and the model refuses the gap.
    """
    r_n = float(problem.r_f[min(CELLS_ACROSS_CONTACT, problem.cells)])
    return r_n**2 / (2.0 * problem.radius)


def problem_from_scene(scene: Scene, cells: int | None, domain_factor: float,
                       penetration: float, gap_shape: str = "parabolic",
                       contact: str = "meniscus", wall_angle: str = "film",
                       wetting_width: float = 0.05, fine_factor: float | None = None,
                       growth: float = 1.03) -> FilmProblem:
    r"""The :class:`FilmProblem` of a film scene at a resolution.

    ``wall_angle = "film"``: the meniscus foot meets the liquid film (theta = 0, the wall
    under a film is wet); ``"scene"``: the scene's wall contact angle. ``cells = None``:
    the fine cells of :func:`auto_cells` (the uniform grid that resolves lambda).
    ``fine_factor = None``: a uniform grid; else graded (:func:`graded_faces`), fine out to
    ``fine_factor`` times the pile-up wetted radius :math:`\sqrt{4R\delta}` (the path of
    the contact line: it reaches 1.1 of it on the water case), cells growing by ``growth``
    beyond.
    """
    assert scene.film_thickness is not None
    if wall_angle not in ("film", "scene"):
        raise InputError(f"thinfilm: wall_angle = {wall_angle!r}; allowed: 'film', 'scene'")
    r_pile = math.sqrt(4.0 * scene.radius * scene.film_thickness)
    length = domain_factor * r_pile
    fine = None if fine_factor is None else fine_factor * r_pile
    if fine is not None and not 0.0 < fine < length:
        raise InputError(f"thinfilm: fine_factor = {fine_factor!r}; allowed: (0, "
                         f"domain_factor = {domain_factor:g})")
    if cells is None:
        n_u = auto_cells(scene.radius, scene.film_thickness, wetting_width, domain_factor)
        cells = n_u if fine is None else graded_cells(length / n_u, length, fine, growth)
    return FilmProblem(radius=scene.radius, viscosity=scene.viscosity,
                       surface_tension=scene.surface_tension, density=scene.density,
                       gravity=scene.gravity, film_thickness=scene.film_thickness,
                       velocity=scene.velocity, cells=int(cells), domain=length,
                       penetration=penetration, gap_shape=gap_shape, contact=contact,
                       angle_sphere=scene.contact_angle_sphere,
                       angle_wall=0.0 if wall_angle == "film" else scene.contact_angle_wall,
                       wetting_width=wetting_width, fine_radius=fine, growth=growth)


def sphere_mass(scene: Scene, mass: float | None = None) -> float:
    """m = ``mass`` if given, else (4/3) pi R^3 rho_p from the scene's particle density."""
    if mass is not None:
        if not (math.isfinite(mass) and mass > 0):
            raise InputError(f"thinfilm: mass = {mass!r}; allowed: > 0 kg")
        return float(mass)
    if scene.particle_density is None:
        raise InputError("thinfilm: inertia needs the sphere's mass: give [particle] "
                         "density in the case or the setting mass (kg)")
    return 4.0 / 3.0 * math.pi * scene.radius**3 * scene.particle_density


@register
class ThinFilm(Model):
    """Sphere squeezing a liquid film with a free surface: the thin-film equation joined
    to the quasi-static finite-element meniscus at a sharp contact line (default), or the
    penalty-obstacle contacts ``meniscus``/``tangential``."""

    name = "thinfilm"
    level = 2
    component = "both"
    validity = (f"sphere-wall, film; delta/R <= {DELTA_OVER_R_MAX}, Ca <= {CA_MAX}, "
                f"Ca* = 3 eta v R^2/(sigma delta^2) <= {CA_STAR_MAX:g}; approach (v > 0); "
                f"sharp contact (default): theta_s < 90 deg, Ca* >= {CA_STAR_MIN_SHARP:g}, "
                "capillary part quasi-static (error of order Ca)")
    order = 2.0
    order_tolerance = 0.3
    reference_rank = {"viscous": 20}  # its capillary part is not compared with closures
    reference = ("thin-film equation (Oron, Davis & Bankoff 1997) joined at its minimum to "
                 "the finite-element Young-Laplace meniscus (sharp contact; or a penalty "
                 "obstacle); limits: Pitois et al. 2000")
    source = ("thin-film equation (Oron, Davis & Bankoff 1997) joined to the finite-element "
              "Young-Laplace meniscus; checked against the leveling of a free film, the "
              "lubrication limit (Pitois, Moucheront & Chateau 2000) and the static bridge")
    presets = {
        # film_cells, elements, rtol: the sharp contact (default; its bridge's force
        # moves by 6e-8 from 16 to 64 elements, 3e-9 from 32); wetting_width,
        # penetration, fine_factor: the penalty contacts ("meniscus", "tangential"),
        # unused by the sharp one; "contact" says which one a result used
        "fast": {"contact": "sharp", "film_cells": 40, "elements": 16, "rtol": 1e-3,
                 "wetting_width": 0.2, "penetration": 3e-3, "domain_factor": 3.0,
                 "fine_factor": 1.3},
        "default": {"contact": "sharp", "film_cells": 120, "elements": 32, "rtol": 3e-4,
                    "wetting_width": 0.05, "penetration": 1e-3, "domain_factor": 3.0,
                    "fine_factor": 1.3},
        "accurate": {"contact": "sharp", "film_cells": 240, "elements": 64, "rtol": 1e-4,
                     "wetting_width": 0.025, "penetration": 1e-3, "domain_factor": 3.0,
                     "fine_factor": 1.3},
    }

    def check(self, scene: Scene) -> None:
        """Film on a wall, approach, (delta/R, Ca, Ca*) inside the validity, and the
        default (sharp) contact's limits (:meth:`check_options` at the default preset)."""
        self.check_options(scene, self.presets["default"])

    def check_options(self, scene: Scene, opts: dict[str, Any]) -> None:
        """:meth:`check` at the options ``opts``; the sharp contact (the default) also needs
        a wetting sphere (theta_s < 90 deg) and no gap within 3 FIRST_DIP delta of first
        touch, where its meniscus is still forming."""
        if scene.amount == "immersed":
            raise ValidityError(self.name, "the scene is immersed, not a film",
                                use_instead="stokes")
        if scene.amount == "bridge":
            raise ValidityError(self.name, "the scene is a liquid bridge, not a film",
                                use_instead="lubrication")
        if scene.kind != "sphere-wall":
            raise ValidityError(self.name, "only a sphere on a wall", use_instead="stokes")
        if scene.velocity <= 0:
            raise ValidityError(self.name, f"velocity = {scene.velocity:g} m/s; only "
                                "approach (v > 0) is modelled", use_instead="stokes")
        assert scene.film_thickness is not None
        ca = scene.viscosity * scene.velocity / scene.surface_tension
        cs = reduced_capillary_number(scene)
        reason = validity_reason(scene.film_thickness / scene.radius, ca, cs)
        if reason:
            raise ValidityError(self.name, reason, use_instead="stokes")
        if opts.get("contact", "sharp") == "sharp":
            if cs < CA_STAR_MIN_SHARP:
                raise ValidityError(
                    self.name, f"Ca* = 3 eta v R^2/(sigma delta^2) = {cs:.3g} < "
                    f"{CA_STAR_MIN_SHARP:g}: the film relaxes much faster than the sphere "
                    "moves and the sharp contact's time steps fail there (quasi-static "
                    "limit: its capillary force tends to the FE bridge holding the wetted "
                    "volume, its viscous force to the lubrication film's)",
                    use_instead="lubrication")
            if not scene.contact_angle_sphere < 0.5 * math.pi:
                raise ValidityError(
                    self.name, f"contact angle on the sphere "
                    f"{math.degrees(scene.contact_angle_sphere):.4g} deg >= 90 deg: the sharp "
                    "contact needs a wetting liquid (setting contact = 'tangential' models a "
                    "non-wetting sphere)", use_instead="lubrication")
            gaps, delta = scene.gap_array, scene.film_thickness
            early = gaps[(gaps < delta) & (gaps > delta * (1.0 - 3.0 * FIRST_DIP))]
            if early.size:
                raise ValidityError(
                    self.name, f"gap S = {float(early[0]):.6g} m is within "
                    f"{3 * FIRST_DIP:g} delta of first touch (delta = {delta:g} m), where the "
                    "sharp contact's meniscus is still forming from the undisturbed film "
                    f"(its run starts at delta (1 - {FIRST_DIP:g})); S = delta itself is 0",
                    use_instead="lubrication")
        # the penalty contacts' gap limits depend on their resolution: see _force

    @staticmethod
    def _too_small(scene: Scene, s_min: float, preset: str) -> str:
        return (f"gap S = {float(np.min(scene.gap_array)):.3g} m is below the smallest gap "
                f"the '{preset}' preset resolves, {s_min:.3g} m ({CELLS_ACROSS_CONTACT} cells "
                "across the contact zone sqrt(2 R S))")

    @staticmethod
    def _problem(scene: Scene, cells: int | None = None, penetration: float = 1e-3,
                 domain_factor: float = 3.0, gap_shape: str = "parabolic",
                 contact: str = "meniscus", wall_angle: str = "film",
                 wetting_width: float = 0.05, fine_factor: float | None = None,
                 growth: float = 1.03, **_: Any) -> FilmProblem:
        """The :class:`FilmProblem` of ``scene`` at these settings (cells: auto)."""
        return problem_from_scene(scene, cells, domain_factor, penetration, gap_shape,
                                  contact, wall_angle, wetting_width, fine_factor, growth)

    def _force(self, scene: Scene, preset: str, cells: int | None = None,
               penetration: float = 1e-3, rtol: float = 1e-4, domain_factor: float = 3.0,
               gap_shape: str = "parabolic", contact: str = "sharp",
               wall_angle: str = "film", wetting_width: float = 0.05,
               integrator: str = "bdf2", inertia: bool = False, mass: float | None = None,
               profile_gaps: Sequence[float] | None = None, progress: bool = False,
               error_estimate: bool = True, fine_factor: float | None = None,
               growth: float = 1.03, film_cells: int = 80, elements: int = 64,
               **opts: Any) -> ForceCurve:
        if opts:
            raise InputError("thinfilm: unknown settings " + ", ".join(sorted(opts))
                             + "; allowed: contact, film_cells, elements, cells, penetration, "
                             "rtol, domain_factor, gap_shape, wall_angle, wetting_width, "
                             "integrator, inertia, mass, profile_gaps, progress, "
                             "error_estimate, fine_factor, growth")
        if contact not in CONTACTS:
            raise InputError(f"thinfilm: contact = {contact!r}; allowed: "
                             + ", ".join(repr(c) for c in CONTACTS))
        if integrator not in ("bdf2", "scipy"):
            raise InputError(f"thinfilm: integrator = {integrator!r}; allowed: 'bdf2' "
                             "(own BDF2 + Newton), 'scipy' (py-pde ScipySolver, BDF)")
        gaps = scene.gap_array
        if profile_gaps is None:
            profile_gaps = [float(np.max(gaps)), float(np.median(gaps)), float(np.min(gaps))]
        m = sphere_mass(scene, mass) if (inertia or mass is not None) else None
        if integrator == "scipy" and m is not None:
            raise InputError("thinfilm: inertia needs integrator = 'bdf2'")
        if contact == "sharp":
            if integrator != "bdf2":
                raise InputError("thinfilm: contact = 'sharp' needs integrator = 'bdf2'")
            if cells is not None:
                raise InputError(f"thinfilm: cells = {cells!r} is a setting of the penalty "
                                 "contacts ('meniscus', 'tangential'); the sharp contact's "
                                 "film takes film_cells (an integer >= 8)")
            sharp = _sharp_problem(self.name, scene, film_cells, elements, domain_factor,
                                   gap_shape)

            def run_sharp(prob: SharpFilm, tol: float, dip: float) -> RunResult:
                return sharp_run(prob, gaps, profile_gaps=profile_gaps, rtol=tol, mass=m,
                                 first_dip=dip)

            res = run_sharp(sharp, rtol, FIRST_DIP)
            estimate = None
            if error_estimate:
                coarse = replace(sharp, cells=max(8, sharp.cells // 2),
                                 n_elements=max(16, sharp.n_elements // 2))
                estimate = _two_resolution_estimate(
                    res, run_sharp(coarse, 10.0 * rtol, 3.0 * FIRST_DIP),
                    ORDER_OF_CONTACT["sharp"])
            diag = {"cells": sharp.cells, "elements": sharp.n_elements,
                    "domain_m": sharp.domain, "smallest_resolved_gap_m": 0.0,
                    "error_estimate_method": (
                        f"two resolutions: {SAFETY_FACTOR} |F(x) - F(2x)|/(2^p - 1), "
                        f"p = {ORDER_OF_CONTACT['sharp']}, 2x = half the film cells and "
                        "bridge elements, rtol x 10, first dip x 3") if error_estimate
                    else "none", "first_dip": FIRST_DIP}
            foot = [res.details.get(float(g), {}).get("foot_radius", 0.0) for g in gaps]
            return _curve(self.name, scene, res, sharp.velocity, m, estimate, diag,
                          {"foot_radius": np.array(foot, dtype=float)})
        settings = {"cells": cells, "penetration": penetration, "domain_factor": domain_factor,
                    "gap_shape": gap_shape, "contact": contact, "wall_angle": wall_angle,
                    "wetting_width": wetting_width, "fine_factor": fine_factor,
                    "growth": growth}
        s_pen = SMALLEST_GAP_OVER_DELTA * float(scene.film_thickness or 0.0)
        if float(np.min(gaps)) < s_pen:
            raise ValidityError(
                self.name, f"gap S = {float(np.min(gaps)):.3g} m is below "
                f"{SMALLEST_GAP_OVER_DELTA:g} delta = {s_pen:.3g} m, where the penalty "
                f"contact's pressure ({contact!r}) is not controlled",
                use_instead="lubrication")
        problem = self._problem(scene, **settings)
        s_min = smallest_resolved_gap(problem)
        if float(np.min(gaps)) < s_min:
            raise ValidityError(self.name, self._too_small(scene, s_min, preset)
                                + f" at {problem.cells} cells; a finer preset or more cells "
                                "resolve smaller gaps", use_instead="lubrication")

        def run(prob: FilmProblem) -> RunResult:
            if integrator == "scipy":
                return penetration_run(prob, gaps, profile_gaps=profile_gaps, rtol=rtol,
                                       progress=progress)
            return implicit_run(prob, gaps, profile_gaps=profile_gaps, rtol=rtol, mass=m)

        res = run(problem)
        _check_fine_zone(problem, res)
        estimate = None
        if error_estimate:
            coarse = self._problem(scene, **_coarser(settings, problem.cells))
            estimate = _two_resolution_estimate(res, run(coarse),
                                                ORDER_OF_CONTACT[problem.contact])
        diag = {"cells": problem.cells, "domain_m": problem.domain, "dr_m": problem.dr,
                "smallest_resolved_gap_m": s_min,
                "fine_radius_m": problem.fine_radius or problem.domain,
                "error_estimate_method": (
                    f"two resolutions: {SAFETY_FACTOR} |F(x) - F(2x)|/(2^p - 1), "
                    f"p = {ORDER_OF_CONTACT[problem.contact]}, x = the contact "
                    "resolution") if error_estimate else "none"}
        return _curve(self.name, scene, res, problem.velocity, m, estimate, diag, {})

    def convergence_data(self) -> tuple[np.ndarray, np.ndarray]:
        """Relative error of the J0-mode decay rate against sigma delta^3 k^4/(3 eta)
        on 24, 48, 96, 192 cells (analytic reference; second order)."""
        cells = np.array([24, 48, 96, 192])
        err = []
        for n in cells:
            prob = leveling_problem(int(n))
            num, an = bessel_mode_decay(prob, mode=2)
            err.append(num / an - 1.0)
        return 1.0 / cells, np.array(err)



def _coarser(settings: dict[str, Any], cells: int) -> dict[str, Any]:
    """Settings of the companion run of the error estimate: the contact resolution halved
    (meniscus: lambda doubled, at most 0.5, with its cells; tangential: half the cells)."""
    out = dict(settings)
    if settings["contact"] == "meniscus":
        out["wetting_width"] = min(2.0 * settings["wetting_width"], 0.5)
        if settings["cells"] is not None:
            out["cells"] = max(8, cells // 2)
    else:
        out["cells"] = max(8, cells // 2)
    return out


def _two_resolution_estimate(fine: RunResult, coarse: RunResult, order: float) -> np.ndarray:
    r"""Relative error of the fine run per gap,
    :math:`F_s|F_x - F_{2x}|/((2^p - 1)(|F_{\rm visc}| + |F_{\rm cap}|))` (Richardson's
    estimate for order p times the safety factor :data:`SAFETY_FACTOR`; the scale is the
    force magnitude of the fine run because the total changes sign). 0 at first touch (no
    wetted zone: the force is exactly 0); 1 where only one of the two runs reached the gap
    (inertia)."""
    out = np.zeros(len(fine.snapshots))
    for i, (a, b) in enumerate(zip(fine.snapshots, coarse.snapshots, strict=True)):
        ra = not fine.reached or fine.reached[i]
        rb = not coarse.reached or coarse.reached[i]
        scale = abs(a.force_viscous) + abs(a.force_capillary)
        if ra != rb:
            out[i] = 1.0
        elif ra and scale > 0.0:
            diff = (a.force_viscous + a.force_capillary) - (b.force_viscous + b.force_capillary)
            out[i] = SAFETY_FACTOR * abs(diff) / ((2.0**order - 1.0) * scale)
    return out


def _check_fine_zone(problem: FilmProblem, res: RunResult) -> None:
    """Raise :class:`SolverError` if the contact line left the fine zone of a graded grid
    (its coarse cells do not resolve the contact)."""
    if problem.fine_radius is None:
        return
    r_w = max(s.wetted_radius for s in res.snapshots)
    if r_w > problem.fine_radius:
        raise SolverError(f"thinfilm: the wetted radius {r_w:.3g} m left the fine zone "
                          f"(fine_radius = {problem.fine_radius:.3g} m); raise fine_factor")


def _sharp_problem(name: str, scene: Scene, film_cells: int, elements: int,
                   domain_factor: float, gap_shape: str) -> SharpFilm:
    """The :class:`SharpFilm` of a film scene (its limits, a wetting sphere among them, are
    refused by :meth:`ThinFilm.check_options` before it is built)."""
    assert scene.film_thickness is not None
    if not (isinstance(film_cells, int | np.integer) and film_cells >= 8):
        raise InputError(f"thinfilm: film_cells = {film_cells!r}; allowed: an integer >= 8")
    if not (isinstance(elements, int | np.integer) and 16 <= elements <= 1024):
        raise InputError(f"thinfilm: elements = {elements!r}; allowed: an integer in "
                         "[16, 1024]")
    if not 1.0 <= domain_factor <= 20.0:
        raise InputError(f"thinfilm: domain_factor = {domain_factor!r}; allowed: [1, 20]")
    r_pile = math.sqrt(4.0 * scene.radius * scene.film_thickness)
    return SharpFilm(radius=scene.radius, viscosity=scene.viscosity,
                     surface_tension=scene.surface_tension, density=scene.density,
                     gravity=scene.gravity, film_thickness=scene.film_thickness,
                     velocity=scene.velocity, domain=domain_factor * r_pile,
                     angle_sphere=scene.contact_angle_sphere, cells=int(film_cells),
                     gap_shape=gap_shape, n_elements=int(elements))


def _curve(name: str, scene: Scene, res: RunResult, velocity: float, m: float | None,
           estimate: np.ndarray | None, diag: dict[str, Any],
           extra: dict[str, np.ndarray]) -> ForceCurve:
    """The :class:`ForceCurve` of a run (both contacts)."""
    snaps = res.snapshots
    speeds = res.speeds or [velocity] * len(snaps)
    reached = res.reached or [True] * len(snaps)
    gaps = scene.gap_array
    return ForceCurve(
        case=scene.name, model=name, gap=gaps,
        force_viscous=np.array([s.force_viscous for s in snaps]),
        force_capillary=np.array([s.force_capillary for s in snaps]),
        extras={"wetted_radius": np.array([s.wetted_radius for s in snaps]),
                "laplace_pressure": np.array([s.edge_pressure for s in snaps]),
                "max_slope": np.array([s.max_slope for s in snaps]),
                "max_penetration": np.array([s.max_penetration for s in snaps]),
                "sphere_speed": np.array(speeds, dtype=float),
                "reached": np.array(reached, dtype=float), **extra},
        error_estimate=estimate,
        diagnostics={"steps": res.steps, "steps_shortened_by_rejection":
                     res.steps_shortened, "rhs_evaluations": res.rhs_evaluations,
                     "volume_drift": res.volume_drift, **diag,
                     "min_gap_m": res.min_gap if m is not None else float(np.min(gaps)),
                     "mass_kg": m if m is not None else 0.0,
                     "profile_r_m": res.r.tolist(),
                     "profile_gaps_m": sorted(res.profiles, reverse=True),
                     "profiles_h_m": [res.profiles[g].tolist()
                                      for g in sorted(res.profiles, reverse=True)]},
    )
