r"""Forces on the sphere and the geometry of one film state.

:math:`F = 2\pi\int_0^{r_w} p\,r\,dr = F_{\rm cap} + F_{\rm visc}`,
:math:`F_{\rm cap} = \pi r_w^2 p(r_w)` (+ the contact-line pull of the wetting meniscus),
:math:`F_{\rm visc}` the rest (PHYSICS.md sections 1-3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wetcontact.errors import SolverError
from wetcontact.solver.thinfilm.problem import FilmProblem


@dataclass(frozen=True)
class Snapshot:
    """Forces and geometry of one film state at surface gap ``gap``."""

    gap: float
    force_viscous: float
    force_capillary: float
    wetted_radius: float
    edge_pressure: float
    max_slope: float
    max_penetration: float
    volume: float


def snapshot(problem: FilmProblem, h: np.ndarray, s: float) -> Snapshot:
    """Wetted radius, edge pressure and the force split of state ``h`` at gap ``s``.

    The wetted zone is the run of cells from the axis in which h >= g; r_w is the zero of
    sqrt(g - h), extrapolated linearly from the first two free cells (the free surface
    touches the sphere tangentially, g - h ~ (r - r_w)^2), kept between the last wetted
    and the first free cell centre. p is piecewise linear between cell
    centres (constant on the first half cell); F = 2 pi int_0^{r_w} p r dr (trapezoid).
    """
    p = problem.pressure(h, s)
    slope = float(np.max(np.abs(np.diff(h) / problem.dc)))
    vol = problem.volume(h)
    if problem.gap_shape == "none":
        return Snapshot(s, 0.0, 0.0, 0.0, 0.0, slope, 0.0, vol)
    if problem.contact == "meniscus":
        return _meniscus_snapshot(problem, h, s, p, slope, vol)
    g = problem.gap(problem.r_c, s)
    pen = h - g
    if pen[0] < 0.0:
        return Snapshot(s, 0.0, 0.0, 0.0, float(p[0]), slope, 0.0, vol)
    outside = np.nonzero(pen < 0.0)[0]
    if outside.size == 0:
        raise SolverError("thinfilm: the liquid fills the gap out to the domain edge; "
                          "raise domain_factor")
    j = int(outside[0])  # first free cell
    r0, r1 = problem.r_c[j - 1], problem.r_c[j]
    if j + 1 < problem.cells and pen[j + 1] < pen[j]:
        # tangential contact: g - h ~ c (r - r_w)^2 on the free side, so sqrt(g - h) is
        # linear in r; extrapolate its zero from the first two free cells
        a, b = math.sqrt(-pen[j]), math.sqrt(-pen[j + 1])
        r_lo = problem.r_c[max(j - 2, 0)]
        r_w = float(np.clip(r1 - a * (problem.r_c[j + 1] - r1) / (b - a), r_lo, r1))
    else:
        r_w = r0 + pen[j - 1] / (pen[j - 1] - pen[j]) * (r1 - r0)
    if r_w < r0 and j >= 2:  # contact point inside the last (barely) wetted cell
        j -= 1
        r0, r1 = problem.r_c[j - 1], problem.r_c[j]
    w = (r_w - r0) / (r1 - r0)
    p_w = p[j - 1] + w * (p[j] - p[j - 1])
    rr = np.concatenate(([0.0], problem.r_c[:j], [r_w]))
    pp = np.concatenate(([p[0]], p[:j], [p_w]))
    f_tot = 2.0 * np.pi * float(np.trapezoid(pp * rr, rr))
    f_cap = np.pi * r_w**2 * float(p_w)
    return Snapshot(s, f_tot - f_cap, f_cap, float(r_w), float(p_w), slope,
                    float(np.max(pen[:j]) / s), vol)


def _meniscus_snapshot(problem: FilmProblem, h: np.ndarray, s: float, p: np.ndarray,
                       slope: float, vol: float) -> Snapshot:
    r"""Force split of a state with the wetting meniscus (``contact = "meniscus"``).

    Wetted area :math:`A_w = \sum_i V_i f_i = \pi r_w^2` (f the wetted fraction),
    :math:`F = \sum_i V_i f_i p_i + F_{\rm line}`, the liquid pressure on the wetted
    sphere plus the surface tension pulling along the contact line,
    :math:`F_{\rm line} = -2\pi\sigma r_w \sin(\theta_s + \psi)`,
    :math:`\psi = \arctan(dg/dr)` the sphere's slope at r_w (PHYSICS.md section 2, the
    contact-line decomposition). Capillary part :math:`\pi r_w^2 p(r_w) + F_{\rm line}`
    with p(r_w) interpolated where f = 1/2; viscous part the rest.
    """
    g = problem.gap(problem.r_c, s)
    f, _ = problem.wetted_fraction(h, g)
    area = float(np.dot(problem.vol, f))
    if area <= 0.0:
        return Snapshot(s, 0.0, 0.0, 0.0, float(p[0]), slope, 0.0, vol)
    r_w = math.sqrt(area / math.pi)
    j = int(np.argmax(f < 0.5)) if np.any(f < 0.5) else problem.cells - 1
    if j == 0:
        p_w = float(p[0])
    else:
        w = (f[j - 1] - 0.5) / (f[j - 1] - f[j])
        p_w = float(p[j - 1] + w * (p[j] - p[j - 1]))
    rr = np.array([r_w])
    dg = float((problem.gap(rr * (1 + 1e-6), s) - problem.gap(rr, s))[0]) / (1e-6 * r_w)
    f_line = (-2.0 * np.pi * problem.surface_tension * r_w
              * math.sin(problem.angle_sphere + math.atan(dg)))
    f_tot = float(np.dot(problem.vol, f * p)) + f_line
    f_cap = math.pi * r_w**2 * p_w + f_line
    pen = float(np.max(h - g)) / s
    return Snapshot(s, f_tot - f_cap, f_cap, r_w, p_w, slope, max(pen, 0.0), vol)

