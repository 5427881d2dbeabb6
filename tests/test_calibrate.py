"""Calibration core: parametrised forms, fit on a grid, held-out report, refitted models."""

from __future__ import annotations

import json
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from wetcontact import calibrate as cal
from wetcontact.calibrate import make_scene
from wetcontact.errors import InputError, ValidityError
from wetcontact.generate.__main__ import main as generate_main
from wetcontact.reduced_models import capillary as cap
from wetcontact.reduced_models import rupture as rup

ROOT = Path(__file__).resolve().parents[1]


def _bridge_inputs(theta: float = 0.4) -> dict[str, np.ndarray]:
    g = np.array([1e-7, 1e-6, 1e-5, 6e-5])
    return {"gap": g, "volume": np.full(4, 2e-12), "r_closure": np.full(4, 1e-3),
            "radius": np.full(4, 1e-3), "sigma": np.full(4, 0.072), "theta": np.full(4, theta)}


def test_published_coefficients_reproduce_the_package_closures() -> None:
    """With the published coefficients each family's form must give the package's closure
    to rounding.

    Independent: ``willett_form``, ``bagheri_form`` and ``lian_form`` are written in
    calibrate.py with their own coefficient arrays, so agreement checks them against
    capillary.py and rupture.py. Not independent: ``mikami_form`` calls
    ``capillary._mikami`` and the families' published sets are ``capillary._MIKAMI_PW`` and
    ``_MIKAMI_PP``, so the Mikami rows agree by construction and check only that each family
    carries its own geometry's set; Mikami's coefficients are checked against PHYSICS.md by
    tests/reduced_models/test_capillary.py::test_mikami_model_is_the_published_regression.
    """
    x = _bridge_inputs()
    g, v, r, sig, th = x["gap"], 2e-12, 1e-3, 0.072, 0.4
    pairs = [
        (cal.FAMILIES["willett"], cap.willett_force(g, v, r, sig, th)),
        (cal.FAMILIES["bagheri"], cap.bagheri_force(g, v, r, sig, th)),
        (cal.FAMILIES["mikami-pw"], cap.mikami_force_pw(g, v, r, sig, th)),
        (cal.FAMILIES["mikami-pp"], cap.mikami_force_pp(g, v, r, sig, th)),
        (cal.FAMILIES["lian-rupture"], rup.lian_rupture_distance(v, th)),
    ]
    for fam, ref in pairs:
        np.testing.assert_allclose(fam.form(fam.published, x), ref, rtol=1e-13, err_msg=fam.name)


def test_finite_liquid_published_is_pitois() -> None:
    fam = cal.FAMILIES["finite-liquid"]
    s = np.array([1e-6, 5e-6, 9e-6])
    x = {"gap": s, "edge_gap": np.full(3, 1e-5), "r_star": np.full(3, 1e-3),
         "viscosity": np.full(3, 1e-3), "velocity": np.full(3, 0.1)}
    ref = 6 * np.pi * 1e-3 * 1e-6 * 0.1 / s * (1 - s / 1e-5) ** 2
    np.testing.assert_allclose(fam.form(fam.published, x), ref, rtol=1e-13)


@pytest.fixture(scope="module")
def finite_liquid_run(tmp_path_factory):
    """Finite-liquid factor refitted against lubrication (fast: no meniscus solves)."""
    fam = cal.FAMILIES["finite-liquid"]
    train = cal.reference_points(fam, cal.design(fam, 12), gaps_per=8)
    held = cal.reference_points(fam, cal.design(fam, 8, seed=11), gaps_per=6, seed=11)
    res = cal.calibrate(fam, train, held, held_out_seed=11)
    out = tmp_path_factory.mktemp("cal") / "finite-liquid.json"
    files = cal.write_calibration(res, held, out)
    return res, files, held


def test_refit_beats_published_on_held_out_points(finite_liquid_run) -> None:
    """Pitois' (1 - S/H)^2 ignores the sphere's departure from a parabola (about 5 % at
    delta/R = 0.1 against lubrication); the refit removes most of it on unseen points."""
    res, _, held = finite_liquid_run
    before, after = res.held_out["before"], res.held_out["after"]
    assert before["max"] > 0.01
    assert after["max"] < 0.5 * before["max"]
    assert after["mean"] < before["mean"]
    assert set(before["max_at"]) == {"delta_over_r", "s_over_h"}
    # the reported figures are recomputed from the held-out points, not copied
    e = cal.rel_errors(cal.FAMILIES["finite-liquid"], res.coefficients, held)
    assert after["max"] == pytest.approx(float(e.max()))


