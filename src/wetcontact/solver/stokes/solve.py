"""Axisymmetric Stokes flow by Taylor-Hood finite elements: the viscous-force reference (level 3).

Steady Stokes flow ``-div(sigma) = 0``, ``div u = 0``, ``sigma = -p I + 2 eta e(u)`` in the
meridian half-plane (r, z), r >= 0, without swirl. With the volume element 2 pi r dr dz the
weak form is: find (u, p) with

    a(u, w) - b(w, p) = 0,   b(u, q) = 0,
    a(u, w) = int 2 eta [e_rr(u) e_rr(w) + e_zz e_zz + 2 e_rz e_rz + (u_r/r)(w_r/r)] r dr dz,
    b(w, q) = int q (r d_r w_r + w_r + r d_z w_z) dr dz,

``(u_r/r)(w_r/r)`` the hoop term. P2 velocity / P1 pressure on a second-order gmsh mesh
(``wetcontact.meshes``). Boundaries by name: ``axis`` u_r = 0; ``wall``, ``far`` u = 0;
``symmetry`` u_z = 0, shear-free; ``sphere``/``sphere2`` the body's velocity;
``free_surface`` traction-free. Navier slip (length b) adds ``int (eta/b) u_t w_t r ds``
(:func:`navier_slip_form`), the normal condition in a rotated frame (Engelman, Sani &
Gresho 1982). A quasi-static meniscus (``solve_stokes(surface=...)``, bridges) has its
normal velocity prescribed and the pressure constant fixed so that it does no net work;
the force is then the dissipation over the speed, ``F = Phi / v``. Films: a flat,
traction-free top meeting the no-slip sphere in an integrable stick-slip corner
(Richardson 1970), graded to 2e-3, 5e-4, 1e-4 delta (fast, default, accurate).

Force on the sphere: the **reaction**, ``F_z = -2 pi sum_i [A u - B^T p]_i`` on the sphere's
u_z degrees of freedom (O(h^4); reported), and the **traction** integral (O(h^2);
``force_traction``). Units R = eta = 1, unit speed; ``F = eta R v f(S/R)``. Far boundary
u = 0 at L = max(``far``, 100 (S/R + 2)) R (truncation below 1e-6 for S/R <= 10 at 1e3 R).

Sign and speed: the axial force on the sphere, positive when it pushes the surfaces apart;
for two spheres v is the relative approach speed ``-dS/dt`` and the force is on the first.
Domain: S/R >= 1e-5; R2/R in [0.1, 10].

Accuracy (``benchmarks/bench_stokes.py``; Brenner 1961 and the two-sphere series, S/R 1e-4
to 10): ``fast`` <= 5e-4, ``default`` <= 1e-4, ``accurate`` <= 6e-6, all errors positive;
Basset's slipping sphere within 2e-5; unequal spheres against Jeffrey & Onishi (1984);
bridges: presets within 3.1e-5 (fast) and 1.1e-5 (default) of accurate up to 0.99 S_c; films:
within 3.3e-4 and 5.7e-5. Formulation, limits and checks in full: the guide's *Solver notes*
(``docs/solvers.md``).

Sources: Brezzi & Fortin (mixed FEM); Carey, Chow & Seager (1985) (reaction flux); Navier
(1823); Basset (1888); Vinogradova (1995); Brenner (1961); Maude (1961); Huh & Scriven (1971).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import (
    Basis,
    ElementTriP1,
    ElementTriP2,
    ElementVector,
    FacetBasis,
    MeshTri2,
)
from skfem.mapping import MappingIsoparametric

from wetcontact.errors import SolverError
from wetcontact.solver.stokes.forms import (
    divergence_form,
    navier_slip_form,
    surface_work,
    traction_z,
    viscous_form,
)

SurfaceMotion = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]
"""Node coordinates (2, n) -> (normal velocity, n_r, n_z) of a free surface."""


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


def solve_stokes(mesh: MeshTri2, sphere_velocity: dict[str, float], intorder: int = 4,
                 slip: dict[str, float] | None = None,
                 surface: SurfaceMotion | None = None) -> StokesSolution:
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
    slip
        Navier slip length b (units of the length scale, > 0) per solid boundary
        (``"sphere"``, ``"sphere2"``, ``"wall"``); a boundary not named is no-slip. See
        :func:`navier_slip_form`: the normal velocity is the body's, the tangential slip
        velocity ``u_t - U_t = (b/eta) sigma_nt``.
    surface
        Kinematic condition on ``free_surface`` (quasi-static meniscus): a function of the
        node coordinates (2, n) returning the prescribed normal velocity and the unit normal
        (n_r, n_z) there; the tangential traction stays zero. At a contact line the node
        takes the velocity meeting both normal conditions (free surface and solid). The
        pressure constant is then fixed by a zero mean (r-weighted) pressure on the free
        surface. Without it the free surface is traction-free.
    """
    t0 = time.perf_counter()
    names = set(mesh.boundaries)
    if "sphere" not in names:
        raise SolverError("mesh has no 'sphere' boundary")
    unknown = names - {"axis", "wall", "symmetry", "sphere", "sphere2", "far", "free_surface"}
    if unknown:
        raise SolverError(f"mesh has unknown boundary groups {sorted(unknown)}")
    slip = {k: float(b) for k, b in (slip or {}).items() if b}
    for name, b in slip.items():
        if name not in ("sphere", "sphere2", "wall") or name not in names:
            raise SolverError(f"slip on '{name}': not a solid boundary of this mesh")
        if not (math.isfinite(b) and b > 0):
            raise SolverError(f"slip length on '{name}' = {b!r}; allowed: finite > 0")
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

    velocity = {"wall": 0.0, **sphere_velocity}
    for name in sphere_velocity:
        if name not in names:
            raise SolverError(f"moving body '{name}' is not a mesh boundary")
    # Navier slip: friction matrix, its body-velocity load, and the nodes turned to (n, t)
    M = sp.csr_matrix((nu, nu))
    body = np.zeros(nu)
    frames: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}
    if slip:
        pinned = pinned_dofs(bu, names, slip)
        for name, b in slip.items():
            fb = facet_basis(mesh, eu, name, intorder)
            Mb = navier_slip_form.assemble(fb, friction=1.0 / b)
            ub = np.zeros(nu)
            ub[dofs(name, "u^2")] = velocity.get(name, 0.0)
            M, body = M + Mb, body + Mb @ ub
            frames[name] = _slip_frame(bu, name, dofs(name, "u^1"), dofs(name, "u^2"), pinned)
    for name in ("wall", "far"):
        if name not in slip:
            fixed += [dofs(name, "u^1"), dofs(name, "u^2")]
    fixed += [dofs("axis", "u^1"), dofs("symmetry", "u^2")]
    moving_z: dict[str, np.ndarray] = {}
    for name in sphere_velocity:
        moving_z[name] = dofs(name, "u^2")
        if name not in slip:
            fixed += [dofs(name, "u^1"), moving_z[name]]
    # normal-constrained nodes: name -> (ir, iz, n_r, n_z, u_n)
    normal: dict[str, tuple[np.ndarray, ...]] = {
        name: (ir, iz, nr, nz, velocity.get(name, 0.0) * nz)
        for name, (ir, iz, nr, nz) in frames.items()}
    if surface is not None:
        if "free_surface" not in names:
            raise SolverError("a free-surface motion is given but the mesh has no "
                              "'free_surface'")
        ir, iz = dofs("free_surface", "u^1"), dofs("free_surface", "u^2")
        un, nr, nz = (np.asarray(a, dtype=float) for a in surface(bu.doflocs[:, ir]))
        keep = ~np.isin(ir, pinned_dofs(bu, names, slip | {"free_surface": 0.0}))
        normal["free_surface"] = (ir[keep], iz[keep], nr[keep], nz[keep], un[keep])
        # a meniscus meeting a symmetry plane (u_z = 0) at a right angle (n_z = 0): the
        # kinematic condition fixes u_r there
        on_sym = np.isin(ir, dofs("symmetry", "u^1")) & ~keep
        if np.any(on_sym):
            if np.any(np.abs(nz[on_sym]) > 0.05):  # the interpolated normal: ~1e-3 there
                raise SolverError("free surface meets the symmetry plane at an angle: "
                                  f"n_z = {np.abs(nz[on_sym]).max():.3g}")
            x[ir[on_sym]] = un[on_sym] / nr[on_sym]
            fixed.append(ir[on_sym])
    for name in frames:
        # nodes of a slip boundary shared with the axis or a no-slip boundary stay fixed
        ir, iz = normal[name][:2]
        fixed.append(np.setdiff1d(np.concatenate([dofs(name, "u^1"), dofs(name, "u^2")]),
                                  np.concatenate([ir, iz])))
    # set moving values last: sphere dofs on the axis keep their u_z
    for name, vel in sphere_velocity.items():
        x[moving_z[name]] = vel
    corners = _corner_velocities(normal)
    for ir, iz, ur, uz in corners:
        x[ir], x[iz] = ur, uz
        fixed += [ir, iz]
    T = sp.identity(nu + npr, format="csr")
    if normal:
        # rotated nodes: dof ir carries u_n (fixed), dof iz carries u_t (free)
        ir, iz, nr, nz, un = (np.concatenate(a) for a in zip(*normal.values(), strict=True))
        done = np.isin(ir, np.concatenate([c[0] for c in corners])) if corners else (
            np.zeros(ir.size, dtype=bool))
        ir, iz, nr, nz, un = ir[~done], iz[~done], nr[~done], nz[~done], un[~done]
        rows = np.concatenate([ir, ir, iz, iz])
        cols = np.concatenate([ir, iz, ir, iz])
        vals = np.concatenate([nr, -nz, nz, nr])  # u_r = nr u_n - nz u_t, u_z = nz u_n + nr u_t
        other = np.setdiff1d(np.arange(nu + npr), np.concatenate([ir, iz]))
        T = sp.csr_matrix((np.concatenate([vals, np.ones(other.size)]),
                           (np.concatenate([rows, other]), np.concatenate([cols, other]))),
                          shape=(nu + npr, nu + npr))
        x[ir], x[iz] = un, 0.0
        fixed.append(ir)
    if surface is not None:
        fixed.append(np.array([nu + _pressure_pin(mesh)]))
    if "free_surface" not in names and "far" in names:
        far_p = bp.get_dofs("far").all()
        fixed.append(np.array([nu + far_p[0]]))
    elif "free_surface" not in names:
        fixed.append(np.array([nu]))  # closed domain without a free surface: pin one pressure
    D = np.unique(np.concatenate(fixed).astype(np.int64))
    free = np.setdiff1d(np.arange(nu + npr), D, assume_unique=True)
    Ks = sp.bmat([[A + M, -B.T], [-B, None]], format="csr") if slip else K
    Kt = (T.T @ Ks @ T).tocsr()
    load = T.T @ np.concatenate([body, np.zeros(npr)])
    t1 = time.perf_counter()
    rhs = load[free] - Kt[free][:, D] @ x[D]
    Kff = Kt[free][:, free].tocsc()
    try:
        x[free] = spla.spsolve(Kff, rhs, permc_spec="COLAMD")
    except RuntimeError as exc:
        raise SolverError(f"Stokes linear solve failed: {exc}") from exc
    if not np.all(np.isfinite(x)):
        raise SolverError("Stokes linear solve returned non-finite values (singular system?)")
    x = T @ x
    t2 = time.perf_counter()
    if surface is not None:
        # pressure constant: the free surface does no net work, int u_n sigma_nn r ds = 0
        # (then the reaction and the traction integral equal the dissipation force; see
        # the module docstring); the pin at the contact line only removed the null space
        ffb = facet_basis(mesh, eu, "free_surface", intorder)
        ffp = ffb.with_element(ElementTriP1())
        uf, pf = ffb.interpolate(x[:nu]), ffp.interpolate(x[nu:])
        work = float(surface_work.assemble(ffb, u=uf, p=pf))
        flux = float(surface_work.assemble(ffb, u=uf, p=ffp.interpolate(-np.ones(npr)),
                                           viscous=0.0))
        if flux == 0.0:
            raise SolverError("free surface at rest: its pressure constant is undefined")
        x[nu:] += work / flux
    u, p = x[:nu], x[nu:]
    res = K[:nu] @ x
    dz = moving_z["sphere"]
    f_reac = -2.0 * math.pi * float(res[dz].sum())
    diss = 2.0 * math.pi * float(u @ (A @ u))
    if slip:
        ub = np.zeros(nu)
        for name, vel in sphere_velocity.items():
            ub[moving_z[name]] = vel
        # friction dissipation int (eta/b) |u_t - U_t|^2 dA: M (u - U) with U per boundary
        diss += 2.0 * math.pi * float(u @ (M @ u) - 2.0 * u @ body + ub @ (M @ ub))
    # dissipation identity: sum_bodies F_b U_b = -Phi; attribute to 'sphere' by symmetry of
    # the imposed motion (exact for one moving body, and for two mirror-image bodies)
    v_s = sphere_velocity["sphere"]
    movers = sum(1 for vel in sphere_velocity.values() if vel)
    f_diss = -diss / v_s / movers if v_s else float("nan")
    fb = facet_basis(mesh, eu, "sphere", intorder)
    fbp = fb.with_element(ElementTriP1())
    f_trac = 2.0 * math.pi * float(traction_z.assemble(fb, u=fb.interpolate(u),
                                                        p=fbp.interpolate(p)))
    t3 = time.perf_counter()
    return StokesSolution(mesh=mesh, basis_u=bu, basis_p=bp, u=u, p=p,
                          force_reaction=f_reac, force_traction=f_trac,
                          force_dissipation=f_diss, ndofs=nu + npr, nelements=mesh.t.shape[1],
                          timings={"assemble": t1 - t0, "solve": t2 - t1, "post": t3 - t2})


