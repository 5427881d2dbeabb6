r"""Study files: a base case plus axes -> points (scene x model).

A study file (``cases/studies/*.toml``) names a base case file, the models to run and the
fields to vary; every point is the base case with those fields replaced, solved by each
model::

    name = "bridge-sphere-plate"
    base = "../dem-pendular-bridge-100um.toml"   # a case file, relative to this file
    models = ["meniscus", "willett"]
    preset = "default"                           # optional: fast, default, accurate
    [axes]                                       # the full grid of all axes
    "liquid.contact_angle" = [0.0, 20.0, 40.0]   # any case-file field path: a list ...
    "amount.bridge_volume" = { start = 1e-13, stop = 1e-11, points = 6, spacing = "log" }
    [set]                                        # optional: fields set on every point
    "motion.gap_over_rupture" = { start = 0.02, stop = 0.98, points = 20, spacing = "linear" }

``[sample] method = "latin-hypercube", points = N, seed = S`` draws N points over ranges
``{ min, max, spacing }``: axis j of point i is ``u = (pi_j(i) + U_ij)/N``, ``pi_j`` a
random permutation, ``U`` uniform on [0, 1) (McKay, Beckman & Conover 1979), mapped
linearly or logarithmically onto [min, max].

Derived fields (axes or ``[set]``) set a case-file field from the point's other values:
``geometry.radius_ratio`` (radius2 = x R), ``amount.volume_over_radius3`` (V = x R^3),
``amount.film_over_radius`` (delta = x R), ``motion.capillary_number`` (v = x sigma/eta),
``motion.gap_over_radius`` / ``gap_over_film`` / ``gap_over_rupture`` (gaps = x R, x delta,
x S_c), ``motion.gap_over_edge_gap`` (S/H = x in (0, 1), H = ``sqrt(S^2 + V/(pi R*))``,
Pitois 2000: ``S = x sqrt(V/(pi R*)/(1 - x^2))``), and for collision studies
``impact.capillary_number`` (v = x sigma/eta) and ``impact.stokes_number``
(v = x 6 pi eta R*^2/m*). ``S_c`` is the point's finite-element rupture distance
(:func:`wetcontact.solver.meniscus.rupture_distance`, ``fast`` preset, about 1e-5).

A collision base (``[impact]`` and ``[solid]``, :mod:`wetcontact.collide.case`) makes every
point one impact; ``models`` then name force sets (``"reference"`` or
:data:`wetcontact.collide.record.FORCE_SET_NAMES`), and each point's curve is the
collision's one-row record (:mod:`wetcontact.collide.record`).

Every error is one :class:`~wetcontact.errors.CaseError` naming the study file, the key, the
value and the allowed range, blamed on the axis or ``set`` entry that produced it. The
guide's page *Sweeps* (``docs/jobs/sweeps.md``) has the rules for amounts, angles and gaps.
"""

from __future__ import annotations

import copy
import itertools
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import CaseError, InputError
from wetcontact.fileio import read_toml
from wetcontact.models import PRESETS, get_model
from wetcontact.scene import _SCHEMA, MIN_GAP, Scene, min_gap, scene_from_dict
from wetcontact.sweep import Point

MAX_SCENES = 100_000
MAX_POINTS = 1_000_000
_KEYS = ("name", "description", "source", "base", "models", "preset", "axes", "set",
         "sample")
_AMOUNTS = ("film_thickness", "bridge_volume", "immersed")
_PER_SURFACE = ("contact_angle_sphere", "contact_angle_wall", "contact_angle_sphere2")


def _rupture_gaps(case: dict[str, Any], value: Any) -> Any:
    sc = scene_from_dict(_without_gaps(case), source="<study point>")
    if sc.bridge_volume is None:
        raise InputError("needs a bridge (amount.bridge_volume) to define a rupture distance")
    sc_rupture = _rupture_distance(sc.radius, sc.radius2 if sc.kind == "sphere-sphere" else
                                   None, sc.contact_angle_sphere, sc.contact_angle_wall,
                                   sc.surface_tension, sc.bridge_volume)
    return _scaled(value, sc_rupture)


