"""Generator of the shipped ``calibrated-viscous`` closure (``data/calibrated_viscous.json``):
``python -m wetcontact.generate calibrated-viscous``.

The closure's form and coordinates are in :mod:`wetcontact.reduced_models.calibrated`. The
immersed tables interpolate the exact series (Brenner 1961; Maude 1961) at Chebyshev
points (:func:`fit_immersed`); the film and bridge factors are refitted to ``lubrication``
(:func:`wetcontact.calibrate.calibrate` on the families ``finite-liquid``,
``finite-liquid-bridge-sw`` and ``-ss``), and the film's is corrected to ``stokes`` with
the flat film top (:func:`fit_film_stokes`), each with its held-out error table.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.calibrate import (
    FAMILIES,
    R,
    calibrate,
    design,
    make_scene,
    reference_points,
    scene_inputs,
)
from wetcontact.models import get_model
from wetcontact.reduced_models import DATA_DIR
from wetcontact.reduced_models import viscous as visc
from wetcontact.reduced_models.calibrated import FILM_D, FILM_X, film_coords, film_point
from wetcontact.reduced_models.forms import finite_liquid_form
from wetcontact.scene import Scene


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
    data: dict[str, Any] = {"generated_by": "python -m wetcontact.generate calibrated-viscous",
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
