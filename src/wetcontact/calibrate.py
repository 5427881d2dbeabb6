"""Calibration: refit a closure family's coefficients to reference points, and measure the
refit on held-out points it never saw.

The core works on arrays of reference points (:class:`Points`: per-point inputs and the
reference value), however they were computed: directly through
``get_model(name).force(scene)`` (:func:`reference_points`) or from a sweep's store.
:func:`calibrate` trains on a grid, reports on a seeded held-out design the fit never saw
(maximum, mean and 95th percentile of the relative error before and after, and where the
maximum sits), and writes the coefficients with the domain they are valid on, each named
in its family's formula (:func:`labelled_coefficients`), a parity plot and an error map
beside the JSON (:func:`write_calibration`).

The families (their forms, published coefficients and domains) and a refit read back as a
model (:func:`~wetcontact.reduced_models.refit.load_coefficients`,
:class:`~wetcontact.reduced_models.refit.CalibratedClosure`: NaN at the gaps outside its
domain, a scene outside it refused) are :mod:`wetcontact.reduced_models.refit`; this module
re-exports their names.

The fit minimises the relative error by least squares, then by Lawson's reweighting
toward the minimax solution (scipy.optimize.least_squares), then (up to 50 coefficients)
polishes the maximum directly in epigraph form (SLSQP; Willett's 48: 4.3 -> 4.1 %).

``wetcontact calibrate STUDY.toml --closure FAMILY --out F.json`` (:func:`calibrate_study`)
fits a family to a study's reference points from the store (swept first when missing) and
reports on a seeded Latin-hypercube held-out design over the study's ranges; the capillary
families' studies are ``cases/studies/calibrate-*.toml``.
``python -m wetcontact.generate fit FAMILY --out F.json`` calibrates one family on its default
design (:func:`run_family`); the shipped tables are built by :mod:`wetcontact.generate`, which
uses this module's fit.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import InputError, SolverError
from wetcontact.models import ForceCurve, get_model
from wetcontact.reduced_models.forms import (  # re-exported: the families' forms
    BAGHERI_PUBLISHED,  # noqa: F401
    WILLETT_PUBLISHED,  # noqa: F401
    bagheri_form,  # noqa: F401
    finite_liquid_form,  # noqa: F401
    mikami_form,  # noqa: F401
    willett_form,  # noqa: F401
)
from wetcontact.reduced_models.refit import (  # re-exported: the families and the refits
    DOMAIN_LIMITS,  # noqa: F401
    FAMILIES,  # noqa: F401
    GAP_AXES,  # noqa: F401
    CalibratedClosure,  # noqa: F401
    Family,
    domain_coords,
    get_family,
    load_coefficients,  # noqa: F401
    scene_inputs,
)
from wetcontact.scene import Scene, scene_from_dict

# ---- reference scenes ---------------------------------------------------------------------

R = 1.0e-3


def make_scene(kind: str, amount: dict[str, Any], gaps: Any, radius2: float | None = None,
               theta: tuple[float, float] = (0.0, 0.0), velocity: float = 0.1,
               name: str = "bounds") -> Scene:
    """A water-like scene with R = 1 mm: the reference points' scenes, and the bound tables'
    (every table is in dimensionless coordinates)."""
    geom: dict[str, Any] = {"kind": kind, "radius": R}
    if radius2 is not None:
        geom["radius2"] = radius2
    a, b = theta
    other = "contact_angle_wall" if kind == "sphere-wall" else "contact_angle_sphere2"
    liquid = {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
              "contact_angle_sphere": a, other: b}
    return scene_from_dict({"name": name, "geometry": geom, "liquid": liquid,
                            "amount": amount,
                            "motion": {"velocity": velocity, "gaps": [float(g) for g in gaps]}})


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
        """The calibration file's object: ``coefficients`` (the loader's), ``formula`` and
        ``labelled_coefficients`` (each coefficient named in the formula,
        :func:`labelled_coefficients`), the domain and the error tables."""
        labelled = labelled_coefficients(get_family(self.family), self.coefficients,
                                         self.published)
        return {"family": self.family, "coefficients": self.coefficients.tolist(),
                "published": self.published.tolist(), **labelled,
                "domain": {k: list(v) for k, v in self.domain.items()},
                "train": self.train, "held_out": self.held_out, "goal_met": self.goal_met,
                **self.extra}


def labelled_coefficients(family: Family, k: np.ndarray, published: np.ndarray | None = None
                          ) -> dict[str, Any]:
    """``k`` named in ``family``'s formula: what a calibration file writes beside the bare
    ``coefficients`` list (which the loader reads; these keys are for the reader).

    Parameters
    ----------
    family
        The closure family (its :attr:`Family.labels`).
    k
        Coefficients in the family's order.
    published
        The published coefficients, written beside each value (None: left out).

    Returns
    -------
    dict
        ``{"formula": str, "labelled_coefficients": [{"name", "value", "published",
        "term"}, ...]}``, one entry per coefficient in the order of ``k``; ``term`` is what
        the coefficient multiplies in the formula (``"theta^2 in B"``), or ``"exponent of
        ..."``. Empty for a family without labels.
    """
    if family.labels is None:
        return {}
    k = np.asarray(k, dtype=float).ravel()
    if len(family.labels.terms) != k.size:  # a labels table out of step with its form
        raise ValueError(f"{family.name}: {len(family.labels.terms)} labels for {k.size} "
                         "coefficients")
    pub = None if published is None else np.asarray(published, dtype=float).ravel()
    rows = []
    for i, (name, term) in enumerate(family.labels.terms):
        row: dict[str, Any] = {"name": name, "value": float(k[i])}
        if pub is not None:
            row["published"] = float(pub[i])
        row["term"] = term
        rows.append(row)
    return {"formula": family.labels.formula, "labelled_coefficients": rows}


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


