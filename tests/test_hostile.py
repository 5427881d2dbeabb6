"""Hostile input and what a user sees (issue 14): the CLI's error boundary, --save-fields
paths, unbounded and non-finite case values, a bridge past rupture, progress on stderr, and
property-based tests that generate case files and argument combinations and check the
contract: exit 0/1/2, at most three stderr lines, no traceback, nothing written outside the
working folder, no NaN in any output."""

from __future__ import annotations

import contextlib
import errno
import io
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import wetcontact.scene as scene_mod
from wetcontact import cli
from wetcontact.errors import CaseError, InputError, short_repr
from wetcontact.models import ForceCurve, Model, get_model
from wetcontact.scene import load_case, scene_from_dict

MAX_GAPS = getattr(scene_mod, "MAX_GAPS", 100_000)  # the table form's cap
MAX_NAME = getattr(scene_mod, "MAX_NAME", 200)

ROOT = Path(__file__).resolve().parents[1]

IMMERSED = {
    "name": "imm",
    "geometry": {"kind": "sphere-wall", "radius": 1.0e-3},
    "liquid": {"viscosity": 1.0e-3, "surface_tension": 0.072, "density": 998.0},
    "amount": {"immersed": True},
    "motion": {"velocity": 0.1, "gaps": [1.0e-4]},
}
BRIDGE = {
    "name": "bridge",
    "geometry": {"kind": "sphere-sphere", "radius": 1.0e-3},
    "liquid": {"viscosity": 1.0e-3, "surface_tension": 0.072, "density": 998.0,
               "contact_angle": 20.0},
    "amount": {"bridge_volume": 1.0e-12},
    "motion": {"velocity": 0.1, "gaps": [1.0e-5, 1.0e-4]},
}
FILM = {
    "name": "film",
    "geometry": {"kind": "sphere-wall", "radius": 1.0e-3},
    "liquid": {"viscosity": 1.0e-3, "surface_tension": 0.072, "density": 998.0,
               "contact_angle": 10.0},
    "amount": {"film_thickness": 1.0e-4},
    "motion": {"velocity": 0.1, "gaps": {"start": 5e-5, "stop": 1e-6, "points": 4}},
}
FAST_MODELS = ("bagheri", "brenner", "cox-brenner", "lambert", "mikami", "rabinovich",
               "reynolds", "reynolds-finite", "schaeffer", "toroidal", "vinogradova",
               "willett", "willett-simple", "lubrication")


# ---- TOML writer for generated case files (tomllib reads only) ---------------------------


def _key(k: str) -> str:
    return k if k and all(c.isalnum() or c in "_-" for c in k) and k.isascii() else json.dumps(
        k, ensure_ascii=False)


