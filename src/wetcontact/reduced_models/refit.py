"""Refitted closure families (level 0): each family's form, published coefficients, scene
class and calibrated domain (:class:`Family`, :data:`FAMILIES`), and a refit read back from
its calibration file as a model (:func:`load_coefficients`, :class:`CalibratedClosure`). The
fit that writes those files is :mod:`wetcontact.calibrate`.

Families (the published coefficients are the starting point of a refit):

``mikami-pw``, ``mikami-pp``
    ``F = pi R sigma (exp(A S/R + B) + C)`` (Mikami, Kamiya & Horio 1998), 8 coefficients.
``willett``
    ``ln F* = f1 - f2 exp(f3 ln S+ + f4 ln^2 S+)``, f_i quadratic in theta and cubic in
    ln V* (Willett et al. 2000, eq. A1), 48 coefficients (the published ones are 43 of
    them; the other 5 start at 0).
``bagheri``
    Bagheri, Roy & Poeschel (2024) eqs. 24-30, 23 coefficients.
``lian-rupture``
    ``S_c/R = (a + b theta) V*^(1/3) + c V*^(2/3)`` (Lian et al. 1993: a = 1, b = 1/2, c = 0).
``finite-liquid`` (films), ``finite-liquid-bridge-sw`` / ``-ss`` (bridges)
    Reynolds force times a factor replacing Pitois' ``(1 - S/H)^2``
    (:func:`~wetcontact.reduced_models.forms.finite_liquid_form`, 10 coefficients).

A refit answers inside its calibrated domain only: a scene outside it on a scene axis
(volume, contact angle, film thickness, radius ratio) is refused, a gap outside it on a gap
axis (:data:`GAP_AXES`) is answered by NaN; a file whose domain claims more than
:data:`DOMAIN_LIMITS` allows is refused when read.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import InputError, ValidityError
from wetcontact.models import ForceCurve, Model
from wetcontact.reduced_models import capillary as cap
from wetcontact.reduced_models import rupture as rup
from wetcontact.reduced_models import viscous as visc
from wetcontact.reduced_models.forms import (
    BAGHERI_LABELS,
    BAGHERI_PUBLISHED,
    FINITE_LIQUID_LABELS,
    LIAN_LABELS,
    MIKAMI_LABELS,
    WILLETT_LABELS,
    WILLETT_PUBLISHED,
    Arrays,
    FormLabels,
    bagheri_form,
    finite_liquid_form,
    lian_form,
    mikami_form,
    willett_form,
)
from wetcontact.scene import Scene

# ---- families ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Family:
    """A closure family: its form, published coefficients, scene class and domain axes.

    Attributes
    ----------
    name, description
        Family key and one line.
    form
        ``form(coefficients, inputs) -> predicted value`` (positive magnitude).
    published
        Published coefficients (the starting point and the "before" of the table).
    kind, amount
        Scene class (``equal`` True: equal spheres only).
    target
        ``"capillary"`` (attraction magnitude), ``"rupture"`` (S_c) or ``"viscous"``.
    domain_axes
        Coordinates whose training range is the calibrated domain.
    default_design
        Ranges of the design variables: name -> (lo, hi, "log" | "lin").
    equal
        Equal spheres only.
    rupture_of
        The family's own rupture distance (m) of inputs, the ``s_over_sc`` axis' S_c.
    labels
        The form's formula and each coefficient's name and term, in the order of the
        coefficients (written in a calibration file, :func:`labelled_coefficients`).
    """

    name: str
    description: str
    form: Callable[[np.ndarray, Arrays], np.ndarray]
    published: np.ndarray
    kind: str
    amount: str
    target: str
    domain_axes: tuple[str, ...]
    default_design: Mapping[str, tuple[float, float, str]]
    equal: bool = False
    rupture_of: Callable[[Arrays], np.ndarray] | None = None
    labels: FormLabels | None = None


def _mikami_sc_pw(x: Arrays) -> np.ndarray:
    return rup.mikami_rupture_distance_pw(x["volume"], x["r_closure"], x["theta"])


def _mikami_sc_pp(x: Arrays) -> np.ndarray:
    return rup.mikami_rupture_distance_pp(x["volume"], x["r_closure"], x["theta"])


def _willett_sc(x: Arrays) -> np.ndarray:
    return rup.willett_rupture_distance(x["volume"], x["r_closure"], x["theta"])


_CAP_DESIGN = {"v_star": (1e-4, 0.1, "log"), "theta_deg": (0.0, 50.0, "lin"),
               "s_over_scref": (0.01, 0.95, "lin")}

FAMILIES: dict[str, Family] = {f.name: f for f in (
    Family("mikami-pw", "Mikami et al. (1998) particle-wall force", mikami_form,
           np.array(cap._MIKAMI_PW), "sphere-wall", "bridge", "capillary",
           ("v_star", "theta_deg", "s_over_sc"), _CAP_DESIGN, rupture_of=_mikami_sc_pw,
           labels=MIKAMI_LABELS),
    Family("mikami-pp", "Mikami et al. (1998) particle-particle force", mikami_form,
           np.array(cap._MIKAMI_PP), "sphere-sphere", "bridge", "capillary",
           ("v_star", "theta_deg", "s_over_sc"), _CAP_DESIGN, equal=True,
           rupture_of=_mikami_sc_pp, labels=MIKAMI_LABELS),
    Family("willett", "Willett et al. (2000) full fit", willett_form,
           WILLETT_PUBLISHED.ravel(), "sphere-sphere", "bridge", "capillary",
           ("v_star", "theta_deg", "s_over_sc"), _CAP_DESIGN, equal=True,
           rupture_of=_willett_sc, labels=WILLETT_LABELS),
    Family("bagheri", "Bagheri, Roy & Poeschel (2024)", bagheri_form, BAGHERI_PUBLISHED,
           "sphere-sphere", "bridge", "capillary", ("v_star", "theta_deg", "s_over_sc"),
           _CAP_DESIGN, equal=True, rupture_of=_willett_sc, labels=BAGHERI_LABELS),
    Family("lian-rupture", "Lian et al. (1993) rupture distance", lian_form,
           np.array([1.0, 0.5, 0.0]), "sphere-sphere", "bridge", "rupture",
           ("v_star", "theta_deg"), {"v_star": (1e-4, 0.1, "log"),
                                      "theta_deg": (0.0, 50.0, "lin")}, equal=True,
           labels=LIAN_LABELS),
    Family("finite-liquid", "finite-liquid factor replacing (1 - S/H)^2 (films)",
           finite_liquid_form, np.array([2.0] + [0.0] * 9), "sphere-wall", "film",
           "viscous", ("delta_over_r", "s_over_h"),
           {"delta_over_r": (1e-3, 0.1, "log"), "s_over_h": (0.01, 0.95, "lin")},
           labels=FINITE_LIQUID_LABELS),
    Family("finite-liquid-bridge-sw", "finite-liquid factor, bridge on a wall",
           finite_liquid_form, np.array([2.0] + [0.0] * 9), "sphere-wall",
           "bridge", "viscous", ("v_star", "s_over_h"),
           {"v_star": (1e-4, 0.1, "log"), "s_over_h": (0.01, 0.95, "lin")},
           labels=FINITE_LIQUID_LABELS),
    Family("finite-liquid-bridge-ss", "finite-liquid factor, bridge between two spheres",
           finite_liquid_form, np.array([2.0] + [0.0] * 9), "sphere-sphere",
           "bridge", "viscous", ("v_star", "s_over_h", "radius_ratio"),
           {"v_star": (1e-4, 0.1, "log"), "radius_ratio": (1.0, 10.0, "log"),
            "s_over_h": (0.01, 0.95, "lin")}, labels=FINITE_LIQUID_LABELS),
)}


def get_family(name: str) -> Family:
    """Family by name; an :class:`InputError` listing the names otherwise."""
    if name not in FAMILIES:
        raise InputError(f"closure family = {name!r}; allowed: " + ", ".join(FAMILIES))
    return FAMILIES[name]


def scene_inputs(family: Family, scene: Scene) -> dict[str, np.ndarray]:
    """Per-gap inputs of ``family`` for ``scene`` (the same the fit used)."""
    g = scene.gap_array
    full = lambda v: np.full(g.shape, float(v))  # noqa: E731
    x = {"gap": g, "radius": full(scene.radius), "sigma": full(scene.surface_tension),
         "viscosity": full(scene.viscosity), "velocity": full(scene.velocity),
         "r_star": full(scene.reduced_radius)}
    x["kappa"] = full(1.0)
    if scene.kind == "sphere-sphere":
        x["kappa"] = full(scene.reduced_radius**3 * (scene.radius**-3 + scene.radius2**-3))
        x["r_small"] = full(min(scene.radius, scene.radius2))
        x["radius_ratio"] = full(max(scene.radius, scene.radius2) / min(scene.radius,
                                                                       scene.radius2))
    else:
        x["r_small"] = full(scene.radius)
        x["radius_ratio"] = full(1.0)
    if scene.amount == "bridge":
        x["edge_gap"] = visc.bridge_edge_gap(g, scene.bridge_volume, scene.reduced_radius)
        th = cap.mean_contact_angle(scene.contact_angle_sphere, scene.contact_angle_wall)
        x["theta"] = full(th)
        x["volume"] = full(scene.bridge_volume)
        rc = scene.radius if (family.name == "mikami-pw" or family.target == "rupture") \
            else scene.willett_radius
        x["r_closure"] = full(rc)
    if scene.amount == "film":
        x["edge_gap"] = full(scene.film_thickness)
    return x


def domain_coords(family: Family, x: Arrays) -> dict[str, np.ndarray]:
    """The family's domain coordinates of inputs ``x``."""
    c: dict[str, np.ndarray] = {"radius_ratio": x["radius_ratio"]}
    if "volume" in x:
        c["v_star"] = x["volume"] / x["r_small"] ** 3
        c["theta_deg"] = np.degrees(x["theta"])
        if family.rupture_of is not None:
            c["s_over_sc"] = x["gap"] / family.rupture_of(x)
    if "edge_gap" in x:
        c["s_over_h"] = x["gap"] / x["edge_gap"]
        if "volume" not in x:
            c["delta_over_r"] = x["edge_gap"] / x["radius"]
    return c


