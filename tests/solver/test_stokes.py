"""Axisymmetric Stokes FEM against exact Stokes results.

References: the Stokes drag 6 pi eta R v of an isolated sphere (with the Haberman & Sayre
1958 factor for the finite container), Brenner's (1961) sphere-wall series and the
two-sphere / shear-free-plane series, all from ``wetcontact.reduced_models.viscous``. The
tolerances are the presets' documented bounds (fast 1e-3, accurate 1e-5), measured by
``benchmarks/bench_stokes.py``.
"""

from __future__ import annotations

import math

import meshio
import numpy as np
import pytest

from wetcontact.errors import SolverError, ValidityError
from wetcontact.meshes.builders import Resolution
from wetcontact.meshes.cache import get_mesh
from wetcontact.models import get_model
from wetcontact.reduced_models.viscous import brenner_lambda, two_sphere_lambda
from wetcontact.solver import stokes as st

R, ETA, V = 1.0e-3, 1.0e-3, 0.1


@pytest.fixture(scope="module")
def model():
    return get_model("stokes")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("WETCONTACT_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))


def _scene(factory, kind="sphere-wall", gaps=(1e-3,), **amount):
    return factory(geometry={"kind": kind, "radius": R},
                   liquid={"viscosity": ETA, "surface_tension": 0.072, "density": 998.0},
                   amount=amount or {"immersed": True},
                   motion={"velocity": V, "gaps": [g * R for g in gaps]})


def test_isolated_sphere_stokes_drag():
    """6 pi eta R v within 1e-4 after the exact finite-container factor K(R/L)."""
    res = Resolution(h_sphere=0.05, growth=0.15, far=1e4)
    sol = st.solve_stokes(get_mesh("isolated_sphere", res=res), {"sphere": -1.0})
    k = st.container_factor(1.0 / res.far)
    assert k == pytest.approx(1 + 2.25e-4, rel=1e-6)  # the correction is not negligible
    assert sol.force_reaction / (6 * math.pi * k) == pytest.approx(1.0, abs=1e-4)
    assert sol.force_traction / (6 * math.pi * k) == pytest.approx(1.0, abs=1e-3)


@pytest.mark.parametrize("s", [1e-4, 1e-3, 0.1, 1.0, 10.0])
def test_sphere_wall_fast_preset_within_1e_3_of_brenner(model, scene_factory, s):
    curve = model.force(_scene(scene_factory, gaps=(s,)), preset="fast")
    ref = 6 * math.pi * ETA * R * V * brenner_lambda(s)
    assert curve.force_viscous[0] / ref == pytest.approx(1.0, abs=1e-3)
    assert curve.force_viscous[0] > 0  # resistance to approach pushes the surfaces apart
    assert curve.diagnostics["gap_elements"][0] >= model.presets["fast"]["n_gap"]


def test_reaction_equals_dissipation_and_traction_agrees():
    res = Resolution(n_gap=3, h_sphere=0.08, growth=0.25, far=1e3)
    sol = st.solve_stokes(get_mesh("sphere_wall", gap=0.1, res=res, plane="wall"),
                          {"sphere": -1.0})
    assert sol.force_dissipation == pytest.approx(sol.force_reaction, rel=1e-9)
    assert sol.force_traction == pytest.approx(sol.force_reaction, rel=3e-3)


@pytest.mark.parametrize("s", [1e-3, 1.0])
def test_two_spheres_symmetry_and_full_mesh_against_series(model, scene_factory, s):
    """The shear-free-plane half problem, the full two-sphere mesh and the series agree."""
    scene = _scene(scene_factory, kind="sphere-sphere", gaps=(s,))
    ref = 6 * math.pi * ETA * R * (V / 2) * two_sphere_lambda(s)
    half = model.force(scene, preset="fast", method="symmetry").force_viscous[0]
    full = model.force(scene, preset="fast", method="full").force_viscous[0]
    assert half / ref == pytest.approx(1.0, abs=1e-3)
    assert full / ref == pytest.approx(1.0, abs=1e-3)
    assert full / half == pytest.approx(1.0, abs=1e-3)


def test_sign_follows_velocity(model, scene_factory):
    sc = scene_factory(geometry={"kind": "sphere-wall", "radius": R},
                       motion={"velocity": -V, "gaps": [0.1 * R]})
    assert model.force(sc, preset="fast").force_viscous[0] < 0


def test_refuses_tiny_gap_and_bridge(model, scene_factory):
    with pytest.raises(ValidityError, match="S/R"):
        model.force(_scene(scene_factory, gaps=(5e-6,)))
    with pytest.raises(ValidityError, match="lubrication"):
        model.force(_scene(scene_factory, gaps=(0.01,), bridge_volume=1e-12))


def test_refuses_mesh_with_too_few_gap_elements(model, scene_factory, monkeypatch):
    monkeypatch.setattr(st, "gap_elements", lambda mesh, z0, z1: 1)
    with pytest.raises(SolverError, match="elements across the gap"):
        model.force(_scene(scene_factory, gaps=(0.01,)), preset="fast")


def test_film_approaches_lubrication_as_the_film_thins(model, scene_factory):
    """S/delta = 0.5 fixed; F_FEM / [6 pi eta R^2 v/S (1 - S/delta)^2] -> 1 as delta/R -> 0."""
    ratios = []
    for delta in (0.04, 0.01):
        s = 0.5 * delta
        sc = _scene(scene_factory, gaps=(s,), film_thickness=delta * R)
        f = model.force(sc, preset="fast").force_viscous[0]
        lub = 6 * math.pi * ETA * R**2 * V / (s * R) * (1 - s / delta) ** 2
        ratios.append(f / lub)
    dev = np.abs(np.array(ratios) - 1.0)
    assert dev[1] < 0.7 * dev[0]
    assert dev[1] < 0.12


def test_film_gap_above_the_film_has_no_force(model, scene_factory):
    sc = _scene(scene_factory, gaps=(0.01, 0.06), film_thickness=0.05 * R)
    f = model.force(sc, preset="fast").force_viscous
    assert f[0] > 0 and f[1] == 0.0


def test_save_fields_writes_vtu(model, scene_factory, tmp_path):
    assert model.saves_fields  # the CLI's --save-fields relies on it
    curve = model.force(_scene(scene_factory, gaps=(0.1,)), preset="fast",
                        save_fields=str(tmp_path))
    (path,) = curve.diagnostics["vtu_files"]
    m = meshio.read(path)
    assert set(m.point_data) == {"velocity", "pressure"}
    # the sphere moves at -v: some vertex carries that velocity
    assert m.point_data["velocity"][:, 1].min() == pytest.approx(-V, rel=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("s", [1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0])
def test_sphere_wall_accurate_preset_within_1e_5_of_brenner(model, scene_factory, s):
    curve = model.force(_scene(scene_factory, gaps=(s,)), preset="accurate")
    ref = 6 * math.pi * ETA * R * V * brenner_lambda(s)
    assert curve.force_viscous[0] / ref == pytest.approx(1.0, abs=1e-5)


@pytest.mark.slow
@pytest.mark.parametrize("s", [1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0])
def test_two_spheres_accurate_preset_within_1e_5_of_series(model, scene_factory, s):
    scene = _scene(scene_factory, kind="sphere-sphere", gaps=(s,))
    ref = 6 * math.pi * ETA * R * (V / 2) * two_sphere_lambda(s)
    f = model.force(scene, preset="accurate").force_viscous[0]
    assert f / ref == pytest.approx(1.0, abs=1e-5)


def test_error_table_section_quick(tmp_path):
    """The report section writes its CSV and a Markdown table whose FEM column is small."""
    import csv

    from wetcontact.store import Store
    from wetcontact.sweep import sweep
    from wetcontact.tables import StudyContext
    from wetcontact.tables.stokes import points, section

    ctx = StudyContext(quick=True)
    md = section(tmp_path, sweep(points(ctx), Store(tmp_path / "s.h5"), progress=False), ctx)
    assert md.startswith("## ") and "| immersed |" in md and "| film |" in md
    rows = list(csv.DictReader((tmp_path / "stokes_errors.csv").open()))
    imm = [r for r in rows if r["case"] == "immersed"]
    assert imm and all(abs(float(r["fem_vs_exact"])) < 1e-3 for r in imm)
    # Reynolds is 12.7 % low against the exact force at S/R = 0.1 (PHYSICS.md)
    r01 = next(r for r in imm if float(r["s_over_r"]) == 0.1)
    assert float(r01["err_reynolds"]) == pytest.approx(-0.127, abs=2e-3)
