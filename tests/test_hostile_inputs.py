"""Bad input that must be one clear line with exit 2 (issue 58): deeply nested tables,
FIFOs, devices and huge files as inputs, an empty ``--closure``, integers beyond the float
range in a study, gaps below any physical scale, a full disk during a sweep, bad output
paths found before any work, one stderr line per error, and a quiet interrupted sweep.

Each test runs the CLI (in this process through :func:`wetcontact.cli.main`, or as a
subprocess where a hang, a signal or the interpreter's exit is what is tested) and checks
the exit code, that stderr is exactly one line, and the field or flag that line names.
"""

from __future__ import annotations

import contextlib
import io
import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import pytest
from conftest import IMMERSED_TOML

from wetcontact import cli
from wetcontact.errors import CaseError
from wetcontact.fileio import MAX_INPUT_BYTES, MAX_NESTING, nesting_depth
from wetcontact.scene import load_case, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
FILM_CASE = ROOT / "cases" / "glass-2mm-water-film.toml"
WILLETT_JSON = ROOT / "benchmarks" / "results" / "calibration" / "willett.json"



def run_cli(argv: list[str]) -> tuple[int, str, str]:
    """``wetcontact ARGV`` in this process: exit code, stdout, stderr."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main(argv)
    return code, out.getvalue(), err.getvalue()


def one_error_line(code: int, err: str, *words: str, exit_code: int = 2) -> str:
    """Assert exit ``exit_code`` and exactly one stderr line holding every word; return it."""
    assert code == exit_code, (code, err)
    lines = err.splitlines()
    assert len(lines) == 1, err
    line = lines[0]
    assert line.startswith("wetcontact: error: "), line
    assert "Traceback" not in line and "internal error" not in line, line
    for w in words:
        assert w in line, (w, line)
    return line


def study(tmp_path: Path, body: str, base: Path = FILM_CASE, name: str = "s.toml") -> Path:
    """A study file in ``tmp_path`` on ``base`` with the ``reynolds`` model."""
    p = tmp_path / name
    p.write_text(f'name = "s"\nbase = "{base}"\nmodels = ["reynolds"]\n' + body,
                 encoding="utf-8")
    return p


# ---- 1. deeply nested tables ---------------------------------------------------------------


@pytest.mark.parametrize("depth", [40, 400, 1000])
def test_a_deeply_nested_table_is_one_short_line(tmp_path, depth):
    """1000 levels of ``[a.a.a...]`` was exit 1 (RecursionError while the value was shown),
    400 levels exit 2 with the nested value in the line."""
    p = tmp_path / "deep.toml"
    p.write_text("[" + ".".join(["a"] * depth) + "]\nx = 1\n")
    code, out, err = run_cli(["solve", str(p), "--model", "reynolds"])
    line = one_error_line(code, err, "deep.toml", "(syntax)", f"{depth + 1} levels",
                          f"at most {MAX_NESTING} levels")
    assert len(line) - len(str(p)) < 160 and not out  # short: no part of the value
    code, _, err = run_cli(["sweep", str(p), "--store", str(tmp_path / "s.h5")])
    one_error_line(code, err, "deep.toml", "(syntax)")
    base = study(tmp_path, "", base=p)
    code, _, err = run_cli(["sweep", str(base), "--store", str(tmp_path / "s.h5")])
    one_error_line(code, err, "s.toml", "of base", "deep.toml", "(syntax)")


def test_nesting_depth_needs_no_recursion_and_the_formats_stay_well_inside():
    deep: dict = {}
    d = deep
    for _ in range(100_000):
        d["a"] = {}
        d = d["a"]
    assert nesting_depth(deep) == 100_001
    assert nesting_depth({"motion": {"gaps": {"start": 1}}, "x": [[1]]}) == 3
    for f in [*ROOT.glob("cases/*.toml"), *ROOT.glob("cases/studies/*.toml")]:
        assert nesting_depth(tomllib.loads(f.read_text())) <= 4 < MAX_NESTING, f


def test_a_dict_nested_too_deep_for_repr_is_a_case_error():
    """Through the Python API the value of a bad key was shown with ``repr``."""
    deep: dict = {}
    d = deep
    for _ in range(5000):
        d["a"] = {}
        d = d["a"]
    with pytest.raises(CaseError, match="nested too deep to show"):
        scene_from_dict({"name": "x", "a": deep})


# ---- 5. FIFOs, devices, folders and huge files as inputs --------------------------------------


def _fifo(tmp_path: Path, name: str) -> Path:
    p = tmp_path / name
    os.mkfifo(p)
    return p


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_a_fifo_as_case_study_or_coefficient_file_is_refused_at_once(tmp_path):
    """A FIFO as the case file hung forever (the read waits for a writer): a subprocess
    with a timeout, so a regression fails instead of hanging the suite."""
    fifo_toml, fifo_json = _fifo(tmp_path, "case.toml"), _fifo(tmp_path, "k.json")
    runs = [
        (["solve", str(fifo_toml), "--model", "reynolds"], "case.toml"),
        (["sweep", str(fifo_toml), "--store", str(tmp_path / "s.h5")], "case.toml"),
        (["sweep", str(study(tmp_path, "", base=fifo_toml)), "--store",
          str(tmp_path / "s.h5")], "of base"),
        (["solve", str(FILM_CASE), "--model", "willett", "--coefficients", str(fifo_json)],
         "k.json"),
        (["export", "python", "--out", str(tmp_path / "x.py"), "--capillary",
          str(fifo_json)], "k.json"),
    ]
    for argv, word in runs:
        t0 = time.monotonic()
        r = subprocess.run([sys.executable, "-m", "wetcontact.cli", *argv],
                           capture_output=True, text=True, timeout=60, cwd=tmp_path)
        one_error_line(r.returncode, r.stderr, word, "a FIFO (named pipe)",
                       "allowed: a regular file")
        assert time.monotonic() - t0 < 30


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_dev_zero_and_a_folder_are_refused_before_a_byte_is_read(tmp_path):
    """``/dev/zero`` as the case file read until memory ran out."""
    for argv, word in [
            (["solve", "/dev/zero", "--model", "reynolds"], "/dev/zero"),
            (["sweep", "/dev/zero", "--store", str(tmp_path / "s.h5")], "/dev/zero"),
            (["solve", str(FILM_CASE), "--model", "willett", "--coefficients", "/dev/zero"],
             "/dev/zero")]:
        code, _, err = run_cli(argv)
        one_error_line(code, err, word, "(file) = 'a character device'")
    code, _, err = run_cli(["solve", str(tmp_path), "--model", "reynolds"])
    one_error_line(code, err, str(tmp_path), "(file) = 'a folder'")


def test_a_file_over_the_size_limit_is_refused_without_reading_it(tmp_path, monkeypatch):
    big = tmp_path / "big.toml"
    with open(big, "wb") as fh:  # sparse: no disk space, no time
        fh.truncate(MAX_INPUT_BYTES + 1)
    code, _, err = run_cli(["solve", str(big), "--model", "reynolds"])
    one_error_line(code, err, "big.toml", f"'{MAX_INPUT_BYTES + 1} bytes'",
                   f"at most {MAX_INPUT_BYTES} bytes")
    code, _, err = run_cli(["solve", str(FILM_CASE), "--model", "willett", "--coefficients",
                            str(big)])
    one_error_line(code, err, "big.toml", f"at most {MAX_INPUT_BYTES} bytes")
    ok = tmp_path / "ok.toml"  # at the limit a case file still reads
    ok.write_text(IMMERSED_TOML.format(gaps="[1e-4]") + "#" * (MAX_INPUT_BYTES - 300) + "\n")
    assert ok.stat().st_size <= MAX_INPUT_BYTES
    assert load_case(ok).gaps == (1e-4,)


# ---- 2. an empty name where a choice is asked for ---------------------------------------------


def test_export_json_with_an_empty_closure_names_the_flag_and_the_choices(tmp_path):
    """``--closure ''`` was exit 1 (TypeError: the empty name read as no name)."""
    code, out, err = run_cli(["export", "json", "--closure", "", "--out",
                              str(tmp_path / "x.json")])
    one_error_line(code, err, "--closure = ''", "allowed: 'calibrated-viscous', "
                   "'calibrated-capillary'")
    assert not out and not (tmp_path / "x.json").exists()


def test_solve_with_an_empty_model_is_refused_not_the_case_default():
    """``--model ''`` silently ran the case's own choice of model."""
    code, out, err = run_cli(["solve", str(FILM_CASE), "--model", ""])
    one_error_line(code, err, "--model = ''", "allowed: a model name")
    assert not out


