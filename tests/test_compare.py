"""The one comparison record (wetcontact.compare) and the reference choice by declared rank."""

from __future__ import annotations

import numpy as np
import pytest

from wetcontact.compare import CSV_FIELDS, compare, pooled, reference_for
from wetcontact.errors import InputError
from wetcontact.models import ForceCurve, load_all


def _curve(model, visc=None, cap=None, gap=(1e-6, 2e-6, 3e-6, 4e-6)):
    return ForceCurve(case="c", model=model, gap=np.array(gap),
                      force_viscous=None if visc is None else np.array(visc, float),
                      force_capillary=None if cap is None else np.array(cap, float))


def test_statistics_by_hand():
    ref = _curve("lubrication", visc=[1.0, 2.0, 0.0, -4.0])
    cur = _curve("reynolds", visc=[1.1, 1.0, 0.5, -4.4])
    rec = compare(cur, ref, "viscous")
    # gaps 1, 2, 4 compared; errors 0.1, 0.5, 0.1; the zero reference at gap 3 is spurious
    assert rec.points == 3 and rec.spurious == 1
    assert rec.max_rel_error == pytest.approx(0.5) and rec.gap_of_max == 2e-6
    assert rec.mean_rel_error == pytest.approx(0.7 / 3)
    # linear-interpolated 95th percentile of (0.1, 0.1, 0.5): 0.1 + 0.9 * 0.4
    assert rec.p95_rel_error == pytest.approx(0.46)
    assert rec.signed_error == pytest.approx([0.1, -0.5, 0.1])
    assert rec.signed_at(4e-6) == pytest.approx(0.1) and np.isnan(rec.signed_at(3e-6))
    assert rec.rel_at(2e-6) == pytest.approx(0.5)
    row = rec.as_row()
    assert tuple(row) == CSV_FIELDS and row["closure"] == "reynolds"
    assert row["reference"] == "lubrication"


def test_total_component_and_pooling():
    ref = _curve("thinfilm", visc=[1.0, 1.0, 1.0, 1.0], cap=[-1.0, -1.0, -1.0, -1.0])
    cur = _curve("x", visc=[1.0, 1.0, 1.0, 1.0], cap=[-1.0, -1.0, -1.0, -1.5])
    tot = compare(cur, ref, "total")  # totals 0, 0, 0, -0.5 against 0: all spurious but one
    assert tot.points == 0 and tot.spurious == 1 and np.isnan(tot.max_rel_error)
    a = compare(cur, ref, "capillary")
    st = pooled([a, compare(ref, ref, "capillary")])
    assert st["points"] == 8 and st["max_rel_error"] == pytest.approx(0.5)
    assert st["mean_rel_error"] == pytest.approx(0.5 / 8)


def test_mismatched_gaps_or_missing_component_is_input_error():
    ref = _curve("meniscus", cap=[-1.0, -1.0, -1.0, -1.0])
    with pytest.raises(InputError, match="different gaps"):
        compare(_curve("toroidal", cap=[-1.0, -1.0, -1.0], gap=(1e-6, 2e-6, 3e-6)), ref,
                "capillary")
    with pytest.raises(InputError, match="no viscous force"):
        compare(_curve("toroidal", cap=[-1.0] * 4), ref, "viscous")
    with pytest.raises(InputError, match="component"):
        compare(ref, ref, "normal")


def test_reference_is_the_highest_declared_rank():
    load_all()
    brenner = _curve("brenner", visc=[1, 1, 1, 1])
    stokes = _curve("stokes", visc=[1, 1, 1, 1])
    thin = _curve("thinfilm", visc=[1, 1, 1, 1], cap=[-1, -1, -1, -1])
    lub = _curve("lubrication", visc=[1, 1, 1, 1])
    men = _curve("meniscus", cap=[-1, -1, -1, -1])
    rey = _curve("reynolds", visc=[1, 1, 1, 1])
    assert reference_for({"reynolds": rey, "stokes": stokes, "brenner": brenner},
                         "viscous") == "brenner"
    assert reference_for({"lubrication": lub, "thinfilm": thin, "stokes": stokes},
                         "viscous") == "stokes"
    assert reference_for({"lubrication": lub, "thinfilm": thin}, "viscous") == "thinfilm"
    assert reference_for({"lubrication": lub, "meniscus": men}, "capillary") == "meniscus"
    assert reference_for({"reynolds": rey}, "viscous") is None
    assert reference_for({"thinfilm": thin}, "capillary") is None  # not a capillary reference


def test_no_module_keeps_its_own_list_of_references():
    import wetcontact.report as report

    assert not hasattr(report, "VISCOUS_REFERENCES")
    assert not hasattr(report, "CAPILLARY_REFERENCES")
