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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any, ClassVar

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq
from scipy.sparse.linalg import splu
from skfem import Basis, ElementLineP2, MeshLine

from wetcontact.errors import InputError, SolverError, ValidityError
from wetcontact.models import ForceCurve, Model, register
from wetcontact.scene import Scene

__all__ = [
    "Bridge",
    "BridgeSolution",
    "SeparationCurve",
    "MeniscusModel",
    "energy_derivative",
    "force_separation_curve",
    "meniscus_profile",
    "rupture_distance",
    "solve_suction",
    "solve_volume",
]

THETA_MAX = math.radians(150.0)
DEFAULT_ELEMENTS = 128
PHI_MAX = math.radians(70.0)  # largest half-filling angle accepted (else volume too large)


# ---------------------------------------------------------------------------------------
# Problem description
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Bridge:
    """The solids and the liquid of a bridge (SI units, radians).

    Attributes
    ----------
    radius
        Radius R1 of the upper sphere (m), or ``None`` for a plate (analytic checks).
    radius2
        Radius R2 of the lower sphere (m), or ``None`` for a wall (plate).
    contact_angle1, contact_angle2
        Contact angle on the upper solid and on the lower solid, in [0, 150 deg].
    surface_tension
        sigma (N/m).
    gravity, density
        g (m/s^2, along -z) and liquid density (kg/m^3); gravity is off by default.
    """

    radius: float | None
    radius2: float | None = None
    contact_angle1: float = 0.0
    contact_angle2: float = 0.0
    surface_tension: float = 0.072
    gravity: float = 0.0
    density: float = 0.0

    def __post_init__(self) -> None:
        for name in ("radius", "radius2"):
            val = getattr(self, name)
            if val is not None and not (math.isfinite(val) and val > 0):
                raise InputError(f"meniscus: {name} = {val!r}; allowed: > 0 m or None")
        for name in ("contact_angle1", "contact_angle2"):
            val = getattr(self, name)
            if not (math.isfinite(val) and 0.0 <= val <= THETA_MAX):
                raise InputError(
                    f"meniscus: {name} = {math.degrees(val):.6g} deg; allowed: [0, 150] deg"
                )
        if not (math.isfinite(self.surface_tension) and self.surface_tension > 0):
            raise InputError(f"meniscus: surface_tension = {self.surface_tension!r}; "
                             "allowed: > 0 N/m")
        if self.gravity < 0 or self.density < 0:
            raise InputError("meniscus: gravity and density must be >= 0")

    @classmethod
    def from_scene(cls, scene: Scene) -> Bridge:
        """The bridge of a :class:`~wetcontact.scene.Scene` (sphere 1 on top)."""
        return cls(
            radius=scene.radius,
            radius2=scene.radius2 if scene.kind == "sphere-sphere" else None,
            contact_angle1=scene.contact_angle_sphere,
            contact_angle2=scene.contact_angle_wall,
            surface_tension=scene.surface_tension,
            gravity=scene.gravity,
            density=scene.density,
        )

    def length_scale(self, volume: float | None) -> float:
        """The unit of length inside the solver: R1, else R2, else V^(1/3)."""
        if self.radius is not None:
            return self.radius
        if self.radius2 is not None:
            return self.radius2
        if volume is None:
            raise InputError("meniscus: a plate-plate bridge needs the volume as length scale")
        return volume ** (1.0 / 3.0)

    def _geo(self, ell: float) -> _Geo:
        return _Geo(
            rt=None if self.radius is None else self.radius / ell,
            rb=None if self.radius2 is None else self.radius2 / ell,
            tht=self.contact_angle1, thb=self.contact_angle2,
            bo=self.density * self.gravity * ell**2 / self.surface_tension,
        )


@dataclass(frozen=True)
class _Geo:
    """Dimensionless solids (lengths over ell, pressure over sigma/ell)."""

    rt: float | None
    rb: float | None
    tht: float
    thb: float
    bo: float

    # contact-line position and tangent angle on each solid, with d/dc --------------
    def top(self, c: float, s: float) -> tuple[np.ndarray, np.ndarray]:
        if self.rt is None:
            return np.array([c, s, self.tht]), np.array([1.0, 0.0, 0.0])
        R = self.rt
        return (np.array([R * math.sin(c), s + R * (1 - math.cos(c)), c + self.tht]),
                np.array([R * math.cos(c), R * math.sin(c), 1.0]))

    def bottom(self, c: float) -> tuple[np.ndarray, np.ndarray]:
        if self.rb is None:
            return np.array([c, 0.0, math.pi - self.thb]), np.array([1.0, 0.0, 0.0])
        R = self.rb
        return (np.array([R * math.sin(c), -R * (1 - math.cos(c)), math.pi - c - self.thb]),
                np.array([R * math.cos(c), -R * math.sin(c), -1.0]))

    @staticmethod
    def cap(c: float, R: float | None) -> tuple[float, float]:
        """Volume of the sphere cap inside the bridge and its derivative in c."""
        if R is None:
            return 0.0, 0.0
        cc = math.cos(c)
        return (math.pi * R**3 * (1 - cc) ** 2 * (2 + cc) / 3.0,
                math.pi * R**3 * math.sin(c) ** 3)

    @staticmethod
    def wetted(c: float, R: float | None) -> tuple[float, float]:
        """Wetted solid area and its derivative in c."""
        if R is None:
            return math.pi * c * c, 2 * math.pi * c
        return 2 * math.pi * R * R * (1 - math.cos(c)), 2 * math.pi * R * R * math.sin(c)

    def valid_c(self, c: float, R: float | None) -> bool:
        return c > 0 and (R is None or c < math.pi)


# ---------------------------------------------------------------------------------------
# Discretisation (scikit-fem provides the mesh, the P2 element and the quadrature)
# ---------------------------------------------------------------------------------------


