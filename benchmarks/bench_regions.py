"""Failure-region maps: where each solver and shipped closure solves, warns, refuses or fails.

The project charts every solver's error against time (the other ``bench_*.py``); this
benchmark maps the other half of the rule, the region where each answers. Every cell of a
2-D grid of scene parameters is one scene built by :func:`wetcontact.scene.scene_from_dict`
and solved through the public call ``get_model(name).force(scene, preset=...)``; the cell
is classified as

- ``ok``: solved, every force finite, no warning;
- ``warned``: solved, with the model's validity note (``diagnostics.outside_stated_validity``,
  what ``wetcontact solve`` prints as a warning; the package emits no Python warning for
  validity) or any Python warning; its first line is kept;
- ``refused``: :class:`~wetcontact.errors.ValidityError` or another
  :class:`~wetcontact.errors.InputError` from the model; kept: the model the message names
  instead (``use_instead``, else a quoted registered name), whether that model's check
  accepts the scene, whether it then warns (closures: asked), and, where the benchmark
  solved the very same scene with it, its class there (``named_solves``);
- ``failed``: :class:`~wetcontact.errors.SolverError` or any other exception (type and
  message kept; a ``SolverError`` saying the model "produced non-finite" values is a NaN
  that the ForceCurve guard caught, flagged ``nonfinite_caught``);
- ``nan``: a non-finite force returned without an exception (a bug if it ever shows);

and, not a verdict of the model, ``no-scene`` (the case loader refuses the scene itself:
a film the sphere never reaches, S >= delta, or a gap beyond 100 R) and ``not-run``
(accepted by the model's check but skipped for cost: ``stokes`` between unequal spheres
below S/R = 1e-4, 12-18 s a solve there).

Maps (sphere radius R = 1 mm, water: eta = 1 mPa s, sigma = 0.072 N/m; approach 0.1 m/s):

- ``lubrication`` (default preset): a film on a wall, S/R x delta/R; a bridge (20 deg) on a
  wall, S/R x V/R^3; error against the adaptive quadrature of ``6 pi eta v int r^3/h^3 dr``
  over the same wetted zone (``wetcontact.solver.lubrication.quadrature_force``); a dot
  marks a bridge answered without a warning at or past the ``meniscus`` rupture distance;
- ``stokes`` (fast preset): immersed sphere-sphere, S/R x R2/R1, and a sphere-wall row;
  error against ``brenner`` (the exact series) on the wall and equal-sphere rows;
- ``meniscus`` (default preset): a bridge on a wall, V/R^3 (1e-12 to 4) x contact angle
  (0-160 deg), at S = 1e-6 R and at S = 0.9 S_c (S_c the model's own ``rupture_distance``
  from the first solve; Lian's ``(1 + theta/2) V^(1/3)`` where that solve gave none);
- ``calibrated-capillary``: on a wall, V/R^3 x contact angle, error against the meniscus
  map's forces at both gaps where the grids meet; between spheres (20 deg), V/R_s^3 x R2/R1;
- ``calibrated-viscous``: immersed, S/R x (wall, equal spheres, R2 = 2 R1), error against
  ``brenner``; a film, S/delta x delta/R; a bridge (20 deg) on a wall, S/H x V/R^3
  (H = sqrt(S^2 + V/(pi R)), Pitois' edge gap), error against ``lubrication`` (the bridge
  tables' calibration reference: a check of the fit, not an independent one), dots as for
  ``lubrication``.

Then a few refusals are followed model to model (``refusal_chains``): bridges the meniscus
map finds refused although its check accepts them, and unequal immersed spheres.

Writes ``benchmarks/results/regions.json`` (per map: the axes, a table of distinct
outcomes and, per row, each cell's outcome index as a space-separated string, the errors
likewise; the solves and wall time; per model the wall time) and ``regions.png`` (one
panel a map). Run from the repository root::

    .venv/bin/python benchmarks/bench_regions.py           # 3-4 min on 2 shared cores
    .venv/bin/python benchmarks/bench_regions.py --chart   # redraw the PNG from the JSON

A progress line per map goes to stderr. Timings are single runs on 2 shared cores.
"""

from __future__ import annotations

import json
import math
import re
import sys
import textwrap
import time
import warnings
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, main_or_chart, write_json  # noqa: E402

from wetcontact.errors import InputError, SolverError, ValidityError  # noqa: E402
from wetcontact.models import ForceCurve, get_model, load_all  # noqa: E402
from wetcontact.reduced_models.rupture import lian_rupture_distance  # noqa: E402
from wetcontact.scene import scene_from_dict  # noqa: E402
from wetcontact.solver.lubrication import GapProfile, quadrature_force  # noqa: E402

R, ETA, SIGMA, RHO, SPEED = 1.0e-3, 1.0e-3, 0.072, 998.0, 0.1
THETA_BRIDGE = 20.0          # deg, the bridges whose angle is not an axis
S_CONTACT = 1.0e-6           # S/R of the "near contact" meniscus gap
RUPTURE_FRACTION = 0.9       # the second meniscus gap, S / S_c
STOKES_MIN_UNEQUAL = 1.0e-4  # S/R below which unequal spheres are not solved (cost)
PAST_RUPTURE = ("dot: S >= S_c of meniscus (no bridge there), answered with no warning")

