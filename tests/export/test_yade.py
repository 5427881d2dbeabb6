"""Yade capillary files: every row against independent solves, the file layout against
Yade's reader, and (marker ``yade``) Yade itself reading the files.

References: the volume-controlled solver at the row's volume and gap (another closing of
the same discretisation, at 4x the elements), the ODE shooting solutions of
tests/solver/shooting.py and tests/export/yade_rows.py (independent code; the latter checks
every row, also of the full set in ``benchmarks/bench_export_yade.py --part rows``), and
the rupture distances at zero suction that Yade's own generator prints (writesCapFile.m:
maxD = 0.3995, 0.2772, 0.1615 for r = 1, 2, 5, theta = 0, from a 2e-6 Euler profile and a
0.5 deg filling-angle grid: 1e-3 relative).
"""

from __future__ import annotations

import json
import math
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact.cli import main
from wetcontact.export.yade import (
    RATIOS,
    capillary_table,
    file_name,
    format_table,
    read_table,
    yade_probe,
)
from wetcontact.solver.meniscus import Bridge, solve_suction, solve_volume

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "solver"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from shooting import shoot_volume  # noqa: E402
from yade_rows import QUANTITIES, check_rows  # noqa: E402

DEG = math.pi / 180.0


@pytest.fixture(scope="module")
def table_r2():
    return capillary_table(2.0, 20 * DEG, n_suctions=10, n_distances=6)


@pytest.mark.parametrize("ratio, theta", [(1.0, 0.0), (2.0, 20.0), (10.0, 40.0)])
def test_rows_match_the_volume_controlled_solver(ratio, theta):
    """Every row (F*, delta1, delta2) within 1e-6 of solve_volume at its V* and D*."""
    tab = capillary_table(ratio, theta * DEG, n_suctions=8, n_distances=5)
    br = Bridge(radius=1.0 / ratio, radius2=1.0, contact_angle1=theta * DEG,
                contact_angle2=theta * DEG, surface_tension=1.0)
    assert tab.rows.shape[0] >= 8
    for D, u, V, F, d1, d2, nn11, nn33 in tab.rows:
        if u == 0.0 and D == 0.0:
            continue
        sol = solve_volume(br, D, V)
        assert sol.exists and sol.stability > 0
        assert F == pytest.approx(sol.force_contact1 / (2 * math.pi), rel=1e-6)
        assert -sol.laplace_pressure == pytest.approx(u, rel=1e-6, abs=1e-6)
        assert d1 == pytest.approx(math.degrees(sol.filling_angle1), abs=1e-6)
        assert d2 == pytest.approx(math.degrees(sol.filling_angle2), abs=1e-6)
        # 2 nn11 + nn33 is the liquid-gas area
        assert 2 * nn11 + nn33 == pytest.approx(sol.area, rel=1e-6, abs=0)  # areas ~4e-7


@pytest.mark.parametrize("ratio, theta", [(1.0, 0.0), (10.0, 40.0)])
def test_every_row_matches_the_exact_bridge_at_its_grid_point(ratio, theta):
    """Every row of a reduced table (its fold rows included) within 1e-6 (relative) of the
    exact bridge at its (D*, u*) from the ODE shooting of yade_rows.py, the checker the
    benchmark runs on the full set (``bench_export_yade.py --part rows``).

    The suction is the row's key (written exactly) and is checked as read back through the
    row's volume, u(D*, V*), relative to max(u*, 0.002) (u* = 0 rows: the first positive
    grid suction as the floor).
    """
    tab = capillary_table(ratio, theta * DEG, n_suctions=10, n_distances=12)
    res = check_rows(ratio, theta * DEG, tab.rows)
    assert res["converged"].all()
    assert np.max(res["self_check"]) < 1e-12        # the force is the same at both ends
    assert np.max(res["step_check"]) < 1e-9         # the shooting's own error (step halved)
    for q in QUANTITIES:
        assert np.max(res["err"][q]) < 1e-6, (q, tab.rows[np.argmax(res["err"][q])])
    # the rows reach their folds (the checker sees the hard cases) ...
    assert np.min(np.abs(res["dD_ddelta1"])) < 0.05 * np.median(np.abs(res["dD_ddelta1"]))
    # ... and it notices an error of 2e-6 in any one column
    cols = {2: "V*", 3: "F*", 4: "delta1", 5: "delta2", 6: "nn11*", 7: "nn33*"}
    bad = np.repeat(tab.rows[5:6], len(cols), axis=0)
    for k, col in enumerate(cols):
        bad[k, col] *= 1 + 2e-6
    err = check_rows(ratio, theta * DEG, bad)["err"]
    for k, q in enumerate(cols.values()):
        assert err[q][k] > 1e-6, q