@lru_cache(maxsize=4096)
def _rupture_distance(r1: float, r2: float | None, th1: float, th2: float, sigma: float,
                      volume: float) -> float:
    """The bridge's rupture distance at ``meniscus``'s fast preset, kept in the user cache
    (:class:`~wetcontact.branch_cache.NodeCache`, file ``study_rupture``): each
    load of a study (sweep, export csv, calibrate) needs them to build its gaps, and a
    solve takes about 0.5 s. A load that is interrupted keeps those already solved."""
    from wetcontact.solver.meniscus import Bridge, rupture_distance

    n_el = int(get_model("meniscus").presets["fast"]["n_elements"])
    cache = _rupture_cache()
    key = f"{r1!r}|{r2!r}|{th1!r}|{th2!r}|{sigma!r}|{volume!r}|{n_el}"
    if (got := cache.get(key)) is not None:
        return got[0]
    bridge = Bridge(radius=r1, radius2=r2, contact_angle1=th1, contact_angle2=th2,
                    surface_tension=sigma)
    s_c = float(rupture_distance(bridge, volume, n_elements=n_el))
    cache.put(key, s_c, [])
    return s_c


@lru_cache(maxsize=1)
def _rupture_cache() -> Any:
    from wetcontact.branch_cache import NodeCache

    return NodeCache(prefix="study_rupture")


def _film_gaps(case: dict[str, Any], value: Any) -> Any:
    delta = case.get("amount", {}).get("film_thickness")
    if not isinstance(delta, int | float) or not delta > 0:
        raise InputError("needs a film (amount.film_thickness > 0) to scale the gaps by")
    return _scaled(value, float(delta))


def _edge_gaps(case: dict[str, Any], value: Any) -> Any:
    """Gaps S with S/H = value, H = sqrt(S^2 + V/(pi R*)) the bridge's edge gap (the
    coordinate of the finite-liquid factor, :mod:`wetcontact.reduced_models.calibrated`)."""
    vol = case.get("amount", {}).get("bridge_volume")
    if not isinstance(vol, int | float) or not vol > 0:
        raise InputError("needs a bridge (amount.bridge_volume > 0) to define its edge gap")
    geo = case["geometry"]
    r1 = float(geo["radius"])
    r2 = float(geo.get("radius2", r1))
    rstar = r1 if geo.get("kind") == "sphere-wall" else r1 * r2 / (r1 + r2)
    h0sq = float(vol) / (math.pi * rstar)
    xs = [float(v) for v in value] if isinstance(value, list | tuple) else [float(value)]
    for x in xs:
        if not 0.0 <= x < 1.0:
            raise InputError(f"S/H = {x!r}; allowed: [0, 1)")
    gaps = [x * math.sqrt(h0sq / (1.0 - x * x)) for x in xs]
    return gaps if isinstance(value, list | tuple) else gaps[0]


def any_gap(case: Mapping[str, Any]) -> float:
    """A gap (m) that passes every gap check of ``case`` if its other fields are valid: the
    smallest gap its radius allows (:func:`~wetcontact.scene.min_gap`), which is <= 100 R
    and below any allowed film (a film must be thicker than it). It stands in for gaps
    still to be derived, so that a point's other fields can be validated on their own; an
    invalid radius gets :data:`~wetcontact.scene.MIN_GAP` (the radius is refused first)."""
    geo = case.get("geometry")
    r = geo.get("radius") if isinstance(geo, Mapping) else None
    if isinstance(r, int | float) and not isinstance(r, bool):
        try:
            if 0.0 < float(r) <= 10.0:
                return min_gap(float(r))
        except OverflowError:  # an integer beyond the float range
            pass
    return MIN_GAP


def _without_gaps(case: dict[str, Any]) -> dict[str, Any]:
    """A shallow copy of ``case`` with its gaps replaced by :func:`any_gap` (the rupture
    distance and the validity of every other field do not depend on the gaps)."""
    motion = case.get("motion")
    if not isinstance(motion, Mapping):
        return case
    return {**case, "motion": {**motion, "gaps": [any_gap(case)]}}


