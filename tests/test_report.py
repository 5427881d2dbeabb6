"""The report job (``wetcontact run``): sweeps into the store, renderers, a report swapped in
whole, the output lock, progress lines, safe file names and the figures' styles."""

from __future__ import annotations

import ast
import copy
import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import wetcontact.report as report
from wetcontact.models import ForceCurve, load_all
from wetcontact.plotting import clipped_texts, overlapping_ticks
from wetcontact.scene import scene_from_dict
from wetcontact.store import Store
from wetcontact.tables import StudyContext

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "wetcontact"
BRIDGE = {
    "name": "tiny-bridge",
    "geometry": {"kind": "sphere-sphere", "radius": 1e-4, "radius2": 1e-4},
    "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
               "contact_angle": 20.0},
    "amount": {"bridge_volume": 1e-13},
    "motion": {"velocity": 0.01, "gaps": [1e-6, 5e-6, 2e-5]},
}
CHEAP = ("toroidal", "willett", "reynolds", "reynolds-finite", "lubrication")


def _bridge(name="tiny-bridge", **over):
    d = copy.deepcopy(BRIDGE)
    d["name"] = name
    d.update(over)
    return scene_from_dict(d)


@pytest.fixture
def cheap(monkeypatch):
    """Cases get closures and lubrication only, no study sections: a report in seconds."""
    models = load_all()
    monkeypatch.setattr(report, "SECTIONS", ())
    monkeypatch.setattr(report, "load_all", lambda: {n: models[n] for n in CHEAP})


def _case_dir(tmp_path, *names):
    folder = tmp_path / "cases"
    folder.mkdir()
    for n in names:
        text = (f'name = "{n}"\n[geometry]\nkind = "sphere-sphere"\nradius = 1e-4\n'
                'radius2 = 1e-4\n[liquid]\nviscosity = 1e-3\nsurface_tension = 0.072\n'
                'density = 998.0\ncontact_angle = 20.0\n[amount]\nbridge_volume = 1e-13\n'
                '[motion]\nvelocity = 0.01\ngaps = [1e-6, 5e-6, 2e-5]\n')
        (folder / f"{abs(hash(n))}.toml").write_text(text)
    return folder


# ---- the data path ----------------------------------------------------------------------


def test_no_model_is_run_twice_and_a_rerun_computes_nothing(tmp_path, cheap):
    scenes = [_bridge("a"), _bridge("b", amount={"bridge_volume": 2e-13})]
    store = Store(tmp_path / "s.h5")
    out1 = tmp_path / "r1"
    out1.mkdir()
    _, st1 = report.build(scenes, out1, store, "default", StudyContext(scenes=tuple(scenes)))
    assert st1.computed_twice == [] and len(st1.computed) == 2 * len(CHEAP)
    assert len(store) == len(st1.computed)  # every computed curve saved, once
    out2 = tmp_path / "r2"
    out2.mkdir()
    _, st2 = report.build(scenes, out2, store, "default", StudyContext(scenes=tuple(scenes)))
    assert st2.computed == [] and st2.reused == len(st1.computed)
    a, b = ((o / "closure_errors.csv").read_text() for o in (out1, out2))
    assert a == b


def test_closure_table_goes_through_compare(tmp_path, cheap):
    """The table row equals compare() of directly solved curves against the ranked
    reference (lubrication: the only declared viscous reference here)."""
    import csv

    from wetcontact.compare import compare

    sc = _bridge()
    out = tmp_path / "r"
    out.mkdir()
    report.build([sc], out, Store(tmp_path / "s.h5"), "default", StudyContext(scenes=(sc,)))
    rows = list(csv.DictReader((out / "closure_errors.csv").open()))
    models = load_all()
    ref = models["lubrication"].force(sc)
    for name in ("reynolds", "reynolds-finite"):
        row = next(r for r in rows if r["closure"] == name)
        rec = compare(models[name].force(sc), ref, "viscous")
        assert row["reference"] == "lubrication" and int(row["points"]) == rec.points == 3
        assert float(row["max_rel_error"]) == rec.max_rel_error
        assert float(row["gap_of_max_m"]) == rec.gap_of_max
    assert not any(r["component"] == "capillary" for r in rows)  # no meniscus: no reference