# ---- refitted closures as models -----------------------------------------------------------


GAP_AXES = frozenset({"s_over_sc", "s_over_h"})
"""Domain axes that vary along a curve (the gap's): a gap outside the calibrated range on one
of them is answered by NaN at that gap (:class:`CalibratedClosure`); the other axes (volume,
angle, film thickness, radius ratio) are the scene's, and a scene outside refuses."""


class CalibratedClosure(Model):
    """A family with refitted coefficients, answering per gap inside its calibrated domain.

    A scene outside the domain on a scene axis (volume, contact angle, film thickness, radius
    ratio), of another geometry or liquid amount, or with every gap outside it, is refused
    (:class:`~wetcontact.errors.ValidityError`). A scene with some gaps outside on a gap axis
    (:data:`GAP_AXES`: ``s_over_sc``, ``s_over_h``) gets NaN at those gaps and
    ``diagnostics["outside_domain"]`` saying how many and why (``wetcontact solve`` prints
    it as a warning).
    """

    level = 0

    def __init__(self, family: Family, coefficients: np.ndarray,
                 domain: Mapping[str, tuple[float, float]], source: str):
        self.family, self.k, self.domain, self.source = family, coefficients, domain, source
        self.name = f"{family.name}@{Path(source).name}"  # type: ignore[misc]
        self.component = "viscous" if family.target == "viscous" else "capillary"  # type: ignore[misc]
        self.validity = "calibrated domain " + ", ".join(  # type: ignore[misc]
            f"{k} in [{lo:.4g}, {hi:.4g}]" for k, (lo, hi) in domain.items())
        self.reference = f"{family.description}, refitted ({source})"  # type: ignore[misc]

    def _refuse(self, why: str) -> ValidityError:
        return ValidityError(self.name, why, "meniscus" if self.family.amount == "bridge"
                             else "lubrication")

    def outside(self, scene: Scene) -> tuple[np.ndarray, list[str]]:
        """The gaps of ``scene`` outside the calibrated domain on a gap axis.

        Parameters
        ----------
        scene
            A scene of the family's class, inside the domain on the scene axes
            (:meth:`check` refuses the others).

        Returns
        -------
        mask : numpy.ndarray
            True at the gaps outside, shape of ``scene.gap_array``.
        reasons : list of str
            Per axis with gaps outside, the range of their values against the calibrated
            range (empty when no gap is outside).
        """
        coords = domain_coords(self.family, scene_inputs(self.family, scene))
        mask = np.zeros(scene.gap_array.shape, dtype=bool)
        reasons = []
        for k, (lo, hi) in self.domain.items():
            if k not in GAP_AXES:
                continue
            v = coords[k]
            bad = _beyond(v, lo, hi)
            if np.any(bad):
                reasons.append(f"{k} = {float(v[bad].min()):.4g} to {float(v[bad].max()):.4g} "
                               f"outside [{lo:.4g}, {hi:.4g}]")
            mask |= bad
        return mask, reasons

    def check(self, scene: Scene) -> None:
        fam = self.family
        if scene.kind != fam.kind or scene.amount != fam.amount or (
                fam.equal and not scene.equal_spheres):
            raise self._refuse(f"calibrated for {fam.kind} {fam.amount}"
                               + (" (equal spheres)" if fam.equal else ""))
        coords = domain_coords(fam, scene_inputs(fam, scene))
        for k, (lo, hi) in self.domain.items():
            if k in GAP_AXES:  # per gap: NaN there (_force), unless every gap is outside
                continue
            v = coords[k]
            bad = _beyond(v, lo, hi)
            if np.any(bad):
                raise self._refuse(f"{k} = {float(v[bad][0]):.4g} outside the calibrated "
                                   f"domain [{lo:.4g}, {hi:.4g}] ({self.source})")
        mask, reasons = self.outside(scene)
        if np.all(mask):
            raise self._refuse(f"every gap outside the calibrated domain ({'; '.join(reasons)};"
                               f" {self.source})")

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
        out_mask, reasons = self.outside(scene)
        full_gap = scene.gap_array
        if np.any(out_mask):  # the form evaluated at the gaps inside only
            scene = scene.with_gaps([float(g) for g in full_gap[~out_mask]])
        x = scene_inputs(self.family, scene)
        gap = scene.gap_array
        try:  # absurd coefficients (a file edited by hand) overflow: refused, not printed
            with np.errstate(over="raise", invalid="raise"):
                val = np.asarray(self.family.form(self.k, x), dtype=float)
            ok = bool(np.all(np.isfinite(val)))
        except FloatingPointError:
            ok = False
        if not ok:
            raise InputError(f"{self.source}: the coefficients overflow the {self.family.name} "
                             f"form on case '{scene.name}' (a non-finite intermediate); "
                             "allowed: coefficients written by wetcontact calibrate")
        # the form's sign: a squeeze force along the velocity, an attraction (inside the
        # domain, s/S_c < 1: never 0, which is an exp underflowed), a positive rupture
        # distance; coefficients that break it are refused, not printed
        wrong = (val * math.copysign(1.0, scene.velocity) < 0 if self.family.target == "viscous"
                 else val <= 0)
        if np.any(wrong):
            i = int(np.argmax(wrong))
            what = {"viscous": "a viscous force against the motion", "capillary":
                    "a capillary force that is not an attraction (repulsive or 0)",
                    "rupture": "a rupture distance <= 0"}
            raise InputError(f"{self.source}: the coefficients give {what[self.family.target]}"
                             f" ({float(val[i]):.4g} at gap {float(gap[i]):.4g} m, case "
                             f"'{scene.name}'); allowed: coefficients whose {self.family.name} "
                             "form keeps its sign over the domain")
        diagnostics: dict[str, Any] = {}
        if np.any(out_mask):
            filled = np.full(full_gap.shape, np.nan)
            filled[~out_mask] = val
            val, gap = filled, full_gap
            diagnostics["outside_domain"] = (
                f"{int(out_mask.sum())} of {out_mask.size} gaps outside the calibrated domain "
                f"({'; '.join(reasons)}; {self.source}): NaN there")
        if self.family.target == "viscous":
            return ForceCurve(case=scene.name, model=self.name, gap=gap, force_viscous=val,
                              force_capillary=None, diagnostics=diagnostics)
        if self.family.target == "rupture":  # a rupture distance, no force: both None
            return ForceCurve(case=scene.name, model=self.name, gap=gap, force_viscous=None,
                              force_capillary=None, extras={"rupture_distance": val},
                              diagnostics=diagnostics)
        return ForceCurve(case=scene.name, model=self.name, gap=gap, force_viscous=None,
                          force_capillary=-val, diagnostics=diagnostics)