def _collision(case: dict[str, Any], velocity: float | None = None) -> Any:
    """The point's :class:`~wetcontact.collide.CollisionCase` (``impact.velocity`` replaced
    by ``velocity`` when given)."""
    from wetcontact.collide import collision_case_from_dict

    if not isinstance(case.get("impact"), Mapping):
        raise InputError("needs a collision base (a case file with [impact] and [solid])")
    if velocity is not None:
        case = {**case, "impact": {**case["impact"], "velocity": velocity}}
    return collision_case_from_dict(_without_gaps(case), source="<study point>")


def _stokes_velocity(case: dict[str, Any], value: Any) -> float:
    """``impact.velocity`` of Stokes number ``St = m* v / (6 pi eta R*^2)``."""
    st = float(value)
    if not st > 0.0:
        raise InputError(f"St = {value!r}; allowed: > 0")
    return float(_collision(case, 1.0).stokes_velocity(st))


def _scaled(value: Any, scale: float) -> Any:
    if isinstance(value, list | tuple):
        return [float(v) * scale for v in value]
    return float(value) * scale


# Derived field -> (case-file field it sets, function(case dict, value) -> field value).
DERIVED: dict[str, tuple[str, Callable[[dict[str, Any], Any], Any]]] = {
    "geometry.radius_ratio": ("geometry.radius2",
                              lambda c, v: float(v) * c["geometry"]["radius"]),
    "amount.volume_over_radius3": ("amount.bridge_volume",
                                   lambda c, v: float(v) * c["geometry"]["radius"] ** 3),
    "amount.film_over_radius": ("amount.film_thickness",
                                lambda c, v: float(v) * c["geometry"]["radius"]),
    "motion.capillary_number": ("motion.velocity", lambda c, v: float(v)
                                * c["liquid"]["surface_tension"] / c["liquid"]["viscosity"]),
    "motion.gap_over_radius": ("motion.gaps",
                               lambda c, v: _scaled(v, c["geometry"]["radius"])),
    "motion.gap_over_rupture": ("motion.gaps", _rupture_gaps),
    "motion.gap_over_film": ("motion.gaps", _film_gaps),
    "motion.gap_over_edge_gap": ("motion.gaps", _edge_gaps),
    "impact.capillary_number": ("impact.velocity", lambda c, v: float(v)
                                * c["liquid"]["surface_tension"] / c["liquid"]["viscosity"]),
    "impact.stokes_number": ("impact.velocity", _stokes_velocity),
}
"""Derived dimensionless fields, applied in this order after the plain fields."""


@dataclass(frozen=True)
class Study:
    """A validated study: its points are built (and checked) when it is loaded.

    Attributes
    ----------
    name, description
        From the study file.
    source
        The study file.
    base
        The base case file.
    models
        Model names, each run on every scene.
    preset
        Resolution preset of every point.
    axes
        Axis field paths, in file order (the columns of ``export csv``).
    scenes
        ``(axis values, scene)`` per point of the design, grid order (first axis slowest)
        or sample order.
    cases
        A collision study's :class:`~wetcontact.collide.CollisionCase` per scene (the
        same order); empty for a study of force curves.
    """

    name: str
    description: str
    source: Path
    base: Path
    models: tuple[str, ...]
    preset: str
    axes: tuple[str, ...]
    scenes: tuple[tuple[Mapping[str, Any], Scene], ...] = field(repr=False)
    cases: tuple[Any, ...] = field(default=(), repr=False)

    @property
    def collisions(self) -> bool:
        """Whether the points are impacts (a collision base) rather than force curves."""
        return bool(self.cases)

    def points(self) -> list[Point]:
        """Every (scene, model) point, scene-major, with ``axes`` filled; a collision
        study's points carry their case (``Point.collision``)."""
        if self.cases:
            return [Point(scene=case.scene, model=m, preset=self.preset, axes=dict(ax),
                          collision=case)
                    for (ax, _), case in zip(self.scenes, self.cases, strict=True)
                    for m in self.models]
        return [Point(scene=sc, model=m, preset=self.preset, axes=dict(ax))
                for ax, sc in self.scenes for m in self.models]