def test_rows_match_the_shooting_solution(table_r2):
    """A row per distance block against the independent ODE shooting (units of R1)."""
    r, th = 2.0, 20 * DEG
    rows = [b[len(b) // 2] for b in table_r2.blocks()[:-1]]
    for D, u, V, F, d1, _, _, _ in rows:
        ref = shoot_volume(V * r**3, D * r, th, th, r, (math.radians(d1), -u / r))
        assert ref.residual < 1e-10
        assert 2 * math.pi * r * F == pytest.approx(ref.force, rel=1e-6)
        assert -ref.pressure * r == pytest.approx(u, rel=1e-6, abs=1e-7)


@pytest.mark.parametrize("ratio, yade_max_d", [(1.0, 0.3995), (2.0, 0.2772), (5.0, 0.1615)])
def test_rupture_at_zero_suction_matches_yade_generator(ratio, yade_max_d):
    tab = capillary_table(ratio, 0.0, n_suctions=3, n_distances=2)
    assert tab.suctions[0] == 0.0
    assert tab.rupture[0] == pytest.approx(yade_max_d, rel=1e-3)


def test_suction_continuation_agrees_with_direct_suction_solve(table_r2):
    """Rows against solve_suction (fixed dp and gap, Newton from a toroidal guess)."""
    br = Bridge(radius=0.5, radius2=1.0, contact_angle1=20 * DEG, contact_angle2=20 * DEG,
                surface_tension=1.0)
    for D, u, V, *_ in table_r2.rows[::7]:
        sol = solve_suction(br, D, -u, volume_guess=V)
        assert sol.exists
        assert sol.volume == pytest.approx(V, rel=1e-6)


def test_layout_is_what_yades_reader_expects(table_r2, tmp_path):
    path = tmp_path / file_name(2.0, "_x")
    path.write_text(format_table(table_r2))
    lines = path.read_text().splitlines()
    assert lines[0] == "2" and lines[1] == str(table_r2.distances.size)
    ratio, blocks = read_table(path)
    assert ratio == 2.0 and len(blocks) == table_r2.distances.size
    Ds = [b[-1, 0] for b in blocks]                   # Yade takes D from the last row
    assert np.all(np.diff(Ds) > 0) and Ds[0] == 0.0
    for b in blocks:
        assert b.shape[0] >= 1                         # an empty block crashes Yade
        assert np.all(b[:, 0] == b[0, 0])
        assert np.all(np.diff(b[:, 1]) > 0)            # suction increasing
        assert np.all(b[:, 2] > 0) and np.all(b[:, 3] > 0)


def test_rupture_shrinks_with_suction(table_r2):
    assert np.all(np.diff(table_r2.rupture) < 0)


def test_cli_export_yade(tmp_path, capsys):
    rc = main(["export", "yade", "--contact-angle", "30", "--out", str(tmp_path),
               "--suctions", "4", "--distances", "3", "--workers", "1", "--json"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert out["suffix"] == "_theta30"
    assert [Path(f).name for f in out["files"]] == [file_name(r, "_theta30") for r in RATIOS]
    assert all(Path(f).exists() for f in out["files"])


def test_cli_rejects_bad_angle(tmp_path, capsys):
    assert main(["export", "yade", "--contact-angle", "95", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "--contact-angle" in err and "[0, 89)" in err


@pytest.mark.parametrize("flags, says", [
    (["--suffix", "a/b"], "--suffix = 'a/b'"),
    (["--suctions", "1000000"], "--suctions = 1000000"),
    (["--distances", "1"], "--distances = 1"),
])
def test_cli_rejects_bad_grid_and_suffix_before_solving(tmp_path, capsys, flags, says):
    """A suffix with a '/' failed only when the first file was written, after every table
    was computed (minutes at the default grid), and any grid size started running."""
    out = tmp_path / "yd"
    assert main(["export", "yade", "--contact-angle", "20", "--out", str(out), *flags]) == 2
    assert says in capsys.readouterr().err
    assert not out.exists()  # refused before the folder was made


# ---------------------------------------------------------------------------------------
# The real consumer
# ---------------------------------------------------------------------------------------

YADE_SUCTIONS = 60          # u* from 0.002 to 20: step ratio 1.17 -> <= 0.5 % (linear interp.)
YADE_DISTANCES = 25
YADE_MAX_SUCTION = 20.0


@pytest.mark.yade
def test_yade_reads_the_files_and_matches_meniscus(tmp_path):
    """Two spheres in Yade with the exported files (theta = 20 deg): fCap and vMeniscus
    within 0.5 % of meniscus at off-grid (distance, suction) points."""
    if shutil.which("yade") is None:
        pytest.skip("yade is not installed (.ci/run installs it with apt when it can)")
    sigma, R1 = 0.072, 1e-3
    # the probed ratios (1 and 2, read by Yade without interpolation in r) at the test
    # density; Yade also loads the other eight files, written at a token density
    files = []
    for r in RATIOS:
        dense = r in (1.0, 2.0)
        tab = capillary_table(r, 20 * DEG, n_suctions=YADE_SUCTIONS if dense else 4,
                              n_distances=YADE_DISTANCES if dense else 3,
                              max_suction=YADE_MAX_SUCTION)
        files.append(tmp_path / file_name(r, "_t20"))
        files[-1].write_text(format_table(tab))
    res = {"files": [str(f) for f in files], "suffix": "_t20"}
    pairs = [(R1, r * R1, Ds * r * R1) for r in (1.0, 2.0) for Ds in (0.0131, 0.0517)]
    u_star = [0.0371, 0.533, 4.71]                     # off the geometric grid
    suctions = [u * sigma / (2 * R1) for u in u_star]  # Pa: u* for R2 = 2 mm
    out = yade_probe(res["files"], res["suffix"], pairs, suctions, sigma, tmp_path / "run")
    assert len(out) == len(pairs) * len(suctions)
    for o in out:
        assert o["vMeniscus"] > 0, o
        b = Bridge(radius=o["R1"], radius2=o["R2"], contact_angle1=20 * DEG,
                   contact_angle2=20 * DEG, surface_tension=sigma)
        ref_f = solve_volume(b, o["gap"], o["vMeniscus"]).force_contact1
        ref_v = solve_suction(b, o["gap"], -o["suction"], volume_guess=o["vMeniscus"]).volume
        assert o["fCap"] == pytest.approx(ref_f, rel=5e-3), o
        assert o["vMeniscus"] == pytest.approx(ref_v, rel=5e-3, abs=0), o  # V ~ 1e-10 m3
