"""The report section on the dynamic rupture distance (issue 57), rendered from the shipped
generation record."""

from __future__ import annotations

import csv
import math

import pytest

from wetcontact.reduced_models import dynamic_rupture as dr
from wetcontact.sweep import SweepResult
from wetcontact.tables import StudyContext, dynamic_rupture


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    out = tmp_path_factory.mktemp("dynamic") / "reports"
    md = dynamic_rupture.section(out, SweepResult([], None, 0.0), StudyContext(quick=True))
    with open(out / "dynamic_rupture.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return md, rows, out


def test_one_row_per_run_that_reached_the_pinch(rendered):
    md, rows, out = rendered
    data = dr.load()
    ok = [r for r in data["runs"] if "result" in r and not r.get("edge")]
    assert len(rows) == len(ok)
    assert (out / "dynamic_rupture.png").stat().st_size > 0
    assert "Pitois 2001" in md and "Conclusion:" in md


def test_errors_are_relative_distances_to_the_reference(rendered):
    """Each law's error is |ratio_law / ratio_ref - 1|; Pitois' ratio is 1 + Ca^1/2; the
    held-out summary's max is the data file's."""
    md, rows, _ = rendered
    for r in rows:
        ref = float(r["ratio_ref"])
        assert float(r["ratio_pitois"]) == pytest.approx(1 + math.sqrt(float(r["Ca"])),
                                                         rel=1e-14)
        for law in ("pitois", "refit_ab", "closure"):
            col = "ratio_" + law if law != "refit_ab" else "ratio_refit_ab"
            assert float(r["err_" + law]) == pytest.approx(abs(float(r[col]) / ref - 1),
                                                           rel=1e-9, abs=1e-15)
        assert float(r["S_c_dynamic"]) == pytest.approx(ref * float(r["S_c_static"]),
                                                        rel=1e-12)
    held = [float(r["err_closure"]) for r in rows if r["held_out"] == "True"]
    assert max(held) == pytest.approx(dr.load()["held_out"]["max"], rel=1e-9)
    assert f"{max(held):.3g}" in md


def test_stability_map_lists_every_run_and_why_a_run_failed(rendered):
    """Every run of the record is on the map, the failed ones with the solver's reason (no
    ratio), the others with their volume error; the paragraph counts them."""
    md, _, out = rendered
    with open(out / "dynamic_stability.csv", newline="") as fh:
        stab = list(csv.DictReader(fh))
    runs = dr.load()["runs"]
    assert len(stab) == len(runs)
    assert (out / "dynamic_stability.png").stat().st_size > 0
    for row, run in zip(stab, runs, strict=True):
        assert row["pinch"] == str(int("result" in run))
        if "result" in run:
            assert row["reason"] == "" and float(row["volume_error"]) < 1e-12
        else:
            assert row["reason"] and row["reason"] in run["error"]
            assert math.isnan(float(row["ratio_ref"]))
    ok = sum(r["pinch"] == "1" for r in stab)
    assert f"of {len(stab)} runs" in md and f"{ok} reached the pinch" in md