def test_calibration_files_and_refitted_model(finite_liquid_run, tmp_path, capsys) -> None:
    res, files, _ = finite_liquid_run
    js, parity, errors = files
    data = json.loads(js.read_text())
    assert data["family"] == "finite-liquid" and len(data["coefficients"]) == 10
    assert data["domain"]["delta_over_r"][0] == pytest.approx(1e-3)
    assert parity.stat().st_size > 5000 and errors.stat().st_size > 5000
    model = cal.load_coefficients(js, family="finite-liquid")
    inside = make_scene("sphere-wall", {"film_thickness": 1e-5}, [2e-6, 5e-6])
    f = model.force(inside).force_viscous
    assert np.all(f > 0)
    outside = make_scene("sphere-wall", {"film_thickness": 5e-4}, [2e-6, 5e-6])  # d = 0.5
    with pytest.raises(ValidityError, match="delta_over_r"):
        model.force(outside)
    from wetcontact.cli import main

    case = tmp_path / "film.toml"
    case.write_text(
        'name = "film"\n[geometry]\nkind = "sphere-wall"\nradius = 1e-3\n[liquid]\n'
        'viscosity = 1e-3\nsurface_tension = 0.072\ndensity = 998.0\n[amount]\n'
        'film_thickness = 1e-5\n[motion]\nvelocity = 0.1\ngaps = [2e-6, 5e-6]\n')
    assert main(["solve", str(case), "--model", "finite-liquid", "--coefficients", str(js),
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(out["force_viscous"], f, rtol=1e-12)
    assert main(["solve", str(case), "--model", "willett", "--coefficients", str(js)]) == 2


def test_refit_file_names_each_coefficient_in_its_formula(finite_liquid_run) -> None:
    """The refit file written by ``write_calibration`` carries, beside the bare
    ``coefficients`` list the loader reads, the formula and one labelled record per
    coefficient in the formula's order (issue 58): its name, value, published value and the
    term it multiplies; the terms are checked against the form itself."""
    res, files, _ = finite_liquid_run
    data = json.loads(files[0].read_text())
    rows = data["labelled_coefficients"]
    assert [r["name"] for r in rows] == ["p"] + [f"c{i}" for i in range(9)]
    assert [r["value"] for r in rows] == data["coefficients"]
    assert [r["published"] for r in rows] == data["published"]
    assert all(set(r) == {"name", "value", "published", "term"} for r in rows)
    assert data["formula"].startswith("F = F_Reynolds (1 - x)^p [1 + d (c0 + c1 u")
    assert cal.load_coefficients(files[0], family="finite-liquid").k.tolist() == \
        data["coefficients"]
    # each c_n's term is the form's derivative in c_n over F_Reynolds (1 - x)^p
    fam = cal.FAMILIES["finite-liquid"]
    s, h, r = np.array([1e-6, 4e-6, 8e-6]), 1e-5, 1e-3
    x = {"gap": s, "edge_gap": np.full(3, h), "r_star": np.full(3, r),
         "viscosity": np.full(3, 1e-3), "velocity": np.full(3, 0.1)}
    xx, d = s / h, h / r
    base = fam.form(np.array([2.0] + [0.0] * 9), x)
    for i, row in enumerate(rows[1:], start=1):
        k = np.array([2.0] + [0.0] * 9)
        k[i] = 1.0
        term = eval(row["term"].replace("^", "**").replace(" ", "*"),  # noqa: S307
                    {"d": d, "u": np.sqrt(xx), "x": xx})
        np.testing.assert_allclose(fam.form(k, x) / base - 1.0, term, rtol=0, atol=1e-14,
                                   err_msg=row["name"])


def test_every_family_labels_its_coefficients_in_order() -> None:
    """One label per coefficient for every family, unique names, each named in its
    formula; Willett's 48 follow k[i, j, m] flattened in C order (ln^j V* theta^m in
    f_(i+1)); the shipped labels of Mikami's eight name A, B and C."""
    for fam in cal.FAMILIES.values():
        rows = cal.labelled_coefficients(fam, fam.published)["labelled_coefficients"]
        names = [r["name"] for r in rows]
        assert len(rows) == fam.published.size and len(set(names)) == len(names), fam.name
        assert [r["value"] for r in rows] == fam.published.tolist()
        if fam.name != "willett":  # its formula writes fi_jm once for f1 to f4
            words = set(re.findall(r"\w+", fam.labels.formula))
            assert set(names) <= words, (fam.name, set(names) - words)
    rows = cal.labelled_coefficients(cal.FAMILIES["willett"],
                                     cal.WILLETT_PUBLISHED.ravel())["labelled_coefficients"]
    for (i, j, m), row in zip(np.ndindex(4, 4, 3), rows, strict=True):
        assert row["name"] == f"f{i + 1}_{j}{m}"
        assert row["value"] == cal.WILLETT_PUBLISHED[i, j, m]
        want = " ".join(t for t in ({0: "", 1: "ln V*"}.get(j, f"ln^{j} V*"),
                                    {0: "", 1: "theta"}.get(m, f"theta^{m}")) if t) or "1"
        assert row["term"] == f"{want} in f{i + 1}"
    mikami = cal.labelled_coefficients(cal.FAMILIES["mikami-pp"], cal.FAMILIES[
        "mikami-pp"].published)["labelled_coefficients"]
    assert [r["name"] for r in mikami] == ["a0", "a1", "b0", "b1", "b2", "b3", "c0", "c1"]
    assert [r["term"].split(" in ")[-1] for r in mikami] == list("AABBBBCC")


def test_refit_answers_nan_at_gaps_outside_its_domain(finite_liquid_run, tmp_path,
                                                      capsys) -> None:
    """Gaps outside the refit's calibrated S/H range get NaN force, counted and explained
    in ``diagnostics["outside_domain"]``, the others the value they have alone; a scene
    outside on a scene axis (the film's thickness), or with every gap outside, is refused
    as before (issue 58)."""
    _, files, _ = finite_liquid_run
    model = cal.load_coefficients(files[0], family="finite-liquid")
    lo, hi = model.domain["s_over_h"]
    h = 1e-5
    gaps = [0.5 * lo * h, 2e-6, 5e-6, 0.5 * (1.0 + hi) * h]
    curve = model.force(make_scene("sphere-wall", {"film_thickness": h}, gaps))
    f = curve.force_viscous
    assert np.isnan(f[[0, 3]]).all() and np.all(f[1:3] > 0)
    alone = model.force(make_scene("sphere-wall", {"film_thickness": h}, gaps[1:3]))
    np.testing.assert_array_equal(f[1:3], alone.force_viscous)
    assert "outside_domain" not in alone.diagnostics
    note = curve.diagnostics["outside_domain"]
    assert note.startswith("2 of 4 gaps outside the calibrated domain (s_over_h = ")
    assert f"outside [{lo:.4g}, {hi:.4g}]" in note and note.endswith("NaN there")
    with pytest.raises(ValidityError, match="every gap outside the calibrated domain"):
        model.force(make_scene("sphere-wall", {"film_thickness": h}, [gaps[0], gaps[3]]))
    with pytest.raises(ValidityError, match="delta_over_r = 0.5 outside"):
        model.force(make_scene("sphere-wall", {"film_thickness": 5e-4}, gaps))
    # wetcontact solve: a warning line naming the NaN gaps; --json writes them as null
    from wetcontact.cli import main

    case = tmp_path / "film.toml"
    case.write_text(
        'name = "film"\n[geometry]\nkind = "sphere-wall"\nradius = 1e-3\n[liquid]\n'
        'viscosity = 1e-3\nsurface_tension = 0.072\ndensity = 998.0\n[amount]\n'
        f'film_thickness = {h!r}\n[motion]\nvelocity = 0.1\ngaps = {gaps!r}\n')
    argv = ["solve", str(case), "--model", "finite-liquid", "--coefficients", str(files[0])]
    assert main(argv) == 0
    cap_ = capsys.readouterr()
    warn = [ln for ln in cap_.err.splitlines() if "warning" in ln]
    assert len(warn) == 1 and "gives NaN at gaps " in warn[0] and "2 of 4 gaps" in warn[0]
    assert f"{gaps[0]:.6g}, {gaps[3]:.6g} m" in warn[0]
    assert sum("nan" in ln for ln in cap_.out.splitlines()) == 2
    assert main(argv + ["--json"]) == 0
    cap_ = capsys.readouterr()
    out = json.loads(cap_.out, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    assert out["force_viscous"][0] is None and out["force_viscous"][3] is None
    assert out["force_total"][1] == pytest.approx(f[1], rel=1e-12)
    assert out["diagnostics"]["outside_domain"] == note
    assert "gives NaN at gaps" in cap_.err


def test_bad_coefficient_files_are_input_errors(tmp_path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"family": "willett", "coefficients": [1.0, 2.0], "domain": {}}))
    with pytest.raises(InputError, match="'coefficients' has 2 values; allowed: 48"):
        cal.load_coefficients(bad)
    with pytest.raises(InputError, match=r"missing.json: \(file\) missing; allowed: an "
                                         "existing calibration JSON"):
        cal.load_coefficients(tmp_path / "missing.json")
    png = tmp_path / "parity.png"  # a binary file given by mistake: was an internal error
    png.write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff")
    with pytest.raises(InputError, match="parity.png: not a UTF-8 text file; allowed: a "
                                         "calibration JSON"):
        cal.load_coefficients(png)
    bad.write_text(json.dumps({"family": "nope", "coefficients": [], "domain": {}}))
    with pytest.raises(InputError, match="allowed"):
        cal.load_coefficients(bad)


WILLETT_JSON = ROOT / "benchmarks" / "results" / "calibration" / "willett.json"


def _break(data: dict, how: str) -> str:
    """Mutate a copy of a calibration JSON; return the field the message must name."""
    dom, k = data["domain"], data["coefficients"]
    if how == "domain key missing":
        del dom["theta_deg"]
        return "'domain'"
    if how == "domain key extra":
        dom["foo"] = [0, 1]
        return "'domain'"
    if how in ("NaN bound", "string bound", "null range", "one bound"):
        dom["theta_deg"] = {"NaN bound": [0, math.nan], "string bound": [0, "50"],
                            "null range": None, "one bound": [0]}[how]
        return "'domain.theta_deg"
    if how == "inverted range":
        dom["v_star"] = [0.1, 1e-4]
        return "'domain.v_star'"
    if how == "volume beyond the sphere":  # the refit answered silently at V* = 4
        dom["v_star"] = [-1, 1e9]
        return "'domain.v_star'"
    if how == "angle beyond 90 deg":  # ... and at 85 deg, where the built-in one warns
        dom["theta_deg"] = [-90, 179]
        return "'domain.theta_deg'"
    if how in ("string coefficient", "boolean coefficient", "NaN coefficient",
               "huge integer coefficient"):
        k[3] = {"string coefficient": "abc", "boolean coefficient": True,
                "NaN coefficient": math.nan, "huge integer coefficient": 10**400}[how]
        return "'coefficients'[3]"
    if how == "other kind":
        data["kind"] = "sphere-wall"
        return "'kind'"
    if how == "family misspelt":
        data["family"] = "willet"
        return "'family'"
    raise AssertionError(how)


@pytest.mark.parametrize("how", [
    "domain key missing", "domain key extra", "NaN bound", "string bound", "null range",
    "one bound", "inverted range", "volume beyond the sphere", "angle beyond 90 deg",
    "string coefficient", "boolean coefficient",
    "NaN coefficient", "huge integer coefficient", "other kind", "family misspelt"])
def test_malformed_coefficient_file_names_file_and_field(tmp_path, how) -> None:
    """Each malformation found by a new user's audit (2026-11-25) is an InputError naming
    the file and the field; before, a missing or NaN theta range silently dropped the
    refusal outside it, and null, short or extra ranges and string coefficients raised
    TypeError, IndexError, KeyError or ValueError (exit 1, "internal error")."""
    data = json.loads(WILLETT_JSON.read_text())
    field = _break(data, how)
    bad = tmp_path / "broken.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(InputError) as err:
        cal.load_coefficients(bad, family="willett")
    assert str(bad) in str(err.value) and field in str(err.value), str(err.value)


def test_coefficients_that_flip_the_force_are_refused(tmp_path) -> None:
    """A file that passes every field check can still hold coefficients under which the
    form changes sign (a squeeze force against the motion was printed with exit 0);
    the model now refuses them, naming the file."""
    data = json.loads((ROOT / "benchmarks" / "results" / "calibration"
                       / "finite-liquid.json").read_text())
    sc = make_scene("sphere-wall", {"film_thickness": 0.01 * 1e-3}, [2e-6, 5e-6, 9e-6])
    path = tmp_path / "fl.json"
    path.write_text(json.dumps(data))
    assert np.all(cal.load_coefficients(path).force(sc).force_viscous > 0)  # as refitted
    data["coefficients"][1] = -1000.0
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match="against the motion") as err:
        cal.load_coefficients(path).force(sc)
    assert str(path) in str(err.value)