def _val(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) \
            else repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(_val(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {_val(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_dumps(data: dict[str, Any]) -> str:
    """Top-level scalars, then one [table] per dict value; deeper dicts inline."""
    lines = [f"{_key(k)} = {_val(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, v in data.items():
        if isinstance(v, dict):
            lines.append(f"[{_key(k)}]")
            lines += [f"{_key(kk)} = {_val(vv)}" for kk, vv in v.items()]
    return "\n".join(lines) + "\n"


# ---- running the CLI in-process and checking the contract --------------------------------


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main(argv)
    return code, out.getvalue(), err.getvalue()


def tree(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): (p.read_bytes() if p.is_file() else b"<dir>")
            for p in sorted(root.rglob("*"))}


def _no_nan_json(text: str) -> None:
    def bad(const: str) -> None:
        raise AssertionError(f"non-finite {const} in JSON output")

    obj = json.loads(text, parse_constant=bad)
    assert isinstance(obj, dict)


def _no_nan_table(text: str) -> None:
    lines = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
    for ln in lines[1:]:  # the first is the column header
        vals = [float(t) for t in ln.split()]
        assert all(math.isfinite(v) for v in vals), ln


def check_contract(code: int, out: str, err: str, as_json: bool) -> None:
    assert code in (0, 1, 2), (code, err)
    assert "Traceback" not in err and "Traceback" not in out, err
    assert len(err.splitlines()) <= 3, err
    if code != 0:
        assert err.strip(), "a failure must say why on stderr"
        assert err.startswith("wetcontact"), err
    elif out.strip() and argv_is_solve(out):
        (_no_nan_json if as_json else _no_nan_table)(out)


def argv_is_solve(out: str) -> bool:
    return out.lstrip().startswith(("{", "# case"))


# ---- 1. one error boundary: exit 1/2, one line, --debug, --version ------------------------


def test_version():
    from wetcontact import __version__

    code, out, err = run_cli(["--version"])
    assert code == 0 and out.strip() == f"wetcontact {__version__}" and not err


@pytest.mark.parametrize("exc, code, words", [
    (ZeroDivisionError("float division by zero"), 1, ("internal error", "--debug")),
    (RecursionError("maximum recursion depth exceeded"), 1, ("internal error", "--debug")),
    (MemoryError(), 1, ("out of memory",)),
    (PermissionError(errno.EACCES, "Permission denied", "/no/such"), 2, ("/no/such",)),
    (FileExistsError(errno.EEXIST, "File exists", "out.vtu"), 2, ("out.vtu",)),
    (FileNotFoundError(errno.ENOENT, "No such file or directory", "x/y"), 2, ("x/y",)),
    (NotADirectoryError(errno.ENOTDIR, "Not a directory", "f/x"), 2, ("f/x",)),
    (OSError(errno.ENOSPC, "No space left on device", "r.csv"), 2, ("r.csv", "space")),
    (OSError(errno.ENAMETOOLONG, "File name too long", "x" * 300), 2, ("too long",)),
    (OSError(errno.EIO, "Input/output error"), 1, ("Input/output error",)),
])
def test_every_failure_is_one_line_exit_1_or_2(monkeypatch, exc, code, words):
    def boom() -> int:
        raise exc

    monkeypatch.setattr(cli, "_models", boom)
    monkeypatch.delenv("WETCONTACT_DEBUG", raising=False)
    got, out, err = run_cli(["models"])
    assert got == code
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert len(err) < 400
    for w in words:
        assert w in err, err


def test_debug_flag_and_env_show_the_traceback(monkeypatch):
    def boom() -> int:
        raise ZeroDivisionError("x")

    monkeypatch.setattr(cli, "_models", boom)
    monkeypatch.delenv("WETCONTACT_DEBUG", raising=False)
    code, _, err = run_cli(["--debug", "models"])
    assert code == 1 and "Traceback" in err and "ZeroDivisionError" in err
    monkeypatch.setenv("WETCONTACT_DEBUG", "1")
    code, _, err = run_cli(["models"])
    assert code == 1 and "Traceback" in err


def test_a_warning_is_one_line(monkeypatch):
    def warns() -> int:
        import warnings

        warnings.warn("overflow encountered in exp", RuntimeWarning, stacklevel=1)
        return 0

    monkeypatch.setattr(cli, "_models", warns)
    code, out, err = run_cli(["models"])
    assert code == 0 and err.count("\n") == 1
    assert err.startswith("wetcontact: warning: RuntimeWarning: overflow encountered in exp")


def test_argument_errors_return_2_in_process():
    code, out, err = run_cli(["solve", "--no-such-flag"])
    assert code == 2 and len(err.strip().splitlines()) == 1
    code, out, err = run_cli([])
    assert code == 2 and len(err.strip().splitlines()) == 1


# ---- 2. --save-fields onto bad paths; case names as file stems ---------------------------


def _case(tmp: Path, data: dict[str, Any], stem: str = "case") -> Path:
    p = tmp / f"{stem}.toml"
    p.write_text(toml_dumps(data), encoding="utf-8")
    return p


@pytest.mark.parametrize("target", ["existing-file", "under-a-file"])
def test_save_fields_onto_a_bad_path_is_one_line_exit_2(tmp_path, target):
    case = _case(tmp_path, IMMERSED)
    (tmp_path / "f").write_text("keep me")
    dest = tmp_path / "f" if target == "existing-file" else tmp_path / "f" / "sub"
    code, out, err = run_cli(["solve", str(case), "--model", "stokes", "--preset", "fast",
                              "--save-fields", str(dest)])
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "--save-fields" in err and str(tmp_path / "f") in err
    assert not out  # refused before solving
    assert (tmp_path / "f").read_text() == "keep me"


def test_save_fields_unwritable_folder(tmp_path, monkeypatch):
    case = _case(tmp_path, IMMERSED)

    def denied(*a: Any, **k: Any) -> Any:
        raise PermissionError(errno.EACCES, "Permission denied", str(tmp_path / "ro"))

    monkeypatch.setattr(tempfile, "mkstemp", denied)
    code, out, err = run_cli(["solve", str(case), "--model", "stokes", "--save-fields",
                              str(tmp_path / "ro")])
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "Permission denied" in err and "--save-fields" in err


def test_case_name_with_path_separators_stays_in_the_fields_folder(tmp_path):
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    case = _case(work, {**IMMERSED, "name": "../../escaped"})
    before = tree(tmp_path)
    code, out, err = run_cli(["solve", str(case), "--model", "stokes", "--preset", "fast",
                              "--save-fields", str(work / "fields")])
    assert code == 0, err
    new = set(tree(tmp_path)) - set(before)
    assert new and all(p.startswith(str(Path("a", "b", "fields"))) for p in new), new
    files = sorted((work / "fields").iterdir())  # the VTU and its ParaView collection
    assert [f.suffix for f in files] == [".vtu", ".pvd"], files
    assert all(f.name.startswith("stokes-") for f in files)


def test_report_curve_files_stay_in_curves_for_a_traversal_name(tmp_path):
    from wetcontact.report import CaseResult, write_case_outputs

    scene = scene_from_dict({**IMMERSED, "name": "../../escaped"})
    curve = get_model("brenner").force(scene)
    out = tmp_path / "a" / "reports"
    out.mkdir(parents=True)
    write_case_outputs(CaseResult(scene, {"brenner": curve}, {}), out)
    written = [p for p in tmp_path.rglob("*") if p.is_file()]
    assert written and all(p.parent == out / "curves" for p in written), written


def test_a_5000_character_name_is_a_case_error(tmp_path):
    case = _case(tmp_path, {**IMMERSED, "name": "x" * 5000})
    code, out, err = run_cli(["solve", str(case), "--model", "reynolds"])
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "name" in err and str(MAX_NAME) in err and len(err) < 400
    assert "(5000 chars)" in err  # the name's own length, not its quoted repr's


def test_names_with_control_characters_are_case_errors():
    with pytest.raises(CaseError, match="name"):
        scene_from_dict({**IMMERSED, "name": "two\nlines"})


# ---- 3. unbounded and non-finite case values ---------------------------------------------


class _HugeList(list):
    """Claims millions of entries; touching one fails the test (the cap must come first)."""

    def __len__(self) -> int:
        return 3_700_000

    def __iter__(self):
        raise AssertionError("gaps converted before the length check")

    def __getitem__(self, i):
        raise AssertionError("gaps converted before the length check")


def test_gap_list_longer_than_the_table_cap_is_refused_before_conversion():
    with pytest.raises(CaseError, match=r"motion\.gaps.*100000"):
        scene_from_dict({**IMMERSED, "motion": {"velocity": 0.1, "gaps": _HugeList()}})
    ok = [1e-5] * MAX_GAPS
    assert len(scene_from_dict({**IMMERSED, "motion": {"velocity": 0.1, "gaps": ok}}).gaps) \
        == MAX_GAPS
    with pytest.raises(CaseError, match=r"motion\.gaps"):
        scene_from_dict({**IMMERSED, "motion": {"velocity": 0.1, "gaps": ok + [1e-5]}})


NUMERIC_FIELDS = [
    ("geometry", "radius", IMMERSED), ("liquid", "viscosity", IMMERSED),
    ("liquid", "surface_tension", IMMERSED), ("liquid", "density", IMMERSED),
    ("liquid", "gravity", IMMERSED), ("liquid", "contact_angle", IMMERSED),
    ("liquid", "slip_length_sphere", IMMERSED), ("liquid", "slip_length_wall", IMMERSED),
    ("motion", "velocity", IMMERSED), ("motion", "gaps", IMMERSED),
    ("amount", "bridge_volume", BRIDGE), ("amount", "film_thickness", FILM),
    ("particle", "density", IMMERSED), ("fidelity", "tolerance", IMMERSED),
    ("geometry", "radius2", BRIDGE),
]
HOSTILE_NUMBERS = [math.nan, math.inf, -math.inf, 1e308, -1e308, 10**400, -(10**400), None,
                   "1e-3", [1e-3, [2e-3]], {"a": 1}, True]


@pytest.mark.parametrize("table, key, base", NUMERIC_FIELDS)
@pytest.mark.parametrize("value", HOSTILE_NUMBERS, ids=short_repr)
def test_every_numeric_field_refuses_non_finite_huge_and_wrong_types(table, key, base, value):
    data = json.loads(json.dumps(base))
    data.setdefault(table, {})[key] = value
    with pytest.raises(CaseError) as info:
        scene_from_dict(data)
    assert f"{table}.{key}" in str(info.value) and len(str(info.value)) < 400


@pytest.mark.parametrize("key", ["start", "stop", "points"])
@pytest.mark.parametrize("value", HOSTILE_NUMBERS, ids=short_repr)
def test_gap_table_fields_refuse_hostile_values(key, value):
    data = json.loads(json.dumps(FILM))
    data["motion"]["gaps"][key] = value
    with pytest.raises(CaseError, match=f"motion.gaps.{key}"):
        scene_from_dict(data)


@pytest.mark.parametrize("value", [math.nan, 10**400, -1e-5, None, "x"], ids=short_repr)
def test_each_gap_in_a_list_is_checked(value):
    with pytest.raises(CaseError, match=r"motion\.gaps\[1\]"):
        scene_from_dict({**IMMERSED, "motion": {"velocity": 0.1, "gaps": [1e-5, value]}})


@pytest.mark.parametrize("text", [
    "a = " + "[" * 100_000 + "]" * 100_000,
    "name = 'a'\nname = 'b'\n",
    "x = { " * 5000 + "}" * 5000,
    "name = \"\x00\"",
])
def test_deeply_nested_duplicate_and_binary_toml_is_a_case_error(tmp_path, text):
    p = tmp_path / "deep.toml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(CaseError):
        load_case(p)


def test_non_utf8_and_folder_case_paths(tmp_path):
    p = tmp_path / "bin.toml"
    p.write_bytes(b"\xff\xfe\x00name")
    with pytest.raises(CaseError, match="UTF-8"):
        load_case(p)
    with pytest.raises(CaseError):
        load_case(tmp_path)


# ---- 4. a bridge far past rupture -----------------------------------------------------


@pytest.mark.parametrize("kind", ["sphere-sphere", "sphere-wall"])
def test_toroidal_bridge_far_past_rupture_gives_zero_force(kind):
    data = json.loads(json.dumps(BRIDGE))
    data["geometry"]["kind"] = kind
    data["motion"]["gaps"] = [0.05, 0.09]
    curve = get_model("toroidal").force(scene_from_dict(data))
    assert np.all(curve.force_capillary == 0.0)
    # the same scene with a gap inside rupture still gives the attraction
    data["motion"]["gaps"] = [1e-6, 0.05]
    curve = get_model("toroidal").force(scene_from_dict(data))
    assert curve.force_capillary[0] < 0.0 and curve.force_capillary[1] == 0.0


def test_toroidal_function_past_its_existence_is_an_error_not_a_root_finder_crash():
    from wetcontact.errors import SolverError
    from wetcontact.reduced_models.capillary import toroidal_bridge

    with pytest.raises((InputError, SolverError)):
        toroidal_bridge([0.09], 1e-12, 1e-3, 0.072, 0.3, kind="sphere-sphere")


@pytest.mark.parametrize("name", FAST_MODELS)
def test_every_fast_model_past_rupture_gives_a_curve_or_a_one_line_error(name):
    data = json.loads(json.dumps(BRIDGE))
    data["motion"]["gaps"] = [0.05, 0.09]
    try:
        curve = get_model(name).force(scene_from_dict(data))
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    assert np.all(np.isfinite(curve.force_total))


@pytest.mark.parametrize("volume, gap", [(1e-16, 1.0), (1e-20, 1e-3), (1e-24, 0.5)])
def test_lubrication_tiny_bridge_far_apart_is_the_parallel_disk_squeeze(volume, gap):
    """Found by the property tests: a bridge far smaller than its gap gave 'non-finite
    pressure' (the ln h grading degenerates when h is flat over the wetted zone). The gap
    varies by < 1e-9 relative there, so the parallel-disk squeeze film
    F = 3 pi eta v r_w^4 / (2 S^3), with pi r_w^2 S = V, holds to about 1e-9."""
    data = {**IMMERSED, "geometry": {"kind": "sphere-wall", "radius": 1.0},
            "amount": {"bridge_volume": volume},
            "motion": {"velocity": 0.1, "gaps": [gap, 2 * gap]}}
    curve = get_model("lubrication").force(scene_from_dict(data))
    s = np.array([gap, 2 * gap])
    xi = volume / (np.pi * s)
    ref = 3 * np.pi * 1e-3 * 0.1 * xi**2 / (2 * s**3)
    assert np.allclose(curve.force_viscous, ref, rtol=1e-6, atol=0.0)


# ---- 5. progress on stderr for a slow model ------------------------------------------------


class _Slow(Model):
    name = "slow-test-model"
    component = "viscous"

    def _force(self, scene, preset, **opts):
        time.sleep(0.35)
        return ForceCurve(case=scene.name, model=self.name, gap=scene.gap_array,
                          force_viscous=np.ones(scene.gap_array.size), force_capillary=None)


def test_slow_solve_prints_progress_lines_on_stderr_not_stdout(tmp_path, monkeypatch):
    monkeypatch.setattr(cli, "PROGRESS_EVERY", 0.1)
    import wetcontact.models as models

    monkeypatch.setitem(models.MODELS, _Slow.name, _Slow())
    case = _case(tmp_path, IMMERSED)
    code, out, err = run_cli(["solve", str(case), "--model", _Slow.name, "--json"])
    assert code == 0, err
    assert json.loads(out)["force_viscous"] == [1.0]
    lines = err.strip().splitlines()
    assert len(lines) >= 2 and all("still solving" in ln and _Slow.name in ln for ln in lines)


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_on_a_terminal_is_one_redrawn_line_erased_at_the_end(monkeypatch):
    monkeypatch.setattr(cli, "PROGRESS_EVERY", 0.1)
    stream = _Tty()
    with cli.Progress("case with model 'x'", stream=stream):
        time.sleep(0.5)
    text = stream.getvalue()
    assert "\n" not in text and text.count("\r") >= 3 and text.endswith("\r\x1b[K")
    assert "solving case with model 'x'" in text


class _NanDiag(_Slow):
    name = "nan-diagnostics-test-model"

    def _force(self, scene, preset, **opts):
        return ForceCurve(case=scene.name, model=self.name, gap=scene.gap_array,
                          force_viscous=np.ones(scene.gap_array.size), force_capillary=None,
                          diagnostics={"residual": float("nan")})


def test_a_nan_in_diagnostics_never_reaches_json_stdout(tmp_path, monkeypatch):
    import wetcontact.models as models

    monkeypatch.setitem(models.MODELS, _NanDiag.name, _NanDiag())
    case = _case(tmp_path, IMMERSED)
    code, out, err = run_cli(["solve", str(case), "--model", _NanDiag.name, "--json"])
    assert code == 1 and out == "" and "non-finite" in err
    assert len(err.strip().splitlines()) == 1


def test_debug_flag_works_after_the_subcommand(monkeypatch):
    def boom() -> int:
        raise ZeroDivisionError("x")

    monkeypatch.setattr(cli, "_models", boom)
    monkeypatch.delenv("WETCONTACT_DEBUG", raising=False)
    code, _, err = run_cli(["models", "--debug"])
    assert code == 1 and "Traceback" in err


def test_fast_solve_prints_nothing_on_stderr(tmp_path):
    case = _case(tmp_path, IMMERSED)
    code, out, err = run_cli(["solve", str(case), "--model", "brenner", "--json"])
    assert code == 0 and err == "" and json.loads(out)["model"] == "brenner"


# ---- 6. property-based: generated case files and argument combinations -------------------

COUNTER: dict[str, int] = {"cases": 0, "argv": 0, "exit 0": 0, "exit 1": 0, "exit 2": 0}

_hostile_text = st.one_of(
    st.text(st.characters(exclude_categories=("Cs",)), max_size=40),
    st.sampled_from(["../../x", "a/b", "..", ".", "/etc/passwd", "C:\\x", "\\..\\y", "nul",
                     "x" * 5000, "é" * 300, "\u202e", "line\nbreak", "", " "]),
)
_hostile_number = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=1e-12, max_value=1e3),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.sampled_from([0, -1, 0.0, -0.0, 1e-300, 5e-324, 1e308]),
)
_leaf = st.one_of(_hostile_number, _hostile_text, st.booleans())
_value = st.recursive(_leaf, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=6), inner, max_size=3)),
    max_leaves=12)


