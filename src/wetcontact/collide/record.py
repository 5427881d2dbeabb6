"""A collision as a point of the reference store.

A collision point is a :class:`~wetcontact.collide.CollisionCase` integrated with one force
set: ``"reference"`` (the toolkit's default models, :func:`wetcontact.collide.collide`) or a
DEM code's set (:data:`wetcontact.collide.dem.FORCE_SETS`). The store keeps curves
(:class:`~wetcontact.models.ForceCurve`), so a collision is kept as a one-row curve:

- ``gap``: the case scene's smallest gap (m), a label only: the collision starts at
  ``impact.start_gap`` (:func:`point_case` keeps one gap, so the store's scene and the
  record agree);
- ``extras``: ``restitution``, ``stick`` (1 or 0), ``stokes_number``, ``energy_residual``,
  and where they exist ``contact_velocity``, ``rebound_velocity``, ``transfer_fraction``,
  ``bridge_volume``;
- ``diagnostics["collision"]``: the whole result (:meth:`Collision.to_json_dict`), which
  :func:`collision_from_curve` turns back into a :class:`Collision`;
- ``settings``: the case's collision tables and the force set (:func:`settings_for`), so
  the store's content key tells two impacts of the same scene apart.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from wetcontact.collide.case import CollisionCase
from wetcontact.collide.dem import FORCE_SETS
from wetcontact.collide.impact import RTOL, collide
from wetcontact.collide.result import Collision, Phase
from wetcontact.errors import InputError
from wetcontact.models import ForceCurve

REFERENCE = "reference"
FORCE_SET_NAMES = (REFERENCE, *FORCE_SETS)
"""What a collision point's ``model`` may be: the reference force set or a DEM code's."""
PREFIX = "collide/"
"""Model names of collision records in the store (``collide/reference``, ...)."""


def check_force_set(name: str) -> str:
    """``name`` if it is a force set (:data:`FORCE_SET_NAMES`), else an InputError."""
    if name not in FORCE_SET_NAMES:
        raise InputError(f"collision force set {name!r}; allowed: "
                         + ", ".join(FORCE_SET_NAMES))
    return name


def settings_for(case: CollisionCase, force_set: str, rtol: float = RTOL) -> dict[str, Any]:
    """The settings a collision record carries: the case's tables (SI units, angles in
    degrees), the force set and the integrator's tolerance."""
    check_force_set(force_set)

    def deg(a: tuple[float, float] | None) -> list[float] | None:
        return None if a is None else [math.degrees(a[0]), math.degrees(a[1])]

    return {"force_set": force_set, "rtol": rtol,
            "impact": dataclasses.asdict(case.impact),
            "solid": dataclasses.asdict(case.solid),
            "solid2": dataclasses.asdict(case.solid2),
            "contact": {"model": case.contact_model, "cutoff": case.cutoff},
            "phases": {"viscous_on_rebound": case.viscous_on_rebound,
                       "advancing_angle_deg": deg(case.advancing_angle),
                       "receding_angle_deg": deg(case.receding_angle),
                       "rupture": case.rupture}}


def point_case(case: CollisionCase) -> CollisionCase:
    """``case`` with its scene's gaps cut to the smallest: the scene a store point carries
    (the collision does not use the gaps)."""
    sc = case.scene
    return case if len(sc.gaps) == 1 else case.with_(scene=sc.with_gaps([min(sc.gaps)]))


def solve(case: CollisionCase, force_set: str = REFERENCE, rtol: float = RTOL) -> ForceCurve:
    """Integrate ``case`` with ``force_set`` and return the collision as a one-row record.

    Raises
    ------
    InputError
        An unknown force set, or a model that does not apply to the case.
    SolverError
        The integrator failed.
    """
    check_force_set(force_set)
    res = collide(case, force_set=None if force_set == REFERENCE else force_set,
                  trajectory=False, rtol=rtol)
    return to_curve(res, case, force_set, rtol)


def to_curve(res: Collision, case: CollisionCase, force_set: str = REFERENCE,
             rtol: float = RTOL) -> ForceCurve:
    """The one-row :class:`ForceCurve` of a collision result (see the module docstring)."""
    extras = {"restitution": res.restitution, "stick": float(res.outcome == "stick"),
              "stokes_number": res.stokes_number,
              "energy_residual": float(res.diagnostics.get("energy_residual", 0.0))}
    for name, val in (("contact_velocity", res.contact_velocity),
                      ("rebound_velocity", res.rebound_velocity),
                      ("transfer_fraction", res.liquid.get("transfer_fraction")),
                      ("bridge_volume", res.liquid.get("bridge_volume"))):
        if val is not None:
            extras[name] = float(val)
    diag = {"collision": res.to_json_dict(),
            "wall_time_s": float(res.diagnostics.get("table_time_s", 0.0))
            + float(res.diagnostics.get("integration_time_s", 0.0))}
    return ForceCurve(case=res.case, model=PREFIX + force_set,
                      gap=point_case(case).scene.gap_array, force_viscous=None,
                      force_capillary=None,
                      extras={k: [v] for k, v in extras.items()}, diagnostics=diag,
                      settings=settings_for(case, force_set, rtol),
                      provenance=dict(res.provenance))


def is_record(curve: ForceCurve) -> bool:
    """Whether ``curve`` is a collision record (:func:`to_curve`)."""
    return curve.model.startswith(PREFIX) and "collision" in curve.diagnostics


def collision_from_curve(curve: ForceCurve) -> Collision:
    """The :class:`Collision` a record holds (without its trajectory).

    Raises
    ------
    InputError
        ``curve`` is not a collision record.
    """
    if not is_record(curve):
        raise InputError(f"curve of model {curve.model!r} is not a collision record "
                         f"(model {PREFIX}<force set>)")
    d = dict(curve.diagnostics["collision"])
    d["phases"] = tuple(Phase(p["name"], p["start"], p["end"]) for p in d["phases"])
    d["validity"] = tuple(d.get("validity", ()))
    return Collision(**d)
