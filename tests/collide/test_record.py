"""Collisions as store points: the record, collision studies, sweep, store and export csv."""

from __future__ import annotations

import csv
import dataclasses
import math
from pathlib import Path

import pytest

from wetcontact.collide import collide, collision_case_from_dict
from wetcontact.collide.record import (
    FORCE_SET_NAMES,
    collision_from_curve,
    is_record,
    point_case,
    solve,
)
from wetcontact.errors import CaseError, InputError
from wetcontact.export.csv import COLLISION_COLUMNS, write_csv
from wetcontact.store import Store
from wetcontact.study import load_study
from wetcontact.sweep import Point, sweep

R = 1e-3


def bridge_case(vstar: float = 0.01, st: float = 100.0, e_dry: float = 0.97):
    """A 2 mm glass bead on a wall with a water bridge, started at its rupture distance."""
    c = collision_case_from_dict({
        "name": "bridge-impact", "geometry": {"kind": "sphere-wall", "radius": R},
        "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
                   "contact_angle": 20.0},
        "amount": {"bridge_volume": vstar * R ** 3}, "impact": {"velocity": 1.0},
        "solid": {"density": 2500.0, "restitution": e_dry, "roughness": 1e-4 * R}})
    return c.with_(velocity=c.stokes_velocity(st))


def test_stokes_velocity_inverts_the_stokes_number():
    c = bridge_case(st=37.0)
    res = collide(c, trajectory=False)
    assert res.stokes_number == pytest.approx(37.0, rel=1e-12)


def test_bridge_started_at_its_rupture_distance_rebounds_with_its_speed_there():
    """The default start gap of a bridge is its rupture distance, where the rupture event
    and the start gap coincide: e is the speed there (it used to be reported a stick)."""
    res = collide(bridge_case(0.01, 100.0), trajectory=True)
    assert res.outcome == "rebound"
    assert res.settings["start_gap"] == pytest.approx(res.liquid["rupture_distance_static"])
    v_end = -float(res.trajectory["velocity"][-1])
    assert res.restitution == pytest.approx(v_end / res.settings["velocity"], rel=1e-12)
    assert 0.0 < res.restitution < 0.97
    assert abs(res.diagnostics["energy_residual"]) <= 1e-9


def test_conservative_bridge_returns_the_impact_speed():
    """e_dry = 1, no viscous force, the same angle on approach and rebound: the bridge's
    work on approach is returned on rebound, e = 1. The fold's square-root force (F - F_c ~
    sqrt(S_c - S)) limits DOP853 there: 7e-8 at the default rtol."""
    c = bridge_case(0.01, 50.0, e_dry=1.0)
    res = collide(c, viscous="none", trajectory=False)
    assert res.outcome == "rebound"
    assert abs(res.restitution - 1.0) <= 1e-6
    assert res.energy["capillary"] == pytest.approx(-res.energy["bridge"], rel=1e-6)


def test_record_round_trip_through_the_store(tmp_path: Path):
    case = point_case(bridge_case(0.01, 100.0))
    curve = solve(case, "reference")
    assert is_record(curve)
    assert curve.model == "collide/reference"
    st = Store(tmp_path / "s.h5")
    key = st.save(case.scene, curve)
    back = collision_from_curve(st.load(key))
    direct = collide(case, trajectory=False)
    assert back.restitution == direct.restitution
    assert back.outcome == direct.outcome
    assert back.phases == direct.phases
    assert back.liquid["transfer_fraction"] == direct.liquid["transfer_fraction"]
    assert float(st.load(key).extras["restitution"][0]) == direct.restitution
    with pytest.raises(InputError, match="force set"):
        solve(case, "hertz")


def test_points_of_two_force_sets_or_two_cases_have_different_keys():
    case = point_case(bridge_case())
    keys = {Point(case.scene, m, collision=case).key for m in FORCE_SET_NAMES}
    assert len(keys) == len(FORCE_SET_NAMES)
    other = case.with_(solid=dataclasses.replace(case.solid, restitution=0.9))
    assert Point(other.scene, "reference", collision=other).key != \
        Point(case.scene, "reference", collision=case).key


