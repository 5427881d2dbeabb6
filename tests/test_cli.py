"""The wetcontact command: exit codes, one-line errors, JSON output, the main job."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact.models import get_model
from wetcontact.scene import load_case

ROOT = Path(__file__).resolve().parents[1]
BAD = ROOT / "tests" / "data" / "bad_cases"

# each malformed case file and the field its message must name
EXPECTED_FIELD = {
    "bad-gap-range": "motion.gaps.points",
    "bad-kind": "geometry.kind",
    "bad-syntax": "(syntax)",
    "contact-angle-180": "liquid.contact_angle",
    "film-thinner-than-gaps": "amount.film_thickness",
    "missing-radius": "geometry.radius",
    "negative-viscosity": "liquid.viscosity",
    "radius2-on-wall": "geometry.radius2",
    "string-velocity": "motion.velocity",
    "two-amounts": "amount",
    "unknown-key": "liquid.viscocity",
    "zero-gap": "motion.gaps[0]",
}


def wc(*args: str, cwd: Path = ROOT, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wetcontact.cli", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=600,
                          env=None if env is None else {**os.environ, **env})


def test_every_bad_case_file_is_listed():
    assert {p.stem for p in BAD.glob("*.toml")} == set(EXPECTED_FIELD)


@pytest.mark.parametrize("stem", sorted(EXPECTED_FIELD))
def test_bad_case_exit_2_one_line_naming_field(stem):
    r = wc("solve", str(BAD / f"{stem}.toml"), "--model", "reynolds")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert "Traceback" not in r.stderr
    assert f"{stem}.toml" in lines[0] and EXPECTED_FIELD[stem] in lines[0]
    assert "allowed" in lines[0]


def test_unknown_model_and_bad_flag_exit_2():
    case = ROOT / "cases" / "brenner-immersed-sphere-wall.toml"
    r = wc("solve", str(case), "--model", "nope")
    assert r.returncode == 2 and "allowed" in r.stderr and "Traceback" not in r.stderr
    r = wc("solve", str(case), "--preset", "fastest")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("argv", [
    ["sweep", "cases/studies/stokes-immersed-16.toml", "--store", ""],
    ["export", "csv", "cases/studies/stokes-immersed-16.toml", "--store", "x.h5", "--out", " "],
    ["export", "python", "--out", ""],
])
def test_empty_path_flag_is_exit_2(argv):
    """An empty --store raised ValueError inside the store (exit 1, "internal error"), an
    empty --out an OSError on '.', and export python silently wrote into the current
    folder."""
    r = wc(*argv)
    assert r.returncode == 2 and "an empty path" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


def test_model_outside_validity_names_the_alternative():
    r = wc("solve", str(ROOT / "cases" / "glass-2mm-water-film.toml"), "--model", "brenner")
    assert r.returncode == 2 and "use model" in r.stderr and "Traceback" not in r.stderr


def _edited_case(tmp_path: Path, stem: str, edits: dict[str, str]) -> Path:
    """A copy of ``cases/STEM.toml`` with each line starting with a key replaced."""
    lines = (ROOT / "cases" / f"{stem}.toml").read_text().splitlines()
    for key, line in edits.items():
        at = [i for i, x in enumerate(lines) if x.startswith(key)]
        assert len(at) == 1, key
        lines[at[0]] = line
    out = tmp_path / f"{stem}-edited.toml"
    out.write_text("\n".join(lines) + "\n")
    return out


def test_refusal_hint_names_a_solver_in_a_fresh_process(tmp_path):
    """A closure refusing before the solvers are imported named the best *loaded* model
    (calibrated-capillary at 71 deg said "use model 'bagheri'", itself outside its stated
    validity there); the hint now looks at every model."""
    case = _edited_case(tmp_path, "dem-pendular-bridge-100um",
                        {"contact_angle": "contact_angle = 71.0"})
    r = wc("solve", str(case), "--model", "calibrated-capillary")
    assert r.returncode == 2 and "use model 'meniscus' instead" in r.stderr, r.stderr


@pytest.mark.parametrize("stem, edits, model, applies", [
    ("dem-pendular-bridge-100um", {"contact_angle": "contact_angle = 60.0",
                                   "gaps": "gaps = [1e-8, 1e-7, 1e-6]"}, "bagheri", "meniscus"),
    ("brenner-immersed-sphere-wall", {"gaps": "gaps = [5.0e-2, 1.0e-3]"}, "reynolds",
     "brenner"),
    ("unequal-spheres-bridge", {}, "reynolds", None),
])
def test_closure_outside_stated_validity_warns_naming_the_model(tmp_path, stem, edits,
                                                                model, applies):
    """Outside its stated validity a closure still answers (the error tables map that
    region), but says so on stderr and names the model that applies; before, only the JSON
    diagnostics said it (capillary closures) or nothing did (reynolds: 51x low at S/R = 50,
    a flooded-gap force on a bridge)."""
    case = _edited_case(tmp_path, stem, edits) if edits else ROOT / "cases" / f"{stem}.toml"
    r = wc("solve", str(case), "--model", model)
    assert r.returncode == 0, r.stderr
    warn = [x for x in r.stderr.splitlines() if "outside its stated validity" in x]
    assert len(warn) == 1 and f"model '{model}'" in warn[0], r.stderr
    assert "applies" in warn[0] and (applies is None or f"'{applies}' applies" in warn[0])
    inside = wc("solve", str(ROOT / "cases" / "brenner-immersed-sphere-wall.toml"),
                "--model", "brenner")
    assert inside.returncode == 0 and "stated validity" not in inside.stderr


def test_tolerance_and_case_model_errors_name_their_source(tmp_path):
    case = ROOT / "cases" / "willett-2000-experiment.toml"
    for flag in ("1e-13", "1"):  # the same open range as fidelity.tolerance
        r = wc("solve", str(case), "--tol", flag)
        assert r.returncode == 2 and "--tol" in r.stderr and "(1e-12, 1)" in r.stderr
    for value in ("1.0", "0.0"):  # one range in both messages (0.0 said "(1e-12, 1]")
        bad = _edited_case(tmp_path, "willett-2000-experiment",
                           {"tolerance": f"tolerance = {value}"})
        r = wc("solve", str(bad))
        assert r.returncode == 2 and str(bad) in r.stderr and "fidelity.tolerance" in r.stderr
        assert "a number in (1e-12, 1) (relative)" in r.stderr, r.stderr
    bad = _edited_case(tmp_path, "willett-2000-experiment", {"tolerance": 'model = "stoks"'})
    r = wc("solve", str(bad))
    assert r.returncode == 2 and str(bad) in r.stderr and "fidelity.model" in r.stderr


def test_solve_json_keys_and_values():
    case = ROOT / "cases" / "brenner-immersed-sphere-wall.toml"
    r = wc("solve", str(case), "--model", "brenner", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    for key in ("case", "model", "gap", "force_viscous", "force_capillary", "force_total",
                "wall_time_s", "error_estimate", "provenance"):
        assert key in out
    assert out["model"] == "brenner" and out["force_capillary"] is None
    assert len(out["gap"]) == len(out["force_total"]) == 26
    import math

    from wetcontact.reduced_models.viscous import brenner_lambda
    s, f = out["gap"][-1], out["force_viscous"][-1]
    assert f == pytest.approx(6 * math.pi * 1.2 * 1e-3 * 1e-3 * brenner_lambda(s / 1e-3),
                              rel=1e-12, abs=0)


def test_solve_by_tolerance_picks_cheapest_adequate_model():
    case = ROOT / "cases" / "brenner-immersed-sphere-wall.toml"
    out = json.loads(wc("solve", str(case), "--tol", "0.005", "--json").stdout)
    assert out["model"] == "schaeffer"  # 0.3 % fit beats 0.5 %; reynolds does not
    out = json.loads(wc("solve", str(case), "--tol", "1e-6", "--json").stdout)
    assert out["model"] == "calibrated-viscous"  # measured 5e-9, claimed at the 1e-6 floor
    out = json.loads(wc("solve", str(case), "--tol", "1e-7", "--json").stdout)
    assert out["model"] == "brenner"


def test_models_lists_registry():
    r = wc("models")
    assert r.returncode == 0
    for name in ("reynolds", "brenner", "reynolds-finite"):
        assert name in r.stdout
    from wetcontact.calibrate import FAMILIES  # the refit families are found here too

    tail = r.stdout.split("closure families to refit")[1]
    assert [ln.split()[0] for ln in tail.strip().splitlines()[1:]] == list(FAMILIES)


def test_model_names_point_to_the_refit_families(tmp_path):
    case = ROOT / "cases" / "dem-pendular-bridge-100um.toml"
    r = wc("solve", str(case), "--model", "nope")
    assert r.returncode == 2 and "a closure family: mikami-pw, mikami-pp, willett" in r.stderr
    pp = ROOT / "benchmarks" / "results" / "calibration" / "mikami-pp.json"
    r = wc("solve", str(case), "--model", "mikami", "--coefficients", str(pp))
    assert r.returncode == 2 and "allowed: --model mikami-pp" in r.stderr, r.stderr


def test_sweep_in_which_every_point_fails_exits_1(tmp_path):
    """A study whose model refuses every scene computed nothing but exited 0."""
    study = tmp_path / "s.toml"
    study.write_text(f'name = "refused"\nbase = "{ROOT / "cases" / "unequal-spheres-bridge.toml"}"'
                     '\nmodels = ["brenner"]\n[axes]\n"liquid.contact_angle" = [10.0, 20.0]\n')
    for extra in ((), ("--json",)):
        r = wc("sweep", str(study), "--workers", "0", "--store", str(tmp_path / "s.h5"), *extra)
        assert r.returncode == 1, r.stderr
        assert "every one of the 2 points failed" in r.stderr and "Traceback" not in r.stderr


def test_python_dash_m_wetcontact_is_the_cli():
    r = subprocess.run([sys.executable, "-m", "wetcontact", "solve", "nope.toml"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and r.stderr.startswith("wetcontact: error: nope.toml")


def test_help_on_every_command():
    for cmd in ([], ["run"], ["solve"], ["models"]):
        r = wc(*cmd, "--help")
        assert r.returncode == 0 and "usage" in r.stdout


def test_run_quick_writes_report(tmp_path):
    cases = tmp_path / "cases"
    cases.mkdir()
    for name in ("brenner-immersed-sphere-wall", "dem-pendular-bridge-100um"):
        shutil.copy(ROOT / "cases" / f"{name}.toml", cases)
    out = tmp_path / "reports"
    r = wc("run", "--quick", "--cases", str(cases), "--out", str(out), cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    assert (out / "README.md").exists() and (out / "closure_errors.csv").exists()
    assert (out / "curves" / "brenner-immersed-sphere-wall.png").stat().st_size > 1000
    from wetcontact.store import Store

    assert len(Store(out / "reference.h5").find(case="dem-pendular-bridge-100um")) >= 2
    from wetcontact.report import QUICK_GAPS, quick_gaps
    from wetcontact.scene import load_case

    case = load_case(cases / "dem-pendular-bridge-100um.toml")
    thin = quick_gaps(case)  # a smoke run takes at most QUICK_GAPS gaps of each case
    assert len(case.gaps) > QUICK_GAPS and len(thin.gaps) == QUICK_GAPS
    assert thin.gaps[0] == case.gaps[0] and thin.gaps[-1] == case.gaps[-1]
    assert set(thin.gaps) <= set(case.gaps) and quick_gaps(thin) == thin
    text = (out / "README.md").read_text()
    assert "| brenner-immersed-sphere-wall | viscous | reynolds | brenner |" in text


def test_run_without_cases_is_input_error(tmp_path):
    r = wc("run", "--cases", str(tmp_path), "--out", str(tmp_path / "o"), cwd=tmp_path)
    assert r.returncode == 2 and "no case files" in r.stderr


def test_solve_by_tolerance_bridge_uses_the_fe_meniscus():
    """Below calibrated-capillary's measured bound (about 4e-5 on this single-angle bridge
    between equal spheres, gaps past rupture included) the capillary force goes to the
    finite-element bridge (tested bound 1e-5 at its fastest preset), the viscous force of the
    moving bridge to lubrication; neither component is null."""
    case = ROOT / "cases" / "dem-pendular-bridge-100um.toml"
    r = wc("solve", str(case), "--tol", "1e-5", "--json")
    assert r.returncode == 0, r.stderr[-500:]
    out = json.loads(r.stdout)
    assert out["model_capillary"] == "meniscus" and out["model_viscous"] == "lubrication"
    assert out["force_viscous"] is not None and out["force_capillary"] is not None
    assert max(out["error_estimate_capillary"]) <= 1e-5


def test_solve_by_tolerance_single_angle_bridge_uses_calibrated_capillary():
    """At 1e-4 the shipped calibrated-capillary meets the tolerance on this bridge (one
    contact angle on both spheres) and is chosen; its force is checked against the FE
    bridge solved here, gap by gap (zero past rupture in both)."""
    case = ROOT / "cases" / "dem-pendular-bridge-100um.toml"
    r = wc("solve", str(case), "--tol", "1e-4", "--json")
    assert r.returncode == 0, r.stderr[-500:]
    out = json.loads(r.stdout)
    assert out["model_capillary"] == "calibrated-capillary"
    assert max(out["error_estimate_capillary"]) <= 1e-4
    scene = load_case(case)
    ref = get_model("meniscus").force(scene, preset="accurate").force_capillary
    got = np.asarray(out["force_capillary"])
    both = (ref == 0) & (got == 0)
    assert np.all(both | (np.abs(got - ref) <= 1e-4 * np.abs(ref)))


def test_json_stdout_is_one_line_even_when_meshes_are_built(tmp_path):
    """gmsh/meshio must not write to stdout: --json is one line a program can parse."""
    case = ROOT / "cases" / "brenner-immersed-sphere-wall.toml"
    r = wc("solve", str(case), "--model", "stokes", "--preset", "fast", "--json",
           env={"WETCONTACT_CACHE": str(tmp_path / "meshes")})
    assert r.returncode == 0, r.stderr[-500:]
    lines = r.stdout.splitlines()
    assert len(lines) == 1 and json.loads(lines[0])["model"] == "stokes"


BRIDGE_CASE = """
name = "{name}"
[geometry]
kind = "sphere-wall"
radius = 1.0e-3
[liquid]
viscosity = 1.0e-3
surface_tension = 0.072
density = 998.0
contact_angle = {angle}
[amount]
bridge_volume = {volume}
[motion]
velocity = 0.0
gaps = {gaps}
"""


@pytest.mark.parametrize("name, angle, volume, gaps, words", [
    ("too-much-liquid", 20.0, 2.0e-9, "[1.0e-6]", "volume"),
    ("no-bridge-angles", 170.0, 1.0e-11, "[1.0e-6]", "angle"),
])
def test_meniscus_bad_input_exit_2(tmp_path, name, angle, volume, gaps, words):
    case = tmp_path / f"{name}.toml"
    case.write_text(BRIDGE_CASE.format(name=name, angle=angle, volume=volume, gaps=gaps))
    r = wc("solve", str(case), "--model", "meniscus")
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr
    assert words in lines[0].lower()


def test_meniscus_with_every_gap_past_rupture_gives_zero_and_a_note(tmp_path):
    """No bridge at any gap: force 0, as every capillary closure gives (it was exit 2, and
    --tol, which chose meniscus, failed with it)."""
    case = tmp_path / "beyond.toml"
    case.write_text(BRIDGE_CASE.format(name="beyond", angle=20.0, volume=1.0e-11,
                                       gaps="[5.0e-4, 8.0e-4]"))
    r = wc("solve", str(case), "--model", "meniscus", "--json")
    assert r.returncode == 0, r.stderr
    assert r.stderr.strip().startswith("wetcontact: note: every gap") and "rupture" in r.stderr
    assert json.loads(r.stdout)["force_capillary"] == [0.0, 0.0]


def test_meniscus_partly_beyond_rupture_is_explicit_zero(tmp_path):
    case = tmp_path / "partly.toml"
    case.write_text(BRIDGE_CASE.format(name="partly", angle=20.0, volume=1.0e-11,
                                       gaps="[1.0e-5, 8.0e-4]"))
    out = json.loads(wc("solve", str(case), "--model", "meniscus", "--json").stdout)
    assert out["bridge_exists"] == [1.0, 0.0]
    assert out["force_capillary"][0] < 0 and out["force_capillary"][1] == 0.0