# ---- 3. integers beyond the float range in a study --------------------------------------------

HUGE = "1" + "0" * 400  # an integer TOML reads exactly and float() cannot hold


@pytest.mark.parametrize("body, field", [
    (f'[axes]\n"liquid.contact_angle" = {{ start = {HUGE}, stop = 10, points = 2 }}\n',
     "axes.liquid.contact_angle.start"),
    (f'[axes]\n"liquid.viscosity" = {{ start = 1e-3, stop = -{HUGE}, points = 2 }}\n',
     "axes.liquid.viscosity.stop"),
    (f'[axes]\n"liquid.contact_angle" = [{HUGE}, 10]\n', "axes.liquid.contact_angle[0]"),
    (f'[axes]\n"motion.gap_over_film" = [0.5, {HUGE}]\n', "axes.motion.gap_over_film[1]"),
    (f'[axes]\n"liquid.viscosity" = [1e-3]\n[set]\n"motion.gap_over_film" = {HUGE}\n',
     "set.motion.gap_over_film"),
    (f'[axes]\n"liquid.viscosity" = [1e-3]\n[set]\n"liquid.density" = {HUGE}\n',
     "set.liquid.density"),
    (f'[sample]\nmethod = "latin-hypercube"\npoints = 2\nseed = 1\n[axes]\n'
     f'"liquid.contact_angle" = {{ min = 0, max = {HUGE} }}\n', "axes.liquid.contact_angle.max"),
], ids=["range-start", "range-stop", "list", "derived-list", "derived-set", "plain-set",
        "sample-max"])