def _nested(depth: int) -> list:
    out: list = []
    for _ in range(depth):
        out = [out]
    return out


_deep = st.integers(1, 60).map(_nested)

FIELDS = [("name",), ("description",), ("geometry", "kind"), ("geometry", "radius"),
          ("geometry", "radius2"), ("liquid", "viscosity"), ("liquid", "surface_tension"),
          ("liquid", "density"), ("liquid", "contact_angle"), ("liquid", "gravity"),
          ("liquid", "contact_angle_wall"), ("liquid", "slip_length_wall"),
          ("amount", "bridge_volume"), ("amount", "film_thickness"), ("amount", "immersed"),
          ("motion", "velocity"), ("motion", "gaps"), ("fidelity", "model"),
          ("fidelity", "tolerance"), ("particle", "density"), ("geometry",), ("motion",),
          ("unknown",), ("liquid", "unknown_key")]


@st.composite
def case_files(draw) -> tuple[str, str]:
    """A case file's text (a valid base with 0-3 hostile mutations, sometimes with raw
    hostile text appended) and the base's name."""
    which = draw(st.sampled_from(["immersed", "bridge", "film"]))
    base = json.loads(json.dumps({"immersed": IMMERSED, "bridge": BRIDGE, "film": FILM}[which]))
    for _ in range(draw(st.sampled_from([0, 0, 0, 1, 1, 1, 2, 3]))):
        path = draw(st.sampled_from(FIELDS))
        action = draw(st.sampled_from(["set", "set", "delete", "deep", "physical",
                                       "physical", "physical"]))
        parent = base
        for p in path[:-1]:
            parent = parent.setdefault(p, {}) if isinstance(parent, dict) else {}
        if not isinstance(parent, dict):
            continue
        if action == "delete":
            parent.pop(path[-1], None)
        elif action == "deep":
            parent[path[-1]] = draw(_deep)
        elif action == "physical":  # plausible magnitudes: exercises the models, not parsing
            parent[path[-1]] = draw(st.floats(1e-9, 1e-2) | st.lists(
                st.floats(1e-9, 1e-2), min_size=1, max_size=5))
        else:
            parent[path[-1]] = draw(_value)
    text = toml_dumps(base)
    extra = draw(st.sampled_from([""] * 12 + ["name = \"dup\"\n", "[liquid]\n", "\x00",
                                              "[[geometry]]\n"]))
    return text + extra, which


