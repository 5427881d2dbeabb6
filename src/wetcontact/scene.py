"""Scene: the validated, frozen description of one wet contact.

A scene is read from a TOML case file (format in ``../shared/DESIGN.md`` and the README)
or built from a nested dict with :func:`scene_from_dict`. Everything inside is SI; angles
are given in degrees in the case file and stored in radians. Every validation error is a
:class:`~wetcontact.errors.CaseError` naming the file, the field, the value and the
allowed range.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from wetcontact.errors import CaseError

Kind = Literal["sphere-wall", "sphere-sphere"]
AmountKind = Literal["immersed", "film", "bridge"]

# Allowed keys per table, with whether they are required. Unknown keys are errors.
_SCHEMA: dict[str, dict[str, bool]] = {
    "": {"name": True, "description": False, "source": False},
    "geometry": {"kind": True, "radius": True, "radius2": False},
    "liquid": {
        "viscosity": True,
        "surface_tension": True,
        "density": True,
        "contact_angle": False,
        "contact_angle_sphere": False,
        "contact_angle_wall": False,
        "contact_angle_sphere2": False,
        "slip_length_sphere": False,
        "slip_length_wall": False,
        "gravity": False,
    },
    "amount": {"film_thickness": False, "bridge_volume": False, "immersed": False},
    "motion": {"velocity": True, "gaps": True},
    "particle": {"density": False},
    "fidelity": {"tolerance": False, "model": False},
    # collision tables: read by wetcontact.collide.case, which validates their values
    "impact": {"velocity": False, "start_gap": False, "tangential_velocity": False,
               "spin": False, "gravity": False, "buoyancy": False, "added_mass": False,
               "drag": False},
    "solid": {"density": False, "youngs_modulus": False, "poisson_ratio": False,
              "restitution": False, "friction": False, "lubricated_friction": False,
              "roughness": False},
    "solid2": {"density": False, "youngs_modulus": False, "poisson_ratio": False,
               "restitution": False, "friction": False, "lubricated_friction": False,
               "roughness": False},
    "contact": {"model": False, "cutoff": False},
    "phases": {"viscous_on_rebound": False, "advancing_angle": False,
               "receding_angle": False, "rupture": False},
}
_TABLES = {k for k in _SCHEMA if k}
#: most gaps a case may ask for, as a list or as a ``{start, stop, points}`` table
MAX_GAPS = 100_000
#: longest case name; names become file stems (see :func:`wetcontact.fileio.safe_stem`)
MAX_NAME = 200
#: longest description or source text
MAX_TEXT = 100_000
#: smallest gap at any radius (m): a hundredth of the molecular scale (an atom is about
#: 1e-10 m, a water molecule 2.8e-10 m across). Below it a gap is no distance between two
#: surfaces; it is kept that far below the molecular scale so that a near-contact limit
#: stays expressible (the shipped calibrate-lian-rupture study evaluates rupture distances
#: at S/R = 1e-7 of a 50 um sphere, 5e-12 m), though no continuum model describes a gap
#: under about 1e-9 m
MIN_GAP = 1e-12
#: smallest gap relative to the radius, S/R: below it the gap is lost in the rounding of
#: the sphere's position (R + S keeps 7 of 16 digits of S) and the exact Stokes series need
#: more than 10^5 terms per gap (Brenner's at S/R = 1e-12 ran out of memory)
MIN_GAP_OVER_RADIUS = 1e-9


def min_gap(radius: float) -> float:
    """The smallest gap (m) a scene may ask for, ``radius`` (m) its smaller sphere's R_s:
    ``max(MIN_GAP, MIN_GAP_OVER_RADIUS R_s)`` = max(1e-12 m, 1e-9 R_s).

    A physical lower limit, relative to the molecular scale (:data:`MIN_GAP`) and to the
    radius (:data:`MIN_GAP_OVER_RADIUS`): gaps of 1e-300 m gave a viscous force of
    4.7e288 N, 1e-15 m ran Brenner's series out of memory and 5e-324 m gave NaNs. A film
    must be thicker than this smallest gap.
    """
    # R / 1e9, not R * 1e-9: correctly rounded, so that 1e-12 m at R = 1 mm is at the
    # limit, not an ulp below it (1e-3 * 1e-9 = 1.0000000000000002e-12)
    return max(MIN_GAP, float(radius) / round(1.0 / MIN_GAP_OVER_RADIUS))


@dataclass(frozen=True)
class Scene:
    """One wet contact: geometry, liquid, liquid amount and motion (SI units, radians).

    Attributes
    ----------
    name, description, source
        Identification and provenance of the numbers.
    kind
        ``"sphere-wall"`` or ``"sphere-sphere"``.
    radius, radius2
        Sphere radius R (m); second sphere radius (m, sphere-sphere only, else ``None``).
    viscosity, surface_tension, density
        Liquid eta (Pa s), sigma (N/m), rho (kg/m^3).
    contact_angle_sphere, contact_angle_wall
        Contact angle (rad) on the (first) sphere and on the wall, or on the second sphere
        for ``sphere-sphere``.
    slip_length_sphere, slip_length_wall
        Navier slip lengths b (m) on the sphere and on the wall (or second sphere).
    gravity
        Gravitational acceleration (m/s^2) acting along -z; 0 by default.
    amount
        ``"immersed"``, ``"film"`` or ``"bridge"``.
    film_thickness, bridge_volume
        delta (m) for a film, V (m^3) for a bridge; ``None`` otherwise.
    velocity
        Normal approach speed v (m/s), positive = approach.
    gaps
        Surface gaps S (m) to evaluate, in the order given.
    particle_density
        Density of the sphere (kg/m^3), for Stokes numbers and inertial runs; optional.
    tolerance, model
        Fidelity request: a relative tolerance, or a fixed model name (or neither).
    """

    name: str
    kind: Kind
    radius: float
    viscosity: float
    surface_tension: float
    density: float
    velocity: float
    gaps: tuple[float, ...]
    amount: AmountKind
    contact_angle_sphere: float = 0.0
    contact_angle_wall: float = 0.0
    radius2: float | None = None
    film_thickness: float | None = None
    bridge_volume: float | None = None
    slip_length_sphere: float = 0.0
    slip_length_wall: float = 0.0
    gravity: float = 0.0
    particle_density: float | None = None
    tolerance: float | None = None
    model: str | None = None
    description: str = ""
    source: str = ""
    origin: str = field(default="<dict>", compare=False)

    # ---- derived quantities -------------------------------------------------------
    @property
    def gap_array(self) -> np.ndarray:
        """Gaps S as a float array (m)."""
        return np.asarray(self.gaps, dtype=float)

    @property
    def reduced_radius(self) -> float:
        """R* of the Reynolds closure: R for a wall, R1 R2/(R1 + R2) for two spheres."""
        if self.kind == "sphere-wall":
            return self.radius
        assert self.radius2 is not None
        return self.radius * self.radius2 / (self.radius + self.radius2)

    @property
    def small_radius(self) -> float:
        """R_s: the sphere's radius on a wall, the smaller radius of a pair."""
        if self.kind == "sphere-wall":
            return self.radius
        assert self.radius2 is not None
        return min(self.radius, self.radius2)

    @property
    def willett_radius(self) -> float:
        """Derjaguin radius of the equal-sphere closures: 2 R1 R2/(R1 + R2), and 2 R for a
        wall (Willett et al. 2000; the sphere-plate limit R2 -> infinity)."""
        return 2.0 * self.reduced_radius if self.kind == "sphere-sphere" else 2.0 * self.radius

    @property
    def equal_spheres(self) -> bool:
        """True for two spheres of equal radius (relative difference < 1e-12)."""
        return self.kind == "sphere-sphere" and abs(self.radius2 - self.radius) <= (
            1e-12 * self.radius
        )

    def to_dict(self) -> dict[str, Any]:
        """Canonical dict (SI, radians), the input of the store's content hash."""
        d = asdict(self)
        d.pop("origin")
        d["gaps"] = list(self.gaps)
        return d

    def canonical_json(self) -> str:
        """Canonical JSON: sorted keys, floats at full precision (``repr``)."""
        return json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))

    def with_gaps(self, gaps: Any) -> Scene:
        """Copy with other gaps, validated like the case file's.

        Parameters
        ----------
        gaps
            Surface gaps S (m): a number, a sequence, a 1-D array or the table form
            ``{start, stop, points, spacing}``; each in [max(1e-12 m, 1e-9 R_s), 100 R]
            (:func:`min_gap`, R_s the smaller radius), at most 100 000, and
            for a film at least one below the film thickness (as ``load_case`` requires).

        Returns
        -------
        Scene
            The same scene on ``gaps``.

        Raises
        ------
        CaseError
            A gap outside its range, naming the scene's file and the gap.
        """
        new = _validate_gaps(self.origin, gaps, self.radius, self.small_radius)
        if self.film_thickness is not None:
            _check_film_reached(self.origin, self.film_thickness, new)
        return replace(self, gaps=new)

    @property
    def contact_angles_deg(self) -> tuple[float, float]:
        """The contact angles in degrees, as case files and flags give them: (on the first
        sphere, on the wall or the second sphere)."""
        return math.degrees(self.contact_angle_sphere), math.degrees(self.contact_angle_wall)

    def with_angles_deg(self, sphere: float | None = None, wall: float | None = None, *,
                        both: float | None = None) -> Scene:
        """Copy with other contact angles, given in degrees (the scene keeps radians).

        Every other place a user types an angle (case files, flags) takes degrees; this is
        the Python API's way to do the same instead of ``dataclasses.replace`` with
        radians. Also available as the function ``wetcontact.scene.with_angles_deg(scene,
        sphere=..., wall=...)``.

        Parameters
        ----------
        sphere
            Contact angle on the (first) sphere (deg, [0, 180)); ``None`` keeps it.
        wall
            Contact angle on the wall, or on the second sphere of a ``sphere-sphere`` scene
            (deg, [0, 180)); ``None`` keeps it.
        both
            One angle on both solids (deg), instead of ``sphere`` and ``wall``.

        Returns
        -------
        Scene
            The same scene with those angles (radians inside).

        Raises
        ------
        CaseError
            An angle outside [0, 180) degrees or not a number, or ``both`` with ``sphere``
            or ``wall``, naming the field as a case file would.
        """
        other = "contact_angle_wall" if self.kind == "sphere-wall" else "contact_angle_sphere2"
        if both is not None:
            if sphere is not None or wall is not None:
                raise CaseError(self.origin, "liquid.contact_angle", both,
                                "both= alone, or sphere= and wall=, not both")
            sphere = wall = both
        th_s = (self.contact_angle_sphere if sphere is None
                else _angle(self.origin, "liquid.contact_angle_sphere", sphere))
        th_w = (self.contact_angle_wall if wall is None
                else _angle(self.origin, f"liquid.{other}", wall))
        return replace(self, contact_angle_sphere=th_s, contact_angle_wall=th_w)