CATEGORIES: dict[str, dict[str, str]] = {
    # colour (distinct lightness too), hatch, meaning; the chart's legend reads them
    "ok": {"color": "#a6dba0", "hatch": "", "label": "ok: solved, finite, no warning"},
    "warned": {"color": "#fdb863", "hatch": "///", "label": "warned: solved outside the "
               "stated validity"},
    "refused": {"color": "#6f8fd0", "hatch": "...", "label": "refused: ValidityError / "
                "InputError (names a model)"},
    "failed": {"color": "#b2182b", "hatch": "xxx", "label": "failed: SolverError or other "
               "exception"},
    "nan": {"color": "#111111", "hatch": "ooo", "label": "nan: non-finite force, no "
            "exception (bug)"},
    "no-scene": {"color": "#ffffff", "hatch": "--", "label": "no scene: the case loader "
                 "refuses it (S >= delta, S > 100 R)"},
    "not-run": {"color": "#d9d9d9", "hatch": "\\\\\\", "label": "not run: accepted, skipped "
                "for cost (12-18 s a solve)"},
}


# ---- one cell --------------------------------------------------------------------------


@dataclass
class Cell:
    """The verdict on one scene: class, message (first line), named model and so on."""

    status: str
    message: str = ""
    named: str | None = None            # the model a refusal names instead
    named_accepts: bool | None = None   # whether that model's own check accepts the scene
    named_warns: bool | None = None     # a closure named instead answers with a warning
    error: float | None = None          # relative error against the map's reference
    nonfinite_caught: bool = False      # a SolverError from the ForceCurve's finite guard
    marked: bool = False                # the map's own marker (e.g. past rupture, no warning)
    named_solves: str | None = None     # the named solver's class on the same scene, where known
    parts: dict[str, float] = field(default_factory=dict)   # errors per gap, where several

    def outcome(self) -> tuple[Any, ...]:
        """What the JSON's outcome table keeps (everything but the error and marker)."""
        return (self.status, self.message, self.named, self.named_accepts, self.named_warns,
                self.named_solves, self.nonfinite_caught)


def first_line(text: str, limit: int = 300) -> str:
    line = str(text).strip().splitlines()[0] if str(text).strip() else ""
    return line if len(line) <= limit else line[: limit - 3] + "..."


def named_model(exc: Exception, model: str) -> str | None:
    """The model a refusal names instead: ``ValidityError.use_instead``, else the first
    registered name in quotes or backticks in the message other than ``model`` itself."""
    if isinstance(exc, ValidityError) and exc.use_instead:
        return exc.use_instead
    names = set(load_all())
    for cand in re.findall(r"[`'\"]([a-z][a-z0-9-]*)[`'\"]", str(exc)):
        if cand in names and cand != model:
            return cand
    return None


def case(kind: str, amount: dict[str, Any], gap_over_r: float, theta: float = THETA_BRIDGE,
         radius2_over_r: float | None = None) -> dict[str, Any]:
    """A case-file dict: sphere (R = 1 mm) on a wall or against a sphere of R2, water."""
    geometry: dict[str, Any] = {"kind": kind, "radius": R}
    if radius2_over_r is not None:
        geometry["radius2"] = radius2_over_r * R
    return {"name": "regions", "geometry": geometry,
            "liquid": {"viscosity": ETA, "surface_tension": SIGMA, "density": RHO,
                       "contact_angle": theta},
            "amount": amount, "motion": {"velocity": SPEED, "gaps": [gap_over_r * R]}}


def classify(model: str, data: dict[str, Any], preset: str = "default",
             run: bool = True) -> tuple[Cell, ForceCurve | None]:
    """Build the scene and solve it with ``model``; ``run=False`` only checks it (a cell
    accepted by the check becomes ``not-run``)."""
    try:
        scene = scene_from_dict(data)
    except InputError as exc:  # the field and its range; the values vary cell by cell
        return Cell("no-scene", re.sub(r"(= |gap )[-+0-9.e]+", r"\1...", first_line(exc))), None
    m = get_model(model)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            if not run:
                m.check(scene)
                return Cell("not-run", "accepted by the check; not solved (cost)"), None
            curve = m.force(scene, preset=preset)
    except InputError as exc:  # ValidityError among them
        named = named_model(exc, model)
        accepts = warns = None
        if named is not None and named in load_all():
            other = get_model(named)
            accepts = other.applicable(scene) is None
            if accepts and other.level == 0:  # a closure: cheap to ask whether it warns
                try:
                    warns = bool(other.force(scene).diagnostics.get("outside_stated_validity"))
                except Exception:  # noqa: BLE001 - recorded as "does not answer cleanly"
                    warns = True
        return Cell("refused", first_line(exc), named, accepts, warns), None
    except SolverError as exc:
        return Cell("failed", f"SolverError: {first_line(exc)}",
                    nonfinite_caught="non-finite" in str(exc)), None
    except Exception as exc:  # noqa: BLE001 - any other exception is what the map records
        return Cell("failed", f"{type(exc).__name__}: {first_line(exc)}"), None
    forces = [f for f in (curve.force_viscous, curve.force_capillary) if f is not None]
    if not all(np.all(np.isfinite(f)) for f in forces):
        return Cell("nan", "non-finite force returned without an exception"), curve
    notes = []
    if note := curve.diagnostics.get("outside_stated_validity"):
        notes.append(f"validity: {first_line(note)}")
    notes += [f"{w.category.__name__}: {first_line(str(w.message))}" for w in caught]
    if notes:
        return Cell("warned", notes[0]), curve
    return Cell("ok"), curve


