"""Contact-line laws of the dynamic bridge: Cox-Voinov's dynamic angle and pinned lines.

Independent references: the geometry of the computed surface (its angle at each line,
from the P2 tangent, against the law at the line's speed measured from its positions over
time); a Young-Laplace shooting solution (``scipy.integrate.solve_ivp``) of the pinned
bridge, the quasi-static limit of a slow pinned stretch; the static law as the limit
``ln(L/b) = 0`` of Cox-Voinov's."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

from wetcontact.errors import SolverError
from wetcontact.models import observed_order
from wetcontact.solver.meniscus import Bridge, solve_volume
from wetcontact.solver.stokes_dynamic import ORDER, Stepping, Wetting, run, static_profile
from wetcontact.solver.stokes_dynamic.domain import (
    contact_angles,
    sphere_angle,
    surface_volume,
)
from wetcontact.solver.stokes_dynamic.step import COX_VOINOV_MAX, cox_voinov

TH = math.radians(20.0)
V, S0 = 1e-3, 0.02
BRIDGE = Bridge(radius=1.0, contact_angle1=TH, contact_angle2=TH, surface_tension=1.0)


class Lines:
    """Observer: the wall line's radius and the sphere line's angle at each state."""

    def __init__(self) -> None:
        self.t: list[float] = []
        self.rw: list[float] = []
        self.phi: list[float] = []

    def __call__(self, t, dom, sol) -> None:
        xs = dom.surface_xy
        self.t.append(t)
        self.rw.append(float(xs[0, 0]))
        self.phi.append(float(sphere_angle(xs[:, -1:], dom.gap)[0]))


def test_static_law_is_cox_voinov_without_its_logarithm():
    """L = b: ln(L/b) = 0, and Cox-Voinov's run is the static run, to the last bit."""
    st = Stepping(dt=0.05, t_end=1.0)
    a = run(V, S0, 1e-2, Wetting(TH, TH, 1e-3, 1e-3), st)
    b = run(V, S0, 1e-2, Wetting(TH, TH, 1e-3, 1e-3, "cox-voinov", 1e-3), st)
    np.testing.assert_array_equal(a.force, b.force)
    np.testing.assert_array_equal(a.neck_radius, b.neck_radius)


def test_static_angles_are_kept_at_sliding_lines():
    r = run(V, S0, 1e-2, Wetting(TH, TH, 1e-3, 1e-3), Stepping(dt=0.05, t_end=4.0))
    tw, ts = contact_angles(r.domain.surface_xy, r.domain.gap)
    assert math.degrees(tw) == pytest.approx(20.0, abs=0.15)  # measured 19.96
    assert math.degrees(ts) == pytest.approx(20.0, abs=0.15)  # measured 19.92


def test_dynamic_angle_follows_the_lines_speed():
    """Stretching at Ca = 1e-3 with L = R, b = 1e-3 R, theta_s = 40 deg: both lines recede
    and their angles fall below the static one; each equals Cox-Voinov's at the line's
    speed over its solid, measured from the line's positions (the last states' difference
    quotient), within 0.2 deg (the weak angle's discretisation: 0.04-0.08 deg for the
    static angle)."""
    obs = Lines()
    th = math.radians(40.0)
    wet = Wetting(th, th, 1e-3, 1e-3, "cox-voinov", 1.0)
    r = run(V, S0, 1e-3, wet, Stepping(dt=0.2, t_end=8.0), observer=obs)
    assert r.stopped == "t_end"
    t, rw, phi = (np.array(v) for v in (obs.t, obs.rw, obs.phi))
    uw = float(np.gradient(rw, t)[-1])  # > 0 advancing: the wetted disc grows
    us = float(np.gradient(phi, t)[-1])  # R = 1: the line's speed over the sphere
    assert uw < 0 and us < 0  # both recede while the bridge is stretched
    tw, ts = contact_angles(r.domain.surface_xy, r.domain.gap)
    assert tw < th - math.radians(2) and ts < th - math.radians(2)
    assert math.degrees(tw) == pytest.approx(math.degrees(cox_voinov(th, uw, 1e-3, 1.0)[0]),
                                             abs=0.2)
    assert math.degrees(ts) == pytest.approx(math.degrees(cox_voinov(th, us, 1e-3, 1.0)[0]),
                                             abs=0.2)


def test_cox_voinov_keeps_the_declared_order():
    """The dynamic angle, Newton-iterated on the lines' speeds each step, keeps BDF2's
    order: theta_s = 40 deg, Ca = 1e-3 to t = 4 at dt = 0.4, 0.2, 0.1, 0.05 (no remeshing):
    the force's differences 6.3e-4, 2.0e-4, 3.1e-5 (observed order 2.2; the neck's last
    difference, 1.4e-8, is at the runs' noise floor, as for static lines)."""
    dts = [0.4, 0.2, 0.1, 0.05]
    th = math.radians(40.0)
    wet = Wetting(th, th, 1e-3, 1e-3, "cox-voinov", 1.0)
    runs = [run(V, S0, 1e-3, wet, Stepping(dt=dt, t_end=4.0, remesh_shape=0.0,
                                            remesh_curvature=0.05, slide_limit=None))
            for dt in dts]
    assert all(r.stopped == "t_end" for r in runs)
    diffs = np.abs(np.diff([r.force[-1] for r in runs]))
    assert observed_order(dts[:-1], diffs) == pytest.approx(ORDER, abs=0.3)