def with_angles_deg(scene: Scene, sphere: float | None = None, wall: float | None = None, *,
                    both: float | None = None) -> Scene:
    """``scene`` with other contact angles given in degrees: :meth:`Scene.with_angles_deg`."""
    return scene.with_angles_deg(sphere, wall, both=both)


# ---- reading ------------------------------------------------------------------------


def load_case(path: str | Path) -> Scene:
    """Read and validate a TOML case file.

    Parameters
    ----------
    path
        The case file (TOML, SI units, angles in degrees; fields and ranges in the README's
        "Case files").

    Returns
    -------
    Scene
        The validated, frozen scene (angles in radians inside).

    Raises
    ------
    CaseError
        For a missing file, anything but a regular file, a file over 10 MiB, TOML syntax
        error, nesting deeper than 32 levels, unknown key, missing field or a value outside
        its allowed range; the message names file, field, value and range (read by
        :func:`wetcontact.fileio.read_toml`).
    """
    from wetcontact.fileio import read_toml

    data = read_toml(path, "an existing TOML case file")
    return scene_from_dict(data, source=str(path))


def scene_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Scene:
    """Build and validate a :class:`Scene` from the nested dict of a case file.

    Parameters
    ----------
    data
        The case file's tables as nested dicts (``{"name": ..., "geometry": {...},
        "liquid": {...}, "amount": {...}, "motion": {...}}``); SI units, angles in degrees;
        numpy scalars are taken as the numbers they hold.
    source
        What error messages name as the file.

    Returns
    -------
    Scene

    Raises
    ------
    CaseError
        An unknown key, a missing field or a value outside its range (named with its
        allowed range).
    """
    _check_keys(source, data)
    g = data["geometry"]
    liq = data["liquid"]
    amt = data.get("amount", {})
    mot = data["motion"]
    fid = data.get("fidelity", {})
    part = data.get("particle", {})

    name = data["name"]
    if (not isinstance(name, str) or not name.strip() or len(name) > MAX_NAME
            or not name.isprintable()):
        raise CaseError(source, "name", name, f"a non-empty printable string of at most "
                        f"{MAX_NAME} characters")

    kind = g["kind"]
    if kind not in ("sphere-wall", "sphere-sphere"):
        raise CaseError(source, "geometry.kind", kind, "'sphere-wall' or 'sphere-sphere'")
    radius = _num(source, "geometry.radius", g["radius"], 1e-9, 10.0, "m")
    radius2 = None
    if kind == "sphere-sphere":
        if "radius2" not in g:
            radius2 = radius
        else:
            radius2 = _num(source, "geometry.radius2", g["radius2"], 1e-9, 10.0, "m")
    elif "radius2" in g:
        raise CaseError(source, "geometry.radius2", g["radius2"], "only with kind='sphere-sphere'")

    eta = _num(source, "liquid.viscosity", liq["viscosity"], 1e-7, 1e5, "Pa s")
    sigma = _num(source, "liquid.surface_tension", liq["surface_tension"], 1e-5, 10.0, "N/m")
    rho = _num(source, "liquid.density", liq["density"], 1e-3, 3e4, "kg/m3")
    gravity = _num(source, "liquid.gravity", liq.get("gravity", 0.0), 0.0, 1e3, "m/s2",
                   lo_open=False)
    th_s, th_w = _contact_angles(source, kind, liq)
    b_s = _num(source, "liquid.slip_length_sphere", liq.get("slip_length_sphere", 0.0), 0.0,
               radius, "m", lo_open=False)
    b_w = _num(source, "liquid.slip_length_wall", liq.get("slip_length_wall", 0.0), 0.0,
               radius, "m", lo_open=False)

    amounts = [k for k in ("film_thickness", "bridge_volume", "immersed") if k in amt]
    if "immersed" in amt and amt["immersed"] is not True:
        raise CaseError(source, "amount.immersed", amt["immersed"],
                        "true (omit the key for a film or a bridge)")
    if len(amounts) != 1:
        raise CaseError(source, "amount", sorted(amounts) if amounts else None,
                        "exactly one of film_thickness, bridge_volume, immersed = true")
    gaps = _validate_gaps(source, mot["gaps"], radius, min(radius, radius2 or radius))
    film = volume = None
    if amounts[0] == "film_thickness":
        if kind != "sphere-wall":
            raise CaseError(source, "amount.film_thickness", amt["film_thickness"],
                            "only with kind='sphere-wall' (a film lies on the wall)")
        film = _num(source, "amount.film_thickness", amt["film_thickness"], min_gap(radius),
                    10 * radius, "m")  # thicker than the smallest gap allowed
        _check_film_reached(source, film, gaps)
        amount: AmountKind = "film"
    elif amounts[0] == "bridge_volume":
        vmax = 4.0 / 3.0 * math.pi * radius**3
        volume = _num(source, "amount.bridge_volume", amt["bridge_volume"], 1e-30, vmax, "m3")
        amount = "bridge"
    else:
        amount = "immersed"

    v = _num(source, "motion.velocity", mot["velocity"], -1e3, 1e3, "m/s", lo_open=False)
    pdens = None
    if "density" in part:
        pdens = _num(source, "particle.density", part["density"], 1.0, 3e4, "kg/m3")
    tol = model = None
    if "tolerance" in fid and "model" in fid:
        raise CaseError(source, "fidelity", sorted(fid), "one of tolerance or model, not both")
    if "tolerance" in fid:
        lo, hi = TOLERANCE_RANGE
        tol = _num(source, "fidelity.tolerance", fid["tolerance"], lo, hi, "(relative)",
                   hi_open=True)
    if "model" in fid:
        model = fid["model"]
        if not isinstance(model, str) or not model:
            raise CaseError(source, "fidelity.model", model, "a registered model name")
    for key in ("description", "source"):
        if key in data and (not isinstance(data[key], str) or len(data[key]) > MAX_TEXT):
            raise CaseError(source, key, data[key], f"a string of at most {MAX_TEXT} characters")
    return Scene(
        name=name, kind=kind, radius=radius, radius2=radius2, viscosity=eta,
        surface_tension=sigma, density=rho, gravity=gravity, contact_angle_sphere=th_s,
        contact_angle_wall=th_w, slip_length_sphere=b_s, slip_length_wall=b_w,
        amount=amount, film_thickness=film, bridge_volume=volume, velocity=v, gaps=gaps,
        particle_density=pdens, tolerance=tol, model=model,
        description=data.get("description", ""), source=data.get("source", ""), origin=source,
    )


