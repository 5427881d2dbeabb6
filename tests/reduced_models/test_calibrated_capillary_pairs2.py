"""``calibrated-capillary`` between two spheres with their own contact angles (the
``sphere-sphere-two-angles`` table) against ``meniscus``, at its joins and its ridge.

To check a candidate table before shipping it, run this module with a conftest whose
``pytest_configure`` patches ``calibrated_capillary.capillary_table``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_calibrated_capillary import _errors_against_meniscus  # fresh meniscus errors

from wetcontact.generate.bounds import MARGIN
from wetcontact.generate.calibrated_capillary_pairs import (
    PAIR_RIDGE_BRACKET_DEG,
    pair_ridge,
    pair_rupture,
)
from wetcontact.models import get_model
from wetcontact.reduced_models import calibrated_capillary as cc
from wetcontact.scene import Scene, scene_from_dict

R = 1.0e-3
GOAL_FORCE, GOAL_RUPTURE = 1e-3, 5e-4  # issue 11
PAIR = cc.PAIR_TWO_ANGLES


def _lead(ratio: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
    return [cc.ratio_coordinate(np.asarray(ratio, float)),
            cc.volume_coordinate(np.asarray(v, float))]


def _pair_points(n: int, seed: int, near_ridge: float | None = None,
                 log_from: float | None = None, ratio_max: float = 10.0,
                 theta1: tuple[float, float] = (0.0, 70.0)
                 ) -> list[tuple[float, float, float, float, float]]:
    """Seeded (ratio, v, theta1, theta2, S/S_c): the small sphere's angle theta1, the large
    one's theta2 uniform, or within ``near_ridge`` deg of the table's ridge (uniformly, or
    at a distance log-uniform from ``log_from`` up, either side)."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        ratio = float(np.exp(rng.uniform(0.0, math.log(ratio_max))))
        v = float(np.exp(rng.uniform(math.log(1e-4), math.log(0.1))))
        t1, t2 = float(rng.uniform(*theta1)), float(rng.uniform(0.0, 70.0))
        if near_ridge is not None:
            d = (float(rng.choice([-1.0, 1.0]) * np.exp(rng.uniform(math.log(log_from),
                                                                    math.log(near_ridge))))
                 if log_from is not None else float(rng.uniform(-near_ridge, near_ridge)))
            t2 = float(cc.ridge_deg(v, t1, ratio=ratio)) + d
            if not 0.0 <= t2 <= 70.0:
                continue
        out.append((ratio, v, t1, t2, float(rng.uniform(0.0, 0.99))))
    return out


def _scene(ratio: float, v: float, t1: float, t2: float, swap: bool = False) -> Scene:
    """Sphere 1 of radius R with angle theta1 and sphere 2 of radius ratio R with theta2
    (``swap``: the large sphere is sphere 1); bridge volume v R^3."""
    (r1, a1), (r2, a2) = ((R, t1), (R * ratio, t2))[::-1 if swap else 1]
    return scene_from_dict({
        "name": "pairs2", "geometry": {"kind": "sphere-sphere", "radius": r1, "radius2": r2},
        "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
                   "contact_angle_sphere": a1, "contact_angle_sphere2": a2},
        "amount": {"bridge_volume": v * R**3},
        "motion": {"velocity": 0.1, "gaps": [R * 1e-3]}})


