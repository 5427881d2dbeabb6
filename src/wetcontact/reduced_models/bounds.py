"""Measured error bounds of the closures: lookup in the held-out tables (package data).

A closure's error bound is not a formula: it is the maximum relative error measured on
held-out points over its declared domain, binned along a few scene coordinates, against
an independent reference (the exact Brenner series for immersed viscous closures,
``lubrication`` for films and bridges, ``meniscus`` for capillary closures). The tables
live in ``data/bounds.json``, written by ``python -m wetcontact.generate bounds``
(:func:`wetcontact.calibrate.measure_bounds`). Outside a table's bins a closure has no
bound and is not eligible for selection; a bound is never zero or negative (floor
:data:`BOUND_FLOOR`).

Coordinates (per gap):

``s_over_r``
    S/R, immersed scenes (R the first sphere's radius; equal spheres only).
``delta_over_r``, ``s_over_h``
    Film thickness over R; gap over the wetted-edge gap H (film: H = delta; bridge:
    H = sqrt(S^2 + V/(pi R*)), Pitois et al. 2000).
``v_star``
    Bridge volume over the smaller sphere's radius cubed (sphere-wall: the sphere's).
``radius_ratio``
    Larger over smaller radius (sphere-wall: 1).
``theta_deg``
    Larger of the two contact angles (deg).
``s_over_sc``
    Gap over the closure's own rupture distance.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import Any

import numpy as np

from wetcontact.scene import Scene

#: smallest bound ever returned (relative); an exact series is still summed in floats
BOUND_FLOOR = 1e-12
DATA_FILE = "bounds.json"


@dataclass(frozen=True)
class Table:
    """One binned bound table of one closure for one component and scene class.

    Attributes
    ----------
    model, component
        Closure name; ``"viscous"`` or ``"capillary"``.
    kind, amount
        Scene class the table covers (``"sphere-wall"``/``"sphere-sphere"``;
        ``"immersed"``/``"film"``/``"bridge"``).
    reference
        What the errors were measured against.
    axes
        Coordinate names, in the order of ``edges`` and of the bound array's dimensions.
    edges
        Bin edges per axis (closed intervals at both ends of the table).
    bound
        Bound per bin (relative), ``inf`` where the bin holds no measured point.
    equal_spheres
        True when a sphere-sphere table covers equal radii only.
    """

    model: str
    component: str
    kind: str
    amount: str
    reference: str
    axes: tuple[str, ...]
    edges: tuple[np.ndarray, ...]
    bound: np.ndarray
    equal_spheres: bool = False

    def covers(self, scene: Scene) -> bool:
        """True if the scene is of this table's class (every table was measured without
        slip, the capillary ones without gravity)."""
        if scene.kind != self.kind or scene.amount != self.amount:
            return False
        if scene.slip_length_sphere > 0 or scene.slip_length_wall > 0:
            return False
        if self.component == "capillary" and scene.gravity != 0:
            return False
        return not (self.equal_spheres and not scene.equal_spheres)

    def outside(self, coords: dict[str, np.ndarray]) -> str:
        """Which coordinate of the gaps lies outside the measured bins and by how much
        (the first such axis), or that a bin holds no measured point; empty if neither."""
        for name, e in zip(self.axes, self.edges, strict=True):
            x = np.asarray(coords[name], dtype=float)
            tol = 1e-12 * max(abs(e[0]), abs(e[-1]))
            bad = (x < e[0] - tol) | (x > e[-1] + tol)
            if bad.any():
                lo, hi = float(x[bad].min()), float(x[bad].max())
                at = f"{lo:.3g}" if lo == hi else f"{lo:.3g} to {hi:.3g}"
                return (f"{name} = {at} at {int(bad.sum())} of {x.size} gaps, outside the "
                        f"measured [{e[0]:.3g}, {e[-1]:.3g}]")
        n = int(np.sum(~np.isfinite(self.lookup(coords))))
        return f"{n} gaps fall in bins without a measured point" if n else ""

    def lookup(self, coords: dict[str, np.ndarray]) -> np.ndarray:
        """Bound per gap; ``inf`` where a gap lies outside the measured bins."""
        n = len(next(iter(coords.values())))
        idx = []
        inside = np.ones(n, bool)
        for name, e in zip(self.axes, self.edges, strict=True):
            x = np.broadcast_to(np.asarray(coords[name], dtype=float), (n,))
            tol = 1e-12 * max(abs(e[0]), abs(e[-1]))
            inside &= (x >= e[0] - tol) & (x <= e[-1] + tol)
            idx.append(np.clip(np.searchsorted(e, x, side="right") - 1, 0, e.size - 2))
        out = np.full(n, np.inf)
        out[inside] = self.bound[tuple(i[inside] for i in idx)]
        return np.maximum(out, BOUND_FLOOR)


@cache
def tables() -> tuple[Table, ...]:
    """All tables of the shipped ``bounds.json`` (empty if it has not been generated)."""
    path = resources.files("wetcontact.reduced_models") / "data" / DATA_FILE
    if not path.is_file():
        return ()
    data = json.loads(path.read_text())
    return tuple(table_from_dict(t) for t in data["tables"])


def table_from_dict(t: dict[str, Any]) -> Table:
    """A :class:`Table` from its JSON record (``bound`` null = no measured point)."""
    bound = np.array([np.inf if b is None else b for b in np.ravel(np.asarray(
        t["bound"], dtype=object))], dtype=float).reshape([len(e) - 1 for e in t["edges"]])
    return Table(model=t["model"], component=t["component"], kind=t["kind"],
                 amount=t["amount"], reference=t["reference"], axes=tuple(t["axes"]),
                 edges=tuple(np.asarray(e, dtype=float) for e in t["edges"]), bound=bound,
                 equal_spheres=bool(t.get("equal_spheres", False)))


def scene_coords(scene: Scene, rupture_distance: float | None = None) -> dict[str, np.ndarray]:
    """The coordinates of every gap of ``scene`` (module docstring)."""
    s = scene.gap_array
    r_small = scene.small_radius
    r_large = scene.radius if scene.kind == "sphere-wall" else max(scene.radius, scene.radius2)
    c: dict[str, np.ndarray] = {
        "s_over_r": s / scene.radius,
        "radius_ratio": np.full(s.shape, r_large / r_small),
        "theta_deg": np.full(s.shape, math.degrees(max(scene.contact_angle_sphere,
                                                       scene.contact_angle_wall))),
    }
    if scene.amount == "film":
        c["delta_over_r"] = np.full(s.shape, scene.film_thickness / scene.radius)
        c["s_over_h"] = s / scene.film_thickness
    if scene.amount == "bridge":
        v = scene.bridge_volume
        c["v_star"] = np.full(s.shape, v / r_small**3)
        c["s_over_h"] = s / np.sqrt(s**2 + v / (math.pi * scene.reduced_radius))
        if rupture_distance is not None:
            c["s_over_sc"] = s / rupture_distance
    return c


def _table_for(model: str, component: str, scene: Scene,
               rupture_distance: float | None) -> tuple[Table, dict[str, np.ndarray]] | None:
    """The table of ``model`` covering the scene's class and the scene's coordinates, or
    ``None`` when there is none (or the scene lacks one of its coordinates)."""
    for t in tables():
        if t.model == model and t.component == component and t.covers(scene):
            coords = scene_coords(scene, rupture_distance)
            return (t, coords) if all(a in coords for a in t.axes) else None
    return None


def measured_bound(model: str, component: str, scene: Scene,
                   rupture_distance: float | None = None) -> tuple[np.ndarray, str] | None:
    """Measured bound per gap of closure ``model`` on ``scene``, and its reference.

    ``None`` when no table covers the scene's class; the array holds ``inf`` at gaps
    outside the measured domain.
    """
    got = _table_for(model, component, scene, rupture_distance)
    return None if got is None else (got[0].lookup(got[1]), got[0].reference)


def domain_reason(model: str, component: str, scene: Scene,
                  rupture_distance: float | None = None) -> str:
    """Why ``model``'s measured bound does not cover every gap of ``scene`` (the
    coordinate, its values and the measured range), or empty if it does."""
    got = _table_for(model, component, scene, rupture_distance)
    return ("no measured error table for this kind of scene" if got is None
            else got[0].outside(got[1]))


def estimate_or_none(model: str, component: str, scene: Scene,
                     rupture_distance: float | None = None) -> np.ndarray | None:
    """The measured bound as a curve's ``error_estimate``: ``None`` where any gap is
    outside the measured domain (a ForceCurve holds finite values only)."""
    got = measured_bound(model, component, scene, rupture_distance)
    if got is None or not np.all(np.isfinite(got[0])):
        return None
    return got[0]