# ---- helpers ------------------------------------------------------------------------


def _check_keys(source: str, data: Mapping[str, Any]) -> None:
    if not isinstance(data, Mapping):
        raise CaseError(source, "(top level)", type(data).__name__, "a TOML table")
    for key, val in data.items():
        if key in _TABLES:
            if not isinstance(val, Mapping):
                raise CaseError(source, key, val, "a TOML table [" + key + "]")
            for sub in val:
                if sub not in _SCHEMA[key]:
                    raise CaseError(source, f"{key}.{sub}", val[sub],
                                    "known keys: " + ", ".join(_SCHEMA[key]))
        elif key not in _SCHEMA[""]:
            raise CaseError(source, key, val, "known top-level keys: "
                            + ", ".join(list(_SCHEMA[""]) + sorted(_TABLES)))
    for key, req in _SCHEMA[""].items():
        if req and key not in data:
            raise CaseError(source, key, None, "required")
    for table, keys in _SCHEMA.items():
        if not table:
            continue
        sub = data.get(table, {})
        for key, req in keys.items():
            if req and key not in sub:
                raise CaseError(source, f"{table}.{key}", None, "required")


TOLERANCE_RANGE = (1e-12, 1.0)
"""Open interval of a relative tolerance (case file ``fidelity.tolerance``, ``--tol``)."""