#: models that apply to each base case, drawn most of the time so that most inputs solve
APPLIES = {"immersed": ("brenner", "cox-brenner", "reynolds", "schaeffer", "vinogradova"),
           "bridge": ("bagheri", "lambert", "mikami", "rabinovich", "toroidal", "willett",
                      "willett-simple", "reynolds-finite", "lubrication"),
           "film": ("reynolds-finite", "lubrication")}


def _solve_argv(draw, case: str, out: str, which: str) -> list[str]:
    argv = ["solve", case]
    model = draw(st.sampled_from(APPLIES[which]) if draw(st.integers(0, 4))
                 else st.sampled_from(FAST_MODELS + ("nope", "")))
    argv += ["--model", model]
    if draw(st.booleans()):
        argv.append("--json")
    if draw(st.booleans()):
        argv += ["--preset", draw(st.sampled_from(["fast", "default", "accurate"] * 3 + ["x"]))]
    if draw(st.integers(0, 4)) == 0:
        argv += ["--save-fields", draw(st.sampled_from([out, "../../escape", "f"]))]
    if draw(st.integers(0, 9)) == 0:
        argv.append(draw(st.sampled_from(["--unknown", "-x", "--", "--json=1", "\x00"])))
    return argv


def _run_in_sandbox(text: str, make_argv) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        work = root / "outer" / "work"
        work.mkdir(parents=True)
        (work / "case.toml").write_text(text, encoding="utf-8", errors="surrogatepass")
        (work / "f").write_text("a plain file")
        before = tree(root)
        old = os.getcwd()
        os.chdir(work)
        try:
            argv = make_argv("case.toml", "fields")
            code, out, err = run_cli(argv)
        finally:
            os.chdir(old)
        after = tree(root)
        changed = {k for k in set(before) | set(after) if before.get(k) != after.get(k)}
        assert all(k.startswith(str(Path("outer", "work", "fields"))) for k in changed), \
            (argv, changed)
        check_contract(code, out, err, "--json" in argv)
        COUNTER[f"exit {code}"] += 1
        if os.environ.get("WETCONTACT_HOSTILE_LOG"):
            with open(os.environ["WETCONTACT_HOSTILE_LOG"], "a") as fh:
                fh.write(f"{code}\t{err.strip()[:160]!r}\n")