def test_an_integer_too_large_for_a_float_in_a_study_is_one_line(tmp_path, body, field):
    """``start = 1`` and 400 zeros was exit 1 (OverflowError) from ``sweep``."""
    p = study(tmp_path, body)
    code, out, err = run_cli(["sweep", str(p), "--workers", "0", "--store",
                              str(tmp_path / "s.h5")])
    line = one_error_line(code, err, "s.toml", f"{field} = ", "allowed:")
    assert "0000...(40" in line  # the value shown shortened: 401 or 402 chars
    assert not out and not (tmp_path / "s.h5").exists()


@pytest.mark.parametrize("body, field", [
    ('[axes]\n"liquid.contact_angle" = { start = -1.7e308, stop = 1.7e308, points = 3 }\n',
     "axes.liquid.contact_angle = {'start': -1.7e+308"),
    ('[sample]\nmethod = "latin-hypercube"\npoints = 3\nseed = 1\n[axes]\n'
     '"liquid.contact_angle" = { min = -1.7e308, max = 1.7e308 }\n',
     "axes.liquid.contact_angle = {'min': -1.7e+308"),
], ids=["range", "sample"])
def test_a_range_whose_steps_overflow_is_one_line_without_warnings(tmp_path, body, field):
    """numpy's overflow warnings printed two lines before an error blaming a ``nan``."""
    p = study(tmp_path, body)
    code, _, err = run_cli(["sweep", str(p), "--workers", "0", "--store",
                            str(tmp_path / "s.h5")])
    line = one_error_line(code, err, field, "is a finite number")
    assert "nan" not in line and "warning" not in err


# ---- 4. gaps below any physical scale ---------------------------------------------------------