def _check_film_reached(source: str, film: float, gaps: tuple[float, ...]) -> None:
    """A film must be thicker than the smallest gap, else the sphere never touches it."""
    if film <= min(gaps):
        raise CaseError(source, "amount.film_thickness", film,
                        f"> the smallest gap {min(gaps):.6g} m (else the sphere never "
                        "touches the film)")


def plain_number(value: Any) -> Any:
    """A numpy integer or floating scalar (``np.float32(1e-3)``, ``np.int64(2)``) as the
    Python number it holds; anything else (a numpy bool included) as it is."""
    return value.item() if isinstance(value, np.integer | np.floating) else value


def _num(source: str, name: str, value: Any, lo: float, hi: float, unit: str,
         lo_open: bool = True, hi_open: bool = False) -> float:
    """Validate a finite real number in (lo, hi] (``[lo`` with ``lo_open=False``, ``hi)``
    with ``hi_open=True``); numpy scalars are taken as the numbers they hold."""
    value = plain_number(value)
    bracket = "(" if lo_open else "["
    allowed = f"a number in {bracket}{lo:g}, {hi:g}{')' if hi_open else ']'} {unit}".rstrip()
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise CaseError(source, name, value, allowed)
    try:
        x = float(value)
    except OverflowError:  # an integer beyond the float range
        raise CaseError(source, name, value, allowed) from None
    if not math.isfinite(x) or x > hi or x < lo or (lo_open and x == lo) or (
            hi_open and x == hi):
        raise CaseError(source, name, value, allowed)
    return x