def _log_uniform(lo: float, hi: float):
    """Log-uniform in the open interval (lo, hi] of a validated field."""
    return st.floats(math.log10(lo) + 1e-9, math.log10(hi)).map(lambda e: 10.0**e)


@st.composite
def physical_cases(draw) -> tuple[str, str]:
    """A case that passes validation, with every value drawn across its whole allowed range
    (the corners the closures' formulas were never fitted for) and a model for it."""
    kind = draw(st.sampled_from(["sphere-wall", "sphere-sphere"]))
    r = draw(_log_uniform(1e-8, 10.0))
    amount = draw(st.sampled_from(["immersed", "bridge"] + (["film"] if kind == "sphere-wall"
                                                              else [])))
    gaps = draw(st.lists(_log_uniform(max(1e-6 * r, scene_mod.MIN_GAP), 100.0 * r),
                         min_size=1, max_size=6))  # MIN_GAP: the smallest gap (1e-12 m)
    data: dict[str, Any] = {
        "name": draw(_hostile_text.filter(lambda t: t.strip() and t.isprintable()
                                          and len(t) <= 200)),
        "geometry": {"kind": kind, "radius": r},
        "liquid": {"viscosity": draw(_log_uniform(1e-7, 1e5)),
                   "surface_tension": draw(_log_uniform(1e-5, 10.0)),
                   "density": draw(_log_uniform(1e-3, 3e4)),
                   "contact_angle": draw(st.floats(0.0, 179.9))},
        "motion": {"velocity": draw(st.floats(-1e3, 1e3)), "gaps": gaps},
    }
    if kind == "sphere-sphere" and draw(st.booleans()):
        data["geometry"]["radius2"] = draw(_log_uniform(1e-8, 10.0))
    if amount == "immersed":
        data["amount"] = {"immersed": True}
    elif amount == "bridge":
        data["amount"] = {"bridge_volume": draw(_log_uniform(1e-30, 4.18 * r**3))}
    else:
        lo, u = min(gaps) * 1.001, draw(st.floats(0.0, 1.0))
        data["amount"] = {"film_thickness": lo * (10 * r / lo) ** u if lo < 10 * r else lo}
    if draw(st.booleans()):
        data["liquid"]["slip_length_wall"] = draw(st.floats(0.0, r))
    model = draw(st.sampled_from(APPLIES[amount]) if draw(st.integers(0, 3))
                 else st.sampled_from(FAST_MODELS))
    return toml_dumps(data), model


