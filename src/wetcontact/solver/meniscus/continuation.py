r"""Continuation of bridges: volume-controlled in the gap S through the fold (rupture),
suction-controlled in S at fixed Laplace pressure (through its fold), and stability.

Volume control: pseudo-arclength continuation in ``S`` from ``S = 0``; rupture is the first
loss of stability along it. By Maddocks (1987, Arch. Ration. Mech. Anal. 99, 301) the number
of negative eigenvalues of the constrained second variation (axisymmetric perturbations,
fixed volume) changes by one exactly where ``det J`` changes sign; ``stability`` is +1 on the
branch connected to ``S = 0`` until then, -1 after. Two events end the stable branch:

* a **fold** (turning point ``dS = 0``), located to round-off as the root of ``dS/dlambda``
  along the secant through it;
* a **symmetry-breaking bifurcation**: ``det J`` changes sign while S still increases. Between
  equal spheres with equal contact angles (and nearly so) the symmetric bridge loses
  stability to an up-down asymmetric mode before its fold: for V/R^3 = 10^-2.5 at
  theta = 35, 50, 70 deg the fold lies 0.4 %, 6 % and 24 % beyond the bifurcation
  (benchmarks/bench_meniscus_rupture.py). The bridge cannot be held past it, so the
  bifurcation is the rupture distance; it is located by bisection of the det-J sign along
  the secant. Breaking the symmetry slightly (theta1 = theta2 + eps) turns it into a fold
  at ``S_b - c eps^(2/3)`` (an imperfect subcritical pitchfork), which the tests use as the
  independent check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
from scipy.optimize import brentq
from scipy.sparse.linalg import splu

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.meniscus.geometry import PHI_MAX, _Geo
from wetcontact.solver.meniscus.guess import _guess
from wetcontact.solver.meniscus.young_laplace import (
    Fixed,
    Linear,
    VolumeIs,
    _det_sign,
    _Disc,
    _disc,
    _Newton,
    _newton,
    _scales,
    jacobian,
)


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



@dataclass
class _Branch:
    """Stable branch of a volume-controlled bridge from S = 0 to rupture (``x_fold``: the
    fold, or the symmetry-breaking bifurcation when ``end == "bifurcation"``)."""

    d: _Disc
    g: _Geo
    V: float
    xs: list[np.ndarray]          # continuation points (stable side), increasing S
    x_fold: np.ndarray
    xs_after: list[np.ndarray] = field(default_factory=list)   # points past the fold
    end: str = "fold"             # "fold" or "bifurcation": how the stable branch ends

    @property
    def S_fold(self) -> float:
        return float(self.x_fold[self.d.iS])


def _tangent(d: _Disc, g: _Geo, x: np.ndarray, V: float, prev: np.ndarray | None,
             wts: np.ndarray) -> np.ndarray:
    """Unit tangent of the branch F(x) = 0 (volume fixed) in the weighted norm."""
    if prev is None:
        J = jacobian(d, g, x, (VolumeIs(V), Fixed(d.iS, float(x[d.iS]))))
    else:
        J = jacobian(d, g, x, (VolumeIs(V), Linear(wts * prev, 0.0)))
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
    closing = (VolumeIs(V), Fixed(d.iS, S))
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


def _branch(d: _Disc, g: _Geo, V: float, n_steps: int = 40,
            bifurcations: bool = True) -> _Branch:
    """Pseudo-arclength continuation in S from S = 0 to rupture: the first loss of
    stability (fold or bifurcation). ``bifurcations=False`` follows the branch through a
    bifurcation to its fold, the rupture criterion of the literature's symmetric solutions
    (Lian et al. 1993), kept only to measure the difference
    (benchmarks/bench_meniscus_rupture.py)."""
    x = _contact_bridge(d, g, V)
    wts = 1.0 / _scales(d, x) ** 2
    wts[:3 * d.n] /= d.n
    tau = _tangent(d, g, x, V, None, wts)
    # step: about n_steps to the fold (Lian's rupture estimate as the scale)
    s_est = (1 + 0.25 * (g.tht + g.thb)) * V ** (1.0 / 3.0)
    ds = s_est / n_steps / max(tau[d.iS], 1e-6)
    ds_min, ds_fold = 1e-5 * ds, 1e-2 * ds
    crossing: np.ndarray | None = None  # an unstable bridge just past a loss of stability
    near_fold = False                   # the fold was overshot once: no more step growth
    xs = [x]
    after: list[np.ndarray] = []
    for _ in range(20 * n_steps):
        xp = x + ds * tau
        closing = (VolumeIs(V), Linear(wts * tau, float(np.sum(wts * tau * xp))))
        nw = _newton(d, g, xp, closing, maxit=12)
        if not nw.solved or nw.iterations > 7:
            ds *= 0.5
            if crossing is not None and ds < ds_min:
                # Newton stalls next to a bifurcation (J singular along its mode)
                xb = _bisect_stability(d, g, V, x, crossing, wts)
                return _Branch(d, g, V, xs, xb, [crossing], end="bifurcation")
            if ds < 1e-10:
                raise SolverError("meniscus: continuation step collapsed before the fold")
            continue
        xn = nw.x
        tn = _tangent(d, g, xn, V, tau, wts)
        if nw.iterations <= 3 and not near_fold:
            ds *= 1.3
        if bifurcations and tn[d.iS] > 0 and _stability(d, g, xn) < 0:
            # stability lost while S still increases: either a bifurcation, or the step
            # jumped over a small S-loop (two folds) of a nearly symmetric bridge. Shrink
            # the step until it resolves the loop; a sign change that survives a step of
            # ds_min is a bifurcation, located on the (then reliable) secant.
            if ds > ds_min:
                ds *= 0.25
                crossing = xn
                continue
            xb = _bisect_stability(d, g, V, x, xn, wts)
            return _Branch(d, g, V, xs, xb, [xn], end="bifurcation")
        if tn[d.iS] < 0 and ds > ds_fold:
            # past the fold: come back and approach it in small steps, so that the secant
            # refinement below works on a short, nearly straight piece of the branch
            ds, near_fold = max(0.25 * ds, ds_fold), True
            continue
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
        closing = (VolumeIs(V), Linear(sec, base + lam * span))
        w = _newton(d, g, guess, closing)
        if not w.converged:  # the nearest known bridge can be too far: the secant point
            w = _newton(d, g, xa + lam * (xb - xa), closing)
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
    # a step may have crossed a bifurcation and the fold just past it at once: the bridge
    # just before the fold is then already unstable
    dS(lam * (1.0 - 1e-3))
    pre = cache["w"].x
    if bifurcations and _stability(d, g, pre) < 0:
        return _Branch(d, g, V, xs, _bisect_stability(d, g, V, xa, pre, wts), after,
                       end="bifurcation")
    return _Branch(d, g, V, xs, nw.x, after)


def _bisect_stability(d: _Disc, g: _Geo, V: float, xa: np.ndarray, xb: np.ndarray,
                      wts: np.ndarray, tol: float = 1e-10) -> np.ndarray:
    """The last stable bridge between a stable ``xa`` and an unstable ``xb``: bisection of
    the det-J sign along their secant (``sec . x`` fixed, so a fold between them is no
    obstacle), each bridge warm-started from the nearest one solved, to ``tol`` in the
    secant parameter."""
    sec = wts * (xb - xa)
    base, span = float(sec @ xa), float(sec @ (xb - xa))
    lo, hi, x_lo, x_hi = 0.0, 1.0, xa, xb
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        w = _newton(d, g, 0.5 * (x_lo + x_hi), (VolumeIs(V), Linear(sec, base + mid * span)))
        if not w.solved:
            raise SolverError("meniscus: no converged bridge while locating the loss of "
                              f"stability (secant parameter {mid:.6g})")
        if _stability(d, g, w.x) > 0:
            lo, x_lo = mid, w.x
        else:
            hi, x_hi = mid, w.x
    return x_lo


def _contact_bridge(d: _Disc, g: _Geo, V: float) -> np.ndarray:
    """The bridge at contact (S = 0), where every branch starts: an InputError if none
    converges or it fills more than PHI_MAX of a sphere."""
    nw = _solve_at(d, g, 0.0, V, None)
    if not nw.converged:
        raise InputError(
            f"meniscus: no liquid bridge found at contact (S = 0) for V/l^3 = {V:.4g} and "
            f"contact angles {math.degrees(g.tht):.4g}, {math.degrees(g.thb):.4g} deg: the "
            "contact angles or the volume admit no bridge")
    _check_filling(g, nw.x, d)
    return nw.x


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
                 (VolumeIs(V), Fixed(d.iS, S)))
    if nw.converged and _stability(d, g, nw.x) > 0:
        return nw
    xa, xb = pts[k], pts[k + 1]
    wts = 1.0 / _scales(d, xa) ** 2
    wts[:3 * d.n] /= d.n
    sec = wts * (xb - xa)
    cache: dict[str, Any] = {}

    def fun(lam: float) -> float:
        target = float(sec @ (xa + lam * (xb - xa)))
        guess = xa + lam * (xb - xa)
        w = _newton(d, g, guess, (VolumeIs(V), Linear(sec, target)))
        if not w.converged:
            raise SolverError(f"meniscus: branch solve failed at S = {S:.6g} (x l)")
        cache["w"] = w
        return float(w.x[d.iS]) - S

    lam = brentq(fun, 0.0, 1.0, xtol=1e-15, rtol=1e-15)
    fun(lam)
    w = cache["w"]
    return _newton(d, g, w.x, (VolumeIs(V), Fixed(d.iS, S)))


# ---------------------------------------------------------------------------------------
# Suction control: fixed Laplace pressure, the gap marched from contact to the fold
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SuctionBranch:
    """Stable branch of a suction-controlled bridge (dimensionless, fixed pressure ``P``).

    At fixed ``dp`` the bridges form a curve ``S(phi1)`` that rises from contact (or from the
    largest admitted filling angle) to a maximum, the fold ``S_fold``: beyond it no bridge
    exists at this pressure. The stable bridges are those on the large-filling-angle side
    (larger volume: Lian et al. 1993; Duriez & Wan 2017), where ``dS/dphi1 < 0``.

    Attributes
    ----------
    pressure
        P = dp l / sigma.
    points
        Continuation points from the start to the fold, ``phi1`` decreasing and ``S``
        increasing; the last one is the fold (``dS/dphi1 = 0`` to round-off).
    solves
        Newton solves spent (for the benchmark).
    """

    d: _Disc
    g: _Geo
    pressure: float
    points: tuple[np.ndarray, ...]
    solves: int

    @property
    def fold(self) -> np.ndarray:
        return self.points[-1]

    @property
    def S_fold(self) -> float:
        return float(self.fold[self.d.iS])

    @property
    def S_start(self) -> float:
        return float(self.points[0][self.d.iS])


def _at_filling(d: _Disc, g: _Geo, P: float, c1: float, guess: np.ndarray) -> _Newton:
    """Bridge at pressure P with half-filling angle c1 on sphere 1 (the gap is unknown)."""
    x0 = guess.copy()
    x0[d.iP], x0[d.ic1] = P, c1
    return _newton(d, g, x0, (Fixed(d.iP, P), Fixed(d.ic1, c1)), maxit=15)


def _tangent_last(d: _Disc, nw: _Newton) -> np.ndarray:
    """dx/d(target of the last closing) from the Newton's last factorisation."""
    rhs = np.zeros(d.m)
    rhs[-1] = 1.0
    return nw.lu.solve(rhs)


