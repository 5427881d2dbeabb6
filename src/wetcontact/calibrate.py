"""Calibration: refit a closure family's coefficients to reference points.

The core works on arrays of reference points (:class:`Points`: per-point inputs and the
reference value), however they were computed: directly through
``get_model(name).force(scene)`` (:func:`reference_points`) or from a sweep's store.
:func:`calibrate` trains on a grid, reports on a seeded held-out design the fit never saw
(maximum, mean and 95th percentile of the relative error before and after, and where the
maximum sits), and writes the coefficients with the domain they are valid on
(:func:`write_calibration`), a parity plot and an error map beside the JSON.

Families (:data:`FAMILIES`; the published coefficients are the starting point):

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
    (:func:`finite_liquid_form`, 10 coefficients).

The fit minimises the relative error by least squares, then by Lawson's reweighting
toward the minimax solution (scipy.optimize.least_squares), then (up to 50 coefficients)
polishes the maximum directly in epigraph form (SLSQP; Willett's 48: 4.3 -> 4.1 %).

``wetcontact calibrate STUDY.toml --closure FAMILY --out F.json`` (:func:`calibrate_study`)
fits a family to a study's reference points from the store (swept first when missing) and
reports on a seeded Latin-hypercube held-out design over the study's ranges; the capillary
families' studies are ``cases/studies/calibrate-*.toml``.
``python -m wetcontact.calibrate bounds`` regenerates the closures' measured error-bound
tables (:mod:`wetcontact.bounds_gen`); ``python -m wetcontact.calibrate fit FAMILY --out
F.json`` calibrates one family on its default design.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import InputError, SolverError, ValidityError
from wetcontact.models import ForceCurve, Model, get_model
from wetcontact.reduced_models import DATA_DIR
from wetcontact.reduced_models import calibrated_capillary as cc
from wetcontact.reduced_models import capillary as cap
from wetcontact.reduced_models import rupture as rup
from wetcontact.reduced_models import viscous as visc
from wetcontact.reduced_models.calibrated import FILM_D, FILM_X, film_coords, film_point
from wetcontact.reduced_models.forms import (
    BAGHERI_PUBLISHED,
    WILLETT_PUBLISHED,
    Arrays,
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
           ("v_star", "theta_deg", "s_over_sc"), _CAP_DESIGN, rupture_of=_mikami_sc_pw),
    Family("mikami-pp", "Mikami et al. (1998) particle-particle force", mikami_form,
           np.array(cap._MIKAMI_PP), "sphere-sphere", "bridge", "capillary",
           ("v_star", "theta_deg", "s_over_sc"), _CAP_DESIGN, equal=True,
           rupture_of=_mikami_sc_pp),
    Family("willett", "Willett et al. (2000) full fit", willett_form,
           WILLETT_PUBLISHED.ravel(), "sphere-sphere", "bridge", "capillary",
           ("v_star", "theta_deg", "s_over_sc"), _CAP_DESIGN, equal=True,
           rupture_of=_willett_sc),
    Family("bagheri", "Bagheri, Roy & Poeschel (2024)", bagheri_form, BAGHERI_PUBLISHED,
           "sphere-sphere", "bridge", "capillary", ("v_star", "theta_deg", "s_over_sc"),
           _CAP_DESIGN, equal=True, rupture_of=_willett_sc),
    Family("lian-rupture", "Lian et al. (1993) rupture distance", lian_form,
           np.array([1.0, 0.5, 0.0]), "sphere-sphere", "bridge", "rupture",
           ("v_star", "theta_deg"), {"v_star": (1e-4, 0.1, "log"),
                                      "theta_deg": (0.0, 50.0, "lin")}, equal=True),
    Family("finite-liquid", "finite-liquid factor replacing (1 - S/H)^2 (films)",
           finite_liquid_form, np.array([2.0] + [0.0] * 9), "sphere-wall", "film",
           "viscous", ("delta_over_r", "s_over_h"),
           {"delta_over_r": (1e-3, 0.1, "log"), "s_over_h": (0.01, 0.95, "lin")}),
    Family("finite-liquid-bridge-sw", "finite-liquid factor, bridge on a wall",
           finite_liquid_form, np.array([2.0] + [0.0] * 9), "sphere-wall",
           "bridge", "viscous", ("v_star", "s_over_h"),
           {"v_star": (1e-4, 0.1, "log"), "s_over_h": (0.01, 0.95, "lin")}),
    Family("finite-liquid-bridge-ss", "finite-liquid factor, bridge between two spheres",
           finite_liquid_form, np.array([2.0] + [0.0] * 9), "sphere-sphere",
           "bridge", "viscous", ("v_star", "s_over_h", "radius_ratio"),
           {"v_star": (1e-4, 0.1, "log"), "radius_ratio": (1.0, 10.0, "log"),
            "s_over_h": (0.01, 0.95, "lin")}),
)}


def get_family(name: str) -> Family:
    """Family by name; an :class:`InputError` listing the names otherwise."""
    if name not in FAMILIES:
        raise InputError(f"closure family = {name!r}; allowed: " + ", ".join(FAMILIES))
    return FAMILIES[name]


# ---- reference points --------------------------------------------------------------------


@dataclass(frozen=True)
class Points:
    """Reference points: inputs per point (SI, radians) and the reference value ``y``."""

    inputs: dict[str, np.ndarray]
    y: np.ndarray

    def __len__(self) -> int:
        return int(self.y.size)

    def subset(self, mask: np.ndarray) -> Points:
        return Points({k: v[mask] for k, v in self.inputs.items()}, self.y[mask])


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


def design(family: Family, n: int, seed: int | None = None) -> list[dict[str, float]]:
    """Configurations: a full grid (``seed`` None, about ``n`` points) or ``n`` seeded
    random points (the held-out design), over the family's design ranges (the gap axis,
    ``s_over_*``, is drawn per configuration by :func:`reference_points`)."""
    axes = {k: v for k, v in family.default_design.items() if not k.startswith("s_over")}
    if seed is None:
        m = max(2, round(n ** (1 / len(axes))))
        grids = [(_grid(lo, hi, sp, m), name) for name, (lo, hi, sp) in axes.items()]
        mesh = np.meshgrid(*[g for g, _ in grids], indexing="ij")
        return [{name: float(a.ravel()[i]) for (_, name), a in zip(grids, mesh, strict=True)}
                for i in range(mesh[0].size)]
    rng = np.random.default_rng(seed)
    return [{name: float(_draw(rng, lo, hi, sp)) for name, (lo, hi, sp) in axes.items()}
            for _ in range(n)]


def _grid(lo: float, hi: float, spacing: str, m: int) -> np.ndarray:
    return np.geomspace(lo, hi, m) if spacing == "log" else np.linspace(lo, hi, m)


def _draw(rng: np.random.Generator, lo: float, hi: float, spacing: str) -> float:
    if spacing == "log":
        return math.exp(rng.uniform(math.log(lo), math.log(hi)))
    return rng.uniform(lo, hi)


_RAW: dict[tuple, list[tuple[Scene, np.ndarray]]] = {}


def reference_points(family: Family, configs: list[dict[str, float]], gaps_per: int = 8,
                     seed: int | None = None, preset: str = "default") -> Points:
    """Reference values at ``configs`` computed by the reference model (``meniscus`` for
    capillary families, ``lubrication`` at 256 cells for viscous ones). Families of one
    scene class share the computed references within a process."""
    key = (family.kind, family.amount, family.target, json.dumps(configs), gaps_per, seed,
           preset, tuple(family.default_design.items()))
    if key not in _RAW:
        _RAW[key] = _references(family, configs, gaps_per, seed, preset)
    rows, ys = [], []
    for scene, y in _RAW[key]:
        x = scene_inputs(family, scene)
        keep = y > 0
        rows.append({k: v[keep] for k, v in x.items()})
        ys.append(y[keep])
    if not rows:
        raise SolverError(f"calibrate {family.name}: no reference point could be computed")
    return Points({k: np.concatenate([r[k] for r in rows]) for k in rows[0]},
                  np.concatenate(ys))


def _references(family: Family, configs: list[dict[str, float]], gaps_per: int,
                seed: int | None, preset: str) -> list[tuple[Scene, np.ndarray]]:
    from wetcontact.bounds_gen import R, make_scene

    rng = np.random.default_rng(seed)
    out = []
    s_lo, s_hi, _ = family.default_design.get("s_over_scref",
                                               family.default_design.get("s_over_h",
                                                                         (0.01, 0.95, "")))
    for c in configs:
        x_rel = (np.linspace(s_lo, s_hi, gaps_per) if seed is None
                 else np.sort(rng.uniform(s_lo, s_hi, gaps_per)))
        try:
            if family.amount == "bridge" and family.target == "viscous":
                ratio = c.get("radius_ratio", 1.0)
                r2 = R * ratio if family.kind == "sphere-sphere" else None
                rstar = R if r2 is None else R * r2 / (R + r2)
                v = c["v_star"] * R**3
                gaps = x_rel * np.sqrt(v / (math.pi * rstar)) / np.sqrt(1 - x_rel**2)
                scene = make_scene(family.kind, {"bridge_volume": v}, gaps, r2)
                out.append((scene, get_model("lubrication").force(scene, n=256, levels=3)
                            .force_viscous))
            elif family.amount == "bridge":
                th = c["theta_deg"]
                r2 = R if family.kind == "sphere-sphere" else None
                base = make_scene(family.kind, {"bridge_volume": c["v_star"] * R**3},
                                  [1e-7 * R], r2, (th, th), velocity=0.0)
                men = get_model("meniscus")
                sc = float(men.force(base, preset=preset).extras["rupture_distance"][0])
                if family.target == "rupture":
                    out.append((base, np.array([sc])))
                else:
                    scene = base.with_gaps((x_rel * sc).tolist())
                    out.append((scene, -men.force(scene, preset=preset).force_capillary))
            else:
                d = c["delta_over_r"]
                scene = make_scene("sphere-wall", {"film_thickness": d * R}, x_rel * d * R)
                out.append((scene, get_model("lubrication").force(scene, n=256, levels=3)
                            .force_viscous))
        except (InputError, SolverError):
            continue
    return out


def points_from_curves(family: Family, pairs: Iterable[tuple[Scene, ForceCurve]]) -> Points:
    """Reference points from solved curves, e.g. a sweep's outcomes
    (``(o.point.scene, o.curve) for o in result.outcomes if o.curve``): the attraction
    (capillary families), ``rupture_distance`` (rupture) or the viscous force, at the gaps
    where it is non-zero. Curves of another scene class are an :class:`InputError`."""
    rows, ys = [], []
    for scene, curve in pairs:
        if scene.kind != family.kind or scene.amount != family.amount or (
                family.equal and not scene.equal_spheres):
            raise InputError(f"calibrate {family.name}: scene '{scene.name}' is "
                             f"{scene.kind} {scene.amount}; allowed: {family.kind} "
                             f"{family.amount}" + (" (equal spheres)" if family.equal else ""))
        x = scene_inputs(family, scene)
        if family.target == "rupture":
            if "rupture_distance" not in curve.extras:
                raise InputError(f"calibrate {family.name}: model '{curve.model}' gives no "
                                 "rupture_distance")
            y = curve.extras["rupture_distance"][:1]
            x = {k: v[:1] for k, v in x.items()}
        else:
            f = curve.force_viscous if family.target == "viscous" else curve.force_capillary
            if f is None:
                raise InputError(f"calibrate {family.name}: model '{curve.model}' gives no "
                                 f"{family.target} force")
            y = f if family.target == "viscous" else -f
        keep = y > 0
        rows.append({k: v[keep] for k, v in x.items()})
        ys.append(np.asarray(y)[keep])
    if not rows or not sum(len(y) for y in ys):
        raise InputError(f"calibrate {family.name}: no reference point with a non-zero value")
    return Points({k: np.concatenate([r[k] for r in rows]) for k in rows[0]},
                  np.concatenate(ys))


# ---- fitting and reporting ---------------------------------------------------------------


def rel_errors(family: Family, k: np.ndarray, pts: Points) -> np.ndarray:
    """Relative error of the family with coefficients ``k`` at the points."""
    with np.errstate(all="ignore"):
        pred = family.form(k, pts.inputs)
    err = np.abs(pred / pts.y - 1.0)
    return np.where(np.isfinite(err), err, 1e3)


def fit(family: Family, train: Points, lawson_iterations: int = 12) -> np.ndarray:
    """Coefficients minimising the relative error on ``train``: least squares from the
    published values, then Lawson reweighting toward the minimax fit (best max kept).
    Each residual is held within +-1e3 (a non-finite one counts as 1e3): a trial step whose
    form overflows would otherwise square to inf in the solver's cost and Jacobian."""
    from scipy.optimize import least_squares

    w = np.ones(len(train))

    def resid(k: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            r = family.form(k, train.inputs) / train.y - 1.0
        return np.sqrt(w) * np.where(np.isfinite(r), np.clip(r, -1e3, 1e3), 1e3)

    k = family.published.astype(float).copy()
    best, best_max = k, float(rel_errors(family, k, train).max())
    for _ in range(lawson_iterations + 1):
        sol = least_squares(resid, k, x_scale="jac", max_nfev=200 * k.size, method="trf")
        k = sol.x
        e = rel_errors(family, k, train)
        if e.max() < best_max:
            best, best_max = k.copy(), float(e.max())
        w = w * (e + 1e-3 * e.max()) / np.mean(e + 1e-3 * e.max())
        w /= w.mean()
    if best.size <= 50:
        best = _minimax_polish(family, train, best)
    return best


def _minimax_polish(family: Family, train: Points, k0: np.ndarray) -> np.ndarray:
    """Minimise the maximum relative error directly: ``min t`` subject to
    ``-t <= r_i(k) <= t`` (SLSQP, epigraph form), from ``k0``; kept only if it is better."""
    from scipy.optimize import minimize

    e0 = float(rel_errors(family, k0, train).max())
    scale = np.where(np.abs(k0) > 0, np.abs(k0), 1.0)

    def r(z: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            v = family.form(z[:-1] * scale, train.inputs) / train.y - 1.0
        return np.where(np.isfinite(v), v, 1e3)

    z0 = np.append(k0 / scale, e0)
    cons = [{"type": "ineq", "fun": lambda z: z[-1] - r(z)},
            {"type": "ineq", "fun": lambda z: z[-1] + r(z)}]
    try:
        sol = minimize(lambda z: z[-1], z0, method="SLSQP", constraints=cons,
                       options={"maxiter": 300, "ftol": 1e-12})
    except (ValueError, np.linalg.LinAlgError):
        return k0
    k = sol.x[:-1] * scale
    return k if float(rel_errors(family, k, train).max()) < e0 else k0


def error_summary(family: Family, k: np.ndarray, pts: Points) -> dict[str, Any]:
    """max / mean / 95th percentile of the relative error and where the maximum sits."""
    e = rel_errors(family, k, pts)
    i = int(np.argmax(e))
    coords = domain_coords(family, pts.inputs)
    where = {a: float(coords[a][i]) for a in family.domain_axes if a in coords}
    return {"max": float(e.max()), "mean": float(e.mean()),
            "p95": float(np.percentile(e, 95)), "max_at": where}


@dataclass(frozen=True)
class Calibration:
    """A family's refitted coefficients, their domain and the held-out error table."""

    family: str
    coefficients: np.ndarray
    published: np.ndarray
    domain: dict[str, tuple[float, float]]
    train: dict[str, Any]
    held_out: dict[str, Any]
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def goal_met(self) -> bool:
        """Refitted max error at most 1/3 of the published coefficients' (held-out)."""
        return self.held_out["after"]["max"] <= self.held_out["before"]["max"] / 3.0

    def to_json(self) -> dict[str, Any]:
        return {"family": self.family, "coefficients": self.coefficients.tolist(),
                "published": self.published.tolist(),
                "domain": {k: list(v) for k, v in self.domain.items()},
                "train": self.train, "held_out": self.held_out, "goal_met": self.goal_met,
                **self.extra}


def calibrate(family: Family, train: Points, held_out: Points,
              held_out_seed: int | None = None) -> Calibration:
    """Fit on ``train``, report before/after on ``held_out`` (never used by the fit)."""
    t0 = time.perf_counter()
    k = fit(family, train)
    coords = domain_coords(family, train.inputs)
    domain = {a: (float(coords[a].min()), float(coords[a].max())) for a in family.domain_axes
              if a in coords}
    return Calibration(
        family=family.name, coefficients=k, published=family.published.copy(), domain=domain,
        train={"points": len(train), "before": error_summary(family, family.published, train),
               "after": error_summary(family, k, train),
               "fit_time_s": round(time.perf_counter() - t0, 2)},
        held_out={"points": len(held_out), "seed": held_out_seed,
                  "before": error_summary(family, family.published, held_out),
                  "after": error_summary(family, k, held_out)},
        extra={"kind": family.kind, "amount": family.amount, "target": family.target,
               "equal_spheres": family.equal, "description": family.description,
               "reference": ("lubrication (n=256)" if family.target == "viscous"
                             else "meniscus")})


AXIS_LABELS = {"v_star": "V* = V / R^3", "theta_deg": "contact angle theta (deg)",
               "s_over_sc": "S / S_c", "delta_over_r": "film thickness delta / R",
               "s_over_h": "S / H", "radius_ratio": "radius ratio R2 / R1"}
TARGET_LABELS = {"capillary": "capillary force (N)", "viscous": "viscous force (N)",
                 "rupture": "rupture distance S_c (m)"}


def write_calibration(cal: Calibration, held_out: Points, out: Path) -> list[Path]:
    """The JSON, a parity plot (``*_parity.png``) and an error map (``*_errors.png``)."""
    from wetcontact.plotting import save

    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(cal.to_json(), indent=1) + "\n")
    parity_fig, errors_fig = calibration_figures(cal, held_out)
    parity = out.with_name(out.stem + "_parity.png")
    errors = out.with_name(out.stem + "_errors.png")
    save(parity_fig, parity)
    save(errors_fig, errors)
    return [out, parity, errors]


def calibration_figures(cal: Calibration, held_out: Points) -> tuple[Any, Any]:
    """The held-out parity plot and error map of a calibration (matplotlib figures).

    Both name the family, its scene class and its reference in the title; the parity
    axes carry the target's unit, the error map the family's domain axes."""
    from wetcontact.plotting import pyplot

    plt = pyplot()
    fam = get_family(cal.family)
    what = (f"{cal.family}: {fam.kind}, {fam.amount}\nheld out against "
            f"{cal.extra.get('reference', 'the reference')}")
    with np.errstate(all="ignore"):
        before = fam.form(cal.published, held_out.inputs)
        after = fam.form(cal.coefficients, held_out.inputs)
    pfig, ax = plt.subplots(figsize=(5.5, 5.5), layout="constrained")
    ax.loglog(held_out.y, before, "x", ms=4, label="published", color="0.45")
    ax.loglog(held_out.y, after, "o", ms=3, mfc="none", label="refitted", color="C0")
    lim = [held_out.y.min(), held_out.y.max()]
    ax.plot(lim, lim, "k-", lw=0.8, label="closure = reference")
    unit = TARGET_LABELS[fam.target]
    ax.set(xlabel=f"reference {unit}", ylabel=f"closure {unit}")
    ax.set_title(f"{what}: parity", fontsize=8)
    ax.legend(fontsize=8)
    from matplotlib.ticker import NullFormatter

    ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels overlap on a short range
    coords = domain_coords(fam, held_out.inputs)
    ax_names = [a for a in fam.domain_axes if a in coords][:2]
    e_before = rel_errors(fam, cal.published, held_out)
    e_after = rel_errors(fam, cal.coefficients, held_out)
    efig, axs = plt.subplots(1, 2, figsize=(10, 4.3), sharex=True, sharey=True,
                             layout="constrained")
    vmax = max(float(e_before.max()), 1e-12)
    sc = None
    for axx, e, title in ((axs[0], e_before, "published"), (axs[1], e_after, "refitted")):
        o = np.argsort(e)  # largest errors drawn last (on top) where points coincide
        sc = axx.scatter(coords[ax_names[0]][o], (coords[ax_names[1]] if len(ax_names) > 1
                                                  else e)[o],
                         c=np.log10(np.maximum(e[o], 1e-8)), s=14, cmap="viridis",
                         vmin=np.log10(vmax) - 4, vmax=np.log10(vmax))
        axx.set(xlabel=AXIS_LABELS.get(ax_names[0], ax_names[0]),
                ylabel=(AXIS_LABELS.get(ax_names[1], ax_names[1]) if len(ax_names) > 1
                        else "relative error"),
                title=f"{title}: max {e.max():.2g}")
        if ax_names[0] in ("v_star", "delta_over_r"):
            axx.set_xscale("log")
    efig.colorbar(sc, ax=axs, label="log10 relative error (held out)")
    efig.suptitle(what.replace("\n", ", "), fontsize=9)
    return pfig, efig


def run_family(name: str, out: Path, n_train: int = 30, n_held_out: int = 16,
               seed: int = 7919, reuse: bool = False) -> Calibration:
    """Default design for one family: grid training set, seeded held-out set, files.

    The reference points are saved beside the JSON (``*_points.npz``); ``reuse`` refits
    from them instead of solving again."""
    fam = get_family(name)
    cache = out.with_name(out.stem + "_points.npz")
    if reuse and cache.is_file():
        train, held = load_points(cache)
    else:
        train = reference_points(fam, design(fam, n_train), gaps_per=8)
        held = reference_points(fam, design(fam, n_held_out, seed=seed), gaps_per=6,
                                seed=seed)
        save_points(cache, train, held)
    cal = calibrate(fam, train, held, held_out_seed=seed)
    write_calibration(cal, held, out)
    return cal


def save_points(path: Path, train: Points, held: Points) -> Path:
    """Save training and held-out points (read back by :func:`load_points`)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **{f"train_{k}": v for k, v in train.inputs.items()},
                        train_y=train.y, **{f"held_{k}": v for k, v in held.inputs.items()},
                        held_y=held.y)
    return path


def load_points(path: Path) -> tuple[Points, Points]:
    """Training and held-out points saved by :func:`run_family`."""
    with np.load(path) as z:
        parts = {}
        for tag in ("train", "held"):
            inputs = {k[len(tag) + 1:]: z[k] for k in z.files
                      if k.startswith(tag + "_") and k != f"{tag}_y"}
            parts[tag] = Points(inputs, z[f"{tag}_y"])
    return parts["train"], parts["held"]


# ---- calibration from a study file (``wetcontact calibrate``) -----------------------------


def component_of(family: Family) -> str:
    """The force component whose reference the family is fitted to."""
    return "viscous" if family.target == "viscous" else "capillary"


def reference_model(family: Family, models: Iterable[str], source: str = "") -> str:
    """The highest ``reference_rank`` model for the family's component among ``models``.

    Raises
    ------
    InputError
        None of ``models`` is a reference for that component: names the ones that are.
    """
    from wetcontact.models import load_all

    comp = component_of(family)
    ranked = sorted(((get_model(m).reference_rank.get(comp, 0), m) for m in models),
                    reverse=True)
    if not ranked or ranked[0][0] <= 0:
        refs = sorted(((m.reference_rank[comp], m.name) for m in load_all().values()
                       if m.reference_rank.get(comp, 0) > 0), reverse=True)
        raise InputError(f"{source or 'study'}: models = {list(models)} has no reference "
                         f"for the {comp} force of family {family.name}; allowed: add one of "
                         + ", ".join(f"{n} (rank {r})" for r, n in refs))
    return ranked[0][1]


def check_scene_class(family: Family, scenes: Iterable[Scene], source: str) -> None:
    """Every scene must be of the family's class (an :class:`InputError` otherwise)."""
    for sc in scenes:
        if sc.kind != family.kind or sc.amount != family.amount or (
                family.equal and not sc.equal_spheres):
            raise InputError(f"{source}: scene '{sc.name}' is {sc.kind} {sc.amount}"
                             + (" (unequal spheres)" if sc.kind == "sphere-sphere"
                                and not sc.equal_spheres else "")
                             + f"; allowed for family {family.name}: {family.kind} "
                             f"{family.amount}" + (" (equal spheres)" if family.equal else ""))


def held_out_study_text(path: Path, n: int, seed: int, out: Path) -> str:
    """A study file (TOML) of ``n`` seeded Latin-hypercube points over the ranges of the
    study at ``path``: every axis becomes ``{min, max, spacing}`` over the values it takes
    (log spacing where the file's range says so, or a list of positive values spanning
    more than a decade), and every ``[set]`` range (e.g. the gaps as fractions of the
    rupture distance) becomes a sampled axis too, so no held-out point shares a
    coordinate with the training grid but by chance. ``base`` is written relative to the
    folder of ``out`` (where the file will be saved)."""
    import os
    import tomllib

    data = tomllib.loads(path.read_text(encoding="utf-8"))
    axes: dict[str, Any] = {}
    fixed = dict(data.get("set", {}))

    def limits(v: Any) -> tuple[float, float, str] | None:
        if isinstance(v, Mapping) and "start" in v:
            lo, hi = sorted((float(v["start"]), float(v["stop"])))
            return lo, hi, str(v.get("spacing", "linear"))
        if isinstance(v, list) and v and all(isinstance(x, int | float) for x in v):
            lo, hi = float(min(v)), float(max(v))
            return lo, hi, "log" if lo > 0 and hi > 10 * lo else "linear"
        return None

    for p, v in data.get("axes", {}).items():
        lim = limits(v)
        if lim is None or lim[0] == lim[1]:
            fixed[p] = v if lim is None else lim[0]
        else:
            axes[p] = lim
    for p, v in list(fixed.items()):
        if isinstance(v, Mapping) and "start" in v:
            lim = limits(v)
            if lim is not None and lim[0] < lim[1]:
                axes[p] = lim
                del fixed[p]
    if not axes:
        raise InputError(f"{path}: no axis with a range to draw held-out points from; "
                         "allowed: give --held-out STUDY.toml")
    base = Path(os.path.relpath((path.parent / data["base"]).resolve(),
                                out.parent.resolve()))
    lines = [f"name = {json.dumps(str(data['name']) + '-held-out')}",
             "description = " + json.dumps(f"Held-out design of {path.name}: {n} points "
                                           "of a seeded Latin hypercube over its ranges"),
             f"base = {json.dumps(base.as_posix())}",
             f"models = {json.dumps(list(data['models']))}",
             f"preset = {json.dumps(data.get('preset', 'default'))}", "",
             "[sample]", 'method = "latin-hypercube"', f"points = {n}", f"seed = {seed}", "",
             "[axes]"]
    lines += [f'"{p}" = {{ min = {lo!r}, max = {hi!r}, spacing = "{sp}" }}'
              for p, (lo, hi, sp) in axes.items()]
    if fixed:
        lines += ["", "[set]"] + [f'"{p}" = {_toml(v)}' for p, v in fixed.items()]
    return "\n".join(lines) + "\n"


def _toml(v: Any) -> str:
    """A TOML value (numbers, strings, booleans, lists and inline tables of those)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | float):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{k} = {_toml(x)}" for k, x in v.items()) + " }"
    return "[" + ", ".join(_toml(x) for x in v) + "]"


def study_points(family: Family, study: Any, model: str, store: Any,
                 workers: int | None, label: str) -> tuple[Points, int]:
    """Reference points of a study's scenes by ``model``: swept into ``store`` first
    (points already there are reused, never recomputed). Returns the points and the
    number of scenes that failed."""
    from wetcontact.sweep import Point, sweep

    check_scene_class(family, [sc for _, sc in study.scenes], str(study.source))
    pts = [Point(scene=sc, model=model, preset=study.preset, axes=dict(ax))
           for ax, sc in study.scenes]
    res = sweep(pts, store, workers=workers, progress=True)
    pairs = [(o.point.scene, o.curve) for o in res.outcomes if o.curve is not None]
    failed = sum(o.curve is None for o in res.outcomes)
    if not pairs:
        reasons = {o.reason for o in res.outcomes if o.reason}
        raise SolverError(f"{label}: every {model} point failed ("
                          + "; ".join(sorted(reasons))[:300] + ")")
    return points_from_curves(family, pairs), failed


def calibrate_study(study_path: Path | str, family_name: str, out: Path | str,
                    store_path: Path | str, workers: int | None = None,
                    held_out: Path | str | None = None, held_out_points: int = 120,
                    seed: int = 7919) -> tuple[Calibration, list[Path]]:
    """``wetcontact calibrate``: fit ``family_name`` to a study's reference points.

    The reference is the study's model of highest ``reference_rank`` for the family's
    component; its points missing from the store are swept first. The fit trains on the
    study's grid; the held-out design is the study file ``held_out``, or ``held_out_points``
    points of a Latin hypercube with ``seed`` over the study's ranges (written beside
    ``out`` as ``*_heldout.toml``, so it can be rerun or reused). Writes the JSON, the
    parity plot and the error map (:func:`write_calibration`).
    """
    from wetcontact.store import Store
    from wetcontact.study import load_study

    fam = get_family(family_name)
    out = Path(out)
    if out.suffix.lower() != ".json":
        raise InputError(f"--out {out}: allowed: a .json file (the plots are written "
                         "beside it)")
    if out.is_dir():
        raise InputError(f"--out {out}: is a folder; allowed: a .json file")
    if not 4 <= held_out_points <= 100_000:
        raise InputError(f"--held-out-points = {held_out_points}; allowed: 4 to 100000")
    study = load_study(study_path)
    check_scene_class(fam, [sc for _, sc in study.scenes], str(study_path))
    ref = reference_model(fam, study.models, str(study_path))
    store = Store(store_path)
    len(store)  # an unreadable store fails here, before anything is written beside --out
    out.parent.mkdir(parents=True, exist_ok=True)
    if held_out is None:
        held_path = out.with_name(out.stem + "_heldout.toml")
        held_path.write_text(held_out_study_text(Path(study_path), held_out_points, seed,
                                                 held_path))
        held_seed: int | None = seed
    else:
        held_path, held_seed = Path(held_out), None
    held_study = load_study(held_path)
    check_scene_class(fam, [sc for _, sc in held_study.scenes], str(held_path))
    train, n_bad = study_points(fam, study, ref, store, workers, str(study_path))
    held, n_bad_held = study_points(fam, held_study, ref, store, workers, str(held_path))
    cal = calibrate(fam, train, held, held_out_seed=held_seed)
    extra = {**cal.extra, "reference": f"{ref} ({study.preset} preset)",
             "study": str(study_path), "held_out_study": str(held_path),
             "failed_scenes": {"train": n_bad, "held_out": n_bad_held}}
    cal = Calibration(cal.family, cal.coefficients, cal.published, cal.domain, cal.train,
                      cal.held_out, extra)
    files = write_calibration(cal, held, out)
    files.append(save_points(out.with_name(out.stem + "_points.npz"), train, held))
    return cal, files + ([held_path] if held_out is None else [])


# ---- refitted closures as models -----------------------------------------------------------


class CalibratedClosure(Model):
    """A family with refitted coefficients; refuses scenes outside the calibrated domain."""

    level = 0

    def __init__(self, family: Family, coefficients: np.ndarray,
                 domain: Mapping[str, tuple[float, float]], source: str):
        self.family, self.k, self.domain, self.source = family, coefficients, domain, source
        self.name = f"{family.name}@{Path(source).name}"  # type: ignore[misc]
        self.component = "viscous" if family.target == "viscous" else "capillary"  # type: ignore[misc]
        self.validity = "calibrated domain " + ", ".join(  # type: ignore[misc]
            f"{k} in [{lo:.4g}, {hi:.4g}]" for k, (lo, hi) in domain.items())
        self.reference = f"{family.description}, refitted ({source})"  # type: ignore[misc]

    def check(self, scene: Scene) -> None:
        fam = self.family
        if scene.kind != fam.kind or scene.amount != fam.amount or (
                fam.equal and not scene.equal_spheres):
            raise ValidityError(self.name, f"calibrated for {fam.kind} {fam.amount}"
                                + (" (equal spheres)" if fam.equal else ""), "meniscus"
                                if fam.amount == "bridge" else "lubrication")
        coords = domain_coords(fam, scene_inputs(fam, scene))
        for k, (lo, hi) in self.domain.items():
            v = coords[k]
            bad = (v < lo * (1 - 1e-9) - 1e-12) | (v > hi * (1 + 1e-9))
            if np.any(bad):
                raise ValidityError(self.name, f"{k} = {float(v[bad][0]):.4g} outside the "
                                    f"calibrated domain [{lo:.4g}, {hi:.4g}] ({self.source})",
                                    "meniscus" if fam.amount == "bridge" else "lubrication")

    def _force(self, scene: Scene, preset: str, **opts: Any) -> ForceCurve:
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
        if self.family.target == "viscous":
            return ForceCurve(case=scene.name, model=self.name, gap=gap, force_viscous=val,
                              force_capillary=None)
        if self.family.target == "rupture":  # a rupture distance, no force: both None
            return ForceCurve(case=scene.name, model=self.name, gap=gap, force_viscous=None,
                              force_capillary=None, extras={"rupture_distance": val})
        return ForceCurve(case=scene.name, model=self.name, gap=gap, force_viscous=None,
                          force_capillary=-val)


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


# ---- shipped calibrated closures ------------------------------------------------------------

PAIR_KIND = cc.PAIR_TWO_ANGLES
"""The two-angle sphere-pair table's kind (the model's name for it; the command line needs
it to parse its arguments, before it imports ``calibrate_pairs2``)."""


def fit_immersed(kind: str, degree: int = 48, s_range: tuple[float, float] = (1e-5, 100.0),
                 n_held_out: int = 4000, seed: int = 101) -> dict[str, Any]:
    """Chebyshev interpolation of ``q = lambda s/(1 + s)`` (wall) or
    ``lambda 2s/(1 + 2s)`` (equal spheres) in log s at Chebyshev points, and its held-out
    relative error against the exact series at seeded log-uniform points."""
    from wetcontact.reduced_models.calibrated import immersed_lambda

    lo, hi = math.log(s_range[0]), math.log(s_range[1])
    t = np.cos(np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))
    s = np.exp(0.5 * (t * (hi - lo) + lo + hi))
    exact = visc.brenner_lambda if kind == "sphere-wall" else visc.two_sphere_lambda
    q = exact(s) * (s / (1 + s) if kind == "sphere-wall" else 2 * s / (1 + 2 * s))
    coef = np.polynomial.chebyshev.chebfit(t, q, degree)
    table = {"immersed": {kind: {"log_range": [lo, hi], "chebyshev": coef.tolist()}}}
    rng = np.random.default_rng(seed)
    sh = np.exp(rng.uniform(lo, hi, n_held_out))
    err = np.abs(immersed_lambda(sh, kind, table) / exact(sh) - 1.0)
    i = int(np.argmax(err))
    return {"log_range": [lo, hi], "chebyshev": coef.tolist(),
            "held_out": {"points": n_held_out, "seed": seed, "reference": "brenner (exact)",
                         "max": float(err.max()), "mean": float(err.mean()),
                         "p95": float(np.percentile(err, 95)), "max_at_s_over_r": float(sh[i])}}


def _stokes_film(d: float, x: np.ndarray, preset: str) -> tuple[Scene, np.ndarray]:
    from wetcontact.bounds_gen import R, make_scene

    scene = make_scene("sphere-wall", {"film_thickness": d * R}, np.asarray(x) * d * R)
    return scene, get_model("stokes").force(scene, preset=preset).force_viscous


def fit_film_stokes(base: np.ndarray, nodes: tuple[int, int] = (10, 12), n_held_out: int = 24,
                    gaps_per: int = 8, seed: int = 303, preset: str = "default"
                    ) -> dict[str, Any]:
    """Correction of the film closure to ``stokes`` (flat film top, the fast-impact limit).

    The finite-liquid form with coefficients ``base`` (refitted to ``lubrication``) is
    multiplied by ``exp(sum_ij C_ij T_i(a) T_j(b))`` (:func:`film_coords`), C interpolating
    ``ln(F_stokes / F_form)`` at the tensor Chebyshev points. Lubrication itself is 0.4 %
    (delta/R = 1e-3) to 73 % (0.1) below Stokes as S -> delta, where the wetted cap is no
    longer thin. Held-out: ``n_held_out`` seeded films, ``gaps_per`` seeded gaps each,
    against Stokes solved there; the error of Pitois' factor on the same points is
    ``before``."""
    fam = FAMILIES["finite-liquid"]
    na, nb = nodes
    ta = np.cos(np.pi * (np.arange(na) + 0.5) / na)
    tb = np.cos(np.pi * (np.arange(nb) + 0.5) / nb)
    ds, xs = film_point(ta, tb)
    aa, bb, yy = [], [], []
    for t, d in zip(ta, ds, strict=True):
        scene, f = _stokes_film(float(d), xs, preset)
        form = finite_liquid_form(base, scene_inputs(fam, scene))
        aa.append(np.full(nb, t))
        bb.append(tb)
        yy.append(np.log(f / form))
    a, b, y = (np.concatenate(v) for v in (aa, bb, yy))
    coef = np.linalg.solve(np.polynomial.chebyshev.chebvander2d(a, b, [na - 1, nb - 1]), y)
    coef = coef.reshape(na, nb)
    rng = np.random.default_rng(seed)
    errs, errs_pitois, where = [], [], []
    for c in design(fam, n_held_out, seed=seed):
        d = c["delta_over_r"]
        x = np.sort(rng.uniform(*FILM_X, gaps_per))
        scene, f = _stokes_film(d, x, preset)
        inputs = scene_inputs(fam, scene)
        ca, cb = film_coords(np.full(x.size, d), x)
        pred = finite_liquid_form(base, inputs) * np.exp(
            np.polynomial.chebyshev.chebval2d(ca, cb, coef))
        pitois = finite_liquid_form(fam.published, inputs)
        errs.append(np.abs(pred / f - 1))
        errs_pitois.append(np.abs(pitois / f - 1))
        where += [{"delta_over_r": d, "s_over_h": float(v)} for v in x]
    e, ep = np.concatenate(errs), np.concatenate(errs_pitois)

    def table(err: np.ndarray) -> dict[str, Any]:
        return {"max": float(err.max()), "mean": float(err.mean()),
                "p95": float(np.percentile(err, 95)), "max_at": where[int(np.argmax(err))]}

    return {"delta_over_r": list(FILM_D), "s_over_h": list(FILM_X), "nodes": [na, nb],
            "chebyshev_2d": coef.tolist(),
            "reference": f"stokes (flat film top, preset {preset})",
            "held_out": {"points": int(e.size), "seed": seed, "before": table(ep),
                         "after": table(e)}}


def generate_calibrated_viscous(out: Path | None = None, n_train: int = 40,
                                n_held_out: int = 24) -> dict[str, Any]:
    """Write ``data/calibrated_viscous.json``: immersed Chebyshev tables, the film factor
    refitted against lubrication and corrected to Stokes (:func:`fit_film_stokes`), the
    bridge factors refitted against lubrication, each with its held-out error table."""
    t0 = time.perf_counter()
    data: dict[str, Any] = {"generated_by": "python -m wetcontact.calibrate viscous",
                            "immersed": {k: fit_immersed(k) for k in ("sphere-wall",
                                                                      "sphere-sphere")}}
    fam = FAMILIES["finite-liquid"]
    train = reference_points(fam, design(fam, n_train), gaps_per=10)
    held = reference_points(fam, design(fam, n_held_out, seed=303), gaps_per=8, seed=303)
    c = calibrate(fam, train, held, held_out_seed=303)
    corr = fit_film_stokes(c.coefficients)
    data["film"] = {"coefficients": c.coefficients.tolist(),
                    "domain": {k: list(v) for k, v in c.domain.items()},
                    "reference": corr["reference"] + ": the project's best film reference",
                    "stokes_correction": {k: v for k, v in corr.items() if k != "held_out"},
                    "held_out": corr["held_out"],
                    "lubrication_fit": {"reference": "lubrication (n = 256)",
                                        "train": c.train, "held_out": c.held_out}}
    for kind, name in (("sphere-wall", "finite-liquid-bridge-sw"),
                       ("sphere-sphere", "finite-liquid-bridge-ss")):
        fam = FAMILIES[name]
        train = reference_points(fam, design(fam, n_train), gaps_per=10)
        held = reference_points(fam, design(fam, n_held_out, seed=404), gaps_per=8, seed=404)
        c = calibrate(fam, train, held, held_out_seed=404)
        data.setdefault("bridge", {})[kind] = {
            "coefficients": c.coefficients.tolist(),
            "domain": {k: list(v) for k, v in c.domain.items()},
            "reference": "lubrication (n = 256): the project's best bridge viscous reference "
                         "(whole volume between the surfaces)",
            "train": c.train, "held_out": c.held_out}
    data["wall_time_s"] = round(time.perf_counter() - t0, 1)
    out = out or DATA_DIR / "calibrated_viscous.json"
    out.write_text(json.dumps(data, indent=1) + "\n")
    from wetcontact.reduced_models.calibrated import viscous_table

    viscous_table.cache_clear()
    return data



def _table_copy(out: Path | None) -> Path | None:
    """``--out`` for the capillary table commands: a copy of the package data's table file
    made there if it does not exist yet (``None``: the package data itself)."""
    if out is not None and not out.is_file():
        import shutil

        if not out.parent.is_dir():
            raise InputError(f"--out {out}: folder {out.parent} does not exist; allowed: a "
                             "file in an existing folder")
        shutil.copy(Path(cc.__file__).parent / "data" / cc.CAPILLARY_FILE, out)
    return out


def _print_held_out(kind: str, entry: dict[str, Any]) -> None:
    """One line per held-out table of a capillary table's entry."""
    for key in sorted(k for k in entry if k.startswith("held_out")):
        ho = entry[key]
        print(f"{kind} {key}: max rupture {ho['rupture_distance']['max']:.3g}, "
              f"force {ho['force']['max']:.3g} ({ho['force']['points']} points)")

