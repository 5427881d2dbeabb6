"""The calibrated closures the ``python`` and ``c`` exports carry, and the package's own
evaluation of them (the reference those exports are tested against).

Four functions, in SI units, force on the first particle along the line of centres,
positive = pushing the particles apart, ``r2 = inf`` for a plane:

``viscous_force_immersed(r1, r2, viscosity, approach_speed, gap)``
    The shipped ``calibrated-viscous`` closure (immersed part): ``F = 6 pi eta R v lambda``
    (wall) or ``6 pi eta R (v/2) lambda`` (equal spheres, v the relative approach speed),
    lambda from the Chebyshev table in ln(S/R) (Brenner 1961; Maude 1961; held-out error
    about 5e-9). Domain: a plane or equal spheres, S/R in [1e-5, 100].
``viscous_force_bridge(r1, r2, viscosity, volume, approach_speed, gap)``
    The shipped ``calibrated-viscous`` closure (bridge part): the Reynolds force times the
    refitted finite-liquid factor (held-out error 0.2-0.3 % against ``lubrication``).
    Domain: V/r_small^3 in [1e-4, 0.1], S/H in [0.01, 0.95], radius ratio 1-10.
``rupture_distance(r1, r2, volume, theta1_deg, theta2_deg)``
    The REFITTED ``lian-rupture`` family (``S_c = R ((a + b theta) V*^(1/3) + c V*^(2/3))``,
    Lian et al. 1993), equal spheres only, V* = V/R^3 in [1e-4, 0.1], cosine-mean contact
    angle in [0, 50] deg.
``capillary_force(r1, r2, volume, gap, surface_tension, theta1_deg, theta2_deg)``
    The REFITTED ``willett`` family (Willett et al. 2000, eq. A1, 48 coefficients), equal
    spheres only, same V* and angle domain, S/S_c(Willett) in the fitted range; 0 at and
    past the (refitted Lian) rupture distance.

The shipped capillary closure (``calibrated-capillary``) does not exist yet: the capillary
pair is the best refitted family available, labelled so in every export with its measured
held-out error. :class:`CapillarySource` is the one place that names it; a shipped table
replaces it there.

Outside the calibrated domain (or for inputs no closure covers: unequal spheres, a plane for
the capillary pair, a non-finite number) every function returns NaN: this is the documented
contract of the exported C and Python code, where an exception is not available; the
package itself (:func:`package_evaluation`) reports the same points as refusals
(:class:`~wetcontact.errors.ValidityError`) and maps them to NaN only here, for comparison.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import InputError, ValidityError

#: the refitted calibration JSONs the exports carry by default, shipped as package data
#: (copies of ``benchmarks/results/calibration/{willett,lian-rupture}.json``, written by
#: ``wetcontact calibrate``; ``tests/test_export_closures.py`` keeps them equal), so that
#: ``export python`` and ``export c`` work from an installed package, not only a checkout
REFIT_DIR = Path(__file__).resolve().parents[1] / "reduced_models" / "data"
REFIT_FILES = {"willett": "refit_willett.json", "lian-rupture": "refit_lian-rupture.json"}


@dataclass(frozen=True)
class RefitTable:
    """One refitted family read from a calibration JSON (``wetcontact calibrate``)."""

    family: str
    coefficients: tuple[float, ...]
    domain: dict[str, tuple[float, float]]
    held_out_max: float
    held_out_points: int
    source: str
    sha256: str


@dataclass(frozen=True)
class CapillarySource:
    """The capillary pair the exports carry: force and rupture distance.

    Today the refitted ``willett`` force and ``lian-rupture`` distance (``shipped`` False);
    a shipped ``calibrated-capillary`` table takes their place here.
    """

    force: RefitTable
    rupture: RefitTable
    shipped: bool = False

    @property
    def label(self) -> str:
        return ("REFITTED families, not a shipped calibrated closure: capillary force = "
                f"'{self.force.family}' refit (held-out max error "
                f"{100 * self.force.held_out_max:.1f} % against meniscus, "
                f"{self.force.held_out_points} points), rupture distance = "
                f"'{self.rupture.family}' refit (held-out max error "
                f"{100 * self.rupture.held_out_max:.1f} %, {self.rupture.held_out_points} "
                "points)")


def read_refit(path: Path | str, family: str) -> RefitTable:
    """A refitted family from ``path``; an :class:`InputError` naming the file otherwise."""
    from wetcontact.calibrate import load_coefficients

    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such calibration file; write it with `python -m "
                         f"wetcontact.calibrate fit {family} --out {path}` or name another "
                         "with --capillary / --rupture")
    closure = load_coefficients(path)  # validates family, size and finiteness
    if closure.family.name != family:
        raise InputError(f"{path}: family = {closure.family.name!r}; allowed: {family!r} "
                         "(the only family this export writes for that function)")
    data = json.loads(path.read_text())
    ho = data.get("held_out", {}).get("after", {})
    if not isinstance(ho.get("max"), int | float):
        raise InputError(f"{path}: field 'held_out.after.max' missing; allowed: a file "
                         "written by wetcontact calibrate")
    return RefitTable(family, tuple(float(c) for c in closure.k), dict(closure.domain),
                      float(ho["max"]), int(data["held_out"].get("points", 0)), str(path),
                      hashlib.sha256(path.read_bytes()).hexdigest())


def capillary_source(force: Path | str | None = None,
                     rupture: Path | str | None = None) -> CapillarySource:
    """The capillary pair from the given files, or the package's shipped refits."""
    return CapillarySource(
        read_refit(force or REFIT_DIR / REFIT_FILES["willett"], "willett"),
        read_refit(rupture or REFIT_DIR / REFIT_FILES["lian-rupture"], "lian-rupture"))


def immersed_tables() -> dict[str, Any]:
    """The shipped ``calibrated-viscous`` immersed tables (sphere-wall, sphere-sphere)."""
    from wetcontact.reduced_models.calibrated import viscous_table

    table = viscous_table()
    if table is None:
        raise InputError("calibrated-viscous: coefficient table not generated; run "
                         "`python -m wetcontact.calibrate viscous`")
    return table["immersed"]


# ---- the package's evaluation (through the models; the exports' reference) ---------------


def _scene(r1: float, r2: float, gap: float, amount: dict[str, Any], liquid: dict[str, Any],
           velocity: float = 0.0):
    from wetcontact.scene import scene_from_dict

    geo: dict[str, Any] = {"kind": "sphere-wall", "radius": r1}
    if not math.isinf(r2):
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
    ``rupture_distance`` or
    ``capillary_force``; ``args`` are the exported function's arguments (SI, degrees).
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
        assert source is not None
        liquid = {"contact_angle_sphere": args["theta1_deg"],
                  "contact_angle_sphere2": args["theta2_deg"]}
        gap = args.get("gap", 1e-3 * args["r1"])
        if function == "capillary_force":
            liquid["surface_tension"] = args["surface_tension"]
        scene = _scene(args["r1"], args["r2"], gap, {"bridge_volume": args["volume"]}, liquid)
        rupture = _closure(source.rupture)
        sc = float(rupture.force(scene).extras["rupture_distance"][0])
        if function == "rupture_distance":
            return sc
        if gap >= sc:
            return 0.0
        return float(_closure(source.force).force(scene).force_capillary[0])
    except (ValidityError, InputError):
        return math.nan


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
