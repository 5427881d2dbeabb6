"""The ridge search and top-kind test for sphere pairs with two contact angles
(:mod:`wetcontact.generate.calibrated_capillary_pairs`): on functions whose top and kind are
known in closed form, and on ``meniscus`` bridges where symmetry or a dense scan says where
the top is."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import synthetic_onset as _onset
from conftest import synthetic_pair_table
from conftest import synthetic_q as _q
from conftest import synthetic_ridge as _ridge
from conftest import synthetic_rupture as _rupture

from wetcontact.errors import InputError
from wetcontact.generate import calibrated_capillary as gen
from wetcontact.generate import calibrated_capillary_pairs as p2
from wetcontact.reduced_models import calibrated_capillary as cc

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


# ---- the table's pipeline on a synthetic bridge: onset, ridge and pieces exact ----------


@pytest.fixture
def synthetic_table(tmp_path):
    """The coarse stage of :func:`fit_pair_table` on the synthetic bridge of
    :func:`conftest.synthetic_pair_table` (its onset, ridge, S_c and force interpolated
    exactly by the coarse nodes)."""
    return synthetic_pair_table(tmp_path)


def test_pair_table_interpolates_a_synthetic_bridge_exactly(synthetic_table) -> None:
    """The generator's grids (band ends from the onset's nodes, b2 from the ridge's) and
    the model's coordinates (the onset and ridge series, the quadratic map toward the
    ridge) agree: at seeded points in every band and both pieces the table returns the
    synthetic S_c, ridge and force to rounding."""
    from wetcontact.reduced_models import calibrated_capillary as cc

    entry = cc.as_arrays({"e": synthetic_table})["e"]
    assert [b["theta_sphere_deg"] for b in entry["bands"]] == [[0.0, None], [None, 35.0],
                                                              [35.0, 70.0]]
    rng = np.random.default_rng(5)
    n = 400
    r = np.exp(rng.uniform(0.0, math.log(10.0), n))
    v = np.exp(rng.uniform(math.log(1e-4), math.log(0.1), n))
    t1 = rng.uniform(0.0, 70.0, n)
    t2 = rng.uniform(0.0, 70.0, n)
    x = rng.uniform(-1.0, 1.0, n)
    ridge = np.array([_ridge(*p) for p in zip(r, v, t1, strict=True)])
    np.testing.assert_allclose(cc.ridge_deg(v, t1, entry, r), ridge, rtol=0, atol=1e-10)
    sc = np.array([_rupture(*p) for p in zip(r, v, t1, t2, strict=True)])
    rho = r / (1.0 + r)
    s = np.array([cc.gap_from_coordinate(xx, s_c, math.sqrt(vv / (math.pi * rr)))
                  for xx, s_c, vv, rr in zip(x, sc, v, rho, strict=True)])
    f, s_c = cc.force_star(cc.PAIR_TWO_ANGLES, v, np.radians(t1), s, r, entry=entry,
                           theta_wall=np.radians(t2), precision="double")
    np.testing.assert_allclose(s_c, sc, rtol=1e-11)
    q = np.array([_q(rr, tt, np.array([xx]))[0] for rr, tt, xx in zip(r, t2, x, strict=True)])
    want = rho * q * (np.cos(np.radians(t1)) + np.cos(np.radians(t2)))
    np.testing.assert_allclose(f, want, rtol=1e-9)
    # the default sums the force's train in single precision: S_c as in double, the force
    # rounded only, far inside the 1e-3 force goal (the shipped table's: module notes)
    f32, s_c32 = cc.force_star(cc.PAIR_TWO_ANGLES, v, np.radians(t1), s, r, entry=entry,
                               theta_wall=np.radians(t2))
    np.testing.assert_array_equal(s_c32, s_c)
    np.testing.assert_allclose(f32, want, rtol=2e-5)
    assert np.max(np.abs(f32 / want - 1.0)) > 1e-9  # it is single precision
    which = cc.band_index(entry, t1, [cc.ratio_coordinate(r), cc.volume_coordinate(v)])
    assert set(which) == {0, 1, 2}  # every band was evaluated


def test_pair_table_onset_and_nested_stages(synthetic_table) -> None:
    """The onset's r = 1 row is the split angle, its other rows the bisection's; the
    coarse grid's nodes are every other (w, a, b1) and every third b2 node of the medium
    grid, the medium's every third upper b2 node of the full grid, bit for bit (what lets
    a stage reuse the cache of the ones before it); the full grid's 23 lower b2 nodes do
    not nest the medium's 15."""
    on = synthetic_table[gen.cc.ONSET_KEY]
    rs, vs = on["ratio_nodes"], on["v_nodes"]
    np.testing.assert_allclose(on["at_nodes_deg"],
                               [[_onset(r, v) for v in vs] for r in rs], atol=1e-12)
    assert list(p2.ratio_nodes(9)[::2]) == list(p2.ratio_nodes(5))
    assert list(gen._volume_nodes(9)[::2]) == list(gen._volume_nodes(5))
    assert list(gen.lobatto(9)[::2]) == list(gen.lobatto(5))
    assert list(p2.nested_gauss(15)[1::3]) == list(p2.nested_gauss(5))
    assert list(p2.nested_gauss(9)[1::3]) == list(p2.nested_gauss(3))
    assert list(p2.nested_gauss(27)[1::3]) == list(p2.nested_gauss(9))
    stages = list(p2.STAGES.values())  # every stage's nodes are the next's
    for coarse, fine in zip(stages[:-1], stages[1:], strict=True):
        for below, (m, n) in zip((True, False), zip(coarse["b2"], fine["b2"], strict=True),
                                 strict=True):
            nested = set(p2.nested_gauss(m)) <= set(p2.nested_gauss(n))
            # but the full stage's 23 below the ridge (refined past nesting, 2026-11-27)
            assert nested != (below and fine is p2.STAGES["full"])
        for axis, nodes in (("w", p2.ratio_nodes), ("a", gen._volume_nodes),
                            ("b1", gen.lobatto)):
            assert set(nodes(coarse[axis])) <= set(nodes(fine[axis]))
    np.testing.assert_allclose(p2.nested_gauss(7), gen.gauss(7), atol=1e-15)