def suction_start(d: _Disc, g: _Geo, P: float, guess: np.ndarray,
                  c1_max: float) -> np.ndarray | None:
    """First stable bridge at pressure P: at contact (S = 0) if its filling angle on sphere 1
    is at most ``c1_max``, otherwise at ``phi1 = c1_max`` (then S > 0). ``guess`` is a
    nearby bridge (the start at a neighbouring pressure); ``None`` if none is found."""
    x0 = guess.copy()
    x0[d.iP], x0[d.iS] = P, 0.0
    nw = _newton(d, g, x0, (Fixed(d.iP, P), Fixed(d.iS, 0.0)), maxit=15)
    if nw.converged and nw.x[d.ic1] <= c1_max and _tangent_last(d, nw)[d.ic1] < 0:
        return nw.x
    nw = _at_filling(d, g, P, c1_max, guess)
    if nw.converged and nw.x[d.iS] >= 0 and _tangent_last(d, nw)[d.iS] < 0:
        return nw.x
    return None


def suction_branch(d: _Disc, g: _Geo, P: float, start: np.ndarray,
                   ratio: float = 0.85) -> SuctionBranch:
    """Continuation in ``phi1`` at fixed pressure from ``start`` to the fold.

    ``phi1`` is a regular parameter through the fold (``S`` is not), so the curve is followed
    with closings ``dp = P``, ``phi1 = c`` and a tangent predictor, ``c`` shrinking by
    ``ratio`` per step; the fold is the root of ``dS/dphi1`` (implicit differentiation of
    the discrete system, from the Newton's last factorisation), bracketed by the first step
    where it turns positive and found by brentq to ``1e-13`` in ``phi1``.
    """
    solves = 1
    nw = _at_filling(d, g, P, float(start[d.ic1]), start)
    if not nw.converged:
        raise SolverError(f"meniscus: suction branch start did not converge (P = {P:.6g})")
    x, t = nw.x, _tangent_last(d, nw)
    if t[d.iS] >= 0:
        return SuctionBranch(d, g, P, (x,), solves)
    pts = [x]
    c, q = float(x[d.ic1]), ratio
    while True:
        cn = c * q
        nw = _newton(d, g, x + (cn - c) * t, (Fixed(d.iP, P), Fixed(d.ic1, cn)), maxit=10)
        solves += 1
        if not nw.converged:
            q = 0.5 * (1.0 + q)
            if 1.0 - q < 1e-9:
                raise SolverError(f"meniscus: suction continuation stalled (P = {P:.6g})")
            continue
        tn = _tangent_last(d, nw)
        if tn[d.iS] >= 0:
            break
        x, t, c = nw.x, tn, cn
        pts.append(x)
    cache: dict[str, Any] = {}
    lo, hi = cn, c

    def slope(cc: float) -> float:
        w = _at_filling(d, g, P, cc, x + (cc - c) * t)
        if not w.converged:
            raise SolverError(f"meniscus: no bridge near the suction fold (P = {P:.6g})")
        cache["x"] = w.x
        cache["n"] = cache.get("n", 0) + 1
        return float(_tangent_last(d, w)[d.iS])

    cf = brentq(slope, lo, hi, xtol=1e-10 * hi, rtol=1e-12)  # S is flat at the fold
    slope(cf)
    pts.append(cache["x"])
    return SuctionBranch(d, g, P, tuple(pts), solves + cache["n"])


