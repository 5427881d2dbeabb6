"""The calibration section renders the held-out tables from calibration JSONs, never solving."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from wetcontact.calibrate import Calibration, get_family, load_points, rel_errors
from wetcontact.errors import InputError
from wetcontact.reduced_models import DATA_DIR
from wetcontact.tables import StudyContext
from wetcontact.tables import calibration as table

ROOT = Path(__file__).resolve().parents[2]
COMMITTED = ROOT / "benchmarks" / "results" / "calibration"


def _summary(mx: float) -> dict:
    return {"max": mx, "mean": mx / 4, "p95": mx / 2, "max_at": {"v_star": 0.01}}


def _cal(family: str, before: float, after: float) -> dict:
    fam = get_family(family)
    return Calibration(family, fam.published, fam.published, {"v_star": (1e-4, 0.1)},
                       {"points": 10}, {"points": 12, "seed": 3, "before": _summary(before),
                                        "after": _summary(after)},
                       {"target": fam.target, "reference": "meniscus"}).to_json()


def test_renderer_never_solves():
    src = Path(table.__file__).read_text()
    assert "get_model" not in src and ".force(" not in src and "sweep(" not in src


def test_section_tables_goal_and_csv(tmp_path):
    ctx = StudyContext(calibration=(("a/willett.json", _cal("willett", 0.1, 0.05)),
                                    ("a/mikami-pw.json", _cal("mikami-pw", 0.3, 0.09))),
                       calibrated_viscous=json.loads((DATA_DIR / "calibrated_viscous.json")
                                                     .read_text()),
                       calibrated_viscous_path="pkg/calibrated_viscous.json")
    assert table.points(ctx) == []
    md = table.section(tmp_path, None, ctx)
    lines = md.splitlines()
    row = next(ln for ln in lines if ln.startswith("| `willett`"))
    assert "0.1 / 0.025 / 0.05" in row and "0.50" in row and "**not met**" in row
    row = next(ln for ln in lines if ln.startswith("| `mikami-pw`"))
    assert "0.30" in row and "| met |" in row
    assert "v_star [0.0001, 0.1]" in row
    assert "| immersed sphere-wall | shipped | brenner (exact)" in md
    rows = list(csv.DictReader((tmp_path / table.CSV_NAME).open()))
    got = {(r["closure"], r["part"], r["coefficients"]): r for r in rows}
    assert float(got[("willett", "capillary", "refitted")]["max"]) == 0.05
    assert got[("willett", "capillary", "refitted")]["goal_met"] == "False"
    assert got[("mikami-pw", "capillary", "refitted")]["goal_met"] == "True"
    cv = json.loads((DATA_DIR / "calibrated_viscous.json").read_text())
    film = got[("calibrated-viscous", "film", "shipped")]
    assert float(film["max"]) == cv["film"]["held_out"]["after"]["max"]
    assert film["goal_met"] == str(cv["film"]["held_out"]["after"]["max"] <= 0.01)
    assert len(rows) == 4 + 2 + 2 * (1 + len(cv["bridge"]))


def test_section_without_inputs_says_so(tmp_path):
    md = table.section(tmp_path, None, StudyContext())
    assert "No calibration output was given" in md and "was not given" in md
    assert not (tmp_path / table.CSV_NAME).exists()


def test_load_calibrations_names_a_bad_file(tmp_path):
    (tmp_path / "x.json").write_text('{"family": "willett"}')
    with pytest.raises(InputError, match=r"x\.json: field 'held_out' missing"):
        table.load_calibrations(tmp_path)
    (tmp_path / "x.json").write_text("{")
    with pytest.raises(InputError, match=r"x\.json: not a readable"):
        table.load_calibrations(tmp_path)


def test_committed_tables_match_their_saved_points():
    """The committed held-out figures are the errors of the committed coefficients on the
    committed reference points (so the report table is not stale)."""
    cals = table.load_calibrations(COMMITTED)
    assert {d["family"] for _, d in cals} >= {"mikami-pw", "mikami-pp", "willett", "bagheri",
                                              "lian-rupture", "finite-liquid"}
    for path, data in cals:
        fam = get_family(data["family"])
        _, held = load_points(Path(path).with_name(Path(path).stem + "_points.npz"))
        assert len(held) == data["held_out"]["points"]
        for k, tag in ((np.asarray(data["published"]), "before"),
                       (np.asarray(data["coefficients"]), "after")):
            assert rel_errors(fam, k, held).max() == pytest.approx(
                data["held_out"][tag]["max"], rel=1e-9, abs=0), (data["family"], tag)


def test_run_renders_the_section_from_the_folder_it_is_given(tmp_path, monkeypatch):
    import wetcontact.report as report
    from wetcontact.models import load_all

    models = load_all()
    monkeypatch.setattr(report, "SECTIONS", ("calibration",))
    monkeypatch.setattr(report, "load_all", lambda: {"willett": models["willett"]})
    cases = tmp_path / "cases"
    cases.mkdir()
    (cases / "b.toml").write_text(
        'name = "b"\n[geometry]\nkind = "sphere-sphere"\nradius = 1e-4\nradius2 = 1e-4\n'
        '[liquid]\nviscosity = 1e-3\nsurface_tension = 0.072\ndensity = 998.0\n'
        'contact_angle = 20.0\n[amount]\nbridge_volume = 1e-13\n'
        '[motion]\nvelocity = 0.01\ngaps = [1e-6, 5e-6]\n')
    cal = tmp_path / "cal"
    cal.mkdir()
    (cal / "willett.json").write_text(json.dumps(_cal("willett", 0.1, 0.02)))
    path = report.run_all(cases=cases, out=tmp_path / "rep", progress=False, bench=None,
                          calibration=cal)
    md = path.read_text()
    assert "## Calibration: held-out errors" in md and "| `willett` | meniscus | 12 |" in md
    assert (path.parent / table.CSV_NAME).is_file()
    with pytest.raises(InputError, match="not a folder"):
        report.run_all(cases=cases, out=tmp_path / "rep2", progress=False, bench=None,
                       calibration=tmp_path / "missing")


def test_capillary_rows_flag_each_goal_and_the_near_equal_stratum():
    """Rows of the shipped calibrated-capillary table: one per (geometry, stratum, part),
    goal_met computed from the goal (1e-3 force, 5e-4 rupture distance), not copied."""
    def ho(force: float, rupture: float, **extra) -> dict:
        return {"seed": 1, "reference": "meniscus",
                "force": {"points": 8, **_summary(force)},
                "rupture_distance": {"points": 2, **_summary(rupture)}, **extra}

    data = {"goals": {"force": 1e-3, "rupture_distance": 5e-4},
            "domain": {"v": [1e-4, 0.1], "theta_deg": [0, 70], "radius_ratio": [1, 10]},
            "sphere-wall": {"held_out": ho(2e-3, 1e-5)},
            "sphere-sphere": {"held_out": ho(1e-4, 6e-4),
                              "held_out_near_equal": ho(1e-5, 1e-5, stratum={
                                  "radius_ratio": [1, 1.1]})},
            "sphere-sphere-two-angles": {"held_out": ho(1e-4, 1e-4),
                                         "held_out_near_ridge": ho(2e-3, 1e-4, stratum={
                                             "theta2_deg_from_ridge": [-3, 3]})}}
    rows = table.capillary_rows("x.json", data)
    got = {r["part"]: r["goal_met"] for r in rows}
    assert got == {"sphere-wall rupture_distance": True, "sphere-wall force": False,
                   "sphere-sphere rupture_distance": False, "sphere-sphere force": True,
                   "sphere-sphere (nearly equal) rupture_distance": True,
                   "sphere-sphere (nearly equal) force": True,
                   "sphere-sphere-two-angles rupture_distance": True,
                   "sphere-sphere-two-angles force": True,
                   "sphere-sphere-two-angles (near the ridge) rupture_distance": True,
                   "sphere-sphere-two-angles (near the ridge) force": False}
    near = [r for r in rows if "nearly" in r["part"]][0]
    assert "radius_ratio [1, 1.1]" in near["domain"]
    assert "radius_ratio" not in rows[0]["domain"]  # a wall has no ratio
    pair = [r for r in rows if "(near the ridge)" in r["part"]][0]  # two angles, spheres
    assert "radius_ratio [1, 10]" in pair["domain"]
    assert "theta2_deg_from_ridge [-3, 3]" in pair["domain"]
    assert pair["domain"].endswith("the small sphere's and the large sphere's angle each "
                                   "in the theta range")