def load_study(path: str | Path) -> Study:
    """Read and validate a study file and build its points.

    Raises
    ------
    CaseError
        A missing file, TOML syntax error, unknown key, bad axis, or a generated scene
        outside the case-file ranges: file, key, value and allowed range in one line.
    """
    path = Path(path)
    src = str(path)
    data = _read_toml(src, path, "an existing TOML study file")
    for key in data:
        if key not in _KEYS:
            raise CaseError(src, key, data[key], "known keys: " + ", ".join(_KEYS))
    for key in ("name", "base", "models"):
        if key not in data:
            raise CaseError(src, key, None, "required")
    name = data["name"]
    if not isinstance(name, str) or not name.strip():
        raise CaseError(src, "name", name, "a non-empty string")
    for key in ("description", "source"):
        if not isinstance(data.get(key, ""), str):
            raise CaseError(src, key, data[key], "a string")
    base_path, base = _base(src, path, data["base"])
    collisions = isinstance(base.get("impact"), Mapping)
    models = _models(src, data["models"], collisions)
    preset = data.get("preset", "default")
    if preset not in PRESETS:
        raise CaseError(src, "preset", preset, ", ".join(PRESETS))
    fixed = _table(src, data, "set")
    axes = _table(src, data, "axes")
    for p in [*fixed, *axes]:
        _check_path(src, p, "set" if p in fixed else "axes")
    both = sorted(set(fixed) & set(axes))
    if both:
        raise CaseError(src, f"set.{both[0]}", fixed[both[0]], "a field in [set] or in "
                        "[axes], not both")
    _one_entry_each(src, fixed, axes)
    fixed = {p: _set_value(src, p, v) for p, v in fixed.items()}
    if "sample" in data:
        designs = _sample(src, data["sample"], axes)
    else:
        designs = _grid(src, axes)
    if len(designs) * len(models) > MAX_POINTS:
        raise CaseError(src, "axes", f"{len(designs)} scenes x {len(models)} models",
                        f"at most {MAX_POINTS} points")
    built = [(ax, _scene(src, base_path, base, fixed, ax, collisions)) for ax in designs]
    if collisions:
        from wetcontact.collide.record import point_case

        cases = tuple(point_case(c) for _, c in built)
        scenes = tuple((ax, c.scene) for (ax, _), c in zip(built, cases, strict=True))
    else:
        cases, scenes = (), tuple(built)
    return Study(name=name, description=data.get("description", ""), source=path,
                 base=base_path, models=models, preset=preset, axes=tuple(axes),
                 scenes=scenes, cases=cases)


# ---- parts of a study file ----------------------------------------------------------


def _read_toml(src: str, path: Path, allowed: str) -> dict[str, Any]:
    """The TOML at ``path`` (the study file or its base) by
    :func:`wetcontact.fileio.read_toml`; every error names ``src``, the study file (and
    the base file, when it is the base that cannot be read)."""
    try:
        return read_toml(path, allowed)
    except CaseError as exc:
        if exc.source == src:
            raise
        where = exc.field if exc.value is None else f"{exc.field} of base {exc.source}"
        raise CaseError(src, where, exc.value, exc.allowed) from None


def _models(src: str, models: Any, collisions: bool = False) -> tuple[str, ...]:
    """The model names (force-set names for a collision study), each checked."""
    if not isinstance(models, list) or not models or len(models) > 100:
        raise CaseError(src, "models", models, "a non-empty list of model names")
    for i, m in enumerate(models):
        if not isinstance(m, str):
            raise CaseError(src, f"models[{i}]", m, "a model name")
        if collisions:
            from wetcontact.collide.record import FORCE_SET_NAMES

            if m not in FORCE_SET_NAMES:
                raise CaseError(src, f"models[{i}]", m, "a collision study's force sets: "
                                + ", ".join(FORCE_SET_NAMES))
            continue
        try:
            get_model(m)
        except InputError:
            from wetcontact.models import MODELS

            raise CaseError(src, f"models[{i}]", m, ", ".join(sorted(MODELS))) from None
    if len(set(models)) != len(models):
        raise CaseError(src, "models", models, "each model once")
    return tuple(models)


