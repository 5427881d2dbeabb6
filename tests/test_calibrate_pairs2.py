"""The ridge search and top-kind test for sphere pairs with two contact angles
(:mod:`wetcontact.calibrate_pairs2`): on functions whose top and kind are known in closed
form, and on ``meniscus`` bridges where symmetry or a dense scan says where the top is."""

import math

import numpy as np
import pytest

from wetcontact import calibrate_capillary as gen
from wetcontact import calibrate_pairs2 as p2

TOP = 33.3


def _smooth(x: float) -> float:
    return 1.0 - 1e-3 * (x - TOP) ** 2


def _cusp(x: float) -> float:
    return 1.0 - 0.02 * abs(x - TOP) ** (2.0 / 3.0)


def _jump(x: float) -> float:
    """A finite slope up to the top, then 1e-3 lower, falling as a fold's square root."""
    return 1.0 + 0.05 * (x - TOP) if x <= TOP else 0.999 - 0.03 * math.sqrt(x - TOP)


@pytest.mark.parametrize(("f", "kind", "jump"),
                         [(_smooth, "smooth", 0.0), (_cusp, "cusp", None),
                          (_jump, "jump", 1e-3)])
def test_top_kinds_of_known_functions(f, kind: str, jump: float | None) -> None:
    """golden_top finds the top of each to its tolerance, and top_shape names its kind
    from the left slope's growth (p = -1, 1/3, 0) and, for the jump, extrapolates the
    drop (the left side is linear, the right a square root: exact at the true top; the
    bracket's ends sit up to 1e-6 deg past it, which moves the square root's
    extrapolation by up to 0.03 (2 sqrt(h + 1e-6) - sqrt(4 h + 1e-6)) = 3.5e-6 at
    h = 1e-5, 0.35 % of this jump)."""
    top, width = gen.golden_top(f, 0.0, 60.0, "a test", "angle")
    assert width <= gen.RIDGE_TOL_DEG
    assert top == pytest.approx(TOP, abs=gen.RIDGE_TOL_DEG)
    s = p2.top_shape(f, top, width)
    assert s.kind == kind, s
    expected_p = {"smooth": -1.0, "jump": 0.0, "cusp": 1.0 / 3.0}[kind]
    assert s.exponent == pytest.approx(expected_p, abs=0.05), s
    if jump is not None:
        assert s.jump == pytest.approx(jump, rel=1e-2, abs=1e-9), s


def test_a_top_at_the_bracket_end_is_refused() -> None:
    """A maximum at the bracket's end is not a ridge: the search says so."""
    with pytest.raises(RuntimeError, match="not inside the bracket"):
        gen.golden_top(_smooth, 40.0, 60.0, "a test", "angle")


def test_equal_spheres_top_is_a_cusp_at_equal_angles() -> None:
    """Equal spheres, v = 0.01, theta1 = 50 deg (above the fold/bifurcation angle, about 31
    deg): the top over theta2 is at theta2 = theta1 (where the symmetric bridge's branch
    ends at a bifurcation), a cusp: S_c 0.5 and 1 deg below it is lower by amounts in the
    ratio 2^(2/3) of |delta|^(2/3) (within 10 %), and the same bridge with the spheres'
    angles swapped has the same S_c (the symmetry, independent of the search)."""
    top, width = p2.pair_ridge(1.0, 0.01, 50.0)
    assert top == pytest.approx(50.0, abs=1e-5)
    s = p2.top_shape(lambda x: p2.pair_rupture(1.0, 0.01, 50.0, x), top, width)
    assert s.kind == "cusp" and abs(s.jump) < 1e-4, s
    d = [s.s_top - p2.pair_rupture(1.0, 0.01, 50.0, 50.0 - x) for x in (0.5, 1.0)]
    assert d[1] / d[0] == pytest.approx(2.0 ** (2.0 / 3.0), rel=0.1), d
    assert p2.pair_rupture(1.0, 0.01, 50.0, 49.0) == pytest.approx(
        p2.pair_rupture(1.0, 0.01, 49.0, 50.0), rel=1e-9)


@pytest.mark.slow
def test_unequal_spheres_top_is_a_jump_where_a_dense_scan_peaks() -> None:
    """r = 2, v = 0.01, theta1 = 50 deg: a dense scan of S_c over theta2 (41 points,
    0.01 deg apart around the search's top) peaks at the scan point just short of the
    top, the top is a jump (S_c drops across it by more than 1e-5 of itself, and rises to
    it at a finite slope)."""
    top, width = p2.pair_ridge(2.0, 0.01, 50.0)
    assert width < 1e-5
    grid = top + 0.01 * np.arange(-20, 21) - 0.005
    s = np.array([p2.pair_rupture(2.0, 0.01, 50.0, float(x)) for x in grid])
    assert int(np.argmax(s)) == 20, (grid[np.argmax(s)], top)  # top - 0.005, just short of it
    shape = p2.top_shape(lambda x: p2.pair_rupture(2.0, 0.01, 50.0, x), top, width)
    assert shape.kind == "jump" and shape.jump > 1e-5, shape


@pytest.mark.slow
def test_equal_spheres_onset_is_the_fold_bifurcation_split() -> None:
    """Between equal spheres the top over theta2 stops being smooth where the equal-angle
    bridge's end changes from a fold to a bifurcation: the one-angle table's split angle
    theta_s(V) (located by a bisection on the branch's end, not on the top's shape), 30.0
    deg at v = 0.01; the onset bisection lands within its own tolerance (1 deg here) of it."""
    from wetcontact.reduced_models import calibrated_capillary as cc

    v = 0.01
    split = float(cc.theta_split_deg(cc.capillary_table()["sphere-sphere"],
                                     cc.volume_coordinate(np.array([v])))[0])
    onset = p2.pair_onset(1.0, v, 29.0, 31.0, tol=1.0)
    assert onset == pytest.approx(split, abs=0.5 + 0.01), (onset, split)