def test_coefficients_that_overflow_the_form_are_refused(tmp_path) -> None:
    """Willett's coefficients scaled by 1e4 (an audit's hand edit) underflow the form's exp
    to F = 0 N inside the bridge, and scaled by -1e4 overflow it: both were printed with
    exit 0 (the second with numpy's overflow warning only)."""
    data = json.loads(WILLETT_JSON.read_text())
    sc = make_scene("sphere-sphere", {"bridge_volume": 0.01 * 1e-9}, [2e-5, 1e-4],
                    radius2=1e-3, theta=(20.0, 20.0))
    path = tmp_path / "w.json"
    path.write_text(json.dumps(data))
    assert np.all(cal.load_coefficients(path).force(sc).force_capillary < 0)  # as refitted
    k = data["coefficients"]
    for scale, says in ((1e4, "not an attraction"), (-1e4, "overflow the willett form")):
        data["coefficients"] = [scale * c for c in k]
        path.write_text(json.dumps(data))
        with pytest.raises(InputError, match=says) as err:
            cal.load_coefficients(path).force(sc)
        assert str(path) in str(err.value)


def test_points_from_a_sweep(tmp_path) -> None:
    """Reference points from the sweep interface (store-backed) equal a direct solve."""
    from wetcontact.store import Store
    from wetcontact.sweep import Point, sweep

    fam = cal.FAMILIES["finite-liquid"]
    scenes = [make_scene("sphere-wall", {"film_thickness": d}, [0.2 * d, 0.6 * d])
              for d in (1e-5, 4e-5)]
    res = sweep([Point(sc, "lubrication", "accurate") for sc in scenes],
                Store(tmp_path / "ref.h5"), progress=False)
    pts = cal.points_from_curves(fam, [(o.point.scene, o.curve) for o in res.outcomes])
    assert len(pts) == 4 and np.all(pts.y > 0)
    direct = np.concatenate([cal.get_model("lubrication").force(sc, preset="accurate")
                             .force_viscous for sc in scenes])
    np.testing.assert_allclose(pts.y, direct, rtol=1e-12)
    with pytest.raises(InputError, match="allowed: sphere-wall film"):
        cal.points_from_curves(fam, [(make_scene("sphere-wall", {"immersed": True}, [1e-5]),
                                      res.outcomes[0].curve)])


