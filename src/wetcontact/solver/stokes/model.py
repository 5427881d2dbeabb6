"""The registered ``stokes`` model (level 3): meshes per scene and gap, the presets, slip,
films and quasi-static bridges on top of :func:`~wetcontact.solver.stokes.solve.solve_stokes`
(the equations, the force and the accuracy are in :mod:`wetcontact.solver.stokes.solve`)."""

from __future__ import annotations

import math
import time
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import numpy as np
from skfem import MeshTri2

from wetcontact.errors import InputError, SolverError, ValidityError
from wetcontact.meshes.builders import Resolution
from wetcontact.meshes.cache import get_mesh
from wetcontact.models import ForceCurve, Model, register
from wetcontact.scene import Scene
from wetcontact.solver.stokes.solve import StokesSolution, gap_elements, solve_stokes

MIN_GAP = 1e-5
"""Smallest S/R the solver accepts (below it the graded mesh and the P2 force lose digits)."""

RADIUS_RATIO = (0.1, 10.0)
"""Range of R2/R meshed for two unequal spheres (outside it one sphere is a wall or a point)."""

UNEQUAL_FAR = 1.0e6
"""Far-boundary radius L/R for two unequal spheres (net force: Stokeslet far field)."""


def container_factor(x: float) -> float:
    """Drag factor of a sphere moving inside a concentric spherical container at rest.

    ``K = (1 - x^5) / (1 - 9/4 x + 5/2 x^3 - 9/4 x^5 + x^6)``, x = R/L (Haberman & Sayre 1958;
    Happel & Brenner 1965, sec. 4-22): the exact far-boundary correction of the isolated-sphere
    mesh, whose far boundary u = 0 is a circle of radius L about the sphere's centre.
    K = 1 + (9/4) x + O(x^3).
    """
    return (1 - x**5) / (1 - 2.25 * x + 2.5 * x**3 - 2.25 * x**5 + x**6)


def _mesh_for(scene: Scene, s: float, res: Resolution, method: str, cache: Any
              ) -> tuple[MeshTri2, dict[str, float], dict[str, float], tuple[float, float], int]:
    """Mesh, body velocities, slip lengths (units of R), axis interval of the gap and the
    required elements across it."""
    R = scene.radius
    b1, b2 = scene.slip_length_sphere / R, scene.slip_length_wall / R
    if scene.amount == "film":
        film = scene.film_thickness / R
        mesh = get_mesh("sphere_film", cache=cache, gap=s, film=film, res=res)
        return mesh, {"sphere": -1.0}, {"sphere": b1, "wall": b2}, (0.0, s), res.n_gap
    if scene.kind == "sphere-wall":
        mesh = get_mesh("sphere_wall", cache=cache, gap=s, res=res, plane="wall")
        return mesh, {"sphere": -1.0}, {"sphere": b1, "wall": b2}, (0.0, s), res.n_gap
    if method == "symmetry" and _mirror_symmetric(scene):
        mesh = get_mesh("sphere_wall", cache=cache, gap=0.5 * s, res=res, plane="symmetry")
        return mesh, {"sphere": -0.5}, {"sphere": b1}, (0.0, 0.5 * s), res.n_gap
    if scene.equal_spheres:
        mesh = get_mesh("sphere_sphere", cache=cache, gap=s, res=res)
    else:
        # unequal spheres exert a net force: the far field is a Stokeslet, whose container
        # error (9/4) R/L needs L >= 1e6 R to stay below the accurate preset's 1e-5
        far = replace(res, far=max(res.far, UNEQUAL_FAR))
        mesh = get_mesh("sphere_sphere", cache=cache, gap=s, res=far,
                        radius2=scene.radius2 / R)
    return (mesh, {"sphere": -0.5, "sphere2": 0.5}, {"sphere": b1, "sphere2": b2},
            (-0.5 * s, 0.5 * s), 2 * res.n_gap)


def _mirror_symmetric(scene: Scene) -> bool:
    """Two spheres that are mirror images (equal radii and slip lengths)."""
    return scene.equal_spheres and scene.slip_length_sphere == scene.slip_length_wall