class _Disc:
    """P2 fields on ``MeshLine`` over t in [0, 1], two Gauss points per element."""

    def __init__(self, n_el: int):
        if n_el < 2:
            raise InputError(f"meniscus: n_elements = {n_el}; allowed: >= 2")
        mesh = MeshLine(np.linspace(0.0, 1.0, n_el + 1))
        basis = Basis(mesh, ElementLineP2(), intorder=3)  # 2-point Gauss, exact to degree 3
        self.n_el = n_el
        self.n = basis.N
        dofs = basis.element_dofs  # (3, n_el)
        nq = basis.dx.shape[1]
        self.M = n_el * nq
        rows = np.arange(n_el)[:, None] * nq + np.arange(nq)[None, :]
        v0 = np.stack([np.asarray(basis.basis[i][0]) for i in range(3)])
        v1 = np.stack([basis.basis[i][0].grad[0] for i in range(3)])
        R = np.broadcast_to(rows[None], v0.shape).ravel()
        C = np.broadcast_to(dofs[:, :, None], v0.shape).ravel()
        self.qr, self.qc = R, C
        self.v0, self.v1 = v0.ravel(), v1.ravel()
        self.Q0 = sp.csr_matrix((self.v0, (R, C)), shape=(self.M, self.n))
        self.Q1 = sp.csr_matrix((self.v1, (R, C)), shape=(self.M, self.n))
        self.w = basis.dx.ravel()
        self.t = basis.doflocs[0]
        self.i0 = int(np.argmin(np.abs(self.t)))
        self.i1 = int(np.argmin(np.abs(self.t - 1.0)))
        self.vertices = np.arange(n_el + 1)  # scikit-fem numbers the vertex dofs first
        if not np.allclose(self.t[self.vertices], mesh.p[0]):
            raise SolverError("meniscus: unexpected scikit-fem dof numbering")
        self.sorted = np.argsort(self.t)
        # unknown layout: r, z, psi (n each), then L, dp, c1, c2, S
        n = self.n
        self.iL, self.iP, self.ic1, self.ic2, self.iS = (3 * n + k for k in range(5))
        self.m = 3 * n + 5


@lru_cache(maxsize=16)
def _disc(n_el: int) -> _Disc:
    return _Disc(n_el)


# closing equations: ("volume", V) | ("fix", index, value) | ("linear", a, b)
Closing = tuple[Any, ...]


def _fields(d: _Disc, x: np.ndarray) -> tuple[np.ndarray, ...]:
    n = d.n
    return x[:n], x[n:2 * n], x[2 * n:3 * n]


def _volume(d: _Disc, g: _Geo, x: np.ndarray, grad: bool = False):
    r, _, psi = _fields(d, x)
    L, c1, c2 = x[d.iL], x[d.ic1], x[d.ic2]
    rq, pq = d.Q0 @ r, d.Q0 @ psi
    sq, cq = np.sin(pq), np.cos(pq)
    vrev = math.pi * np.sum(d.w * rq * rq * sq) * L
    cap1, dcap1 = g.cap(c1, g.rt)
    cap2, dcap2 = g.cap(c2, g.rb)
    V = vrev - cap1 - cap2
    if not grad:
        return V
    gr = d.Q0.T @ (2 * math.pi * d.w * rq * sq * L)
    gp = d.Q0.T @ (math.pi * d.w * rq * rq * cq * L)
    a = np.zeros(d.m)
    a[:d.n] = gr
    a[2 * d.n:3 * d.n] = gp
    a[d.iL] = vrev / L
    a[d.ic1] = -dcap1
    a[d.ic2] = -dcap2
    return V, a


def _system(d: _Disc, g: _Geo, x: np.ndarray, closing: tuple[Closing, Closing],
            jac: bool = True):
    """Residual (and sparse Jacobian) of the collocation system plus BCs and closings."""
    n, M = d.n, d.M
    r, z, psi = _fields(d, x)
    L, P, c1, c2, S = x[d.iL], x[d.iP], x[d.ic1], x[d.ic2], x[d.iS]
    rq, zq, pq = d.Q0 @ r, d.Q0 @ z, d.Q0 @ psi
    sq, cq = np.sin(pq), np.cos(pq)
    curv = P - g.bo * zq - sq / rq
    F = np.empty(d.m)
    F[:M] = d.Q1 @ r - L * cq
    F[M:2 * M] = d.Q1 @ z - L * sq
    F[2 * M:3 * M] = d.Q1 @ psi - L * curv
    top, dtop = g.top(c1, S)
    bot, dbot = g.bottom(c2)
    k = 3 * M
    F[k:k + 3] = np.array([r[d.i0], z[d.i0], psi[d.i0]]) - bot
    F[k + 3:k + 6] = np.array([r[d.i1], z[d.i1], psi[d.i1]]) - top
    rows_c = []
    for j, cl in enumerate(closing):
        kk = k + 6 + j
        if cl[0] == "volume":
            if jac:
                V, a = _volume(d, g, x, grad=True)
                rows_c.append((kk, a))
            else:
                V = _volume(d, g, x)
            F[kk] = V - cl[1]
        elif cl[0] == "fix":
            F[kk] = x[cl[1]] - cl[2]
            if jac:
                a = np.zeros(d.m)
                a[cl[1]] = 1.0
                rows_c.append((kk, a))
        else:
            F[kk] = cl[1] @ x - cl[2]
            if jac:
                rows_c.append((kk, cl[1]))
    if not jac:
        return F
    qr, qc, v0, v1 = d.qr, d.qc, d.v0, d.v1
    # per-entry coefficients evaluated at the row's Gauss point
    sr, cr, rr = sq[qr], cq[qr], rq[qr]
    R_, C_, D_ = [], [], []

    def add(rows, cols, vals):
        R_.append(rows)
        C_.append(cols)
        D_.append(vals)

    iq = np.arange(M)
    # F1 = Q1 r - L cos psi
    add(qr, qc, v1)
    add(qr, 2 * n + qc, L * sr * v0)
    add(iq, np.full(M, d.iL), -cq)
    # F2 = Q1 z - L sin psi
    add(M + qr, n + qc, v1)
    add(M + qr, 2 * n + qc, -L * cr * v0)
    add(M + iq, np.full(M, d.iL), -sq)
    # F3 = Q1 psi - L (P - Bo z - sin psi / r)
    add(2 * M + qr, 2 * n + qc, v1 + L * cr / rr * v0)
    add(2 * M + qr, qc, -L * sr / rr**2 * v0)
    if g.bo != 0.0:
        add(2 * M + qr, n + qc, L * g.bo * v0)
    add(2 * M + iq, np.full(M, d.iL), -curv)
    add(2 * M + iq, np.full(M, d.iP), np.full(M, -L))
    # boundary conditions
    b_rows = k + np.arange(6)
    add(b_rows, np.array([d.i0, n + d.i0, 2 * n + d.i0, d.i1, n + d.i1, 2 * n + d.i1]),
        np.ones(6))
    add(k + np.arange(3), np.full(3, d.ic2), -dbot)
    add(k + 3 + np.arange(3), np.full(3, d.ic1), -dtop)
    add(np.array([k + 4]), np.array([d.iS]), np.array([-1.0]))
    for kk, a in rows_c:
        nz = np.flatnonzero(a)
        add(np.full(nz.size, kk), nz, a[nz])
    J = sp.csc_matrix((np.concatenate(D_), (np.concatenate(R_), np.concatenate(C_))),
                      shape=(d.m, d.m))
    return F, J


