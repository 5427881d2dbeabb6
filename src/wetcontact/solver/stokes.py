"""Axisymmetric Stokes flow by Taylor-Hood finite elements: the viscous-force reference (level 3).

Equations
---------
Steady Stokes flow ``-div(sigma) = 0``, ``div u = 0``, ``sigma = -p I + 2 eta e(u)`` in the
meridian half-plane (r, z), r >= 0, for an axisymmetric velocity u = (u_r, u_z) without
swirl. With the volume element 2 pi r dr dz the weak form is: find (u, p) with

    a(u, w) - b(w, p) = 0,   b(u, q) = 0,
    a(u, w) = int 2 eta [e_rr(u) e_rr(w) + e_zz e_zz + 2 e_rz e_rz + (u_r/r)(w_r/r)] r dr dz,
    b(w, q) = int q (r d_r w_r + w_r + r d_z w_z) dr dz,

where ``(u_r/r)(w_r/r)`` is the hoop strain e_thth (the hoop term); the 2 pi cancels and is
restored in the force. Elements: P2 velocity / P1 pressure (Taylor-Hood) on a second-order,
isoparametric triangle mesh from gmsh (``wetcontact.meshes``).

Boundary conditions (by named physical group): ``axis`` u_r = 0; ``wall`` and ``far``
u = 0; ``symmetry`` (shear-free plane) u_z = 0 with zero tangential traction (natural);
``sphere`` u = (0, U), ``sphere2`` u = (0, U2); ``free_surface`` traction-free (natural; the
quasi-static surface moves with the flow, so the force is the instantaneous one for the
current shape). When every boundary fixes the normal velocity the pressure is defined up to a
constant, fixed by p = 0 at one far-boundary vertex (a constant pressure exerts no net force
on the closed sphere).

Force on the sphere, two ways (Brezzi & Fortin; the reaction is the "consistent" or
"variationally consistent" flux of e.g. Carey, Chow & Seager 1985):

* **reaction**: the residual of the assembled momentum equations on the sphere's u_z degrees
  of freedom, ``F_z = -2 pi sum_i [A u - B^T p]_i``. It equals the dissipation identity
  ``F . U = -2 pi a(u, u)`` exactly for the discrete solution when the other boundaries are at
  rest or traction-free, and converges at twice the energy-norm rate (O(h^4) for P2/P1 on a
  P2 geometry); this is the reported force.
* **traction**: ``F_z = 2 pi int_sphere (sigma n)_z r ds`` with the pointwise stress of the
  discrete solution (O(h^2)); returned as ``force_traction`` for comparison.

The problem is solved in units R = eta = 1 with unit sphere speed; by linearity
``F = eta R v f(S/R)``.

Far boundary: u = 0 on a circle of radius L = max(``far``, 100 (S/R + 2)) R about the contact
point (``far`` = 1e3 in the presets). Next to a wall or a symmetry plane the disturbance decays
at least like a force dipole, and the measured truncation error at L = 1e3 R is below 1e-6 for
S/R <= 10 (compared with L = 1e4). An isolated sphere (a test geometry only) decays like a
Stokeslet, error (9/4) R/L; there the exact container factor :func:`container_factor` is applied.

Accuracy (``benchmarks/bench_stokes.py``, sphere-wall against Brenner 1961, two spheres
against the two-sphere series, S/R from 1e-4 to 10): ``fast`` <= 5e-4, ``default`` <= 1e-4,
``accurate`` <= 6e-6. The discrete force is an upper bound in practice (all errors positive).

Sign and speed convention: the force is the axial force on the sphere, positive when it pushes
the surfaces apart, so the resistance to approach (``scene.velocity > 0``) is positive. For two
spheres ``scene.velocity`` v is the relative approach speed ``-dS/dt``; each sphere moves at
v/2 toward the other, and the force is the one on either sphere (equal and opposite).
Reference check: ``F = 6 pi eta R (v/2) lambda_fs(S/R)`` (Brenner 1961, Maude 1961).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import (
    Basis,
    BilinearForm,
    ElementTriP1,
    ElementTriP2,
    ElementVector,
    FacetBasis,
    Functional,
    MeshTri2,
)

from wetcontact.errors import InputError, SolverError, ValidityError
from wetcontact.meshes.builders import Resolution
from wetcontact.meshes.cache import get_mesh
from wetcontact.models import ForceCurve, Model, register
from wetcontact.scene import Scene

MIN_GAP = 1e-5
"""Smallest S/R the solver accepts (below it the graded mesh and the P2 force lose digits)."""


def container_factor(x: float) -> float:
    """Drag factor of a sphere moving inside a concentric spherical container at rest.

    ``K = (1 - x^5) / (1 - 9/4 x + 5/2 x^3 - 9/4 x^5 + x^6)``, x = R/L (Haberman & Sayre 1958;
    Happel & Brenner 1965, sec. 4-22): the exact far-boundary correction of the isolated-sphere
    mesh, whose far boundary u = 0 is a circle of radius L about the sphere's centre.
    K = 1 + (9/4) x + O(x^3).
    """
    return (1 - x**5) / (1 - 2.25 * x + 2.5 * x**3 - 2.25 * x**5 + x**6)


# ---- weak forms -------------------------------------------------------------------------


@BilinearForm
def viscous_form(u, w, x):
    """Axisymmetric viscous dissipation form a(u, w), eta = 1, including the hoop term."""
    r = x.x[0]
    du, dw = u.grad, w.grad
    erz_u = du[0][1] + du[1][0]
    erz_w = dw[0][1] + dw[1][0]
    return 2.0 * (du[0][0] * dw[0][0] + du[1][1] * dw[1][1]) * r + erz_u * erz_w * r + (
        2.0 * u[0] * w[0] / r
    )


@BilinearForm
def divergence_form(w, q, x):
    """r-weighted divergence b(w, q) = q (r d_r w_r + w_r + r d_z w_z)."""
    r = x.x[0]
    return q * (r * (w.grad[0][0] + w.grad[1][1]) + w[0])


@Functional
def traction_z(x):
    """Axial traction on the sphere, r-weighted: -(sigma n)_z r with n out of the fluid."""
    u, p = x["u"], x["p"]
    n = x.n
    r = x.x[0]
    szr = u.grad[0][1] + u.grad[1][0]
    szz = -p + 2.0 * u.grad[1][1]
    return -(szr * n[0] + szz * n[1]) * r


# ---- solution ---------------------------------------------------------------------------


@dataclass
class StokesSolution:
    """Discrete solution on one mesh (units R = eta = 1) and the force on ``sphere``.

    Attributes
    ----------
    force_reaction, force_traction, force_dissipation
        Axial force on the sphere named ``sphere`` (units eta R U), three evaluations.
    u, p
        Velocity (P2, interleaved) and pressure (P1) coefficient vectors.
    ndofs, nelements, gap_elements
        Problem size; elements across the gap on the axis (``None`` if no gap).
    timings
        Wall time (s) of ``assemble`` and ``solve``.
    """

    mesh: MeshTri2
    basis_u: Basis
    basis_p: Basis
    u: np.ndarray
    p: np.ndarray
    force_reaction: float
    force_traction: float
    force_dissipation: float
    ndofs: int
    nelements: int
    timings: dict[str, float] = field(default_factory=dict)


def solve_stokes(mesh: MeshTri2, sphere_velocity: dict[str, float], intorder: int = 4
                 ) -> StokesSolution:
    """Solve axisymmetric Stokes flow on ``mesh`` with the named boundary conditions.

    Parameters
    ----------
    mesh
        Second-order mesh with named boundaries (see module docstring); ``sphere`` required.
    sphere_velocity
        Axial velocity of each moving body, e.g. ``{"sphere": -1.0}`` or
        ``{"sphere": -0.5, "sphere2": 0.5}`` (units of the speed scale).
    intorder
        Quadrature order (the hoop term and the r weight are not polynomials on curved
        elements; order 4 agrees with order 6 within 3e-9 in the force, order 3 is off by
        up to 7e-6).
    """
    t0 = time.perf_counter()
    names = set(mesh.boundaries)
    if "sphere" not in names:
        raise SolverError("mesh has no 'sphere' boundary")
    unknown = names - {"axis", "wall", "symmetry", "sphere", "sphere2", "far", "free_surface"}
    if unknown:
        raise SolverError(f"mesh has unknown boundary groups {sorted(unknown)}")
    eu = ElementVector(ElementTriP2())
    bu = Basis(mesh, eu, intorder=intorder)
    bp = Basis(mesh, ElementTriP1(), intorder=intorder)
    A = viscous_form.assemble(bu)
    B = divergence_form.assemble(bu, bp)
    nu, npr = A.shape[0], B.shape[0]
    K = sp.bmat([[A, -B.T], [-B, None]], format="csr")

    x = np.zeros(nu + npr)
    fixed: list[np.ndarray] = []

    def dofs(name: str, comp: str) -> np.ndarray:
        return bu.get_dofs(name).all(comp) if name in names else np.empty(0, dtype=np.int64)

    for name in ("wall", "far"):
        fixed += [dofs(name, "u^1"), dofs(name, "u^2")]
    fixed += [dofs("axis", "u^1"), dofs("symmetry", "u^2")]
    moving_z: dict[str, np.ndarray] = {}
    for name in sphere_velocity:
        if name not in names:
            raise SolverError(f"moving body '{name}' is not a mesh boundary")
        dz = dofs(name, "u^2")
        moving_z[name] = dz
        fixed += [dofs(name, "u^1"), dz]
    # set moving values last: sphere dofs on the axis keep their u_z
    for name, vel in sphere_velocity.items():
        x[moving_z[name]] = vel
    if "free_surface" not in names and "far" in names:
        far_p = bp.get_dofs("far").all()
        fixed.append(np.array([nu + far_p[0]]))
    elif "free_surface" not in names:
        fixed.append(np.array([nu]))  # closed domain without a free surface: pin one pressure
    D = np.unique(np.concatenate(fixed).astype(np.int64))
    free = np.setdiff1d(np.arange(nu + npr), D, assume_unique=True)
    t1 = time.perf_counter()
    rhs = -(K[free][:, D] @ x[D])
    Kff = K[free][:, free].tocsc()
    try:
        x[free] = spla.spsolve(Kff, rhs, permc_spec="COLAMD")
    except RuntimeError as exc:
        raise SolverError(f"Stokes linear solve failed: {exc}") from exc
    if not np.all(np.isfinite(x)):
        raise SolverError("Stokes linear solve returned non-finite values (singular system?)")
    t2 = time.perf_counter()
    u, p = x[:nu], x[nu:]
    res = K[:nu] @ x
    dz = moving_z["sphere"]
    f_reac = -2.0 * math.pi * float(res[dz].sum())
    diss = 2.0 * math.pi * float(u @ (A @ u))
    # dissipation identity: sum_bodies F_b U_b = -Phi; attribute to 'sphere' by symmetry of
    # the imposed motion (exact for one moving body, and for two mirror-image bodies)
    v_s = sphere_velocity["sphere"]
    f_diss = -diss / v_s / len(sphere_velocity) if v_s else float("nan")
    fb = FacetBasis(mesh, eu, facets=mesh.boundaries["sphere"], intorder=intorder)
    fbp = fb.with_element(ElementTriP1())
    f_trac = 2.0 * math.pi * float(traction_z.assemble(fb, u=fb.interpolate(u),
                                                        p=fbp.interpolate(p)))
    t3 = time.perf_counter()
    return StokesSolution(mesh=mesh, basis_u=bu, basis_p=bp, u=u, p=p,
                          force_reaction=f_reac, force_traction=f_trac,
                          force_dissipation=f_diss, ndofs=nu + npr, nelements=mesh.t.shape[1],
                          timings={"assemble": t1 - t0, "solve": t2 - t1, "post": t3 - t2})


# ---- meshes for a scene -------------------------------------------------------------------


def gap_elements(mesh: MeshTri2, z_lo: float, z_hi: float) -> int:
    """Number of mesh edges on the axis between z_lo and z_hi (elements across the gap)."""
    if "axis" not in mesh.boundaries:
        return 0
    f = mesh.boundaries["axis"]
    zm = mesh.p[1, mesh.facets[:, f]].mean(axis=0)
    return int(np.count_nonzero((zm > z_lo) & (zm < z_hi)))


def _mesh_for(scene: Scene, s: float, res: Resolution, method: str, cache: Any
              ) -> tuple[MeshTri2, dict[str, float], tuple[float, float], int]:
    """Mesh, body velocities, axis interval of the gap and required elements across it."""
    if scene.amount == "film":
        film = scene.film_thickness / scene.radius
        mesh = get_mesh("sphere_film", cache=cache, gap=s, film=film, res=res)
        return mesh, {"sphere": -1.0}, (0.0, s), res.n_gap
    if scene.kind == "sphere-wall":
        mesh = get_mesh("sphere_wall", cache=cache, gap=s, res=res, plane="wall")
        return mesh, {"sphere": -1.0}, (0.0, s), res.n_gap
    if method == "symmetry":
        mesh = get_mesh("sphere_wall", cache=cache, gap=0.5 * s, res=res, plane="symmetry")
        return mesh, {"sphere": -0.5}, (0.0, 0.5 * s), res.n_gap
    mesh = get_mesh("sphere_sphere", cache=cache, gap=s, res=res)
    return mesh, {"sphere": -0.5, "sphere2": 0.5}, (-0.5 * s, 0.5 * s), 2 * res.n_gap


def _save_fields(out: Path, scene: Scene, i: int, sol: StokesSolution) -> Path:
    """Velocity (m/s) and pressure (Pa) at the mesh vertices, SI coordinates, to VTU."""
    from wetcontact.meshes.io import write_vtu

    R, v, eta = scene.radius, scene.velocity, scene.viscosity
    nd = sol.basis_u.nodal_dofs
    vel = np.column_stack([sol.u[nd[0]], sol.u[nd[1]], np.zeros(nd.shape[1])]) * v
    path = Path(out) / f"stokes-{scene.name}-{i:03d}.vtu"
    return write_vtu(path, sol.mesh, {"velocity": vel, "pressure": sol.p * eta * v / R},
                     scale=R)


# ---- the registered model -----------------------------------------------------------------


@register
class Stokes(Model):
    """Axisymmetric Stokes FEM (Taylor-Hood P2/P1, isoparametric P2 geometry, gmsh meshes).

    Immersed sphere-wall and two-sphere scenes, and a sphere dipping into a flat film.
    ``scene.velocity`` v is the approach speed; for two spheres it is the relative speed
    ``-dS/dt`` and each sphere moves at v/2. The force is the axial force on the (first)
    sphere, positive when it pushes the surfaces apart, ``F = eta R v f(S/R)`` with f from
    the unit problem. Options: ``method`` (``"symmetry"``: equal spheres solved as one
    sphere approaching a shear-free plane at speed v/2 and gap S/2; ``"full"``: both
    spheres meshed), ``save_fields`` (a directory for VTU files), ``cache`` (mesh cache
    directory), and the mesh resolution keys of :class:`~wetcontact.meshes.builders.Resolution`.
    """

    name = "stokes"
    level = 3
    component = "viscous"
    validity = ("Re << 1; immersed sphere-wall or equal spheres (any S/R >= 1e-5), or a "
                "sphere in a flat film (S < delta <= S + R); no slip")
    order = 4.0
    saves_fields = True
    reference_rank = {"viscous": 30}
    reference = ("Taylor-Hood axisymmetric Stokes FEM (scikit-fem, gmsh); force by the "
                 "reaction (dissipation) and by the traction integral")
    presets = {
        "fast": {"n_gap": 3, "h_sphere": 0.08, "growth": 0.25, "far": 1.0e3, "n_film": 4},
        "default": {"n_gap": 4, "h_sphere": 0.05, "growth": 0.15, "far": 1.0e3, "n_film": 6},
        "accurate": {"n_gap": 8, "h_sphere": 0.02, "growth": 0.08, "far": 1.0e3, "n_film": 8},
    }
    error_bound = {"fast": 1e-3, "default": 1e-4, "accurate": 1e-5}
    """Relative error bound of the immersed force per preset (measured, benchmarks/)."""

    def check(self, scene: Scene) -> None:
        s = scene.gap_array / scene.radius
        if s.min() < MIN_GAP:
            raise ValidityError(self.name, f"S/R = {s.min():.3g} < {MIN_GAP:g}: the graded "
                                "mesh cannot resolve the gap to the preset's accuracy",
                                "cox-brenner")
        if scene.amount == "bridge":
            raise ValidityError(self.name, "a liquid bridge needs the meniscus profile of the "
                                "finite-element meniscus solver, which is not available yet",
                                "lubrication")
        if scene.slip_length_sphere > 0 or scene.slip_length_wall > 0:
            raise ValidityError(self.name, "Navier slip is not implemented (no-slip only)",
                                "vinogradova")
        if scene.kind == "sphere-sphere" and not scene.equal_spheres:
            raise ValidityError(self.name, "two spheres of unequal radii are not meshed yet",
                                "reynolds")
        if scene.amount == "film":
            d = scene.film_thickness / scene.radius
            if np.any((s < d) & (d > s + 1.0)):
                raise ValidityError(self.name, f"film thickness delta/R = {d:g} reaches above "
                                    "the sphere's equator at some gap (allowed S < delta <= "
                                    "S + R)", "thinfilm")

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
               intorder: int = 4, **res_opts: Any) -> ForceCurve:
        if method not in ("symmetry", "full"):
            raise InputError(f"model 'stokes': method = {method!r}; allowed: 'symmetry', 'full'")
        res = Resolution(**res_opts)
        R, eta, v = scene.radius, scene.viscosity, scene.velocity
        gaps = scene.gap_array
        n = gaps.size
        f_reac, f_trac = np.zeros(n), np.zeros(n)
        ndofs, nel, ngap, times = (np.zeros(n) for _ in range(4))
        files: list[str] = []
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
            mesh, vel, (z0, z1), need = _mesh_for(scene, s, res, method, cache)
            ngap[i] = gap_elements(mesh, z0, z1)
            if ngap[i] < need:
                raise SolverError(f"model 'stokes': mesh at S/R = {s:.3g} has {int(ngap[i])} "
                                  f"elements across the gap, fewer than the {need} the preset "
                                  "needs; refine (n_gap) or use a larger gap")
            sol = solve_stokes(mesh, vel, intorder=intorder)
            f_reac[i] = sol.force_reaction * eta * R * v
            f_trac[i] = sol.force_traction * eta * R * v
            ndofs[i], nel[i] = sol.ndofs, sol.nelements
            if save_fields is not None:
                files.append(str(_save_fields(Path(save_fields), scene, i, sol)))
            times[i] = time.perf_counter() - t0
        est = None
        if scene.amount == "immersed":
            est = np.full(n, self.error_bound.get(preset, np.nan))
            if not np.isfinite(est).all():
                est = None
        diag: dict[str, Any] = {"dofs": ndofs.astype(int).tolist(),
                                "elements": nel.astype(int).tolist(),
                                "gap_elements": ngap.astype(int).tolist(),
                                "gap_wall_time_s": times.tolist(), "method": method}
        if files:
            diag["vtu_files"] = files
        return ForceCurve(case=scene.name, model=self.name, gap=gaps, force_viscous=f_reac,
                          force_capillary=None, extras={"force_traction": f_trac},
                          error_estimate=est, diagnostics=diag)