class _Isoparametric(MappingIsoparametric):
    """scikit-fem's isoparametric mapping with a looser tolerance in ``invF``.

    The stock Newton inversion stops at an absolute 1e-12 in reference coordinates, which
    rounding cannot reach on elements 1e-5 times smaller than their distance from the
    origin (contact-line and tiny-gap grading); 1e-9 still failed on bridge contact-line
    elements of 1e-7 R at r = 0.2 R (rounding 6e-17 / 1e-7 in reference coordinates, and
    Newton stagnates there). 1e-8 is still far below what quadrature needs (the Newton
    step converges quadratically, so the error left is far smaller than the tolerance).
    """

    def invF(self, x, tind=None, newton_max_iters=50, newton_tol=1e-8):
        return super().invF(x, tind=tind, newton_max_iters=newton_max_iters,
                            newton_tol=newton_tol)


def facet_basis(mesh: MeshTri2, elem: Any, name: str, intorder: int) -> FacetBasis:
    """Facet basis on the named boundary (with the tolerant mapping)."""
    mapping = _Isoparametric(mesh, mesh.elem(), mesh.bndelem)
    return FacetBasis(mesh, elem, mapping=mapping, facets=mesh.boundaries[name],
                      intorder=intorder)


def pinned_dofs(bu: Basis, names: set[str], slip: dict[str, float]) -> np.ndarray:
    """u_r dofs of the boundaries that fix both components or u_r (axis, far, no-slip solids,
    the symmetry plane): nodes there are never turned to a normal-tangential frame."""
    out = [bu.get_dofs(nm).all("u^1") for nm in names if nm not in slip and nm != "free_surface"]
    return np.concatenate(out) if out else np.empty(0, dtype=np.int64)


