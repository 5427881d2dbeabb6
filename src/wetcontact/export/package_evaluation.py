"""The package's own evaluation of the exported closures, through its models: the
reference the ``python`` and ``c`` exports are tested against (:func:`package_evaluation`;
NaN where the package refuses a point, the exports' contract outside the calibrated domain).
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np

from wetcontact.errors import InputError, ValidityError
from wetcontact.export.closure_tables import CapillarySource, RefitTable


def _scene(r1: float, r2: float, gap: float, amount: dict[str, Any], liquid: dict[str, Any],
           velocity: float = 0.0):
    from wetcontact.scene import scene_from_dict

    geo: dict[str, Any] = {"kind": "sphere-wall", "radius": r1}
    if not (math.isinf(r2) and r2 > 0):  # r2 = +inf is a plane (-inf: a bad radius)
        geo = {"kind": "sphere-sphere", "radius": r1, "radius2": r2}
    liq = {"viscosity": 1e-3, "surface_tension": 0.072, "density": 1000.0, **liquid}
    if geo["kind"] == "sphere-wall" and "contact_angle_sphere2" in liq:
        liq["contact_angle_wall"] = liq.pop("contact_angle_sphere2")
    return scene_from_dict({"name": "export-check", "geometry": geo, "liquid": liq,
                            "amount": amount, "motion": {"velocity": velocity,
                                                         "gaps": [gap]}})


def package_evaluation(function: str, source: CapillarySource | None = None,
                       **args: float) -> float:
    """One exported function evaluated by the package's models at one point (NaN where the
    package refuses: a :class:`ValidityError` or an input a Scene rejects).

    ``function`` is ``viscous_force_immersed``, ``viscous_force_bridge``,
    ``rupture_distance``, ``capillary_force`` (``calibrated-capillary``),
    ``rupture_distance_refit`` or ``capillary_force_refit`` (the refits of ``source``);
    ``args`` are the exported function's arguments (SI, degrees).
    """
    from wetcontact.models import get_model

    try:
        if function == "viscous_force_immersed":
            scene = _scene(args["r1"], args["r2"], args["gap"], {"immersed": True},
                           {"viscosity": args["viscosity"]}, args["approach_speed"])
            return float(get_model("calibrated-viscous").force(scene).force_viscous[0])
        if function == "viscous_force_bridge":
            scene = _scene(args["r1"], args["r2"], args["gap"],
                           {"bridge_volume": args["volume"]}, {"viscosity": args["viscosity"]},
                           args["approach_speed"])
            return float(get_model("calibrated-viscous").force(scene).force_viscous[0])
        liquid = {"contact_angle_sphere": args["theta1_deg"],
                  "contact_angle_sphere2": args["theta2_deg"]}
        if function.startswith("capillary_force"):
            liquid["surface_tension"] = args["surface_tension"]
        if function in ("rupture_distance", "capillary_force"):
            return _calibrated_capillary(function, liquid, **args)
        assert source is not None
        gap = args.get("gap", 1e-3 * args["r1"])
        scene = _scene(args["r1"], args["r2"], gap, {"bridge_volume": args["volume"]}, liquid)
        rupture = _closure(source.rupture)
        sc = float(rupture.force(scene).extras["rupture_distance"][0])
        if function == "rupture_distance_refit":
            return sc
        if gap >= sc:
            return 0.0
        return float(_closure(source.force).force(scene).force_capillary[0])
    except (ValidityError, InputError):
        return math.nan


def _calibrated_capillary(function: str, liquid: dict[str, Any], **args: float) -> float:
    """``calibrated-capillary`` through its model: the scene's checks, its rupture distance
    and its force (0 at and past rupture), every table summed in double precision (its
    ``accurate`` preset, what the exports compute; the default sums the two-angle tables'
    force trains in single precision). Two gaps a Scene does not hold are answered by
    the model's own formula: S = 0 (the limit at contact, :func:`force_star` at s = 0) and
    S > 100 r1 (past any rupture distance: 0)."""
    from wetcontact.models import get_model
    from wetcontact.reduced_models.calibrated_capillary import force_star

    model = get_model("calibrated-capillary")
    r1, r2 = args["r1"], args["r2"]
    nominal = _scene(r1, r2, 1e-3 * r1, {"bridge_volume": args["volume"]}, liquid)
    model.check(nominal)
    sc = model.rupture_distance(nominal)
    if function == "rupture_distance":
        return sc
    gap = args["gap"]
    if gap == 0.0:
        v, ratio = model._v_ratio(nominal)
        rs = model.small_radius(nominal)
        th, other = model._angles(nominal)
        f, _ = force_star(nominal.kind, v, th, 0.0, ratio, theta_wall=other,
                          precision="double")
        return -float(2.0 * math.pi * nominal.surface_tension * rs * f)
    if gap > 100.0 * r1 and math.isfinite(gap):
        assert gap > sc
        return 0.0
    return float(model.force(nominal, gaps=[gap], preset="accurate").force_capillary[0])


def _closure(table: RefitTable):
    return _closure_at(table.source, table.family)


@cache
def _closure_at(source: str, family: str):
    from wetcontact.calibrate import load_coefficients

    return load_coefficients(source, family)


def package_evaluation_many(function: str, source: CapillarySource | None = None,
                            **arrays: np.ndarray) -> np.ndarray:
    """:func:`package_evaluation` at each point of equal-length arrays."""
    n = len(next(iter(arrays.values())))
    return np.array([package_evaluation(function, source,
                                        **{k: float(v[i]) for k, v in arrays.items()})
                     for i in range(n)])