def test_two_angle_pairs_against_meniscus() -> None:
    """Two spheres with their own angles: uniformly (radius ratio 1-10, both angles
    0-70 deg, the large sphere first at one bridge), within 2 deg of the rupture distance's
    ridge, at its top (log-uniform in the distance, within ``cc.RIDGE_TOP_ZONE_DEG``) and
    nearly equal spheres near the ridge (ratio < 1.1, theta1 20-45 deg, where both sides of
    the top are a cusp's). Fresh ``meniscus`` references (other seeds than the held-out
    tables'): the goals hold in every zone, the true S_c lies in the closure's rupture
    window, and near the ridge the closure's ``bound_floor`` is above both errors."""
    model = get_model("calibrated-capillary")
    top = cc.capillary_table()[PAIR]["held_out_ridge_top"]
    zones: dict[str, list[tuple[float, float, float]]] = {"far": [], "near": [], "top": []}
    points = (_pair_points(5, 91) + _pair_points(4, 92, near_ridge=2.0)
              + _pair_points(4, 93, near_ridge=cc.RIDGE_TOP_ZONE_DEG, log_from=1e-3)
              + _pair_points(3, 94, near_ridge=2.0, ratio_max=1.1, theta1=(20.0, 45.0)))
    for i, (ratio, v, t1, t2, x) in enumerate(points):
        scene = _scene(ratio, v, t1, t2, swap=i == 0)
        dist = abs(t2 - float(cc.ridge_deg(v, t1, ratio=ratio)))
        zone = ("far" if dist > cc.RIDGE_ZONE_DEG else
                "near" if dist > cc.RIDGE_TOP_ZONE_DEG else "top")
        window = cc.NEAR_RIDGE_MARGIN * max(ho["rupture_distance"]["max"]
                                            for ho in sum(model.held_out_tables(scene), []))
        e_r, e_f = _errors_against_meniscus(model, scene, v, x)
        assert e_r < window, (ratio, v, t1, t2, e_r, window)
        zones[zone].append((e_r, e_f, float(model.bound_floor(scene)[0])))
    assert sum(len(z) for z in zones.values()) == 16 and zones["top"], zones
    for e_r, e_f, _ in sum(zones.values(), []):
        assert e_r < GOAL_RUPTURE and e_f < GOAL_FORCE, zones
    for e_r, e_f, floor in zones["near"] + zones["top"]:
        assert 0 < floor and e_r < floor and e_f < floor, zones
    assert max(z[0] for z in zones["top"]) < MARGIN * top["rupture_distance"]["max"]


def test_low_angle_stratum_is_within_the_goals() -> None:
    """Both angles 0-15 deg at V* 0.01-0.1, at gaps to 0.999 S_c (the held-out stratum
    ``held_out_low_angles``, seeded, against meniscus): where band 0's piece below the
    ridge oscillated in the radius ratio with 9 nodes (this stratum: S_c 8.0e-5, the force
    1.43e-3, over the goal; with 13 nodes 3.5e-5 / 7.8e-4)."""
    from wetcontact.generate.calibrated_capillary import CORNER_FRACTIONS
    from wetcontact.generate.calibrated_capillary_pairs import LOW_ANGLES_DEG, LOW_ANGLES_V

    ho = cc.capillary_table()[PAIR]["held_out_low_angles"]
    assert ho["design"]["s_over_sc"] == list(CORNER_FRACTIONS)
    assert ho["stratum"] == {"theta_sphere_deg": list(LOW_ANGLES_DEG),
                             "theta2_deg": list(LOW_ANGLES_DEG), "v": list(LOW_ANGLES_V)}
    assert ho["bridges"] == 60 and ho["force"]["points"] == 300
    assert ho["rupture_distance"]["max"] <= GOAL_RUPTURE
    assert ho["force"]["max"] <= GOAL_FORCE, ho["force"]["max_at"]


def test_either_sphere_may_be_the_small_one() -> None:
    """The same bridge with its spheres given in either order: the same force and rupture
    distance (the table's theta1 is the smaller sphere's angle)."""
    model = get_model("calibrated-capillary")
    for ratio, v, t1, t2, _ in _pair_points(4, 95):
        a, b = (model.force(_scene(ratio, v, t1, t2, swap=s), gaps=[R * 1e-3])
                for s in (False, True))
        np.testing.assert_allclose(b.force_capillary, a.force_capillary, rtol=1e-13)
        np.testing.assert_allclose(b.extras["rupture_distance"],
                                   a.extras["rupture_distance"], rtol=1e-13)