def _angle(source: str, name: str, value: Any) -> float:
    value = plain_number(value)
    if isinstance(value, bool) or not isinstance(value, int | float) or not (
        0.0 <= value < 180.0  # False for NaN; exact for any int, however large
    ):
        raise CaseError(source, name, value, "a number in [0, 180) degrees")
    return math.radians(float(value))


def _contact_angles(source: str, kind: str, liq: Mapping[str, Any]) -> tuple[float, float]:
    other = "contact_angle_wall" if kind == "sphere-wall" else "contact_angle_sphere2"
    wrong = "contact_angle_sphere2" if kind == "sphere-wall" else "contact_angle_wall"
    if wrong in liq:
        raise CaseError(source, f"liquid.{wrong}", liq[wrong], f"not with kind='{kind}'; use "
                        f"liquid.{other}")
    if "contact_angle" in liq:
        for k in ("contact_angle_sphere", other):
            if k in liq:
                raise CaseError(source, f"liquid.{k}", liq[k],
                                "either contact_angle or the per-surface angles, not both")
        th = _angle(source, "liquid.contact_angle", liq["contact_angle"])
        return th, th
    if "contact_angle_sphere" not in liq and other not in liq:
        return 0.0, 0.0
    for k in ("contact_angle_sphere", other):
        if k not in liq:
            raise CaseError(source, f"liquid.{k}", None,
                            "required when the other per-surface contact angle is given")
    return (_angle(source, "liquid.contact_angle_sphere", liq["contact_angle_sphere"]),
            _angle(source, f"liquid.{other}", liq[other]))


