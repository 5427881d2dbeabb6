"""Yade capillary files on coarse grids (every block of every file filled with exact rows),
and an export that writes all ten files or none.

On a coarse suction grid a distance of the grid can lie above the fold of one grid suction
and below the start (the filling-angle cap) of the next lower one; above a contact angle of
about 88.7 deg the bridge at contact at the top suction passed that cap. Both left a block
that no grid suction reaches, and the export failed (exit 1, "no bridge at D* = ...") on
grids the command accepts; from about 88.9 deg the 0.7 deg bridge at contact is convex and the
top suction came out negative. The rows are checked as in test_yade.py: against the exact
bridge at each row's (D*, u*) from the independent ODE shooting of yade_rows.py.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact.cli import main
from wetcontact.errors import SolverError
from wetcontact.export import yade
from wetcontact.export.yade import (
    RATIOS,
    U_FIRST,
    U_MIN_TOP,
    CapillaryTable,
    capillary_table,
    file_name,
    read_table,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from yade_rows import QUANTITIES, check_rows  # noqa: E402


def _assert_exact(ratio: float, theta_deg: float, rows: np.ndarray) -> None:
    """Every row within 1e-6 (relative) of the exact bridge at its (D*, u*)."""
    res = check_rows(ratio, math.radians(theta_deg), rows)
    assert res["converged"].all()
    assert np.max(res["step_check"]) < 1e-9          # the shooting's own error
    for q in QUANTITIES:
        assert np.max(res["err"][q]) < 1e-6, (q, rows[np.argmax(res["err"][q])])


def test_coarse_grid_export_fills_every_block_with_exact_rows(tmp_path, capsys):
    """theta = 20 deg, 5 suctions x 5 distances: r = 10 had no grid suction at D* = 0.0199
    (u* = 0.65 starts at the 70 deg cap at D* = 0.029, u* = 211 ruptures at 0.0055)."""
    out = tmp_path / "caps"
    rc = main(["export", "yade", "--contact-angle", "20", "--suctions", "5",
               "--distances", "5", "--out", str(out), "--workers", "1"])
    assert rc == 0, capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == sorted(file_name(r, "_theta20")
                                                           for r in RATIOS)
    ratio, blocks = read_table(out / file_name(10.0, "_theta20"))
    assert ratio == 10.0 and len(blocks) == 5
    assert all(b.shape[0] >= 1 for b in blocks)      # an empty block crashes Yade
    Ds = np.array([b[0, 0] for b in blocks])
    np.testing.assert_allclose(Ds, np.linspace(0.0, Ds[-1], 5), rtol=0, atol=1e-15)
    u_max = max(b[:, 1].max() for b in blocks)
    grid = np.concatenate([[0.0], np.geomspace(U_FIRST, u_max, 4)])
    hole = blocks[1]
    # the hole's rows: suctions between two grid suctions, at least two of them
    assert hole.shape[0] >= 2
    assert not np.any(np.isclose(hole[:, 1][:, None], grid[None, :], rtol=1e-12))
    _assert_exact(10.0, 20.0, np.vstack(blocks))


def test_top_suction_reaches_contact_near_90_degrees():
    """theta = 88.9 deg: the 0.7 deg bridge at contact has 1.27 deg on the small sphere
    (r = 10), past the cap 90 - theta = 1.1 deg, so no suction had a row at D* = 0."""
    tab = capillary_table(10.0, math.radians(88.9), n_suctions=3, n_distances=2)
    blocks = tab.blocks()
    assert blocks[0].shape[0] >= 1 and blocks[0][0, 0] == 0.0
    top = blocks[0][-1]
    assert top[1] == tab.suctions[-1]
    assert top[4] == pytest.approx(0.9 * 1.1, rel=1e-9)   # 0.9 of the cap, at contact
    _assert_exact(10.0, 88.9, tab.rows)



def test_top_suction_stays_positive_up_to_89_degrees():
    """theta = 88.99 deg, r = 1: the 0.7 deg bridge at contact is convex (u* = -9.4), and the
    grid's top suction was negative (a NaN grid from 4 suctions on)."""
    tab = capillary_table(1.0, math.radians(88.99), n_suctions=3, n_distances=2)
    assert tab.suctions[-1] == U_MIN_TOP
    assert np.all(np.diff(tab.suctions) > 0)
    for b in tab.blocks():
        assert b[0, 1] >= 0.0 and np.all(np.diff(b[:, 1]) > 0)
    assert tab.blocks()[0][-1, 1] == U_MIN_TOP                # a row at contact
    _assert_exact(1.0, 88.99, tab.rows)