CALIBRATION = ROOT / "benchmarks" / "results" / "calibration"


def committed_refit(family: str) -> tuple[cal.Points, cal.Points, dict]:
    """A family's committed calibration: its training and held-out points and its record
    (``benchmarks/results/calibration/FAMILY.json``)."""
    train, held = cal.load_points(CALIBRATION / f"{family}_points.npz")
    return train, held, json.loads((CALIBRATION / f"{family}.json").read_text())


def perturbed_starts(refit: np.ndarray, n: int) -> list[np.ndarray]:
    """``n`` seeded starts around a refit: each coefficient perturbed by 30 % (normal)."""
    rng = np.random.default_rng(0)
    return [refit * (1.0 + 0.3 * rng.standard_normal(refit.size)) for _ in range(n)]


def test_fit_survives_a_start_whose_form_overflows() -> None:
    """From a start at which Willett's form overflows on some training points (the
    committed refit, each coefficient perturbed by 30 %), the fit once raised inside the
    least-squares solver (its cost and Jacobian became inf). It must now return a fit as
    good as from the published start: the same minimax maximum on the committed training
    points (the form's limit there) as the committed refit, which is that fit (0.0409077
    both, to 13 digits, when checked on 2026-11-27)."""
    fam = cal.FAMILIES["willett"]
    train, _, record = committed_refit("willett")
    refit = np.array(record["coefficients"])
    start = perturbed_starts(refit, 5)[-1]  # the committed refit perturbed: the fifth overflows
    with np.errstate(all="ignore"):
        assert not np.all(np.isfinite(fam.form(start, train.inputs)))
    got = cal.rel_errors(fam, cal.fit(replace(fam, published=start), train), train).max()
    ref = cal.rel_errors(fam, refit, train).max()  # = the fit from the published start
    assert np.isfinite(got) and abs(got - ref) <= 1e-6 * ref


