"""The toroidal (circular-arc) initial guess of a bridge: a circular meridian between the
contact lines, its chord along the mean tangent angle, as a state vector of the
discretisation (:mod:`.young_laplace`) on the solids (:mod:`.geometry`)."""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from wetcontact.solver.meniscus.geometry import _Geo
from wetcontact.solver.meniscus.young_laplace import _Disc

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
    return _guess_at(d, g, S, c1, P)


def _guess_at(d: _Disc, g: _Geo, S: float, c1: float,
              P: float | None = None) -> np.ndarray | None:
    """Toroidal guess with half-filling angle ``c1`` on sphere 1 at gap ``S``."""
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