def force_of(curve: ForceCurve | None, component: str) -> float | None:
    if curve is None:
        return None
    arr = curve.force_viscous if component == "viscous" else curve.force_capillary
    return None if arr is None else float(arr[0])


def rel_error(value: float | None, reference: float | None) -> float | None:
    if value is None or reference is None or reference == 0.0:
        return None
    return abs(value / reference - 1.0)


_FE_RUPTURE: dict[tuple[float, float], float | None] = {}
_FE_COST = {"solves": 0, "wall_time_s": 0.0}
"""The meniscus solves :func:`fe_rupture` adds (inside the bridge maps' wall times)."""
_MENISCUS_CONTACT: dict[tuple[float, float], str] = {}
"""The meniscus map's class of each (V/R^3, theta) bridge on a wall at S = S_CONTACT R."""


def fe_rupture(v: float, theta: float) -> float | None:
    """``meniscus``'s rupture distance S_c (m) of a bridge of V = v R^3 at theta (deg) on a
    wall (cached; ``None`` where it refuses or fails)."""
    key = (float(f"{v:.12g}"), float(theta))
    if key not in _FE_RUPTURE:
        t0 = time.perf_counter()
        _, curve = classify("meniscus", case("sphere-wall", {"bridge_volume": v * R**3},
                                             S_CONTACT, theta))
        _FE_COST["solves"] += 1
        _FE_COST["wall_time_s"] += time.perf_counter() - t0
        _FE_RUPTURE[key] = (None if curve is None
                            else float(curve.extras["rupture_distance"][0]))
    return _FE_RUPTURE[key]


# ---- a map -----------------------------------------------------------------------------


@dataclass
class Axis:
    name: str
    values: list[float]
    scale: str = "log"                        # "log", "linear" or "cat" (labels below)
    labels: list[str] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        return {"name": self.name, "values": self.values, "scale": self.scale,
                "labels": self.labels}


@dataclass
class RegionMap:
    """One panel: ``cells[iy][ix]`` over ``x`` and ``y``."""

    key: str
    model: str
    title: str
    preset: str
    x: Axis
    y: Axis
    reference: str = ""
    error_style: str = ""                     # "contour", "numbers" or "" (no errors)
    marker: str = ""                          # what a dot in a cell means ("": no dots)
    short_reference: str = ""                 # the reference as the chart's legend says it
    cells: list[list[Cell]] = field(default_factory=list)
    solves: int = 0
    wall_time_s: float = 0.0
    dots_time_s: float = 0.0                  # of it, meniscus solves for the dots (fe_rupture)

    def to_json(self) -> dict[str, Any]:
        """Compact form: a table of distinct outcomes and, per row of y, the outcome index
        of each x as a space-separated string (likewise the errors, ``-`` for none)."""
        table: dict[tuple[Any, ...], int] = {}
        rows = []
        for row in self.cells:
            rows.append(" ".join(str(table.setdefault(c.outcome(), len(table))) for c in row))
        flat = [c for row in self.cells for c in row]
        cells_of = Counter(table[c.outcome()] for c in flat)
        keys = ("status", "message", "named", "named_accepts", "named_warns", "named_solves",
                "nonfinite_caught")
        outcomes = [{**dict(zip(keys, o, strict=True)), "cells": cells_of[i]}
                    for o, i in table.items()]
        errs = [c.error for c in flat if c.error is not None]
        out: dict[str, Any] = {
            "key": self.key, "model": self.model, "title": self.title, "preset": self.preset,
            "x": self.x.to_json(), "y": self.y.to_json(),
            "grid": [len(self.y.values), len(self.x.values)],
            "counts": dict(Counter(c.status for c in flat)),
            "outcomes": outcomes, "cells": rows,
            "error_reference": self.reference, "short_reference": self.short_reference,
            "error_style": self.error_style, "error_max": max(errs) if errs else None,
            "solves": self.solves, "wall_time_s": self.wall_time_s,
            "of_which_meniscus_for_dots_s": self.dots_time_s,
        }
        if self.error_style:
            out["error"] = [" ".join("-" if c.error is None else f"{c.error:.3g}" for c in row)
                            for row in self.cells]
        for part in sorted({k for c in flat for k in c.parts}):
            out[f"error_{part}"] = [" ".join(f"{c.parts[part]:.3g}" if part in c.parts else "-"
                                             for c in row) for row in self.cells]
        if self.marker:
            out["marker"] = self.marker
            out["marked"] = ["".join("1" if c.marked else "0" for c in row)
                             for row in self.cells]
        return out


def progress(text: str) -> None:
    sys.stderr.write(f"bench_regions: {text}\n")
    sys.stderr.flush()