def _base(src: str, path: Path, base: Any) -> tuple[Path, dict[str, Any]]:
    if not isinstance(base, str) or not base or len(base) > 4096 or "\0" in base:
        raise CaseError(src, "base", base, "a case file path relative to the study file")
    base_path = path.parent / base
    data = _read_toml(src, base_path, f"an existing case file ({base_path} not found)")
    if isinstance(data.get("impact"), Mapping):  # the base alone must be valid
        from wetcontact.collide import collision_case_from_dict

        collision_case_from_dict(data, source=str(base_path))
    else:
        scene_from_dict(data, source=str(base_path))
    return base_path, data


def _table(src: str, data: Mapping[str, Any], key: str) -> dict[str, Any]:
    val = data.get(key, {})
    if not isinstance(val, Mapping):
        raise CaseError(src, key, val, f"a table [{key}] of field path = values")
    return dict(val)


def _check_path(src: str, p: str, where: str) -> None:
    table, _, key = p.partition(".")
    plain = bool(table) and table in _SCHEMA and key in _SCHEMA[table]
    if not (plain or p in DERIVED):
        allowed = sorted(f"{t}.{k}" for t, ks in _SCHEMA.items() if t for k in ks)
        raise CaseError(src, where, p, "a case-file field path (" + ", ".join(allowed)
                        + ") or a derived one (" + ", ".join(DERIVED) + ")")


def _one_entry_each(src: str, fixed: Mapping[str, Any], axes: Mapping[str, Any]) -> None:
    """Refuse two entries that set the same case-file field (a derived field counts as the
    field it sets, e.g. ``motion.gap_over_radius`` as ``motion.gaps``) or two amounts (a
    case has exactly one of ``[amount]``'s fields): the later one would silently win."""
    seen: dict[str, str] = {}
    for p in [*fixed, *axes]:
        target = DERIVED[p][0] if p in DERIVED else p
        slot = "amount" if target.startswith("amount.") else target
        if slot in seen:
            where = "set" if p in fixed else "axes"
            first = f"{'set' if seen[slot] in fixed else 'axes'}.{seen[slot]}"
            raise CaseError(src, f"{where}.{p}", (fixed if p in fixed else axes)[p],
                            f"one entry for {slot} ({first} sets it already)")
        seen[slot] = p


def _number(src: str, key: str, v: Any) -> float:
    """``v`` as a finite float; an integer beyond the float range (``1`` and 400 zeros)
    is refused like infinity, not an ``OverflowError``."""
    if isinstance(v, bool) or not isinstance(v, int | float) or not _finite(v):
        raise CaseError(src, key, v, "a finite number")
    return float(v)


def _finite(v: int | float) -> bool:
    """True for a finite float or an integer a float can hold."""
    try:
        return math.isfinite(v)
    except OverflowError:  # math.isfinite converts an int to float first
        return False


def _range(src: str, key: str, spec: Mapping[str, Any]) -> list[float]:
    """``{start, stop, points, spacing}`` -> values."""
    for k in spec:
        if k not in ("start", "stop", "points", "spacing"):
            raise CaseError(src, f"{key}.{k}", spec[k], "keys start, stop, points, spacing")
    for k in ("start", "stop", "points"):
        if k not in spec:
            raise CaseError(src, f"{key}.{k}", None, "required")
    a, b = _number(src, f"{key}.start", spec["start"]), _number(src, f"{key}.stop", spec["stop"])
    n = spec["points"]
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_SCENES:
        raise CaseError(src, f"{key}.points", n, f"an integer in [1, {MAX_SCENES}]")
    spacing = spec.get("spacing", "linear")
    if spacing == "log":
        if a <= 0 or b <= 0:
            raise CaseError(src, f"{key}.start", a, "> 0 (and stop > 0) for spacing = 'log'")
        return _finite_values(src, key, spec, np.geomspace, a, b, n)
    if spacing != "linear":
        raise CaseError(src, f"{key}.spacing", spacing, "'log' or 'linear'")
    return _finite_values(src, key, spec, np.linspace, a, b, n)


