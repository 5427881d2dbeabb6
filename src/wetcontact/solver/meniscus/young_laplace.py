r"""The discrete Young-Laplace system: its residual and Jacobian as named functions, the
closing equations, and Newton's method.

The meridian ``(r, z, psi)(t)``, ``t = s/L`` in [0, 1], solves (PHYSICS.md section 2)

.. math::
    r_t = L\cos\psi,\quad z_t = L\sin\psi,\quad
    \psi_t = L\left(\Delta p - Bo\, z - \frac{\sin\psi}{r}\right),

with P2 fields tested by discontinuous P1 functions under the two-point Gauss rule (two-stage
Gauss collocation, nodal order 4: Hairer, Norsett & Wanner, *Solving ODEs I*, sec. II.7),
six contact-line conditions, and two closing equations (volume, gap, pressure or a
continuation's arclength condition) for the unknowns ``(r, z, psi, L, dp, phi1, phi2|r_w, S)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu
from skfem import Basis, ElementLineP2, MeshLine

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.meniscus.geometry import _Geo


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
        # gathers for the Gauss-point values: f_q = sum_i V[i] f[dofs[i]] (no sparse matvec)
        self.gq = C.reshape(3, self.M)
        self.g0 = self.v0.reshape(3, self.M)
        self.g1 = self.v1.reshape(3, self.M)
        self._pattern()

    def at_q(self, f: np.ndarray) -> np.ndarray:
        """Values of a P2 field at the Gauss points (``Q0 @ f``)."""
        return np.sum(self.g0 * f[self.gq], axis=0)

    def dt_q(self, f: np.ndarray) -> np.ndarray:
        """t-derivative of a P2 field at the Gauss points (``Q1 @ f``)."""
        return np.sum(self.g1 * f[self.gq], axis=0)

    def _pattern(self) -> None:
        """Fixed sparsity of the Jacobian (closing rows stored dense) and its CSC order."""
        n, M, m = self.n, self.M, self.m
        qr, qc = self.qr, self.qc
        iq = np.arange(M)
        k = 3 * M
        full = lambda v: np.full(M, v)  # noqa: E731
        rows = [qr, qr, iq, M + qr, M + qr, M + iq, 2 * M + qr, 2 * M + qr, 2 * M + qr,
                2 * M + iq, 2 * M + iq, k + np.arange(6), k + np.arange(3),
                k + 3 + np.arange(3), np.array([k + 4]), np.full(m, k + 6), np.full(m, k + 7)]
        cols = [qc, 2 * n + qc, full(self.iL), n + qc, 2 * n + qc, full(self.iL), 2 * n + qc,
                qc, n + qc, full(self.iL), full(self.iP),
                np.array([self.i0, n + self.i0, 2 * n + self.i0, self.i1, n + self.i1,
                          2 * n + self.i1]),
                np.full(3, self.ic2), np.full(3, self.ic1), np.array([self.iS]),
                np.arange(m), np.arange(m)]
        R, Cc = np.concatenate(rows), np.concatenate(cols)
        key = Cc.astype(np.int64) * m + R
        if np.unique(key).size != key.size:
            raise SolverError("meniscus: duplicate Jacobian entries in the pattern")
        self.perm = np.argsort(key, kind="stable")
        self.indices = R[self.perm].astype(np.int32)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(Cc, minlength=m))]).astype(
            np.int32)


@lru_cache(maxsize=16)
def _disc(n_el: int) -> _Disc:
    return _Disc(n_el)


# ---------------------------------------------------------------------------------------
# Closing equations (two per system)
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class VolumeIs:
    """Closing ``V(x) = volume`` (dimensionless volume)."""

    volume: float

    def value(self, d: _Disc, g: _Geo, x: np.ndarray) -> float:
        return _volume(d, g, x) - self.volume

    def row(self, d: _Disc, g: _Geo, x: np.ndarray) -> np.ndarray:
        return _volume(d, g, x, grad=True)[1]


@dataclass(frozen=True)
class Fixed:
    """Closing ``x[index] = value`` (a gap, a pressure)."""

    index: int
    target: float

    def value(self, d: _Disc, g: _Geo, x: np.ndarray) -> float:
        return float(x[self.index]) - self.target

    def row(self, d: _Disc, g: _Geo, x: np.ndarray) -> np.ndarray:
        a = np.zeros(d.m)
        a[self.index] = 1.0
        return a


@dataclass(frozen=True)
class Linear:
    """Closing ``a . x = b`` (a continuation's arclength or secant condition)."""

    a: np.ndarray
    b: float

    def value(self, d: _Disc, g: _Geo, x: np.ndarray) -> float:
        return float(self.a @ x) - self.b

    def row(self, d: _Disc, g: _Geo, x: np.ndarray) -> np.ndarray:
        return self.a


Closing = VolumeIs | Fixed | Linear


def _fields(d: _Disc, x: np.ndarray) -> tuple[np.ndarray, ...]:
    n = d.n
    return x[:n], x[n:2 * n], x[2 * n:3 * n]


def _volume(d: _Disc, g: _Geo, x: np.ndarray, grad: bool = False):
    r"""Bridge volume ``V = L \int pi r^2 sin(psi) dt - V_cap1 - V_cap2`` (and its gradient)."""
    r, _, psi = _fields(d, x)
    L, c1, c2 = x[d.iL], x[d.ic1], x[d.ic2]
    rq, pq = d.at_q(r), d.at_q(psi)
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



def residual(d: _Disc, g: _Geo, x: np.ndarray, closing: tuple[Closing, Closing]) -> np.ndarray:
    """Residual of the collocation system, the six contact-line conditions and the closings.

    Rows: ``Q1 r - L cos psi``, ``Q1 z - L sin psi``, ``Q1 psi - L (P - Bo z - sin psi / r)``
    at the Gauss points; ``(r, z, psi)(0) = bottom(phi2)``, ``(r, z, psi)(1) = top(phi1, S)``;
    the two closings.
    """
    M = d.M
    r, z, psi = _fields(d, x)
    L, P, c1, c2, S = x[d.iL], x[d.iP], x[d.ic1], x[d.ic2], x[d.iS]
    rq, zq, pq = d.at_q(r), d.at_q(z), d.at_q(psi)
    sq, cq = np.sin(pq), np.cos(pq)
    F = np.empty(d.m)
    F[:M] = d.dt_q(r) - L * cq
    F[M:2 * M] = d.dt_q(z) - L * sq
    F[2 * M:3 * M] = d.dt_q(psi) - L * (P - g.bo * zq - sq / rq)
    k = 3 * M
    F[k:k + 3] = np.array([r[d.i0], z[d.i0], psi[d.i0]]) - g.bottom(c2)[0]
    F[k + 3:k + 6] = np.array([r[d.i1], z[d.i1], psi[d.i1]]) - g.top(c1, S)[0]
    for j, cl in enumerate(closing):
        F[k + 6 + j] = cl.value(d, g, x)
    return F


def jacobian(d: _Disc, g: _Geo, x: np.ndarray,
             closing: tuple[Closing, Closing]) -> sp.csc_matrix:
    """Sparse Jacobian ``dF/dx`` of :func:`residual` (exact), on the fixed pattern of
    :class:`_Disc` (rows of ``Q1 - L d(rhs)/d(field)`` at each Gauss point, the
    contact-line rows, and the closings' gradients)."""
    r, z, psi = _fields(d, x)
    L, P, c1, c2, S = x[d.iL], x[d.iP], x[d.ic1], x[d.ic2], x[d.iS]
    rq, zq, pq = d.at_q(r), d.at_q(z), d.at_q(psi)
    sq, cq = np.sin(pq), np.cos(pq)
    curv = P - g.bo * zq - sq / rq
    qr, v0, v1 = d.qr, d.v0, d.v1
    # per-entry coefficients evaluated at the row's Gauss point
    sr, cr, rr = sq[qr], cq[qr], rq[qr]
    M = d.M
    data = np.concatenate([
        v1, L * sr * v0, -cq,                       # F1 = Q1 r - L cos psi
        v1, -L * cr * v0, -sq,                      # F2 = Q1 z - L sin psi
        v1 + L * cr / rr * v0, -L * sr / rr**2 * v0,  # F3 = Q1 psi - L (P - Bo z - sin psi / r)
        L * g.bo * v0, -curv, np.full(M, -L),
        np.ones(6), -g.bottom(c2)[1], -g.top(c1, S)[1], [-1.0],   # contact lines
        closing[0].row(d, g, x), closing[1].row(d, g, x),
    ])
    J = sp.csc_matrix((data[d.perm], d.indices.copy(), d.indptr.copy()), shape=(d.m, d.m))
    J.eliminate_zeros()  # structural zeros (unused closing entries) would slow SuperLU down
    return J


def _admissible(d: _Disc, g: _Geo, x: np.ndarray) -> bool:
    r = x[:d.n]
    if not np.all(np.isfinite(x)) or np.min(r) <= 0 or x[d.iL] <= 0:
        return False
    if np.min(d.at_q(r)) <= 0:
        return False
    if x[d.iS] < -1e-12 and g.rt is not None and not g.immersed:
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

    @property
    def solved(self) -> bool:
        """Converged, or the residual is at round-off although the step test stalled: next
        to a bifurcation J is nearly singular along its mode, so the steps cannot shrink
        below ``xtol`` there while the bridge equations already hold."""
        return self.converged or self.residual < 1e-9


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
        F, J = residual(d, g, x, closing), jacobian(d, g, x, closing)
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
                Fn = residual(d, g, xn, closing)
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
    """Sign of det J of the volume- and gap-controlled system at x: 0 where the LU
    factorisation finds J exactly singular (x on the stability boundary itself, which the
    stability bisection may land on: it then counts as not stable)."""
    V = _volume(d, g, x)
    J = jacobian(d, g, x, (VolumeIs(V), Fixed(d.iS, float(x[d.iS]))))
    try:
        lu = splu(J)
    except RuntimeError:  # SuperLU: "Factor is exactly singular"
        return 0
    return int(np.prod(np.sign(lu.U.diagonal()))) * _parity(lu.perm_r) * _parity(lu.perm_c)