def sweep(rmap: RegionMap, cell_of: Callable[[int, int], Cell]) -> RegionMap:
    """Fill ``rmap.cells`` by calling ``cell_of(ix, iy)``; time it; report on stderr."""
    t0 = time.perf_counter()
    last, fe0 = t0, _FE_COST["wall_time_s"]
    nx, ny = len(rmap.x.values), len(rmap.y.values)
    progress(f"{rmap.key} ({rmap.model}, {rmap.preset}): {ny} x {nx} cells ...")
    rows = []
    for iy in range(ny):
        row = []
        for ix in range(nx):
            row.append(cell_of(ix, iy))
            if time.perf_counter() - last > 15.0:
                last = time.perf_counter()
                progress(f"  {rmap.key}: {iy * nx + ix + 1}/{nx * ny} cells, "
                         f"{last - t0:.0f} s")
        rows.append(row)
    rmap.cells = rows
    rmap.wall_time_s = time.perf_counter() - t0
    rmap.dots_time_s = _FE_COST["wall_time_s"] - fe0
    counts = Counter(c.status for row in rows for c in row)
    progress(f"  {rmap.key}: {rmap.wall_time_s:.1f} s, {rmap.solves} solves, "
             + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    return rmap


def decades(lo: float, hi: float, per_decade: int) -> list[float]:
    """Log-spaced values from 10^lo to 10^hi, ``per_decade`` steps a decade."""
    n = int(round((hi - lo) * per_decade)) + 1
    return [float(10.0**e) for e in np.linspace(lo, hi, n)]


# ---- the maps ----------------------------------------------------------------------------


def lubrication_maps() -> list[RegionMap]:
    """A film and a bridge on a wall, errors against the adaptive quadrature."""
    model = get_model("lubrication")
    film = RegionMap(
        "lubrication-film", "lubrication",
        "lubrication: film on a wall\nR = 1 mm, water, v = 0.1 m/s, no slip",
        "default", Axis("S/R (gap / sphere radius)", decades(-7, math.log10(2), 4)),
        Axis("delta/R (film thickness / R)", decades(-4, math.log10(4), 4)),
        reference="adaptive quadrature of 6 pi eta v int r^3/h^3 dr over the same wetted "
                  "zone", error_style="contour", short_reference="quadrature of the same zone")
    bridge = RegionMap(
        "lubrication-bridge", "lubrication",
        f"lubrication: bridge on a wall, {THETA_BRIDGE:g} deg\nR = 1 mm, water, v = 0.1 m/s",
        "default", Axis("S/R (gap / sphere radius)", decades(-7, math.log10(2), 4)),
        Axis("V/R^3 (bridge volume / R^3)", decades(-6, 0, 4)),
        reference="adaptive quadrature of 6 pi eta v int r^3/h^3 dr over the same wetted "
                  "zone", error_style="contour", short_reference="quadrature of the same zone",
        marker=PAST_RUPTURE)

    def reference(s: float, amount: dict[str, float]) -> float:
        prof = GapProfile.sphere_wall(s, R)
        if "film_thickness" in amount:
            xi = prof.xi_of_edge_gap(np.array([amount["film_thickness"]]))[0]
        else:
            xi = prof.xi_of_volume(np.array([amount["bridge_volume"]]))[0]
        return quadrature_force(prof.h, math.sqrt(xi), ETA, SPEED, math.sqrt(2 * R * s))

    def runner(rmap: RegionMap, amount_of: Callable[[float], dict[str, float]]
               ) -> Callable[[int, int], Cell]:
        def cell(ix: int, iy: int) -> Cell:
            s, a = rmap.x.values[ix] * R, rmap.y.values[iy]
            amount = amount_of(a)
            c, curve = classify(model.name, case("sphere-wall", amount, s / R), "default")
            rmap.solves += curve is not None or c.status == "failed"
            if c.status in ("ok", "warned"):
                c.error = rel_error(force_of(curve, "viscous"), reference(s, amount))
            if c.status == "ok" and "bridge_volume" in amount:
                sc = fe_rupture(a, THETA_BRIDGE)
                c.marked = sc is not None and s >= sc
            return c
        return cell

    sweep(film, runner(film, lambda a: {"film_thickness": a * R}))
    sweep(bridge, runner(bridge, lambda a: {"bridge_volume": a * R**3}))
    return [film, bridge]


def stokes_map() -> RegionMap:
    """Immersed spheres (and a wall row), fast preset, errors against brenner."""
    rows: list[tuple[str, float | None]] = [
        ("0.05", 0.05), ("0.1", 0.1), ("0.5", 0.5), ("1", 1.0), ("2", 2.0), ("10", 10.0),
        ("20", 20.0), ("wall", None)]
    rmap = RegionMap(
        "stokes-immersed", "stokes",
        "stokes (fast preset): immersed sphere-sphere\nand sphere-wall, R1 = 1 mm, v = 0.1 m/s",
        "fast", Axis("S/R1 (gap / first sphere's radius)",
                     [1e-6, 3e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0]),
        Axis("R2/R1 (radius ratio; wall: a plane)", [float(i) for i in range(len(rows))],
             "cat", [lab for lab, _ in rows]),
        reference="brenner (exact series; wall and equal spheres)", error_style="numbers",
        short_reference="brenner (exact series)")
    brenner = get_model("brenner")

    def cell(ix: int, iy: int) -> Cell:
        s, (_, q) = rmap.x.values[ix], rows[iy]
        data = (case("sphere-wall", {"immersed": True}, s) if q is None else
                case("sphere-sphere", {"immersed": True}, s, radius2_over_r=q))
        run = q is None or q == 1.0 or s >= STOKES_MIN_UNEQUAL
        c, curve = classify("stokes", data, "fast", run=run)
        rmap.solves += curve is not None or c.status == "failed"
        if curve is not None and (q is None or q == 1.0):
            ref = brenner.force(scene_from_dict(data))
            c.error = rel_error(force_of(curve, "viscous"), force_of(ref, "viscous"))
        return c

    return sweep(rmap, cell)


MENISCUS_V = [1e-12, 1e-11, 1e-10, 1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 0.1, 1.0, 2.0, 4.0]
MENISCUS_THETA = [0.0, 20.0, 40.0, 60.0, 70.0, 80.0, 89.0, 120.0, 150.0, 160.0]


def meniscus_maps() -> tuple[list[RegionMap], dict[tuple[float, float], dict[str, float]]]:
    """A bridge on a wall near contact and at 0.9 S_c; also returns the forces (for the
    calibrated closure's errors), keyed by (V/R^3, theta)."""
    x = Axis("V/R^3 (bridge volume / R^3)", MENISCUS_V)
    y = Axis("contact angle theta (deg, sphere and wall)", MENISCUS_THETA, "linear")
    near = RegionMap("meniscus-contact", "meniscus",
                     f"meniscus: bridge on a wall at S = {S_CONTACT:g} R\nR = 1 mm, sigma = "
                     "0.072 N/m, one angle on both solids", "default", x, y)
    far = RegionMap("meniscus-rupture", "meniscus",
                    f"meniscus: bridge on a wall at S = {RUPTURE_FRACTION:g} S_c\n(S_c its own "
                    "rupture distance; Lian's where it has none)", "default", x, y)
    refs: dict[tuple[float, float], dict[str, float]] = {}
    pending: dict[tuple[int, int], float] = {}

    def cell_near(ix: int, iy: int) -> Cell:
        v, th = MENISCUS_V[ix], MENISCUS_THETA[iy]
        c, curve = classify("meniscus", case("sphere-wall", {"bridge_volume": v * R**3},
                                             S_CONTACT, th), "default")
        near.solves += curve is not None or c.status == "failed"
        _MENISCUS_CONTACT[(float(f"{v:.12g}"), th)] = c.status
        sc = float(lian_rupture_distance(v * R**3, math.radians(th)))
        own = False
        _FE_RUPTURE[(float(f"{v:.12g}"), th)] = None
        if curve is not None:
            sc, own = float(curve.extras["rupture_distance"][0]), True
            refs[(v, th)] = {"contact": force_of(curve, "capillary") or 0.0, "sc_m": sc}
            _FE_RUPTURE[(float(f"{v:.12g}"), th)] = sc
        pending[(ix, iy)] = sc
        if not own and c.status not in ("refused", "no-scene"):
            c.message += " (0.9 S_c map: Lian's S_c)"
        return c

    def cell_far(ix: int, iy: int) -> Cell:
        v, th = MENISCUS_V[ix], MENISCUS_THETA[iy]
        s = RUPTURE_FRACTION * pending[(ix, iy)]
        c, curve = classify("meniscus", case("sphere-wall", {"bridge_volume": v * R**3},
                                             s / R, th), "default")
        far.solves += curve is not None or c.status == "failed"
        if curve is not None and (v, th) in refs:
            refs[(v, th)]["rupture"] = force_of(curve, "capillary") or 0.0
            refs[(v, th)]["gap_m"] = s
        return c

    sweep(near, cell_near)
    sweep(far, cell_far)
    return [near, far], refs


def calibrated_capillary_maps(refs: dict[tuple[float, float], dict[str, float]]
                              ) -> list[RegionMap]:
    """On a wall (errors against the meniscus map) and between spheres."""
    wall = RegionMap(
        "calibrated-capillary-wall", "calibrated-capillary",
        f"calibrated-capillary: bridge on a wall at S = {S_CONTACT:g} R\n(numbers: max error "
        f"vs meniscus at S = {S_CONTACT:g} R and 0.9 S_c)", "default",
        Axis("V/R^3 (bridge volume / R^3)", decades(-6, 0, 4) + [2.0, 4.0]),
        Axis("contact angle theta (deg, sphere and wall)",
             [float(t) for t in range(0, 90, 5)] + [89.0], "linear"),
        reference="meniscus (default preset) at S = 1e-6 R and 0.9 S_c(meniscus), max of "
                  "the two", error_style="numbers",
        short_reference="meniscus, max at 1e-6 R and 0.9 S_c")
    model = get_model("calibrated-capillary")

    def cell_wall(ix: int, iy: int) -> Cell:
        v, th = wall.x.values[ix], wall.y.values[iy]
        c, curve = classify(model.name, case("sphere-wall", {"bridge_volume": v * R**3},
                                             S_CONTACT, th))
        wall.solves += curve is not None or c.status == "failed"
        if c.status == "refused" and c.named == "meniscus":  # the very same scene, solved
            c.named_solves = _MENISCUS_CONTACT.get((float(f"{v:.12g}"), th))
        key = next((k for k in refs if math.isclose(k[0], v, rel_tol=1e-9) and k[1] == th),
                   None)
        if curve is not None and key is not None and "rupture" in refs[key]:
            ref = refs[key]
            e0 = rel_error(force_of(curve, "capillary"), ref["contact"])
            far = model.force(scene_from_dict(case("sphere-wall", {"bridge_volume": v * R**3},
                                                   ref["gap_m"] / R, th)))
            e1 = rel_error(force_of(far, "capillary"), ref["rupture"])
            c.parts = {k: e for k, e in (("contact", e0), ("rupture", e1)) if e is not None}
            c.error = max(c.parts.values()) if c.parts else None
        return c

    pairs = RegionMap(
        "calibrated-capillary-spheres", "calibrated-capillary",
        f"calibrated-capillary: bridge between spheres, {THETA_BRIDGE:g} deg\nR1 = 1 mm, "
        f"S = {S_CONTACT:g} R_s, V scaled by the smaller radius R_s", "default",
        Axis("V/R_s^3 (bridge volume / smaller radius^3)", decades(-6, 0, 4)),
        Axis("R2/R1 (radius ratio)", [0.05, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5,
                                       2.0, 3.0, 5.0, 7.0, 10.0, 15.0, 20.0]))

    def cell_pair(ix: int, iy: int) -> Cell:
        v, q = pairs.x.values[ix], pairs.y.values[iy]
        rs = min(1.0, q)
        c, curve = classify(model.name, case("sphere-sphere",
                                             {"bridge_volume": v * (rs * R) ** 3},
                                             S_CONTACT * rs, THETA_BRIDGE, radius2_over_r=q))
        pairs.solves += curve is not None or c.status == "failed"
        return c

    return [sweep(wall, cell_wall), sweep(pairs, cell_pair)]


def calibrated_viscous_maps() -> list[RegionMap]:
    """Immersed (errors against brenner), films, bridges (errors against lubrication)."""
    model = get_model("calibrated-viscous")
    brenner, lub = get_model("brenner"), get_model("lubrication")
    rows: list[tuple[str, float | None]] = [("wall", None), ("R2 = R1", 1.0),
                                            ("R2 = 2 R1", 2.0)]
    imm = RegionMap(
        "calibrated-viscous-immersed", "calibrated-viscous",
        "calibrated-viscous: immersed sphere, R = 1 mm\n(numbers: error vs brenner)",
        "default", Axis("S/R (gap / sphere radius)", decades(-7, 3, 4)),
        Axis("geometry", [0.0, 1.0, 2.0], "cat", [lab for lab, _ in rows]),
        reference="brenner (exact series)", error_style="numbers",
        short_reference="brenner (exact series)")

    def cell_imm(ix: int, iy: int) -> Cell:
        s, (_, q) = imm.x.values[ix], rows[iy]
        data = (case("sphere-wall", {"immersed": True}, s) if q is None else
                case("sphere-sphere", {"immersed": True}, s, radius2_over_r=q))
        c, curve = classify(model.name, data)
        imm.solves += curve is not None or c.status == "failed"
        if curve is not None and brenner.applicable(scene_from_dict(data)) is None:
            c.error = rel_error(force_of(curve, "viscous"),
                                force_of(brenner.force(scene_from_dict(data)), "viscous"))
        return c

    film = RegionMap(
        "calibrated-viscous-film", "calibrated-viscous",
        "calibrated-viscous: film on a wall\nR = 1 mm, water, v = 0.1 m/s", "default",
        Axis("S/delta (gap / film thickness)", decades(-3, 0, 4)[:-1] + [0.95, 0.99]),
        Axis("delta/R (film thickness / R)", decades(-4, 0, 4)))

    def cell_film(ix: int, iy: int) -> Cell:
        sd, d = film.x.values[ix], film.y.values[iy]
        c, curve = classify(model.name, case("sphere-wall", {"film_thickness": d * R}, sd * d))
        film.solves += curve is not None or c.status == "failed"
        return c

    bridge = RegionMap(
        "calibrated-viscous-bridge", "calibrated-viscous",
        f"calibrated-viscous: bridge on a wall, {THETA_BRIDGE:g} deg\n(contours: error vs "
        "lubrication, its calibration reference)", "default",
        Axis("S/H (gap / edge gap sqrt(S^2 + V/(pi R)))",
             decades(-3, 0, 4)[:-1] + [0.95, 0.99]),
        Axis("V/R^3 (bridge volume / R^3)", decades(-6, 0, 4)),
        reference="lubrication (default preset; the calibration reference of the bridge "
                  "tables, not independent)", error_style="contour",
        short_reference="lubrication (its calibration reference)",
        marker=PAST_RUPTURE)

    def cell_bridge(ix: int, iy: int) -> Cell:
        sh, v = bridge.x.values[ix], bridge.y.values[iy]
        s = sh * math.sqrt(v * R**3 / (math.pi * R)) / math.sqrt(1.0 - sh * sh)
        data = case("sphere-wall", {"bridge_volume": v * R**3}, s / R)
        c, curve = classify(model.name, data)
        bridge.solves += curve is not None or c.status == "failed"
        if c.status == "ok":
            sc = fe_rupture(v, THETA_BRIDGE)
            c.marked = sc is not None and s >= sc
        if curve is not None:
            ref, ref_curve = classify(lub.name, data)
            if ref.status in ("ok", "warned"):
                c.error = rel_error(force_of(curve, "viscous"), force_of(ref_curve, "viscous"))
        return c

    return [sweep(imm, cell_imm), sweep(film, cell_film), sweep(bridge, cell_bridge)]


# ---- where a refusal sends the user -----------------------------------------------------


def chain_scenes() -> list[tuple[str, dict[str, Any], tuple[str, ...]]]:
    """Scenes whose refusals are followed model to model: the bridges the meniscus map
    finds refused at contact although its check accepts them, and unequal immersed spheres."""
    return [
        ("bridge on a wall, V = 4 R^3, 20 deg, S = 0.01 R",
         case("sphere-wall", {"bridge_volume": 4.0 * R**3}, 1e-2, 20.0),
         ("toroidal", "calibrated-capillary", "lubrication", "calibrated-viscous")),
        ("bridge on a wall, V = 2 R^3, 0 deg, S = 0.01 R",
         case("sphere-wall", {"bridge_volume": 2.0 * R**3}, 1e-2, 0.0),
         ("toroidal", "calibrated-capillary", "lubrication", "calibrated-viscous")),
        ("immersed spheres, R2 = 2 R1, S = 10 R1",
         case("sphere-sphere", {"immersed": True}, 10.0, radius2_over_r=2.0),
         ("calibrated-viscous",)),
    ]


def refusal_chains() -> list[dict[str, Any]]:
    """Follow each refusal to the model it names (fast preset) until one answers, refuses
    naming nothing, or repeats; ``dead_end``: a named model refused the scene."""
    out = []
    for label, data, starts in chain_scenes():
        for start in starts:
            steps: list[dict[str, Any]] = []
            name: str | None = start
            while name is not None and name not in {st["model"] for st in steps}:
                c, _ = classify(name, data, "fast")
                steps.append({"model": name, "status": c.status, "message": c.message,
                              "named": c.named})
                name = c.named if c.status == "refused" else None
            out.append({"scene": label, "chain": steps,
                        "dead_end": len(steps) > 1 and steps[-1]["status"] == "refused"})
            progress(f"  chain ({label}): " + " -> ".join(
                f"{st['model']} {st['status']}" for st in steps))
    return out


# ---- main and chart ----------------------------------------------------------------------


def main() -> None:
    t0 = time.perf_counter()
    load_all()
    men, refs = meniscus_maps()  # first: the others reuse its rupture distances
    maps: list[RegionMap] = [*men, *calibrated_capillary_maps(refs), *lubrication_maps(),
                             *calibrated_viscous_maps(), stokes_map()]
    progress("refusal chains ...")
    chains = refusal_chains()
    total = time.perf_counter() - t0
    per_model: dict[str, float] = {}
    for m in maps:  # the dots' meniscus solves counted as meniscus time
        per_model[m.model] = per_model.get(m.model, 0.0) + m.wall_time_s - m.dots_time_s
        per_model["meniscus"] = per_model.get("meniscus", 0.0) + m.dots_time_s
    order = ["lubrication-film", "lubrication-bridge", "stokes-immersed", "meniscus-contact",
             "meniscus-rupture", "calibrated-capillary-wall", "calibrated-capillary-spheres",
             "calibrated-viscous-immersed", "calibrated-viscous-film",
             "calibrated-viscous-bridge"]
    maps.sort(key=lambda m: order.index(m.key))
    data = {
        "what": "failure-region maps: every cell one scene through get_model(name).force",
        "categories": {k: v["label"] for k, v in CATEGORIES.items()},
        "fixed": {"radius_m": R, "viscosity_Pa_s": ETA, "surface_tension_N_m": SIGMA,
                  "density_kg_m3": RHO, "velocity_m_s": SPEED,
                  "bridge_contact_angle_deg": THETA_BRIDGE, "contact_gap_over_r": S_CONTACT,
                  "rupture_fraction": RUPTURE_FRACTION,
                  "stokes_unequal_min_gap_over_r": STOKES_MIN_UNEQUAL},
        "maps": [m.to_json() for m in maps],
        "wall_time_s": {"total": total, "per_model": per_model,
                        "per_map": {m.key: m.wall_time_s for m in maps},
                        "rupture_dots": {**_FE_COST, "note": "meniscus solves for the dots' "
                                         "rupture distances: inside the bridge maps' times, "
                                         "counted as meniscus in per_model"}},
        "solves": {m.key: m.solves for m in maps},
        "refusal_chains": chains,
        "note": "single run on 2 shared cores; the calibrated-capillary errors reuse the "
                "meniscus map's forces (its time is the meniscus map's)",
    }
    path = write_json("regions", data)
    chart(json.loads(path.read_text()))  # with the machine write_json attached
    progress(f"wrote {path} and regions.png in {total:.0f} s")


def _edges(axis: dict[str, Any]) -> np.ndarray:
    """Cell edges of an axis: midpoints in log (or linear) coordinates, half a step beyond
    the ends; index +- 0.5 for a categorical axis."""
    v = np.asarray(axis["values"], dtype=float)
    if axis["scale"] == "cat":
        return np.arange(v.size + 1) - 0.5
    u = np.log10(v) if axis["scale"] == "log" else v
    mid = 0.5 * (u[1:] + u[:-1])
    e = np.concatenate([[u[0] - (mid[0] - u[0])], mid, [u[-1] + (u[-1] - mid[-1])]])
    return 10.0**e if axis["scale"] == "log" else e


def _short(e: float) -> str:
    """1.234e-05 -> '1e-5' (one digit, no padded exponent)."""
    mant, exp = f"{e:.0e}".split("e")
    return f"{mant}e{int(exp)}"


def _grids(m: dict[str, Any]) -> tuple[list[list[str]], np.ndarray, np.ndarray]:
    """The status of every cell, the errors (NaN: none) and the markers, from the JSON."""
    status = [[m["outcomes"][int(i)]["status"] for i in row.split()] for row in m["cells"]]
    shape = (len(status), len(status[0]))
    err = np.full(shape, np.nan)
    if "error" in m:
        err = np.array([[np.nan if t == "-" else float(t) for t in row.split()]
                        for row in m["error"]])
    marked = np.zeros(shape, bool)
    if "marked" in m:
        marked = np.array([[ch == "1" for ch in row] for row in m["marked"]])
    return status, err, marked


def _panel(ax: Any, m: dict[str, Any]) -> None:
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle

    xe, ye = _edges(m["x"]), _edges(m["y"])
    status, err, marked = _grids(m)
    for cat, sty in CATEGORIES.items():
        rects = [Rectangle((xe[ix], ye[iy]), xe[ix + 1] - xe[ix], ye[iy + 1] - ye[iy])
                 for iy, row in enumerate(status) for ix, s in enumerate(row) if s == cat]
        if rects:
            ax.add_collection(PatchCollection(
                rects, facecolor=sty["color"], edgecolor="0.35", linewidth=0.25,
                hatch=sty["hatch"] or None))
    for name, axis, edges in (("x", m["x"], xe), ("y", m["y"], ye)):
        if axis["scale"] == "log":
            getattr(ax, f"set_{name}scale")("log")
        getattr(ax, f"set_{name}lim")(edges[0], edges[-1])
        if axis["scale"] == "cat":
            getattr(ax, f"set_{name}ticks")(axis["values"], axis["labels"])
    ax.set_xlabel(m["x"]["name"])
    ax.set_ylabel(m["y"]["name"])
    ax.set_title(m["title"], fontsize=9)
    xv, yv = np.asarray(m["x"]["values"]), np.asarray(m["y"]["values"])
    if marked.any():
        iy, ix = np.nonzero(marked)
        ax.plot(xv[ix], yv[iy], "o", ms=5, mfc="k", mec="white", mew=0.8, ls="none")
    if m["error_style"] == "numbers":
        step = 4 if xv.size > 20 else 1            # every decade on a fine log axis
        for iy, ix in zip(*np.nonzero(np.isfinite(err)), strict=True):
            if ix % step == 0:
                ax.text(xv[ix], yv[iy], _short(max(err[iy, ix], 1e-16)), ha="center",
                        va="center", fontsize=7,
                        bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none",
                              "alpha": 0.85})
    elif m["error_style"] == "contour" and np.isfinite(err).sum() >= 4:
        xc, yc = np.meshgrid(xv, yv)
        z = np.ma.masked_invalid(np.log10(np.maximum(err, 1e-16)))
        levels = [lv for lv in (-12, -10, -8, -6, -4, -3, -2, -1) if z.min() < lv < z.max()]
        if levels:
            cs = ax.contour(xc, yc, z, levels=levels, colors="k", linewidths=0.9)
            ax.clabel(cs, fmt=lambda lv: f"1e{int(lv)}", fontsize=7, inline=True)


