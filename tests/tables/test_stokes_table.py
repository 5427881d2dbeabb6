"""The Stokes error table compares each closure on the gaps it accepts."""

from __future__ import annotations

import numpy as np

from wetcontact.compare import compare
from wetcontact.models import get_model
from wetcontact.tables import stokes as table


def test_a_closure_refusing_one_gap_is_compared_on_the_others():
    """cox-brenner refuses S/R = 10, and with it the whole immersed scene: its column was
    n/a at every gap. It now runs on the five gaps it accepts and is compared there (against
    Brenner's exact series here, in place of the FEM curve)."""
    (case, _, s_over_r, scene), *_ = table._studies(quick=False)
    assert case == "immersed" and 10.0 in s_over_r
    pts = table._closure_points(scene)
    assert get_model("cox-brenner").applicable(scene) is not None
    assert [g / table.R for g in pts["cox-brenner"].scene.gaps] == [s for s in s_over_r
                                                                   if s <= 1.0]
    assert pts["reynolds"].scene == scene  # a closure taking every gap keeps the scene
    exact = get_model("brenner").force(scene)
    sub = table._on_gaps(exact, np.asarray(pts["cox-brenner"].scene.gaps))
    assert np.array_equal(sub.force_viscous, exact.force_viscous[:5])
    cox = get_model("cox-brenner").force(pts["cox-brenner"].scene)
    rec = compare(cox, sub, "viscous")
    assert rec.points == 5
    # Cox-Brenner's two-term asymptote: within 1 % of the series at S/R = 1e-3
    g = 1e-3 * table.R
    assert abs(rec.signed_at(g)) < 1e-2
