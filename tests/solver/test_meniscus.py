"""Tests of the finite-element Young-Laplace bridge (model ``meniscus``).

References, each independent of the FE code:
- an ODE shooting solution written separately (``tests/solver/shooting.py``);
- analytic cases of PHYSICS.md section 2: catenoid and cylinder between plates, the
  small-volume contact limits F -> 2 pi R* sigma (cos th1 + cos th2).
Tolerances: 1e-6 relative against shooting (acceptance line of the issue; the FE error at
the default resolution is about 1e-9, the shooting error about 1e-12); 1e-4 for the rupture
distance; 1e-8 for the spread of the three force evaluations; 1e-5 for -dE/dS.
Lengths are in units of the sphere radius (R1 = 1, sigma = 1), where the solver is scale free.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact.errors import InputError, ValidityError
from wetcontact.models import load_all
from wetcontact.solver.meniscus import (
    Bridge,
    energy_derivative,
    force_separation_curve,
    meniscus_profile,
    rupture_distance,
    solve_suction,
    solve_volume,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from shooting import shoot_rupture, shoot_volume  # noqa: E402

DEG = math.pi / 180.0


def _bridge(R2, th1, th2):
    return Bridge(radius=1.0, radius2=R2, contact_angle1=th1 * DEG, contact_angle2=th2 * DEG,
                  surface_tension=1.0)


def _compare(R2, V, th1, th2, fracs):
    br = _bridge(R2, th1, th2)
    Sc = rupture_distance(br, V)
    for frac in fracs:
        S = frac * Sc
        sol = solve_volume(br, S, V)
        assert sol.exists and sol.stability == 1.0
        ref = shoot_volume(V, S, th1 * DEG, th2 * DEG, R2,
                           (sol.filling_angle1, sol.laplace_pressure))
        assert ref.residual < 1e-10, "shooting did not converge"
        assert -sol.force == pytest.approx(ref.force, rel=1e-6)
        assert sol.laplace_pressure == pytest.approx(ref.pressure, rel=1e-6)
        assert sol.filling_angle1 == pytest.approx(ref.phi1, rel=1e-6)
        assert sol.force_spread < 1e-8
    return br, Sc


FAST_CASES = [
    # (R2 (None = wall), V*, theta1, theta2)
    (None, 1e-4, 0.0, 0.0),
    (None, 0.2, 60.0, 0.0),
    (None, 1e-2, 30.0, 60.0),
    (1.0, 1e-2, 0.0, 40.0),
    (2.0, 1e-3, 60.0, 60.0),
    (0.5, 1e-4, 20.0, 0.0),
]


@pytest.mark.parametrize("R2,V,th1,th2", FAST_CASES)
def test_against_shooting(R2, V, th1, th2):
    _compare(R2, V, th1, th2, (0.0, 0.5, 0.95))


@pytest.mark.slow
@pytest.mark.parametrize("R2", [None, 1.0, 0.2, 5.0])
@pytest.mark.parametrize("V", [1e-4, 1e-3, 1e-2, 0.2])
@pytest.mark.parametrize("th1,th2", [(0.0, 0.0), (60.0, 60.0), (0.0, 60.0), (45.0, 10.0)])
def test_against_shooting_sweep(R2, V, th1, th2):
    if R2 is not None and V > 0.5 * R2**3:
        pytest.skip("volume too large for the small sphere")
    _compare(R2, V, th1, th2, (0.0, 0.3, 0.7, 0.95))


@pytest.mark.parametrize("R2,V,th1,th2", [(None, 1e-3, 0.0, 0.0), (1.0, 1e-2, 30.0, 10.0)])
def test_rupture_distance_against_shooting_turning_point(R2, V, th1, th2):
    br = _bridge(R2, th1, th2)
    Sc = rupture_distance(br, V)
    near = solve_volume(br, 0.999 * Sc, V)
    phi = near.filling_angle1
    ref = shoot_rupture(V, th1 * DEG, th2 * DEG, R2, (0.8 * phi, 1.2 * phi),
                        (0.999 * Sc, near.laplace_pressure))
    assert ref.residual < 1e-10
    assert Sc == pytest.approx(ref.gap, rel=1e-4)
    assert solve_volume(br, 1.001 * Sc, V).exists is False


def test_catenoid_between_plates():
    a, h = 1.0, 1.2
    th = math.atan2(1.0, math.sinh(h / a))
    V = math.pi * a * a * (h + 0.5 * a * math.sinh(2 * h / a))
    sol = solve_volume(Bridge(None, None, th, th, 1.0), 2 * h, V)
    assert abs(sol.laplace_pressure) < 1e-6
    assert sol.neck_radius == pytest.approx(a, rel=1e-7)
    assert -sol.force == pytest.approx(2 * math.pi * a, rel=1e-7)


def test_cylinder_between_plates():
    a, S = 0.7, 2.0
    sol = solve_volume(Bridge(None, None, math.pi / 2, math.pi / 2, 0.05), S, math.pi * a * a * S)
    assert sol.laplace_pressure == pytest.approx(0.05 / a, rel=1e-9)
    assert -sol.force == pytest.approx(math.pi * 0.05 * a, rel=1e-9)   # attractive pi sigma a


@pytest.mark.parametrize("R2,th1,th2", [(None, 0.0, 0.0), (None, 40.0, 20.0),
                                        (1.0, 0.0, 0.0), (1.0, 30.0, 50.0), (3.0, 10.0, 0.0)])
def test_small_volume_contact_limit(R2, th1, th2):
    """F -> 2 pi R* sigma (cos th1 + cos th2) at contact as V -> 0; the approach is linear
    in the filling angle, so extrapolate the two smallest volumes to phi1 = 0."""
    br = _bridge(R2, th1, th2)
    Rs = 1.0 if R2 is None else R2 / (1.0 + R2)
    limit = 2 * math.pi * Rs * (math.cos(th1 * DEG) + math.cos(th2 * DEG))
    a, b = (solve_volume(br, 0.0, V) for V in (1e-10, 1e-9))
    fa, fb = -a.force, -b.force
    extrap = fa - a.filling_angle1 * (fb - fa) / (b.filling_angle1 - a.filling_angle1)
    assert extrap == pytest.approx(limit, rel=2e-4)
    assert fa == pytest.approx(limit, rel=2e-2)


@pytest.mark.parametrize("R2", [None, 1.0])
def test_energy_derivative_matches_force(R2):
    br = _bridge(R2, 20.0, 40.0)
    for S in (0.0, 0.05, 0.12):
        sol = solve_volume(br, S, 1e-2)
        assert -energy_derivative(sol) == pytest.approx(sol.force, rel=1e-5)
        # and a finite difference of the energy itself (step 1e-4, error ~1e-8)
        e1, e0 = (solve_volume(br, S + s, 1e-2).energy for s in (1e-4, -1e-4) if S + s >= 0) \
            if S > 0 else (None, None)
        if e1 is not None:
            assert -(e1 - e0) / 2e-4 == pytest.approx(sol.force, rel=1e-5)


def test_force_curve_to_rupture_and_stability():
    br = _bridge(None, 20.0, 10.0)
    curve = force_separation_curve(br, 5e-3, n_points=20)
    assert curve.gap[-1] == pytest.approx(curve.rupture_distance, rel=1e-12, abs=0)
    assert np.all(np.diff(curve.gap) > 0)
    assert np.all(curve.force < 0)                      # attraction everywhere
    assert np.all(np.diff(curve.force[1:]) > 0)         # weakening with separation
    assert all(s.stability == 1.0 for s in curve.solutions[:-1])
    assert curve.unstable and all(s.stability == -1.0 for s in curve.unstable)
    assert all(s.force_spread < 1e-8 for s in curve.solutions)


def test_suction_controlled_matches_volume_controlled():
    br = _bridge(1.5, 10.0, 30.0)
    vol = solve_volume(br, 0.05, 1e-2)
    suc = solve_suction(br, 0.05, vol.laplace_pressure, volume_guess=1.1e-2)
    assert suc.exists
    assert suc.volume == pytest.approx(1e-2, rel=1e-9)
    assert suc.force == pytest.approx(vol.force, rel=1e-9)
    # without a volume guess (toroidal guess at the given pressure)
    suc2 = solve_suction(br, 0.05, vol.laplace_pressure)
    assert suc2.force == pytest.approx(vol.force, rel=1e-9)


def test_profile_export_lies_on_the_solids():
    br = _bridge(2.0, 30.0, 20.0)
    sol = solve_volume(br, 0.03, 3e-3)
    prof = meniscus_profile(sol, n=200)
    r, z = prof["r"], prof["z"]
    R1, R2, S = 1.0, 2.0, 0.03
    assert math.hypot(r[-1], z[-1] - (S + R1)) == pytest.approx(R1, abs=1e-12)
    assert math.hypot(r[0], z[0] + R2) == pytest.approx(R2, abs=1e-12)
    assert r[-1] == pytest.approx(math.sin(sol.filling_angle1), rel=1e-12, abs=0)
    assert np.min(r) == pytest.approx(sol.neck_radius, rel=1e-4)
    ds = np.hypot(np.diff(r), np.diff(z))
    assert np.sum(ds) == pytest.approx(prof["s"][-1], rel=1e-4)


def test_gravity_force_balance():
    """With gravity the cut force changes by the liquid weight; the three evaluations
    (referred to sphere 1) still agree, and Bo -> 0 recovers the no-gravity force."""
    base = dict(radius=1e-3, radius2=None, contact_angle1=0.2, contact_angle2=0.1,
                surface_tension=0.072)
    V = 1e-11
    s0 = solve_volume(Bridge(**base), 1e-4, V)
    sg = solve_volume(Bridge(**base, gravity=9.81, density=1000.0), 1e-4, V)
    assert sg.force_spread < 1e-8
    assert sg.force != pytest.approx(s0.force, rel=1e-6)
    assert sg.force == pytest.approx(s0.force, rel=5e-2)


# ---- the registered model -------------------------------------------------------------


def _scene(scene_factory, kind="sphere-wall", V=1e-11, gaps=(1e-6, 5e-5), **liq):
    geom = {"kind": kind, "radius": 1e-3}
    if kind == "sphere-sphere":
        geom["radius2"] = 2e-3
    liquid = {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
              "contact_angle": 20.0, **liq}
    return scene_factory(geometry=geom, liquid=liquid, amount={"bridge_volume": V},
                         motion={"velocity": 0.0, "gaps": list(gaps)})


def test_model_registered_with_extras(scene_factory):
    model = load_all()["meniscus"]
    assert model.level == 3 and model.component == "capillary" and model.order == 4.0
    scene = _scene(scene_factory, gaps=(0.0005e-3, 0.05e-3, 0.5e-3))
    curve = model.force(scene)
    assert curve.force_viscous is None
    ex = curve.extras
    assert ex["bridge_exists"].tolist() == [1.0, 1.0, 0.0]     # 0.5 mm is beyond rupture
    assert curve.force_capillary[0] < curve.force_capillary[1] < 0
    assert curve.force_capillary[2] == 0.0
    assert np.all(ex["rupture_distance"] == ex["rupture_distance"][0])
    assert 5e-5 < ex["rupture_distance"][0] < 5e-4
    assert "wetted_radius" in ex and "filling_angle2" not in ex
    assert np.all(ex["force_spread"][:2] < 1e-8)
    assert np.all(ex["stability"][:2] == 1.0)
    sph = model.force(_scene(scene_factory, kind="sphere-sphere"))
    assert "filling_angle2" in sph.extras and "wetted_radius" not in sph.extras


def test_model_force_matches_shooting(scene_factory):
    scene = _scene(scene_factory, V=1e-11, gaps=(2e-5,))
    curve = load_all()["meniscus"].force(scene)
    R, sig = 1e-3, 0.072
    ref = shoot_volume(1e-11 / R**3, 2e-5 / R, 20 * DEG, 20 * DEG, None,
                       (curve.extras["filling_angle"][0],
                        curve.extras["laplace_pressure"][0] * R / sig))
    assert curve.force_capillary[0] == pytest.approx(-ref.force * sig * R, rel=1e-6)


@pytest.mark.parametrize("preset", ["fast", "default"])
@pytest.mark.parametrize("kind,theta", [("sphere-wall", 20.0), ("sphere-sphere", 50.0)])
def test_model_presets_within_their_declared_bounds_of_shooting(scene_factory, preset, kind,
                                                                theta):
    """Each preset's declared bound (``error_bound``: 1e-5 fast, 1e-6 default), which
    selection relies on, holds against the shooting solution at a small gap, half the
    rupture distance and 0.95 of it (V/R^3 = 1e-2; R2 = 2 R between spheres)."""
    model = load_all()["meniscus"]
    R, sig, v = 1e-3, 0.072, 1e-11
    s_c = model.force(_scene(scene_factory, kind=kind, V=v, gaps=(1e-7,),
                             contact_angle=theta)).extras["rupture_distance"][0]
    gaps = (1e-7, 0.5 * s_c, 0.95 * s_c)
    curve = model.force(_scene(scene_factory, kind=kind, V=v, gaps=gaps, contact_angle=theta),
                        preset=preset)
    r2 = 2.0 if kind == "sphere-sphere" else None
    bound = model.error_bound[preset]
    for i, gap in enumerate(gaps):
        phi = curve.extras["filling_angle"][i]  # on the first sphere
        ref = shoot_volume(v / R**3, gap / R, theta * DEG, theta * DEG, r2,
                           (phi, curve.extras["laplace_pressure"][i] * R / sig))
        assert ref.residual < 1e-10, "shooting did not converge"
        assert abs(curve.force_capillary[i] / (-ref.force * sig * R) - 1.0) <= bound, gap


def test_model_rejects_bad_input(scene_factory):
    model = load_all()["meniscus"]
    immersed = scene_factory()
    with pytest.raises(ValidityError, match="stokes"):
        model.force(immersed)
    film = scene_factory(amount={"film_thickness": 1e-4})
    with pytest.raises(ValidityError, match="thinfilm"):
        model.force(film)
    with pytest.raises(InputError, match="volume too large"):
        model.force(_scene(scene_factory, V=2e-9))
    with pytest.raises(ValidityError, match="volume too large"):  # refused by check
        model.check(_scene(scene_factory, V=2e-9))
    # every gap past rupture: no bridge, force 0 (as the closures give), said in a note
    past = model.force(_scene(scene_factory, gaps=(5e-4, 8e-4)))
    assert np.array_equal(past.force_capillary, [0.0, 0.0])
    assert "beyond the rupture distance" in past.diagnostics["past_rupture"]
    assert not past.extras["bridge_exists"].any()
    with pytest.raises(ValidityError, match="150 deg"):
        model.force(_scene(scene_factory, contact_angle=170.0))
    with pytest.raises(InputError, match=r"\[0, 150\] deg"):
        Bridge(1.0, None, math.radians(160.0), 0.0, 1.0)


def test_no_bridge_is_explicit_not_nan():
    br = _bridge(None, 0.0, 0.0)
    sol = solve_volume(br, 1.0, 1e-4)
    assert sol.exists is False and "no bridge" in sol.message
    assert sol.force == 0.0 and math.isfinite(sol.laplace_pressure)
    with pytest.raises(InputError):
        meniscus_profile(sol)


def test_nonwetting_bridge_is_repulsive_and_steeper_angles_are_refused():
    """Contact angles up to 150 deg still give a (convex, repulsive) bridge; above 150 deg
    the solver refuses with a message instead of failing inside Newton."""
    br = _bridge(None, 150.0, 150.0)
    sol = solve_volume(br, 0.05, 1e-3)
    assert sol.exists and sol.force > 0 and sol.laplace_pressure > 0
    assert sol.force_spread < 1e-8
    ref = shoot_volume(1e-3, 0.05, 150 * DEG, 150 * DEG, None,
                       (sol.filling_angle1, sol.laplace_pressure))
    assert ref.residual < 1e-10
    assert -sol.force == pytest.approx(ref.force, rel=1e-6)
    with pytest.raises(InputError, match=r"allowed: \[0, 150\] deg"):
        _bridge(None, 20.0, 155.0)


def test_rupture_at_symmetry_breaking_bifurcation():
    """Equal spheres, equal angles 50 deg: the symmetric bridge loses stability to an
    up-down asymmetric mode before its fold, so rupture is that bifurcation. Independent
    check: breaking the symmetry (theta1 = 50 + eps) turns it into ordinary folds at
    S_b - c eps^(2/3) - d eps^(4/3) (imperfect subcritical pitchfork), found by the fold
    search alone; their eps -> 0 limit must be the bifurcation."""
    from wetcontact.solver.meniscus.solve import _branch_for

    V = 10**-2.5
    br, _ = _branch_for(_bridge(1.0, 50.0, 50.0), V, 128)
    assert br.end == "bifurcation"
    eps = np.array([0.25, 0.5, 1.0])
    folds = []
    for e in eps:
        b, _ = _branch_for(_bridge(1.0, 50.0 + e, 50.0), V, 128)
        assert b.end == "fold"
        folds.append(b.S_fold)
    A = np.column_stack([np.ones(3), eps ** (2 / 3), eps ** (4 / 3)])
    s_b = np.linalg.solve(A, np.array(folds))[0]
    assert br.S_fold == pytest.approx(s_b, rel=2e-4)
    # the fold of the symmetric branch lies well beyond it (6 %): not a round-off effect
    assert folds[0] < br.S_fold
    assert rupture_distance(_bridge(1.0, 50.0, 50.0), V) == pytest.approx(br.S_fold, rel=1e-12,
                                                                          abs=0)
    sol = solve_volume(_bridge(1.0, 50.0, 50.0), 1.001 * br.S_fold, V)
    assert sol.exists is False


def test_stability_bisection_may_land_on_a_singular_jacobian():
    """A branch whose stability bisection lands on a bridge where SuperLU finds the
    Jacobian exactly singular (the stability boundary itself; met by the two-angle pair
    table's generator at radius ratio 10, V = 0.0769 R^3, contact angles 14.0 and 91.0
    deg): the point counts as not stable and the bisection goes on, instead of SuperLU's
    RuntimeError ending the branch. Its rupture distance is the shooting solution's
    turning point (1e-4, as above), and its force at the gap nodes finite and attractive."""
    from wetcontact.generate.calibrated_capillary import lobatto, solve_branch

    ratio, V = 10.000000000000007, 0.07688104870871841
    th1, th2 = 0.24410425148815793, 1.5881520564395548  # rad, as the generator had them
    s_c, q = solve_branch("sphere-sphere", ratio, V, th1, lobatto(19), th2)
    br = Bridge(radius=1.0, radius2=ratio, contact_angle1=th1, contact_angle2=th2,
                surface_tension=1.0)
    near = solve_volume(br, 0.999 * s_c, V)
    phi = near.filling_angle1
    ref = shoot_rupture(V, th1, th2, ratio, (0.8 * phi, 1.2 * phi),
                        (0.999 * s_c, near.laplace_pressure))
    assert ref.residual < 1e-10
    assert s_c == pytest.approx(ref.gap, rel=1e-4)
    assert np.all(np.isfinite(q)) and np.all(q > 0)
