"""The dynamic (moving free-surface) sphere-wall bridge, ``wetcontact.solver.stokes_dynamic``.

Independent references:

* the static meniscus (``wetcontact.solver.meniscus``, a Young-Laplace solver on its own
  discretisation): the fixed point of the dynamics at v = 0, and the Ca -> 0 limit;
* the quasi-static ``stokes`` model (Stokes flow in the static bridge with the prescribed
  normal motion of the static family): the O(Ca) excess of the force over the static one,
  ``lim (F - F_static)/Ca = F_viscous/(eta R v)`` (the static shape is an equilibrium, so
  its O(Ca) deformation does no work to first order: ``F v = Phi + dE_static/dt``);
* the declared order of the time stepping against runs with halved steps.

Every force is the force at the time it is recorded (``DynamicRun.force[k]`` at
``time[k]``; the first entry is the instantaneous flow of the initial shape).

Units R = sigma = eta = 1 (speed = Ca, time eta R/sigma, force sigma R). The tolerances
are the measured errors (in each docstring) with a margin.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact.errors import SolverError
from wetcontact.models import observed_order
from wetcontact.solver.meniscus import Bridge, solve_volume
from wetcontact.solver.stokes_dynamic import (
    ORDER,
    SPACE_ORDER,
    Domain,
    MeshOptions,
    Stepping,
    Wetting,
    run,
    solve_step,
    static_profile,
)
from wetcontact.solver.stokes_dynamic.domain import correct_volume, redistribute

sys.path.insert(0, str(Path(__file__).resolve().parent))
from quasi_static import assert_at_rest, viscous_per_speed  # noqa: E402

TH = math.radians(20.0)
V = 1e-3  # V/R^3
S0 = 0.02  # S/R at the start
WET = Wetting(TH, TH, 1e-3, 1e-3)  # slip lengths 1e-3 R
BRIDGE = Bridge(radius=1.0, contact_angle1=TH, contact_angle2=TH, surface_tension=1.0)


def _static(gap: float):
    return solve_volume(BRIDGE, gap, V)


def _perturbed(amplitude: float = 0.003) -> np.ndarray:
    """The static meniscus at S0 pushed out along its normal by ``amplitude sin^2(pi f)``
    (f the arc-length fraction): the contact lines and angles are unchanged, the volume
    is off by 4 % (restored by the solver)."""
    prof = static_profile(S0, V, WET)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(prof.T, axis=1)))])
    t = np.gradient(prof, axis=0)
    t /= np.hypot(t[:, 0], t[:, 1])[:, None]
    n = np.column_stack([t[:, 1], -t[:, 0]])
    return prof + amplitude * (np.sin(np.pi * s / s[-1]) ** 2)[:, None] * n


def test_static_meniscus_is_an_equilibrium():
    """One step at v = 0 from the static shape: the force on the sphere is the meniscus
    solver's within 1e-5 (measured 2e-6), the spurious velocity below 1e-4 sigma/eta
    (measured 1.5e-5), and the wall feels the opposite force (Stokes flow, no body force)."""
    dom = Domain.from_profile(S0, static_profile(S0, V, WET), MeshOptions())
    xs, _ = correct_volume(dom.surface_xy, S0, V)
    dom = dom.moved(xs, S0)
    st = _static(S0)
    for dt in (1e-3, 1e-1):
        sol = solve_step(dom, dt, 0.0, WET)
        assert sol.force == pytest.approx(st.force, rel=1e-5)
        assert sol.force_wall == pytest.approx(-sol.force, rel=1e-12)
        assert np.abs(sol.u).max() < 1e-4


def test_perturbed_bridge_relaxes_to_the_meniscus():
    """At v = 0 a perturbed bridge relaxes to the static meniscus of its volume: after
    t = 1.2 eta R/sigma the force is the meniscus solver's within 2e-5 (measured 5e-6 at
    dt = 0.01, 1e-5 at 0.02), the neck radius within 1e-6 (measured 3e-7), every surface
    node within 2e-6 R of the static meridian, and the volume within 1e-12 throughout."""
    r = run(V, S0, 0.0, WET, Stepping(dt=0.02, t_end=1.2), initial=_perturbed())
    st = _static(S0)
    assert r.stopped == "t_end"
    assert r.force[0] == pytest.approx(st.force, rel=0.1)  # perturbed: ~ 8 % off at first
    assert abs(r.force[0] / st.force - 1) > 0.03
    assert r.force[-1] == pytest.approx(st.force, rel=2e-5)
    assert r.neck_radius[-1] == pytest.approx(st.neck_radius, rel=1e-6)
    assert np.abs(r.volume / V - 1).max() < 1e-12
    ref = static_profile(S0, V, WET).T
    fine = redistribute(ref, np.linspace(0.0, 1.0, 20001))
    xs = r.domain.surface_xy
    dist = np.min(np.hypot(xs[0][:, None] - fine[0][None], xs[1][:, None] - fine[1][None]),
                  axis=1)
    assert dist.max() < 2e-6


@pytest.fixture(scope="module")
def stretched():
    """Ca = 1e-3 separation from S/R = 0.02 to 0.03 (t = 10) at two time steps (dS = 2e-4,
    1e-4)."""
    ca = 1e-3
    return ca, [run(V, S0, ca, WET, Stepping(dt=ds / ca, t_end=0.01 / ca)) for ds in (2e-4, 1e-4)]


def test_volume_is_kept_while_stretching(stretched):
    """The volume stays within 1e-12 relative at every step (measured 1e-13: the normal
    correction each step), remeshing included (forced here by a strict quality
    threshold)."""
    _, runs = stretched
    remeshed = run(V, S0, 1e-3, WET, Stepping(dt=0.5, gap_end=0.03, remesh_shape=0.95))
    assert remeshed.remeshes >= 2
    assert remeshed.stopped == "gap_end"
    for r in [*runs, remeshed]:
        assert np.abs(r.volume / V - 1).max() < 1e-12


def test_small_ca_force_excess_is_the_quasi_static_viscous_force(stretched):
    """(F - F_static)/Ca at S/R = 0.03 (the force of the step that ends there: BDF2 gives
    the force at the end of its step), against the quasi-static ``stokes`` bridge's
    viscous force per unit speed (same slip lengths, contact angles and volume): measured
    -25.90 at both steps (they differ by 4e-5 relative; dS = 4e-4 gives -25.97) against
    the quasi-static -25.7 (0.8 %: the O(Ca) shape lag and the two meshes)."""
    ca, runs = stretched
    fst = _static(0.03).force
    excess = []
    for r in runs:
        assert r.stopped == "t_end" and r.gap[-1] == pytest.approx(0.03, abs=1e-12)
        excess.append((r.force[-1] - fst) / ca)
    fv = viscous_per_speed(0.03, V, 20.0)
    assert fv < 0  # separation is resisted
    for e in excess:
        assert e == pytest.approx(fv, rel=0.015)
    assert excess[0] == pytest.approx(excess[1], rel=1e-3)  # the time error is small


def test_time_stepping_has_the_declared_order():
    """Stretching from the static bridge at Ca = 1e-2 to t = 0.8 (no remeshing) with dt =
    0.025, 0.0125, 0.00625: the neck radius' and the force's successive differences fall at
    the declared order (2; measured ratios 3.96 and 3.88, then 4.04 and 4.01 at dt =
    0.003125; the steps start at dt/8 and grow by 1.5, so every run has the same shape of
    step sequence)."""
    dts = [0.025, 0.0125, 0.00625]
    runs = [run(V, S0, 1e-2, WET, Stepping(dt=dt, t_end=0.8, remesh_shape=0.0,
                                           remesh_curvature=0.05)) for dt in dts]
    for r in runs:
        assert r.stopped == "t_end" and r.remeshes == 0
    for values in ([r.neck_radius[-1] for r in runs], [r.force[-1] for r in runs]):
        diffs = np.abs(np.diff(values))
        assert observed_order(dts[:-1], diffs) == pytest.approx(ORDER, abs=0.15)


def test_force_converges_in_space_at_the_declared_order():
    """The force of the flow at Ca = 1e-2 in the static bridge at S0 (``dt = 0``) on four
    meshes, every size halved from one to the next (0.5, 1, 2, 4 times the default's
    resolution): the successive differences fall at the declared order (measured 1.48 and
    1.41; the contact lines' wedge corners limit it), and the default mesh is within 2e-5
    of the finest (measured 1.0e-5; relative 3e-6)."""
    prof = static_profile(S0, V, WET)
    forces = []
    for k in (0.5, 1, 2, 4):
        opts = MeshOptions(h_surface=0.01 / k, contact_size=1e-3 / k, n_gap=int(4 * k),
                           n_neck=int(8 * k))
        dom = Domain.from_profile(S0, prof, opts)
        xs, _ = correct_volume(dom.surface_xy, S0, V)
        forces.append(solve_step(dom.moved(xs, S0), 0.0, 1e-2, WET).force)
    diffs = np.abs(np.diff(forces))
    assert observed_order([2.0, 1.0], diffs[:2]) == pytest.approx(SPACE_ORDER, abs=0.2)
    assert observed_order([1.0, 0.5], diffs[1:]) == pytest.approx(SPACE_ORDER, abs=0.2)
    assert abs(forces[1] - forces[-1]) < 2e-5 * abs(forces[-1])


def test_a_checkpointed_run_resumes(tmp_path):
    """A run stopped at t = 0.4 into a checkpoint and resumed to t = 0.8 (remeshed at the
    resume, its BDF2 history carried over) ends where an uninterrupted run does, within the
    time error of the step (the uninterrupted run at half the step); a finished run resumes
    without a step; a checkpoint of other arguments is refused, naming the file."""
    path = tmp_path / "run.npz"
    straight = run(V, S0, 1e-2, WET, Stepping(dt=0.025, t_end=0.8))
    half = run(V, S0, 1e-2, WET, Stepping(dt=0.0125, t_end=0.8))
    first = run(V, S0, 1e-2, WET, Stepping(dt=0.025, t_end=0.4), checkpoint=path)
    assert first.stopped == "t_end" and path.is_file()
    resumed = run(V, S0, 1e-2, WET, Stepping(dt=0.025, t_end=0.8), checkpoint=path)
    assert resumed.stopped == "t_end" and resumed.time[-1] == pytest.approx(0.8)
    assert resumed.steps > first.steps
    np.testing.assert_array_equal(resumed.time[: first.time.size], first.time)
    time_error = abs(straight.force[-1] - half.force[-1])
    assert abs(resumed.force[-1] - straight.force[-1]) < 2 * time_error
    assert abs(resumed.neck_radius[-1] - straight.neck_radius[-1]) < 2 * abs(
        straight.neck_radius[-1] - half.neck_radius[-1])
    assert np.abs(resumed.volume / V - 1).max() < 1e-12
    again = run(V, S0, 1e-2, WET, Stepping(dt=0.025, t_end=0.8), checkpoint=path)
    assert again.steps == resumed.steps
    np.testing.assert_array_equal(again.force, resumed.force)
    with pytest.raises(SolverError, match="run.npz was written by a run with other"):
        run(V, S0, 2e-2, WET, Stepping(dt=0.025, t_end=0.8), checkpoint=path)


def test_stepping_needs_a_stop():
    with pytest.raises(SolverError, match="t_end or gap_end"):
        Stepping(dt=0.1)
    with pytest.raises(SolverError, match="dt"):
        Stepping(dt=float("nan"), t_end=1.0)


def test_gmsh_that_does_not_finish_is_stopped():
    """gmsh runs in a worker process: past ``MeshOptions.timeout`` the worker is killed and
    the mesh fails with a SolverError (a run stops with reason ``"mesh"``); the next mesh
    starts a new worker."""
    prof = static_profile(S0, V, WET)
    with pytest.raises(SolverError, match="did not finish"):
        Domain.from_profile(S0, prof, MeshOptions(timeout=1e-4))
    dom = Domain.from_profile(S0, prof, MeshOptions())
    assert dom.mesh.t.shape[1] > 100


def test_thin_neck_is_resolved_locally():
    """At the static fold's gap the neck (radius w ~ 0.03 R) gets elements of at most about
    w/n_neck (``sphere_bridge(n_width=...)``, gmsh's sizes are targets: 30 % margin), while
    away from it the size stays h_surface: the count grows with the neck's resolution only
    (measured ~2.5x fewer elements than a mesh uniformly at the neck's size)."""
    from wetcontact.solver.meniscus import rupture_distance

    gap = 0.995 * rupture_distance(BRIDGE, V)
    opts = MeshOptions(n_neck=16)
    dom = Domain.from_profile(gap, static_profile(gap, V, WET), opts)
    w, zn = dom.neck()
    m = dom.mesh
    a, b, c = (m.p[:, m.t[i]] for i in range(3))
    edge = np.max([np.hypot(*(p - q)) for p, q in ((a, b), (b, c), (c, a))], axis=0)
    centre = (a + b + c) / 3
    near = np.abs(centre[1] - zn) < 0.5 * w
    assert near.sum() >= opts.n_neck
    assert edge[near].max() < 1.3 * w / opts.n_neck * 2  # longest edge ~ 2 x size
    assert edge.max() > 3 * w / opts.n_neck  # coarser away from the neck


@pytest.fixture(scope="module")
def pinched():
    """Ca = 1e-2 from S/R = 0.02 until the neck is 1.1 % of its initial radius."""
    return run(V, S0, 1e-2, WET, Stepping(dt=0.05, gap_end=0.5, neck_stop=0.011,
                                          neck_step=0.05))


@pytest.mark.slow
def test_stretched_bridge_ruptures_beyond_the_static_fold(pinched):
    """The pinch located from the neck's late law (``locate_pinch`` over its last decade):
    the rupture distance at Ca = 1e-2 is beyond the static fold of the meniscus solver
    (S_c/R = 0.11037): measured 0.13217 R, 1.1975 S_c (Pitois et al. 2001: 1.10), with the
    pinch 1.6e-4 R of gap after the last state (16 s, 3 000 elements at the end; the neck
    reached 1e-3 of its start in 170 s, 37 000 elements)."""
    from wetcontact.solver.meniscus import rupture_distance
    from wetcontact.solver.stokes_dynamic import locate_pinch

    sc = rupture_distance(BRIDGE, V)
    r = pinched
    assert r.stopped == "neck"
    p = locate_pinch(r)
    assert p.gap > 1.1 * sc
    assert 0 < p.gap - r.gap[-1] < 2e-3 * p.gap  # measured 1.2e-3
    assert np.abs(r.volume / V - 1).max() < 1e-12


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="not within 2 % at this run's resolution: over "
                   "its last decade (1.2e-2 .. 1.2e-3 R) the fitted rate is 0.089 sigma/eta, "
                   "the thread still forming. The goal's decade is reached by "
                   "benchmarks/bench_pinch.py (3 h, 12 elements across the neck, 2.5 % neck "
                   "steps, to 1.13e-4 R): rate 0.0699 (-1.4 %) over 1.12e-3 .. 1.13e-4 R, "
                   "Papageorgiou's line within 1.8 % of the neck there")
def test_neck_thins_at_papageorgiou_rate(pinched):
    """Papageorgiou (1995): h_min = 0.0709 sigma (t_c - t)/eta near pinch, within 2 %."""
    from wetcontact.solver.stokes_dynamic import PAPAGEORGIOU, locate_pinch

    assert locate_pinch(pinched).slope == pytest.approx(PAPAGEORGIOU, rel=0.02)


@pytest.fixture(scope="module")
def slow_stretch():
    """Ca = 1e-4 from S/R = 0.02 (dS = 2.5e-4 per step) until the neck is 1 % of its start."""
    return run(V, S0, 1e-4, WET, Stepping(dt=2.5, gap_end=0.5, neck_stop=0.01,
                                          neck_step=0.05))


@pytest.mark.slow
def test_small_ca_force_is_static_plus_quasi_static_viscous(slow_stretch):
    """At Ca = 1e-4 the force against gap is the meniscus solver's plus Ca times the
    quasi-static ``stokes`` viscous force within 1e-4 relative at S/R = 0.03, 0.05, 0.08
    (measured 1.2e-5, 1.7e-5, 9.5e-6; the viscous part is 1.4e-3 .. 1.8e-4 of the force;
    the time error at dS = 5e-4 per step is 1e-4, at 1.25e-4 2e-6). Near the fold: 1.4e-4
    at S/R = 0.1 and 0.105 (5e-4 and 1.3e-3 at dS = 5e-4)."""
    from scipy.interpolate import CubicSpline

    r = slow_stretch
    k = int(np.argmax(r.gap > 0.09))  # the spline stays clear of the fold
    force = CubicSpline(r.gap[1:k], r.force[1:k])
    for gap in (0.03, 0.05, 0.08):
        expected = _static(gap).force + 1e-4 * viscous_per_speed(gap, V, 20.0)
        assert float(force(gap)) == pytest.approx(expected, rel=1e-4)


BRIDGE2 = Bridge(radius=1.0, radius2=1.0, contact_angle1=TH, contact_angle2=TH,
                 surface_tension=1.0)
HALF = MeshOptions(plane="symmetry")  # two equal spheres: the upper half, mid-plane z = 0


def test_equal_spheres_static_bridge_is_an_equilibrium():
    """Two equal spheres at S/R = 0.04 holding V/R^3 = 1e-3, as the half above the
    shear-free mid-plane (gap 0.02, volume 5e-4): one step at rest from the meniscus
    solver's two-sphere bridge gives its force within 1e-5 (measured 9e-7), the mid-plane
    the opposite force, a spurious velocity below 1e-4."""
    dom = Domain.from_profile(S0, static_profile(S0, V / 2, WET, "symmetry"), HALF)
    assert dom.plane == "symmetry"
    xs, _ = correct_volume(dom.surface_xy, S0, V / 2)
    dom = dom.moved(xs, S0)
    assert_at_rest(dom, WET, solve_volume(BRIDGE2, 2 * S0, V).force)


def test_equal_spheres_force_excess_is_the_quasi_static_viscous_force():
    """Equal spheres separated at Ca = 1e-3 (relative speed; the half's sphere moves at
    Ca/2) from S/R = 0.04 to 0.06, dS = 2e-4 per step: (F - F_static)/Ca against the
    quasi-static ``stokes`` two-sphere bridge's viscous force per unit relative speed:
    measured -1.9349 against -1.9256 (0.5 %; dS = 4e-4 gives -1.9353)."""
    ca = 1e-3
    r = run(V / 2, S0, ca / 2, WET, Stepping(dt=0.2, t_end=0.02 / ca), mesh=HALF)
    assert r.stopped == "t_end" and 2 * r.gap[-1] == pytest.approx(0.06, abs=1e-12)
    assert np.abs(r.volume / (V / 2) - 1).max() < 1e-12
    excess = (r.force[-1] - solve_volume(BRIDGE2, 0.06, V).force) / ca
    fv = viscous_per_speed(0.06, V, 20.0, radius2=1.0)
    assert fv < 0
    assert excess == pytest.approx(fv, rel=0.01)


@pytest.mark.slow
def test_equal_spheres_rupture_beyond_the_static_rupture():
    """Equal spheres stretched at Ca = 1e-2 to pinch at the mid-plane (12 s, 2 700
    elements at the end): the rupture distance is beyond the meniscus solver's static
    rupture distance (S_c/R = 0.11431): measured 0.13320, 1.165 S_c (Pitois: 1.10); the
    volume is kept within 1e-12."""
    from wetcontact.solver.meniscus import rupture_distance
    from wetcontact.solver.stokes_dynamic import locate_pinch

    sc = rupture_distance(BRIDGE2, V)
    r = run(V / 2, S0, 0.5e-2, WET, Stepping(dt=0.05, gap_end=0.5, neck_stop=0.011,
                                            neck_step=0.05), mesh=HALF)
    assert r.stopped == "neck"
    p = locate_pinch(r)
    assert 2 * p.gap > 1.1 * sc
    assert np.abs(r.volume / (V / 2) - 1).max() < 1e-12


def test_neck_error_estimate_is_the_cubic_term():
    """The step's error estimate is a sixth of the distance from the parabola through the
    last three neck radii: zero on a parabola, ``dt^3 h''' / 6`` on a cubic at equal steps,
    ``(t1 - t0)(t1 - t1')(t1 - t2) h''' / 36`` at unequal ones."""
    from wetcontact.solver.stokes_dynamic.run import _neck_error

    par = {"t": [0.0, 1.0, 3.0], "neck": [1.0, 2.0, 10.0]}  # 1 + t^2
    assert _neck_error(par, 4.5, 1.0 + 4.5**2) == pytest.approx(0.0, abs=1e-12)
    cubic = {"t": [0.0, 1.0, 2.0], "neck": [0.0, 1.0, 8.0]}
    assert _neck_error(cubic, 3.0, 27.0) == pytest.approx(1.0, rel=1e-14)
    cubic = {"t": [0.0, 1.0, 3.0], "neck": [0.0, 1.0, 27.0]}
    assert _neck_error(cubic, 4.5, 4.5**3) == pytest.approx(4.5 * 3.5 * 1.5 / 6, rel=1e-14)
    with pytest.raises(SolverError, match="tolerance = 0.0; allowed"):
        Stepping(dt=0.1, t_end=1.0, tolerance=0.0)