def _validate_gaps(source: str, gaps: Any, radius: float, small: float
                   ) -> tuple[float, ...]:
    """Gaps from a list or a ``{start, stop, points, spacing}`` table; each in
    [max(1e-12 m, 1e-9 R_s), 100 R] (:func:`min_gap`: a physical lower limit; R the
    first radius, R_s = ``small`` the smaller one)."""
    lo, hi = min_gap(small), 100 * radius
    allowed = f"each gap in [{lo:g}, {hi:g}] m (max(1e-12 m, 1e-9 R_s) <= S <= 100 R)"
    if isinstance(gaps, Mapping):
        for k in gaps:
            if k not in ("start", "stop", "points", "spacing"):
                raise CaseError(source, f"motion.gaps.{k}", gaps[k],
                                "keys start, stop, points, spacing")
        for k in ("start", "stop", "points"):
            if k not in gaps:
                raise CaseError(source, f"motion.gaps.{k}", None, "required")
        start = _gap(source, "motion.gaps.start", gaps["start"], lo, hi)
        stop = _gap(source, "motion.gaps.stop", gaps["stop"], lo, hi)
        n = gaps["points"]
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_GAPS:
            raise CaseError(source, "motion.gaps.points", n, f"an integer in [1, {MAX_GAPS}]")
        spacing = gaps.get("spacing", "log")
        if spacing == "log":
            arr = np.geomspace(start, stop, n)
        elif spacing == "linear":
            arr = np.linspace(start, stop, n)
        else:
            raise CaseError(source, "motion.gaps.spacing", spacing, "'log' or 'linear'")
        return tuple(float(x) for x in arr)
    if isinstance(gaps, np.ndarray) and gaps.ndim != 1:
        raise CaseError(source, "motion.gaps", f"an array of shape {gaps.shape}",
                        "a 1-D list of gaps")
    if isinstance(gaps, list | tuple | np.ndarray):
        if not 1 <= len(gaps) <= MAX_GAPS:  # before touching an entry: cheap for any size
            raise CaseError(source, "motion.gaps", f"a list of {len(gaps)} gaps",
                            f"a list of 1 to {MAX_GAPS} gaps (as for points in the table form)")
        out = []
        for i, s in enumerate(gaps):
            out.append(_gap(source, f"motion.gaps[{i}]", s, lo, hi))
        return tuple(out)
    gaps = plain_number(gaps)
    if isinstance(gaps, int | float) and not isinstance(gaps, bool):
        return (_gap(source, "motion.gaps", gaps, lo, hi),)
    raise CaseError(source, "motion.gaps", gaps, "a list of gaps or {start, stop, points, "
                    "spacing}; " + allowed)


def _gap(source: str, name: str, value: Any, lo: float, hi: float) -> float:
    """One gap (or a gap range's end) in [lo, hi] m, saying where the lower limit is from."""
    try:
        return _num(source, name, value, lo, hi, "m", lo_open=False)
    except CaseError as exc:
        raise CaseError(source, name, exc.value, f"{exc.allowed} (the lower limit, "
                        "max(1e-12 m, 1e-9 R_s), is below the molecular scale)") from None
