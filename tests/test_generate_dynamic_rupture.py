"""The dynamic-rupture generator's run cache and its end-to-end pipeline, on a stand-in
solver (the real runs take minutes each: they are the slow suite's and the benchmark's)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import wetcontact.generate.dynamic_rupture as gen
from wetcontact.branch_cache import cache_file, read_rows
from wetcontact.reduced_models import dynamic_rupture as dr
from wetcontact.solver.stokes_dynamic.rupture import RuptureCase

COEF = {"wall": {"a": 2.0, "b": 0.5, "c": 0.01, "d": 0.05, "e": -0.3, "g": 0.0},
        "pair": {"a": 1.5, "b": 0.45, "c": 0.0, "d": -0.02, "e": 0.2, "g": -0.35}}


def _fake_solve(calls: list):
    """A stand-in for one run: the closure's own form at known coefficients (and a failure
    at one case, as a remeshing failure would report it)."""

    def solve(job):
        case, preset = job
        calls.append(case)
        row = {"key": gen.RunCache.key(case, preset), "case": gen.asdict(case),
               "preset": preset}
        if case.capillary_number == 0.3 and case.volume == 1e-2 and case.theta_deg == 50.0:
            row["error"] = "stand-in: remeshing failed"
            return row
        wall = case.kind == "wall"
        v, rho = ((case.volume, 1.0) if wall
                  else dr.pair_coordinates(case.volume, case.radius_ratio))
        ratio = dr.ratio_form(COEF, np.array([wall]), np.array([case.capillary_number]),
                              np.array([v]), np.array([case.theta_deg]), np.array([rho]))
        row["result"] = {"ratio": float(ratio[0])}
        return row

    return solve


def test_run_cache_round_trip_skips_a_cut_line(tmp_path):
    cache = gen.RunCache(tmp_path)
    case = RuptureCase("wall", 1e-2, 1e-3, 20.0)
    row = {"key": cache.key(case, "default"), "result": {"ratio": 1.2}}
    cache.put(row)
    with cache.path.open("a") as fh:  # a kill in the middle of a write
        fh.write('{"key": "cut", "res')
    again = gen.RunCache(tmp_path)
    assert again.rows == {row["key"]: row}
    assert again.path == cache_file("dynamic_rupture", gen.SOURCES, tmp_path)
    # a new version of the sources reads another file
    assert cache_file("dynamic_rupture", gen.SOURCES[:-1], tmp_path) != again.path


def test_solve_all_solves_only_what_the_cache_lacks(tmp_path, monkeypatch):
    calls: list = []
    monkeypatch.setattr(gen, "solve_case", _fake_solve(calls))
    cases = gen.fit_cases()[:5]
    cache = gen.RunCache(tmp_path)
    first = gen.solve_all(cases[:3], workers=1, cache=cache)
    assert calls == cases[:3]
    # a new process (a rerun after a kill) reads the file and solves the rest only
    rows = gen.solve_all(cases, workers=1, cache=gen.RunCache(tmp_path))
    assert calls == cases[:3] + cases[3:]
    assert rows[:3] == first
    assert [r["case"] for r in rows] == [gen.asdict(c) for c in cases]
    assert len(list(read_rows(cache.path))) == 5


def test_generator_recovers_known_coefficients(tmp_path, monkeypatch):
    """End to end on the stand-in solver: the grid, the held-out cases, the fit and the
    data file; the fit finds the coefficients the stand-in was built from."""
    calls: list = []
    monkeypatch.setattr(gen, "solve_case", _fake_solve(calls))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    out = tmp_path / "dynamic_rupture.json"
    data = gen.generate_dynamic_rupture(out, workers=1, log=lambda _m: None)
    held = gen.HELD_OUT + gen.UNEQUAL_HELD_OUT
    assert len(calls) == len(gen.fit_cases()) + held + len(gen.EDGE_CASES)
    assert sum(r["edge"] for r in data["runs"]) == len(gen.EDGE_CASES)
    assert sum(r["held_out"] for r in data["runs"]) == held
    assert json.loads(out.read_text())["coefficients"] == data["coefficients"]
    for kind, want in COEF.items():
        for name, value in want.items():
            assert data["coefficients"][kind][name] == pytest.approx(value, abs=1e-6)
    assert data["held_out"]["max"] < 1e-8
    errors = [r for r in data["runs"] if "error" in r]
    assert len(errors) == 1 and errors[0]["case"]["capillary_number"] == 0.3
    # a rerun finds every run in the cache
    n = len(calls)
    gen.generate_dynamic_rupture(out, workers=1, log=lambda _m: None)
    assert len(calls) == n


def test_unequal_cases_hold_their_volume_over_the_effective_radius():
    """An unequal pair's V/R^3 is V*/R*^3 of the grid's V*, and its held-out cases lie
    inside the grid's ranges (seeded)."""
    for c in gen.fit_cases():
        if c.radius_ratio != 1.0:
            v, rho = dr.pair_coordinates(c.volume, c.radius_ratio)
            assert min(gen.UNEQUAL_VOLUMES, key=lambda g: abs(g - v)) == pytest.approx(
                v, rel=1e-7)  # V/R^3 rounded to 1e-10
            assert 1 / rho in gen.UNEQUAL_RATIOS
    cases = gen.unequal_held_out_cases()
    assert cases == gen.unequal_held_out_cases()
    for c in cases:
        v, rho = dr.pair_coordinates(c.volume, c.radius_ratio)
        assert gen.UNEQUAL_VOLUMES[0] <= v * (1 + 1e-6) and v <= gen.UNEQUAL_VOLUMES[-1]
        assert 1 / gen.UNEQUAL_RATIOS[-1] <= rho <= 1.0
        assert gen.UNEQUAL_CAS[0] <= c.capillary_number <= gen.UNEQUAL_CAS[-1]


def test_held_out_cases_lie_inside_the_grid():
    cases = gen.held_out_cases()
    assert cases == gen.held_out_cases()  # seeded
    for c in cases:
        ths = gen.THETAS if c.kind == "wall" else gen.PAIR_THETAS
        assert gen.CAS[0] <= c.capillary_number <= gen.CAS[-1]
        assert gen.VOLUMES[0] <= c.volume <= gen.VOLUMES[-1]
        assert ths[0] <= c.theta_deg <= ths[-1]
        assert not any(math.isclose(c.capillary_number, g) for g in gen.CAS)