def _study(tmp_path: Path, body: str) -> Path:
    base = Path(__file__).resolve().parents[2] / "cases" / "collisions"
    p = tmp_path / "study.toml"
    p.write_text(f'name = "s"\nbase = "{base / "glass-2mm-water-film-impact.toml"}"\n'
                 + body)
    return p


def test_collision_study_sweeps_into_the_store_and_exports(tmp_path: Path):
    path = _study(tmp_path, 'models = ["reference", "mercurydpm"]\n[axes]\n'
                  '"amount.film_over_radius" = [0.05, 0.1]\n'
                  '"impact.stokes_number" = [20.0, 300.0]\n')
    study = load_study(path)
    assert study.collisions and len(study.cases) == 4
    pts = study.points()
    assert len(pts) == 8 and all(p.collision is not None for p in pts)
    store = Store(tmp_path / "s.h5")
    res = sweep(pts, store, workers=0, progress=False)
    assert res.count("computed") == 8 and res.count("failed") == 0
    again = sweep(study.points(), store, workers=0, progress=False)
    assert again.count("reused") == 8
    for p in pts:  # each stored record is the collision integrated directly
        c = collision_from_curve(res.curve(p))
        assert c.stokes_number == pytest.approx(p.axes["impact.stokes_number"], rel=1e-12)
        direct = collide(p.collision, force_set=None if p.model == "reference" else p.model,
                         trajectory=False)
        assert c.restitution == direct.restitution
    out = tmp_path / "o.csv"
    counts = write_csv(pts, study.axes, store, out)
    assert counts["ok"] == 8
    rows = list(csv.DictReader(out.open()))
    assert list(rows[0]) == [*study.axes, *COLLISION_COLUMNS]
    ref = [r for r in rows if r["force_set"] == "reference"]
    assert {r["outcome"] for r in ref} <= {"rebound", "stick"}
    assert all(math.isfinite(float(r["restitution"])) for r in rows)


def test_collision_study_bad_input_names_the_entry(tmp_path: Path):
    with pytest.raises(CaseError, match=r"models\[0\].*force sets: reference"):
        load_study(_study(tmp_path, 'models = ["lubrication"]\n[axes]\n'
                          '"impact.stokes_number" = [20.0]\n'))
    with pytest.raises(CaseError, match=r"axes.impact.stokes_number"):
        load_study(_study(tmp_path, 'models = ["reference"]\n[axes]\n'
                          '"impact.stokes_number" = [-1.0]\n'))
    with pytest.raises(CaseError, match=r"solid.restitution"):
        load_study(_study(tmp_path, 'models = ["reference"]\n[axes]\n'
                          '"solid.restitution" = [0.5, 1.5]\n'))


def test_stokes_number_needs_a_collision_base(tmp_path: Path):
    base = Path(__file__).resolve().parents[2] / "cases" / "glass-2mm-water-film.toml"
    p = tmp_path / "study.toml"
    p.write_text(f'name = "s"\nbase = "{base}"\nmodels = ["reynolds"]\n[axes]\n'
                 '"impact.stokes_number" = [20.0]\n')
    with pytest.raises(CaseError, match="collision base"):
        load_study(p)


def test_report_section_renders_from_the_store(tmp_path: Path):
    """The collisions section's impacts are swept into a store and rendered from it; a
    rendered row is the collision integrated directly."""
    from wetcontact.tables import StudyContext, collisions

    ctx = StudyContext(quick=True)
    pts = collisions.points(ctx)
    assert all(p.collision is not None for p in pts)
    res = sweep(pts, Store(tmp_path / "s.h5"), workers=0, progress=False)
    assert res.count("failed") == 0
    md = collisions.section(tmp_path, res, ctx)
    for name in ("collision_immersed", "collision_dem", "collision_bridge"):
        assert (tmp_path / f"{name}.csv").is_file() and (tmp_path / f"{name}.png").is_file()
    assert "Stick or rebound with a pendular bridge" in md
    rows = collisions.bridge_rows(res, True)
    r = rows[-1]
    direct = collide(collisions.bridge_case(r["volume_over_radius3"], r["St"], r["rupture"]),
                     trajectory=False)
    assert r["restitution"] == direct.restitution and r["outcome"] == direct.outcome
