"""Every refit family through ``export c|python --refit`` (:mod:`wetcontact.export.refits`).

For each family in :data:`~wetcontact.export.refits.REFIT_FORMS` (all of
:data:`wetcontact.calibrate.FAMILIES`), with its fitted file from
``benchmarks/results/calibration``: the compiled C function, the imported numpy function
and the package's :meth:`CalibratedClosure.force` agree within 1e-12 relative at seeded
points over the whole fitted domain (the same arithmetic in the same order; libm and numpy's
elementary functions differ by an ulp or so, 1e-12 leaves room for the cancellation in
Willett's ``f1 - f2 exp(...)``), and all three answer NaN at the points outside it: past
each domain axis, another geometry, and the scene limits the package refuses.

The CLI: ``export c --refit A --refit B`` writes both functions; a bad file or a second
file of one family is one line, exit 2.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact.calibrate import FAMILIES, domain_coords, get_family, scene_inputs
from wetcontact.cli import main
from wetcontact.errors import InputError
from wetcontact.export.c_header import write_header
from wetcontact.export.closures import capillary_source, read_refit
from wetcontact.export.package_evaluation import _scene
from wetcontact.export.python_module import write_module
from wetcontact.export.refits import (
    EQUAL,
    PLANE,
    REFIT_FORMS,
    TARGET_ARGS,
    package_refit,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from exported import c_eval_many, python_eval, python_module  # noqa: E402

CALIBRATION = Path(__file__).resolve().parents[2] / "benchmarks" / "results" / "calibration"
RTOL = 1e-12
N_INSIDE = 150


def refit_file(family: str) -> Path:
    return CALIBRATION / f"{family}.json"


@pytest.fixture(scope="module")
def exports(tmp_path_factory):
    """The header and the module with all eight refits, the C values at every point (one
    compile) and the module."""
    d = tmp_path_factory.mktemp("refits")
    refits = [read_refit(refit_file(f)) for f in REFIT_FORMS]
    src = capillary_source()
    write_header(d, src, refits)
    write_module(d, src, refits)
    tables = {t.family: t for t in refits}
    pts = {f: np.vstack([inside(f, tables[f]), outside(f, tables[f])]) for f in REFIT_FORMS}
    c = c_eval_many(d, {REFIT_FORMS[f].c_name: pts[f] for f in REFIT_FORMS})
    return tables, pts, c, python_module(d / "wetcontact_closures.py")


def _radii(rng: np.random.Generator, geometry: str) -> tuple[float, float]:
    r1 = float(np.exp(rng.uniform(np.log(1e-5), np.log(1e-2))))
    if geometry == PLANE:
        return r1, math.inf
    if geometry == EQUAL:
        return r1, r1
    q = float(np.exp(rng.uniform(0.0, np.log(10.0))))
    return (r1, r1 * q) if rng.random() < 0.5 else (r1, r1 / q)


def _draw(rng: np.random.Generator, lo: float, hi: float, log: bool) -> float:
    if log:
        return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))
    return float(rng.uniform(lo, hi))


def _gap_for(family: str, row: dict[str, float], axis: str, x: float) -> float:
    """The gap at which the family's gap axis (``s_over_sc`` or ``s_over_h``) is ``x``."""
    fam = get_family(family)
    r1, r2 = row["r1"], row["r2"]
    if fam.target == "viscous" and fam.amount == "film":
        return x * row["volume_or_film_thickness"]
    if fam.target == "viscous":
        rstar = r1 if math.isinf(r2) else r1 * r2 / (r1 + r2)
        volume = row["volume_or_film_thickness"]
        if not volume > 0 or x >= 1.0:  # outside on an axis: a gap of S/H near 1 or any
            return min(10.0 * math.sqrt(abs(volume) / (math.pi * rstar)), 50 * r1) or 1e-3 * r1
        return x * math.sqrt(volume / (math.pi * rstar)) / math.sqrt(1.0 - x * x)
    liquid = {"contact_angle_sphere": row["theta1_deg"],
              "contact_angle_sphere2": row["theta2_deg"]}
    probe = 1e-3 * r1
    try:
        scene = _scene(r1, r2, probe, {"bridge_volume": row["volume"]}, liquid)
    except InputError:  # a point outside on another axis (V* <= 0): any gap will do
        return probe
    return x * probe / float(domain_coords(fam, scene_inputs(fam, scene))[axis][0])


