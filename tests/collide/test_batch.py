"""The vectorised restitution map against the event-driven integrator, and its order."""

from __future__ import annotations

import numpy as np
import pytest

from wetcontact.collide import collide
from wetcontact.collide.batch import ORDER, restitution_map
from wetcontact.errors import InputError
from wetcontact.models import observed_order
from wetcontact.tables.collisions import film_case

CASE = film_case(5e-5, 100.0)
MASS = CASE.solid.density * 4 / 3 * np.pi * 1e-9
SPEEDS = np.array([30.0, 60.0, 100.0, 300.0]) * 6 * np.pi * 1e-3 * 1e-6 / MASS


@pytest.mark.parametrize("capillary", ["none", None])
def test_map_matches_collide(capillary: str | None) -> None:
    """Two integrators of the same equations (time with events; ln x with RK4)."""
    ref = [collide(CASE.with_(velocity=float(v)), capillary=capillary, trajectory=False)
           for v in SPEEDS]
    b = restitution_map(CASE, velocity=SPEEDS, capillary=capillary)
    assert np.max(np.abs(b.restitution - [r.restitution for r in ref])) < 1e-7
    assert list(b.stick) == [r.outcome == "stick" for r in ref]
    assert np.allclose(b.stokes_number, [r.stokes_number for r in ref], rtol=1e-12)


def test_map_order() -> None:
    """RK4 in ln x: the error against a 6400-step map falls as steps^-ORDER."""
    kw = {"velocity": SPEEDS[1:], "viscous": "reynolds-finite", "capillary": "willett"}
    fine = restitution_map(CASE, steps=6400, **kw).restitution
    ns = np.array([8, 16, 32, 64])
    err = [np.max(np.abs(restitution_map(CASE, steps=int(n), **kw).restitution - fine))
           for n in ns]
    assert abs(observed_order(1.0 / ns, err) - ORDER) < 0.5


def test_map_refuses_what_it_does_not_model() -> None:
    with pytest.raises(InputError, match="use wetcontact.collide.collide"):
        restitution_map(CASE.with_(contact_model="hertz"))


def test_one_impact_path_equals_the_array_path() -> None:
    many = restitution_map(CASE, velocity=SPEEDS)
    for v, e in zip(SPEEDS, many.restitution, strict=True):
        assert abs(restitution_map(CASE, velocity=float(v)).restitution.item() - e) < 1e-13