def _finite_values(src: str, key: str, spec: Mapping[str, Any],
                   space: Callable[..., np.ndarray], a: float, b: float, n: int) -> list[float]:
    """``space(a, b, n)`` as floats, computed without numpy's warnings (they printed lines
    before the error); a range whose steps overflow (start -1e308, stop 1e308) is one
    error naming the range, not a ``nan`` blamed on the field it sets."""
    with np.errstate(all="ignore"):
        vals = space(a, b, n)
    if not np.all(np.isfinite(vals)):
        raise CaseError(src, key, dict(spec), "start and stop whose difference is a finite "
                        "number (the values in between must be finite)")
    return [float(x) for x in vals]


def _values(src: str, key: str, v: Any) -> list[Any]:
    """An axis: a non-empty list of scalars or a range table."""
    if isinstance(v, Mapping):
        return _range(src, key, v)
    if not isinstance(v, list) or not v or len(v) > MAX_SCENES:
        raise CaseError(src, key, v, f"a list of 1 to {MAX_SCENES} values or "
                        "{start, stop, points, spacing}")
    for i, x in enumerate(v):
        if isinstance(x, Mapping | list) or (
                isinstance(x, int | float) and not isinstance(x, bool) and not _finite(x)):
            raise CaseError(src, f"{key}[{i}]", x, "a finite number, string or boolean")
    return list(v)


def _set_value(src: str, p: str, v: Any) -> Any:
    """A ``[set]`` value: as given; a range table for a derived gap field is expanded."""
    key = f"set.{p}"
    if p in DERIVED and DERIVED[p][0] == "motion.gaps":
        return _values(src, key, v) if isinstance(v, Mapping | list) else _number(src, key, v)
    if p in DERIVED:
        return _number(src, key, v)
    return v


def _grid(src: str, axes: Mapping[str, Any]) -> list[dict[str, Any]]:
    values = {p: _values(src, f"axes.{p}", v) for p, v in axes.items()}
    for p in values.keys() & DERIVED.keys():  # a derived field scales a number
        values[p] = [_number(src, f"axes.{p}", x) for x in values[p]]
    n = math.prod(len(v) for v in values.values())  # first: it is cheap at any size
    if n > MAX_SCENES:
        raise CaseError(src, "axes", f"{n} grid points", f"at most {MAX_SCENES} scenes")
    for p, vals in values.items():  # a repeated value would be one point listed twice
        seen: set[object] = set()
        for v in vals:  # numbers compare as numbers (1 == 1.0), anything else by its repr
            key = float(v) if isinstance(v, int | float) and not isinstance(v, bool) else repr(v)
            if key in seen:
                raise CaseError(src, f"axes.{p}", axes[p], f"distinct values ({v!r} appears "
                                "more than once)")
            seen.add(key)
    return [dict(zip(values, combo, strict=True)) for combo in itertools.product(*values.values())]