@pytest.mark.parametrize("gaps, field", [
    ("[1e-300]", "motion.gaps[0] = 1e-300"),
    ("[1e-4, 1e-15]", "motion.gaps[1] = 1e-15"),
    ("[5e-324]", "motion.gaps[0] = 5e-324"),
    ("9.9e-13", "motion.gaps = 9.9e-13"),
    ("{ start = 1e-4, stop = 1e-13, points = 3 }", "motion.gaps.stop = 1e-13"),
], ids=["1e-300", "1e-15", "denormal", "scalar", "table"])
@pytest.mark.parametrize("model", ["brenner", "lubrication", "reynolds-finite"])
def test_gaps_below_the_physical_limit_are_refused(tmp_path, gaps, field, model):
    """1e-300 m gave 4.7e288 N (reynolds-finite), 1e-15 m ran brenner out of memory and
    5e-324 m gave NaN (lubrication), each with exit 0."""
    p = tmp_path / "tiny.toml"
    p.write_text(IMMERSED_TOML.format(gaps=gaps))
    code, out, err = run_cli(["solve", str(p), "--model", model, "--json"])
    one_error_line(code, err, "tiny.toml", field, "allowed: a number in [1e-12, 0.1] m",
                   "max(1e-12 m, 1e-9 R_s)")
    assert not out


def test_the_gap_limit_is_relative_to_the_smaller_radius_and_inclusive():
    from wetcontact.scene import MIN_GAP, MIN_GAP_OVER_RADIUS, min_gap

    assert (MIN_GAP, MIN_GAP_OVER_RADIUS) == (1e-12, 1e-9)
    assert min_gap(1e-3) == 1e-12 and min_gap(10.0) == 1e-8 and min_gap(2e-9) == 1e-12
    base = {"name": "x", "geometry": {"kind": "sphere-sphere", "radius": 10.0,
                                      "radius2": 1.0},
            "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0},
            "amount": {"immersed": True}, "motion": {"velocity": 0.1, "gaps": [1e-9]}}
    sc = scene_from_dict(base)  # 1e-9 R_s = 1e-9 m: at the limit
    with pytest.raises(CaseError, match=r"motion\.gaps\[0\] = 9\.9e-10; allowed: a number in "
                                        r"\[1e-09, 1000\] m"):
        sc.with_gaps([9.9e-10])
    one_mm = scene_from_dict({**base, "geometry": {"kind": "sphere-wall", "radius": 1e-3},
                              "motion": {"velocity": 0.1, "gaps": [1e-12]}})
    assert one_mm.gaps == (1e-12,)  # 1e-12 m at R = 1 mm is at the limit, not an ulp below
    with pytest.raises(CaseError, match=r"amount\.film_thickness = 1e-12; allowed: a number "
                                        r"in \(1e-12, "):
        scene_from_dict({**base, "geometry": {"kind": "sphere-wall", "radius": 1e-3},
                         "amount": {"film_thickness": 1e-12}})


def test_derived_study_gaps_below_the_limit_are_blamed_on_their_entry(tmp_path):
    """``gap_over_edge_gap = 1e-300`` gave gaps of 4e-306 m and exit 0 from sweep."""
    bridge = ROOT / "cases" / "dem-pendular-bridge-100um.toml"
    p = study(tmp_path, '[axes]\n"liquid.contact_angle" = [10.0]\n'
              '"motion.gap_over_edge_gap" = [1e-300]\n', base=bridge)
    code, _, err = run_cli(["sweep", str(p), "--workers", "0", "--store",
                            str(tmp_path / "s.h5")])
    one_error_line(code, err, "axes.motion.gap_over_edge_gap = 1e-300",
                   "a value giving motion.gaps a number in [1e-12, ")
    assert not (tmp_path / "s.h5").exists()


def test_shipped_cases_and_studies_keep_within_the_gap_limit():
    """Every shipped case, and the studies at the smallest gaps (S/R = 1e-7 of a 50 um
    sphere: 5e-12 m), still load."""
    from wetcontact.study import load_study

    for f in sorted(ROOT.glob("cases/*.toml")):
        load_case(f)
    for f in (ROOT / "cases" / "studies" / "calibrate-lian-rupture.toml",
              ROOT / "benchmarks" / "results" / "calibration" / "lian-rupture_heldout.toml"):
        assert min(min(sc.gaps) for _, sc in load_study(f).scenes) >= 5e-12


