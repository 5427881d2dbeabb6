"""The registered model ``meniscus``: the finite-element Young-Laplace bridge as a
:class:`~wetcontact.models.Model` (volume-controlled curve from contact to rupture)."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from wetcontact.errors import InputError, ValidityError
from wetcontact.models import ForceCurve, Model, register
from wetcontact.scene import Scene
from wetcontact.solver.meniscus.division import divide_branch, transfer_fraction
from wetcontact.solver.meniscus.geometry import DEFAULT_ELEMENTS, THETA_MAX, Bridge
from wetcontact.solver.meniscus.solve import _branch_for, contact_problem, solve_volume
from wetcontact.solver.meniscus.young_laplace import _disc

MIN_VOLUME_RATIO = 2e-11
"""Smallest V/R_small^3 the model accepts: at 3e-11 the bridge at contact solves at 0, 20
and 60 deg, at 1e-11 its Newton iteration fails at every angle."""


@register
class MeniscusModel(Model):
    """Finite-element Young-Laplace bridge (P2, Newton, continuation to rupture).

    Extras per gap: ``laplace_pressure`` (Pa), ``neck_radius`` (m), ``filling_angle`` (rad,
    sphere 1), ``filling_angle2`` (rad) or ``wetted_radius`` (m), ``rupture_distance`` (m),
    ``bridge_exists``, ``force_spread``, ``stability``; and two properties of the rupture,
    the same at every gap: ``rupture_distance`` and ``transfer_fraction``, the fraction of
    the liquid that body 1 (the sphere; the upper sphere of a pair) keeps when the bridge
    ruptures, ``1 - f`` going to the wall or sphere 2
    (:func:`~wetcontact.solver.meniscus.division.transfer_fraction`: the critical bridge
    cut at its neck; diagnostics ``transfer_neck`` says whether the neck lay between the
    contact lines or at one of them).
    """

    name: ClassVar[str] = "meniscus"
    level: ClassVar[int] = 3
    component: ClassVar[str] = "capillary"
    validity: ClassVar[str] = (
        "static axisymmetric pendular bridge; sphere-wall or sphere-sphere (R2/R1 in "
        "[0.1, 10]); contact angles 0-150 deg; half-filling angle <= 70 deg at contact; "
        "gravity optional"
    )
    order: ClassVar[float | None] = 4.0
    reference_rank: ClassVar[dict[str, int]] = {"capillary": 30}
    reference: ClassVar[str] = (
        "Young-Laplace equation; P2 Petrov-Galerkin FE (Gauss collocation), Newton; "
        "Lambert et al. (2008) force decomposition; Maddocks (1987) stability at folds"
    )
    source: ClassVar[str] = (
        "Young-Laplace equation by P2 finite elements, Newton and arclength continuation "
        "(stability: Maddocks 1987); checked against the force decomposition of Lambert et al. "
        "2008, the analytic catenoid, cylinder and contact limits, and an ODE shooting"
    )
    presets: ClassVar[dict[str, dict[str, Any]]] = {
        "fast": {"n_elements": 64},
        "default": {"n_elements": DEFAULT_ELEMENTS},
        "accurate": {"n_elements": 256},
    }
    error_bound: ClassVar[dict[str, float]] = {"fast": 1e-5, "default": 1e-6, "accurate": 1e-6}
    """Relative force error per preset: default and accurate as tested against the shooting
    solution over the validity range (1e-6); fast from the benchmark (1.6e-8 at 32
    elements), stated with margin."""
    extras_order: ClassVar[dict[str, float]] = {"transfer_fraction": 4.0}
    """Declared convergence order of extras under refinement of ``n_elements``: the division
    of the liquid at rupture (:mod:`~wetcontact.solver.meniscus.division`) inherits order 4
    from the nodal values and the neck (:meth:`extras_convergence_data`)."""
    extras_error_bound: ClassVar[dict[str, dict[str, float]]] = {
        "transfer_fraction": {"fast": 1e-6, "default": 1e-7, "accurate": 1e-8}}
    """Absolute error of an extra per preset: ``transfer_fraction`` as tested against the
    shooting solution (tests/solver/test_division.py); the largest found over the corners
    of its domain is 2.8e-7, 1.7e-8 and 9.6e-10 (zero contact angles)."""

    def check(self, scene: Scene) -> None:
        """Refuse what is not a bridge, angles above 150 deg, V/R_small^3 below
        :data:`MIN_VOLUME_RATIO`, sphere pairs of radius ratio outside [0.1, 10], and a
        volume whose bridge at contact does not exist or fills more than 70 deg of a sphere
        (:func:`~wetcontact.solver.meniscus.solve.contact_problem`, the solve's own first
        step: no model in the package covers such a bridge)."""
        if scene.amount == "immersed":
            raise ValidityError(self.name, "the scene is immersed (no liquid bridge)",
                                use_instead="stokes")
        if scene.amount == "film":
            raise ValidityError(self.name, "the liquid is a film on the wall, not a bridge",
                                use_instead="thinfilm")
        if scene.bridge_volume is None:
            raise ValidityError(self.name, "the scene has no bridge_volume")
        for label, th in (("contact_angle_sphere", scene.contact_angle_sphere),
                          ("contact_angle_wall", scene.contact_angle_wall)):
            if th > THETA_MAX + 1e-12:
                raise ValidityError(self.name, f"{label} = {math.degrees(th):.4g} deg is above "
                                    "150 deg: outside the solver's range")
        if (v := scene.bridge_volume / scene.small_radius**3) < MIN_VOLUME_RATIO:
            raise ValidityError(self.name, f"V/R_small^3 = {v:.4g} < {MIN_VOLUME_RATIO:g}: "
                                "below the volumes the solver resolves (its Newton iteration "
                                "at contact fails from 1e-11); the toroidal bridge is within "
                                "1.2e-4 of it at 3e-11 (20 deg, wall)", use_instead="toroidal")
        if scene.kind == "sphere-sphere":
            ratio = scene.radius2 / scene.radius
            if not 0.1 - 1e-12 <= ratio <= 10 + 1e-12:
                raise ValidityError(self.name, f"radius ratio R2/R1 = {ratio:.4g} outside "
                                    "[0.1, 10]")
        why = contact_problem(Bridge.from_scene(scene), float(scene.bridge_volume))
        if why is not None:
            raise ValidityError(self.name, why)

    def convergence_data(self) -> tuple[np.ndarray, np.ndarray]:
        """Force error of a catenoid between plates (analytic, PHYSICS.md) against 1/N."""
        a, h = 1.0, 1.2
        th = math.atan2(1.0, math.sinh(h / a))
        V = math.pi * a * a * (h + 0.5 * a * math.sinh(2 * h / a))
        br = Bridge(radius=None, contact_angle1=th, contact_angle2=th, surface_tension=1.0)
        exact = 2 * math.pi * a
        ns = np.array([8, 16, 32, 64])
        err = []
        for n in ns:
            sol = solve_volume(br, 2 * h, V, n_elements=int(n))
            err.append(abs(sol.force_contact1 - exact) / exact)
        return 1.0 / ns, np.array(err)

    def extras_convergence_data(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Error of an extra against 1/N, for :attr:`extras_order`.

        ``transfer_fraction``: sphere-sphere, R2 = 2 R1, V = 1e-3 R1^3, contact angles 30
        and 10 deg, at N = 16-128 elements against N = 512 (its own error is below 1e-12,
        by the order-4 rate from 2.3e-9 at 128).
        """
        if name != "transfer_fraction":
            raise InputError(f"model '{self.name}': no convergence data for extra {name!r}; "
                             f"allowed: {', '.join(self.extras_order)}")
        br = Bridge(radius=1.0, radius2=2.0, contact_angle1=math.radians(30.0),
                    contact_angle2=math.radians(10.0), surface_tension=1.0)
        ref = transfer_fraction(br, 1e-3, n_elements=512).fraction
        ns = np.array([16, 32, 64, 128])
        err = [abs(transfer_fraction(br, 1e-3, n_elements=int(n)).fraction - ref) for n in ns]
        return 1.0 / ns, np.array(err)

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        n_el = int(opts.get("n_elements", DEFAULT_ELEMENTS))
        bridge = Bridge.from_scene(scene)
        V = float(scene.bridge_volume)
        br, ell = _branch_for(bridge, V, n_el)
        Sc = br.S_fold * ell
        gaps = scene.gap_array
        past = ""
        if np.all(gaps > Sc * (1 + 1e-12)):  # no bridge at any gap: force 0, as closures give
            past = (f"every gap ({gaps.min():.6g} to {gaps.max():.6g} m) is beyond the "
                    f"rupture distance {Sc:.6g} m of V = {V:.6g} m^3: no bridge, force 0")
        keys = ("laplace_pressure", "neck_radius", "filling_angle", "rupture_distance",
                "bridge_exists", "force_spread", "stability")
        keys += ("wetted_radius",) if scene.kind == "sphere-wall" else ("filling_angle2",)
        ex = {k: np.zeros(gaps.size) for k in keys}
        division = divide_branch(br, ell)  # a property of the rupture: one value a curve
        ex["transfer_fraction"] = np.full(gaps.size, division.fraction)
        fc = np.zeros(gaps.size)
        iters = []
        for i, s in enumerate(gaps):
            ex["rupture_distance"][i] = Sc
            sol = solve_volume(bridge, float(s), V, n_elements=n_el, branch=br)
            iters.append(sol.iterations)
            if not sol.exists:
                continue
            fc[i] = sol.force
            ex["laplace_pressure"][i] = sol.laplace_pressure
            ex["neck_radius"][i] = sol.neck_radius
            ex["filling_angle"][i] = sol.filling_angle1
            ex["bridge_exists"][i] = 1.0
            ex["force_spread"][i] = sol.force_spread
            ex["stability"][i] = sol.stability
            if scene.kind == "sphere-wall":
                ex["wetted_radius"][i] = sol.wetted_radius
            else:
                ex["filling_angle2"][i] = sol.filling_angle2
        return ForceCurve(
            case=scene.name, model=self.name, gap=gaps, force_viscous=None,
            force_capillary=fc, extras=ex,
            diagnostics={**({"past_rupture": past} if past else {}),
                         "newton_iterations": iters, "n_elements": n_el,
                         "dofs": _disc(n_el).m, "continuation_points": len(br.xs),
                         "transfer_neck": division.neck,
                         "rupture": ("symmetry-breaking bifurcation" if br.end == "bifurcation"
                                     else "fold")},
        )