# ---------------------------------------------------------------------------------------
# All or nothing: a failure part-way leaves --out as it was
# ---------------------------------------------------------------------------------------


def _fake_table(ratio, theta, *args, fail_at=5.0, **kwargs):
    """A one-row table in no time, or the solver failure of the ratio ``fail_at``."""
    if ratio == fail_at:
        raise SolverError(f"yade export: no bridge at D* = 0.5 for r = {ratio:g}")
    return CapillaryTable(ratio, theta, np.array([0.0]), np.array([0.0]),
                          np.array([[0.0, 0.0, 1.0, 1.0, 30.0, 3.0, 1.0, 1.0]]),
                          np.array([0.1]), 0, 0.0)


def _export(out: Path) -> int:
    return main(["export", "yade", "--contact-angle", "20", "--suctions", "3",
                 "--distances", "2", "--out", str(out), "--workers", "1"])


def _leftovers(*folders: Path) -> list[str]:
    return [p.name for f in folders if f.exists() for p in f.iterdir()
            if "partial" in p.name or p.name.endswith(".tmp")]


def test_failure_part_way_leaves_the_previous_export_intact(tmp_path, monkeypatch, capsys):
    """The sixth of ten tables fails: the first five used to be written over the previous
    export's files already (a mixed set Yade would read without complaint)."""
    out = tmp_path / "caps"
    out.mkdir()
    before = {file_name(r, "_theta20"): f"previous export of r = {r:g}\n" for r in RATIOS}
    before["notes.txt"] = "the user's own file\n"
    for name, text in before.items():
        (out / name).write_text(text)
    monkeypatch.setattr(yade, "capillary_table", _fake_table)
    assert _export(out) == 1
    assert "no bridge at D* = 0.5 for r = 5" in capsys.readouterr().err
    assert {p.name: p.read_text() for p in out.iterdir()} == before
    assert _leftovers(tmp_path, out) == []


def test_failure_into_a_new_folder_leaves_nothing(tmp_path, monkeypatch, capsys):
    out = tmp_path / "new" / "caps"
    monkeypatch.setattr(yade, "capillary_table", _fake_table)
    assert _export(out) == 1
    capsys.readouterr()
    assert not out.exists()
    assert _leftovers(tmp_path, tmp_path / "new") == []


def test_success_replaces_every_file_and_leaves_no_staging(tmp_path, monkeypatch, capsys):
    out = tmp_path / "caps"
    out.mkdir()
    (out / "notes.txt").write_text("the user's own file\n")
    for r in RATIOS:
        (out / file_name(r, "_theta20")).write_text("previous export\n")
    monkeypatch.setattr(yade, "capillary_table",
                        lambda *a, **k: _fake_table(*a, fail_at=-1.0, **k))
    assert _export(out) == 0
    capsys.readouterr()
    assert (out / "notes.txt").read_text() == "the user's own file\n"
    for r in RATIOS:
        ratio, blocks = read_table(out / file_name(r, "_theta20"))
        assert ratio == r and len(blocks) == 1
    assert _leftovers(tmp_path, out) == []


# ---------------------------------------------------------------------------------------
# --workers, checked as sweep and calibrate check it
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("value", ["-1", "two", "1.5"])
def test_cli_rejects_bad_workers_before_solving(tmp_path, capsys, value):
    out = tmp_path / "caps"
    assert main(["export", "yade", "--contact-angle", "20", "--out", str(out),
                 f"--workers={value}"]) == 2
    err = capsys.readouterr().err
    assert f"--workers = '{value}'; allowed: an integer >= 0" in err
    assert "Traceback" not in err
    assert not out.exists()


def test_workers_zero_runs_in_this_process(tmp_path, monkeypatch, capsys):
    """0 = in this process, as for sweep and calibrate (it was refused: 'allowed: >= 1');
    the monkeypatched table is seen only in this process."""
    monkeypatch.setattr(yade, "capillary_table",
                        lambda *a, **k: _fake_table(*a, fail_at=-1.0, **k))
    out = tmp_path / "caps"
    assert main(["export", "yade", "--contact-angle", "20", "--suctions", "3",
                 "--distances", "2", "--out", str(out), "--workers", "0"]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == sorted(file_name(r, "_theta20")
                                                           for r in RATIOS)