def _sample(src: str, sample: Any, axes: Mapping[str, Any]) -> list[dict[str, Any]]:
    if not isinstance(sample, Mapping):
        raise CaseError(src, "sample", sample, "a table [sample] with method, points, seed")
    for k in sample:
        if k not in ("method", "points", "seed"):
            raise CaseError(src, f"sample.{k}", sample[k], "keys method, points, seed")
    if sample.get("method") != "latin-hypercube":
        raise CaseError(src, "sample.method", sample.get("method"), "'latin-hypercube'")
    n, seed = sample.get("points"), sample.get("seed")
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_SCENES:
        raise CaseError(src, "sample.points", n, f"an integer in [1, {MAX_SCENES}]")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise CaseError(src, "sample.seed", seed, "an integer >= 0 (the design is "
                        "reproducible only with a fixed seed)")
    if not axes:
        raise CaseError(src, "axes", None, "at least one axis {min, max} to sample")
    lims = {}
    for p, spec in axes.items():
        key = f"axes.{p}"
        if not isinstance(spec, Mapping) or set(spec) - {"min", "max", "spacing"} or not (
                {"min", "max"} <= set(spec)):
            raise CaseError(src, key, spec, "{min, max, spacing} with [sample]")
        lo, hi = _number(src, f"{key}.min", spec["min"]), _number(src, f"{key}.max", spec["max"])
        spacing = spec.get("spacing", "linear")
        if spacing not in ("linear", "log"):
            raise CaseError(src, f"{key}.spacing", spacing, "'log' or 'linear'")
        if not lo < hi:
            raise CaseError(src, f"{key}.max", hi, f"> min = {lo:g}")
        if spacing == "log" and lo <= 0:
            raise CaseError(src, f"{key}.min", lo, "> 0 for spacing = 'log'")
        lims[p] = (lo, hi, spacing)
    u = latin_hypercube(n, len(lims), seed)
    out = []
    for row in u:
        pt = {}
        for (p, (lo, hi, spacing)), x in zip(lims.items(), row, strict=True):
            with np.errstate(all="ignore"):  # an overflow is the error below, not a warning
                v = float(lo * (hi / lo) ** x) if spacing == "log" else float(lo + (hi - lo) * x)
            if not math.isfinite(v):
                raise CaseError(src, f"axes.{p}", dict(axes[p]), "min and max whose "
                                "difference (ratio, for spacing = 'log') is a finite number")
            pt[p] = v
        out.append(pt)
    return out


def latin_hypercube(n: int, d: int, seed: int) -> np.ndarray:
    """A seeded Latin hypercube on [0, 1)^d, shape (n, d): each column has exactly one
    value in each of the n strata [k/n, (k+1)/n) (McKay, Beckman & Conover 1979).

    Hand-written on purpose, not ``scipy.stats.qmc.LatinHypercube``: the two draw from the
    generator in another order, so scipy's design for the same seed is another set of
    points (seed 7919, n = 5, d = 2: no point in common). The seeded designs are part of
    shipped results: ``cases/studies/bridge-held-out.toml`` and the committed held-out
    studies ``benchmarks/results/calibration/*_heldout.toml`` (seed 7919) name points whose
    references are in ``*_points.npz`` and whose errors are the published held-out tables;
    scipy's points would change every one of those points and their store keys
    (``tests/test_calibrate.py::test_committed_reference_points_are_solved_again`` fails
    with it). The design is the textbook one (a permutation per column, a uniform offset in
    each stratum) and ``tests/test_study.py`` checks its stratification.
    """
    rng = np.random.default_rng(seed)
    perms = np.stack([rng.permutation(n) for _ in range(d)], axis=1)
    return (perms + rng.random((n, d))) / n


# ---- building one scene -------------------------------------------------------------


def _assign(case: dict[str, Any], p: str, value: Any) -> None:
    table, _, key = p.partition(".")
    sub = case.setdefault(table, {})
    if table == "amount":
        for k in _AMOUNTS:
            sub.pop(k, None)
    if table == "liquid" and key == "contact_angle":
        for k in _PER_SURFACE:
            sub.pop(k, None)
    if table == "liquid" and key in _PER_SURFACE and "contact_angle" in sub:
        th = sub.pop("contact_angle")
        other = "contact_angle_wall" if case["geometry"].get("kind") == "sphere-wall" \
            else "contact_angle_sphere2"
        sub["contact_angle_sphere"] = th
        sub[other] = th
    sub[key] = value