@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(case=physical_cases(), as_json=st.booleans())
def test_generated_physical_scenes_keep_the_contract(case, as_json):
    COUNTER["physical"] = COUNTER.get("physical", 0) + 1
    text, model = case
    _run_in_sandbox(text, lambda path, out: ["solve", path, "--model", model]
                    + (["--json"] if as_json else []))


N_EXAMPLES = 150


@settings(max_examples=N_EXAMPLES, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(case=case_files(), data=st.data())
def test_generated_case_files_keep_the_contract(case, data):
    COUNTER["cases"] += 1
    _run_in_sandbox(case[0], lambda path, out: _solve_argv(data.draw, path, out, case[1]))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(argv=st.lists(st.one_of(
    st.sampled_from(["solve", "models", "run", "--json", "--model", "--preset", "--tol",
                     "--save-fields", "--debug", "--version", "--help", "-h", "case.toml",
                     "reynolds", "fast", "--quick", "--full", "--out", "--resume"]),
    _hostile_text), max_size=6))
def test_generated_argument_lists_keep_the_contract(argv):
    COUNTER["argv"] += 1
    if "run" in argv and "--help" not in argv and "-h" not in argv and "--version" not in argv:
        argv = [a for a in argv if a != "run"]  # the main job is not a fast test
    argv = [a for a in argv if a != "--tol"]  # model selection: select.py's own tests
    _run_in_sandbox(toml_dumps(IMMERSED), lambda case, out: argv)


@pytest.mark.slow
@settings(max_examples=2000, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(case=case_files(), data=st.data())
def test_generated_case_files_keep_the_contract_many(case, data):
    COUNTER["cases"] += 1
    _run_in_sandbox(case[0], lambda path, out: _solve_argv(data.draw, path, out, case[1]))


@pytest.mark.slow
@settings(max_examples=2000, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(case=physical_cases(), as_json=st.booleans())
def test_generated_physical_scenes_keep_the_contract_many(case, as_json):
    test_generated_physical_scenes_keep_the_contract.hypothesis.inner_test(case, as_json)


# ---- generated study files (sweep and export csv) ------------------------------------------

STUDY_FIELDS = ("liquid.contact_angle", "liquid.viscosity", "geometry.radius",
                "motion.velocity", "amount.bridge_volume", "motion.gap_over_radius",
                "motion.gap_over_rupture", "amount.volume_over_radius3",
                "geometry.radius_ratio", "motion.capillary_number", "motion.gaps")
_small_points = st.sampled_from([0, -1, 1, 2, 3, 10**9, 2**63, float("nan"), 1.5, "3", True])
_axis_value = st.one_of(
    st.lists(_hostile_number, min_size=0, max_size=4),
    st.fixed_dictionaries({"start": _hostile_number, "stop": _hostile_number,
                           "points": _small_points,
                           "spacing": st.sampled_from(["log", "linear", "cubic", "", 3])}),
    st.fixed_dictionaries({"min": _hostile_number, "max": _hostile_number}),
    _leaf)


_valid_axes = {
    "liquid.contact_angle": st.sampled_from([[0.0, 20.0], [40.0], [10.0, 30.0, 60.0]]),
    "amount.volume_over_radius3": st.sampled_from(
        [{"start": 1e-3, "stop": 1e-2, "points": 2, "spacing": "log"}, [1e-3, 0.02]]),
    "motion.gap_over_radius": st.sampled_from([[0.01, 0.1], {"start": 0.001, "stop": 0.05,
                                                              "points": 3}]),
    "liquid.viscosity": st.sampled_from([[1e-3, 1e-2]]),
    "motion.gap_over_rupture": st.sampled_from([[0.1, 0.5], [0.9]]),
}


def _maybe_hostile(draw, valid, hostile):
    """The valid value three times in four, else a hostile one."""
    return draw(hostile) if draw(st.integers(0, 3)) == 0 else draw(valid)


@st.composite
def study_files(draw) -> str:
    """A valid study on a bridge case with cheap models (sweeps stay in-process and fast),
    with each part replaced by a hostile value one time in four: names, bases, model lists,
    axis paths and values, presets, samples and unknown keys."""
    axes = {}
    for key in draw(st.lists(st.sampled_from(sorted(_valid_axes)), min_size=1, max_size=2,
                             unique=True)):
        if draw(st.integers(0, 3)) == 0:
            key = draw(st.one_of(st.sampled_from(STUDY_FIELDS), _hostile_text))
            axes[key] = draw(_axis_value)
        else:
            axes[key] = _maybe_hostile(draw, _valid_axes[key], _axis_value)
    data: dict[str, Any] = {
        "name": _maybe_hostile(draw, st.just("hostile-study"), _hostile_text),
        "base": _maybe_hostile(draw, st.just("base.toml"), _hostile_text),
        "models": _maybe_hostile(
            draw, st.lists(st.sampled_from(["willett", "toroidal", "reynolds", "lubrication",
                                            "bagheri"]), min_size=1, max_size=3, unique=True),
            st.one_of(st.lists(_hostile_text, max_size=3), _leaf)),
        "axes": axes,
    }
    if draw(st.booleans()):
        data["preset"] = _maybe_hostile(draw, st.sampled_from(["fast", "default"]),
                                        _hostile_text)
    if draw(st.integers(0, 3)) == 0:
        data["sample"] = {"method": draw(st.sampled_from(["latin-hypercube", "grid", ""])),
                          "points": draw(_small_points), "seed": draw(_hostile_number)}
    if draw(st.integers(0, 5)) == 0:
        data[draw(_hostile_text) or "x"] = draw(_leaf)
    return toml_dumps(data)


def _run_study_in_sandbox(text: str, runs: list[list[str]]) -> list[int]:
    """Each argv of ``runs`` in turn, in one sandbox (base.toml, study.toml, fields/)."""
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        work = root / "outer" / "work"
        (work / "fields").mkdir(parents=True)
        (work / "base.toml").write_text(toml_dumps(BRIDGE), encoding="utf-8")
        (work / "study.toml").write_text(text, encoding="utf-8", errors="surrogatepass")
        before = tree(root)
        codes = []
        for argv in runs:
            old = os.getcwd()
            os.chdir(work)
            try:
                code, out, err = run_cli(argv)
            finally:
                os.chdir(old)
            check_contract(code, out, err, False)
            if code == 0 and "--json" in argv:
                _no_nan_json(out)
            COUNTER["studies"] = COUNTER.get("studies", 0) + 1
            COUNTER[f"exit {code}"] += 1
            if os.environ.get("WETCONTACT_HOSTILE_LOG"):
                with open(os.environ["WETCONTACT_HOSTILE_LOG"], "a") as fh:
                    fh.write(f"{argv[0]}\t{code}\t{err.strip()[:160]!r}\n")
            codes.append(code)
        after = tree(root)
        changed = {k for k in set(before) | set(after) if before.get(k) != after.get(k)}
        assert all(k.startswith(str(Path("outer", "work", "fields"))) for k in changed), \
            (runs, changed)
        return codes


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(study=study_files())
def test_generated_study_files_keep_the_contract(study):
    """Issue 14: generated study files, valid and hostile, through `sweep` (in-process,
    --json) and then `export csv` of the same store: exit in {0, 1, 2}, at most three
    stderr lines, no traceback, no NaN in the JSON, nothing written outside the store's
    folder; a study that sweeps also exports."""
    codes = _run_study_in_sandbox(study, [
        ["sweep", "study.toml", "--store", "fields/s.h5", "--workers", "0", "--json"],
        ["export", "csv", "study.toml", "--store", "fields/s.h5", "--out", "fields/o.csv"]])
    if codes[0] == 0:
        assert codes[1] == 0


@pytest.mark.slow
@settings(max_examples=1000, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(study=study_files())
def test_generated_study_files_keep_the_contract_many(study):
    test_generated_study_files_keep_the_contract.hypothesis.inner_test(study)


def test_report_the_count():
    """Runs last in this file: the number of generated inputs the property tests ran."""
    sys.stderr.write(f"\nhostile inputs run: {COUNTER}\n")
    if COUNTER["cases"]:
        assert COUNTER["cases"] >= N_EXAMPLES


# ---- a few through a real subprocess -------------------------------------------------------


def test_subprocess_hostile_cases_one_line_no_traceback(tmp_path):
    for i, data in enumerate([{**IMMERSED, "name": "x" * 5000},
                              {**BRIDGE, "motion": {"velocity": 0.1, "gaps": [0.05, 0.09]}}]):
        case = _case(tmp_path, data, f"c{i}")
        r = subprocess.run([sys.executable, "-m", "wetcontact.cli", "solve", str(case),
                            "--model", "toroidal", "--json"], capture_output=True, text=True,
                           timeout=120, cwd=tmp_path)
        assert r.returncode in (0, 2) and "Traceback" not in r.stderr
        assert len(r.stderr.strip().splitlines()) <= 1
        if r.returncode == 0:
            _no_nan_json(r.stdout)


def test_a_closed_pipe_stops_quietly(tmp_path):
    data = {**IMMERSED, "motion": {"velocity": 0.1,
                                   "gaps": {"start": 1e-4, "stop": 1e-6, "points": 3000}}}
    case = _case(tmp_path, data)
    proc = subprocess.Popen([sys.executable, "-m", "wetcontact.cli", "solve", str(case),
                             "--model", "reynolds"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, cwd=tmp_path)
    assert proc.stdout.readline().startswith(b"# case")
    proc.stdout.close()  # like `| head -1`
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) in (0, 1)
    assert "Traceback" not in err and "Exception ignored" not in err and "Broken" not in err
