"""Rupture-distance closures against hand-computed values of the papers' equations and
against each other's limits (each tolerance says where it comes from)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wetcontact.errors import InputError
from wetcontact.reduced_models.rupture import (
    lian_rupture_distance,
    mikami_rupture_distance_pp,
    mikami_rupture_distance_pw,
    pitois_rupture_distance,
    willett_rupture_distance,
)


def test_lian_hand_values():
    # (1 + 0/2) * (1e-9)^(1/3) = 1e-3 m; (1 + 0.25) * (8e-9)^(1/3) = 1.25 * 2e-3 m
    assert lian_rupture_distance(1e-9, 0.0) == pytest.approx(1e-3, rel=1e-12, abs=0)
    assert lian_rupture_distance(8e-9, 0.5) == pytest.approx(2.5e-3, rel=1e-12, abs=0)


def test_willett_hand_values():
    # R = 1 mm, V = 1e-12 m3 -> V* = 1e-3, V*^(1/3) = 0.1, V*^(2/3) = 0.01:
    # theta = 0: S_c = 1e-3 * (0.1 + 0.001) = 1.01e-4 m; theta = 1 rad: 1.5 times that.
    assert willett_rupture_distance(1e-12, 1e-3, 0.0) == pytest.approx(1.01e-4, rel=1e-12, abs=0)
    assert willett_rupture_distance(1e-12, 1e-3, 1.0) == pytest.approx(1.515e-4, rel=1e-12, abs=0)


def test_willett_tends_to_lian_for_small_volume():
    # Willett / Lian = 1 + 0.1 V*^(1/3): 1.001 at V* = 1e-6 (exact ratio of the two papers)
    r, v = 1e-3, 1e-6 * 1e-9
    ratio = willett_rupture_distance(v, r, 0.3) / lian_rupture_distance(v, 0.3)
    assert ratio == pytest.approx(1.001, rel=1e-12, abs=0)


def test_mikami_hand_values():
    # V* = 1e-3: pp 0.99 * 10^(-1.02) = 0.0945443; pw 0.95 * 10^(-0.96) = 0.1041654 (in R)
    r = 2e-3
    v = 1e-3 * r**3
    assert mikami_rupture_distance_pp(v, r, 0.0) == pytest.approx(0.0945443 * r, rel=1e-6)
    assert mikami_rupture_distance_pw(v, r, 0.0) == pytest.approx(0.1041654 * r, rel=1e-6)
    # theta = 0.5 rad: prefactors 0.99 + 0.31 = 1.30 and 0.95 + 0.11 = 1.06
    assert mikami_rupture_distance_pp(v, r, 0.5) == pytest.approx(1.30 / 0.99 * 0.0945443 * r,
                                                                  rel=1e-6)
    assert mikami_rupture_distance_pw(v, r, 0.5) == pytest.approx(1.06 / 0.95 * 0.1041654 * r,
                                                                  rel=1e-6)


def test_mikami_pp_close_to_lian_at_zero_angle():
    # both fit Young-Laplace rupture of equal spheres; at V* = 1e-3 they agree to 6 %
    # (0.9454 vs 1.0 times V^(1/3)); a wrong exponent or R-scaling would be far off
    r = 1e-3
    v = 1e-3 * r**3
    assert mikami_rupture_distance_pp(v, r, 0.0) / lian_rupture_distance(v, 0.0) == \
        pytest.approx(0.945, abs=0.01)


def test_pitois_reduces_to_lian_at_zero_capillary_number():
    v = np.array([1e-12, 3e-11])
    th = np.array([0.0, 0.6])
    np.testing.assert_allclose(pitois_rupture_distance(v, th, 0.0), lian_rupture_distance(v, th),
                               rtol=0, atol=0)


def test_pitois_hand_value():
    # Ca = 0.25 -> factor 1 + 0.5; V = 1e-9 m3, theta = 0 -> 1.5e-3 m
    assert pitois_rupture_distance(1e-9, 0.0, 0.25) == pytest.approx(1.5e-3, rel=1e-12, abs=0)


@pytest.mark.parametrize("call", [
    lambda: lian_rupture_distance(0.0, 0.1),
    lambda: lian_rupture_distance(-1e-12, 0.1),
    lambda: lian_rupture_distance(1e-12, -0.1),
    lambda: lian_rupture_distance(1e-12, math.pi),
    lambda: willett_rupture_distance(1e-12, 0.0, 0.1),
    lambda: mikami_rupture_distance_pp(float("nan"), 1e-3, 0.1),
    lambda: mikami_rupture_distance_pw(1e-12, 1e-3, 4.0),
    lambda: pitois_rupture_distance(1e-12, 0.1, -0.1),
])
def test_invalid_inputs_raise(call):
    with pytest.raises(InputError, match="allowed"):
        call()