def test_cox_voinov_refuses_outside_its_law():
    with pytest.raises(SolverError, match="a film is left behind"):
        cox_voinov(TH, -1e-3, 1e-3, 1.0)
    with pytest.raises(SolverError, match="outside the law"):
        cox_voinov(TH, 0.5, 1e-3, 1.0)
    th, dc = cox_voinov(TH, 1e-3, 1e-3, 1.0)
    assert TH < th < COX_VOINOV_MAX and dc < 0
    h = 1e-7  # the derivative against a difference quotient
    fd = (math.cos(cox_voinov(TH, 1e-3 + h, 1e-3, 1.0)[0])
          - math.cos(cox_voinov(TH, 1e-3 - h, 1e-3, 1.0)[0])) / (2 * h)
    assert dc == pytest.approx(fd, rel=1e-6)
    with pytest.raises(SolverError, match="line = 'sticky'"):
        Wetting(TH, TH, 1e-3, 1e-3, "sticky")


def _pinned_meniscus(a: float, phi0: float, gap: float, volume: float, guess):
    """Young-Laplace bridge from the wall's line at r = a to the sphere's point at angle
    phi0 (both pinned) holding ``volume``: shooting on (pressure P, wall angle psi0) of
    r' = cos psi, z' = sin psi, psi' = P - sin(psi)/r (arc length; units R = sigma = 1)."""
    c = np.array([0.0, 1.0 + gap])

    def shoot(q):
        P, psi0 = q

        def rhs(_s, y):
            return [math.cos(y[2]), math.sin(y[2]), P - math.sin(y[2]) / y[0]]

        def hit(_s, y):
            return math.hypot(y[0] - c[0], y[1] - c[1]) - 1.0

        hit.terminal, hit.direction = True, -1
        sol = solve_ivp(rhs, (0, 1.0), [a, 0.0, psi0], events=hit, rtol=1e-11, atol=1e-13,
                        dense_output=True)
        s_end = sol.t_events[0][0]
        ss = np.linspace(0.0, s_end, 2001)
        xs = sol.sol(ss)[:2]
        return xs

    def residual(q):
        xs = shoot(q)
        phi = float(sphere_angle(xs[:, -1:], gap)[0])
        return [phi - phi0, (surface_volume(xs, gap) - volume) / volume]

    q = fsolve(residual, guess, xtol=1e-12)
    assert np.max(np.abs(residual(q))) < 1e-9
    return shoot(q), q


def test_shooting_reproduces_the_static_meniscus():
    """The shooting, pinned at the static bridge's own lines, finds that bridge: its
    pressure and angle those of the ``meniscus`` solver within 1e-8 (measured 2e-10)."""
    sol = solve_volume(BRIDGE, 0.022, V)
    prof = static_profile(0.022, V, Wetting(TH, TH, 1e-3, 1e-3)).T
    phi0 = float(sphere_angle(prof[:, -1:], 0.022)[0])
    ref, (p, psi0) = _pinned_meniscus(prof[0, 0], phi0, 0.022, V,
                                      guess=[0.9 * sol.laplace_pressure, math.pi - 1.1 * TH])
    assert p == pytest.approx(sol.laplace_pressure, rel=1e-8)
    assert math.pi - psi0 == pytest.approx(TH, rel=1e-8)
    assert np.min(ref[0]) == pytest.approx(sol.neck_radius, rel=1e-7)


def test_pinned_lines_stay_and_the_slow_stretch_is_the_pinned_meniscus():
    """Pinned lines keep their places on the solids to rounding. Stretched at Ca = 1e-4
    from 0.02 to 0.021 R (the angles close from 20 to about 9.6 deg), the bridge is the
    pinned Young-Laplace bridge of the same volume (shooting) within its O(Ca) lag and the
    discretisation: the neck radius within 2e-3 relative (measured 3.5e-5), the wall angle
    within 0.2 deg (measured 0.13 deg, 9.70 against 9.57: the end tangent's
    discretisation, 0.04-0.08 deg for static angles)."""
    obs = Lines()
    wet = Wetting(TH, TH, 1e-3, 1e-3, "pinned")
    r = run(V, S0, 1e-4, wet, Stepping(dt=0.5, t_end=10.0), observer=obs)
    assert r.stopped == "t_end" and r.gap[-1] == pytest.approx(0.021, abs=1e-12)
    assert np.ptp(obs.rw) < 1e-13 and np.ptp(obs.phi) < 1e-12
    assert np.abs(r.volume / V - 1).max() < 1e-12
    xs = r.domain.surface_xy
    tw, ts = contact_angles(xs, r.domain.gap)
    assert tw < TH and ts < TH
    # continuation in the gap from the static bridge at S0, where pinned = static
    q = [solve_volume(BRIDGE, S0, V).laplace_pressure, math.pi - TH]
    for gap in np.linspace(S0, 0.021, 11)[1:]:
        ref, q = _pinned_meniscus(obs.rw[0], obs.phi[0], float(gap), V, guess=q)
    psi0 = q[1]
    assert np.min(ref[0]) == pytest.approx(r.neck_radius[-1], rel=2e-3)
    assert math.degrees(math.pi - psi0) == pytest.approx(math.degrees(tw), abs=0.2)


def test_pinned_line_stops_when_its_wedge_closes():
    """Stretched further, the pinned angles fall towards zero: the run stops at 2 deg
    (reason ``"line"``) and says that a real line would depin."""
    wet = Wetting(TH, TH, 1e-3, 1e-3, "pinned")
    r = run(V, S0, 1e-4, wet, Stepping(dt=2.5, t_end=100.0))
    assert r.stopped == "line" and "depins" in r.message
    assert min(contact_angles(r.domain.surface_xy, r.domain.gap)) < math.radians(2.5)
