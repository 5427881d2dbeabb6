"""`wetcontact calibrate STUDY --closure FAMILY --out F.json`: a tiny film study end to end
(lubrication as reference, seconds), and bad inputs (exit 2, one line)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from wetcontact.calibrate import get_family, load_coefficients, load_points, rel_errors
from wetcontact.cli import main
from wetcontact.study import load_study

ROOT = Path(__file__).resolve().parents[1]
FILM = ROOT / "cases" / "glass-2mm-water-film.toml"


def _study(tmp_path: Path, models: str = '["lubrication", "reynolds-finite"]',
           name: str = "tiny-film") -> Path:
    p = tmp_path / f"{name}.toml"
    p.write_text(f'name = "{name}"\nbase = "{FILM.as_posix()}"\nmodels = {models}\n'
                 '[axes]\n"amount.film_over_radius" = [0.02, 0.05, 0.1]\n'
                 '[set]\n"motion.gap_over_radius" = { start = 0.001, stop = 0.018, '
                 'points = 6, spacing = "linear" }\n')
    return p


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("cal")
    out = tmp / "out" / "film.json"
    code = main(["calibrate", str(_study(tmp)), "--closure", "finite-liquid", "--out",
                 str(out), "--store", str(tmp / "r.h5"), "--workers", "0",
                 "--held-out-points", "8", "--seed", "5"])
    return code, out, tmp


def test_calibrate_writes_json_plots_and_held_out_study(calibrated):
    code, out, _ = calibrated
    assert code == 0
    data = json.loads(out.read_text())
    assert data["family"] == "finite-liquid"
    assert data["reference"].startswith("lubrication")  # highest reference_rank in the study
    assert data["train"]["points"] == 18 and data["held_out"]["points"] == 8
    for suffix in ("_parity.png", "_errors.png", "_points.npz", "_heldout.toml"):
        assert out.with_name(out.stem + suffix).stat().st_size > 0
    held = load_study(out.with_name("film_heldout.toml"))
    assert len(held.scenes) == 8  # the seeded hypercube, loadable as a study of its own


def test_held_out_points_are_off_the_training_grid_and_refit_beats_published(calibrated):
    _, out, _ = calibrated
    data = json.loads(out.read_text())
    fam = get_family("finite-liquid")
    train, held = load_points(out.with_name("film_points.npz"))
    train_gaps = set(np.round(train.inputs["gap"] / train.inputs["radius"], 12))
    assert not train_gaps & set(np.round(held.inputs["gap"] / held.inputs["radius"], 12))
    # the table is the errors of the saved coefficients on the saved held-out points
    k = np.asarray(data["coefficients"])
    e_after = rel_errors(fam, k, held)
    e_before = rel_errors(fam, fam.published, held)
    assert data["held_out"]["after"]["max"] == pytest.approx(e_after.max(), rel=1e-12, abs=0)
    assert data["held_out"]["before"]["max"] == pytest.approx(e_before.max(), rel=1e-12,
                                                             abs=0)
    # Pitois' (1 - S/H)^2 is a few % off lubrication; the refit at least 3x better
    assert e_before.max() > 0.01
    assert e_after.max() <= e_before.max() / 3.0
    assert data["goal_met"] is True
    # the coefficients load as a model that refuses scenes outside the calibrated domain
    model = load_coefficients(out, family="finite-liquid")
    assert model.domain["delta_over_r"][0] == pytest.approx(0.02)


def test_second_run_reuses_the_store(calibrated, capsys):
    code, out, tmp = calibrated
    again = tmp / "again.json"
    assert main(["calibrate", str(_study(tmp)), "--closure", "finite-liquid", "--out",
                 str(again), "--store", str(tmp / "r.h5"), "--workers", "0",
                 "--held-out", str(out.with_name("film_heldout.toml"))]) == 0
    assert "computed 0" in capsys.readouterr().err
    a, b = json.loads(out.read_text()), json.loads(again.read_text())
    assert a["held_out"]["before"] == b["held_out"]["before"]


def test_fewer_training_points_than_coefficients_warns(tmp_path, capsys):
    """Six training points for finite-liquid's ten coefficients: the fit interpolates them
    (training error about 1e-15), which only the held-out table shows; it now says so."""
    study = tmp_path / "one-film.toml"
    study.write_text(_study(tmp_path).read_text().replace("[0.02, 0.05, 0.1]", "[0.05]"))
    assert main(["calibrate", str(study), "--closure", "finite-liquid", "--out",
                 str(tmp_path / "c.json"), "--store", str(tmp_path / "r.h5"), "--workers",
                 "0", "--held-out-points", "4", "--seed", "1"]) == 0
    err = capsys.readouterr().err
    assert "warning: 6 training points for 10 coefficients" in err, err


@pytest.mark.parametrize("case", ["family", "no-reference", "scene-class", "out", "points",
                                  "missing", "seed", "store"])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, case):
    study = _study(tmp_path)
    args = ["calibrate", str(study), "--closure", "finite-liquid", "--out",
            str(tmp_path / "c.json"), "--store", str(tmp_path / "r.h5"), "--workers", "0"]
    expect = {"family": "finite-liquid",  # the message lists the families
              "no-reference": "no reference", "scene-class": "allowed for family willett",
              "out": "--out", "points": "--held-out-points", "missing": "nope.toml",
              "seed": "--seed", "store": "not a readable HDF5 store"}[case]
    if case == "family":
        args[3] = "mikami-xx"
    elif case == "no-reference":
        args[1] = str(_study(tmp_path, '["reynolds", "reynolds-finite"]', "closures-only"))
    elif case == "scene-class":
        args[3] = "willett"
    elif case == "out":
        args[5] = str(tmp_path / "c.txt")
    elif case == "points":
        args += ["--held-out-points", "2"]
    elif case == "missing":
        args[1] = str(tmp_path / "nope.toml")
    elif case == "store":  # it wrote the held-out design beside --out before failing
        (tmp_path / "r.h5").write_text("not hdf5")
    else:
        args += ["--seed", "-1"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert expect in err
    assert case == "store" or not (tmp_path / "r.h5").exists()  # nothing was solved
    assert not list(tmp_path.glob("c_*")) + list(tmp_path.glob("c.*"))  # nothing beside --out


@pytest.mark.slow
def test_capillary_refit_beats_published_mikami_on_held_out_bridges(tmp_path):
    """Sphere-plate bridges against the finite-element meniscus (about a minute)."""
    base = ROOT / "cases" / "sphere-plate-unequal-angles.toml"
    study = tmp_path / "pw.toml"
    study.write_text(
        f'name = "pw"\nbase = "{base.as_posix()}"\nmodels = ["meniscus", "mikami"]\n'
        '[axes]\n"amount.volume_over_radius3" = { start = 1e-3, stop = 0.1, points = 3, '
        'spacing = "log" }\n"liquid.contact_angle" = [0.0, 20.0, 40.0]\n'
        '[set]\n"motion.gap_over_rupture" = { start = 0.05, stop = 0.9, points = 5, '
        'spacing = "linear" }\n')
    out = tmp_path / "pw.json"
    assert main(["calibrate", str(study), "--closure", "mikami-pw", "--out", str(out),
                 "--store", str(tmp_path / "r.h5"), "--workers", "0",
                 "--held-out-points", "12", "--seed", "11"]) == 0
    ho = json.loads(out.read_text())["held_out"]
    assert ho["points"] == 12
    assert ho["after"]["max"] < ho["before"]["max"]
    assert ho["after"]["mean"] < ho["before"]["mean"]


CAL_STUDIES = sorted((ROOT / "cases" / "studies").glob("calibrate-*.toml"))


@pytest.mark.parametrize("path", [p for p in CAL_STUDIES if "finite-liquid" not in p.stem],
                         ids=lambda p: p.stem)
def test_shipped_calibration_studies_reproduce_the_default_designs(path):
    """Each calibrate-FAMILY.toml: the family's scene class, a reference model, and the
    training configurations of ``python -m wetcontact.generate fit FAMILY --train 40``."""
    import tomllib

    from wetcontact.calibrate import check_scene_class, design, reference_model
    from wetcontact.scene import load_case
    from wetcontact.study import _range

    fam = get_family(path.stem.removeprefix("calibrate-"))
    data = tomllib.loads(path.read_text())
    check_scene_class(fam, [load_case(path.parent / data["base"])], str(path))
    assert reference_model(fam, data["models"]) == "meniscus"
    axes = {"amount.volume_over_radius3": "v_star", "liquid.contact_angle": "theta_deg"}
    grid = {axes[k]: _range(str(path), k, v) for k, v in data["axes"].items()}
    configs = design(fam, 40)
    for name, values in grid.items():
        assert sorted({c[name] for c in configs}) == pytest.approx(sorted(values), rel=1e-12,
                                                                 abs=0)
    assert len(configs) == np.prod([len(v) for v in grid.values()])
    gaps = data["set"].get("motion.gap_over_rupture")
    if fam.target != "rupture":
        lo, hi, _ = fam.default_design["s_over_scref"]
        assert (gaps["start"], gaps["stop"], gaps["points"]) == (lo, hi, 8)  # gaps_per = 8


@pytest.mark.parametrize("path", [p for p in CAL_STUDIES if "finite-liquid" in p.stem],
                         ids=lambda p: p.stem)
def test_finite_liquid_studies_cover_the_family_domain(path):
    """Each calibrate-finite-liquid*.toml: the family's scene class, ``lubrication`` as
    reference, and training points spanning the family's design ranges (S/delta or S/H
    from 0.01 to 0.95, delta/R or V/R^3 and the radius ratio end to end)."""
    import tomllib

    from wetcontact.calibrate import (
        check_scene_class,
        domain_coords,
        reference_model,
        scene_inputs,
    )
    from wetcontact.study import load_study

    fam = get_family(path.stem.removeprefix("calibrate-"))
    data = tomllib.loads(path.read_text())
    assert reference_model(fam, data["models"]) == "lubrication"
    study = load_study(path)
    scenes = [sc for _, sc in study.scenes]
    check_scene_class(fam, scenes, str(path))
    coords: dict[str, list[float]] = {}
    for sc in scenes:
        for k, v in domain_coords(fam, scene_inputs(fam, sc)).items():
            coords.setdefault(k, []).extend(np.atleast_1d(v).tolist())
    for k, (lo, hi, _) in fam.default_design.items():
        assert min(coords[k]) == pytest.approx(lo, rel=1e-9, abs=0)
        assert max(coords[k]) == pytest.approx(hi, rel=1e-9, abs=0)


def test_committed_held_out_designs_point_at_existing_bases():
    import tomllib

    files = sorted((ROOT / "benchmarks" / "results" / "calibration").glob("*_heldout.toml"))
    assert len(files) >= 5
    for f in files:
        data = tomllib.loads(f.read_text())
        assert (f.parent / data["base"]).is_file(), f
        assert data["sample"]["seed"] == 7919


@pytest.mark.parametrize("kind", ["sphere-wall", "sphere-wall-two-angles"])
def test_capillary_table_commands_write_into_out(tmp_path, monkeypatch, kind) -> None:
    """``python -m wetcontact.generate calibrated-capillary --kind K --retrain --out F`` (was
    ``python -m wetcontact.calibrate capillary``) wrote into the package data whatever F was,
    for every kind but the two-angle pairs' (found when a retrain meant for a copy replaced
    the shipped table); now F, a copy of the package data's file made there first, for
    every kind."""
    import wetcontact.generate.calibrated_capillary as gen
    from wetcontact.generate.__main__ import main as generate_main

    got = {}

    def fake(out=None, kinds=(), **kw):
        got.update(out=out, kinds=kinds, **kw)
        return {k: {"held_out": {"rupture_distance": {"max": 0.0}, "force": {
            "max": 0.0, "points": 0}}} for k in kinds} | {"retrain_wall_time_s": 0.0}

    monkeypatch.setattr(gen, "generate_calibrated_capillary", fake)
    out = tmp_path / "cc.json"
    assert generate_main(["calibrated-capillary", "--kind", kind, "--retrain", "--out",
                          str(out)]) == 0
    assert got["out"] == out and got["kinds"] == (kind,) and got["retrain"]
    shipped = Path(gen.cc.__file__).parents[1] / "data" / gen.cc.CAPILLARY_FILE
    assert out.read_bytes() == shipped.read_bytes()