def test_lian_rupture_refit_is_the_global_minimax_of_its_form() -> None:
    """Lian's rupture distance ``(a + b theta) V*^(1/3) + c V*^(2/3)`` is linear in its
    coefficients, so the smallest maximum relative error on the training points is a linear
    programme (min t, -t <= A k / y - 1 <= t), solved here independently of the fit. The
    committed refit reaches that optimum (0.0203 on 2026-11-28), so no coefficients of this
    form fit the study grid better; and it exceeds the issue's goal, a third of the
    published coefficients' held-out maximum (0.0113): the goal is out of this form's reach,
    not a fitting failure."""
    from scipy.optimize import linprog

    fam = cal.FAMILIES["lian-rupture"]
    train, held, record = committed_refit("lian-rupture")
    refit = np.array(record["coefficients"])
    n = refit.size
    a = np.stack([fam.form(np.eye(n)[i], train.inputs) for i in range(n)], axis=1)
    np.testing.assert_allclose(a @ refit, fam.form(refit, train.inputs), rtol=1e-12)  # linear
    m = a / train.y[:, None]
    ones = np.ones((len(m), 1))
    lp = linprog(np.r_[np.zeros(n), 1.0], A_ub=np.block([[m, -ones], [-m, -ones]]),
                 b_ub=np.r_[np.ones(len(m)), -np.ones(len(m))],
                 bounds=[(None, None)] * n + [(0.0, None)])
    assert lp.status == 0
    best = lp.x[-1]
    assert cal.rel_errors(fam, refit, train).max() <= best * (1.0 + 1e-9)
    goal = cal.rel_errors(fam, fam.published.astype(float), held).max() / 3.0
    assert best > goal