def _admissible(d: _Disc, g: _Geo, x: np.ndarray) -> bool:
    r = x[:d.n]
    if not np.all(np.isfinite(x)) or np.min(r) <= 0 or x[d.iL] <= 0:
        return False
    if np.min(d.Q0 @ r) <= 0:
        return False
    if x[d.iS] < -1e-12 and g.rt is not None:
        return False
    return g.valid_c(x[d.ic1], g.rt) and g.valid_c(x[d.ic2], g.rb)


def _scales(d: _Disc, x: np.ndarray) -> np.ndarray:
    """Typical magnitude of each unknown (for step norms and continuation weights)."""
    n = d.n
    rs = float(np.max(np.abs(x[:n]))) + 1e-300
    sc = np.empty(d.m)
    sc[:2 * n] = rs
    sc[2 * n:3 * n] = 1.0
    sc[d.iL] = abs(x[d.iL]) + 1e-300
    sc[d.iP] = abs(x[d.iP]) + 1.0 / rs
    sc[d.ic1] = abs(x[d.ic1]) + 1e-300
    sc[d.ic2] = abs(x[d.ic2]) + 1e-300
    sc[d.iS] = rs
    return sc


@dataclass
class _Newton:
    x: np.ndarray
    converged: bool
    iterations: int
    residual: float
    lu: Any = None


def _newton(d: _Disc, g: _Geo, x: np.ndarray, closing: tuple[Closing, Closing],
            maxit: int = 40, xtol: float = 1e-10) -> _Newton:
    """Newton's method with backtracking on ||F||_2 (Armijo), keeping x admissible.

    Converged when a full step is smaller than ``xtol`` relative to each unknown's scale
    (quadratic convergence then puts the iterate at round-off level).
    """
    x = x.copy()
    res = np.inf
    sc = _scales(d, x)
    for it in range(1, maxit + 1):
        F, J = _system(d, g, x, closing)
        res = float(np.linalg.norm(F))
        if not np.isfinite(res):
            return _Newton(x, False, it, res)
        try:
            lu = splu(J)
            dx = lu.solve(-F)
        except RuntimeError:
            return _Newton(x, False, it, res)
        if not np.all(np.isfinite(dx)):
            return _Newton(x, False, it, res)
        step = float(np.max(np.abs(dx) / sc))
        lam = 1.0
        while True:
            xn = x + lam * dx
            if _admissible(d, g, xn):
                Fn = _system(d, g, xn, closing, jac=False)
                rn = float(np.linalg.norm(Fn))
                if rn <= (1 - 1e-4 * lam) * res or step * lam < 1e-7:
                    break
            lam *= 0.5
            if lam < 1e-6:
                return _Newton(x, False, it, res)
        x = xn
        if lam == 1.0 and step < xtol:
            return _Newton(x, True, it, rn, lu)
    return _Newton(x, False, maxit, res)


def _parity(p: np.ndarray) -> int:
    """Sign of a permutation given as an index array."""
    p = np.asarray(p)
    seen = np.zeros(p.size, dtype=bool)
    sign = 1
    for i in range(p.size):
        if not seen[i]:
            j, length = i, 0
            while not seen[j]:
                seen[j] = True
                j = p[j]
                length += 1
            if length % 2 == 0:
                sign = -sign
    return sign


def _det_sign(d: _Disc, g: _Geo, x: np.ndarray) -> int:
    """Sign of det J of the volume- and gap-controlled system at x."""
    V = _volume(d, g, x)
    _, J = _system(d, g, x, (("volume", V), ("fix", d.iS, x[d.iS])))
    lu = splu(J)
    return int(np.prod(np.sign(lu.U.diagonal()))) * _parity(lu.perm_r) * _parity(lu.perm_c)


@lru_cache(maxsize=32)
def _stable_reference(n_el: int, top_sphere: bool, bottom_sphere: bool) -> int:
    """det-J sign on a bridge known to be stable (small volume, at contact, wetting).

    Stable bridges form a connected set on which J is regular, so the sign is the same for
    all of them (for one discretisation and one pair of solid types).
    """
    d = _disc(n_el)
    g = _Geo(1.0 if top_sphere else None, 1.0 if bottom_sphere else None, 0.0, 0.0, 0.0)
    S = 0.0 if top_sphere else 0.5
    nw = _solve_at(d, g, S, 1e-2, None)
    if not nw.converged:
        raise SolverError("meniscus: reference bridge for the stability sign did not converge")
    return _det_sign(d, g, nw.x)


def _stability(d: _Disc, g: _Geo, x: np.ndarray) -> float:
    """+1 stable, -1 unstable (Maddocks: parity of negative eigenvalues of the second
    variation at fixed volume changes exactly where det J changes sign)."""
    ref = _stable_reference(d.n_el, g.rt is not None, g.rb is not None)
    return float(_det_sign(d, g, x) * ref)


# ---------------------------------------------------------------------------------------
# Initial guess: a circular meridian (toroidal approximation)
# ---------------------------------------------------------------------------------------

_GL_X, _GL_W = np.polynomial.legendre.leggauss(24)
_GL_X = 0.5 * (_GL_X + 1.0)
_GL_W = 0.5 * _GL_W


def _sinc(x: np.ndarray) -> np.ndarray:
    return np.sinc(np.asarray(x) / math.pi)