def chart(data: dict[str, Any]) -> Path:
    """Draw ``regions.png``: one panel a map (categorical colours and hatches), a legend
    panel; errors as contours (dense grids) or numbers (coarse grids)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    maps = data["maps"]
    ncol = 3
    nrow = math.ceil((len(maps) + 1) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(16, 4.6 * nrow), layout="constrained")
    flat = list(np.ravel(axes))
    for ax, m in zip(flat, maps, strict=False):
        _panel(ax, m)
    leg = flat[len(maps)]
    leg.axis("off")
    handles = [Patch(facecolor=s["color"], hatch=s["hatch"], edgecolor="0.35",
                     label=s["label"]) for s in CATEGORIES.values()]
    leg.legend(handles=handles, loc="upper left", fontsize=9, frameon=False,
               handleheight=2.0, handlelength=3.0, title="cell class", title_fontsize=10)
    total = data["wall_time_s"]["total"]
    lines = ["errors |F/F_ref - 1|: numbers in cells (coarse grids) or",
             "contours of log10 (dense grids, labels 1e-k), against:"]
    lines += [f"  {m['key']}: {m['short_reference']}" for m in maps if m["short_reference"]]
    for m in maps:
        if m.get("marker"):
            lines += textwrap.wrap(f"{m['key']}, {m['marker']}", 68, subsequent_indent="  ")
    for ch in data.get("refusal_chains", []):
        if ch["dead_end"]:
            lines += textwrap.wrap("refusal chain ending in a refusal: " + " -> ".join(
                f"{st['model']} ({st['status']})" for st in ch["chain"])
                + f"; {ch['scene']}", 68, subsequent_indent="  ")
    lines += textwrap.wrap(
        f"one scene a cell through get_model(name).force(scene); {total:.0f} s on "
        f"{data['machine'].get('cores')} shared cores (load "
        f"{data['machine'].get('load_1min', 0):.1f}), commit "
        f"{data['machine'].get('commit')}", 68, subsequent_indent="  ")
    notes = flat[len(maps) + 1] if len(flat) > len(maps) + 1 else leg
    notes.axis("off")
    notes.text(0.0, 1.0, "\n".join(lines), transform=notes.transAxes, fontsize=8,
               va="top", family="monospace")
    for ax in flat[len(maps) + 2:]:
        ax.axis("off")
    fig.suptitle("Failure-region maps (benchmarks/bench_regions.py): where each model "
                 "solves, warns, refuses or fails", fontsize=12)
    path = RESULTS / "regions.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


if __name__ == "__main__":
    main_or_chart("regions", main, chart)