def test_model_takes_the_small_spheres_angle_first(synthetic_table, monkeypatch) -> None:
    """``calibrated-capillary`` on two spheres with two angles evaluates the two-angle
    table with theta1 the smaller sphere's angle, whichever of the scene's spheres it is
    (the synthetic S_c is not symmetric in the angles, so a swap would show)."""
    from wetcontact.models import get_model
    from wetcontact.reduced_models import calibrated_capillary as cc
    from wetcontact.scene import Scene

    table = {**cc.capillary_table(),
             cc.PAIR_TWO_ANGLES: cc.as_arrays({"e": synthetic_table})["e"]}
    monkeypatch.setattr(cc.shipped, "capillary_table", lambda: table)
    model = get_model("calibrated-capillary")
    rs, ratio, v = 1e-3, 3.0, 2e-3

    def scene(r1: float, r2: float, th1: float, th2: float) -> Scene:
        return Scene(name="two-angle pair", kind="sphere-sphere", amount="bridge",
                     radius=r1, radius2=r2, bridge_volume=v * rs**3, viscosity=1e-3,
                     surface_tension=0.07, density=1000.0, velocity=0.0, gaps=(1e-7,),
                     contact_angle_sphere=math.radians(th1),
                     contact_angle_wall=math.radians(th2))

    want = _rupture(ratio, v, 20.0, 40.0) * rs
    for sc in (scene(rs, ratio * rs, 20.0, 40.0), scene(ratio * rs, rs, 40.0, 20.0)):
        model.check(sc)
        assert model.rupture_distance(sc) == pytest.approx(want, rel=1e-11, abs=0)