def _arc(p0: np.ndarray, p1: np.ndarray, t: np.ndarray):
    """Circular arc from p0=(r, z, psi0) to the point of p1 with mean-angle chord."""
    dpsi = p1[2] - p0[2]
    chord = math.hypot(p1[0] - p0[0], p1[1] - p0[1])
    L = chord / float(_sinc(0.5 * dpsi))
    mean = p0[2] + 0.5 * dpsi * t
    fac = L * t * _sinc(0.5 * dpsi * t)
    return p0[0] + fac * np.cos(mean), p0[1] + fac * np.sin(mean), p0[2] + dpsi * t, L


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _bottom_for(g: _Geo, p1: np.ndarray) -> float | None:
    """Lower contact parameter whose chord to p1 points along the mean tangent angle."""

    def gfun(c: float) -> float:
        b, _ = g.bottom(c)
        return _wrap(math.atan2(p1[1] - b[1], p1[0] - b[0]) - 0.5 * (b[2] + p1[2]))

    if g.rb is None:
        m = 0.5 * (math.pi - g.thb + p1[2])
        sm = math.sin(m)
        if abs(sm) < 1e-12:
            return None
        c = p1[0] - (p1[1]) * math.cos(m) / sm
        return c if c > 0 else None
    grid = np.linspace(1e-4, 0.95 * math.pi, 60)
    vals = np.array([gfun(c) for c in grid])
    for i in range(grid.size - 1):
        if vals[i] == 0:
            return float(grid[i])
        if vals[i] * vals[i + 1] < 0 and abs(vals[i] - vals[i + 1]) < math.pi:
            return brentq(gfun, grid[i], grid[i + 1], xtol=1e-12)
    return None


def _arc_state(g: _Geo, c1: float, S: float):
    p1, _ = g.top(c1, S)
    c2 = _bottom_for(g, p1)
    if c2 is None or not g.valid_c(c2, g.rb):
        return None
    p0, _ = g.bottom(c2)
    r, z, psi, L = _arc(p0, p1, _GL_X)
    if np.min(r) <= 0 or L <= 0:
        return None
    V = math.pi * L * np.sum(_GL_W * r * r * np.sin(psi)) - g.cap(c1, g.rt)[0] - g.cap(c2, g.rb)[0]
    return c2, p0, p1, V


def _c1_range(g: _Geo) -> np.ndarray:
    if g.rt is None:
        return np.geomspace(0.02, 50.0, 80)
    hi = min(0.5 * math.pi + 0.3, math.pi - 1e-3)
    return np.geomspace(2e-3, hi, 80)


def _guess(d: _Disc, g: _Geo, S: float, V: float | None = None,
           P: float | None = None) -> np.ndarray | None:
    """Toroidal (circular-arc) guess with volume V (or pressure P), the largest c1 root."""
    grid = _c1_range(g)
    vals = []
    for c1 in grid:
        st = _arc_state(g, float(c1), S)
        if st is None:
            vals.append(np.nan)
            continue
        if V is not None:
            vals.append(st[3] - V)
        else:
            r, z, psi, L = _arc(st[1], st[2], np.array([0.5]))
            vals.append(((st[2][2] - st[1][2]) / L + math.sin(psi[0]) / r[0]) - P)
    vals = np.array(vals)
    c1 = None
    for i in range(grid.size - 2, -1, -1):
        a, b = vals[i], vals[i + 1]
        if np.isfinite(a) and np.isfinite(b) and a * b <= 0:
            if V is not None:
                f = lambda c: _arc_state(g, c, S)[3] - V  # noqa: E731
                try:
                    c1 = brentq(f, grid[i], grid[i + 1], xtol=1e-10)
                except (ValueError, TypeError):
                    c1 = 0.5 * (grid[i] + grid[i + 1])
            else:
                c1 = float(grid[i] - a * (grid[i + 1] - grid[i]) / (b - a))
            break
    if c1 is None:
        return None
    st = _arc_state(g, c1, S)
    if st is None:
        return None
    c2, p0, p1, _ = st
    r, z, psi, L = _arc(p0, p1, d.t)
    rm, zm, pm, _ = _arc(p0, p1, np.array([0.5]))
    x = np.zeros(d.m)
    x[:d.n], x[d.n:2 * d.n], x[2 * d.n:3 * d.n] = r, z, psi
    x[d.iL] = L
    x[d.iP] = (p1[2] - p0[2]) / L + math.sin(pm[0]) / rm[0] if P is None else P
    x[d.ic1], x[d.ic2], x[d.iS] = c1, c2, S
    return x


# ---------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BridgeSolution:
    """One static bridge (SI units, radians). ``exists = False`` means "no bridge".

    Attributes
    ----------
    exists
        True for a bridge; False beyond rupture or when none exists (forces 0, other
        quantities 0, ``message`` says why).
    gap, volume, laplace_pressure
        S (m), V (m^3), dp = p_liquid - p_gas (Pa; at z = 0 with gravity).
    force
        Axial force on sphere 1 (N), positive pushing the solids apart (attraction < 0).
    force_contact1, force_contact2, force_neck
        Attractive force (N, > 0 for attraction) evaluated at the contact line on sphere 1,
        at the lower contact line, and at the neck.
    force_spread
        (max - min)/|mean| of the three evaluations.
    neck_radius, filling_angle1, filling_angle2, wetted_radius
        y0 (m); half-filling angles on sphere 1 and 2 (rad, 0 if not a sphere); the
        wetted radius on a wall (m, 0 if not a wall).
    area, energy
        Liquid-gas area (m^2) and free energy E = sigma (A - cos th1 A1 - cos th2 A2) (J).
    stability
        +1 stable (branch from S = 0 before the fold), -1 unstable, 0 unknown.
    """

    exists: bool
    gap: float
    volume: float
    laplace_pressure: float = 0.0
    force: float = 0.0
    force_contact1: float = 0.0
    force_contact2: float = 0.0
    force_neck: float = 0.0
    force_spread: float = 0.0
    neck_radius: float = 0.0
    filling_angle1: float = 0.0
    filling_angle2: float = 0.0
    wetted_radius: float = 0.0
    area: float = 0.0
    energy: float = 0.0
    stability: float = 0.0
    iterations: int = 0
    message: str = ""
    state: Any = field(default=None, repr=False, compare=False)

    @property
    def suction(self) -> float:
        """u = -dp (Pa)."""
        return -self.laplace_pressure


@dataclass(frozen=True)
class _State:
    """Dimensionless converged solution with what is needed to post-process it."""

    x: np.ndarray
    n_el: int
    geo: _Geo
    ell: float
    sigma: float
    bridge: Bridge


