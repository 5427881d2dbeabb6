"""Collision case: the scene plus the tables ``[impact]``, ``[solid]``, ``[solid2]``,
``[contact]`` and ``[phases]``.

A collision case file is a case file (``wetcontact.scene``) with these tables added; its
``[motion]`` table may be left out (the impact gives the speed). SI units inside; angles
in degrees in the file. Every error is a :class:`~wetcontact.errors.CaseError` naming the
file, the field, the value and its allowed range.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

from wetcontact.errors import CaseError
from wetcontact.scene import Scene, _num, plain_number, scene_from_dict

ContactModel = Literal["impulse", "hertz", "thornton"]
Cutoff = Literal["zero", "constant", "shifted"]
CONTACT_MODELS = ("impulse", "hertz", "thornton")
CUTOFFS = ("zero", "constant", "shifted")
RUPTURE_LAWS = ("static", "dynamic")


@dataclass(frozen=True)
class Solid:
    """A sphere's (or the wall's) material.

    Attributes
    ----------
    density
        rho_p (kg/m^3).
    youngs_modulus, poisson_ratio
        E (Pa) and nu, for the ``hertz`` and ``thornton`` contacts; E = None: not given.
    restitution
        Dry restitution coefficient e_dry in (0, 1].
    friction, lubricated_friction
        Coulomb coefficients, dry and with liquid in the contact (the latter applies to
        every wet impact).
    roughness
        The gap x_r (m) at which solid contact starts.
    """

    density: float
    youngs_modulus: float | None = None
    poisson_ratio: float = 0.25
    restitution: float = 1.0
    friction: float = 0.0
    lubricated_friction: float = 0.0
    roughness: float = 0.0


@dataclass(frozen=True)
class Impact:
    """Initial motion and the far-field forces switched on.

    Attributes
    ----------
    velocity
        Normal approach speed v0 (m/s) at ``start_gap``, positive = toward.
    start_gap
        Gap (m) where the collision starts and where the rebound speed is measured.
    tangential_velocity, spin
        Tangential speed of the centre (m/s) and angular velocity (rad/s; positive spin
        makes the contact point move with ``tangential_velocity``).
    gravity, buoyancy, added_mass, drag
        Far-field terms for an immersed or partly immersed sphere on a wall.
    """

    velocity: float
    start_gap: float
    tangential_velocity: float = 0.0
    spin: float = 0.0
    gravity: bool = False
    buoyancy: bool = False
    added_mass: bool = False
    drag: bool = False


@dataclass(frozen=True)
class CollisionCase:
    """Everything a collision needs: the scene (liquid, geometry, amount) and the tables.

    Attributes
    ----------
    scene
        The contact (its gaps and velocity are not used by the collision).
    impact, solid, solid2, contact_model, cutoff
        As in the case file (``solid2`` is the wall or the second sphere).
    viscous_on_rebound
        False: cavitation, no viscous force while the gap opens.
    advancing_angle, receding_angle
        Contact angles (rad) on approach and on emergence / in the bridge, the same on both
        bodies unless the scene has two angles and these are not given.
    rupture
        ``"static"`` (the capillary model's rupture distance) or ``"dynamic"`` (times
        Pitois' ``1 + Ca^1/2``, Ca = eta |v| / sigma, Pitois et al. 2001).
    """

    scene: Scene
    impact: Impact
    solid: Solid
    solid2: Solid
    contact_model: ContactModel = "impulse"
    cutoff: Cutoff = "zero"
    viscous_on_rebound: bool = True
    advancing_angle: tuple[float, float] | None = None
    receding_angle: tuple[float, float] | None = None
    rupture: str = "static"

    @property
    def roughness(self) -> float:
        """Gap x_r (m) at which solid contact starts: the larger of the two bodies'."""
        return max(self.solid.roughness, self.solid2.roughness)

    @property
    def restitution(self) -> float:
        """e_dry of the pair: the smaller of the two bodies' (a pair has one value)."""
        return min(self.solid.restitution, self.solid2.restitution)

    @property
    def reduced_mass(self) -> float:
        """m* (kg): the sphere's mass on a wall, ``m1 m2 / (m1 + m2)`` for two spheres
        (without added mass)."""
        sc = self.scene
        m1 = self.solid.density * 4.0 / 3.0 * math.pi * sc.radius ** 3
        if sc.kind == "sphere-wall":
            return m1
        m2 = self.solid2.density * 4.0 / 3.0 * math.pi * float(sc.radius2) ** 3
        return m1 * m2 / (m1 + m2)

    def stokes_velocity(self, stokes_number: float) -> float:
        """The approach speed (m/s) of Stokes number ``St = m* v / (6 pi eta R*^2)``."""
        sc = self.scene
        return (stokes_number * 6.0 * math.pi * sc.viscosity * sc.reduced_radius ** 2
                / self.reduced_mass)

    @property
    def friction(self) -> float:
        """Coulomb coefficient in the contact: lubricated where liquid is present."""
        return min(self.solid.lubricated_friction, self.solid2.lubricated_friction)

    def with_(self, **changes: Any) -> CollisionCase:
        """A copy with fields changed (``dataclasses.replace``); the impact's fields may
        be given by name (``velocity=...``)."""
        imp = {k: changes.pop(k) for k in list(changes) if k in Impact.__dataclass_fields__}
        if imp:
            changes["impact"] = replace(self.impact, **imp)
        return replace(self, **changes)


def _bool(src: str, name: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise CaseError(src, name, value, "true or false")
    return value


def _choice(src: str, name: str, value: Any, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in choices:
        raise CaseError(src, name, value, "one of " + ", ".join(f'"{c}"' for c in choices))
    return value


def _table(src: str, data: Mapping[str, Any], key: str) -> Mapping[str, Any]:
    val = data.get(key, {})
    if not isinstance(val, Mapping):
        raise CaseError(src, key, val, f"a TOML table [{key}]")
    return val


def _solid(src: str, key: str, t: Mapping[str, Any], base: Solid | None, r_star: float
           ) -> Solid:
    def get(field: str, default: Any) -> Any:
        return plain_number(t.get(field, default))

    if base is None and "density" not in t:
        raise CaseError(src, f"{key}.density", None, "required (kg/m3)")
    b = base or Solid(density=1.0, roughness=1e-4 * r_star)
    density = _num(src, f"{key}.density", get("density", b.density), 0.0, 1e6, "kg/m3")
    e_mod = get("youngs_modulus", b.youngs_modulus)
    if e_mod is not None:
        e_mod = _num(src, f"{key}.youngs_modulus", e_mod, 0.0, 1e13, "Pa")
    nu = _num(src, f"{key}.poisson_ratio", get("poisson_ratio", b.poisson_ratio), -1.0, 0.5,
              "", hi_open=True)
    e_dry = _num(src, f"{key}.restitution", get("restitution", b.restitution), 0.0, 1.0, "")
    mu = _num(src, f"{key}.friction", get("friction", b.friction), 0.0, 10.0, "",
              lo_open=False)
    mu_l = _num(src, f"{key}.lubricated_friction", get("lubricated_friction", t.get(
        "friction", b.lubricated_friction if base else mu)), 0.0, 10.0, "", lo_open=False)
    rough = _num(src, f"{key}.roughness", get("roughness", b.roughness), 0.0, 0.5 * r_star,
                 "m (and at most R*/2)")
    return Solid(density, e_mod, nu, e_dry, mu, mu_l, rough)


def _angles(src: str, name: str, value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    vals = value if isinstance(value, list) else [value, value]
    if len(vals) != 2:
        raise CaseError(src, name, value, "an angle in [0, 180) deg, or a list of two (one "
                        "per body)")
    out = []
    for v in vals:
        v = plain_number(v)
        if isinstance(v, bool) or not isinstance(v, int | float) or not 0.0 <= v < 180.0:
            raise CaseError(src, name, value, "an angle in [0, 180) deg, or a list of two")
        out.append(math.radians(float(v)))
    return out[0], out[1]


def default_start_gap(scene: Scene) -> float:
    """Where an impact starts when ``impact.start_gap`` is not given: the film thickness
    for a film, 1 R for an immersed sphere; for a bridge the rupture distance (found by
    :func:`wetcontact.collide.forces.rupture_distance` when the collision is set up;
    ``nan`` here as a marker)."""
    if scene.amount == "film":
        return float(scene.film_thickness)
    if scene.amount == "immersed":
        return scene.radius
    return math.nan


def collision_case_from_dict(data: Mapping[str, Any], source: str = "<dict>"
                             ) -> CollisionCase:
    """Validate a collision case given as the nested dict of its TOML file.

    Parameters
    ----------
    data
        The case file's tables; ``[impact]`` and ``[solid]`` are required, ``[motion]`` may
        be left out (it is filled from ``[impact]``).
    source
        What error messages name as the file.

    Returns
    -------
    CollisionCase

    Raises
    ------
    CaseError
        A missing table or field, or a value outside its range.
    """
    if not isinstance(data, Mapping):
        raise CaseError(source, "(top level)", type(data).__name__, "a TOML table")
    for key in ("impact", "solid"):
        if key not in data:
            raise CaseError(source, f"[{key}]", None, f"a [{key}] table (wetcontact collide "
                            "needs [impact] and [solid]; see docs/jobs/collide.md)")
    imp_t = _table(source, data, "impact")
    if "velocity" not in imp_t:
        raise CaseError(source, "impact.velocity", None, "required (m/s, positive = toward)")
    v0 = _num(source, "impact.velocity", imp_t["velocity"], 0.0, 1e3, "m/s")
    scene_data = dict(data)
    if "motion" not in scene_data:
        geo = _table(source, data, "geometry")
        amt = _table(source, data, "amount")
        r = plain_number(geo.get("radius", 1.0))
        r = float(r) if isinstance(r, int | float) and not isinstance(r, bool) else 1.0
        gap = 1e-3 * r
        film = plain_number(amt.get("film_thickness"))
        if isinstance(film, int | float) and not isinstance(film, bool) and film > 0:
            gap = min(gap, 0.5 * float(film))
        scene_data["motion"] = {"velocity": v0, "gaps": [gap]}
    scene = scene_from_dict(scene_data, source=source)
    return _with_tables(scene, data, source)


def collision_case(scene: Scene, impact: Mapping[str, Any], solid: Mapping[str, Any],
                   solid2: Mapping[str, Any] | None = None,
                   contact: Mapping[str, Any] | None = None,
                   phases: Mapping[str, Any] | None = None) -> CollisionCase:
    """A collision case from a scene and the tables of a case file, given as dicts with
    the case file's keys and units (SI, angles in degrees); validated as a file is.

    Examples
    --------
    >>> case = collision_case(scene, impact={"velocity": 0.5},
    ...                       solid={"density": 2500.0, "restitution": 0.97})
    """
    data: dict[str, Any] = {"impact": dict(impact), "solid": dict(solid)}
    for key, val in (("solid2", solid2), ("contact", contact), ("phases", phases)):
        if val is not None:
            data[key] = dict(val)
    return _with_tables(scene, data, scene.origin)


def _with_tables(scene: Scene, data: Mapping[str, Any], source: str) -> CollisionCase:
    imp_t = _table(source, data, "impact")
    if "velocity" not in imp_t:
        raise CaseError(source, "impact.velocity", None, "required (m/s, positive = toward)")
    v0 = _num(source, "impact.velocity", imp_t["velocity"], 0.0, 1e3, "m/s")
    r_star = scene.reduced_radius

    solid = _solid(source, "solid", _table(source, data, "solid"), None, r_star)
    solid2 = (_solid(source, "solid2", _table(source, data, "solid2"), solid, r_star)
              if "solid2" in data else solid)
    con = _table(source, data, "contact")
    model = _choice(source, "contact.model", con.get("model", "impulse"), CONTACT_MODELS)
    cutoff = _choice(source, "contact.cutoff", con.get("cutoff", "zero"), CUTOFFS)
    if model != "impulse":
        for key, s in (("solid", solid), ("solid2", solid2)):
            if s.youngs_modulus is None:
                raise CaseError(source, f"{key}.youngs_modulus", None,
                                f"required by contact.model = \"{model}\" (Pa)")
    ph = _table(source, data, "phases")
    rupture = _choice(source, "phases.rupture", ph.get("rupture", "static"), RUPTURE_LAWS)
    von = _bool(source, "phases.viscous_on_rebound", ph.get("viscous_on_rebound", True))
    adv = _angles(source, "phases.advancing_angle", ph.get("advancing_angle"))
    rec = _angles(source, "phases.receding_angle", ph.get("receding_angle"))

    rough = max(solid.roughness, solid2.roughness)
    start = imp_t.get("start_gap")
    if start is None:
        start_gap = default_start_gap(scene)
    else:
        start_gap = _num(source, "impact.start_gap", start, 0.0, 100.0 * scene.radius,
                         "m (and at most 100 R)")
        if start_gap <= rough:
            raise CaseError(source, "impact.start_gap", start, f"> the roughness gap "
                            f"{rough:.6g} m, where solid contact starts")
    if not math.isnan(start_gap) and start_gap <= rough:
        raise CaseError(source, "solid.roughness", rough, f"< the start gap {start_gap:.6g} m")
    flags = {k: _bool(source, f"impact.{k}", imp_t.get(k, False))
             for k in ("gravity", "buoyancy", "added_mass", "drag")}
    if any(flags.values()) and scene.kind != "sphere-wall":
        on = ", ".join(k for k, v in flags.items() if v)
        raise CaseError(source, "impact", on, "gravity, buoyancy, added_mass and drag for "
                        "sphere-wall impacts only (a pair's relative motion is free of them)")
    if flags["gravity"] and scene.gravity == 0.0:
        raise CaseError(source, "impact.gravity", True, "needs liquid.gravity > 0 (m/s2)")
    vt = _num(source, "impact.tangential_velocity", imp_t.get("tangential_velocity", 0.0),
              -1e3, 1e3, "m/s", lo_open=False)
    spin = _num(source, "impact.spin", imp_t.get("spin", 0.0), -1e7, 1e7, "rad/s",
                lo_open=False)
    impact = Impact(v0, start_gap, vt, spin, **flags)
    return CollisionCase(scene, impact, solid, solid2, model, cutoff,  # type: ignore[arg-type]
                         von, adv, rec, rupture)


def load_collision_case(path: str | Path) -> CollisionCase:
    """Read and validate a collision case file (TOML).

    Parameters
    ----------
    path
        The case file: a case file (README "Case files") with ``[impact]`` and ``[solid]``
        tables (and optionally ``[solid2]``, ``[contact]``, ``[phases]``).

    Returns
    -------
    CollisionCase

    Raises
    ------
    CaseError
        The file is missing, not a regular file, too large, not TOML, or a field is
        missing or out of range.
    """
    from wetcontact.fileio import read_toml

    data = read_toml(path, "an existing TOML collision case file")
    return collision_case_from_dict(data, source=str(path))
