"""collide --tol: the shipped restitution bounds hold off their grid, and the choice."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wetcontact.collide import collide
from wetcontact.collide.batch import restitution_map
from wetcontact.collide.tolerance import CANDIDATES, DATA, _case, _critical

BOUNDS = json.loads(DATA.read_text())["candidates"]


@pytest.mark.parametrize("seed", [11, 12, 13])
def test_bounds_hold_at_random_points_of_the_box(seed: int) -> None:
    """Away from each pair's uncertain band around its critical St, |e - e_ref| stays
    within the bound measured on the generator's grid, at geometries off that grid."""
    rng = np.random.default_rng(seed)
    case = _case(rng.uniform(0.02, 0.1), rng.uniform(0.0, 40.0), rng.uniform(0.5, 1.0),
                 10 ** rng.uniform(-5, -3))
    st = np.geomspace(5.0, 1000.0, 150)
    speeds = st * 6 * math.pi * 1e-3 * 1e-6 / (2500.0 * 4 / 3 * math.pi * 1e-9)
    ref = restitution_map(case, velocity=speeds)
    for v, c in CANDIDATES:
        rec = BOUNDS[f"{v}+{c}"]
        res = restitution_map(case, velocity=speeds, viscous=v, capillary=c)
        far = np.abs(st / _critical(st, res.stick) - 1.0) > rec["band"]
        assert np.max(np.abs(res.restitution - ref.restitution)[far]) <= rec["e_bound"]


def test_tol_picks_a_cheaper_pair_within_its_bound() -> None:
    case = _case(0.05, 20.0, 0.9, 1e-4).with_(velocity=0.5)
    loose = collide(case, tol=0.01, trajectory=False)
    ref = collide(case, trajectory=False)
    tol = loose.models["tolerance"]
    assert (loose.models["viscous"], loose.models["capillary"]) == CANDIDATES[0]
    assert abs(loose.restitution - ref.restitution) <= tol["bound"] <= 0.01
    tight = collide(case, tol=1e-6, trajectory=False)
    assert tight.models["tolerance"]["bound"] is None
    assert tight.models["viscous"] == ref.models["viscous"]


def test_tol_outside_the_box_uses_the_reference() -> None:
    case = _case(0.05, 20.0, 0.9, 1e-4).with_(velocity=0.5, contact_model="hertz")
    from dataclasses import replace

    case = replace(case, solid=replace(case.solid, youngs_modulus=6e10),
                   solid2=replace(case.solid2, youngs_modulus=6e10))
    res = collide(case, tol=0.01, trajectory=False)
    assert "impulse contact" in res.models["tolerance"]["reason"]
    assert res.models["capillary"] == "calibrated-capillary"
