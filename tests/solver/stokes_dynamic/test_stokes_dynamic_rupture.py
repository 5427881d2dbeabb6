"""The dynamic rupture runs (``stokes_dynamic.rupture``): inputs, steps, one run to pinch."""

from __future__ import annotations

import math

import pytest

from wetcontact.errors import InputError
from wetcontact.solver.stokes_dynamic.rupture import (
    PAIR_THETA_MAX,
    PRESETS,
    S_REF,
    RuptureCase,
    dynamic_rupture,
    gap_step,
    static_fold,
)


@pytest.mark.parametrize("field,value", [("capillary_number", 2.0), ("volume", 0.5),
                                         ("theta_deg", 80.0), ("slip", 0.0),
                                         ("capillary_number", math.nan)])
def test_case_outside_the_method_is_refused_by_name(field, value):
    args = {"kind": "wall", "capillary_number": 1e-2, "volume": 1e-3, "theta_deg": 20.0,
            field: value}
    with pytest.raises(InputError, match=rf"{field} = .*allowed"):
        RuptureCase(**args)



def test_equal_spheres_past_the_symmetry_breaking_angle_are_refused():
    """Above PAIR_THETA_MAX the static branch between equal spheres ends at the
    symmetry-breaking bifurcation, which the symmetric half cannot follow."""
    with pytest.raises(InputError, match="kind"):
        RuptureCase("plate", 1e-2, 1e-3, 20.0)
    with pytest.raises(InputError, match="symmetry"):
        RuptureCase("pair", 1e-2, 1e-3, PAIR_THETA_MAX + 1.0)
    assert RuptureCase("wall", 1e-2, 1e-3, PAIR_THETA_MAX + 1.0).theta_deg > PAIR_THETA_MAX


def test_gap_step_follows_the_delay_below_ca_1e_2():
    """The step is the preset's at S_c = S_REF and Ca >= 1e-2, proportional to S_c, and
    shrinks like Ca^(1/3) below."""
    base = PRESETS["default"][0]
    assert gap_step("default", S_REF, 0.1) == pytest.approx(base, rel=1e-14)
    assert gap_step("default", 2 * S_REF, 1e-2) == pytest.approx(2 * base, rel=1e-14)
    assert gap_step("default", S_REF, 1e-5) == pytest.approx(base * 0.1, rel=1e-12)
    assert gap_step("fast", S_REF, 1.0) == 2 * gap_step("default", S_REF, 1.0)


def test_equal_spheres_rupture_beyond_the_fold_and_converges_in_the_step():
    """Two equal spheres, V/R^3 = 1e-3, 30 deg, Ca = 0.05: the rupture distance lies beyond
    the meniscus solver's static fold, the volume is kept to 1e-11, and the fast preset
    (twice the default gap step and neck step) is within 2 % of the default one (first
    order in the step: their difference bounds the default's time error)."""
    case = RuptureCase("pair", 0.05, 1e-3, 30.0)
    fast = dynamic_rupture(case, "fast")
    default = dynamic_rupture(case, "default")
    assert default.static_gap == pytest.approx(static_fold(case), rel=1e-12)
    assert default.ratio > 1.1
    assert default.volume_error < 1e-11 and fast.volume_error < 1e-11
    assert fast.gap == pytest.approx(default.gap, rel=0.02)
    assert default.steps > fast.steps