def _quintic_min(y0, d0, dd0, y1, d1, dd1, h):
    """Minimiser (u in [0,1]) of the quintic Hermite interpolant on one element."""
    # coefficients in u of the quintic matching values, h-scaled first and second derivatives
    a0, a1, a2 = y0, d0 * h, 0.5 * dd0 * h * h
    A = np.array([[1, 1, 1], [3, 4, 5], [6, 12, 20]], dtype=float)
    rhs = np.array([y1 - a0 - a1 - a2, d1 * h - a1 - 2 * a2, dd1 * h * h - 2 * a2])
    a3, a4, a5 = np.linalg.solve(A, rhs)
    coef = np.array([a0, a1, a2, a3, a4, a5])
    der = np.polynomial.polynomial.polyder(coef)
    roots = np.polynomial.polynomial.polyroots(der)
    roots = roots[(np.abs(roots.imag) < 1e-9) & (roots.real >= -1e-9) & (roots.real <= 1 + 1e-9)]
    return coef, roots.real


def _neck(d: _Disc, g: _Geo, x: np.ndarray) -> tuple[float, float, bool]:
    """(neck radius, neck height, interior) from a quintic Hermite through vertex values."""
    r, z, psi = _fields(d, x)
    L, P = x[d.iL], x[d.iP]
    v = d.vertices  # vertex dofs ordered by t (scikit-fem numbers them first)
    rv, zv, pv = r[v], z[v], psi[v]
    pt = L * (P - g.bo * zv - np.sin(pv) / rv)
    rt_ = L * np.cos(pv)
    rtt = -L * np.sin(pv) * pt
    zt_ = L * np.sin(pv)
    ztt = L * np.cos(pv) * pt
    h = 1.0 / d.n_el
    best = (float(np.min(rv)), float(zv[np.argmin(rv)]), False)
    sgn = np.cos(pv)
    for i in np.flatnonzero(sgn[:-1] * sgn[1:] <= 0):
        coef, roots = _quintic_min(rv[i], rt_[i], rtt[i], rv[i + 1], rt_[i + 1], rtt[i + 1], h)
        for u in roots:
            rn = float(np.polynomial.polynomial.polyval(u, coef))
            if rn < best[0] or not best[2]:
                cz, _ = _quintic_min(zv[i], zt_[i], ztt[i], zv[i + 1], zt_[i + 1], ztt[i + 1], h)
                best = (rn, float(np.polynomial.polynomial.polyval(u, cz)), True)
    return best


def _post(st: _State, stability: float = 0.0, iterations: int = 0) -> BridgeSolution:
    d, g, x = _disc(st.n_el), st.geo, st.x
    ell, sig = st.ell, st.sigma
    L, P, c1, c2, S = x[d.iL], x[d.iP], x[d.ic1], x[d.ic2], x[d.iS]
    top, _ = g.top(c1, S)
    bot, _ = g.bottom(c2)

    def cut(p: np.ndarray) -> float:
        return 2 * math.pi * p[0] * math.sin(p[2]) - math.pi * p[0] ** 2 * (P - g.bo * p[1])

    cap1, cap2 = g.cap(c1, g.rt)[0], g.cap(c2, g.rb)[0]
    V = _volume(d, g, x)
    vrev = V + cap1 + cap2
    f1 = cut(top) - g.bo * cap1
    # with gravity G(top) = G(bottom) + Bo * Vrev: refer every evaluation to sphere 1
    f2 = cut(bot) + g.bo * (vrev - cap1)
    yn, zn, interior = _neck(d, g, x)
    evals = [f1, f2]
    fn = 2 * math.pi * yn - math.pi * yn**2 * (P - g.bo * zn)
    if interior and g.bo == 0.0:
        evals.append(fn)
    spread = (max(evals) - min(evals)) / max(abs(np.mean(evals)), 1e-300)
    r = x[:d.n]
    rq = d.Q0 @ r
    A = 2 * math.pi * L * float(np.sum(d.w * rq))
    A1, A2 = g.wetted(c1, g.rt)[0], g.wetted(c2, g.rb)[0]
    E = A - math.cos(g.tht) * A1 - math.cos(g.thb) * A2
    fs = sig * ell
    return BridgeSolution(
        exists=True, gap=S * ell, volume=V * ell**3, laplace_pressure=P * sig / ell,
        force=-f1 * fs, force_contact1=f1 * fs, force_contact2=f2 * fs,
        force_neck=(fn if interior else f1) * fs, force_spread=float(spread),
        neck_radius=yn * ell,
        filling_angle1=c1 if g.rt is not None else 0.0,
        filling_angle2=c2 if g.rb is not None else 0.0,
        wetted_radius=c2 * ell if g.rb is None else 0.0,
        area=A * ell**2, energy=E * sig * ell**2, stability=stability,
        iterations=iterations, state=st,
    )


def _no_bridge(gap: float, volume: float, why: str) -> BridgeSolution:
    return BridgeSolution(exists=False, gap=gap, volume=volume, message="no bridge: " + why)


# ---------------------------------------------------------------------------------------
# Branch following, rupture
# ---------------------------------------------------------------------------------------


@dataclass
class _Branch:
    """Stable branch of a volume-controlled bridge from S = 0 to the fold."""

    d: _Disc
    g: _Geo
    V: float
    xs: list[np.ndarray]          # continuation points (stable side), increasing S
    x_fold: np.ndarray
    xs_after: list[np.ndarray] = field(default_factory=list)   # points past the fold

    @property
    def S_fold(self) -> float:
        return float(self.x_fold[self.d.iS])


def _tangent(d: _Disc, g: _Geo, x: np.ndarray, V: float, prev: np.ndarray | None,
             wts: np.ndarray) -> np.ndarray:
    """Unit tangent of the branch F(x) = 0 (volume fixed) in the weighted norm."""
    if prev is None:
        _, J = _system(d, g, x, (("volume", V), ("fix", d.iS, x[d.iS])))
    else:
        _, J = _system(d, g, x, (("volume", V), ("linear", wts * prev, 0.0)))
    rhs = np.zeros(d.m)
    rhs[-1] = 1.0
    t = splu(J).solve(rhs)
    t /= math.sqrt(float(np.sum(wts * t * t)))
    if prev is not None and float(np.sum(wts * t * prev)) < 0:
        t = -t
    if prev is None and t[d.iS] < 0:
        t = -t
    return t