def _row(family: str, rng: np.random.Generator, coords: dict[str, float],
         r1: float, r2: float) -> np.ndarray:
    """The exported function's arguments at domain coordinates ``coords``."""
    form = REFIT_FORMS[family]
    rs = r1 if math.isinf(r2) else min(r1, r2)
    row: dict[str, float] = {"r1": r1, "r2": r2}
    if form.target == "viscous":
        row["viscosity"] = _draw(rng, 1e-4, 1.0, True)
        row["approach_speed"] = float(rng.uniform(-1.0, 1.0))
        row["volume_or_film_thickness"] = (coords["delta_over_r"] * r1 if form.amount == "film"
                                           else coords["v_star"] * rs**3)
    else:
        row["volume"] = coords["v_star"] * rs**3
        th = coords["theta_deg"]  # a pair of angles whose cosine mean is th
        t1 = float(rng.uniform(0.0, th))
        c2 = 2.0 * math.cos(math.radians(th)) - math.cos(math.radians(t1))
        row["theta1_deg"], row["theta2_deg"] = t1, math.degrees(math.acos(min(c2, 1.0)))
        row["surface_tension"] = float(rng.uniform(0.02, 0.08))
    for axis in ("s_over_sc", "s_over_h"):
        if axis in coords:
            row["gap"] = _gap_for(family, row, axis, coords[axis])
    return np.array([row[a] for a in TARGET_ARGS[form.target]])


def inside(family: str, table) -> np.ndarray:
    """``N_INSIDE`` seeded points over the family's whole fitted domain (log-uniform in V*
    and the film thickness, uniform in the others; a radius ratio drawn either way)."""
    rng = np.random.default_rng(sum(map(ord, family)) + 20261207)
    rows = []
    for _ in range(N_INSIDE):
        coords = {a: _draw(rng, lo, hi, a in ("v_star", "delta_over_r"))
                  for a, (lo, hi) in table.domain.items()}
        r1, r2 = _radii(rng, REFIT_FORMS[family].geometry)
        if "radius_ratio" in coords:
            r2 = r1 * coords["radius_ratio"] if rng.random() < 0.5 else r1 / coords[
                "radius_ratio"]
        rows.append(_row(family, rng, coords, r1, r2))
    return np.array(rows)


def outside(family: str, table) -> np.ndarray:
    """Points the package refuses or answers NaN: past each end of each domain axis (by 2 %
    and by a factor), the other geometry, unequal spheres where equal ones are fitted, and
    the scene's limits (a radius, a viscosity, a surface tension, a speed past them; a
    negative and a NaN gap; an angle of 180 deg)."""
    rng = np.random.default_rng(sum(map(ord, family)))
    form = REFIT_FORMS[family]
    mid = {a: (math.sqrt(lo * hi) if a in ("v_star", "delta_over_r") and lo > 0
               else 0.5 * (lo + hi)) for a, (lo, hi) in table.domain.items()}
    r1, r2 = _radii(rng, form.geometry)
    if "radius_ratio" in mid:
        r2 = r1 * mid["radius_ratio"]
    rows = []
    for a, (lo, hi) in table.domain.items():
        for x in (lo * 0.98 - 1e-6, lo * 0.5 - 1e-3, hi * 1.02, hi * 1.5):
            if a == "theta_deg" and x < 0:
                continue  # below 0 deg is not an angle: the scene refuses it (below)
            c = {**mid, a: x}
            rr2 = r2
            if a == "radius_ratio":
                if x < 1.0:
                    continue  # a ratio below 1 is the same pair the other way round
                rr2 = r1 * x
            rows.append(_row(family, rng, c, r1, rr2))
    base = _row(family, rng, mid, r1, r2)
    args = TARGET_ARGS[form.target]
    i = {a: k for k, a in enumerate(args)}
    other = (1.0 if form.geometry == PLANE else math.inf)
    for name, value in (("r2", r1 * other), ("r1", 11.0), ("r1", 0.0), ("r2", -r1),
                        ("viscosity", 2e5), ("viscosity", 0.0), ("approach_speed", 2e3),
                        ("surface_tension", 20.0), ("surface_tension", 0.0),
                        ("gap", -1e-6), ("gap", math.nan), ("theta1_deg", 180.0),
                        ("theta2_deg", math.nan), ("volume", 0.0),
                        ("volume_or_film_thickness", math.nan)):
        if name in i:
            row = base.copy()
            row[i[name]] = value
            rows.append(row)
    if form.geometry == EQUAL:
        row = base.copy()
        row[i["r2"]] = r1 * 1.01
        rows.append(row)
    return np.array(rows)