def test_pair_held_out_strata_draw_where_they_say(synthetic_table) -> None:
    """The held-out design of the two-angle pair table: ratios in [1, 10] (nearly equal
    spheres: [1, 1.1], theta1 in 20-45 deg), the large sphere's angle within 3 deg of the
    table's ridge or at a log-uniform distance in the band, theta1 in the onset stratum's
    range; every draw inside the domain."""
    from wetcontact.reduced_models import calibrated_capillary as cc

    entry = cc.as_arrays({"e": synthetic_table})["e"]
    for key, st in p2.PAIR_STRATA.items():
        design = gen.held_out_design(cc.PAIR_TWO_ANGLES, 60, 4, st["seed"],
                                     st.get("near_equal", False),
                                     entry if st.get("near_ridge") or "ridge_band" in st
                                     else None, st.get("ridge_band"), st.get("theta_range"),
                                     st.get("theta2_range"), st.get("v_range"),
                                     st.get("fractions"))
        r = np.array([d["ratio"] for d in design])
        t1 = np.array([d["theta_deg"] for d in design])
        t2 = np.array([d["theta_wall_deg"] for d in design])
        v = np.array([d["v"] for d in design])
        assert r.min() >= 1.0 and r.max() <= (1.1 if st.get("near_equal") else 10.0), key
        lo2, hi2 = st.get("stratum", {}).get("theta2_deg", (0.0, 70.0))
        assert t2.min() >= lo2 and t2.max() <= hi2, key
        lo, hi = st.get("stratum", {}).get("theta_sphere_deg", (0.0, 70.0))
        assert t1.min() >= lo and t1.max() <= hi, key
        lo_v, hi_v = st.get("stratum", {}).get("v", (1e-4, 0.1))
        assert v.min() >= lo_v and v.max() <= hi_v, key
        fr = [d["fractions"] for d in design]
        if "fractions" in st:  # the corner stratum's gaps, to 0.999 S_c, on every bridge
            assert all(f == list(gen.CORNER_FRACTIONS) for f in fr), key
        else:
            assert len({tuple(f) for f in fr}) == len(fr) and len(fr[0]) == 4, key
        d = np.abs(t2 - cc.ridge_deg([x["v"] for x in design], t1, entry, r))
        if "ridge_band" in st:
            assert d.min() >= st["ridge_band"][0] * (1 - 1e-9), key
            assert d.max() <= st["ridge_band"][1] * (1 + 1e-9), key
        elif st.get("near_ridge"):
            assert d.max() <= gen.NEAR_RIDGE_DEG, key
        else:
            assert d.max() > gen.NEAR_RIDGE_DEG, key  # uniform: not only near the ridge