def _solve_at(d: _Disc, g: _Geo, S: float, V: float, guess: np.ndarray | None) -> _Newton:
    closing = (("volume", V), ("fix", d.iS, S))
    tried = []
    if guess is not None:
        x0 = guess.copy()
        x0[d.iS] = S
        tried.append(x0)
    tg = _guess(d, g, S, V=V)
    if tg is not None:
        tried.append(tg)
    nw = None
    for x0 in tried:
        nw = _newton(d, g, x0, closing)
        if nw.converged:
            return nw
    return nw if nw is not None else _Newton(np.zeros(d.m), False, 0, np.inf)


def _branch(d: _Disc, g: _Geo, V: float, n_steps: int = 40) -> _Branch:
    """Pseudo-arclength continuation in S from S = 0 through the fold (rupture)."""
    nw = _solve_at(d, g, 0.0, V, None)
    if not nw.converged:
        raise InputError(
            f"meniscus: no liquid bridge found at contact (S = 0) for V/l^3 = {V:.4g} and "
            f"contact angles {math.degrees(g.tht):.4g}, {math.degrees(g.thb):.4g} deg: the "
            "contact angles or the volume admit no bridge")
    x = nw.x
    _check_filling(g, x, d)
    wts = 1.0 / _scales(d, x) ** 2
    wts[:3 * d.n] /= d.n
    tau = _tangent(d, g, x, V, None, wts)
    # step: about n_steps to the fold (Lian's rupture estimate as the scale)
    s_est = (1 + 0.25 * (g.tht + g.thb)) * V ** (1.0 / 3.0)
    ds = s_est / n_steps / max(tau[d.iS], 1e-6)
    xs = [x]
    after: list[np.ndarray] = []
    for _ in range(20 * n_steps):
        xp = x + ds * tau
        closing = (("volume", V), ("linear", wts * tau, float(np.sum(wts * tau * xp))))
        nw = _newton(d, g, xp, closing, maxit=12)
        if not nw.converged or nw.iterations > 7:
            ds *= 0.5
            if ds < 1e-10:
                raise SolverError("meniscus: continuation step collapsed before the fold")
            continue
        xn = nw.x
        tn = _tangent(d, g, xn, V, tau, wts)
        if nw.iterations <= 3:
            ds *= 1.3
        x, tau = xn, tn
        if tau[d.iS] < 0:
            after.append(x)
            break
        xs.append(x)
    else:
        raise SolverError("meniscus: no fold found along the continuation")
    # refine the fold: along the secant between the last stable point and the first point
    # past the fold, x(lam) solves F = 0 with  sec.(x - xa) = lam sec.(xb - xa); the fold is
    # the root of dS/dlam (implicit differentiation), found to round-off by brentq.
    xa, xb = xs[-1], after[0]
    sec = wts * (xb - xa)
    base, span = float(sec @ xa), float(sec @ (xb - xa))
    known = [xa, xb]
    cache: dict[str, Any] = {}
    rhs = np.zeros(d.m)
    rhs[-1] = span

    def dS(lam: float) -> float:
        guess = min(known, key=lambda y: abs(float(sec @ y) - base - lam * span))
        w = _newton(d, g, guess, (("volume", V), ("linear", sec, base + lam * span)))
        if not w.converged:
            raise SolverError(f"meniscus: no converged bridge near rupture (lam = {lam:.3g})")
        known.append(w.x)
        cache["w"] = w
        return float(w.lu.solve(rhs)[d.iS])

    if dS(0.0) * dS(1.0) > 0:
        raise SolverError("meniscus: fold not bracketed by the continuation")
    lam = brentq(dS, 0.0, 1.0, xtol=1e-14, rtol=1e-14)
    dS(lam)
    nw = cache["w"]
    return _Branch(d, g, V, xs, nw.x, after)


def _check_filling(g: _Geo, x: np.ndarray, d: _Disc) -> None:
    for name, c, R in (("sphere 1", x[d.ic1], g.rt), ("sphere 2", x[d.ic2], g.rb)):
        if R is not None and c > PHI_MAX:
            raise InputError(
                f"meniscus: bridge volume too large for the geometry: the half-filling angle "
                f"on {name} would be {math.degrees(c):.1f} deg at contact (allowed <= "
                f"{math.degrees(PHI_MAX):.0f} deg); reduce the volume")


def _on_branch(br: _Branch, S: float) -> _Newton:
    """Stable-branch solution at gap S <= S_fold (dimensionless).

    Newton at fixed S from the nearest continuation point; if it fails or lands on the
    unstable side, the secant between the two continuation points that bracket S is
    searched (S is monotone there) with a bracketing root find.
    """
    d, g, V = br.d, br.g, br.V
    if S >= br.S_fold:
        return _Newton(br.x_fold.copy(), True, 0, 0.0)
    pts = [*br.xs, br.x_fold]
    Ss = np.array([x[d.iS] for x in pts])
    k = int(np.clip(np.searchsorted(Ss, S) - 1, 0, len(pts) - 2))
    cand = pts[k] if S - Ss[k] <= Ss[k + 1] - S else pts[k + 1]
    nw = _newton(d, g, np.where(np.arange(d.m) == d.iS, S, cand),
                 (("volume", V), ("fix", d.iS, S)))
    if nw.converged and _stability(d, g, nw.x) > 0:
        return nw
    xa, xb = pts[k], pts[k + 1]
    wts = 1.0 / _scales(d, xa) ** 2
    wts[:3 * d.n] /= d.n
    sec = wts * (xb - xa)
    known = [xa, xb]
    cache: dict[str, Any] = {}

    def fun(lam: float) -> float:
        target = float(sec @ (xa + lam * (xb - xa)))
        guess = xa + lam * (xb - xa)
        w = _newton(d, g, guess, (("volume", V), ("linear", sec, target)))
        if not w.converged:
            raise SolverError(f"meniscus: branch solve failed at S = {S:.6g} (x l)")
        known.append(w.x)
        cache["w"] = w
        return float(w.x[d.iS]) - S

    lam = brentq(fun, 0.0, 1.0, xtol=1e-15, rtol=1e-15)
    fun(lam)
    w = cache["w"]
    return _newton(d, g, w.x, (("volume", V), ("fix", d.iS, S)))


# ---------------------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------------------