@pytest.mark.slow
@pytest.mark.parametrize("family", ["willett", "bagheri"])
def test_refit_from_other_starts_finds_no_smaller_maximum(family: str) -> None:
    """The nonlinear forms (Willett's 48 coefficients, Bagheri's 23) may have several local
    minima. From five starts around the committed refit (each coefficient perturbed by 30 %,
    seeded) the fit's best maximum relative error on the training points stays above a third
    of the published coefficients' held-out maximum (the goal), and the committed refit is
    within 1 % of it (2026-11-28: Willett 4.09 % from all five, as committed; Bagheri 12.23 %
    from one start, 0.09 % below the committed 12.24 %, 63 % from another, the form's poles
    from three): the miss of the 1/3 goal is the form's limit as far as these starts see.
    About 20 s (willett) and 60 s (bagheri)."""
    fam = cal.FAMILIES[family]
    train, _, record = committed_refit(family)
    refit = np.array(record["coefficients"])
    ref = cal.rel_errors(fam, refit, train).max()
    goal = record["held_out"]["before"]["max"] / 3.0
    got = [cal.rel_errors(fam, cal.fit(replace(fam, published=start), train), train).max()
           for start in perturbed_starts(refit, 5)]
    assert min(got) > goal and min(got) >= 0.99 * ref, (goal, ref, got)


