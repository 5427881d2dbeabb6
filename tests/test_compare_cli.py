"""``wetcontact compare CASE``: one case's closure error table and figure, through the same
data path as the report (case points, the store, ``compare``), without the studies."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest

import wetcontact.report as report
from wetcontact.cli import main
from wetcontact.compare import compare
from wetcontact.models import load_all
from wetcontact.scene import load_case
from wetcontact.store import Store

ROOT = Path(__file__).resolve().parents[1]
IMMERSED = ROOT / "cases" / "brenner-immersed-sphere-wall.toml"
CHEAP = ("toroidal", "willett", "reynolds", "reynolds-finite", "lubrication")
BRIDGE = ('name = "tiny-bridge"\n[geometry]\nkind = "sphere-sphere"\nradius = 1e-4\n'
          'radius2 = 1e-4\n[liquid]\nviscosity = 1e-3\nsurface_tension = 0.072\n'
          'density = 998.0\ncontact_angle = 20.0\n[amount]\nbridge_volume = 1e-13\n'
          '[motion]\nvelocity = 0.01\ngaps = [1e-6, 5e-6, 2e-5]\n')


def _run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(["compare", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_named_models_against_the_case_reference(tmp_path, capsys):
    """Named closures (and a solver) against the case's reference, which is added; a named
    model that does not apply is listed with its reason and is not fatal."""
    out = tmp_path / "cmp"
    code, text, err = _run(capsys, str(IMMERSED), "--models", "reynolds, schaeffer,toroidal",
                           "--out", str(out), "--workers", "0", "--json")
    assert code == 0, err
    got = json.loads(text)
    assert got["references"] == {"viscous": "brenner"}
    assert sorted(r["closure"] for r in got["rows"]) == ["reynolds", "schaeffer"]
    assert "needs a liquid bridge" in got["not_applicable"]["toroidal"]
    assert got["counts"]["computed"] == 3 and got["failed"] == {}  # brenner added, no stokes
    rows = list(csv.DictReader((out / "closure_errors.csv").open()))
    scene, models = load_case(IMMERSED), load_all()
    ref = models["brenner"].force(scene)
    for row in rows:
        rec = compare(models[row["closure"]].force(scene), ref, "viscous")
        assert float(row["max_rel_error"]) == rec.max_rel_error
        assert int(row["points"]) == rec.points == len(scene.gaps)
    for name in ("brenner-immersed-sphere-wall.png", "brenner-immersed-sphere-wall.csv"):
        assert (out / "curves" / name).stat().st_size > 0
    assert all(Path(f).exists() for f in got["files"])


def test_every_applicable_closure_and_nothing_else(tmp_path, capsys, monkeypatch):
    """Without --models: every closure that applies, against the ranked reference; the
    store holds the case's curves only (no study swept) and a rerun computes nothing."""
    models = load_all()
    monkeypatch.setattr(report, "load_all", lambda: {n: models[n] for n in CHEAP})
    case = tmp_path / "bridge.toml"
    case.write_text(BRIDGE)
    out = tmp_path / "out"
    code, text, err = _run(capsys, str(case), "--out", str(out), "--workers", "0")
    assert code == 0, err
    assert "reference viscous lubrication" in text and "5 curves computed" in text
    assert re.search(r"^\| tiny-bridge \| viscous \| reynolds-finite \| lubrication \|", text,
                     re.MULTILINE)
    rows = list(csv.DictReader((out / "closure_errors.csv").open()))
    assert sorted(r["closure"] for r in rows) == ["reynolds", "reynolds-finite"]
    assert len(Store(out / "reference.h5")) == 5
    assert text.splitlines()[-1].startswith("wrote ")
    code, text, _ = _run(capsys, str(case), "--out", str(out), "--workers", "0", "--json")
    assert code == 0 and json.loads(text)["counts"]["reused"] == 5


def test_default_output_folder_is_named_after_the_case(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, text, err = _run(capsys, str(IMMERSED), "--models", "reynolds", "--workers", "0")
    assert code == 0, err
    assert (tmp_path / "compare-brenner-immersed-sphere-wall" / "closure_errors.csv").is_file()


@pytest.mark.parametrize(("argv", "says"), [
    (["--models", "reynolds,nosuchmodel"], "model = 'nosuchmodel'; allowed:"),
    (["--models", " , "], "--models = ' , '; allowed: model names"),
    (["--models", "toroidal,willett"], "none of the named models can be compared"),
    (["--preset", "fastest"], "invalid choice"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, argv, says):
    code, text, err = _run(capsys, str(IMMERSED), "--out", str(tmp_path / "o"), *argv)
    assert code == 2 and text == ""
    assert len(err.splitlines()) == 1 and says in err, err


def test_bad_paths_exit_2_before_any_work(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    code, _, err = _run(capsys, str(IMMERSED), "--out", str(blocker), "--models", "reynolds")
    assert code == 2 and len(err.splitlines()) == 1 and "--out" in err
    code, _, err = _run(capsys, str(tmp_path / "missing.toml"), "--out", str(tmp_path / "o"))
    assert code == 2 and len(err.splitlines()) == 1


def test_compare_is_in_the_readme_and_the_guide():
    readme = (ROOT / "README.md").read_text()
    commands = readme.split("## Three commands", 1)[1].split("\n## ", 1)[0]
    assert "wetcontact compare cases/" in commands
    assert "wetcontact compare" in (ROOT / "docs" / "jobs" / "report.md").read_text()