def test_pair_bands_join_at_their_breaks() -> None:
    """The bands in the small sphere's angle (the lowest ends at the onset angle, a series
    in (w, a), the next at 35 deg): a point at a break belongs to the lower band, the bands
    are contiguous, and 1e-9 deg either side of each break the ridge agrees to the two
    bands' search tolerances (each band searched its own nodes there, the lowest to 1e-4
    deg, the others to 1e-5), S_c and the force to within the goals (the bands' nodes on
    the break differ in the large sphere's angle, mapped from each band's ridge). At the
    onset the band above has 17 w nodes in its ridge and the band below 9, whose series is
    off between them by up to 1.4e-3 deg there (as the band above's was with 9,
    docs/notes/sphere_pair_two_angles.md): the ridges agree to that plus the tolerances
    (2e-3 deg, the ridge window below 35 deg), where the top is smooth or its jump below
    1e-6 of S_c, which the S_c and force checks bound."""
    from wetcontact.generate.calibrated_capillary_pairs import PAIR_RIDGE_TOL_DEG

    e = cc.capillary_table()[PAIR]
    ends = [h["theta_sphere_deg"] for h in e["bands"]]
    assert ends[0][0] == cc.THETA_RANGE_DEG[0] and ends[-1][1] == cc.THETA_RANGE_DEG[1]
    assert all(a[1] == b[0] for a, b in zip(ends, ends[1:], strict=False))
    rng = np.random.default_rng(36)
    n = 60
    ratio = np.exp(rng.uniform(0.0, math.log(10.0), n))
    v = np.exp(rng.uniform(*np.log(cc.V_RANGE), n))
    lead = _lead(ratio, v)
    t2 = np.radians(rng.uniform(*cc.THETA_RANGE_DEG, n))
    for k, (_, cut) in enumerate(ends[:-1]):
        cut_deg = cc.onset_deg(e, lead) if cut is None else np.full(n, cut)
        np.testing.assert_array_equal(cc.band_index(e, cut_deg, lead), k)
        np.testing.assert_array_equal(cc.band_index(e, cut_deg + 1e-9, lead), k + 1)
        sides = np.radians([cut_deg - 1e-9, cut_deg + 1e-9])
        ridge = [cc.ridge_deg(v, np.degrees(t), ratio=ratio) for t in sides]
        interp = cc.RIDGE_WINDOW_DEG[PAIR] if cut is None else 0.0  # 9 against 17 w nodes
        np.testing.assert_allclose(ridge[1], ridge[0], rtol=0,
                                   atol=PAIR_RIDGE_TOL_DEG[k] + PAIR_RIDGE_TOL_DEG[k + 1]
                                   + interp)
        gap = 0.3 * cc.rupture_star(PAIR, v, sides[0], ratio, theta_wall=t2)
        (f0, s_c0), (f1, s_c1) = (cc.force_star(PAIR, v, t, gap, ratio, theta_wall=t2)
                                  for t in sides)
        np.testing.assert_allclose(s_c1, s_c0, rtol=GOAL_RUPTURE)
        np.testing.assert_allclose(f1, f0, rtol=GOAL_FORCE)


def test_pair_table_joins_the_one_angle_table() -> None:
    """Two angles that approach each other: the two-angle pair table tends to the
    one-angle table (each interpolates ``meniscus`` to about 1e-4), away from the
    one-angle table's split angle (about 30 deg), where the pieces of both meet."""
    rng = np.random.default_rng(37)
    n = 400
    ratio = np.exp(rng.uniform(0.0, math.log(10.0), n))
    v = np.exp(rng.uniform(*np.log(cc.V_RANGE), n))
    th = np.radians(rng.uniform(0.0, 70.0, n))
    gap = rng.uniform(0.0, 0.95, n) * cc.rupture_star("sphere-sphere", v, th, ratio)
    one = cc.force_star("sphere-sphere", v, th, gap, ratio)
    two = cc.force_star(PAIR, v, th, gap, ratio, theta_wall=th + 1e-8)
    np.testing.assert_allclose(two[1], one[1], rtol=GOAL_RUPTURE)
    np.testing.assert_allclose(two[0], one[0], rtol=GOAL_FORCE)