def test_refitted_rupture_distance_is_no_force(tmp_path, capsys) -> None:
    """A refitted rupture-distance family (``lian-rupture``) models S_c, not a force: its
    curve has no force component (both ``None``, JSON ``null``; a column of 0 N was printed
    before) and carries S_c, ``(a + b theta) V*^(1/3) + c V*^(2/3)`` times R with the
    file's coefficients, which the text table shows."""
    from wetcontact.cli import main
    from wetcontact.scene import load_case

    path = ROOT / "benchmarks" / "results" / "calibration" / "lian-rupture.json"
    a, b, c = json.loads(path.read_text())["coefficients"]
    r, v, theta = 5e-5, 1.25e-15, 20.0
    case = tmp_path / "bridge.toml"
    case.write_text(
        'name = "bridge"\n[geometry]\nkind = "sphere-sphere"\nradius = 5e-5\nradius2 = 5e-5\n'
        '[liquid]\nviscosity = 1e-3\nsurface_tension = 0.072\ndensity = 998.0\n'
        f'contact_angle = {theta}\n[amount]\nbridge_volume = {v}\n[motion]\n'
        'velocity = 0.01\ngaps = [1e-6, 5e-6]\n')
    v_star = v / r**3
    s_c = r * ((a + b * math.radians(theta)) * v_star ** (1 / 3) + c * v_star ** (2 / 3))
    curve = cal.load_coefficients(path, family="lian-rupture").force(load_case(case))
    assert curve.force_viscous is None and curve.force_capillary is None
    assert curve.force_total is None
    np.testing.assert_allclose(curve.extras["rupture_distance"], s_c, rtol=1e-12)
    assert main(["solve", str(case), "--model", "lian-rupture", "--coefficients",
                 str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["force_capillary"] is None and out["force_total"] is None
    assert out["model_capillary"] is None and out["model_viscous"] is None
    np.testing.assert_allclose(out["rupture_distance"], s_c, rtol=1e-12)
    assert main(["solve", str(case), "--model", "lian-rupture", "--coefficients",
                 str(path)]) == 0
    head, cols, first = capsys.readouterr().out.splitlines()[:3]
    assert cols.split() == ["gap_m", "rupture_distance_m"]
    assert float(first.split()[1]) == pytest.approx(s_c, rel=1e-6)
    # a family named without its coefficients: exit 2, saying what to give
    assert main(["solve", str(case), "--model", "lian-rupture"]) == 2
    assert "--coefficients FILE.json" in capsys.readouterr().err


COMMITTED = ROOT / "benchmarks" / "results" / "calibration"


@pytest.mark.parametrize("family", sorted(p.stem for p in COMMITTED.glob("*.json")))
def test_committed_reference_points_are_solved_again(family):
    """The committed held-out tables are the errors on the committed reference points
    (``tests/tables/test_calibration.py``); here two of their scenes, the first and the
    last of the held-out study, are solved again by the reference model at the study's
    preset, and every point they give is one of the committed points with the same value
    (within 1e-9): the committed references are not stale."""
    from wetcontact.models import get_model
    from wetcontact.study import load_study

    data = json.loads((COMMITTED / f"{family}.json").read_text())
    fam = cal.get_family(data["family"])
    ref_name = data["reference"].split()[0]
    study = load_study(ROOT / data["held_out_study"])
    _, held = cal.load_points(COMMITTED / f"{family}_points.npz")
    keys = sorted(held.inputs)
    table = np.column_stack([held.inputs[k] for k in keys])
    scenes = [sc for _, sc in study.scenes]
    for scene in (scenes[0], scenes[-1]):
        curve = get_model(ref_name).force(scene, preset=study.preset)
        fresh = cal.points_from_curves(fam, [(scene, curve)])
        assert len(fresh) > 0
        for i in range(len(fresh)):
            row = np.array([fresh.inputs[k][i] for k in keys])
            match = np.flatnonzero(np.all(np.isclose(table, row, rtol=1e-12, atol=0), axis=1))
            assert match.size == 1, (scene.name, i)
            # abs=0: forces down to 8e-9 N, where approx's default abs 1e-12 is 1e-4 of y
            assert fresh.y[i] == pytest.approx(held.y[match[0]], rel=1e-9, abs=0), (scene.name,
                                                                                  i)


def test_bounds_quick_never_replaces_the_shipped_tables(monkeypatch, tmp_path, capsys):
    """``python -m wetcontact.generate bounds --quick`` writes bounds-quick.json in the
    current folder (it wrote the package data), plain ``bounds`` the package data, and
    ``--out`` wherever it says."""
    import wetcontact.generate.bounds as bg

    seen = []
    monkeypatch.setattr(bg, "measure_bounds",
                        lambda seed, out, quick, progress, closure: seen.append((out, quick))
                        or {"tables": [], "wall_time_s": 0.0})
    monkeypatch.chdir(tmp_path)
    assert generate_main(["bounds", "--quick"]) == 0
    assert generate_main(["bounds"]) == 0
    assert generate_main(["bounds", "--quick", "--out", str(tmp_path / "q.json")]) == 0
    assert seen == [(Path("bounds-quick.json"), True), (bg.DATA_PATH, False),
                    (tmp_path / "q.json", True)]
    assert "wrote bounds-quick.json" in capsys.readouterr().out


def _fake_bound_tables(monkeypatch):
    """Replace every table measurement of ``generate.bounds`` by a draw from the stream it is
    given (no solve): a table per stream, which records the stream's first numbers."""
    import wetcontact.generate.bounds as bg

    def fake(model, kind, *streams):
        return {"model": model, "kind": kind,
                "draws": [float(x) for r in streams if r is not None for x in r.random(3)]}

    monkeypatch.setattr(bg, "immersed_tables", lambda rng, per_bin: [fake("a", "w", rng)])
    monkeypatch.setattr(bg, "finite_liquid_tables", lambda rng, **kw: [
        fake("b", "w", rng, kw["rng_large"])])
    monkeypatch.setattr(bg, "capillary_tables", lambda rng, **kw: [fake("c", "w", rng)])
    monkeypatch.setattr(bg, "calibrated_capillary_tables", lambda rng, **kw: [
        fake("calibrated-capillary", k, rng, kw["rng_two"], kw["rng_pair_two"])
        for k in ("sphere-wall", "sphere-sphere")])
    return bg


def test_bounds_of_one_closure_are_a_whole_runs(monkeypatch, tmp_path, capsys):
    """``bounds --closure calibrated-capillary`` measures that closure's tables from the
    streams a whole run gives them, in their places: the file equals a whole run's but for
    its record of the partial run; the other tables are not measured again."""
    bg = _fake_bound_tables(monkeypatch)
    whole = bg.measure_bounds(seed=7, out=tmp_path / "whole.json", quick=True)
    part = tmp_path / "part.json"
    stale = json.loads((tmp_path / "whole.json").read_text())
    for t in stale["tables"]:
        t["draws"] = [0.0]  # what the new measurement must replace, and only there
    part.write_text(json.dumps(stale))
    assert generate_main(["bounds", "--quick", "--seed", "7", "--out", str(part),
                          "--closure", "calibrated-capillary"]) == 0
    assert "2 calibrated-capillary tables measured again" in capsys.readouterr().out
    got = json.loads(part.read_text())
    assert got.pop("remeasured")["calibrated-capillary"]["tables"] == 2
    assert [t["model"] for t in got["tables"]] == ["a", "b", "c", "calibrated-capillary",
                                                   "calibrated-capillary"]
    assert got["tables"][3:] == whole["tables"][3:]
    assert all(t["draws"] == [0.0] for t in got["tables"][:3])
    assert {k: v for k, v in got.items() if k != "tables"} == {
        k: v for k, v in whole.items() if k != "tables"}


@pytest.mark.parametrize("edit,message", [
    (None, r"missing\.json: not a bound-table file to measure calibrated-capillary into"),
    ({"seed": 8}, r"field 'seed' = 8; allowed: 7"),
    ({"quick": False}, r"field 'quick' = False; allowed: True"),
])
def test_bounds_of_one_closure_refuse_another_run(monkeypatch, tmp_path, edit, message):
    """A partial measurement needs the whole run it replaces tables of: a missing file, or
    one of another seed or size, is an InputError naming the file, field and value."""
    from wetcontact.errors import InputError

    bg = _fake_bound_tables(monkeypatch)
    out = tmp_path / "b.json"
    bg.measure_bounds(seed=7, out=out, quick=True)
    if edit is None:
        out = tmp_path / "missing.json"
    else:
        out.write_text(json.dumps({**json.loads(out.read_text()), **edit}))
    with pytest.raises(InputError, match=message):
        bg.measure_bounds(seed=7, out=out, quick=True, closure="calibrated-capillary")


def test_calibration_figures_name_the_family_reference_and_units(finite_liquid_run) -> None:
    """The parity plot and the error map say what was fitted against what, in which
    units, and no label leaves the canvas."""
    from wetcontact.plotting import clipped_texts

    res, _, held = finite_liquid_run
    parity, errors = cal.calibration_figures(res, held)
    ax = parity.axes[0]
    assert "finite-liquid: sphere-wall, film\n" in ax.get_title()
    assert "lubrication" in ax.get_title()
    assert ax.get_xlabel() == "reference viscous force (N)"
    assert errors.get_suptitle().startswith("finite-liquid: sphere-wall, film")
    assert errors.axes[0].get_xlabel() == "film thickness delta / R"
    assert errors.axes[0].get_ylabel() == "S / H"
    assert not clipped_texts(parity) and not clipped_texts(errors)
