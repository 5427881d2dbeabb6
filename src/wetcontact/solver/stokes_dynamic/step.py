r"""One time step of the free-surface Stokes problem on the current mesh (units R = sigma =
eta = 1: velocity sigma/eta, time eta R/sigma, stress sigma/R, force sigma R).

Find (u, p) on the (predicted) domain Omega* of time t_{n+1} with

.. math::
    a(u, w) + f_b(u - U, w) + c\,\Delta t\, l(u, w) - b(w, p) = -l(Y, w)
        + \cos\theta_w\, r_w\, w_r + \cos\theta_s\, r_s\, \tau_s \cdot w,
    \qquad b(u, q) = 0,

``a``, ``b`` the axisymmetric viscous and divergence forms (hoop term included;
:mod:`wetcontact.solver.stokes.forms`, 2 pi dropped), ``f_b`` Navier's slip friction
``int (1/b) (u - U)_t w_t r ds`` on the sphere (U its velocity) and on the wall, and the
surface-tension form (the weak Laplace-Beltrami operator with its hoop term)

.. math::
    l(v, w) = \int_\Gamma \left(\partial_s v \cdot \partial_s w
        + \frac{v_r w_r}{r^2}\right) r\, ds,\qquad
    l(x, w) = \int_\Gamma (t \cdot \partial_s w + w_r / r)\, r\, ds,

the first variation of the area ``dA[w]``. Its evaluation at the new position
``Y + c dt u`` (Y the explicit part of the time scheme's update, :mod:`.run`) is
Baensch's (2001) semi-implicit curvature, which removes the capillary time-step limit.
The right-hand side is ``-dE[w]`` of the free energy
``E = sigma (A - cos theta_w A_wall - cos theta_s A_sphere)``: the contact angles are the
natural conditions at the lines, where the nodes slide along their solids (normal velocity
the solid's, imposed in a rotated frame). Axis: u_r = 0; wall: u_z = 0 (a symmetry plane:
u_z = 0, no friction, no contact line); sphere:
``u . n = U . n``; a lower sphere (``Domain.radius2``, at rest) like the wall, with
``u . n = 0`` in its rotated frame. The pressure level is set by the free surface (no
pin).

Force on the sphere (positive pushing the solids apart): the reaction of the discrete
system to the test function ``w = e_z`` on the sphere's nodes, ``F = -2 pi [a(u, w) - b(w,
p) + l(Y + c dt u, w)]``: the liquid's traction plus the interface's pull at the contact
line (the Young force is internal to the solid and does not enter).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, ElementTriP1, ElementTriP2, ElementVector

from wetcontact.errors import SolverError
from wetcontact.solver.stokes import (
    divergence_form,
    facet_basis,
    navier_slip_form,
    viscous_form,
)
from wetcontact.solver.stokes_dynamic.domain import (
    Domain,
    edges_of,
    lower_angle,
    p2_shape,
    sphere_angle,
)

_GX, _GW = np.polynomial.legendre.leggauss(5)
GAUSS5 = (0.5 * (_GX + 1.0), 0.5 * _GW)
"""5-point Gauss rule on [0, 1] for the (rational) surface integrands."""


LINE_LAWS = ("static", "cox-voinov", "pinned")
"""Contact-line conditions: the static angle at a sliding line, Cox-Voinov's dynamic angle,
or lines pinned to their material points of the solids."""


@dataclass(frozen=True)
class Wetting:
    """Contact angles (rad), Navier slip lengths (units R) of the sphere and the wall, and
    the contact-line law.

    ``line``: ``"static"`` (the static angles at lines that slide), ``"cox-voinov"`` (the
    dynamic angle ``theta_d^3 = theta_s^3 + 9 U ln(L/b)`` of each line, U its speed over
    the solid in sigma/eta, positive advancing, b that solid's slip length, L =
    ``macro_length`` R; Cox 1986, Voinov 1976) or ``"pinned"`` (both lines move with their
    solids; the angles follow from the flow).
    """

    theta_sphere: float
    theta_wall: float
    slip_sphere: float
    slip_wall: float
    line: str = "static"
    macro_length: float = 1.0

    def __post_init__(self) -> None:
        if self.line not in LINE_LAWS:
            raise SolverError(f"stokes-dynamic: line = {self.line!r}; allowed: {LINE_LAWS}")
        if not (math.isfinite(self.macro_length) and self.macro_length > 0):
            raise SolverError(f"stokes-dynamic: macro_length = {self.macro_length!r} R; "
                              "allowed: finite > 0")
        for name in ("theta_sphere", "theta_wall"):
            th = getattr(self, name)
            if not (math.isfinite(th) and 0.0 < th < math.pi):
                raise SolverError(f"stokes-dynamic: {name} = {th!r} rad; allowed: (0, pi)")
        for name in ("slip_sphere", "slip_wall"):
            b = getattr(self, name)
            if not (math.isfinite(b) and b > 0):
                raise SolverError(f"stokes-dynamic: {name} = {b!r} R; allowed: finite > 0")


@dataclass
class StepSolution:
    """Velocity (interleaved P2, per mesh node) and pressure (P1) of one step, and the force.

    ``force`` is on the sphere, ``force_wall`` on the lower solid (their sum vanishes in
    Stokes flow: a check), units sigma R.
    """

    u: np.ndarray
    p: np.ndarray
    force: float
    force_wall: float
    ndofs: int
    timings: dict[str, float] = field(default_factory=dict)

    def velocity(self, nodes: np.ndarray) -> np.ndarray:
        """Velocity (2, n) at mesh nodes."""
        return np.stack([self.u[2 * nodes], self.u[2 * nodes + 1]])


def surface_tension_matrix(domain: Domain, n: int) -> sp.csr_matrix:
    """The surface form ``l(v, w)`` on the interleaved P2 velocity dofs (size n)."""
    x = domain.mesh.doflocs
    e = edges_of(domain.surface)  # (N, 3): start, end, middle
    N, dN = p2_shape(GAUSS5[0])  # (3, q)
    xe = x[:, e]  # (2, N, 3)
    dx = np.einsum("cek,kq->ceq", xe, dN)  # dx/dxi (2, N, q)
    jac = np.hypot(dx[0], dx[1])  # ds/dxi
    r = np.einsum("ek,kq->eq", xe[0], N)
    if np.any(r <= 0):
        raise SolverError("free surface touches the axis: the bridge has pinched off")
    wq = GAUSS5[1]
    # tangential part, the same for both components: int N_k' N_l' / J^2 r J dxi
    ss = np.einsum("kq,lq,eq->ekl", dN, dN, wq * r / jac)
    hoop = np.einsum("kq,lq,eq->ekl", N, N, wq * jac / r)
    rows, cols, vals = [], [], []
    for c in (0, 1):
        blk = ss + hoop if c == 0 else ss
        dof = 2 * e + c
        rows.append(np.repeat(dof[:, :, None], 3, axis=2).ravel())
        cols.append(np.repeat(dof[:, None, :], 3, axis=1).ravel())
        vals.append(blk.ravel())
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n, n))


def solve_step(domain: Domain, dt: float, speed: float, wet: Wetting,
               intorder: int = 4, base: np.ndarray | None = None,
               coef: float = 1.0, line_speed: tuple[float, float] = (0.0, 0.0)
               ) -> StepSolution:
    """Solve the step's Stokes problem (module docstring) with the sphere moving at
    ``speed`` = dS/dt (units sigma/eta; > 0 separating).

    The surface tension is evaluated at ``Y = base + coef dt u`` (the new position of the
    free surface, linear in u): ``base`` (2, m) its explicit part per surface node
    (default: the current nodes). ``dt = 0`` gives the instantaneous Stokes flow of the
    current shape.

    Contact lines (``wet.line``): static angles; Cox-Voinov's ``cos theta_d(U)``
    linearised about ``line_speed`` = (U_wall, U_sphere), a prediction of the lines' speeds
    over their solids (the linearisation error is second order in the prediction's, so a
    prediction one step old keeps the scheme's order); or pinned lines (velocity the
    solid's, no angle condition).
    """
    try:
        return _solve_step(domain, dt, speed, wet, intorder, base, coef, line_speed)
    except SolverError:
        raise
    except Exception as exc:  # noqa: BLE001 - e.g. scikit-fem's map of a degenerate element
        raise SolverError(f"stokes-dynamic: the step's assembly failed ({exc})") from exc


def _solve_step(domain: Domain, dt: float, speed: float, wet: Wetting, intorder: int,
                base: np.ndarray | None, coef: float, line_speed: tuple[float, float]
                ) -> StepSolution:
    t0 = time.perf_counter()
    mesh = domain.mesh
    eu = ElementVector(ElementTriP2())
    bu = Basis(mesh, eu, intorder=intorder)
    bp = Basis(mesh, ElementTriP1(), intorder=intorder)
    A = viscous_form.assemble(bu)
    B = divergence_form.assemble(bu, bp)
    nu, npr = A.shape[0], B.shape[0]
    L = surface_tension_matrix(domain, nu)
    x = mesh.doflocs
    X = x.T.ravel()  # interleaved positions (r0, z0, r1, z1, ...)
    if base is not None:
        X = X.copy()
        X[2 * domain.surface], X[2 * domain.surface + 1] = base
    sph, wall, axis = domain.sphere, domain.wall, domain.axis
    # slip friction on both solids; the sphere's moves at (0, speed)
    Ms = navier_slip_form.assemble(facet_basis(mesh, eu, "sphere", intorder),
                                   friction=1.0 / wet.slip_sphere)
    wall_slip = domain.plane == "wall"  # a symmetry plane is shear-free, with no line
    Mw = navier_slip_form.assemble(facet_basis(mesh, eu, domain.lower_name, intorder),
                                   friction=1.0 / wet.slip_wall) if wall_slip else 0 * Ms
    ub = np.zeros(nu)
    ub[2 * sph + 1] = speed
    f = Ms @ ub - L @ X
    # contact lines: -dE of the wetted areas, cos(theta) r tau (tau out of the wetted zone)
    jw, js = domain.surface[0], domain.surface[-1]
    phi = float(sphere_angle(x[:, [js]], domain.gap)[0])
    tau = (math.cos(phi), math.sin(phi))
    # each line: node, static angle, slip length, tau, the solid's velocity along tau
    lines = [(js, wet.theta_sphere, wet.slip_sphere, tau, speed * tau[1], line_speed[1])]
    a2 = (0.0 if domain.radius2 is None
          else float(lower_angle(x[:, [jw]], domain.radius2)[0]))
    if wall_slip:  # the lower solid's tau: along it, away from its apex
        lines.insert(0, (jw, wet.theta_wall, wet.slip_wall, (math.cos(a2), -math.sin(a2)),
                         0.0, line_speed[0]))
    kd, rd, cd = [], [], []
    if wet.line != "pinned":
        for j, theta, slip, t, solid, guess in lines:
            c0, dc = math.cos(theta), 0.0
            if wet.line == "cox-voinov":  # cos theta_d(U) ~ c(U*) + c'(U*) (U - U*)
                us = linearisation_speed(theta, guess, slip, wet.macro_length)
                th, dc = cox_voinov(theta, us, slip, wet.macro_length)
                # U = (u - U_solid) . tau; the term c' (u . tau) r tau goes to the matrix
                c0 = math.cos(th) - dc * (us + solid)
                for a in (0, 1):
                    for b in (0, 1):
                        kd.append(-dc * x[0, j] * t[a] * t[b])
                        rd.append(2 * j + a)
                        cd.append(2 * j + b)
            f[2 * j] += x[0, j] * c0 * t[0]
            f[2 * j + 1] += x[0, j] * c0 * t[1]
    line_k = sp.csr_matrix((kd, (rd, cd)), shape=(nu, nu))
    K = sp.bmat([[A + Ms + Mw + line_k + (coef * dt) * L, -B.T], [-B, None]], format="csr")
    rhs = np.concatenate([f, np.zeros(npr)])
    # constraints: axis u_r = 0, wall u_z = 0, spheres u.n = U.n in a rotated frame
    sol = np.zeros(nu + npr)
    apex, origin = axis[-1], axis[0]
    rot = sph[sph != apex]
    c = np.array([0.0, 1.0 + domain.gap])[:, None]
    nr, nz = (x[:, rot] - c) / np.hypot(*(x[:, rot] - c))
    flat = wall  # nodes with u_z = 0
    if domain.radius2 is not None:  # the lower sphere at rest: u.n = 0 in its frame
        low = wall[wall != origin]
        c2 = np.array([0.0, -domain.radius2])[:, None]
        n2r, n2z = (x[:, low] - c2) / np.hypot(*(x[:, low] - c2))
        rot, nr, nz = np.concatenate([rot, low]), np.concatenate([nr, n2r]), np.concatenate(
            [nz, n2z])
        flat = np.array([origin])
    ir, iz = 2 * rot, 2 * rot + 1
    other = np.setdiff1d(np.arange(nu + npr), np.concatenate([ir, iz]))
    T = sp.csr_matrix((np.concatenate([nr, -nz, nz, nr, np.ones(other.size)]),
                       (np.concatenate([ir, ir, iz, iz, other]),
                        np.concatenate([ir, iz, ir, iz, other]))), shape=K.shape)
    sol[ir] = speed * nz  # dof ir carries u_n, iz the tangential velocity
    if domain.radius2 is not None:
        sol[ir[rot.size - low.size:]] = 0.0
    sol[2 * apex + 1] = speed
    pins: list[int] = []
    if wet.line == "pinned":  # each line moves with its solid
        sol[2 * js + 1] = speed * tau[1]  # the sphere's tangential velocity at the line
        pins = [2 * js + 1] + ([2 * jw + (domain.radius2 is not None)] if wall_slip else [])
    fixed = np.unique(np.concatenate([2 * axis, 2 * flat + 1, ir, [2 * apex + 1],
                                     np.array(pins, dtype=int)]))
    free = np.setdiff1d(np.arange(nu + npr), fixed, assume_unique=True)
    Kt = (T.T @ K @ T).tocsr()
    rt = T.T @ rhs
    t1 = time.perf_counter()
    try:
        sol[free] = spla.spsolve(Kt[free][:, free].tocsc(), rt[free] - Kt[free][:, fixed]
                                 @ sol[fixed], permc_spec="COLAMD")
    except RuntimeError as exc:
        raise SolverError(f"stokes-dynamic: linear solve failed: {exc}") from exc
    sol = T @ sol
    if not np.all(np.isfinite(sol)):
        raise SolverError("stokes-dynamic: the linear solve returned non-finite values")
    t2 = time.perf_counter()
    u, p = sol[:nu], sol[nu:]
    res = A @ u - B.T @ p + L @ (X + coef * dt * u)
    force = -2 * math.pi * float(res[2 * sph + 1].sum())
    force_wall = -2 * math.pi * float(res[2 * wall + 1].sum())
    return StepSolution(u=u, p=p, force=force, force_wall=force_wall, ndofs=nu + npr,
                        timings={"assemble": t1 - t0, "solve": t2 - t1})


COX_VOINOV_MAX = 3 * math.pi / 4
"""Largest dynamic angle of the Cox-Voinov law's validity (its small-slope expansion holds
to about 3 pi / 4; Voinov 1976)."""


def linearisation_speed(theta_s: float, speed: float, slip: float, macro_length: float
                        ) -> float:
    """``speed`` moved into the Cox-Voinov law's range (dynamic angle between 1 deg and
    :data:`COX_VOINOV_MAX`): the point the law is linearised about. A predicted speed may
    overshoot where the true one does not."""
    g = math.log(macro_length / slip)
    if g <= 0.0:
        return speed
    lo = (math.radians(1.0) ** 3 - theta_s**3) / (9.0 * g)
    hi = ((0.99 * COX_VOINOV_MAX) ** 3 - theta_s**3) / (9.0 * g)
    return min(max(speed, lo), hi)


def cox_voinov(theta_s: float, speed: float, slip: float, macro_length: float
               ) -> tuple[float, float]:
    """The dynamic angle ``theta_d`` (rad) of a line moving at ``speed`` (sigma/eta, > 0
    advancing) over a solid of slip length ``slip``, and ``d cos(theta_d)/d speed``:
    ``theta_d^3 = theta_s^3 + 9 speed ln(macro_length/slip)`` (Cox 1986, eq. 7.9; Voinov
    1976).

    Raises
    ------
    SolverError
        A receding line too fast for the law (``theta_d^3 <= 0``: the liquid would leave a
        film behind) or a dynamic angle above :data:`COX_VOINOV_MAX`.
    """
    g = math.log(macro_length / slip)
    cube = theta_s**3 + 9.0 * speed * g
    if cube <= 0.0:
        raise SolverError(f"stokes-dynamic: a line receding at Ca = {-speed:.3g} is faster "
                          f"than Cox-Voinov allows at theta_s = {math.degrees(theta_s):.3g} "
                          "deg (theta_d -> 0: a film is left behind)")
    th = cube ** (1.0 / 3.0)
    if th > COX_VOINOV_MAX:
        raise SolverError(f"stokes-dynamic: Cox-Voinov dynamic angle {math.degrees(th):.4g} "
                          f"deg > {math.degrees(COX_VOINOV_MAX):g} deg, outside the law")
    return th, -math.sin(th) * 3.0 * g / th**2