def main(argv: list[str] | None = None) -> int:
    """``python -m wetcontact.calibrate bounds|fit ...``."""
    from wetcontact.bounds_gen import ALONE

    p = argparse.ArgumentParser(prog="python -m wetcontact.calibrate")
    sub = p.add_subparsers(dest="command", required=True)
    b = sub.add_parser("bounds", help="measure the closures' error-bound tables")
    b.add_argument("--quick", action="store_true",
                   help="fewer held-out scenes per table (a smoke run; the shipped tables "
                        "are not --quick)")
    b.add_argument("--seed", type=int, default=20261123,
                   help="seed of the held-out scenes (default: the shipped tables' seed)")
    b.add_argument("--out", type=Path, default=None,
                   help="JSON file to write (default: the package data; with --quick: "
                        "bounds-quick.json in the current folder, so that a smoke run never "
                        "replaces the shipped tables)")
    b.add_argument("--closure", choices=list(ALONE), default=None,
                   help="measure only this closure's tables again, in place in the file a "
                        "whole run wrote (same --seed and --quick): what a change of the "
                        "closure itself calls for")
    f = sub.add_parser("fit", help="refit closure families on their default designs")
    f.add_argument("family", choices=sorted(FAMILIES) + ["all"])
    f.add_argument("--out", type=Path, required=True, help="JSON file (a folder for 'all')")
    f.add_argument("--train", type=int, default=30,
                   help="about this many training configurations, a full grid over the "
                        "family's design (8 gaps each; default 30)")
    f.add_argument("--held-out", type=int, default=16,
                   help="seeded random held-out configurations (6 gaps each; default 16)")
    f.add_argument("--reuse", action="store_true", help="refit from the saved points")
    sub.add_parser("viscous", help="regenerate the calibrated-viscous closure")
    c = sub.add_parser("capillary", help="regenerate the calibrated-capillary closure")
    c.add_argument("--kind", choices=["sphere-wall", "sphere-sphere", cc.WALL_TWO_ANGLES,
                                      PAIR_KIND, "all"], default="all",
                   help="one table (two contact angles: sphere-wall-two-angles, "
                        "sphere-sphere-two-angles); the others are kept as they are; 'all' "
                        "is the first three")
    c.add_argument("--workers", type=int, default=2,
                   help="processes solving the meniscus nodes (default 2)")
    c.add_argument("--held-out", type=int, default=120, help="held-out bridges per kind")
    c.add_argument("--stage", choices=["coarse", "medium", "full"], default="full",
                   help="sphere-sphere-two-angles only: the node counts (nested: each "
                        "stage reuses what the ones before it solved; full is shipped)")
    c.add_argument("--out", type=Path, default=None,
                   help="write into this copy of the table file, made from the package "
                        "data's if it does not exist (default: the package data itself)")
    c.add_argument("--retrain", action="store_true",
                   help="keep the fit the file holds, build its tensor trains again (the "
                        "two-angle tables) and measure its held-out tables again (no node "
                        "solved; --stage is ignored)")
    c.add_argument("--corners", action="store_true",
                   help="measure only the corner stratum (held_out_corners: the domain's "
                        "ends and middles at gaps up to 0.999 S_c) of every table the package "
                        "data holds, or of --kind's, against meniscus; nothing is refitted")
    c.add_argument("--refine-band", type=int, nargs="+", default=None, metavar="BAND",
                   help="the two-angle tables only (--kind): fit again the pieces of these "
                        "bands (0-2) whose node counts differ from the generator's, from "
                        "each band's own ridge series (searched again only at the w nodes a "
                        "pair band's ridge gains), and measure the table's held-out tables "
                        "again, once")
    args = p.parse_args(argv)
    if args.command == "capillary" and args.refine_band is not None:
        from wetcontact.calibrate_pairs2 import refine_band

        if args.kind not in (cc.WALL_TWO_ANGLES, PAIR_KIND):
            p.error(f"--refine-band: only with --kind {cc.WALL_TWO_ANGLES} or --kind "
                    f"{PAIR_KIND} (given: --kind {args.kind})")
        bad = [b for b in args.refine_band if b not in (0, 1, 2)]
        if bad or len(set(args.refine_band)) < len(args.refine_band):
            p.error(f"--refine-band = {' '.join(map(str, args.refine_band))}; allowed: "
                    "distinct bands 0, 1 or 2")
        entry = refine_band(args.kind, args.refine_band, _table_copy(args.out), args.workers)
        _print_held_out(args.kind, entry)
        for b in args.refine_band:
            rec = entry["refine_band"][str(b)]
            print(f"band {b}: {rec['wall_time_s']} s "
                  f"(held-out tables {rec['held_out_wall_time_s']} s)")
        return 0
    if args.command == "capillary" and args.corners:
        from wetcontact.calibrate_capillary import CORNER_KINDS, add_corner_strata

        kinds = CORNER_KINDS if args.kind == "all" else (args.kind,)
        data = add_corner_strata(_table_copy(args.out), kinds, args.workers)
        for kind in kinds:
            if kind in data:
                ho = data[kind]["held_out_corners"]
                print(f"{kind} held_out_corners: max rupture "
                      f"{ho['rupture_distance']['max']:.3g}, force {ho['force']['max']:.3g} "
                      f"({ho['force']['points']} points, {ho['bridges']} bridges)")
        return 0
    if args.command == "capillary" and args.kind == PAIR_KIND:
        from wetcontact.calibrate_pairs2 import generate_pair_table

        entry = generate_pair_table(args.stage, _table_copy(args.out), args.workers,
                                    args.held_out, retrain=args.retrain)
        _print_held_out(args.kind, entry)
        print(f"{entry['retrain_wall_time_s' if args.retrain else 'wall_time_s']} s")
        return 0
    if args.command == "capillary":
        from wetcontact.calibrate_capillary import KINDS, generate_calibrated_capillary

        kinds = KINDS if args.kind == "all" else (args.kind,)
        data = generate_calibrated_capillary(_table_copy(args.out), kinds=kinds,
                                             workers=args.workers, n_held_out=args.held_out,
                                             retrain=args.retrain)
        for kind in kinds:
            ho = data[kind]["held_out"]
            print(f"{kind}: held-out max rupture {ho['rupture_distance']['max']:.3g}, "
                  f"force {ho['force']['max']:.3g} ({ho['force']['points']} points)")
        print(f"{data['retrain_wall_time_s' if args.retrain else 'wall_time_s']} s")
        return 0
    if args.command == "viscous":
        data = generate_calibrated_viscous()
        for k, v in data["immersed"].items():
            print(f"immersed {k}: held-out max {v['held_out']['max']:.3g}")
        for label, d in (("film", data["film"]), *(
                (f"bridge {k}", v) for k, v in data["bridge"].items())):
            ho = d["held_out"]
            print(f"{label}: held-out max {ho['before']['max']:.3g} (Pitois) -> "
                  f"{ho['after']['max']:.3g}")
        print(f"{data['wall_time_s']} s")
    elif args.command == "bounds":
        from wetcontact.bounds_gen import DATA_PATH, measure_bounds

        out = args.out or (Path("bounds-quick.json") if args.quick else DATA_PATH)
        data = measure_bounds(seed=args.seed, out=out, quick=args.quick, progress=True,
                              closure=args.closure)
        if args.closure:
            done = data["remeasured"][args.closure]
            print(f"wrote {out} ({done['tables']} {args.closure} tables measured again, "
                  f"{done['wall_time_s']} s)")
        else:
            print(f"wrote {out} ({len(data['tables'])} tables, {data['wall_time_s']} s)")
    else:
        names = sorted(FAMILIES) if args.family == "all" else [args.family]
        for name in names:
            out = args.out / f"{name}.json" if args.family == "all" else args.out
            cal = run_family(name, out, args.train, args.held_out, reuse=args.reuse)
            ho = cal.held_out
            print(f"{cal.family}: held-out max {ho['before']['max']:.3g} -> "
                  f"{ho['after']['max']:.3g} (goal 1/3: "
                  f"{'met' if cal.goal_met else 'NOT met'}); wrote {out}", flush=True)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except InputError as exc:  # bad input: one line, exit 2, no traceback
        print(f"python -m wetcontact.calibrate: error: {exc}", file=sys.stderr)
        sys.exit(2)
