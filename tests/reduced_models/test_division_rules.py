"""The published division rules (reduced_models/division.py): their values from the sources,
their limits, and their inputs. Each is a closed form, so the tolerances are round-off."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wetcontact.errors import InputError
from wetcontact.reduced_models.division import (
    even_split_fraction,
    mercurydpm_fraction,
    shi_mccarthy_fraction,
    shi_mccarthy_share,
)


def test_even_split_and_mercurydpm():
    assert np.array_equal(even_split_fraction([1e-3, 2e-3], 1e-3), [0.5, 0.5])
    assert even_split_fraction(1e-3).shape == ()
    assert float(even_split_fraction(1e-3)) == 0.5
    assert np.array_equal(mercurydpm_fraction([1e-3, 2e-3], 5e-3), [0.5, 0.5])
    assert float(mercurydpm_fraction(1e-3)) == 1.0        # the wall keeps nothing


def test_shi_mccarthy_share_is_the_published_formula():
    """V_i,b / V_i = (1 - sqrt(1 - R_j^2/(R_i + R_j)^2))/2 (Shi & McCarthy 2008); equal
    spheres: (1 - sqrt(3)/2)/2, the LIGGGHTS value; the stable form holds at R_j << R_i."""
    for ri, rj in ((1.0, 1.0), (1.0, 10.0), (10.0, 1.0), (3.0, 0.7)):
        direct = 0.5 * (1.0 - math.sqrt(1.0 - rj**2 / (ri + rj) ** 2))
        assert float(shi_mccarthy_share(ri, rj)) == pytest.approx(direct, rel=1e-14)
    assert float(shi_mccarthy_share(1.0, 1.0)) == pytest.approx(0.5 * (1 - math.sqrt(3) / 2),
                                                               rel=1e-15)
    assert float(shi_mccarthy_share(1.0, 1e-9)) == pytest.approx(0.25e-18, rel=1e-8)
    assert float(shi_mccarthy_share(1.0, math.inf)) == 0.5


def test_shi_mccarthy_fraction_symmetry_and_limits():
    r2 = np.array([1.0, 2.0, 10.0])
    f = shi_mccarthy_fraction(1.0, r2)
    assert f[0] == 0.5
    assert np.allclose(f + shi_mccarthy_fraction(r2, 1.0), 1.0, rtol=0, atol=1e-15)
    # a very unequal pair tends to the wall's 2/3 on the small sphere (equal film thickness),
    # slowly: c_12 = 1/2 - sqrt(2 R1/R2)/2 + ..., so f = 2/3 - (2/9) sqrt(2 R1/R2) + ...
    for big in (1e6, 1e8):
        f_big = float(shi_mccarthy_fraction(1.0, big))
        assert 2.0 / 3.0 - f_big == pytest.approx(2.0 / 9.0 * math.sqrt(2.0 / big), rel=1e-2)
    assert float(shi_mccarthy_fraction(1.0)) == pytest.approx(2.0 / 3.0, rel=1e-15)
    # given liquids: each body's share of its own liquid
    got = float(shi_mccarthy_fraction(1.0, 2.0, liquid1=3.0, liquid2=1.0))
    b1, b2 = 3.0 * shi_mccarthy_share(1.0, 2.0), 1.0 * shi_mccarthy_share(2.0, 1.0)
    assert got == pytest.approx(float(b1 / (b1 + b2)), rel=1e-15)


def test_rules_refuse_bad_input():
    with pytest.raises(InputError, match="radius1"):
        even_split_fraction(-1.0)
    with pytest.raises(InputError, match="radius2"):
        mercurydpm_fraction(1.0, float("nan"))
    with pytest.raises(InputError, match="liquid1 and liquid2"):
        shi_mccarthy_fraction(1.0, 2.0, liquid1=1.0)
    with pytest.raises(InputError, match="liquid1 and liquid2"):
        shi_mccarthy_fraction(1.0, None, liquid1=1.0, liquid2=1.0)
    with pytest.raises(InputError, match="radius_j"):
        shi_mccarthy_share(1.0, 0.0)