# ---- 6. a full disk while the store is written ------------------------------------------------


def _small_study(tmp_path: Path) -> Path:
    case = tmp_path / "imm.toml"
    case.write_text(IMMERSED_TOML.format(gaps="[1e-4, 1e-5]"))
    p = tmp_path / "s.toml"
    p.write_text(f'name = "s"\nbase = "{case}"\nmodels = ["brenner"]\n[axes]\n'
                 '"liquid.viscosity" = [1e-3, 2e-3]\n')
    return p


def _failing_h5py_file(monkeypatch, errors: list[BaseException]) -> list[str]:
    """``h5py.File`` in the store raising ``errors`` in turn when opened for writing."""
    import h5py

    import wetcontact.store as store_mod

    real, calls = h5py.File, []

    def fake(name, mode="r", *args, **kwargs):
        if mode != "r":
            calls.append(mode)
            raise errors[min(len(calls), len(errors)) - 1]
        return real(name, mode, *args, **kwargs)

    monkeypatch.setattr(store_mod.h5py, "File", fake)
    return calls


class _NoSpace:
    f_bavail = f_bfree = 3
    f_frsize = 4096


def test_hdf5_slist_error_on_a_full_disk_is_the_enospc_line(tmp_path, monkeypatch):
    """2 of 6 sweeps on a full disk ended in exit 1 'internal error (RuntimeError: Slist
    already enabled?)' from HDF5, the others in the exit 2 ENOSPC line."""
    calls = _failing_h5py_file(monkeypatch, [RuntimeError("Slist already enabled?")])
    monkeypatch.setattr(os, "statvfs", lambda path: _NoSpace())
    store = tmp_path / "s.h5"
    code, out, err = run_cli(["sweep", str(_small_study(tmp_path)), "--workers", "0",
                              "--store", str(store)])
    line = one_error_line(code, err, repr(str(store)), "No space left on device",
                          "12288 bytes free", "Slist already enabled?",
                          "free some space or choose another folder")
    assert calls and not out and not store.exists()
    assert not list(tmp_path.glob("s.h5.*.tmp"))  # the temporary copy removed
    assert "internal error" not in line


@pytest.mark.parametrize("error", [
    OSError(28, "No space left on device"),
    OSError(None, "Can't write data (file write failed: time = x, filename = 'y', "
                  "errno = 28, error message = 'No space left on device')"),
], ids=["errno", "hdf5-text"])
def test_an_enospc_error_from_hdf5_names_the_store_not_its_temporary(tmp_path, monkeypatch,
                                                                    error):
    _failing_h5py_file(monkeypatch, [error])
    store = tmp_path / "s.h5"
    code, _, err = run_cli(["sweep", str(_small_study(tmp_path)), "--workers", "0",
                            "--store", str(store)])
    line = one_error_line(code, err, f"{str(store)!r}: No space left on device; free some "
                          "space or choose another folder")
    assert ".tmp" not in line


def test_a_second_write_after_enospc_is_still_the_full_disk():
    """A retry after a failed write (the sweep's last flush) can fail in HDF5's broken
    state while the disk has room again (the failed copy was removed): the error in the
    chain is what the user sees."""
    try:
        try:
            raise OSError(28, "No space left on device", "/data/s.h5")
        except OSError:
            raise RuntimeError("Slist already enabled?")  # noqa: B904 - as HDF5 does
    except RuntimeError as exc:
        code, line = cli.error_line(exc)
    assert code == 2 and line == ("wetcontact: error: '/data/s.h5': No space left on device; "
                                  "free some space or choose another folder")


def test_an_hdf5_runtime_error_with_room_on_the_disk_stays_an_internal_error(tmp_path,
                                                                              monkeypatch):
    """Not every HDF5 error is a full disk: with room to write it is still reported as a
    bug (exit 1), not as a full disk."""
    _failing_h5py_file(monkeypatch, [RuntimeError("Slist already enabled?")])
    code, _, err = run_cli(["sweep", str(_small_study(tmp_path)), "--workers", "0",
                            "--store", str(tmp_path / "s.h5")])
    assert code == 1 and len(err.splitlines()) == 1, err
    assert "internal error (RuntimeError: Slist already enabled?)" in err
    assert "No space" not in err