def suction_at_gaps(br: SuctionBranch, gaps: np.ndarray) -> list[np.ndarray]:
    """Stable bridges of a suction branch at the given gaps (all in [S_start, S_fold]).

    Newton at fixed (P, S) from the secant between the two branch points that bracket S;
    accepted when its filling angle lies inside that bracket (the stable side), otherwise
    S(phi1) = S is solved by brentq in ``phi1`` over the bracket.
    """
    d, g, P = br.d, br.g, br.pressure
    pts = br.points
    Ss = np.array([p[d.iS] for p in pts])
    out = []
    for S in gaps:
        k = int(np.clip(np.searchsorted(Ss, S) - 1, 0, len(pts) - 2))
        xa, xb = pts[k], pts[k + 1]
        lam = (S - Ss[k]) / (Ss[k + 1] - Ss[k]) if Ss[k + 1] > Ss[k] else 0.0
        guess = xa + lam * (xb - xa)
        guess[d.iS] = S
        nw = _newton(d, g, guess, (Fixed(d.iP, P), Fixed(d.iS, float(S))), maxit=12)
        ca, cb = float(xa[d.ic1]), float(xb[d.ic1])
        if nw.converged and cb - 1e-12 <= nw.x[d.ic1] <= ca + 1e-12:
            out.append(nw.x)
            continue
        cache: dict[str, np.ndarray] = {}

        def miss(cc: float, xa=xa, xb=xb, ca=ca, cb=cb, S=S, cache=cache) -> float:
            w = _at_filling(d, g, P, cc, xa + (cc - ca) / (cb - ca) * (xb - xa))
            if not w.converged:
                raise SolverError(f"meniscus: suction bridge failed at S = {S:.6g} (x l)")
            cache["x"] = w.x
            return float(w.x[d.iS]) - S

        if S >= Ss[-1]:
            out.append(pts[-1].copy())
            continue
        cc = brentq(miss, cb, ca, xtol=1e-14, rtol=1e-15)
        miss(cc)
        out.append(cache["x"])
    return out
