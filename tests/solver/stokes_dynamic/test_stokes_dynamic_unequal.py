"""A dynamic bridge between unequal spheres (``MeshOptions.radius2``: a lower sphere of
radius R2 as a solid with slip and a contact line).

Independent references:

* the meniscus solver's two-sphere bridge (its own Young-Laplace discretisation): the
  fixed point of the dynamics and the liquid below its neck;
* the quasi-static ``stokes`` model's two-sphere bridge: the O(Ca) force excess;
* the symmetric half above a shear-free mid-plane (``plane="symmetry"``, other boundary
  conditions on another domain): the whole bridge between equal spheres must rupture where
  the half does;
* scale invariance: a bridge between spheres R and 2R is the one between R/2 and R scaled
  by 2 (volume and slip lengths scaled with it), so ``S_c(Ca)/S_c`` must not change when
  the larger sphere is taken as the unit.

Units R = sigma = eta = 1 (R the upper sphere's radius). The tolerances are the measured
errors (in each docstring) with a margin.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from wetcontact.errors import InputError, SolverError
from wetcontact.solver.meniscus import Bridge, meniscus_profile, solve_volume
from wetcontact.solver.stokes_dynamic import (
    Domain,
    MeshOptions,
    Stepping,
    Wetting,
    locate_pinch,
    run,
    static_profile,
)
from wetcontact.solver.stokes_dynamic.division import wall_side_volume
from wetcontact.solver.stokes_dynamic.domain import contact_angles, correct_volume, neck
from wetcontact.solver.stokes_dynamic.rupture import (
    NECK_STOP,
    PRESETS,
    START,
    RuptureCase,
    dynamic_rupture,
    static_fold,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from quasi_static import assert_at_rest, viscous_per_speed  # noqa: E402

TH = math.radians(30.0)
V = 1e-3
S0 = 0.02
WET = Wetting(TH, TH, 1e-3, 1e-3)


def _bridge(ratio: float) -> Bridge:
    return Bridge(radius=1.0, radius2=ratio, contact_angle1=TH, contact_angle2=TH,
                  surface_tension=1.0)


def _domain(ratio: float, gap: float = S0, volume: float = V) -> Domain:
    dom = Domain.from_profile(gap, static_profile(gap, volume, WET, radius2=ratio),
                              MeshOptions(radius2=ratio))
    xs, _ = correct_volume(dom.surface_xy, gap, volume, radius2=ratio)
    return dom.moved(xs, gap)


@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_static_bridge_between_unequal_spheres_is_an_equilibrium(ratio):
    """R2/R = 0.5 and 2 at S/R = 0.02, V/R^3 = 1e-3, 30 deg: one step at rest from the
    meniscus solver's bridge keeps its angles (within 0.005 deg; measured 0.0018) and gives
    its force within 1e-5 (measured 7e-7), the lower sphere the opposite force, a spurious
    velocity below 1e-4 sigma/eta (measured 1.9e-5)."""
    dom = _domain(ratio)
    assert dom.lower_name == "sphere2"
    assert [math.degrees(a) for a in contact_angles(dom.surface_xy, S0, ratio)] == (
        pytest.approx([30.0, 30.0], abs=0.005))
    assert_at_rest(dom, WET, solve_volume(_bridge(ratio), S0, V).force)


def test_lower_sphere_keeps_the_liquid_below_the_neck():
    """A static bridge between spheres R and 0.5 R meshed as the dynamic domain: the liquid
    below its neck plane equals the integral of pi r(z)^2 over z < z_n on the meniscus
    solver's dense profile less the lower sphere's cap (within 1e-6, measured 2e-8)."""
    ratio, gap, volume = 0.5, 0.08, 1e-3
    dom = _domain(ratio, gap, volume)
    vw, v = wall_side_volume(SimpleNamespace(domain=dom))
    prof = meniscus_profile(solve_volume(_bridge(ratio), gap, volume), n=20001)
    r, z = np.asarray(prof["r"]), np.asarray(prof["z"])
    zn = neck(dom.surface_xy)[1]
    k = int(np.searchsorted(z, zn))
    rn = r[k - 1] + (r[k] - r[k - 1]) * (zn - z[k - 1]) / (z[k] - z[k - 1])
    zz, rr = np.append(z[:k], zn), np.append(r[:k], rn)
    a2 = math.atan2(r[0], ratio + z[0])  # the lower sphere's filling angle
    cap = ratio**3 * math.pi * (1 - math.cos(a2)) ** 2 * (2 + math.cos(a2)) / 3
    ref = float(np.pi * np.sum(0.5 * (rr[1:] ** 2 + rr[:-1] ** 2) * np.diff(zz))) - cap
    assert v == pytest.approx(volume, rel=1e-9)
    assert vw == pytest.approx(ref, rel=1e-6)
    assert 0.0 < vw < v


def test_force_excess_between_unequal_spheres_is_the_quasi_static_viscous_force():
    """Spheres R and 0.5 R separated at Ca = 1e-3 from S/R = 0.02 to 0.04 (dS = 2e-4 per
    step): (F - F_static)/Ca against the quasi-static ``stokes`` two-sphere bridge's viscous
    force per unit speed: measured -6.696 against -6.666 (0.45 %)."""
    ca, ratio = 1e-3, 0.5
    r = run(V, S0, ca, WET, Stepping(dt=0.2, t_end=0.02 / ca), mesh=MeshOptions(radius2=ratio))
    assert r.stopped == "t_end" and r.gap[-1] == pytest.approx(0.04, abs=1e-12)
    assert np.abs(r.volume / V - 1).max() < 1e-12
    excess = (r.force[-1] - solve_volume(_bridge(ratio), 0.04, V).force) / ca
    fv = viscous_per_speed(0.04, V, 30.0, radius2=ratio)
    assert fv < 0
    assert excess == pytest.approx(fv, rel=0.01)


def test_radius_ratio_is_checked_by_name():
    """A radius ratio on a wall or outside the mesh builder's range is refused, naming the
    field and its range."""
    with pytest.raises(InputError, match="radius_ratio = 2.0 on a wall"):
        RuptureCase("wall", 1e-2, 1e-3, 30.0, radius_ratio=2.0)
    with pytest.raises(InputError, match=r"radius_ratio = 50.0; allowed: \[0.1, 10\]"):
        RuptureCase("pair", 1e-2, 1e-3, 30.0, radius_ratio=50.0)
    with pytest.raises(SolverError, match="radius2 = 0.01 R"):
        MeshOptions(radius2=0.01)


@pytest.mark.slow
def test_whole_bridge_between_equal_spheres_ruptures_where_its_half_does():
    """Equal spheres, Ca = 1e-2, V/R^3 = 1e-3, 30 deg, default preset: the whole bridge
    (lower sphere as a solid, 51 s) against the half above the mid-plane (18 s):
    S_c(Ca)/S_c 1.12863 against 1.12872 (8e-5)."""
    case = RuptureCase("pair", 1e-2, V, 30.0)
    assert case.half
    sc, p = static_fold(case), PRESETS["default"]
    r = run(V, START * sc, 1e-2, WET,
            Stepping(dt=p.largest_gap_step(sc) / 1e-2, gap_end=20 * sc, neck_stop=NECK_STOP,
                     neck_step=p.neck_step, tolerance=p.tolerance), MeshOptions(radius2=1.0))
    assert r.stopped == "neck"
    whole = locate_pinch(r).gap / sc
    assert whole == pytest.approx(dynamic_rupture(case).ratio, rel=5e-4)


@pytest.mark.slow
def test_rupture_ratio_does_not_depend_on_which_sphere_is_the_unit():
    """Spheres R and 2R (V/R^3 = 1e-3, slip 1e-3 R) against spheres R and R/2 (V/R^3 =
    1.25e-4, slip 5e-4 R): the same bridge scaled by 2. Static folds 0.120511 and 2 x
    0.060255; S_c(Ca)/S_c at Ca = 1e-2 1.1607261 and 1.1607206 (5e-6)."""
    big = dynamic_rupture(RuptureCase("pair", 1e-2, 1e-3, 30.0, radius_ratio=2.0))
    small = dynamic_rupture(RuptureCase("pair", 1e-2, 1.25e-4, 30.0, slip=5e-4,
                                        radius_ratio=0.5))
    assert big.static_gap == pytest.approx(2 * small.static_gap, rel=1e-6)
    assert big.ratio == pytest.approx(small.ratio, rel=1e-4)
    assert big.ratio > 1.1