# ---- 7. output paths checked before any work --------------------------------------------------


@pytest.fixture
def no_study_loads(monkeypatch):
    """Fail the test if a study is loaded (where its rupture distances are solved)."""
    import wetcontact.calibrate
    import wetcontact.study

    def loaded(*args, **kwargs):
        raise AssertionError("the study was loaded before the output path was checked")

    monkeypatch.setattr(wetcontact.study, "load_study", loaded)
    monkeypatch.setattr(wetcontact.calibrate, "calibrate", loaded)
    monkeypatch.setattr(cli, "_load_study", loaded)


def _bad_outputs(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    a_file = tmp_path / "a-file"
    a_file.write_text("x")
    (tmp_path / "a-folder").mkdir()
    return {"under-a-file": (a_file / "out.h5", "is a file, not a folder"),
            "a-folder": (tmp_path / "a-folder", "a folder; allowed: a file name"),
            "long-name": (tmp_path / ("n" * 250 + ".h5"), "a name of 253 characters")}


@pytest.mark.parametrize("which", ["under-a-file", "a-folder", "long-name"])
def test_a_bad_store_is_refused_before_the_study_is_loaded(tmp_path, no_study_loads, which):
    """A bad --store was found only after the study's rupture distances were solved
    (25 s in one case)."""
    path, words = _bad_outputs(tmp_path)[which]
    code, out, err = run_cli(["sweep", str(_small_study(tmp_path)), "--store", str(path)])
    one_error_line(code, err, "--store", words)
    assert not out


@pytest.mark.parametrize("which", ["under-a-file", "a-folder", "long-name"])
def test_calibrate_checks_out_and_store_before_any_work(tmp_path, no_study_loads, which):
    path, words = _bad_outputs(tmp_path)[which]
    study_file = str(_small_study(tmp_path))
    code, _, err = run_cli(["calibrate", study_file, "--closure", "willett", "--out",
                            str(path), "--store", str(tmp_path / "s.h5")])
    one_error_line(code, err, f"--out '{str(path)[:60]}", words)
    if which != "a-folder":  # an existing folder is an existing store's folder: fine
        code, _, err = run_cli(["calibrate", study_file, "--closure", "willett", "--out",
                                str(tmp_path / "c.json"), "--store", str(path)])
        one_error_line(code, err, f"--store '{str(path)[:60]}", words)


def test_export_csv_checks_out_before_the_study_is_loaded(tmp_path, no_study_loads):
    store = tmp_path / "s.h5"
    store.write_bytes(b"")  # exists: the --store check passes
    folder = tmp_path / "a-folder"
    folder.mkdir()
    code, _, err = run_cli(["export", "csv", str(_small_study(tmp_path)), "--store",
                            str(store), "--out", str(folder)])
    one_error_line(code, err, "--out", "a folder")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in any folder")
def test_a_store_in_a_read_only_folder_is_refused_first(tmp_path, no_study_loads):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        code, _, err = run_cli(["sweep", str(_small_study(tmp_path)), "--store",
                                str(ro / "s.h5")])
    finally:
        ro.chmod(0o700)
    one_error_line(code, err, "--store", "cannot write in")


def test_a_good_store_path_is_not_refused(tmp_path):
    """The checks refuse nothing a sweep can write: a store in folders still to create."""
    store = tmp_path / "new" / "deeper" / "s.h5"
    code, out, err = run_cli(["sweep", str(_small_study(tmp_path)), "--workers", "0",
                              "--store", str(store)])
    assert code == 0 and store.is_file(), err
    assert "2 computed" in out


# ---- 8. an error is one line on stderr --------------------------------------------------------


def test_a_sweep_in_which_every_point_fails_is_one_stderr_line(tmp_path):
    """The closing progress line came before 'every point failed' (two lines)."""
    bridge = ROOT / "cases" / "unequal-spheres-bridge.toml"
    p = study(tmp_path, '[axes]\n"liquid.contact_angle" = [10.0, 20.0]\n', base=bridge)
    p.write_text(p.read_text().replace('"reynolds"', '"brenner"'))  # refuses a bridge
    for extra in ([], ["--json"]):
        code, out, err = run_cli(["sweep", str(p), "--workers", "0", "--store",
                                  str(tmp_path / "s.h5"), *extra])
        assert code == 1 and err.count("\n") == 1, err
        assert err.startswith("wetcontact: error: every one of the 2 points failed"), err
        assert out.strip()  # the summary (and the reasons) on stdout


@pytest.mark.parametrize("status, left", [("failed", False), ("computed", True)])
def test_the_progress_bar_is_erased_when_every_point_failed(monkeypatch, status, left):
    """On a terminal the bar stayed above the error; it stays when points were solved
    (the counts of a calibrate's sweep, say)."""
    from wetcontact.sweep import _Progress

    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    tty = Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    prog = _Progress(3, True)
    prog.update(status, 3)
    prog.close()
    shown = tty.getvalue().split("\r")[-1]  # what the terminal's line holds at the end
    assert "sweep" in tty.getvalue() and bool(shown.strip()) is left, repr(tty.getvalue())


def test_a_log_gets_the_closing_count_unless_every_point_failed(monkeypatch):
    from wetcontact.sweep import _Progress

    for status, lines in (("failed", 0), ("reused", 1)):
        log = io.StringIO()
        monkeypatch.setattr(sys, "stderr", log)
        prog = _Progress(2, True)
        prog.update(status, 2)
        prog.close()
        assert log.getvalue().count("\n") == lines, log.getvalue()


def test_numpy_warnings_while_a_case_is_validated_print_no_line(tmp_path, monkeypatch):
    """RuntimeWarnings raised while input was validated were printed before its error."""
    import numpy as np

    import wetcontact.scene as scene_mod

    check = scene_mod._check_keys

    def warning_check(source, data):
        np.log(np.zeros(1))  # RuntimeWarning: divide by zero
        check(source, data)

    monkeypatch.setattr(scene_mod, "_check_keys", warning_check)
    p = tmp_path / "bad.toml"
    p.write_text(IMMERSED_TOML.format(gaps="[-1.0]"))
    code, _, err = run_cli(["solve", str(p), "--model", "brenner"])
    one_error_line(code, err, "bad.toml", "motion.gaps[0] = -1.0")
    base = study(tmp_path, '[axes]\n"liquid.viscosity" = [-1.0]\n')
    code, _, err = run_cli(["sweep", str(base), "--store", str(tmp_path / "s.h5")])
    one_error_line(code, err, "axes.liquid.viscosity = -1.0")


# ---- 9. an interrupted or killed --workers 2 sweep --------------------------------------------


def _slow_study(tmp_path: Path) -> Path:
    """60 meniscus points: a sweep that is still running seconds after its two workers
    computed the first."""
    p = tmp_path / "slow.toml"
    p.write_text(f'name = "slow"\nbase = "{ROOT / "cases" / "dem-pendular-bridge-100um.toml"}"'
                 '\nmodels = ["meniscus"]\n[axes]\n'
                 '"liquid.contact_angle" = { start = 1.0, stop = 40.0, points = 60 }\n')
    return p


def _start_cluster_sweep(tmp_path: Path, module: str) -> tuple[subprocess.Popen, Path]:
    """``python -m MODULE sweep --workers 2`` of :func:`_slow_study` in a new session (its
    own process group, SIGINT at its default as at a terminal); returns it and its store."""
    store = tmp_path / "s.h5"
    proc = subprocess.Popen(
        [sys.executable, "-m", module, "sweep", str(_slow_study(tmp_path)),
         "--workers", "2", "--store", str(store)], cwd=tmp_path,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    return proc, store


def _signal_a_running_cluster_sweep(tmp_path: Path, sig: int, group: bool = False
                                    ) -> tuple[int, list[str]]:
    """Run ``sweep --workers 2`` in a new session and send ``sig`` (to the main process, or
    to its whole process group as a terminal's Ctrl-C does) once its workers have computed
    points and the store holds them; return the exit code and the stderr lines that are
    not progress lines, read to the end (the resource tracker, the last process, writes
    its warnings there as it exits)."""
    proc, store = _start_cluster_sweep(tmp_path, "wetcontact.cli")
    try:
        deadline = time.monotonic() + 60
        while not store.exists():  # the first points written: the workers are running
            assert time.monotonic() < deadline and proc.poll() is None, proc.stderr.read()
            time.sleep(0.05)
        os.killpg(proc.pid, sig) if group else proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    from wetcontact.store import Store

    assert len(Store(store)) >= 1  # what was saved is there and readable
    return proc.returncode, [ln for ln in err.splitlines() if not ln.startswith("sweep: ")]


@pytest.mark.parametrize("sig, group, code, word", [
    (signal.SIGTERM, False, 143, "terminated"),
    (signal.SIGINT, True, 130, "interrupted"),
], ids=["sigterm", "ctrl-c"])
def test_a_stopped_cluster_sweep_is_one_line_and_leaks_no_semaphore(tmp_path, sig, group,
                                                                      code, word):
    """A terminated ``--workers 2`` sweep was killed at once, leaving its cluster's
    semaphores to the resource tracker: two 'leaked semaphore' warning lines."""
    got, lines = _signal_a_running_cluster_sweep(tmp_path, sig, group)
    assert got == code and lines == [f"wetcontact: {word}; everything saved before is in "
                                     "the store"], lines


def test_a_killed_cluster_sweep_leaves_no_tracker_warning(tmp_path):
    """SIGKILL: nothing runs in the sweep; the resource tracker still unlinks the
    semaphores, without its two warning lines."""
    got, lines = _signal_a_running_cluster_sweep(tmp_path, signal.SIGKILL)
    assert got == -signal.SIGKILL and lines == [], lines


@pytest.mark.parametrize("delay", [1.5, 3.0])
def test_ctrl_c_while_the_cluster_starts_prints_no_traceback(tmp_path, delay):
    """A terminal's Ctrl-C (SIGINT to the whole process group) while the modules load or
    the local cluster starts printed the tracebacks of workers interrupted while
    importing. Now: before any work, one line; during the cluster's start the Ctrl-C is
    ignored (the workers are started ignoring SIGINT) and the next one stops the sweep.
    (Not earlier than 1.5 s: in the interpreter's own start-up, before any of the package
    runs, a Ctrl-C kills Python with its default handling, rc -2 under load.)"""
    proc, store = _start_cluster_sweep(tmp_path, "wetcontact")
    try:
        time.sleep(delay)
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
        deadline = time.monotonic() + 60
        while proc.poll() is None and not store.exists():
            assert time.monotonic() < deadline
            time.sleep(0.05)
        if proc.poll() is None:  # the first Ctrl-C came while the cluster started
            os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
    lines = [ln for ln in err.splitlines() if not ln.startswith("sweep: ")]
    assert proc.returncode == 130 and "Traceback" not in err, err
    # the last line says what happened; a worker shut down in the middle of a write may
    # add an "Exception ignored" pair before it (seen once in six runs)
    assert lines[-1] in ("wetcontact: interrupted before any work",
                         "wetcontact: interrupted; everything saved before is in the store"), err
    assert len(lines) == 1 or lines[0].startswith("Exception ignored"), err


def test_a_ctrl_c_in_a_finalizer_is_raised_again_in_the_main_thread():
    """A KeyboardInterrupt that lands in a finalizer reaches the unraisable hook: printed
    ("Exception ignored ... KeyboardInterrupt") and lost. The command line's hook raises it
    again in the main thread; anything else goes to the previous hook."""
    from wetcontact._entry import _keep_ctrl_c

    seen: list[object] = []
    hook = _keep_ctrl_c(seen.append)

    class Args:
        def __init__(self, exc_type: type) -> None:
            self.exc_type = exc_type

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            hook(Args(KeyboardInterrupt))
            for _ in range(2000):
                time.sleep(0.001)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert seen == []
    other = Args(ValueError)
    hook(other)
    assert seen == [other]
