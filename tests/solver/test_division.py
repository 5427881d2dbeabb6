"""Division of the liquid at rupture (``transfer_fraction``, model ``meniscus``; issue 56):
the model's extra, its presets and its convergence order.

References, each independent of the FE code:
- symmetry: equal spheres with equal angles split 1/2; exchanging the bodies (R1 <-> R2,
  theta1 <-> theta2) gives 1 - f;
- an ODE shooting solution of the critical bridge (``tests/solver/shooting.py``: the fold
  is the largest gap of the shooting family at fixed volume, the bridge there is cut at the
  smallest r of its meridian, each side's volume integrated along the shot).
Tolerances: 1e-9 for the symmetries (the fold is located to round-off and the meridian is
mirror-symmetric to round-off, measured: 2e-12 at a bifurcation, 1e-15 at a fold); 1e-10
relative for V1 + V2 = V (measured: 5e-14); 1e-6 absolute against shooting (acceptance line
of the issue; measured: the FE error at 128 elements is at most 2e-8, at zero contact angle
on a wall, the shooting error about 1e-11).
Lengths are in units of R1 = 1 (sigma = 1), where the solver is scale free.
"""

from __future__ import annotations

import functools
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from wetcontact.models import load_all, observed_order
from wetcontact.solver.meniscus.division import transfer_fraction
from wetcontact.solver.meniscus.geometry import Bridge
from wetcontact.solver.meniscus.solve import _branch_for

sys.path.insert(0, str(Path(__file__).resolve().parent))
from shooting import fold_split  # noqa: E402

DEG = math.pi / 180.0


def _bridge(r1: float, r2: float | None, th1: float, th2: float) -> Bridge:
    return Bridge(radius=r1, radius2=r2, contact_angle1=th1 * DEG, contact_angle2=th2 * DEG,
                  surface_tension=1.0)


def _shooting(br, V: float, th1: float, th2: float, r2: float | None):
    """The shooting division at the fold, searched within 1 % of the FE fold's pressure
    (scale max(|P|, 1)) from its (phi1, S): the guess only, the fold is the shooting's."""
    d, x = br.d, br.x_fold
    P = float(x[d.iP])
    w = 0.01 * max(abs(P), 1.0)
    ref = fold_split(V, th1 * DEG, th2 * DEG, r2, (P - w, P + w),
                     (float(x[d.ic1]), float(x[d.iS])))
    assert ref.residual < 1e-10, "shooting did not converge"
    return ref


# ---- the extra of the registered model --------------------------------------------------


def _scene(scene_factory, kind: str, th1: float, th2: float, V: float = 1e-11,
           gaps=(1e-6, 5e-5)):
    geom = {"kind": kind, "radius": 1e-3}
    other = "contact_angle_wall"
    if kind == "sphere-sphere":
        geom["radius2"] = 2e-3
        other = "contact_angle_sphere2"
    liquid = {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
              "contact_angle_sphere": th1, other: th2}
    return scene_factory(geometry=geom, liquid=liquid, amount={"bridge_volume": V},
                         motion={"velocity": 0.0, "gaps": list(gaps)})


def test_model_extra_is_the_division_and_keeps_the_other_outputs(scene_factory):
    model = load_all()["meniscus"]
    scene = _scene(scene_factory, "sphere-sphere", 30.0, 10.0, gaps=(1e-6, 5e-5, 5e-4))
    curve = model.force(scene)
    ex = curve.extras
    assert set(ex) == {"laplace_pressure", "neck_radius", "filling_angle", "rupture_distance",
                       "bridge_exists", "force_spread", "stability", "filling_angle2",
                       "transfer_fraction"}
    assert ex["bridge_exists"].tolist() == [1.0, 1.0, 0.0]  # 0.5 mm is beyond rupture
    f = transfer_fraction(_bridge(1e-3, 2e-3, 30.0, 10.0), 1e-11).fraction
    assert np.all(ex["transfer_fraction"] == f)             # the same at every gap
    assert curve.diagnostics["transfer_neck"] == "interior"
    wall = model.force(_scene(scene_factory, "sphere-wall", 20.0, 20.0))
    assert "transfer_fraction" in wall.extras and "wetted_radius" in wall.extras


@pytest.mark.parametrize("preset", ["fast", "default", "accurate"])
@pytest.mark.parametrize("kind,th1,th2", [("sphere-wall", 0.0, 0.0),
                                          ("sphere-sphere", 50.0, 20.0)])
def test_model_presets_within_their_declared_bounds_of_shooting(scene_factory, preset, kind,
                                                                th1, th2):
    """Each preset's declared bound (``extras_error_bound``: 1e-6 fast, 1e-7 default, 1e-8
    accurate) holds against the shooting solution (V/R^3 = 1e-2; R2 = 2 R). Measured here:
    2.4e-7, 1.6e-8, 9.8e-10 at zero angle on a wall, the worst kind of point (over the
    corners of the domain against 512 elements: 2.8e-7, 1.7e-8, 9.6e-10, at zero angles
    between spheres of ratio 10); 8.9e-9, 5.5e-10, 3.1e-11 between the spheres."""
    model = load_all()["meniscus"]
    R, v = 1e-3, 1e-11
    curve = model.force(_scene(scene_factory, kind, th1, th2, V=v), preset=preset)
    ref = _preset_reference(kind, th1, th2, v / R**3)
    err = abs(curve.extras["transfer_fraction"][0] - ref)
    assert err <= model.extras_error_bound["transfer_fraction"][preset]


@functools.cache
def _preset_reference(kind: str, th1: float, th2: float, v_star: float) -> float:
    r2 = 2.0 if kind == "sphere-sphere" else None
    br, _ = _branch_for(_bridge(1.0, r2, th1, th2), v_star, 128)
    return _shooting(br, v_star, th1, th2, r2).fraction


def test_extras_observed_order_matches_declared():
    model = load_all()["meniscus"]
    for name, order in model.extras_order.items():
        h, err = model.extras_convergence_data(name)
        assert abs(observed_order(h, err) - order) <= 0.3, name
