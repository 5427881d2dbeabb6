"""The report section on the division of the liquid at rupture (issue 56): a tiny grid swept
for real into a temporary store, then rendered."""

from __future__ import annotations

import csv
import math

import pytest

from wetcontact.store import Store
from wetcontact.sweep import sweep
from wetcontact.tables import StudyContext, division

TINY = [("sphere-sphere", 1.0, 0.0, 0.0, 1e-2), ("sphere-sphere", 1.0, 20.0, 20.0, 1e-3),
        ("sphere-sphere", 1.0, 20.0, 0.0, 1e-2), ("sphere-sphere", 2.0, 0.0, 20.0, 1e-2),
        ("sphere-wall", division.WALL, 0.0, 20.0, 1e-2)]


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setattr(division, "grid", lambda quick: TINY)
    try:
        tmp = tmp_path_factory.mktemp("division")
        ctx = StudyContext(quick=True)
        result = sweep(division.points(ctx), Store(tmp / "ref.h5"), workers=0,
                       progress=False)
        md = division.section(tmp / "reports", result, ctx)
    finally:
        mp.undo()
    with open(tmp / "reports" / "division_rules.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return md, rows, tmp / "reports"


def test_csv_columns_and_one_row_per_configuration(rendered):
    md, rows, out = rendered
    assert list(rows[0]) == ["kind", "ratio", "theta1_deg", "theta2_deg", "V*", "f_ref",
                             "f_even_split", "error_even_split", "f_mercurydpm",
                             "error_mercurydpm", "f_shi_mccarthy", "error_shi_mccarthy",
                             "neck", "rupture"]
    assert [(r["kind"], float(r["ratio"]), float(r["theta1_deg"]), float(r["theta2_deg"]),
             float(r["V*"])) for r in rows] == TINY
    assert (out / "division_rules.png").stat().st_size > 0
    for label, _ in division.RULES.values():
        assert f"| {label} |" in md
    assert "Conclusion:" in md


def test_errors_are_distances_to_the_reference(rendered):
    _, rows, _ = rendered
    for r in rows:
        f = float(r["f_ref"])
        assert 0.0 < f < 1.0
        assert float(r["f_even_split"]) == 0.5
        assert float(r["error_even_split"]) == pytest.approx(abs(f - 0.5), abs=1e-15)
        for stem in division.RULES:
            assert float(r[f"error_{stem}"]) == pytest.approx(
                abs(float(r[f"f_{stem}"]) - f), abs=1e-15)
    wall = next(r for r in rows if r["kind"] == "sphere-wall")
    assert math.isinf(float(wall["ratio"])) and float(wall["f_mercurydpm"]) == 1.0


def test_equal_spheres_with_equal_angles_split_evenly(rendered):
    _, rows, _ = rendered
    eq = [r for r in rows if float(r["ratio"]) == 1.0 and r["theta1_deg"] == r["theta2_deg"]]
    assert len(eq) == 2
    for r in eq:
        assert abs(float(r["f_ref"]) - 0.5) < 1e-9
        assert float(r["error_even_split"]) < 1e-9


def test_closure_heldout_table(rendered):
    """The closure's held-out table: one CSV row per held-out point of the generation
    record, and the summary's max is the CSV's (outside the band)."""
    import json

    from wetcontact.reduced_models import DATA_DIR
    from wetcontact.reduced_models.transfer_fraction import RECORD_FILE

    md, _, out = rendered
    with open(out / "division_closure_heldout.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    rec = json.loads((DATA_DIR / RECORD_FILE).read_text())
    assert len(rows) == rec["held_out"]["points"]
    errs = [float(r["error"]) for r in rows if r["in_band"] == "False"]
    assert max(errs) == pytest.approx(rec["held_out"]["max"], rel=1e-9)
    assert "held-out table" in md and f"{max(errs):.3g}" in md
