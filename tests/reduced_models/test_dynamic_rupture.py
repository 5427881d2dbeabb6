"""The dynamic rupture closure: its form, its fit, its domain, and the shipped data."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wetcontact.errors import InputError
from wetcontact.reduced_models import dynamic_rupture as dr
from wetcontact.reduced_models.rupture import lian_rupture_distance, pitois_rupture_distance

ZERO = {"a": 1.0, "b": 0.5, "c": 0.0, "d": 0.0, "e": 0.0, "g": 0.0}


def test_form_with_pitois_coefficients_is_pitois():
    """a = 1, b = 1/2, c = d = e = 0 is Pitois et al.'s factor: the published function over
    Lian's static distance, at any volume and angle."""
    ca = np.geomspace(1e-4, 1.0, 9)
    v, th = 2e-12, 0.4
    want = pitois_rupture_distance(v, th, ca) / lian_rupture_distance(v, th)
    got = dr.ratio_form({"wall": ZERO, "pair": ZERO}, np.array([True, False] * 4 + [True]),
                        ca, 3e-3, 25.0)
    np.testing.assert_allclose(got, want, rtol=1e-14)


def test_fit_recovers_the_coefficients_of_its_own_form():
    """Ratios made by the form (coefficients of each kind chosen here; radius ratios between
    spheres only) are fitted back to 1e-10, and a fit restricted to (a, b) of data that has
    only (a, b) too."""
    rng = np.random.default_rng(3)
    n = 60
    wall = np.arange(n) % 2 == 0
    ca = np.exp(rng.uniform(math.log(1e-4), math.log(0.3), n))
    v = np.exp(rng.uniform(math.log(1e-4), math.log(1e-2), n))
    th = rng.uniform(10, 50, n)
    rho = np.where(wall, 1.0, rng.uniform(0.25, 1.0, n))
    coef = {"wall": {"a": 1.7, "b": 0.41, "c": -0.01, "d": 0.05, "e": 0.3, "g": 0.0},
            "pair": {"a": 1.2, "b": 0.38, "c": 0.004, "d": -0.02, "e": 0.1, "g": -0.3}}
    got = dr.fit_form(wall, ca, v, th, dr.ratio_form(coef, wall, ca, v, th, rho), rho=rho)
    for kind in coef:
        for name in dr.NAMES:
            assert got[kind][name] == pytest.approx(coef[kind][name], rel=1e-10, abs=1e-12)
    ab = {k: {**ZERO, "a": c["a"], "b": c["b"]} for k, c in coef.items()}
    got = dr.fit_form(wall, ca, v, th, dr.ratio_form(ab, wall, ca, v, th), names=("a", "b"))
    assert got["pair"]["a"] == pytest.approx(1.2, rel=1e-10)
    assert got["wall"]["c"] == 0.0


def test_shipped_closure_is_in_its_record_and_refuses_outside():
    """The shipped coefficients reproduce the held-out errors the data file states (the
    runs' references against the closure evaluated here), and the closure refuses inputs
    outside the fitted domain with the name and the range."""
    data = dr.load()
    held = [r for r in data["runs"] if r["held_out"] and "result" in r]
    assert len(held) >= 8
    assert any(r["case"]["radius_ratio"] != 1.0 for r in held)
    e = [abs(dr.dynamic_rupture_ratio(r["case"]["kind"], r["case"]["capillary_number"],
                                      r["case"]["volume"], r["case"]["theta_deg"],
                                      r["case"]["radius_ratio"])
             / r["result"]["ratio"] - 1.0) for r in held]
    assert max(e) == pytest.approx(data["held_out"]["max"], rel=1e-9)
    lo = data["domain"]["capillary_number"][0]
    with pytest.raises(InputError, match=r"capillary_number .* outside \["):
        dr.dynamic_rupture_ratio("wall", lo / 2, 1e-3, 20.0)
    with pytest.raises(InputError, match="kind"):
        dr.dynamic_rupture_ratio("plate", 1e-2, 1e-3, 20.0)
    with pytest.raises(InputError, match=r"theta_deg .* outside \[10, 30\]"):
        dr.dynamic_rupture_ratio("pair", 1e-2, 1e-3, 40.0)
    assert dr.dynamic_rupture_ratio("wall", 1e-2, 1e-3, 40.0) > 1.0
    r = dr.dynamic_rupture_ratio("pair", np.array([1e-3, 1e-2]), 1e-3, 20.0)
    assert r.shape == (2,) and np.all(r > 1.0) and r[1] > r[0]
    q0 = data["domain"]["rho"][0]
    with pytest.raises(InputError, match=r"rho = .* outside \["):
        dr.dynamic_rupture_ratio("pair", 1e-2, 1e-3 * dr.effective_radius(0.5 * q0) ** 3,
                                 20.0, 0.5 * q0)
    with pytest.raises(InputError, match="radius_ratio = 2 on a wall"):
        dr.dynamic_rupture_ratio("wall", 1e-2, 1e-3, 20.0, 2.0)


def test_pair_closure_is_the_same_whichever_sphere_is_first():
    """Spheres R and qR holding V are spheres qR and R holding V: ``(V/R^3, q)`` and
    ``(V/(qR)^3, 1/q)`` give the same ratio (to rounding)."""
    for q in (0.3, 0.5, 0.8):
        v = 2e-3 * float(dr.effective_radius(q)) ** 3
        a = dr.dynamic_rupture_ratio("pair", 1e-2, v, 20.0, q)
        b = dr.dynamic_rupture_ratio("pair", 1e-2, v / q**3, 20.0, 1.0 / q)
        assert a == pytest.approx(b, rel=1e-13)
