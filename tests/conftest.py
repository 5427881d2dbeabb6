"""Shared test fixtures: scenes built in memory from case-file style dicts."""

from __future__ import annotations

import copy
from typing import Any

import pytest

from wetcontact.models import load_all
from wetcontact.scene import Scene, scene_from_dict

load_all()  # fill the registry: closures and every solver present

BASE_CASE: dict[str, Any] = {
    "name": "test-scene",
    "geometry": {"kind": "sphere-wall", "radius": 1.0e-3},
    "liquid": {"viscosity": 1.0e-3, "surface_tension": 0.072, "density": 998.0,
               "contact_angle": 0.0},
    "amount": {"immersed": True},
    "motion": {"velocity": 0.1, "gaps": [1e-5, 1e-4]},
}


def make_scene(**tables: dict[str, Any]) -> Scene:
    """Scene from :data:`BASE_CASE` with whole tables replaced, e.g.
    ``make_scene(amount={"film_thickness": 1e-4}, geometry={...})``."""
    data = copy.deepcopy(BASE_CASE)
    for key, val in tables.items():
        data[key] = val
    return scene_from_dict(data)


@pytest.fixture
def scene_factory():
    """The :func:`make_scene` builder as a fixture."""
    return make_scene
