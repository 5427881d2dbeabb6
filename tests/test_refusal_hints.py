"""Refusal hints are consistent: a model that refuses a scene never names, as the model to
use instead, a model that refuses the same scene (issue 12).

Scenes: every case file in ``cases/`` plus a grid of built scenes (sphere-wall, equal,
unequal and very unequal spheres; immersed, thin and thick films, small and large bridges;
no slip, slip on one or both surfaces, unequal slip; tiny, small and wide gaps; equal and
unequal contact angles). The check is the registry's own ``applicable`` on the named model.
Every model's ``check`` is wrapped by ``Model.__init_subclass__`` so that a hint naming a
refusing model is replaced by the most faithful model that accepts the scene; before that
wrapper, 15 models failed this test (e.g. tiny gaps sent to ``stokes``, thick films to
``thinfilm``, unequal slip to ``lubrication`` for immersed scenes).
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from wetcontact.errors import InputError, ValidityError
from wetcontact.models import load_all
from wetcontact.scene import Scene, load_case, scene_from_dict

CASES = Path(__file__).resolve().parents[1] / "cases"
R = 1.0e-3

def _built_scenes() -> list[Scene]:
    geos = [{"kind": "sphere-wall", "radius": R}, {"kind": "sphere-sphere", "radius": R},
            {"kind": "sphere-sphere", "radius": R, "radius2": 2 * R},
            {"kind": "sphere-sphere", "radius": R, "radius2": 27 * R}]
    amounts = [{"immersed": True}, {"film_thickness": 0.05 * R}, {"film_thickness": 3 * R},
               {"bridge_volume": 1e-3 * R**3}, {"bridge_volume": 0.1 * R**3}]
    slips = [(0.0, 0.0), (1e-6, 1e-6), (1e-6, 0.0), (1e-6, 1e-7)]
    gaps = [[1e-9, 1e-6], [1e-6, 1e-5], [1e-5, 2e-3]]
    angles = [{}, {"contact_angle_sphere": 20.0, "contact_angle_wall": 40.0}]
    out = []
    for geo, amt, (bs, bw), gp, ang in itertools.product(geos, amounts, slips, gaps, angles):
        try:
            out.append(scene_from_dict({
                "name": "hint-grid", "geometry": geo, "amount": amt,
                "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
                           "slip_length_sphere": bs, "slip_length_wall": bw, **ang},
                "motion": {"velocity": 0.1, "gaps": gp}}))
        except InputError:  # e.g. a film on two spheres: not a scene the toolkit accepts
            continue
    return out


SCENES = [load_case(p) for p in sorted(CASES.glob("*.toml"))] + _built_scenes()
MODELS = load_all()


def _bad_hints(name: str) -> list[str]:
    bad = []
    for scene in SCENES:
        try:
            MODELS[name].check(scene)
        except ValidityError as exc:
            alt = exc.use_instead
            if alt is None:
                continue
            why = MODELS[alt].applicable(scene) if alt in MODELS else "not a registered model"
            if why is not None:
                bad.append(f"{scene.name} ({scene.kind}, {scene.amount}): -> {alt}: {why}")
    return bad


def test_the_grid_covers_every_amount_and_kind():
    assert len(SCENES) > 200
    assert {(s.kind, s.amount) for s in SCENES} >= {
        ("sphere-wall", "immersed"), ("sphere-wall", "film"), ("sphere-wall", "bridge"),
        ("sphere-sphere", "immersed"), ("sphere-sphere", "bridge")}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_no_refusal_points_to_a_refusing_model(name):
    bad = _bad_hints(name)
    assert not bad, f"{len(bad)} scenes, e.g. {bad[0]}"


def test_stokes_names_a_model_that_applies():
    """``stokes`` refuses tiny gaps, closed-corner bridges, thick films and very unequal spheres:
    each refusal names the most faithful applicable model (``models.model_instead``: the exact
    series where it applies, else lubrication; the check above would catch a bad one; this
    one makes sure the grid does exercise those refusals)."""
    hints = set()
    for scene in SCENES:
        try:
            MODELS["stokes"].check(scene)
        except ValidityError as exc:
            hints.add(exc.use_instead)
    assert {"brenner", "lubrication"} <= hints


def _edge_scenes() -> list[Scene]:
    """Scenes an input-fuzzing audit (2026-11-27) found where a hinted model's check
    accepted but its solve refused: a bridge filling more than 70 deg of the spheres (the
    meniscus solver's limit, met at its first step), films the sharp thin-film contact
    cannot take (a non-wetting sphere, a gap within 3 % of first touch)."""
    liquid = {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
              "contact_angle": 20.0}
    out = [scene_from_dict({"name": "big-bridge", "geometry": {"kind": "sphere-sphere",
                                                               "radius": 5e-5},
                            "liquid": liquid, "amount": {"bridge_volume": 2.5e-13},
                            "motion": {"velocity": 0.01, "gaps": [1e-7]}}),
           scene_from_dict({"name": "big-wall-bridge", "geometry": {"kind": "sphere-wall",
                                                                    "radius": R},
                            "liquid": liquid, "amount": {"bridge_volume": 1.5e-9},
                            "motion": {"velocity": 0.01, "gaps": [1e-6]}})]
    for ang, gaps in ((100.0, [5e-5]), (20.0, [9.8e-5, 5e-5])):
        out.append(scene_from_dict({
            "name": "film-edge", "geometry": {"kind": "sphere-wall", "radius": R},
            "liquid": {**liquid, "contact_angle": ang}, "amount": {"film_thickness": 1e-4},
            "motion": {"velocity": 0.5, "gaps": gaps}}))
    return out


@pytest.mark.parametrize("scene", _edge_scenes(), ids=lambda s: s.name)
def test_a_hinted_model_solves_the_scene(scene):
    """Every refusal's hint, and every model accepting the scene at its check, leads to a
    solve at the fast preset that does not refuse (before: `willett` and the other
    closures sent a bridge of V/R^3 = 2 to `meniscus`, whose solve then refused it)."""
    hinted = set()
    for m in MODELS.values():
        try:
            m.check(scene)
        except ValidityError as exc:
            if exc.use_instead:
                hinted.add(exc.use_instead)
    for name in sorted(hinted):
        MODELS[name].force(scene, preset="fast")  # raises if it refuses after all
    assert MODELS["meniscus"].applicable(scene) is not None  # refused at its check