def test_renderers_never_solve_nor_read_the_repository():
    """Tables and report import no solver module and no repository path."""
    for path in [SRC / "report.py", *sorted((SRC / "tables").glob("*.py"))]:
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module:
                assert not node.module.startswith("wetcontact.solver"), (path, node.module)
            if isinstance(node, ast.Import):
                assert not any(a.name.startswith("wetcontact.solver") for a in node.names)
        text = path.read_text()
        assert "__file__" not in text and "ROOT" not in text, path
        assert '"cases"' not in text.replace('Path("cases")', ""), path


def test_quick_run_defaults_to_a_scratch_folder(tmp_path, cheap, monkeypatch):
    from wetcontact.cli import build_parser

    assert build_parser().parse_args(["run", "--quick"]).out is None
    monkeypatch.chdir(tmp_path)
    cases = _case_dir(tmp_path, "q")
    path = report.run_all(cases=cases, mode="quick", progress=False, bench=None)
    assert path == (tmp_path / "reports-quick" / "README.md").absolute()
    assert not (tmp_path / "reports").exists()


# ---- the report is swapped in whole, under a lock ---------------------------------------


def test_case_name_cannot_escape_the_curves_folder(tmp_path, cheap):
    sc = _bridge("../../x")
    out = tmp_path / "deep" / "out"
    out.mkdir(parents=True)
    report.build([sc], out, Store(tmp_path / "s.h5"), "default", StudyContext(scenes=(sc,)))
    written = {p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file()}
    assert all(str(p).startswith(("deep/out/", "s.h5")) for p in written), written
    stems = [p.name for p in (out / "curves").iterdir()]
    assert len(stems) == 2 and all(not s.startswith(".") and "/" not in s for s in stems)
    assert f"curves/{Path(stems[0]).stem}" in (out / "README.md").read_text()


def test_second_run_on_the_same_folder_is_refused(tmp_path, cheap):
    from wetcontact.errors import InputError

    cases = _case_dir(tmp_path, "l")
    out = tmp_path / "out"
    with report._locked(out.absolute()), pytest.raises(InputError, match="another"):
        report.run_all(cases=cases, out=out, progress=False, bench=None)
    assert report.run_all(cases=cases, out=out, progress=False, bench=None).exists()


def test_swap_replaces_the_whole_folder(tmp_path):
    out, new = tmp_path / "out", tmp_path / ".out.partial"
    out.mkdir()
    (out / "README.md").write_text("old")
    (out / "only-old.csv").write_text("x")
    new.mkdir()
    (new / "README.md").write_text("new")
    report.swap_in(new, out)
    assert sorted(p.name for p in out.iterdir()) == ["README.md"]
    assert (out / "README.md").read_text() == "new" and not new.exists()
    # a swap killed between the fallback's two renames is undone by the next run
    os.rename(out, tmp_path / ".out.old")
    report._recover(out)
    assert (out / "README.md").read_text() == "new"


_KILL_SCRIPT = f"""
CHEAP = {CHEAP!r}
import sys, wetcontact.report as r
from wetcontact.models import load_all
m = load_all()
r.SECTIONS = ()
r.load_all = lambda: {{n: m[n] for n in CHEAP}}
r.run_all(cases=sys.argv[1], out=sys.argv[2], progress=False, bench=None)
print("done", flush=True)
"""


def test_killed_run_leaves_the_old_or_the_new_report(tmp_path):
    """SIGKILL while the new report is half written (its curves folder exists in the staging
    folder), and at a few other moments: README.md and the files it links are always one
    complete report, the old one or the new one, never a mix."""
    cases = _case_dir(tmp_path, "k1", "k2")
    out = tmp_path / "out"
    out.mkdir()
    (out / "README.md").write_text("OLD REPORT\n")
    (out / "old-only.csv").write_text("old\n")
    staging = tmp_path / ".out.partial"
    env = {**os.environ, "PYTHONPATH": str(SRC.parent)}

    def start():
        return subprocess.Popen([sys.executable, "-c", _KILL_SCRIPT, str(cases), str(out)],
                                env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                start_new_session=True)

    def check() -> str:
        files = sorted(f.name for f in out.iterdir())
        text = (out / "README.md").read_text()
        if text == "OLD REPORT\n":
            assert files == ["README.md", "old-only.csv"]
            return "old"
        assert "old-only.csv" not in files and "## Provenance" in text
        for link in ("curves/k1.png", "curves/k2.csv", "closure_errors.csv"):
            assert (out / link).stat().st_size > 0
        return "new"

    p = start()
    t0 = time.monotonic()
    while not (staging / "curves").exists() and p.poll() is None:
        assert time.monotonic() - t0 < 120
        time.sleep(0.01)
    os.killpg(p.pid, signal.SIGKILL)
    p.wait()
    assert check() == "old"  # killed mid-report: the old report, whole
    for delay in (0.3, 2.0):
        p = start()
        time.sleep(delay)
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()
        check()
    p = start()
    assert p.wait(timeout=120) == 0
    assert check() == "new"


