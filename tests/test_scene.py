"""Scene construction and validation (values, ranges, units)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import BASE_CASE, make_scene

from wetcontact.errors import CaseError
from wetcontact.scene import load_case, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]


def test_every_shipped_case_loads_with_a_source():
    files = sorted((ROOT / "cases").glob("*.toml"))
    assert len(files) >= 8
    for f in files:
        sc = load_case(f)
        assert sc.source.strip() and sc.description.strip(), f


def test_angles_in_degrees_become_radians_and_scene_is_frozen():
    sc = make_scene(liquid={"viscosity": 1e-3, "surface_tension": 0.07, "density": 1e3,
                            "contact_angle_sphere": 30.0, "contact_angle_wall": 60.0})
    assert sc.contact_angle_sphere == pytest.approx(math.pi / 6)
    assert sc.contact_angle_wall == pytest.approx(math.pi / 3)
    with pytest.raises(AttributeError):
        sc.radius = 2.0  # type: ignore[misc]


def test_sphere_sphere_reduced_radius_and_default_radius2():
    sc = make_scene(geometry={"kind": "sphere-sphere", "radius": 1e-3, "radius2": 3e-3})
    assert sc.reduced_radius == pytest.approx(0.75e-3)
    eq = make_scene(geometry={"kind": "sphere-sphere", "radius": 1e-3})
    assert eq.radius2 == 1e-3 and eq.equal_spheres
    assert sc.willett_radius == pytest.approx(1.5e-3)
    assert make_scene().willett_radius == pytest.approx(2e-3)  # Derjaguin: 2R for a wall


def test_gap_range_log_and_linear():
    sc = make_scene(motion={"velocity": 1.0, "gaps": {"start": 1e-4, "stop": 1e-6,
                                                      "points": 3}})
    # atol=0: np.allclose's default atol 1e-8 is 1 % of a 1e-6 m gap; rtol 1e-12 is
    # geomspace's round-off with margin
    assert np.allclose(sc.gap_array, [1e-4, 1e-5, 1e-6], rtol=1e-12, atol=0)
    sc = make_scene(motion={"velocity": 1.0, "gaps": {"start": 1e-6, "stop": 3e-6, "points": 3,
                                                      "spacing": "linear"}})
    assert np.allclose(sc.gap_array, [1e-6, 2e-6, 3e-6], rtol=1e-12, atol=0)


@pytest.mark.parametrize("table, value, field", [
    ("amount", {"immersed": False}, "amount.immersed"),
    ("amount", {}, "amount"),
    ("liquid", {"viscosity": 1e-3, "surface_tension": 0.07, "density": 1e3,
                "contact_angle": 10.0, "contact_angle_sphere": 10.0},
     "liquid.contact_angle_sphere"),
    ("liquid", {"viscosity": 1e-3, "surface_tension": 0.07, "density": 1e3,
                "contact_angle_sphere": 10.0}, "liquid.contact_angle_wall"),
    ("liquid", {"viscosity": 1e-3, "surface_tension": float("nan"), "density": 1e3},
     "liquid.surface_tension"),
    ("motion", {"velocity": 1.0, "gaps": []}, "motion.gaps"),
    ("motion", {"velocity": 1.0, "gaps": [1.0]}, "motion.gaps[0]"),
    ("fidelity", {"tolerance": 0.01, "model": "stokes"}, "fidelity"),
    ("geometry", {"kind": "sphere-wall", "radius": True}, "geometry.radius"),
])
def test_invalid_values_name_field(table, value, field):
    with pytest.raises(CaseError) as info:
        make_scene(**{table: value})
    assert info.value.field == field
    assert "allowed" in str(info.value)


def test_film_only_on_a_wall():
    with pytest.raises(CaseError, match="amount.film_thickness"):
        make_scene(geometry={"kind": "sphere-sphere", "radius": 1e-3},
                   amount={"film_thickness": 1e-4})


def test_unknown_top_level_key_and_missing_file(tmp_path):
    with pytest.raises(CaseError, match="colour"):
        scene_from_dict({**BASE_CASE, "colour": "blue"})
    with pytest.raises(CaseError, match="nope.toml"):
        load_case(tmp_path / "nope.toml")


def test_canonical_json_is_stable_and_complete():
    a, b = make_scene(), make_scene()
    assert a.canonical_json() == b.canonical_json()
    assert '"viscosity":0.001' in a.canonical_json()