def _prep(bridge: Bridge, volume: float | None, n_elements: int):
    if volume is not None and not (math.isfinite(volume) and volume > 0):
        raise InputError(f"meniscus: volume = {volume!r}; allowed: > 0 m^3")
    ell = bridge.length_scale(volume)
    return _disc(int(n_elements)), bridge._geo(ell), ell


def _check_gap(gap: float) -> None:
    if not (math.isfinite(gap) and gap >= 0):
        raise InputError(f"meniscus: gap = {gap!r}; allowed: >= 0 m")


@dataclass(frozen=True)
class SeparationCurve:
    """Volume-controlled force-separation curve from S = 0 to rupture.

    Attributes
    ----------
    solutions
        Stable-branch bridges at increasing gap, the last one at the rupture distance.
    rupture_distance
        S_c (m), the turning point of the branch.
    unstable
        Bridges just past the fold (unstable branch, stability = -1).
    """

    solutions: tuple[BridgeSolution, ...]
    rupture_distance: float
    unstable: tuple[BridgeSolution, ...] = ()

    @property
    def gap(self) -> np.ndarray:
        return np.array([s.gap for s in self.solutions])

    @property
    def force(self) -> np.ndarray:
        return np.array([s.force for s in self.solutions])


def _branch_for(bridge: Bridge, volume: float, n_elements: int, n_steps: int = 40):
    d, g, ell = _prep(bridge, volume, n_elements)
    V = volume / ell**3
    return _branch(d, g, V, n_steps=n_steps), ell


def rupture_distance(bridge: Bridge, volume: float,
                     n_elements: int = DEFAULT_ELEMENTS) -> float:
    """Rupture distance S_c (m): the turning point of the volume-controlled branch.

    Raises :class:`InputError` when no bridge exists even at contact.
    """
    br, ell = _branch_for(bridge, volume, n_elements)
    return br.S_fold * ell


def solve_volume(bridge: Bridge, gap: float, volume: float,
                 n_elements: int = DEFAULT_ELEMENTS, branch: Any = None) -> BridgeSolution:
    """Volume-controlled bridge at surface gap ``gap`` (m) with volume ``volume`` (m^3).

    The stable bridge is returned; beyond the rupture distance the result has
    ``exists = False`` and a message (no exception). A toroidal guess is tried first;
    when it fails or lands off the stable branch, the branch is followed from contact.
    """
    _check_gap(gap)
    d, g, ell = _prep(bridge, volume, n_elements)
    V, S = volume / ell**3, gap / ell
    st = lambda x: _State(x, d.n_el, g, ell, bridge.surface_tension, bridge)  # noqa: E731
    if branch is None and g.rt is not None:
        nw = _solve_at(d, g, S, V, None)
        if nw.converged:
            _check_filling(g, nw.x, d)
            if _stability(d, g, nw.x) > 0:
                return _post(st(nw.x), +1.0, nw.iterations)
    if g.rt is None:
        nw = _solve_at(d, g, S, V, None)
        if not nw.converged:
            raise SolverError("meniscus: plate-plate bridge did not converge")
        return _post(st(nw.x), 0.0, nw.iterations)
    br = branch if branch is not None else _branch(d, g, V)
    if S > br.S_fold * (1 + 1e-12):
        return _no_bridge(gap, volume, f"S = {gap:.6g} m is beyond the rupture distance "
                                       f"{br.S_fold * ell:.6g} m")
    nw = _on_branch(br, S)
    if not nw.converged:
        raise SolverError(f"meniscus: Newton failed at S = {gap:.6g} m")
    return _post(st(nw.x), +1.0, nw.iterations)


def solve_suction(bridge: Bridge, gap: float, laplace_pressure: float,
                  n_elements: int = DEFAULT_ELEMENTS,
                  volume_guess: float | None = None) -> BridgeSolution:
    """Suction-controlled bridge: given dp = p_liquid - p_gas (Pa) at gap ``gap`` (m).

    The volume follows from the solution. Yade's tables are of this kind (PHYSICS.md
    section 4, ``P* = u R2 / sigma`` with u = -dp). Of the (generally two) solutions the one
    with the larger filling angle is returned. ``volume_guess`` (m^3) helps if known.
    """
    _check_gap(gap)
    if not math.isfinite(laplace_pressure):
        raise InputError(f"meniscus: laplace_pressure = {laplace_pressure!r}; allowed: finite")
    d, g, ell = _prep(bridge, volume_guess, n_elements)
    S = gap / ell
    P = laplace_pressure * ell / bridge.surface_tension
    closing = (("fix", d.iP, P), ("fix", d.iS, S))
    x0 = None
    if volume_guess is not None:
        x0 = _guess(d, g, S, V=volume_guess / ell**3)
    if x0 is None:
        x0 = _guess(d, g, S, P=P)
    if x0 is None:
        return _no_bridge(gap, 0.0, f"no bridge with dp = {laplace_pressure:.6g} Pa at "
                                    f"S = {gap:.6g} m")
    x0[d.iP] = P
    nw = _newton(d, g, x0, closing)
    if not nw.converged:
        return _no_bridge(gap, 0.0, f"no bridge found with dp = {laplace_pressure:.6g} Pa at "
                                    f"S = {gap:.6g} m")
    return _post(_State(nw.x, d.n_el, g, ell, bridge.surface_tension, bridge), 0.0,
                 nw.iterations)


def force_separation_curve(bridge: Bridge, volume: float, n_points: int = 100,
                           n_elements: int = DEFAULT_ELEMENTS) -> SeparationCurve:
    """Force-separation curve at fixed volume: ``n_points`` gaps evenly spaced from 0 to
    rupture (the last one is the turning point), each warm-started from its neighbour."""
    if n_points < 2:
        raise InputError(f"meniscus: n_points = {n_points}; allowed: >= 2")
    br, ell = _branch_for(bridge, volume, n_elements, n_steps=20)
    d, g = br.d, br.g
    Sg = np.linspace(0.0, br.S_fold, n_points)
    out = []
    x = br.xs[0]
    x_prev = None
    for k, S in enumerate(Sg):
        if k == n_points - 1:
            x, it = br.x_fold, 0
        else:
            guess = x.copy()
            if x_prev is not None and x[d.iS] > x_prev[d.iS]:  # secant predictor in S
                guess += (x - x_prev) * (S - x[d.iS]) / (x[d.iS] - x_prev[d.iS])
            guess[d.iS] = S
            x_prev = x
            nw = _newton(d, g, guess, (("volume", br.V), ("fix", d.iS, S)))
            if not nw.converged or (S > 0.7 * br.S_fold and _stability(d, g, nw.x) < 0):
                nw = _on_branch(br, S)
            x, it = nw.x, nw.iterations
        out.append(_post(_State(x, d.n_el, g, ell, bridge.surface_tension, bridge), 1.0, it))
    uns = tuple(_post(_State(x, d.n_el, g, ell, bridge.surface_tension, bridge), -1.0)
                for x in br.xs_after)
    return SeparationCurve(tuple(out), br.S_fold * ell, uns)