def package_values(table, rows: np.ndarray) -> np.ndarray:
    return np.array([package_refit(table, *map(float, r)) for r in rows])


def test_every_family_is_registered():
    assert set(REFIT_FORMS) == set(FAMILIES)
    assert all(refit_file(f).is_file() for f in REFIT_FORMS)


@pytest.mark.parametrize("family", list(REFIT_FORMS))
def test_c_python_and_package_agree(exports, family):
    """Within 1e-12 relative inside the domain; NaN together outside (and NaN at every
    outside point)."""
    tables, pts, c_all, mod = exports
    form = REFIT_FORMS[family]
    rows = pts[family]
    want = package_values(tables[family], rows)
    c = c_all[form.c_name]
    py = python_eval(mod, form.py_name, rows)
    n_in = N_INSIDE
    assert np.all(np.isfinite(want[:n_in])), f"{family}: package NaN at a drawn point"
    assert np.all(np.isnan(want[n_in:])), f"{family}: a point meant outside is inside"
    np.testing.assert_array_equal(np.isnan(c), np.isnan(want))
    np.testing.assert_array_equal(np.isnan(py), np.isnan(want))
    ok = np.isfinite(want)
    rel_c = np.max(np.abs(c[ok] / want[ok] - 1.0))
    rel_py = np.max(np.abs(py[ok] / want[ok] - 1.0))
    print(f"{family}: max |C/package - 1| = {rel_c:.2g}, |Python/package - 1| = "
          f"{rel_py:.2g} ({ok.sum()} points, {(~ok).sum()} NaN)")
    assert rel_c <= RTOL and rel_py <= RTOL
    sign = -1.0 if form.target == "capillary" else 1.0
    if form.target != "viscous":
        assert np.all(sign * want[ok] > 0)


def test_cli_writes_every_refit_and_refuses_in_one_line(tmp_path, capsys):
    a, b = refit_file("mikami-pw"), refit_file("finite-liquid")
    out = tmp_path / "h.h"
    assert main(["export", "c", "--out", str(out), "--refit", str(a), "--refit", str(b),
                 "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["functions"][-2:] == ["wc_refit_mikami_pw", "wc_refit_finite_liquid"]
    text = out.read_text()
    for name, f in (("wc_refit_mikami_pw", a), ("wc_refit_finite_liquid", b)):
        assert f"static inline double {name}(" in text and f.name in text
    assert main(["export", "python", "--out", str(tmp_path / "m.py"), "--refit", str(a)]) == 0
    capsys.readouterr()
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"family": "bagheri", "coefficients": [1.0], "domain": {}}))
    copy = tmp_path / "mikami-pw-copy.json"
    copy.write_bytes(a.read_bytes())
    for fmt in ("c", "python"):
        for argv, says in (
                (["--refit", str(bad)], "field 'coefficients' has 1 values"),
                (["--refit", str(tmp_path / "none.json")], "no such calibration file"),
                (["--refit", str(a), "--refit", str(copy)],
                 "family 'mikami-pw' already given by --refit")):
            dest = tmp_path / f"x.{fmt}"
            assert main(["export", fmt, "--out", str(dest), *argv]) == 2, argv
            err = capsys.readouterr().err.strip()
            assert err.count("\n") == 0 and "Traceback" not in err, err
            assert says in err, err
            assert not dest.exists()


@pytest.mark.parametrize("family", list(REFIT_FORMS))
def test_json_export_carries_every_family(tmp_path, family):
    """``export json --coefficients`` already takes every family: its coefficients and
    domain are the file's."""
    out = tmp_path / "c.json"
    assert main(["export", "json", "--coefficients", str(refit_file(family)), "--out",
                 str(out)]) == 0
    doc = json.loads(out.read_text())
    src = json.loads(refit_file(family).read_text())
    assert doc["closure"] == family and doc["parts"][0]["coefficients"] == src["coefficients"]
    assert doc["parts"][0]["domain"] == src["domain"]
