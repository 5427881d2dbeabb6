"""Yade capillary files on coarse grids: every block of every file filled with exact rows.

On a coarse suction grid a distance of the grid can lie above the fold of one grid suction
and below the start (the filling-angle cap) of the next lower one; above a contact angle of
about 88.7 deg the bridge at contact at the top suction passed that cap. Both left a block
that no grid suction reaches, and the export failed (exit 1, "no bridge at D* = ...") on
grids the command accepts. The rows are checked as in test_yade.py: against the exact
bridge at each row's (D*, u*) from the independent ODE shooting of yade_rows.py.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact.cli import main
from wetcontact.export.yade import RATIOS, U_FIRST, capillary_table, file_name, read_table

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