def _save_fields(out: Path, scene: Scene, i: int, sol: StokesSolution) -> Path:
    """Velocity (m/s) and pressure (Pa) at the mesh vertices, SI coordinates, to VTU."""
    from wetcontact.fileio import safe_stem
    from wetcontact.meshes.io import write_vtu

    R, v, eta = scene.radius, scene.velocity, scene.viscosity
    nd = sol.basis_u.nodal_dofs
    vel = np.column_stack([sol.u[nd[0]], sol.u[nd[1]], np.zeros(nd.shape[1])]) * v
    path = Path(out) / f"stokes-{safe_stem(scene.name)}-{i:03d}.vtu"
    return write_vtu(path, sol.mesh, {"velocity": vel, "pressure": sol.p * eta * v / R},
                     scale=R)


def _save_collection(out: Path, scene: Scene, files: list[tuple[float, str]]) -> Path:
    """``stokes-<case>.pvd`` beside the VTU files: a ParaView collection whose time steps are
    the gaps (m) of the files (``files``: (gap, VTU path) pairs)."""
    from wetcontact.fileio import safe_stem
    from wetcontact.meshes.io import write_pvd

    return write_pvd(Path(out) / f"stokes-{safe_stem(scene.name)}.pvd",
                     [(gap, Path(f)) for gap, f in files])


DEFAULT_SLIP = 1.0e-9
"""Navier slip length (m) a bridge scene gets on a solid whose ``slip_length_*`` is 0: a
moving contact line on a no-slip solid dissipates without bound (Huh & Scriven 1971), and
1 nm is the molecular scale of measured slip lengths (Lauga, Brenner & Stone 2007). Set in
the presets as ``default_slip_length`` (so every result's settings state it)."""

MIN_BRIDGE_SLIP = 1.0e-7
"""Smallest slip length b/R for a bridge: the contact-line elements (``contact_factor`` b)
go below 1e-7 R, where the isoparametric inversion of scikit-fem loses convergence."""

BRIDGE_ANGLES = (math.radians(5.0), math.radians(150.0))
"""Contact angles (rad) accepted for a bridge: at 0 the meniscus is tangent to the solid
(no corner, the contact-line velocity is undefined); 150 deg is the meniscus solver's limit."""


def _angle_scale(scene: Scene) -> float:
    """Factor on the contact-line element size: ``min(1, (45 deg / theta_max)^2)``.

    At an obtuse wedge the force error is first order in the contact-line size (60/120 deg,
    S/R = 1e-2: 8e-3, 1.8e-3, 3.7e-4 at 4, 1, 0.25 slip lengths); at 20 deg it is below
    5e-4 for any size up to 2 slip lengths, and smaller elements there only add a drift of
    +1e-4 per halving (b = 1e-6 R; none at b = 1e-4 R), so acute wedges keep the preset's.
    """
    th = max(scene.contact_angle_sphere, scene.contact_angle_wall)
    return min(1.0, (math.radians(45.0) / th) ** 2)


def _bridge_slip(scene: Scene, default: float) -> dict[str, float]:
    """Slip lengths (m) of a bridge's sphere and lower solid, ``default`` where 0."""
    return {"slip_length_sphere": scene.slip_length_sphere or default,
            "slip_length_wall": scene.slip_length_wall or default}


FILM_TOPS = {"flat": "flat, traction-free film surface z = delta outside the sphere: the "
                     "fast-impact limit (the surface has no time to form a meniscus)"}
"""Film-surface models of the film domain (recorded in a result's ``settings``). The
quasi-static meniscus top (the static meniscus joining the flat film far away) is not built:
it needs gravity (with zero Laplace pressure at infinity and no gravity the meniscus is a
catenoid, z ~ a ln(2r/a), which never becomes flat), and even then the quasi-static problem
has no finite force: the static film far away is flat and at rest (u_n = 0), so the volume
the sphere displaces, pi r_c^2 v, must leave through a film of thickness delta, whose
resistance grows like (6 eta/(pi delta^3)) ln(r_far) without bound; in reality the surface
rises in a spreading ridge (the ``thinfilm`` model's dynamics), which no static shape has."""

def _instead(scene: Scene) -> str | None:
    """The most faithful viscous model that accepts ``scene`` (``None`` if none does)."""
    from wetcontact.models import model_instead

    return model_instead(scene, "viscous", exclude="stokes")


