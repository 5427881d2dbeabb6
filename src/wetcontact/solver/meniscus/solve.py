"""The public solves: rupture distance, volume- and suction-controlled bridges, and the
force-separation curve (SI units in and out; the solver works in units of R1)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.meniscus.continuation import (
    _branch,
    _check_filling,
    _contact_bridge,
    _on_branch,
    _solve_at,
    _stability,
)
from wetcontact.solver.meniscus.geometry import DEFAULT_ELEMENTS, Bridge
from wetcontact.solver.meniscus.guess import _guess
from wetcontact.solver.meniscus.post import BridgeSolution, _no_bridge, _post, _State
from wetcontact.solver.meniscus.young_laplace import Fixed, VolumeIs, _disc, _newton


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
    end
        How the stable branch ends: ``"fold"`` (turning point) or ``"bifurcation"`` (the
        symmetric bridge between equal spheres loses stability to an asymmetric mode).
    """

    solutions: tuple[BridgeSolution, ...]
    rupture_distance: float
    unstable: tuple[BridgeSolution, ...] = ()
    end: str = "fold"

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


@lru_cache(maxsize=256)
def contact_problem(bridge: Bridge, volume: float,
                    n_elements: int = DEFAULT_ELEMENTS) -> str | None:
    """Why no bridge of ``volume`` (m^3) can be followed from contact, or None.

    The first step of every solve along a branch is the bridge at contact (S = 0); its
    Newton solve and the half-filling-angle limit (``PHI_MAX``, :func:`_contact_bridge`,
    what the branch itself runs) are run here alone
    (about 10 ms, cached), so a model's ``check`` can refuse such a volume before a sweep
    or a refusal hint sends a user to it."""
    d, g, ell = _prep(bridge, volume, n_elements)
    if g.rt is None:  # two plates: no contact state
        return None
    try:
        _contact_bridge(d, g, volume / ell**3)
    except InputError as exc:
        return str(exc).removeprefix("meniscus: ")
    return None


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
    closing = (Fixed(d.iP, P), Fixed(d.iS, S))
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


def _checked_fractions(fractions: Any) -> np.ndarray:
    f = np.asarray(fractions, dtype=float)
    if f.ndim != 1 or f.size < 1 or not f[0] >= 0 or f[-1] != 1.0 or np.any(np.diff(f) <= 0):
        raise InputError("meniscus: fractions of the rupture distance must increase from "
                         ">= 0 to exactly 1")
    return f


def force_separation_curve(bridge: Bridge, volume: float, n_points: int = 100,
                           n_elements: int = DEFAULT_ELEMENTS,
                           fractions: np.ndarray | Callable[[float], np.ndarray] | None = None
                           ) -> SeparationCurve:
    """Force-separation curve at fixed volume: ``n_points`` gaps evenly spaced from 0 to
    rupture (the last one is the turning point), each warm-started from its neighbour.

    ``fractions`` (increasing, in [0, 1], the last one 1) replaces the even spacing: the
    gaps are ``fractions * S_c``, for samplers that need given points of the branch. It may
    be a function of S_c (m) returning them, when the points depend on the rupture distance.
    """
    if fractions is None:
        if n_points < 2:
            raise InputError(f"meniscus: n_points = {n_points}; allowed: >= 2")
        fractions = np.linspace(0.0, 1.0, n_points)
    if not callable(fractions):
        fractions = _checked_fractions(fractions)
    br, ell = _branch_for(bridge, volume, n_elements, n_steps=20)
    if callable(fractions):
        fractions = _checked_fractions(fractions(br.S_fold * ell))
    n_points = fractions.size
    d, g = br.d, br.g
    Sg = fractions * br.S_fold
    # predictor: the continuation points bracketing S, linearly interpolated (S is monotone
    # between them on the stable branch). A secant through the previous requested gaps can
    # overshoot onto another solution of the same volume and gap when they are far apart.
    pts = [*br.xs, br.x_fold]
    Sb = np.array([p[d.iS] for p in pts])
    out = []
    for k, S in enumerate(Sg):
        if k == n_points - 1:
            x, it = br.x_fold, 0
        else:
            j = int(np.clip(np.searchsorted(Sb, S) - 1, 0, len(pts) - 2))
            lam = (S - Sb[j]) / (Sb[j + 1] - Sb[j]) if Sb[j + 1] > Sb[j] else 0.0
            guess = pts[j] + min(max(lam, 0.0), 1.0) * (pts[j + 1] - pts[j])
            guess[d.iS] = S
            nw = _newton(d, g, guess, (VolumeIs(br.V), Fixed(d.iS, S)))
            if not nw.converged or (S > 0.7 * br.S_fold and _stability(d, g, nw.x) < 0):
                nw = _on_branch(br, S)
            x, it = nw.x, nw.iterations
        out.append(_post(_State(x, d.n_el, g, ell, bridge.surface_tension, bridge), 1.0, it))
    uns = tuple(_post(_State(x, d.n_el, g, ell, bridge.surface_tension, bridge), -1.0)
                for x in br.xs_after)
    return SeparationCurve(tuple(out), br.S_fold * ell, uns, br.end)