def test_a_piece_with_other_ratio_nodes_than_its_ridge_interpolates_exactly(
        synthetic_table, tmp_path, monkeypatch) -> None:
    """A piece fitted at more ratio nodes than its band's onset and ridge series (band 0's
    lower piece at 9 against the coarse stage's 5) takes its small sphere's angles and its
    ridge from those series at its own nodes (:func:`lead_grid`), as the model maps a
    point: the table still returns the synthetic S_c and force to rounding there; at the
    series' own node count :func:`lead_grid` gives the ridge's node values."""
    entry = synthetic_table
    band = entry["bands"][0]
    ridge, onset = band["theta_split"], entry[cc.ONSET_KEY]
    rs, vs, t1, top = p2.lead_grid(onset, ridge, tuple(band["theta_sphere_deg"]), 5)
    np.testing.assert_allclose(t1, ridge["theta_small_nodes_deg"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(top, ridge["at_nodes_deg"], rtol=0, atol=1e-12)
    assert list(rs) == list(onset["ratio_nodes"])

    def fake_branch(kind, ratio, v, theta, c_nodes, theta2=None):
        t1_, t2_ = math.degrees(theta), math.degrees(theta2)
        return _rupture(ratio, v, t1_, t2_), _q(ratio, t2_, np.asarray(c_nodes))

    monkeypatch.setattr(gen, "solve_branch", fake_branch)
    nb2 = band["pieces"][0]["nodes"][3]
    with pytest.raises(ValueError, match="band_deg"):
        p2.fit_pair_piece(p2.PAIR_PIECES[0], nb2, onset, ridge, 1, tmp_path, nw=9)
    piece = p2.fit_pair_piece(p2.PAIR_PIECES[0], nb2, onset, ridge, 1, tmp_path, nw=9,
                              band_deg=tuple(band["theta_sphere_deg"]))
    assert piece["nodes"][0] == 9 and band["pieces"][1]["nodes"][0] == 5
    bands = [{**band, "pieces": [piece, band["pieces"][1]]}, *entry["bands"][1:]]
    table = cc.as_arrays({"e": {**entry, "bands": bands}})["e"]
    rng = np.random.default_rng(11)
    n = 200
    r = np.exp(rng.uniform(0.0, math.log(10.0), n))
    v = np.exp(rng.uniform(math.log(1e-4), math.log(0.1), n))
    t1p = rng.uniform(0.0, 1.0, n) * np.array([_onset(*p) for p in zip(r, v, strict=True)])
    t2 = rng.uniform(0.0, 1.0, n) * np.array([_ridge(*p) for p in zip(r, v, t1p,
                                                                      strict=True)])
    sc = np.array([_rupture(*p) for p in zip(r, v, t1p, t2, strict=True)])
    f, s_c = cc.force_star(cc.PAIR_TWO_ANGLES, v, np.radians(t1p), 0.5 * sc, r,
                           entry=table, theta_wall=np.radians(t2), precision="double")
    np.testing.assert_allclose(s_c, sc, rtol=1e-11)
    rho = r / (1.0 + r)
    c = np.array([cc.gap_coordinate(np.array([0.5 * s]), np.array([s]),
                                    np.array([math.sqrt(vv / (math.pi * rr))]))[0]
                  for s, vv, rr in zip(sc, v, rho, strict=True)])
    q = np.array([_q(rr, tt, np.array([cx]))[0] for rr, tt, cx in zip(r, t2, c, strict=True)])
    np.testing.assert_allclose(f, rho * q * (np.cos(np.radians(t1p)) + np.cos(np.radians(t2))),
                               rtol=1e-9)


def test_a_ridge_at_nested_ratio_nodes_keeps_the_coarse_nodes_and_the_pieces(
        synthetic_table, tmp_path, monkeypatch) -> None:
    """A band's ridge at more w nodes than the onset's (9 nesting the coarse stage's 5, as
    the shipped bands above the onset have 17 over 9): at the onset's nodes the coarse
    series' own values (bit for bit: no search there), at the others the synthetic ridge
    sought within RIDGE_NEAR_DEG of the coarse series (a top at that bracket's end sought
    again over the whole bracket); the series interpolates the synthetic ridge between all
    nodes; the pieces fitted with it at the onset's nodes are the ones fitted with the
    coarse ridge (the same bridges: their angles are the same floats); counts that do not
    nest are refused."""
    entry = synthetic_table
    band = entry["bands"][1]
    rng_deg = tuple(band["theta_sphere_deg"])
    coarse, onset = band["theta_split"], entry[cc.ONSET_KEY]
    nb1 = np.shape(coarse["at_nodes_deg"])[2]
    calls = []

    def fake_ridge(r, v, t1, bracket, tol):
        calls.append(bracket)
        lo, hi = t1 + bracket[0], t1 + bracket[1]
        top = _ridge(r, v, t1)
        if len(calls) == 1:  # as golden_top refuses a top near its bracket's ends
            raise RuntimeError("not inside the bracket")
        assert lo < top < hi
        return top, tol

    monkeypatch.setattr(p2, "pair_ridge", fake_ridge)
    with pytest.raises(ValueError, match="does not nest"):
        p2.fit_pair_ridge(onset, rng_deg, nb1, 1e-5, 1, tmp_path, 7, coarse)
    fine = p2.fit_pair_ridge(onset, rng_deg, nb1, 1e-5, 1, tmp_path, 9, coarse)
    at = np.asarray(fine["at_nodes_deg"])
    assert at.shape == (9, *np.shape(coarse["at_nodes_deg"])[1:])
    assert at[::2].tolist() == coarse["at_nodes_deg"]
    assert np.asarray(fine["theta_small_nodes_deg"])[::2].tolist() == \
        coarse["theta_small_nodes_deg"]
    na = len(onset["v_nodes"])
    assert len(calls) == 4 * na * nb1 + 1  # new nodes only, one of them twice
    assert calls[1] == p2.PAIR_RIDGE_BRACKET_DEG  # the refused one, over the whole bracket
    near = [b for b in calls if b != p2.PAIR_RIDGE_BRACKET_DEG]
    assert len(near) == 4 * na * nb1
    assert all(b[1] - b[0] == pytest.approx(2 * p2.RIDGE_NEAR_DEG) for b in near)
    rs, vs = p2.ratio_nodes(9), np.asarray(onset["v_nodes"])
    t1 = np.asarray(fine["theta_small_nodes_deg"])
    want = [[[_ridge(rs[i], vs[j], t1[i, j, k]) for k in range(nb1)] for j in range(na)]
            for i in range(9)]
    np.testing.assert_allclose(at, want, rtol=0, atol=1e-11)
    rng = np.random.default_rng(3)
    r = np.exp(rng.uniform(0.0, math.log(10.0), 50))
    v = np.exp(rng.uniform(math.log(1e-4), math.log(0.1), 50))
    on = np.array([_onset(*x) for x in zip(r, v, strict=True)])
    ts = on + rng.uniform(0.0, 1.0, 50) * (35.0 - on)
    table = cc.as_arrays({"e": {**entry, "bands": [
        entry["bands"][0], {**band, "theta_split": fine}, entry["bands"][2]]}})["e"]
    np.testing.assert_allclose(cc.ridge_deg(v, ts, table, r),
                               [_ridge(*x) for x in zip(r, v, ts, strict=True)],
                               rtol=0, atol=1e-10)

    def fake_branch(kind, ratio, v, theta, c_nodes, theta2=None):
        t1_, t2_ = math.degrees(theta), math.degrees(theta2)
        return _rupture(ratio, v, t1_, t2_), _q(ratio, t2_, np.asarray(c_nodes))

    monkeypatch.setattr(gen, "solve_branch", fake_branch)
    cached_map, seen = gen._cached_map, []
    monkeypatch.setattr(gen, "_cached_map",
                        lambda fn, js, *a: seen.extend(js) or cached_map(fn, js, *a))
    for spec, piece in zip(p2.PAIR_PIECES, band["pieces"], strict=True):
        nb2 = piece["nodes"][3]
        jobs = {}
        for name, ridge in (("coarse", coarse), ("fine", fine)):
            seen.clear()
            got = p2.fit_pair_piece(spec, nb2, onset, ridge, 1, tmp_path, 5, rng_deg)
            jobs[name] = (got, [(j[0], j[2], j[3], j[4], j[6]) for j in seen])
        assert jobs["fine"][1] == jobs["coarse"][1]
        assert jobs["fine"][0] == jobs["coarse"][0]


def test_pair_onset_job_widens_a_bracket_that_does_not_hold(monkeypatch) -> None:
    """The onset is first sought between the wall's onset - 1.5 and the split angle + 0.5
    deg (the shipped series at that volume); where that is not a bracket, over [8, 36]."""
    from wetcontact.reduced_models import calibrated_capillary as cc

    seen = []

    def fake(ratio, v, lo, hi, tol, ridge_tol):
        seen.append((lo, hi))
        if len(seen) == 1:
            raise RuntimeError("not bracketed")
        return 0.5 * (lo + hi)

    monkeypatch.setattr(p2, "pair_onset", fake)
    v = 0.01
    a = cc.volume_coordinate(np.array([v]))
    t_on = float(cc.onset_deg(cc.capillary_table()[cc.WALL_TWO_ANGLES], a)[0])
    t_s = float(p2.split_at(np.array([v]))[0])
    assert p2._pair_onset_job((3.0, v)) == 22.0
    assert seen == [(t_on - 1.5, t_s + 0.5), (8.0, 36.0)]
    assert t_on - 1.5 < t_s + 0.5  # the first bracket is not empty


# ---- tensor trains: the form the two-angle pair table is evaluated in ------------------


def test_tt_svd_reconstructs_and_bounds_its_truncation() -> None:
    """TT-SVD (Oseledets 2011, theorem 2.2): with tol 0 the train is the tensor to rounding;
    truncated, its Frobenius error is at most sqrt(d - 1) tol, and it keeps the ranks of a
    tensor of known TT ranks (a sum of 3 separable terms plus noise below tol)."""
    rng = np.random.default_rng(11)
    dense = rng.standard_normal((4, 5, 6, 3))
    full = gen.tt_svd(dense, 0.0)
    assert [g.shape[0] for g in full] == [1, 4, 18, 3]  # min(left, right) unfolding sizes
    np.testing.assert_allclose(_tt_dense(full), dense, rtol=0, atol=1e-12)
    terms = [np.einsum("i,j,k,l->ijkl", *(rng.standard_normal(n) for n in (9, 8, 7, 6)))
             for _ in range(3)]
    noise = 1e-7 * rng.standard_normal((9, 8, 7, 6))
    tol = 1e-4
    cores = gen.tt_svd(sum(terms) + noise, tol)
    assert [g.shape[2] for g in cores[:-1]] == [3, 3, 3]
    err = np.linalg.norm(_tt_dense(cores) - (sum(terms) + noise))
    assert err <= math.sqrt(3) * tol
    assert err >= np.linalg.norm(noise) / 10  # the noise is what was dropped


def test_tt_svd_caps_its_ranks_at_the_best_fixed_rank_truncation() -> None:
    """With ``max_ranks`` each unfolding keeps at most that many singular values: the ranks
    are the caps, and a tensor of TT ranks (3, 3, 3) capped at (3, 2, 3) loses what the
    best rank-2 approximation of its middle unfolding loses, at least (Eckart-Young:
    the 2-norm of the dropped singular values of that unfolding)."""
    rng = np.random.default_rng(13)
    terms = [np.einsum("i,j,k,l->ijkl", *(rng.standard_normal(n) for n in (9, 8, 7, 6)))
             for _ in range(3)]
    dense = sum(terms)
    cores = gen.tt_svd(dense, 1e-10, [3, 2, 3])
    assert [g.shape[2] for g in cores[:-1]] == [3, 2, 3]
    sv = np.linalg.svd(dense.reshape(9 * 8, -1), compute_uv=False)
    err = np.linalg.norm(_tt_dense(cores) - dense)
    assert err >= np.linalg.norm(sv[2:]) * (1 - 1e-9)
    assert err <= math.sqrt(3) * np.linalg.norm(sv[2:])
    uncapped = gen.tt_svd(dense, 1e-10, [50, 50, 50])  # caps above the ranks: no change
    assert [g.shape[2] for g in uncapped[:-1]] == [3, 3, 3]
    np.testing.assert_allclose(_tt_dense(uncapped), dense, rtol=0, atol=1e-12)


def _tt_dense(cores: list[np.ndarray]) -> np.ndarray:
    """A train's dense tensor, its cores in the table's own axis order."""
    from wetcontact.reduced_models.calibrated_capillary import train_dense

    return train_dense(cores, range(len(cores)))


def test_train_sum_is_the_dense_chebyshev_sum_in_any_axis_order() -> None:
    """train_sum over a train stored in a permuted axis order equals the dense tensor
    Chebyshev sum (chebyshev_tensor, an independent contraction) to rounding."""
    from wetcontact.reduced_models import calibrated_capillary as cc

    rng = np.random.default_rng(12)
    dense = rng.standard_normal((5, 4, 6, 3, 7)) / np.arange(1, 8)  # decaying along c
    train = gen.train_of(dense, 0.0)
    assert sorted(train["order"]) == [0, 1, 2, 3, 4]
    train = cc.as_arrays({"e": {"pieces": [{"force_train": train}]}})["e"]["pieces"][0][
        "force_train"]
    inner = [g.shape for g in train["cores"][1:]]  # both ways of taking a core occur
    assert any(r1 > r0 for r0, _, r1 in inner) and any(r1 <= r0 for r0, _, r1 in inner)
    n = 2 * cc.TRAIN_CHUNK + 37  # three batches, the last one short
    x = [rng.uniform(-1.0, 1.0, n) for _ in dense.shape]
    rows = [cc._cheb_rows(xi, n) for xi, n in zip(x, dense.shape, strict=True)]
    np.testing.assert_allclose(cc.train_sum(train, rows), cc.chebyshev_tensor(dense, x),
                               rtol=0, atol=1e-12)


@pytest.mark.parametrize(("kind", "share", "trains"), [
    ("sphere-wall-two-angles", 0.8, gen.WALL_TRAINS),
    ("sphere-sphere-two-angles", 0.5, ("rupture_train", "force_train"))])
def test_shipped_two_angle_pieces_are_trains_of_their_fit_within_their_tolerance(
        kind, share, trains) -> None:
    """Every piece of the shipped two-angle tables carries its trains (sphere pairs: both;
    a wall: the force's, its rupture table stays dense), each within sqrt(d - 1) tol
    (Frobenius) of the fit it was built from (its rupture table, the product of its force
    factors), at the declared TRAIN_TOL, and cheaper to evaluate than that fit: its force
    train at most ``share`` of the low-rank force's multiply-adds a point (measured:
    0.56-0.74 on the wall, 0.23-0.40 for pairs)."""
    from wetcontact.reduced_models import calibrated_capillary as cc

    table = cc.capillary_table()
    if table is None or kind not in table:
        pytest.skip(f"the package data has no {kind} table")
    for band in table[kind]["bands"]:
        for piece in band["pieces"]:
            left, right = piece["force_left"], piece["force_right"]
            fits = {"rupture_train": piece["rupture"],
                    "force_train": np.tensordot(left, right, axes=1)}
            assert [name for name in fits if name in piece] == list(trains)
            for name in trains:
                fit, train = fits[name], piece[name]
                assert train["tol"] == gen.TRAIN_TOL[name]
                dense = cc.train_dense(train["cores"], train["order"])
                assert dense.shape == fit.shape
                assert np.linalg.norm(dense - fit) <= math.sqrt(fit.ndim - 1) * train["tol"]
            cost = sum(g.size for g in piece["force_train"]["cores"])
            assert cost < share * left.shape[-1] * (left[..., 0].size + right[0].size)


def test_wall_retrain_keeps_the_fit_and_rebuilds_its_trains(tmp_path) -> None:
    """The two-angle wall table's retrain (``generate calibrated-capillary --kind
    sphere-wall-two-angles --retrain``) keeps the shipped fit as it is, builds each
    piece's force train from it again (the shipped one: the same dense tensor to rounding,
    the same ranks and axis order; no rupture train) and drops the held-out tables, which
    the caller measures again; a file without that table is refused by name."""
    from wetcontact.errors import InputError
    from wetcontact.reduced_models import calibrated_capillary as cc

    path = Path(cc.__file__).parents[1] / "data" / cc.CAPILLARY_FILE
    old = json.loads(path.read_text())
    if cc.WALL_TWO_ANGLES not in old:
        pytest.skip("the package data has no two-angle wall table")
    new = gen._retrained(path, old, cc.WALL_TWO_ANGLES)
    assert not any(k.startswith("held_out") for k in new)
    assert new[cc.ONSET_KEY] == old[cc.WALL_TWO_ANGLES][cc.ONSET_KEY]
    for band, was in zip(new["bands"], old[cc.WALL_TWO_ANGLES]["bands"], strict=True):
        assert band["theta_split"] == was["theta_split"]
        for piece, before in zip(band["pieces"], was["pieces"], strict=True):
            for name in ("rupture", "force_left", "force_right"):
                assert piece[name] == before[name]
            assert [n for n in cc.TRAIN_FIELDS if n in piece] == list(gen.WALL_TRAINS)
            for name in gen.WALL_TRAINS:
                a, b = piece[name], before[name]
                assert (a["order"], a["ranks"]) == (b["order"], b["ranks"])
                dense = [cc.train_dense([np.asarray(g) for g in t["cores"]], t["order"])
                         for t in (a, b)]
                np.testing.assert_allclose(*dense, rtol=0, atol=1e-12)
    with pytest.raises(InputError, match=r"x\.json: field 'sphere-wall-two-angles' missing"):
        gen._retrained(tmp_path / "x.json", {}, cc.WALL_TWO_ANGLES)


def test_capillary_generator_keeps_the_pair_table(tmp_path) -> None:
    """``generate calibrated-capillary`` (the other tables) rewrites the table file without solving
    what it was not asked for: the two-angle pair table, which calibrate_pairs2 writes,
    stays as it was (it was dropped before)."""
    from wetcontact.reduced_models import calibrated_capillary as cc

    src = Path(cc.__file__).parents[1] / "data" / cc.CAPILLARY_FILE
    old = json.loads(src.read_text())
    if cc.PAIR_TWO_ANGLES not in old:
        pytest.skip("the package data has no two-angle pair table")
    out = tmp_path / cc.CAPILLARY_FILE
    out.write_text(src.read_text())
    try:
        gen.generate_calibrated_capillary(out=out, kinds=())
    finally:
        cc.capillary_table.cache_clear()  # _write cleared it: the package's again
    new = json.loads(out.read_text())
    assert new[cc.PAIR_TWO_ANGLES] == old[cc.PAIR_TWO_ANGLES]
    assert all(new[k] == old[k] for k in gen.KINDS)


@pytest.mark.parametrize("kind", ["sphere-wall", "sphere-sphere"])
def test_one_angle_retrain_keeps_the_fit(tmp_path, kind) -> None:
    """A one-angle table's retrain (``generate calibrated-capillary --kind sphere-wall --retrain``,
    what a change of the closure's evaluation calls for) keeps the fit as the file holds it,
    with its fit time, and drops only the held-out tables, which the caller measures again;
    a file without the table is refused by name."""
    from wetcontact.errors import InputError
    from wetcontact.generate import __main__ as generate_cli
    from wetcontact.reduced_models import calibrated_capillary as cc

    assert generate_cli.PAIR_KIND == p2.PAIR_TWO_ANGLES  # the CLI's copy of the name
    path = Path(cc.__file__).parents[1] / "data" / cc.CAPILLARY_FILE
    old = json.loads(path.read_text())
    new = gen._retrained(path, old, kind)
    assert {k for k in old[kind] if k.startswith("held_out")}  # there were some to drop
    assert new == {k: v for k, v in old[kind].items() if not k.startswith("held_out")}
    assert "fit_time_s" in new
    with pytest.raises(InputError, match=rf"x\.json: field '{kind}' missing"):
        gen._retrained(tmp_path / "x.json", {}, kind)


@pytest.mark.parametrize("argv,message", [
    (["--kind", "sphere-wall", "--refine-band", "2"],
     "--refine-band: only with --kind sphere-wall-two-angles or --kind "
     "sphere-sphere-two-angles (given: --kind sphere-wall)"),
    (["--kind", "sphere-wall-two-angles", "--refine-band", "3"],
     "--refine-band = 3; allowed: distinct bands 0, 1 or 2"),
    (["--kind", "sphere-sphere-two-angles", "--refine-band", "2", "2"],
     "--refine-band = 2 2; allowed: distinct bands 0, 1 or 2"),
])
def test_refine_band_is_refused_outside_the_two_angle_tables(argv, message, capsys) -> None:
    from wetcontact.generate.__main__ import main as generate_main

    with pytest.raises(SystemExit) as exc:
        generate_main(["calibrated-capillary", *argv])
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_refine_band_names_the_file_and_field_of_a_table_it_cannot_refine(tmp_path) -> None:
    out = tmp_path / "cap.json"
    out.write_text(json.dumps({"sphere-wall": {}}))
    with pytest.raises(InputError, match=r"cap.json: field 'sphere-wall-two-angles' missing"):
        p2.refine_band(cc.WALL_TWO_ANGLES, 2, out)


def test_refine_band_refits_only_the_pieces_whose_nodes_changed(tmp_path, monkeypatch) -> None:
    """With the shipped node counts nothing is solved: the band's pieces, its ridge and
    every other band stay as the file holds them; only the held-out tables are measured
    again (stubbed here: they solve meniscus)."""
    src = Path(cc.__file__).parents[1] / "data" / cc.CAPILLARY_FILE
    out = tmp_path / "cap.json"
    out.write_text(src.read_text())
    old = json.loads(src.read_text())[cc.WALL_TWO_ANGLES]
    fitted = []
    monkeypatch.setattr(gen, "fit_piece", lambda *a, **k: fitted.append(a))
    monkeypatch.setattr(gen, "_wall_two_held_out", lambda *a, **k: {"held_out": {"stub": 1}})
    try:
        entry = p2.refine_band(cc.WALL_TWO_ANGLES, 2, out)
    finally:
        cc.capillary_table.cache_clear()
    assert fitted == []
    assert entry["bands"] == old["bands"]
    assert entry["held_out"] == {"stub": 1}
    assert entry["refine_band"]["2"]["branches"]["solved"] == 0
    assert set(entry["refine_band"]) == {"0", "1", "2"}  # the earlier bands' records kept
    held = []
    monkeypatch.setattr(gen, "_wall_two_held_out",
                        lambda *a, **k: held.append(1) or {"held_out": {"stub": 2}})
    try:
        entry = p2.refine_band(cc.WALL_TWO_ANGLES, [2, 0], out)
    finally:
        cc.capillary_table.cache_clear()
    assert fitted == [] and held == [1]  # two bands, the held-out tables measured once
    assert entry["bands"] == old["bands"] and entry["held_out"] == {"stub": 2}


def test_table_commands_name_a_missing_out_folder(tmp_path) -> None:
    from wetcontact.generate.__main__ import main as generate_main

    with pytest.raises(InputError, match=r"--out .*x.json: folder .*nowhere does not exist"):
        generate_main(["calibrated-capillary", "--kind", "sphere-wall-two-angles",
                       "--refine-band", "1", "--out", str(tmp_path / "nowhere" / "x.json")])