@pytest.mark.slow
@pytest.mark.parametrize(("ratio", "v", "theta1"), [(2.89, 0.1, 21.88), (1.627, 0.1, 34.8),
                                                    (2.89, 0.1, 35.67)])
def test_pair_ridge_between_its_ratio_nodes_is_near_the_true_top(ratio, v, theta1) -> None:
    """Above the onset, between the ridge series' w nodes at V* = 0.1, where the series with
    9 of them was off by 1.37e-3, 6.1e-4 and 5.6e-4 deg (the jump there 6e-7, 1.1e-4 and
    3.7e-4 of S_c): the true top (a golden-section search within 0.01 deg of the series, to
    1e-6 deg) lies within 4e-5 deg of the series with 17 (three times the largest offset
    measured between them, 1.3e-5 deg), and within the table's ridge window there."""
    ridge = float(cc.ridge_deg(v, theta1, ratio=ratio))
    top, bracket = pair_ridge(ratio, v, theta1, bracket=(ridge - theta1 - 0.01,
                                                         ridge - theta1 + 0.01), tol=1e-6)
    assert bracket <= 1e-6
    assert abs(ridge - top) <= 4e-5, (ridge, top)
    assert abs(ridge - top) <= cc.ridge_window_deg(PAIR, theta1)


def test_pair_ridge_window_is_narrower_in_the_top_band() -> None:
    """Between spheres the ridge window is 4e-5 deg above a small-sphere angle of 35 deg
    (the top band's series is within 9.6e-6 deg of the true top) and 2e-3 deg below it
    (within 5e-4 between the a nodes near the onset); a scene 1e-4 deg from the series is
    in it at 34.9 deg and not at 35.1 deg; on a wall it is 5e-5 deg at every angle."""
    assert cc.ridge_window_deg(PAIR, 35.1) == 4e-5
    assert cc.ridge_window_deg(PAIR, 34.9) == cc.ridge_window_deg(PAIR, 35.0) == 2e-3
    assert cc.ridge_window_deg(cc.WALL_TWO_ANGLES, 50.0) == 5e-5
    model = get_model("calibrated-capillary")
    for t1, inside in ((34.9, True), (35.1, False)):
        t2 = float(cc.ridge_deg(0.05, t1, ratio=3.0)) + 1e-4
        scene = _scene(3.0, 0.05, t1, t2)
        assert model.ridge_distance(scene) == pytest.approx(1e-4, abs=1e-9)
        assert model.in_ridge_window(scene) is inside


def test_pair_ridge_is_where_the_rupture_distance_peaks() -> None:
    """Between the ridge's nodes, the series agrees with a fresh search for the maximum of
    S_c over the large sphere's angle (to its interpolation error, a few 1e-3 deg), and S_c
    falls on both sides of it."""
    for ratio, v, t1 in ((2.7, 4.2e-4, 12.3), (1.6, 0.031, 51.7)):
        ridge = float(cc.ridge_deg(v, t1, ratio=ratio))
        top, bracket = pair_ridge(ratio, v, t1, bracket=PAIR_RIDGE_BRACKET_DEG, tol=1e-5)
        assert bracket < 2e-5
        assert ridge == pytest.approx(top, abs=0.01)
        s_top = pair_rupture(ratio, v, t1, ridge)
        assert pair_rupture(ratio, v, t1, ridge - 0.3) < s_top
        assert pair_rupture(ratio, v, t1, ridge + 0.3) < s_top
