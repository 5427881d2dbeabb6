"""The region summary of the capillary closure table: the S/S_c reach within a tolerance."""

from __future__ import annotations

from wetcontact.tables.capillary_closures import reach, regions


def _rows(errs, name="x"):
    fr = [0.0, 0.25, 0.5, 0.95]
    return [{"closure": name, "kind": "sphere-wall", "V*": 0.01, "theta_deg": 0.0,
             "S/S_c": f, "rel_error": e} for f, e in zip(fr, errs, strict=True)]


def test_reach_stops_at_first_failure_and_marks_failure_at_contact():
    assert reach(_rows([0.001, 0.004, 0.02, 0.001]), 0.01) == 0.25  # later recovery ignored
    assert reach(_rows([0.001, 0.004, 0.02, 0.001]), 0.05) == 0.95
    assert reach(_rows([0.2, 0.0, 0.0, 0.0]), 0.05) == -1.0
    assert reach(_rows([0.001, None, 0.0, 0.0]), 0.05) == 0.0  # refused counts as failure


def test_regions_one_row_per_series():
    reg = regions(_rows([0.001, 0.03, 0.2, 0.5]) + _rows([0.5, 0.5, 0.5, 0.5], name="y"))
    assert [(r["closure"], r["reach_1pct"], r["reach_5pct"]) for r in reg] == [
        ("x", 0.0, 0.25), ("y", -1.0, -1.0)]