# ---- the registered model -----------------------------------------------------------------


@register
class Stokes(Model):
    """Axisymmetric Stokes FEM (Taylor-Hood P2/P1, isoparametric P2 geometry, gmsh meshes).

    Immersed sphere-wall and two-sphere scenes (unequal radii included), a sphere
    dipping into a flat film, and quasi-static liquid bridges (sphere-wall and two spheres:
    the viscous force ``Phi / v`` in the static meniscus domain, the capillary force being
    the ``meniscus`` model's), with Navier slip lengths ``slip_length_sphere`` and
    ``slip_length_wall`` (the second sphere's for two spheres) from the scene; a bridge
    solid with zero slip gets ``default_slip_length`` (1 nm, :data:`DEFAULT_SLIP`).
    ``scene.velocity`` v is the approach speed; for two spheres it is the relative speed
    ``-dS/dt`` and each sphere moves at v/2. The force is the axial force on the (first)
    sphere, positive when it pushes the surfaces apart, ``F = eta R v f(S/R)`` with f from
    the unit problem. Options: ``method`` (``"symmetry"``: equal spheres solved as one
    sphere approaching a shear-free plane at speed v/2 and gap S/2, used when the spheres
    are mirror images (equal radii and slip lengths), else the full mesh; ``"full"``: both
    spheres meshed), ``film_top`` (the film surface model, :data:`FILM_TOPS`; recorded in
    the settings), ``save_fields`` (a directory for VTU files), ``cache`` (mesh cache
    directory), ``contact_factor`` (bridge: element size at a contact line over the slip
    length, times :func:`_angle_scale` for contact angles above 45 deg), ``bridge_growth``
    (bridge: size growth away from the contact lines; with every size of the bridge mesh
    refined together the force's observed order is about 2, the contact lines' corners
    reducing the bulk's 4), ``default_slip_length`` (bridges only: a film's contact line
    moves with the sphere, see the module docstring), and the mesh resolution keys of
    :class:`~wetcontact.meshes.builders.Resolution` (films: ``n_film`` and ``film_corner``,
    the element size at the corner where the sphere meets the film top over delta).
    """

    name = "stokes"
    level = 3
    component = "viscous"
    validity = ("Re << 1; immersed sphere-wall or two spheres (R2/R in [0.1, 10]; any "
                "S/R >= 1e-5), a sphere in a flat film (S < delta <= S + R), or a "
                "quasi-static liquid bridge (Ca << 1, contact angles 5-150 deg, slip "
                "length >= 1e-7 R, default 1 nm); Navier slip on either surface")
    order = 4.0
    saves_fields = True
    reference_rank = {"viscous": 30}
    reference = ("Taylor-Hood axisymmetric Stokes FEM (scikit-fem, gmsh); force by the "
                 "reaction (dissipation) and by the traction integral")
    source = ("axisymmetric Stokes flow by Taylor-Hood finite elements; checked against Brenner "
              "1961 and Maude 1961 (immersed), Jeffrey & Onishi 1984 (unequal spheres), Basset "
              "1888 and Vinogradova 1995 (slip)")
    presets = {
        "fast": {"n_gap": 3, "h_sphere": 0.08, "growth": 0.25, "far": 1.0e3, "n_film": 8,
                     "film_corner": 2.0e-3,
                     "film_top": "flat", "contact_factor": 2.0,
                     "bridge_growth": 0.08, "default_slip_length": DEFAULT_SLIP},
        "default": {"n_gap": 4, "h_sphere": 0.05, "growth": 0.15, "far": 1.0e3, "n_film": 10,
                     "film_corner": 5.0e-4,
                     "film_top": "flat", "contact_factor": 1.0,
                     "bridge_growth": 0.06, "default_slip_length": DEFAULT_SLIP},
        "accurate": {"n_gap": 8, "h_sphere": 0.02, "growth": 0.08, "far": 1.0e3, "n_film": 14,
                     "film_corner": 1.0e-4,
                     "film_top": "flat", "contact_factor": 0.25,
                     "bridge_growth": 0.03, "default_slip_length": DEFAULT_SLIP},
    }
    error_bound = {"fast": 1e-3, "default": 1e-4, "accurate": 1e-5}
    """Relative error bound of the immersed force per preset (measured, benchmarks/)."""

    def check(self, scene: Scene) -> None:
        s = scene.gap_array / scene.radius
        if s.min() < MIN_GAP:
            raise ValidityError(self.name, f"S/R = {s.min():.3g} < {MIN_GAP:g}: the graded "
                                "mesh cannot resolve the gap to the preset's accuracy",
                                _instead(scene))
        if scene.amount == "bridge":
            self._check_bridge(scene)
        if scene.kind == "sphere-sphere":
            q = scene.radius2 / scene.radius
            if not RADIUS_RATIO[0] <= q <= RADIUS_RATIO[1]:
                raise ValidityError(self.name, f"radius ratio R2/R = {q:.3g} outside the "
                                    f"meshed range [{RADIUS_RATIO[0]:g}, {RADIUS_RATIO[1]:g}]",
                                    _instead(scene))
        if scene.amount == "film":
            d = scene.film_thickness / scene.radius
            if np.any((s < d) & (d > s + 1.0)):
                raise ValidityError(self.name, f"film thickness delta/R = {d:g} reaches above "
                                    "the sphere's equator at some gap (allowed S < delta <= "
                                    "S + R)", _instead(scene))

    def _check_bridge(self, scene: Scene) -> None:
        """A bridge needs the meniscus (its shape), a contact angle that opens the corner
        between the meniscus and each solid, and a resolvable slip length."""
        from wetcontact.models import MODELS

        try:
            MODELS["meniscus"].check(scene)
        except ValidityError as exc:  # no static bridge shape: no domain either
            raise ValidityError(self.name, f"the meniscus solver refuses the bridge ({exc.reason})",
                                _instead(scene)) from exc
        for label, th in (("contact_angle_sphere", scene.contact_angle_sphere),
                          ("contact_angle_wall", scene.contact_angle_wall)):
            if not BRIDGE_ANGLES[0] <= th <= BRIDGE_ANGLES[1] + 1e-12:
                raise ValidityError(self.name, f"{label} = {math.degrees(th):.4g} deg: the "
                                    "moving contact line needs an open wedge, allowed "
                                    f"[{math.degrees(BRIDGE_ANGLES[0]):g}, "
                                    f"{math.degrees(BRIDGE_ANGLES[1]):g}] deg", _instead(scene))
        for label, b in _bridge_slip(scene, DEFAULT_SLIP).items():
            if b / scene.radius < MIN_BRIDGE_SLIP:
                raise ValidityError(self.name, f"{label} = {b:.3g} m = {b / scene.radius:.3g} R "
                                    f"< {MIN_BRIDGE_SLIP:g} R: the contact-line elements "
                                    "cannot resolve it", _instead(scene))

    def convergence_data(self) -> tuple[np.ndarray, np.ndarray]:
        """Relative force error against Brenner's series under uniform refinement.

        Sphere-wall at S/R = 1, base resolution (n_gap 2, h_sphere 0.2, growth 0.4,
        L = 1e3 R) refined by 2, 2.5, 3 and 4 (every size divided by the factor). The
        truncation error of L = 1e3 next to a wall is below 1e-7, far under the finest
        discretisation error (about 1e-5).
        """
        from wetcontact.reduced_models.viscous import brenner_lambda

        base = Resolution(n_gap=2, h_sphere=0.2, growth=0.4, far=1e3)
        ref = 6.0 * math.pi * float(brenner_lambda(1.0))
        h, err = [], []
        for f in (2.0, 2.5, 3.0, 4.0):
            mesh = get_mesh("sphere_wall", gap=1.0, res=base.scaled(f), plane="wall")
            sol = solve_stokes(mesh, {"sphere": -1.0})
            h.append(1.0 / f)
            err.append(abs(sol.force_reaction / ref - 1.0))
        return np.array(h), np.array(err)

    def _force(self, scene: Scene, preset: str, method: str = "symmetry",
               save_fields: str | None = None, cache: str | None = None,
               intorder: int = 4, film_top: str = "flat",
               default_slip_length: float = DEFAULT_SLIP, contact_factor: float = 1.0,
               bridge_growth: float = 0.06, **res_opts: Any) -> ForceCurve:
        if method not in ("symmetry", "full"):
            raise InputError(f"model 'stokes': method = {method!r}; allowed: 'symmetry', 'full'")
        if film_top not in FILM_TOPS:
            raise InputError(f"model 'stokes': film_top = {film_top!r}; allowed: "
                             + ", ".join(repr(k) for k in FILM_TOPS))
        if unknown := sorted(set(res_opts) - {f.name for f in fields(Resolution)}):
            raise InputError(f"model 'stokes': unknown option(s) {unknown}; allowed: method, "
                             "save_fields, cache, intorder, film_top, default_slip_length, "
                             "contact_factor, bridge_growth and "
                             + ", ".join(f.name for f in fields(Resolution)))
        res = Resolution(**res_opts)
        if scene.amount == "bridge":
            return self._bridge_force(scene, preset, replace(res, growth=bridge_growth),
                                      default_slip_length, contact_factor, intorder,
                                      save_fields, method)
        R, eta, v = scene.radius, scene.viscosity, scene.velocity
        gaps = scene.gap_array
        n = gaps.size
        f_reac, f_trac = np.zeros(n), np.zeros(n)
        ndofs, nel, ngap, times = (np.zeros(n) for _ in range(4))
        files: list[str] = []
        file_gaps: list[float] = []  # the gap of each file
        iterator = range(n)
        if n > 20:
            from tqdm import tqdm

            # disable=None: no bar when stderr is not a terminal (CI logs, pipes)
            iterator = tqdm(iterator, desc="stokes", leave=False, disable=None)
        for i in iterator:
            t0 = time.perf_counter()
            s = float(gaps[i] / R)
            if scene.amount == "film" and s >= scene.film_thickness / R:
                times[i] = time.perf_counter() - t0  # sphere above the film: no liquid contact
                continue
            mesh, vel, slip, (z0, z1), need = _mesh_for(scene, s, res, method, cache)
            ngap[i] = gap_elements(mesh, z0, z1)
            if ngap[i] < need:
                raise SolverError(f"model 'stokes': mesh at S/R = {s:.3g} has {int(ngap[i])} "
                                  f"elements across the gap, fewer than the {need} the preset "
                                  "needs; refine (n_gap) or use a larger gap")
            sol = solve_stokes(mesh, vel, intorder=intorder, slip=slip)
            f_reac[i] = sol.force_reaction * eta * R * v
            f_trac[i] = sol.force_traction * eta * R * v
            ndofs[i], nel[i] = sol.ndofs, sol.nelements
            if save_fields is not None:
                files.append(str(_save_fields(Path(save_fields), scene, i, sol)))
                file_gaps.append(float(gaps[i]))
            times[i] = time.perf_counter() - t0
        est = None
        if scene.amount == "immersed":
            est = np.full(n, self.error_bound.get(preset, np.nan))
            if not np.isfinite(est).all():
                est = None
        diag: dict[str, Any] = {"dofs": ndofs.astype(int).tolist(),
                                "elements": nel.astype(int).tolist(),
                                "gap_elements": ngap.astype(int).tolist(),
                                "gap_wall_time_s": times.tolist(),
                                "method": ("full" if scene.kind == "sphere-sphere"
                                           and not _mirror_symmetric(scene) else method)}
        if scene.amount == "film":  # the scene's slip (0: no-slip; no default on films)
            diag["slip_lengths_m"] = [scene.slip_length_sphere, scene.slip_length_wall]
        if files:
            diag["vtu_files"] = files
            diag["pvd_file"] = str(_save_collection(Path(save_fields), scene,
                                                    list(zip(file_gaps, files, strict=True))))
        return ForceCurve(case=scene.name, model=self.name, gap=gaps, force_viscous=f_reac,
                          force_capillary=None, extras={"force_traction": f_trac},
                          error_estimate=est, diagnostics=diag)

    def _bridge_force(self, scene: Scene, preset: str, res: Resolution, default_slip: float,
                      contact_factor: float, intorder: int, save_fields: str | None,
                      method: str = "symmetry") -> ForceCurve:
        """Quasi-static bridge (:mod:`wetcontact.solver.stokes.bridge`): the viscous force
        ``Phi / v`` at every gap, 0 past rupture; the capillary force is the meniscus'.
        A mirror-symmetric two-sphere bridge (equal radii, contact angles and slip lengths)
        is solved on its upper half with ``method = "symmetry"``."""
        from wetcontact.solver.meniscus import Bridge
        from wetcontact.solver.stokes.bridge import solve_bridge

        if not (math.isfinite(default_slip) and default_slip > 0):
            raise InputError(f"model 'stokes': default_slip_length = {default_slip!r}; "
                             "allowed: finite > 0 m")
        if not (math.isfinite(contact_factor) and 0.01 <= contact_factor <= 100):
            raise InputError(f"model 'stokes': contact_factor = {contact_factor!r}; "
                             "allowed: [0.01, 100]")
        R, eta, v = scene.radius, scene.viscosity, scene.velocity
        slip = _bridge_slip(scene, default_slip)
        b = (slip["slip_length_sphere"], slip["slip_length_wall"])
        if min(b) / R < MIN_BRIDGE_SLIP:
            raise ValidityError(self.name, f"slip length {min(b):.3g} m = {min(b) / R:.3g} R < "
                                f"{MIN_BRIDGE_SLIP:g} R: the contact-line elements cannot "
                                "resolve it", _instead(scene))
        cs = max(contact_factor * _angle_scale(scene) * min(b) / R, MIN_BRIDGE_SLIP)
        bridge = Bridge.from_scene(scene)
        symmetric = (method == "symmetry" and _mirror_symmetric(scene)
                     and bridge.contact_angle1 == bridge.contact_angle2)
        gaps = scene.gap_array
        n = gaps.size
        f_diss, f_reac, f_trac = np.zeros(n), np.zeros(n), np.zeros(n)
        ndofs, nel, ngap, times, flux = (np.zeros(n) for _ in range(5))
        files: list[str] = []
        file_gaps: list[float] = []  # the gap of each file
        for i in range(n):
            t0 = time.perf_counter()
            flow = solve_bridge(bridge, float(gaps[i]), float(scene.bridge_volume), b, res,
                                contact_size=cs, intorder=intorder, symmetric=symmetric)
            if flow is not None:  # past rupture: no liquid contact, no force
                sol = flow.solution
                if flow.gap_elements < res.n_gap:  # per half gap on the symmetric half
                    raise SolverError(f"model 'stokes': bridge mesh at S/R = {gaps[i] / R:.3g} "
                                      f"has {flow.gap_elements} elements across the gap, "
                                      f"fewer than the {res.n_gap} the preset needs")
                f_diss[i] = flow.force * eta * R * v
                f_reac[i] = sol.force_reaction * eta * R * v
                f_trac[i] = sol.force_traction * eta * R * v
                ndofs[i], nel[i], ngap[i] = sol.ndofs, sol.nelements, flow.gap_elements
                flux[i] = flow.motion.flux / flow.motion.swept - 1.0
                if save_fields is not None:
                    files.append(str(_save_fields(Path(save_fields), scene, i, sol)))
                    file_gaps.append(float(gaps[i]))
            times[i] = time.perf_counter() - t0
        diag: dict[str, Any] = {"dofs": ndofs.astype(int).tolist(),
                                "elements": nel.astype(int).tolist(),
                                "gap_elements": ngap.astype(int).tolist(),
                                "gap_wall_time_s": times.tolist(),
                                "slip_lengths_m": list(b),
                                "contact_size_R": cs,
                                "surface_flux_mismatch": flux.tolist(),
                                # resolution of the contact lines: the reaction tends to
                                # the dissipation as their elements shrink (a few 1e-3
                                # where the film dominates, up to 9 % where the lines do)
                                "reaction_vs_dissipation": [
                                    float(a / d - 1) if d else 0.0
                                    for a, d in zip(f_reac, f_diss, strict=True)],
                                "method": ("symmetry" if symmetric else "full")
                                + " (quasi-static bridge)"}
        if files:
            diag["vtu_files"] = files
            diag["pvd_file"] = str(_save_collection(Path(save_fields), scene,
                                                    list(zip(file_gaps, files, strict=True))))
        return ForceCurve(case=scene.name, model=self.name, gap=gaps, force_viscous=f_diss,
                          force_capillary=None,
                          extras={"force_reaction": f_reac, "force_traction": f_trac},
                          error_estimate=None, diagnostics=diag)
