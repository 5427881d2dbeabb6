"""What is hand-written where a dependency has it, and why (issue 58): the Latin hypercube
of the seeded designs stays the package's own, the export tests' DOP853 stepper takes
scipy's tableau."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
from scipy.stats import qmc

from wetcontact.study import latin_hypercube

ROOT = Path(__file__).resolve().parents[1]


def test_seeded_latin_hypercube_keeps_the_shipped_designs_points():
    """The committed held-out designs (seed 7919) and bridge-held-out.toml are these draws:
    pinned, so a replacement that moves them (scipy's qmc.LatinHypercube does: another
    order of draws, another design for the same seed) fails here and not only in the
    slower check of the committed reference points."""
    pinned = [[0.8542234889391486, 0.3609743756278922],
              [0.5663216157995973, 0.8351402725671043],
              [0.1091890528124722, 0.10460800172046376]]
    assert latin_hypercube(3, 2, 7919).tolist() == pinned
    scipy_design = qmc.LatinHypercube(d=2, seed=7919).random(3)
    assert not np.allclose(np.sort(scipy_design, axis=0), np.sort(pinned, axis=0))


def test_export_tests_integrate_with_scipys_dop853_tableau():
    """tests/export/yade_rows.py steps with the coefficients scipy ships, not a copy: its
    stepper is its own only because it advances thousands of rows at once on fixed steps
    with a per-row event, which solve_ivp (one system, adaptive steps) does not."""
    from scipy.integrate._ivp import dop853_coefficients as dop

    sys.path.insert(0, str(ROOT / "tests" / "export"))
    try:
        import yade_rows
    finally:
        sys.path.remove(str(ROOT / "tests" / "export"))
    assert yade_rows.N_STAGES == dop.N_STAGES == 12
    assert np.shares_memory(yade_rows._A, dop.A) and yade_rows._B is dop.B
    text = (ROOT / "tests" / "export" / "yade_rows.py").read_text()
    assert not re.findall(r"\d\.\d{12,}", text)  # no tableau entry copied in by hand