@dataclass
class _Entries:
    """Which study entry set which case-file field of one point, to blame errors on.

    Attributes
    ----------
    src, base_path
        The study file and its base case file.
    given
        Every entry of the point (``[set]`` and axis values), field path -> value.
    origin
        Field path -> ``"set"`` or ``"axes"``.
    axes
        The point's axis values (shown when the base is to blame).
    targets
        Case-file field -> the entry that set it, filled as the point is built.
    """

    src: str
    base_path: Path
    given: dict[str, Any]
    origin: dict[str, str]
    axes: Mapping[str, Any]
    targets: dict[str, str] = field(default_factory=dict)

    def blame(self, exc: CaseError) -> CaseError:
        """``exc`` (an error of the point's case) against the study entry that set its
        field: its own value for a plain field, the derived value and what it gave for a
        derived one, the base file and the point when no entry set the field."""
        entry = self.targets.get(_bare(exc.field))
        if entry is None:
            return CaseError(self.src, exc.field, exc.value, f"{exc.allowed} (base "
                             f"{self.base_path} at point {dict(self.axes)})")
        key = f"{self.origin[entry]}.{entry}"
        if entry in DERIVED:
            return CaseError(self.src, key, self.given[entry], f"a value giving {exc.field} "
                             f"{exc.allowed} (it gave {exc.value!r})")
        return CaseError(self.src, key, exc.value, exc.allowed)

    def check_inputs(self, case: dict[str, Any]) -> None:
        """Raise the blamed error of ``case`` (with derived gaps stood in for by
        :func:`any_gap`), unless its error is in a field a derived entry has still to set.
        A derived field reads the point's other fields (radius, angles, volume), so a bad
        value there is the error, not the derived field that read it."""
        derived_gaps = any(DERIVED[p][0] == "motion.gaps" for p in self.given if p in DERIVED)
        given = _without_gaps(case) if derived_gaps else case
        try:
            if isinstance(case.get("impact"), Mapping):
                from wetcontact.collide import collision_case_from_dict

                collision_case_from_dict(given, source=str(self.base_path))
            else:
                scene_from_dict(given, source=str(self.base_path))
        except CaseError as exc:
            pending = {_slot(DERIVED[p][0]) for p in self.given
                       if p in DERIVED and DERIVED[p][0] not in self.targets}
            if _slot(exc.field) not in pending:
                raise self.blame(exc) from None


def _bare(fld: str) -> str:
    """The case-file field of an error's field: ``motion.gaps`` for ``motion.gaps[3]`` or
    ``motion.gaps.start``."""
    return re.sub(r"(\[\d+\]|\.(start|stop|points|spacing))$", "", fld)


def _slot(fld: str) -> str:
    """The case-file field ``fld`` stands for: ``amount`` for any amount (a case has one)."""
    fld = _bare(fld)
    return "amount" if fld == "amount" or fld.startswith("amount.") else fld


def _scene(src: str, base_path: Path, base: dict[str, Any], fixed: Mapping[str, Any],
           axes: Mapping[str, Any], collision: bool = False) -> Any:
    """The base with ``fixed`` and ``axes`` applied (a Scene, or a CollisionCase when
    ``collision``); errors blamed on their origin.

    Plain fields are set first, then the derived ones in :data:`DERIVED` order. A derived
    field that fails, or derived gaps the finished scene refuses, are blamed on that
    derived entry only when the point's other fields are valid on their own
    (:meth:`_Entries.check_inputs`): an angle of 200 deg read by ``gap_over_rupture`` is
    the angle's error.
    """
    case = copy.deepcopy(base)
    given = {**fixed, **axes}
    entries = _Entries(src=src, base_path=base_path, given=given,
                       origin={p: ("set" if p in fixed else "axes") for p in given}, axes=axes)
    for p, v in given.items():
        if p not in DERIVED:
            _assign(case, p, v)
            entries.targets[p] = p
    for p, (target, fn) in DERIVED.items():
        if p not in given:
            continue
        try:
            val = fn(case, given[p])
        except (ValueError, KeyError, TypeError, ArithmeticError) as exc:
            entries.check_inputs(case)
            why = f"missing {exc}" if isinstance(exc, KeyError) else str(exc)
            raise CaseError(src, f"{entries.origin[p]}.{p}", given[p], f"a value giving a "
                            f"valid {target} ({why}; point {dict(axes)})") from None
        _assign(case, target, val)
        entries.targets[target] = p
    try:
        if collision:
            from wetcontact.collide import collision_case_from_dict

            return collision_case_from_dict(case, source=str(base_path))
        return scene_from_dict(case, source=str(base_path))
    except CaseError as exc:
        if entries.targets.get(_bare(exc.field)) in DERIVED:
            entries.check_inputs(case)  # derived gaps are checked before the amounts
        raise entries.blame(exc) from None