def _corner_velocities(normal: dict[str, tuple[np.ndarray, ...]]
                       ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """Nodes with two normal conditions (a contact line: a solid and the free surface).

    The velocity there solves ``n1 . u = u_n1``, ``n2 . u = u_n2`` (the contact line moves
    along the solid at the speed the free surface imposes). Returns, per pair of
    boundaries, (ir, iz, u_r, u_z) of the shared nodes.
    """
    out = []
    keys = list(normal)
    for i, a in enumerate(keys):
        for b in keys[i + 1:]:
            ia, ib = normal[a], normal[b]
            common, ka, kb = np.intersect1d(ia[0], ib[0], return_indices=True)
            if common.size == 0:
                continue
            n1r, n1z, u1 = ia[2][ka], ia[3][ka], ia[4][ka]
            n2r, n2z, u2 = ib[2][kb], ib[3][kb], ib[4][kb]
            det = n1r * n2z - n1z * n2r
            if np.any(np.abs(det) < 1e-8):
                raise SolverError(f"contact line between '{a}' and '{b}' with parallel "
                                  "normals (contact angle 0 or 180 deg): velocity undefined")
            ur = (u1 * n2z - u2 * n1z) / det
            uz = (n1r * u2 - n2r * u1) / det
            out.append((common, ia[1][ka], ur, uz))
    return out


def _pressure_pin(mesh: MeshTri2) -> int:
    """The vertex whose pressure is pinned in a domain bounded by a moving free surface.

    Every boundary prescribes the normal velocity, so incompressibility needs the boundary
    flux to vanish; the discrete flux of the quasi-static meniscus' ``u_n`` at the nodes of
    a P2 boundary does so only to discretisation error (1e-11 to 1e-8). Pinning one pressure
    (to remove the null space) drops the continuity equation of its vertex, so that error
    becomes a point source there, whose dissipation grows as the inverse square of the
    element size. The pin is therefore the free-surface vertex farthest from the surface's
    ends (its contact lines, or the symmetry plane), among the largest elements. At the
    contact line, where the pin used to be, the elements are a slip length across, and the
    source set the force's mesh dependence (+-3e-3, non-monotone in the grading, at
    S/R = 0.05 with b = 1e-6 R; now 3.5e-4 and monotone).
    """
    f = mesh.facets[:, mesh.boundaries["free_surface"]]
    verts, count = np.unique(f, return_counts=True)
    ends = verts[count == 1]
    if ends.size == 0:
        raise SolverError("free surface without ends: no pressure pin")
    p, pe = mesh.p[:, verts], mesh.p[:, ends]
    dist = np.min(np.hypot(p[0][:, None] - pe[0][None, :], p[1][:, None] - pe[1][None, :]),
                  axis=1)
    return int(verts[np.argmax(dist)])


def _slip_frame(bu: Basis, name: str, ir: np.ndarray, iz: np.ndarray, pinned: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Nodes of a slip boundary that turn to (normal, tangential) components, and normals.

    The nodal normal is exact: the wall's is (0, 1); a sphere's boundary nodes lie on a
    circle (isoparametric P2 geometry), whose centre an algebraic least-squares fit
    ``r^2 + z^2 + D r + E z + F = 0`` recovers to rounding. Nodes shared with a pinned
    boundary (the axis, the far boundary, a no-slip solid) are left out: they stay fixed.
    """
    xy = bu.doflocs[:, ir]
    if not np.allclose(xy, bu.doflocs[:, iz]):
        raise SolverError(f"slip boundary '{name}': velocity components are not co-located")
    if name == "wall":
        nr, nz = np.zeros(ir.size), np.ones(ir.size)
    else:
        G = np.column_stack([xy[0], xy[1], np.ones(ir.size)])
        coef = np.linalg.lstsq(G, -(xy[0] ** 2 + xy[1] ** 2), rcond=None)[0]
        d = xy - (-0.5 * coef[:2])[:, None]
        nr, nz = d / np.hypot(d[0], d[1])
    keep = ~np.isin(ir, pinned)
    return ir[keep], iz[keep], nr[keep], nz[keep]


# ---- meshes for a scene -------------------------------------------------------------------


def gap_elements(mesh: MeshTri2, z_lo: float, z_hi: float) -> int:
    """Number of mesh edges on the axis between z_lo and z_hi (elements across the gap)."""
    if "axis" not in mesh.boundaries:
        return 0
    f = mesh.boundaries["axis"]
    zm = mesh.p[1, mesh.facets[:, f]].mean(axis=0)
    return int(np.count_nonzero((zm > z_lo) & (zm < z_hi)))