def energy_derivative(sol: BridgeSolution) -> float:
    """dE/dS at fixed volume (N) by implicit differentiation of the discrete system.

    For an exact solution ``-dE/dS`` equals ``force`` (attraction < 0).
    """
    st = sol.state
    if st is None:
        raise InputError("meniscus: energy_derivative needs an existing bridge")
    d, g, x = _disc(st.n_el), st.geo, st.x
    V = _volume(d, g, x)
    nw = _newton(d, g, x, (("volume", V), ("fix", d.iS, x[d.iS])))
    rhs = np.zeros(d.m)
    rhs[-1] = 1.0
    dx = nw.lu.solve(rhs)
    # gradient of E = A - cos th1 A1 - cos th2 A2
    L, c1, c2 = x[d.iL], x[d.ic1], x[d.ic2]
    rq = d.Q0 @ x[:d.n]
    gE = np.zeros(d.m)
    gE[:d.n] = d.Q0.T @ (2 * math.pi * L * d.w)
    gE[d.iL] = 2 * math.pi * float(np.sum(d.w * rq))
    gE[d.ic1] = -math.cos(g.tht) * g.wetted(c1, g.rt)[1]
    gE[d.ic2] = -math.cos(g.thb) * g.wetted(c2, g.rb)[1]
    return float(gE @ dx) * st.sigma * st.ell


def meniscus_profile(sol: BridgeSolution, n: int | None = None) -> dict[str, np.ndarray]:
    """The meridian curve of a bridge, for the Stokes solver's bridge domain.

    Returns a dict of arrays (SI): ``s`` arc length from the lower contact line, ``r``,
    ``z`` (z = 0 is the wall or the apex of sphere 2, sphere 1's lowest point is at
    z = gap), ``psi`` tangent angle (rad), plus scalars ``gap``, ``radius``, ``radius2``
    (0 for a wall), ``filling_angle1``, ``filling_angle2``, ``wetted_radius`` as 0-d arrays.
    With ``n`` the curve is resampled at ``n`` points uniform in s (P2 interpolation),
    otherwise the FE nodes are returned.
    """
    st = sol.state
    if not sol.exists or st is None:
        raise InputError(f"meniscus: no profile to export ({sol.message or 'no bridge'})")
    d, x, ell = _disc(st.n_el), st.x, st.ell
    r, z, psi = _fields(d, x)
    L = x[d.iL]
    if n is None:
        o = d.sorted
        t, rr, zz, pp = d.t[o], r[o], z[o], psi[o]
    else:
        t = np.linspace(0.0, 1.0, int(n))
        e = np.minimum((t * d.n_el).astype(int), d.n_el - 1)
        u = t * d.n_el - e
        phi = np.stack([(1 - u) * (1 - 2 * u), u * (2 * u - 1), 4 * u * (1 - u)])
        idx = np.stack([e, e + 1, d.n_el + 1 + e])  # vertices, then midpoints (scikit-fem)
        rr, zz, pp = (np.sum(phi * f[idx], axis=0) for f in (r, z, psi))
    b = st.bridge
    return {
        "s": t * L * ell, "r": rr * ell, "z": zz * ell, "psi": pp,
        "gap": np.asarray(sol.gap), "radius": np.asarray(b.radius or 0.0),
        "radius2": np.asarray(b.radius2 or 0.0),
        "filling_angle1": np.asarray(sol.filling_angle1),
        "filling_angle2": np.asarray(sol.filling_angle2),
        "wetted_radius": np.asarray(sol.wetted_radius),
    }


# ---------------------------------------------------------------------------------------
# The registered model
# ---------------------------------------------------------------------------------------


@register
class MeniscusModel(Model):
    """Finite-element Young-Laplace bridge (P2, Newton, continuation to rupture)."""

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
    presets: ClassVar[dict[str, dict[str, Any]]] = {
        "fast": {"n_elements": 64},
        "default": {"n_elements": DEFAULT_ELEMENTS},
        "accurate": {"n_elements": 256},
    }
    error_bound: ClassVar[dict[str, float]] = {"fast": 1e-5, "default": 1e-6, "accurate": 1e-6}
    """Relative force error per preset: default and accurate as tested against the shooting
    solution over the validity range (1e-6); fast from the benchmark (1.6e-8 at 32
    elements), stated with margin."""

    def check(self, scene: Scene) -> None:
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
        if scene.kind == "sphere-sphere":
            ratio = scene.radius2 / scene.radius
            if not 0.1 - 1e-12 <= ratio <= 10 + 1e-12:
                raise ValidityError(self.name, f"radius ratio R2/R1 = {ratio:.4g} outside "
                                    "[0.1, 10]")

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

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        n_el = int(opts.get("n_elements", DEFAULT_ELEMENTS))
        bridge = Bridge.from_scene(scene)
        V = float(scene.bridge_volume)
        br, ell = _branch_for(bridge, V, n_el)
        Sc = br.S_fold * ell
        gaps = scene.gap_array
        if np.all(gaps > Sc * (1 + 1e-12)):
            raise InputError(
                f"meniscus: every gap ({gaps.min():.6g} to {gaps.max():.6g} m) is beyond the "
                f"rupture distance {Sc:.6g} m of V = {V:.6g} m^3: no bridge")
        keys = ("laplace_pressure", "neck_radius", "filling_angle", "rupture_distance",
                "bridge_exists", "force_spread", "stability")
        keys += ("wetted_radius",) if scene.kind == "sphere-wall" else ("filling_angle2",)
        ex = {k: np.zeros(gaps.size) for k in keys}
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
            diagnostics={"newton_iterations": iters, "n_elements": n_el,
                         "dofs": _disc(n_el).m, "continuation_points": len(br.xs)},
        )