# ---- what a user sees ---------------------------------------------------------------------


def test_progress_line_every_few_seconds_when_stderr_is_not_a_terminal(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr(sys, "stderr", buf)
    with report._Heartbeat(True, every=0.05) as beat:
        beat.phase = "stage 1: sweeping 3 points"
        time.sleep(0.32)
    lines = buf.getvalue().splitlines()
    assert len(lines) >= 3 and all(ln.startswith("wetcontact run: stage 1") for ln in lines)


def test_progress_line_counts_the_sweeps_points_and_a_new_phase_forgets_them(monkeypatch):
    buf = io.StringIO()
    monkeypatch.setattr(sys, "stderr", buf)
    with report._Heartbeat(True, every=0.02) as beat:
        beat.phase = "stage 1 (cases and studies)"
        beat.points(3, 40)
        time.sleep(0.1)
        beat.phase = "drawing the case plots"
        time.sleep(0.1)
    lines = buf.getvalue().splitlines()
    assert "wetcontact run: stage 1 (cases and studies): 3/40 points (0 s)" in lines
    assert lines[-1] == "wetcontact run: drawing the case plots (0 s)"


def test_run_in_a_pipe_counts_points_names_its_report_and_leaves_no_lock(
        tmp_path, cheap, monkeypatch, capsys):
    """``wetcontact run`` with stderr not a terminal: progress lines with points done/total
    of each sweep, a last stdout line naming the report, and no lock file left anywhere
    (neither the report's ``.out.lock`` nor the store's ``reference.h5.lock``)."""
    import re

    from wetcontact.cli import main

    real_sweep = report.sweep

    def slow_sweep(*args, on_progress=None, **kw):  # each point takes long enough to be seen
        def seen(done, total):
            on_progress(done, total)
            time.sleep(0.03)
        return real_sweep(*args, on_progress=seen, **kw)

    monkeypatch.setattr(report, "sweep", slow_sweep)
    monkeypatch.setattr(report, "PROGRESS_EVERY_S", 0.01)
    cases, out = _case_dir(tmp_path, "p1", "p2"), tmp_path / "out"
    for attempt in range(2):  # a rerun (everything reused) too
        assert main(["run", "--cases", str(cases), "--out", str(out)]) == 0
        stdout, stderr = capsys.readouterr()
        assert stdout.splitlines()[-1] == f"wetcontact run: wrote {out.absolute()}/README.md"
        counts = [(int(m[1]), int(m[2])) for m in re.finditer(
            r"^wetcontact run: stage 1 \(cases and studies\): (\d+)/(\d+) points \(\d+ s\)$",
            stderr, re.MULTILINE)]
        assert counts and {t for _, t in counts} == {2 * len(CHEAP)}, stderr
        assert [d for d, _ in counts] == sorted(d for d, _ in counts)
        assert [p.name for p in tmp_path.rglob("*") if "lock" in p.name] == [], attempt
    assert (out / "README.md").is_file() and (out / "reference.h5").is_file()


def test_a_rerun_leaves_the_readme_as_it_was_and_times_go_to_an_uncommitted_file(
        tmp_path, cheap):
    """Wall times change with every run: they are in ``timings.json`` (ignored by git for
    ``reports/``), not in the README, which a rerun on unchanged code leaves byte for byte."""
    import json

    cases, out = _case_dir(tmp_path, "t1"), tmp_path / "out"
    first = report.run_all(cases=cases, out=out, progress=False, bench=None).read_bytes()
    assert report.run_all(cases=cases, out=out, progress=False, bench=None).read_bytes() == first
    assert b" s._" not in first and b"wall time" not in first.replace(b"wall times of", b"")
    times = json.loads((out / report.TIMINGS).read_text())
    assert set(times) == {"sweeps_s", "sections_s", "total_s", "curves", "git_commit"}
    assert times["total_s"] > 0 and times["curves"]["computed"] > 0
    assert times["curves"]["computed_twice"] == [] and times["curves"]["failed"] == 0
    ignored = (ROOT / ".gitignore").read_text().splitlines()
    assert f"/reports/{report.TIMINGS}" in ignored
    assert "/reports/reference.h5" in ignored  # every run writes a new store


def _case_result(names, negative=True):
    curves = {}
    gap = np.geomspace(1e-6, 1e-4, 8)
    for k, n in enumerate(names):
        cap = -(k + 1) * 1e-4 / (1 + gap / 1e-5) if negative else None
        curves[n] = ForceCurve(case="c", model=n, gap=gap, force_viscous=(k + 1) * 1e-9 / gap,
                               force_capillary=cap)
    return report.CaseResult(_bridge(), curves, {})


def test_case_plot_colours_never_repeat_and_forces_are_signed():
    from matplotlib.colors import to_hex

    names = sorted(load_all())  # every registered model in one plot
    fig = report.case_figure(_case_result(names))
    assert len(fig.axes) == 2  # viscous and capillary panels
    colour, markers = {}, {}
    for ax in fig.axes:
        for ln in ax.get_lines():
            if ln.get_label().startswith("_"):
                continue
            colour.setdefault(ln.get_label(), set()).add(to_hex(ln.get_color()))
    assert sorted(colour) == names and all(len(c) == 1 for c in colour.values())
    flat = [next(iter(c)) for c in colour.values()]
    assert len(set(flat)) == len(flat)  # no colour repeats within the figure
    # signed axes: viscous F > 0 above the zero line, capillary attraction below it
    visc, cap = fig.axes[0], fig.axes[1]
    for ax, sign in ((visc, 1), (cap, -1)):
        lo, hi = ax.get_ylim()
        assert lo < 0 < hi  # the zero line is in view
        ys = [np.asarray(ln.get_ydata()) for ln in ax.get_lines()
              if not ln.get_label().startswith("_") and len(ln.get_xdata()) > 1]
        assert ys and all(np.all(sign * y > 0) for y in ys)
        assert ax.get_yscale() == "symlog"  # 1e-3 ... 1e+1 N: a log axis, both signs
    for ln in cap.get_lines():
        if ln.get_marker() not in (None, "None", ""):
            markers.setdefault(ln.get_marker(), set()).add(to_hex(ln.get_color()))
    assert all(len(c) == 1 for c in markers.values()) and len(markers) == len(names)
    title = fig.get_suptitle()
    assert "V = 1e-13 m^3" in title and "theta = 20/20 deg" in title
    film = report.scene_label(scene_from_dict({
        **copy.deepcopy(BRIDGE), "geometry": {"kind": "sphere-wall", "radius": 1e-3},
        "amount": {"film_thickness": 1e-4}, "motion": {"velocity": 0.01, "gaps": [5e-5]}}))
    assert "film delta = 0.0001 m" in film
    assert not clipped_texts(fig)


def test_case_plot_draws_zero_and_sign_changes_on_the_axis():
    """F = 0 past rupture is drawn on the zero line, not dropped, and a closure that turns
    repulsive crosses it; a force within two decades gets a linear axis."""
    gap = np.geomspace(1e-6, 1e-4, 9)
    cap = -1e-4 * (1 - gap / 5.6e-5)  # about -1e-4 N, crosses zero at 5.6e-5 m
    cap[-1] = 0.0
    curves = {"a": ForceCurve(case="c", model="a", gap=gap, force_viscous=None,
                              force_capillary=cap),
              "b": ForceCurve(case="c", model="b", gap=gap, force_viscous=None,
                              force_capillary=np.where(gap < 8e-5, -2e-4, 0.0))}
    fig = report.case_figure(report.CaseResult(_bridge(), curves, {}))
    (ax,) = fig.axes
    line = next(ln for ln in ax.get_lines() if ln.get_label() == "a")
    assert np.array_equal(line.get_ydata(), cap)  # signed, zeros kept
    assert ax.get_yscale() == "symlog"  # |F| from 3.6e-7 to 2e-4 N: over two decades
    lo, hi = ax.get_ylim()
    assert lo < -2e-4 and hi > cap.max() > 0
    flat = {"b": curves["b"]}
    fig = report.case_figure(report.CaseResult(_bridge(), flat, {}))
    assert fig.axes[0].get_yscale() == "linear"
    assert fig.axes[0].get_ylim()[1] > 0 > fig.axes[0].get_ylim()[0]
    assert not clipped_texts(fig)


def test_every_series_has_its_own_dash_pattern():
    from wetcontact.plotting import COLOURS, styles

    st = styles([f"m{i}" for i in range(len(COLOURS))])
    dashes = [str(s["linestyle"]) for s in st.values()]
    assert len(set(dashes)) == len(dashes)


def test_lubrication_chart_one_colour_per_film_thickness():
    from matplotlib.colors import to_hex

    from wetcontact.tables.lubrication import chart_figure

    recs = [{"case": c, "delta_over_R": d, "S_over_R": s, "err_reynolds": 0.1 * s,
             "err_finite_liquid": -0.01 * s} for c in ("film", "bridge")
            for d in (1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3) for s in (1e-4, 1e-3)]
    fig = chart_figure(recs)
    for ax in fig.axes:
        by_delta = {}
        for ln in ax.get_lines():
            if ln.get_xydata().size:
                by_delta.setdefault(to_hex(ln.get_color()), set()).add(
                    round(float(ln.get_xydata()[0, 0]), 12))
        assert len(by_delta) == 6  # 0.001 and 0.3 no longer share a colour


def test_capillary_figures_have_distinct_styles_and_nothing_clipped():
    from matplotlib.colors import to_hex

    from wetcontact.tables.capillary_closures import (
        CLOSURES,
        KINDS,
        closures_figure,
        regions_figure,
    )

    pairs = [(v, t) for v in (1e-4, 1e-3, 1e-2, 0.1) for t in (0.0, 25.0, 50.0)]
    reg = [{"closure": c, "kind": k, "V*": v, "theta_deg": t, "reach_1pct": 0.1,
            "reach_5pct": 0.4} for c in CLOSURES for k in KINDS for v, t in pairs]
    fig = regions_figure(reg)
    assert not clipped_texts(fig)
    assert overlapping_ticks(fig.axes[1]) == 0
    rows = [{"closure": c, "kind": k, "V*": 0.01, "theta_deg": 0.0, "S/S_c": f,
             "rel_error": 0.01 * (i + 1)} for i, c in enumerate(CLOSURES) for k in KINDS
            for f in (0.0, 0.5)]
    fig = closures_figure(rows)
    cols = [to_hex(ln.get_color()) for ln in fig.axes[0].get_lines()]
    assert len(set(cols)) == len(cols) == len(CLOSURES)
    assert not clipped_texts(fig)


def test_thinfilm_figure_ticks_do_not_overlap():
    import json

    from wetcontact.tables.thinfilm import stability_figure, validity_map

    bench = ROOT / "benchmarks" / "results" / "thinfilm.json"
    stab = json.loads(bench.read_text())["stability"]["rows"]
    dr, ca = np.geomspace(1e-3, 0.5, 12), np.geomspace(1e-6, 10, 12)
    fig = stability_figure(stab, dr, ca, validity_map(dr, ca))
    assert overlapping_ticks(fig.axes[0]) == 0 and not clipped_texts(fig)
    fig = stability_figure(None, dr, ca, validity_map(dr, ca))  # no benchmark: says so
    assert "no benchmark" in " ".join(t.get_text() for t in fig.axes[0].texts)


def test_full_disk_mid_report_keeps_the_old_report_and_says_one_line(tmp_path, cheap,
                                                                     monkeypatch, capsys):
    """Issue 14: a full disk while the report is written gave 39 'No space' lines, a
    traceback and zero-byte files. Now: ENOSPC on the error table (after the curves are
    written to the staging folder) -> exit 2, one stderr line, the old report whole."""
    import errno

    from wetcontact.cli import main

    cases = _case_dir(tmp_path, "d1", "d2")
    out = tmp_path / "out"
    out.mkdir()
    (out / "README.md").write_text("OLD REPORT\n")

    def full(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device", "closure_errors.csv")

    monkeypatch.setattr(report, "write_error_table", full)
    code = main(["run", "--cases", str(cases), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "space" in err[0], err
    assert sorted(f.name for f in out.iterdir()) == ["README.md"]
    assert (out / "README.md").read_text() == "OLD REPORT\n"
    # lock files are empty by design (flock); the staging folder stays for --resume
    leftovers = [p for p in tmp_path.rglob("*") if p.is_file() and p.stat().st_size == 0
                 and "cases" not in p.parts and p.suffix != ".lock"]
    assert not leftovers, leftovers