def _beyond(v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """True where ``v`` is outside ``[lo, hi]`` beyond rounding (the fit's own points are
    inside)."""
    return (v < lo * (1 - 1e-9) - 1e-12) | (v > hi * (1 + 1e-9))


def _finite_numbers(path: Path, field: str, value: Any, size: int | None = None
                    ) -> np.ndarray:
    """``value`` as an array of finite numbers (JSON numbers, not booleans), or an
    :class:`InputError` naming the file, the field, the entry and what is allowed."""
    want = f"a list of {size} finite numbers" if size else "a list of finite numbers"
    if not isinstance(value, list) or (size is not None and len(value) != size):
        raise InputError(f"{path}: field '{field}' = {_short(value)}; allowed: {want}")
    for i, x in enumerate(value):
        try:
            ok = not isinstance(x, bool) and isinstance(x, int | float) and math.isfinite(x)
        except OverflowError:  # an integer beyond the float range
            ok = False
        if not ok:
            raise InputError(f"{path}: field '{field}'[{i}] = {_short(x)}; allowed: a "
                             "finite number")
    return np.asarray(value, dtype=float)


def _short(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."


def load_coefficients(path: Path | str, family: str | None = None) -> CalibratedClosure:
    """A :class:`CalibratedClosure` from a calibration JSON (``family`` must match).

    The file is read by :func:`wetcontact.fileio.read_input`: a regular file of at most
    10 MiB (a FIFO, a device or a folder is refused before it is read).
    """
    from wetcontact.fileio import read_input

    path = Path(path)
    raw = read_input(path, "an existing calibration JSON written by wetcontact calibrate",
                     "a calibration JSON written by wetcontact calibrate")
    try:
        data = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:  # a PNG or other binary file given by mistake
        raise InputError(f"{path}: not a UTF-8 text file; allowed: a calibration JSON "
                         "written by wetcontact calibrate") from None
    except ValueError as exc:  # not JSON, or an integer of more than 4300 digits
        raise InputError(f"{path}: cannot read the coefficients ({exc})") from None
    except RecursionError:
        raise InputError(f"{path}: JSON nested too deep; allowed: a calibration JSON written "
                         "by wetcontact calibrate") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: a JSON {type(data).__name__}; allowed: an object written "
                         "by wetcontact calibrate")
    for key in ("family", "coefficients", "domain"):
        if key not in data:
            raise InputError(f"{path}: field '{key}' missing; allowed: a file written by "
                             "wetcontact calibrate")
    try:
        fam = get_family(data["family"] if isinstance(data["family"], str)
                         else repr(data["family"]))
    except InputError as exc:
        raise InputError(f"{path}: field 'family': {exc}") from None
    if family is not None and family != fam.name:
        raise InputError(f"{path}: family = {fam.name!r}, but --model {family!r}; allowed: "
                         f"--model {fam.name} (the family the file was fitted for)")
    for key, want in (("kind", fam.kind), ("amount", fam.amount), ("target", fam.target),
                      ("equal_spheres", fam.equal)):
        if key in data and data[key] != want:
            raise InputError(f"{path}: field '{key}' = {data[key]!r}; allowed: {want!r} "
                             f"(family {fam.name})")
    k = _finite_numbers(path, "coefficients", data["coefficients"])
    if k.shape != fam.published.shape:
        raise InputError(f"{path}: field 'coefficients' has {k.size} values; allowed: "
                         f"{fam.published.size} for family {fam.name}")
    dom_in = data["domain"]
    want = set(fam.domain_axes)
    if not isinstance(dom_in, dict) or set(dom_in) != want:
        got = sorted(dom_in) if isinstance(dom_in, dict) else dom_in
        raise InputError(f"{path}: field 'domain' = {got!r}; allowed: an object with the "
                         f"ranges of {', '.join(fam.domain_axes)} (family {fam.name})")
    dom = {}
    for a in fam.domain_axes:
        lo, hi = _finite_numbers(path, f"domain.{a}", dom_in[a], size=2)
        if not lo <= hi:
            raise InputError(f"{path}: field 'domain.{a}' = [{lo:g}, {hi:g}]; allowed: "
                             "[low, high] with low <= high")
        a_lo, a_hi, open_lo, what = DOMAIN_LIMITS[a]
        if not ((lo > a_lo if open_lo else lo >= a_lo) and hi <= a_hi):
            raise InputError(f"{path}: field 'domain.{a}' = [{lo:g}, {hi:g}]; allowed: within "
                             f"{'(' if open_lo else '['}{a_lo:g}, {a_hi:g}] ({what}; family "
                             f"{fam.name})")
        dom[a] = (float(lo), float(hi))
    return CalibratedClosure(fam, k, dom, str(path))


DOMAIN_LIMITS: dict[str, tuple[float, float, bool, str]] = {
    "v_star": (0.0, 1.0, True, "a bridge at most as large as the sphere, as the built-in "
               "closures accept"),
    "theta_deg": (0.0, 90.0, False, "a wetting contact angle in degrees"),
    "s_over_sc": (0.0, 1.5, False, "from contact to the rupture distance, measured with "
                  "the family's own S_c, which the reference bridge may outlast (mikami-pp's "
                  "training reached 1.026)"),
    "s_over_h": (0.0, 1.0, False, "from contact to the liquid's edge gap"),
    "delta_over_r": (0.0, 1.0, True, "a film at most as thick as the sphere's radius"),
    "radius_ratio": (1.0, 10.0, False, "the radius ratios the bridge models take"),
}
"""The widest range a coefficient file's ``domain`` may claim on each axis: (low, high,
low excluded, why). A file claiming more would let the refit answer, unflagged, where no
closure of its form applies (a hand-edited file, an input-fuzzing audit)."""
