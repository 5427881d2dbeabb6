"""``wetcontact export json|python|c``: the schema, and the exported code against the
package's own evaluation (through its models) at thousands of points.

Reference: :func:`wetcontact.export.package_evaluation.package_evaluation`, which goes through
``get_model("calibrated-viscous")``, ``get_model("calibrated-capillary")`` and the refitted
closures of :func:`wetcontact.calibrate.load_coefficients` (NaN where they refuse). The
exported code repeats the arithmetic in another language, so agreement to 1e-12 relative (a
few ulps of libm's exp/log/acos compounded through the forms, and the sums of the
Chebyshev tensors taken in another order) shows it computes the same closures, with the
same domain (NaN at the same points) and the same rupture (0 at the same points).
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
import textwrap
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from wetcontact.cli import main
from wetcontact.export.c_header import write_header
from wetcontact.export.calibration_json import (
    NUMBER_ARRAYS,
    schema,
    shipped_document,
    skeleton,
    write_json,
)
from wetcontact.export.closure_tables import sphere_end_text
from wetcontact.export.closures import REFIT_DIR, REFIT_FILES, capillary_source
from wetcontact.export.package_evaluation import package_evaluation_many
from wetcontact.export.python_module import write_module
from wetcontact.reduced_models import calibrated_capillary as cc
from wetcontact.scene import min_gap

jsonschema = pytest.importorskip("jsonschema")

#: the calibration outputs of a source checkout (``wetcontact calibrate``)
CALIBRATION_DIR = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "calibration"

REL = 1e-12  # a few ulps of libm through exp(f1 - f2 exp(...)); not loosened
#: calibrated-capillary near its rupture distance: the two implementations' S_c differ by
#: a few ulps (the tensor sum in another order), and the force's gap coordinate
#: z = sqrt(1 - ln(1 + S/eps)/ln(1 + S_c/eps)) turns a relative delta of S_c into about
#: delta/(2 z^2) of z, z^2 <= 1 - S/S_c (the fold's square root, F - F_c ~ sqrt(S_c - S)):
#: the force's relative difference may reach FOLD/sqrt(1 - S/S_c) there (measured: up to
#: 0.39 (numpy module) and 0.47 (C) of REL + FOLD/sqrt(1 - S/S_c), 1.1e-11 within 4e-8 of
#: S_c; 3.1e-13 at most where 1 - S/S_c > 1e-6)
FOLD = 1e-15
#: calibrated-capillary with two angles near the ridge: the two implementations' ridge
#: series theta_w* (deg) differ by a few ulps (summed in another order: about 1e-14 deg),
#: and the wall angle's coordinate, quadratic toward the ridge, b = 1 - 2 sqrt(d/L)
#: (d = |theta_w - theta_w*|, L >= 1 deg the piece's width), turns that into
#: delta b ~ 1e-14/sqrt(L d); the force and S_c change by at most about that relative to
#: themselves (their slopes in b are O(1)), so both may differ by RIDGE/sqrt(d) there
#: (measured: 5.9e-12 at d = 3.5e-7 deg, 0.35 of the term)
RIDGE = 1e-14
N = 1500  # points per function (9000 in all)
N_TWO = 600  # added to calibrated-capillary's: planes with two angles, half near the ridge,
# and as many sphere pairs with two angles, half near their ridge
N_RUPTURE = 400  # of the capillary_force points, moved to within 1e-3 of the rupture distance

ARGS = {
    "viscous_force_immersed": ("r1", "r2", "viscosity", "approach_speed", "gap"),
    "viscous_force_bridge": ("r1", "r2", "viscosity", "volume", "approach_speed", "gap"),
    "rupture_distance": ("r1", "r2", "volume", "theta1_deg", "theta2_deg"),
    "capillary_force": ("r1", "r2", "volume", "gap", "surface_tension", "theta1_deg",
                        "theta2_deg"),
    "rupture_distance_refit": ("r1", "r2", "volume", "theta1_deg", "theta2_deg"),
    "capillary_force_refit": ("r1", "r2", "volume", "gap", "surface_tension", "theta1_deg",
                              "theta2_deg"),
}
SHIPPED_CAPILLARY = ("rupture_distance", "capillary_force")


def _second_radius(rng: np.random.Generator, r1: np.ndarray, p_plane: float,
                   p_unequal: float) -> np.ndarray:
    u = rng.uniform(size=r1.size)
    return np.where(u < p_plane, np.inf, np.where(u < p_plane + p_unequal,
                                                  r1 * rng.uniform(1.1, 3.0, r1.size), r1))


def design(seed: int = 20261123) -> dict[str, dict[str, np.ndarray]]:
    """Random points, mostly inside the domains, some outside, some past rupture."""
    rng = np.random.default_rng(seed)
    r1 = np.exp(rng.uniform(np.log(1e-6), np.log(1e-2), N))
    vis = {"r1": r1, "r2": _second_radius(rng, r1, 0.45, 0.1),
           "viscosity": np.exp(rng.uniform(np.log(1e-4), np.log(10.0), N)),
           "approach_speed": rng.uniform(-2.0, 2.0, N),
           "gap": r1 * np.exp(rng.uniform(np.log(3e-6), np.log(300.0), N))}
    r1 = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), N))
    r2 = np.where(rng.uniform(size=N) < 0.4, np.inf,
                  r1 * np.exp(rng.uniform(np.log(0.08), np.log(12.0), N)))
    rstar = 1.0 / (1.0 / r1 + 1.0 / r2)  # r1 for a plane
    vb = np.minimum(r1, r2) ** 3 * np.exp(rng.uniform(np.log(5e-5), np.log(0.15), N))
    x = rng.uniform(0.003, 0.99, N)  # S/H
    bridge = {"r1": r1, "r2": r2, "viscosity": vis["viscosity"], "volume": vb,
              "approach_speed": vis["approach_speed"],
              "gap": x * np.sqrt(vb / (np.pi * rstar)) / np.sqrt(1.0 - x**2)}
    r1 = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), N))
    v = r1**3 * np.exp(rng.uniform(np.log(5e-5), np.log(0.15), N))
    th1, th2 = rng.uniform(0.0, 60.0, N), rng.uniform(0.0, 60.0, N)
    rup = {"r1": r1, "r2": _second_radius(rng, r1, 0.05, 0.05), "volume": v,
           "theta1_deg": th1, "theta2_deg": th2}
    # gap as a fraction of an approximate rupture distance: near contact (NaN), inside,
    # between the force's fitted range and rupture (NaN), past rupture (0)
    sc = r1 * (1.0 + 0.5 * np.radians(0.5 * (th1 + th2))) * np.cbrt(v / r1**3)
    cap = {**rup, "gap": sc * rng.uniform(0.003, 1.3, N),
           "surface_tension": rng.uniform(0.02, 0.08, N)}
    shipped_rup, shipped_cap = shipped_design(rng)
    return {"viscous_force_immersed": vis, "viscous_force_bridge": bridge,
            "rupture_distance": shipped_rup, "capillary_force": shipped_cap,
            "rupture_distance_refit": rup, "capillary_force_refit": cap}


def shipped_design(rng: np.random.Generator) -> tuple[dict[str, np.ndarray], ...]:
    """``calibrated-capillary`` points: planes and sphere pairs (ratio up to 12, beyond the
    domain's 10), v from 5e-5 to 0.15 (beyond [1e-4, 0.1]), theta up to 80 deg (beyond 70),
    mostly one angle, some two (the two-angle tables) or two within the model's tolerance
    (one angle); gaps from 1e-12 R_s (near contact), exactly 0 and negative to past
    rupture; a few non-finite arguments; then ``N_TWO`` planes and ``N_TWO`` sphere pairs
    with two angles (:func:`two_angle_design`). The points near rupture are added by
    :func:`near_rupture`."""
    r1 = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), N))
    r2 = np.where(rng.uniform(size=N) < 0.4, np.inf,
                  r1 * np.exp(rng.uniform(np.log(1 / 12.0), np.log(12.0), N)))
    r2[:40] = r1[:40]  # equal spheres: ratio exactly 1
    rs = np.minimum(r1, r2)
    v = np.exp(rng.uniform(np.log(5e-5), np.log(0.15), N))
    th1 = rng.uniform(0.0, 80.0, N)
    u = rng.uniform(size=N)
    th2 = np.where(u < 0.1, rng.uniform(0.0, 80.0, N), th1)
    th2 = np.where((u >= 0.1) & (u < 0.15), th1 + 1e-8, th2)  # 1.7e-10 rad apart: one angle
    rup = {"r1": r1, "r2": r2, "volume": v * rs**3, "theta1_deg": th1, "theta2_deg": th2}
    cap = {**rup, "gap": _gaps(rng, rs, th1, v), "surface_tension": rng.uniform(0.02, 0.08, N)}
    for args in (rup, cap):  # non-finite arguments: NaN
        for k, name in enumerate(args):
            args[name] = args[name].copy()
            args[name][N - 1 - 2 * k] = np.nan
            args[name][N - 2 - 2 * k] = np.inf if name != "r2" else -np.inf
    rup2, cap2 = two_angle_design(rng, N_TWO)
    return ({k: np.concatenate([rup[k], rup2[k]]) for k in rup},
            {k: np.concatenate([cap[k], cap2[k]]) for k in cap})


def _gaps(rng: np.random.Generator, rs: np.ndarray, theta_deg: np.ndarray,
          v: np.ndarray) -> np.ndarray:
    """Gaps up to 1.3 times about the rupture distance, a fifth from 1e-12 to 1e-3 R_s (near
    contact; those below the smallest gap a scene holds, max(1e-12 m, 1e-9 R_s), at it),
    2 % exactly 0, 1 % negative (an overlap: NaN)."""
    n = rs.size
    sc = rs * (1.0 + 0.5 * np.radians(theta_deg)) * np.cbrt(v)  # about the rupture distance
    gap = sc * rng.uniform(0.0, 1.3, n)
    u = rng.uniform(size=n)
    near = np.maximum(rs * 10.0 ** rng.uniform(-12, -3, n), [min_gap(r) for r in rs])
    gap = np.where(u < 0.2, near, gap)
    gap[u > 0.98] = 0.0
    gap[(u > 0.97) & (u <= 0.98)] *= -1.0  # overlap: NaN
    return gap


def ridge_deg(v: np.ndarray, theta_sphere_deg: np.ndarray,
              ratio: np.ndarray | None = None) -> np.ndarray:
    """The other solid's angle (deg) at the two-angle table's ridge, where its pieces meet
    (NaN without that table), from the package's own series: the plane's, or given the
    radius ratio, the large sphere's (``theta_sphere_deg`` the small one's)."""
    table = cc.capillary_table()
    kind = cc.WALL_TWO_ANGLES if ratio is None else cc.PAIR_TWO_ANGLES
    if table is None or kind not in table:
        return np.full(np.shape(v), np.nan)
    with np.errstate(all="ignore"):  # the design's non-finite arguments
        return cc.ridge_deg(v, theta_sphere_deg, ratio=ratio)


def ridge_offset(a: dict[str, np.ndarray]) -> np.ndarray:
    """Per point of a capillary design ``a``: the other solid's angle (the plane's, or the
    large sphere's) minus its ridge angle (deg), on planes and sphere pairs with two angles;
    NaN elsewhere and without the table."""
    plane = np.isposinf(a["r2"])
    small = plane | (a["r1"] <= a["r2"])  # sphere 1 is the small one (as the model: ties)
    rs, rl = np.where(small, a["r1"], a["r2"]), np.where(small, a["r2"], a["r1"])
    th_s = np.where(small, a["theta1_deg"], a["theta2_deg"])
    th_o = np.where(small, a["theta2_deg"], a["theta1_deg"])
    with np.errstate(all="ignore"):
        v = a["volume"] / rs**3
        ridge = np.where(plane, ridge_deg(v, th_s), ridge_deg(v, th_s, np.where(
            plane, 1.0, rl / rs)))
    geo = geometries(a)
    return np.where(geo[cc.WALL_TWO_ANGLES] | geo[cc.PAIR_TWO_ANGLES], th_o - ridge, np.nan)


def two_angle_design(rng: np.random.Generator, n: int) -> tuple[dict[str, np.ndarray], ...]:
    """Planes with two contact angles: v from 5e-5 to 0.15, the sphere's angle theta1 up
    to 75 deg, the plane's theta2 up to 75 deg (beyond 70: NaN), uniform at even indices
    and at odd ones within 1e-7 ... 3 deg of the table's ridge (log-uniform, both sides;
    uniform when the table is not generated); gaps as :func:`_gaps`. Then ``n`` sphere
    pairs alike (:func:`pair_two_angle_design`)."""
    r1 = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), n))
    v = np.exp(rng.uniform(np.log(5e-5), np.log(0.15), n))
    th1, th2 = rng.uniform(0.0, 75.0, n), rng.uniform(0.0, 75.0, n)
    dist = 10.0 ** rng.uniform(-7.0, np.log10(3.0), n) * rng.choice([-1.0, 1.0], n)
    ridge = ridge_deg(v, th1)
    near = (np.arange(n) % 2 == 1) & np.isfinite(ridge)
    th2 = np.where(near, np.abs(ridge + dist), th2)
    rup = {"r1": r1, "r2": np.full(n, np.inf), "volume": v * r1**3, "theta1_deg": th1,
           "theta2_deg": th2}
    cap = {**rup, "gap": _gaps(rng, r1, th1, v), "surface_tension": rng.uniform(0.02, 0.08, n)}
    rup2, cap2 = pair_two_angle_design(rng, n)
    return ({k: np.concatenate([rup[k], rup2[k]]) for k in rup},
            {k: np.concatenate([cap[k], cap2[k]]) for k in cap})


def pair_two_angle_design(rng: np.random.Generator, n: int
                          ) -> tuple[dict[str, np.ndarray], ...]:
    """Sphere pairs with two contact angles: radius ratio up to 12 (beyond 10: NaN),
    either sphere the smaller, v from 5e-5 to 0.15, both angles up to 75 deg, uniform at
    even indices and at odd ones the large sphere's within 1e-7 ... 3 deg of the pair
    table's ridge (as :func:`two_angle_design`); gaps as :func:`_gaps`."""
    r1 = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), n))
    r2 = r1 * np.exp(rng.uniform(np.log(1 / 12.0), np.log(12.0), n))
    rs, ratio = np.minimum(r1, r2), np.maximum(r1, r2) / np.minimum(r1, r2)
    v = np.exp(rng.uniform(np.log(5e-5), np.log(0.15), n))
    small, large = rng.uniform(0.0, 75.0, n), rng.uniform(0.0, 75.0, n)
    dist = 10.0 ** rng.uniform(-7.0, np.log10(3.0), n) * rng.choice([-1.0, 1.0], n)
    ridge = ridge_deg(v, small, ratio)
    near = (np.arange(n) % 2 == 1) & np.isfinite(ridge)
    large = np.where(near, np.abs(ridge + dist), large)
    one = r1 <= r2
    rup = {"r1": r1, "r2": r2, "volume": v * rs**3,
           "theta1_deg": np.where(one, small, large), "theta2_deg": np.where(one, large, small)}
    cap = {**rup, "gap": _gaps(rng, rs, small, v),
           "surface_tension": rng.uniform(0.02, 0.08, n)}
    return rup, cap


def near_rupture(cap: dict[str, np.ndarray], sc: np.ndarray, seed: int = 7) -> None:
    """Move a third of the capillary points with a rupture distance (at most
    ``N_RUPTURE``) to within a relative 1e-9 ... 1e-3 of it, half before, half after (in
    place)."""
    rng = np.random.default_rng(seed)
    have = np.flatnonzero(np.isfinite(sc) & np.isfinite(cap["gap"]))
    idx = np.sort(rng.choice(have, size=min(N_RUPTURE, have.size // 3), replace=False))
    rel = 10.0 ** rng.uniform(-9, -3, idx.size) * np.where(np.arange(idx.size) % 2, 1, -1)
    cap["gap"][idx] = sc[idx] * (1.0 + rel)


@pytest.fixture(scope="module")
def source():
    return capillary_source()


@pytest.mark.parametrize("family", sorted(REFIT_FILES))
def test_shipped_refits_are_the_checkouts_calibration(family):
    """The package data the exports read by default is the committed calibration output
    (so an installed package exports what the checkout's tables report)."""
    shipped = REFIT_DIR / REFIT_FILES[family]
    assert shipped.is_file()
    src = CALIBRATION_DIR / f"{family}.json"
    if not src.is_file():
        pytest.skip(f"{src} not in this checkout")
    assert json.loads(shipped.read_text()) == json.loads(src.read_text())


@pytest.fixture(scope="module")
def points(source):
    """The design and the package's evaluation at every point."""
    pts = design()
    cap = pts["capillary_force"]
    sc = package_evaluation_many("rupture_distance", source,
                                 **{k: cap[k] for k in ARGS["rupture_distance"]})
    # near rupture: not the sphere pairs near their ridge, where the two implementations'
    # S_c differ by up to RIDGE/sqrt(d) and the fold's square root compounds that beyond
    # the tolerance's two terms (as in :func:`onset_points`; measured on the pairs' 3-D
    # ridge series: 2.4e-10 at d = 2.3e-7 deg, 1 - S/S_c = 3.1e-8)
    with np.errstate(invalid="ignore"):
        ridge = geometries(cap)[cc.PAIR_TWO_ANGLES] & (np.abs(ridge_offset(cap)) <= 3.0)
    near_rupture(cap, np.where(ridge, np.nan, sc))
    ref = {f: package_evaluation_many(f, source, **a) for f, a in pts.items()}
    return pts, ref


@pytest.fixture(scope="module")
def tol(points, source):
    """Per-point relative tolerance: REL, plus FOLD/sqrt(1 - S/S_c) for the force of
    calibrated-capillary (S_c the package's rupture distance)."""
    pts, _ = points
    out = {name: np.full(len(pts[name]["r1"]), REL) for name in ARGS}
    cap = pts["capillary_force"]
    sc = package_evaluation_many("rupture_distance", source, **{
        k: cap[k] for k in ARGS["rupture_distance"]})
    with np.errstate(invalid="ignore", divide="ignore"):
        fold = FOLD / np.sqrt(1.0 - cap["gap"] / sc)
    out["capillary_force"] += np.where(np.isfinite(fold), fold, 0.0)
    for name in ("capillary_force", "rupture_distance"):
        with np.errstate(invalid="ignore", divide="ignore"):
            near = RIDGE / np.sqrt(np.abs(ridge_offset(pts[name])))
        out[name] += np.where(np.isfinite(near), near, 0.0)
    return out


def _compare(name: str, got: np.ndarray, want: np.ndarray,
             tol: np.ndarray | float = REL) -> None:
    nan_w, nan_g = np.isnan(want), np.isnan(got)
    assert np.array_equal(nan_g, nan_w), (
        f"{name}: NaN at {int(np.sum(nan_g & ~nan_w))} points the package computes, "
        f"missing at {int(np.sum(nan_w & ~nan_g))} points it refuses")
    zero = want == 0.0
    assert np.array_equal(got == 0.0, zero), f"{name}: zeros differ"
    ok = ~nan_w & ~zero
    if not np.any(ok):
        return
    rel = np.abs(got[ok] / want[ok] - 1.0)
    worst = np.argmax(rel / np.broadcast_to(tol, got.shape)[ok])
    assert np.all(rel <= np.broadcast_to(tol, got.shape)[ok]), (
        f"{name}: max relative difference {rel.max():.3g} (worst against its tolerance: "
        f"{rel[worst]:.3g})")


def test_design_covers_domain_refusals_and_rupture(points, source):
    """The comparison below is only worth something if every case occurs often."""
    pts, ref = points
    for name, y in ref.items():
        if name not in SHIPPED_CAPILLARY:
            assert np.sum(np.isfinite(y) & (y != 0)) > N // 3, name
        assert np.sum(np.isnan(y)) > 50, name
    for name in ("capillary_force", "capillary_force_refit"):
        assert np.sum(ref[name] == 0.0) > 100, name
        assert np.all(ref[name][np.isfinite(ref[name])] <= 0.0), name
    for name in ("viscous_force_immersed", "viscous_force_bridge"):
        vis = ref[name]
        speed = points[0][name]["approach_speed"]
        assert np.all(np.sign(vis[np.isfinite(vis)]) == np.sign(speed[np.isfinite(vis)]))
    # calibrated-capillary: each generated geometry computed often (planes with two angles
    # also near the ridge), every refusal occurs
    for name in SHIPPED_CAPILLARY:
        a, y = pts[name], ref[name]
        plane = np.isposinf(a["r2"])
        computed = np.isfinite(y) & (y != 0)
        for kind, sel in geometries(a).items():
            if kind in source.table.parts:
                assert np.sum(sel & computed) > 200, (name, kind, np.sum(sel & computed))
            else:  # no table: the package refuses every such point, so must the exports
                assert np.sum(sel & computed) == 0, (name, kind)
        off = ridge_offset(a)
        for kind in (cc.WALL_TWO_ANGLES, cc.PAIR_TWO_ANGLES):  # both pieces, near the ridge
            if kind not in source.table.parts:
                continue
            two = geometries(a)[kind] & computed
            for within, least in ((np.inf, 50), (3.0, 40), (1e-2, 15), (1e-5, 5)):
                with np.errstate(invalid="ignore"):
                    near = two & (np.abs(off) < within)
                    assert np.sum(near & (off <= 0)) > least, (name, kind, within, "below")
                    assert np.sum(near & (off > 0)) > least, (name, kind, within, "above")
        rs = np.minimum(a["r1"], a["r2"])
        with np.errstate(invalid="ignore"):
            two_angles = np.abs(np.radians(a["theta1_deg"] - a["theta2_deg"])) > 1e-9
            refusals = {"theta1 > 70": a["theta1_deg"] > 70.0,
                        "theta2 > 70, two angles": two_angles & (a["theta2_deg"] > 70.0),
                        "v outside": (a["volume"] / rs**3 < 1e-4) | (a["volume"] / rs**3 > 0.1),
                        "ratio > 10": ~plane & (np.maximum(a["r1"], a["r2"]) / rs > 10.0)}
            if cc.PAIR_TWO_ANGLES not in source.table.parts:  # refused without their table
                refusals["two angles, spheres"] = ~plane & two_angles
        for why, sel in refusals.items():
            assert np.sum(sel) > 20 and np.all(np.isnan(y[sel])), (name, why)
        assert np.sum(~np.isfinite(np.stack(list(a.values()))).all(axis=0)) > 0
    gap, y = pts["capillary_force"]["gap"], ref["capillary_force"]
    rs = np.minimum(pts["capillary_force"]["r1"], pts["capillary_force"]["r2"])
    finite = np.isfinite(y) & (y != 0)
    assert np.sum(finite & (gap < 1e-6 * rs)) > 30  # near contact
    assert np.sum(finite & (gap == 0.0)) > 5  # at contact
    assert np.sum(np.isnan(y[gap < 0])) == np.sum(gap < 0) > 5  # overlap
    sc = package_evaluation_many("rupture_distance", source, **{
        k: pts["capillary_force"][k] for k in ARGS["rupture_distance"]})
    with np.errstate(invalid="ignore"):
        near = np.abs(gap / sc - 1.0) < 1e-3
    assert np.sum(near & finite) > 50 and np.sum(near & (y == 0.0)) > 50


def geometries(a: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Which table each point's geometry calls for: a plane or sphere pairs with one angle
    (within the model's tolerance), a plane or sphere pairs with two angles."""
    plane = np.isposinf(a["r2"])
    with np.errstate(invalid="ignore"):
        two = ~(np.abs(np.radians(a["theta1_deg"]) - np.radians(a["theta2_deg"]))
                <= cc.ANGLE_TOL)
    return {"sphere-wall": plane & ~two, "sphere-sphere": ~plane & ~two,
            cc.WALL_TWO_ANGLES: plane & two, cc.PAIR_TWO_ANGLES: ~plane & two}


def _run_python_module(source, pts, d: Path, names=tuple(ARGS)) -> dict[str, np.ndarray]:
    """Write the module for ``source`` into ``d`` and evaluate it at ``pts`` in a subprocess
    where importing wetcontact fails; returns the results and checks scalar calls."""
    module = write_module(d, source)["out"]
    assert Path(module).name == "wetcontact_closures.py"
    for name in names:
        np.save(d / f"{name}_in.npy", np.stack([pts[name][k] for k in ARGS[name]]))
    code = textwrap.dedent(f"""
        import sys
        sys.modules["wetcontact"] = None  # importing the package now fails
        sys.path.insert(0, {str(d)!r})
        import numpy as np
        import wetcontact_closures as wc
        for name in {list(names)!r}:
            x = np.load({str(d)!r} + f"/{{name}}_in.npy")
            np.save({str(d)!r} + f"/{{name}}_out.npy", getattr(wc, name)(*x))
        assert not [m for m in sys.modules if m.startswith("wetcontact.")]
        assert not [m for m in sys.modules if m.split(".")[0] in ("scipy", "skfem", "h5py")]
        print(wc.capillary_force(1e-3, np.inf, 1e-11, 2e-5, 0.07, 20.0, 20.0),
              wc.capillary_force_refit(1e-3, 1e-3, 1e-11, 2e-5, 0.07, 20.0, 30.0))
    """)
    run = subprocess.run([sys.executable, "-I", "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert all(float(x) < 0.0 for x in run.stdout.split())  # scalars in, scalars out
    return {name: np.load(d / f"{name}_out.npy") for name in names}


#: valid inputs of each function, and the impossible value each argument is set to in turn
VALID = {"r1": 1e-3, "r2": 1e-3, "viscosity": 1e-3, "approach_speed": 1.0, "gap": 1e-5,
         "volume": 1e-11, "surface_tension": 0.072, "theta1_deg": 20.0, "theta2_deg": 20.0}
IMPOSSIBLE = {"r1": (0.0, -1e-3), "r2": (0.0, -1e-3), "viscosity": (0.0, -1e-3),
              "volume": (0.0, -1e-11), "surface_tension": (0.0, -0.072), "gap": (-1e-6,)}


def _impossible_points() -> dict[str, dict[str, np.ndarray]]:
    """Per function: the valid point first, then one point per impossible argument value."""
    out = {}
    for name, args in ARGS.items():
        rows = [dict(VALID)] + [{**VALID, a: bad} for a in args if a in IMPOSSIBLE
                                for bad in IMPOSSIBLE[a]]
        out[name] = {a: np.array([r[a] for r in rows]) for a in args}
    return out


def test_impossible_physical_inputs_are_nan_in_both_exports(source, c_program, tmp_path):
    """A negative viscosity gave a negative squeeze force, and a negative surface tension a
    repulsive refitted bridge, in the python module and the C header alike (a new user's
    audit, 2026-11-25); the package refuses such scenes, so every export returns NaN."""
    pts = _impossible_points()
    py = _run_python_module(source, pts, tmp_path)
    for name in ARGS:
        for got in (py[name], _run_c(c_program, pts, name, tmp_path)):
            assert np.isfinite(got[0]) and got[0] != 0.0, name  # the valid point computes
            assert np.all(np.isnan(got[1:])), (name, got)


def _rows(name: str, rows: list[dict[str, float]]) -> dict[str, np.ndarray]:
    return {a: np.array([{**VALID, **r}[a] for r in rows]) for a in ARGS[name]}


def test_usage_notes_hold_in_both_exports(source, c_program, tmp_path):
    """The exports' usage notes (closures.USAGE), for a DEM user: the plane is r2 (r1 = inf
    gives NaN); each angle goes with its own radius, so swapping (r1, theta1) and (r2,
    theta2) between spheres changes nothing; the viscous forces are odd in the approach
    speed."""
    sw = [{"r1": 1e-3, "r2": 2e-3, "theta1_deg": 10.0, "theta2_deg": 40.0},
          {"r1": 2e-3, "r2": 1e-3, "theta1_deg": 40.0, "theta2_deg": 10.0}]
    pts = {"capillary_force": _rows("capillary_force", sw + [{"r1": np.inf, "r2": 1e-3}]),
           "rupture_distance": _rows("rupture_distance", sw + [{"r1": np.inf, "r2": 1e-3}]),
           "viscous_force_bridge": _rows("viscous_force_bridge", [
               {"r2": 2e-3}, {"r1": 2e-3, "r2": 1e-3}, {"r2": 2e-3, "approach_speed": -1.0},
               {"r1": np.inf, "r2": 1e-3}]),
           "viscous_force_immersed": _rows("viscous_force_immersed", [
               {}, {"approach_speed": -1.0}, {"r2": np.inf}, {"r1": np.inf, "r2": 1e-3}])}
    names = tuple(pts)
    py = _run_python_module(source, pts, tmp_path, names=names)
    for got in (py, {n: _run_c(c_program, pts, n, tmp_path) for n in names}):
        for n in ("capillary_force", "rupture_distance"):
            assert np.isfinite(got[n][0]) and got[n][0] == got[n][1], n
            assert np.isnan(got[n][2]), n
        vb, vi = got["viscous_force_bridge"], got["viscous_force_immersed"]
        assert vb[0] > 0 and vb[0] == vb[1] and vb[2] == -vb[0] and np.isnan(vb[3])
        assert vi[0] > 0 and vi[1] == -vi[0] and vi[2] > 0 and np.isnan(vi[3])


def test_usage_notes_figures_against_the_package():
    """The figures of the usage notes: Pitois' (1 - S/H)^2 against `lubrication` outside
    the bridge viscous domain (within 1.6 % below S/H = 0.01, 0.16 % above 0.95, at
    V/R^3 = 0.1 where it is worst), the capillary force's jump to 0 at S_c (3.7 % of its
    contact value for V/R^3 = 0.01, 20 deg, plane), and a large bridge's viscous closure
    still finite just past S_c (so it must be gated by the rupture distance)."""
    from wetcontact.calibrate import make_scene
    from wetcontact.models import get_model

    lub, pit = get_model("lubrication"), get_model("reynolds-finite")
    r = 1e-3
    for r2, lim in ((None, (0.016, 0.0016)), (r, (0.016, 0.0016)), (10 * r, (0.016, 0.0016))):
        rs = r if r2 is None else r * r2 / (r + r2)
        h0 = math.sqrt(0.1 * r**3 / (math.pi * rs))
        for x, bound in ((1e-4, lim[0]), (3e-3, lim[0]), (0.0099, lim[0]), (0.951, lim[1]),
                         (0.99, lim[1])):
            sc = make_scene("sphere-wall" if r2 is None else "sphere-sphere",
                            {"bridge_volume": 0.1 * r**3}, [x * h0 / math.sqrt(1 - x * x)], r2)
            err = pit.force(sc).force_viscous[0] / lub.force(
                sc, preset="accurate").force_viscous[0] - 1
            assert 0 < err <= bound, (r2, x, err)
    cap = get_model("calibrated-capillary")
    base = make_scene("sphere-wall", {"bridge_volume": 0.01 * r**3}, [1e-9], theta=(20.0, 20.0))
    s_c = cap.rupture_distance(base)
    f = cap.force(base.with_gaps([1e-9, s_c * (1 - 1e-9), s_c])).force_capillary
    assert 0.035 < f[1] / f[0] < 0.039 and f[2] == 0
    big = make_scene("sphere-wall", {"bridge_volume": 0.05 * r**3}, [1e-9], theta=(0.0, 0.0))
    past = 1.01 * cap.rupture_distance(big)
    assert get_model("calibrated-viscous").force(big.with_gaps([past])).force_viscous[0] > 0


def test_python_module_numpy_only(points, source, tmp_path, tol):
    pts, ref = points
    got = _run_python_module(source, pts, tmp_path)
    for name in ARGS:
        _compare(name, got[name], ref[name], tol[name])


def test_refit_functions_keep_the_refit_values(source, tmp_path):
    """``*_refit`` are the refitted ``willett`` / ``lian-rupture`` closures (the values the
    exports' ``capillary_force`` / ``rupture_distance`` returned before calibrated-capillary
    shipped; same reference, the refits loaded from the same files), not the shipped
    closure: on equal spheres with one angle, inside both domains, the refit equals its
    package closure to REL and differs from calibrated-capillary by about the refit's own
    error (held-out 2-4 %; calibrated-capillary's is about 1e-5), so above 1e-4 at most
    points."""
    rng = np.random.default_rng(11)
    n = 200
    r1 = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), n))
    th = rng.uniform(0.0, 50.0, n)
    vol = r1**3 * np.exp(rng.uniform(np.log(1e-4), np.log(0.1), n))
    rup = {"r1": r1, "r2": r1.copy(), "volume": vol, "theta1_deg": th, "theta2_deg": th}
    sc = r1 * (1.0 + 0.5 * np.radians(th)) * np.cbrt(vol / r1**3)  # Willett's S_c
    cap = {**rup, "gap": sc * rng.uniform(0.05, 0.5, n),
           "surface_tension": rng.uniform(0.02, 0.08, n)}
    pts = {"rupture_distance": rup, "rupture_distance_refit": rup, "capillary_force": cap,
           "capillary_force_refit": cap}
    got = _run_python_module(source, pts, tmp_path, tuple(pts))
    for name in ("rupture_distance", "capillary_force"):
        refit = package_evaluation_many(name + "_refit", source, **pts[name])
        assert np.all(np.isfinite(refit))
        _compare(name + "_refit", got[name + "_refit"], refit)
        if "sphere-sphere" not in source.table.parts:
            assert np.all(np.isnan(got[name]))  # no table for spheres: the package refuses
            continue
        shipped = got[name]
        assert np.all(np.isfinite(shipped))
        diff = np.abs(got[name + "_refit"] / shipped - 1.0)
        assert np.median(diff) > 1e-4, (name, np.median(diff))


C_DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include "wetcontact_closures.h"

/* argv: function index, n, input file (nargs x n doubles, row-major), output file */
int main(int argc, char **argv)
{
    int f, n, i, nargs;
    double *x, *y;
    FILE *in, *out;
    if (argc != 5) return 2;
    f = atoi(argv[1]);
    n = atoi(argv[2]);
    nargs = f == 1 ? 6 : (f == 2 || f == 4) ? 7 : 5;
    x = malloc(sizeof(double) * (size_t)(nargs * n));
    y = malloc(sizeof(double) * (size_t)n);
    in = fopen(argv[3], "rb");
    if (!x || !y || !in || fread(x, sizeof(double), (size_t)(nargs * n), in)
        != (size_t)(nargs * n)) return 3;
    fclose(in);
    for (i = 0; i < n; ++i) {
        if (f == 0)
            y[i] = wc_viscous_force_immersed(x[i], x[n + i], x[2 * n + i], x[3 * n + i],
                                             x[4 * n + i]);
        else if (f == 1)
            y[i] = wc_viscous_force_bridge(x[i], x[n + i], x[2 * n + i], x[3 * n + i],
                                           x[4 * n + i], x[5 * n + i]);
        else if (f == 2)
            y[i] = wc_capillary_force(x[i], x[n + i], x[2 * n + i], x[3 * n + i],
                                      x[4 * n + i], x[5 * n + i], x[6 * n + i]);
        else if (f == 3)
            y[i] = wc_rupture_distance(x[i], x[n + i], x[2 * n + i], x[3 * n + i],
                                       x[4 * n + i]);
        else if (f == 4)
            y[i] = wc_capillary_force_refit(x[i], x[n + i], x[2 * n + i], x[3 * n + i],
                                            x[4 * n + i], x[5 * n + i], x[6 * n + i]);
        else
            y[i] = wc_rupture_distance_refit(x[i], x[n + i], x[2 * n + i], x[3 * n + i],
                                             x[4 * n + i]);
    }
    out = fopen(argv[4], "wb");
    if (!out || fwrite(y, sizeof(double), (size_t)n, out) != (size_t)n) return 4;
    fclose(out);
    free(x);
    free(y);
    return 0;
}
"""


C_INDEX = {"viscous_force_immersed": 0, "viscous_force_bridge": 1, "capillary_force": 2,
           "rupture_distance": 3, "capillary_force_refit": 4, "rupture_distance_refit": 5}


def _compile(source, d: Path) -> Path:
    """The C driver built against the header for ``source`` (strict C99, warnings fatal)."""
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler (cc) on this machine")
    header = write_header(d, source)["out"]
    assert Path(header).name == "wetcontact_closures.h"
    (d / "driver.c").write_text(C_DRIVER)
    exe = d / "driver"
    run = subprocess.run([cc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2",
                          "-o", str(exe), str(d / "driver.c"), "-lm"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    return exe


def _run_c(exe: Path, pts, name: str, d: Path) -> np.ndarray:
    x = np.ascontiguousarray(np.stack([pts[name][k] for k in ARGS[name]]), dtype="<f8")
    x.tofile(d / "in.bin")
    run = subprocess.run([str(exe), str(C_INDEX[name]), str(x.shape[1]), str(d / "in.bin"),
                          str(d / "out.bin")], capture_output=True, timeout=60)
    assert run.returncode == 0, run.stderr
    return np.fromfile(d / "out.bin", dtype="<f8")


@pytest.fixture(scope="module")
def c_program(source, tmp_path_factory):
    return _compile(source, tmp_path_factory.mktemp("c"))


def test_c_header_matches_package(points, c_program, tmp_path, tol):
    pts, ref = points
    for name in ARGS:
        _compare(name, _run_c(c_program, pts, name, tmp_path), ref[name], tol[name])


C_CONTACT_DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include "wetcontact_closures.h"

/* argv: n, input file (7 x n doubles: capillary_force's arguments), output file. Per point
 * one contact set up once, then the force at GAP_FACTORS times the point's gap, in that
 * order (inside, at contact, past rupture, back inside), through the contact and through
 * wc_capillary_force: 2 x NG x n doubles. */
#define NG 6
int main(int argc, char **argv)
{
    static const double factor[NG] = {1.0, 0.0, 0.5, 1e3, 1.0, -1.0};
    struct wc_capillary_contact c;
    int n, i, k;
    double *x, *y, gap;
    FILE *in, *out;
    if (argc != 4) return 2;
    n = atoi(argv[1]);
    x = malloc(sizeof(double) * (size_t)(7 * n));
    y = malloc(sizeof(double) * (size_t)(2 * NG * n));
    in = fopen(argv[2], "rb");
    if (!x || !y || !in || fread(x, sizeof(double), (size_t)(7 * n), in) != (size_t)(7 * n))
        return 3;
    fclose(in);
    for (i = 0; i < n; ++i) {
        wc_capillary_contact_init(&c, x[i], x[n + i], x[2 * n + i], x[4 * n + i],
                                  x[5 * n + i], x[6 * n + i]);
        for (k = 0; k < NG; ++k) {
            gap = x[3 * n + i] * factor[k];
            y[k * n + i] = wc_capillary_force_at(&c, gap);
            y[(NG + k) * n + i] = wc_capillary_force(x[i], x[n + i], x[2 * n + i], gap,
                                                     x[4 * n + i], x[5 * n + i], x[6 * n + i]);
        }
    }
    out = fopen(argv[3], "wb");
    if (!out || fwrite(y, sizeof(double), (size_t)(2 * NG * n), out) != (size_t)(2 * NG * n))
        return 4;
    fclose(out);
    free(x);
    free(y);
    return 0;
}
"""


def _contact_run(d: Path, cap: dict[str, np.ndarray], out: Path) -> np.ndarray:
    """The contact driver (:data:`C_CONTACT_DRIVER`, compiled in ``d`` beside the header
    there) at the bridges ``cap``: its 6 x n outputs, the contact API's and the direct
    function's (``at``, ``direct``), checked bit for bit equal."""
    (d / "contact.c").write_text(C_CONTACT_DRIVER)
    exe = d / "contact"
    run = subprocess.run([shutil.which("cc"), "-std=c99", "-Wall", "-Wextra", "-pedantic",
                          "-Werror", "-O2", "-o", str(exe), str(d / "contact.c"), "-lm"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    n = cap["r1"].size
    x = np.ascontiguousarray(np.stack([cap[k] for k in ARGS["capillary_force"]]), dtype="<f8")
    x.tofile(out / "in.bin")
    run = subprocess.run([str(exe), str(n), str(out / "in.bin"), str(out / "out.bin")],
                         capture_output=True, timeout=60)
    assert run.returncode == 0, run.stderr
    at, direct = np.fromfile(out / "out.bin", dtype="<f8").reshape(2, 6, n)
    assert np.array_equal(at, direct, equal_nan=True)
    return at


def test_c_contact_api_is_the_force(points, c_program, tmp_path, tol, source):
    """``wc_capillary_contact_init`` once per bridge, then ``wc_capillary_force_at`` at
    gaps that move inside, to contact, past rupture and back (and to an overlap): bit for
    bit ``wc_capillary_force`` at the same arguments (NaN and 0 at the same points), and at
    the point's own gap within the comparison's tolerance of the package; for every
    geometry, planes with two angles among them."""
    pts, ref = points
    cap = pts["capillary_force"]
    n = cap["r1"].size
    at = _contact_run(c_program.parent, cap, tmp_path)
    inside = np.isfinite(at[0]) & (at[0] != 0)
    assert np.sum(inside) > n // 3
    for kind, sel in geometries(cap).items():
        if kind in source.table.parts:
            assert np.sum(inside & sel) > 150, kind
    broke = inside & (at[3] == 0.0)  # inside, then past rupture, then back inside
    assert np.sum(broke) > 200 and np.all(at[4][broke] == at[0][broke])
    assert np.all(at[1][inside] < 0.0)  # at contact: finite, attractive
    assert np.all(np.isnan(at[5][inside & (cap["gap"] > 0)]))  # overlap
    _compare("capillary_force (contact)", at[0], ref["capillary_force"],
             tol["capillary_force"])


#: the array of a piece each table's perturbation moves (the force is carried as the two
#: factors of its low-rank form; the left one's leading entry multiplies the right factor's
#: first row, of norm 1, so it moves the force's exponent by up to 1e-9 at every point)
PERTURBED_ARRAY = {"force": "force_left", "rupture": "rupture"}


def _bumped(piece, table: str):
    """``piece`` with one coefficient of its ``table`` (``force`` or ``rupture``) moved by
    1e-9, in what the package evaluates: the leading entry of :data:`PERTURBED_ARRAY`, or,
    where the piece has the table's tensor train, its first core's G_1[0, 0, 0] (the
    coefficient on T_0 of the first axis: it multiplies the rest of the train's first rank
    component at every point, the train's largest)."""
    train = getattr(piece, f"{table}_train")
    if train is None:
        field = PERTURBED_ARRAY[table]
        arr = getattr(piece, field).copy()
        arr.flat[0] += 1e-9
        return replace(piece, **{field: arr})
    first = train.cores[0].copy()
    first[0, 0, 0] += 1e-9
    return replace(piece, **{f"{table}_train": replace(train, cores=(first, *train.cores[1:]))})


def _with_sections(source, kind: str, change):
    """``source`` with each table of one geometry (the geometry's own, or each band of a
    plane with two angles) replaced by ``change(index, table)``."""
    part = source.table.parts[kind]
    if part.bands:
        part = replace(part, bands=tuple(change(i, h) for i, h in enumerate(part.bands)))
    else:
        part = change(0, part)
    parts = {**source.table.parts, kind: part}
    return replace(source, table=replace(source.table, parts=parts))


def _perturbed(source, kind: str, table: str):
    """``source`` with the leading coefficient of one shipped table (the first theta piece
    of one geometry, of its first band for a plane with two angles; for the force, the
    leading entry of its left factor; of a tensor train, :func:`_bumped`) moved by 1e-9
    (a relative change of up to 1e-9 in
    the force or the rupture distance, 1000x the comparison's 1e-12)."""
    def change(i, sec):
        if i > 0:
            return sec
        return replace(sec, pieces=(_bumped(sec.pieces[0], table), *sec.pieces[1:]))

    return _with_sections(source, kind, change)


def _run_capillary(src, pts, d, language: str) -> dict:
    """The shipped capillary functions of export ``src`` at ``pts``, in ``language``."""
    if language == "python":
        return _run_python_module(src, pts, d, SHIPPED_CAPILLARY)
    exe = _compile(src, d)
    return {name: _run_c(exe, pts, name, d) for name in SHIPPED_CAPILLARY}


@pytest.mark.parametrize("language", ["python", "c"])
@pytest.mark.parametrize("table", ["force", "rupture"])
def test_comparison_sees_a_perturbed_coefficient(points, source, tmp_path, language, table,
                                                 tol):
    """The checker above is sharp: one coefficient of one geometry's table (a plane with
    one angle, sphere pairs, a plane with two) moved by 1e-9 fails it, and only for the
    function and the geometry that table serves."""
    pts, ref = points
    for kind in source.table.parts:
        bad = _perturbed(source, kind, table)
        d = tmp_path / f"{kind}-{table}"
        d.mkdir()
        got = _run_capillary(bad, pts, d, language)
        for name in SHIPPED_CAPILLARY:
            if name == "rupture_distance" and table == "force":
                _compare(name, got[name], ref[name], tol[name])  # force table not used there
                continue
            with pytest.raises(AssertionError, match="relative difference|zeros differ"):
                _compare(name, got[name], ref[name], tol[name])
            other = ~geometries(pts[name])[kind]  # the other geometries: intact
            _compare(name, got[name][other], ref[name][other], tol[name][other])


@pytest.mark.parametrize("language", ["python", "c"])
def test_comparison_sees_the_quadratic_ridge_map(points, source, tmp_path, language, tol):
    """With the two-angle pieces' wall angle mapped linearly instead of quadratically
    toward the ridge (``CapillaryPiece.quadratic``) the exports disagree with the package
    on the two-angle points, and only there."""
    part = source.table.parts.get(cc.WALL_TWO_ANGLES)
    if part is None:
        pytest.skip("the package data has no two-angle table")
    assert part.all_pieces and all(p.quadratic for p in part.all_pieces)
    pts, ref = points
    bad = _with_sections(source, cc.WALL_TWO_ANGLES, lambda i, sec: replace(
        sec, pieces=tuple(replace(p, quadratic=False) for p in sec.pieces)))
    got = _run_capillary(bad, pts, tmp_path, language)
    for name in SHIPPED_CAPILLARY:
        two = geometries(pts[name])[cc.WALL_TWO_ANGLES]
        with pytest.raises(AssertionError, match="relative difference|zeros differ"):
            _compare(name, got[name][two], ref[name][two], tol[name][two])
        _compare(name, got[name][~two], ref[name][~two], tol[name][~two])


def _boundary_design(edge: float, seed: int = 35) -> dict[str, dict[str, np.ndarray]]:
    """Planes with two angles whose sphere angle is at the bands' boundary ``edge`` (deg)
    exactly, 1 and 2 ulps either side, and 1e-12 ... 0.1 deg either side; per angle 12
    bridges (v from 1e-4 to 0.1, the plane's angle 0-70 deg, gaps as :func:`_gaps`)."""
    up, down = np.nextafter(edge, np.inf), np.nextafter(edge, -np.inf)
    angles = [edge, up, down, np.nextafter(up, np.inf), np.nextafter(down, -np.inf)]
    angles += [edge + sign * d for d in (1e-12, 1e-9, 1e-6, 1e-3, 0.1) for sign in (1, -1)]
    rng = np.random.default_rng(seed)
    th1 = np.repeat(angles, 12)
    n = th1.size
    r1 = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), n))
    v = np.exp(rng.uniform(np.log(1e-4), np.log(0.1), n))
    th2 = rng.uniform(0.0, 70.0, n)
    rup = {"r1": r1, "r2": np.full(n, np.inf), "volume": v * r1**3, "theta1_deg": th1,
           "theta2_deg": th2}
    cap = {**rup, "gap": _gaps(rng, r1, th1, v), "surface_tension": rng.uniform(0.02, 0.08, n)}
    cap["gap"] = np.abs(cap["gap"])  # no overlaps here: every point computed or 0
    return {"rupture_distance": rup, "capillary_force": cap}


def _half_alone(half_entry, a: dict[str, np.ndarray], onset=None) -> np.ndarray:
    """The package's capillary force (N) at the plane points ``a`` (``capillary_force``'s
    arguments) from a two-angle table that holds only ``half_entry`` (NaN at the sphere
    angles above its range; b1 mapped from its own range; ``onset``: the table's onset
    series, where an end of the band is the onset angle)."""
    r1 = a["r1"]
    entry = {"bands": [half_entry], **({} if onset is None else {cc.ONSET_KEY: onset})}
    f, _ = cc.force_star(cc.WALL_TWO_ANGLES, a["volume"] / r1**3, np.radians(a["theta1_deg"]),
                         a["gap"] / r1, entry=entry, theta_wall=np.radians(a["theta2_deg"]),
                         precision="double")
    return -(2.0 * np.pi * a["surface_tension"] * r1 * f)


@pytest.mark.parametrize("language", ["python", "c"])
def test_two_angle_bands_meet_at_their_boundary(source, tmp_path, language):
    """A plane with two angles: a sphere angle exactly at the bands' boundary at 35 deg
    belongs to the lower band, one an ulp above it to the upper (the package's rule,
    checked against each band evaluated alone), and the exports agree with the package
    at and around it (ulps to 0.1 deg either side) to the comparison's tolerance. The check
    is sharp: at the boundary the two bands' forces differ by far more than the tolerance
    (their rupture distances meet to round-off, their force tables' low-rank factors do
    not), so a point put in the wrong band fails it."""
    part = source.table.parts.get(cc.WALL_TWO_ANGLES)
    if part is None or len(part.bands) < 2:
        pytest.skip("the package data has no two-angle table in bands")
    k = next(i for i, h in enumerate(part.bands) if h.theta_sphere_hi == 35.0)
    edge = part.bands[k].theta_sphere_hi
    assert part.bands[k + 1].theta_sphere_lo == edge
    pts = _boundary_design(edge)
    cap = pts["capillary_force"]
    ref = {name: package_evaluation_many(name, source, **a) for name, a in pts.items()}
    assert np.all(np.isfinite(ref["rupture_distance"]))
    # the package's rule, from each band alone
    entry = cc.capillary_table()[cc.WALL_TWO_ANGLES]
    first, second = (_half_alone(h, cap, entry.get(cc.ONSET_KEY))
                     for h in entry["bands"][k:k + 2])
    ts = cap["theta1_deg"]
    held = np.degrees(np.radians(ts))  # the sphere's angle as the package holds it
    assert np.array_equal(held, ts)  # (these angles survive the round trip)
    want = np.where(held <= edge, first, second)  # vectorised: a few ulps off
    inside = ref["capillary_force"] != 0.0
    np.testing.assert_allclose(ref["capillary_force"][inside], want[inside], rtol=REL,
                               atol=0.0)
    at = ts == edge
    assert np.sum(at) == 12 and np.sum(ts == np.nextafter(edge, np.inf)) == 12
    jump = np.abs(first[at & inside] / second[at & inside] - 1.0)
    assert jump.size >= 6 and np.median(jump) > 1e-9, jump  # 1000x the tolerance
    # the exports
    got = _run_capillary(source, pts, tmp_path, language)
    for name, a in pts.items():
        with np.errstate(invalid="ignore", divide="ignore"):
            d = np.abs(a["theta2_deg"] - ridge_deg(a["volume"] / a["r1"]**3, a["theta1_deg"]))
            tol = REL + np.where(np.isfinite(RIDGE / np.sqrt(d)), RIDGE / np.sqrt(d), 0.0)
            if name == "capillary_force":
                fold = FOLD / np.sqrt(1.0 - a["gap"] / ref["rupture_distance"])
                tol += np.where(np.isfinite(fold), fold, 0.0)
        _compare(name, got[name], ref[name], tol)
        assert np.sum(np.isfinite(ref[name][at]) & (ref[name][at] != 0)) >= 6, name


def test_c_header_names_shipped_and_refit(source, tmp_path):
    text = Path(write_header(tmp_path, source)["out"]).read_text()
    assert "wc_capillary_force, wc_rupture_distance: the shipped `calibrated-capillary`" in text
    assert "wc_capillary_force_refit, wc_rupture_distance_refit: REFITTED families" in text
    assert "NOT A" in text and "SHIPPED CALIBRATED CLOSURE" in text
    assert f"{100 * source.force.held_out_max:.1f} %" in text
    for kind, part in source.table.parts.items():
        ho = part.held_out
        assert f"force max {ho['force']['max']:.2g}" in text, kind
        for n, piece in (x for sec in part.sections for x in enumerate(sec.pieces)):
            train = piece.force_train
            if train is None:
                assert f"static const double left{n}[{piece.force_left.size}]" in text, kind
                assert f"static const double right{n}[{piece.force_right.size}]" in text, \
                    kind
            else:  # only what is evaluated: the trains' cores, not the fit
                assert f"static const double force_cores{n}[{train.size}]" in text, kind
            if piece.rupture_train is None:  # a rupture table dense or as its train
                assert f"static const double rupture{n}[{piece.rupture.size}]" in text, kind
            else:
                assert f"static const double rupture_cores{n}[" \
                       f"{piece.rupture_train.size}]" in text, kind
            assert f"static const double force{n}[" not in text  # the dense table: not carried
    assert "#include <math.h>" in text and text.count("#include") == 1
    assert "malloc" not in text and "calloc" not in text


def _without_two_angles(source):
    """``source`` as read from a package data file written before the two-angle table."""
    parts = {k: v for k, v in source.table.parts.items() if k != cc.WALL_TWO_ANGLES}
    return replace(source, table=replace(source.table, parts=parts))


@pytest.mark.parametrize("language", ["python", "c"])
def test_a_table_without_two_angles_still_exports(points, source, tmp_path, language):
    """A package data file without ``sphere-wall-two-angles`` (written before it): both
    exports return NaN on planes with two angles (as the package refuses them) and the
    values of the full table, bit for bit, everywhere else."""
    if cc.WALL_TWO_ANGLES not in source.table.parts:
        pytest.skip("the package data has no two-angle table")
    pts, _ = points
    got = {}
    for label, src in (("full", source), ("old", _without_two_angles(source))):
        d = tmp_path / label
        d.mkdir()
        if language == "python":
            got[label] = _run_python_module(src, pts, d, SHIPPED_CAPILLARY)
        else:
            exe = _compile(src, d)
            got[label] = {name: _run_c(exe, pts, name, d) for name in SHIPPED_CAPILLARY}
    for name in SHIPPED_CAPILLARY:
        two = geometries(pts[name])[cc.WALL_TWO_ANGLES]
        full, old = got["full"][name], got["old"][name]
        assert np.sum(np.isfinite(full[two])) > 200
        assert np.all(np.isnan(old[two]))
        assert np.array_equal(old[~two], full[~two], equal_nan=True)


def _table_json(sec) -> dict:
    """One table (a geometry's, or a band's) as the package data lays it out."""
    return {"theta_split": None if sec.split is None else {"chebyshev": sec.split.tolist()},
            "pieces": [{"theta_deg": [p.theta_lo, p.theta_hi], "rupture": p.rupture.tolist(),
                        "force_left": p.force_left.tolist(),
                        "force_right": p.force_right.tolist(),
                        **({"theta_map": "ridge-quadratic"} if p.quadratic else {})}
                       for p in sec.pieces]}


def _entry_json(source, kind: str) -> dict:
    """One geometry of ``source`` as the package data lays it out (lists, None ends; a
    plane with two angles in ``bands``, each with its ``theta_sphere_deg``, and its onset
    series if it has one)."""
    part = source.table.parts[kind]
    if part.bands:
        onset = {} if part.onset is None else {
            cc.ONSET_KEY: {"chebyshev": part.onset.tolist()}}
        return {"bands": [{"theta_sphere_deg": [h.theta_sphere_lo, h.theta_sphere_hi],
                            **_table_json(h)} for h in part.bands],
                "held_out": part.held_out, **onset}
    return {**_table_json(part), "held_out": part.held_out}


def test_two_angle_layout_is_validated(source):
    """The reader accepts the two-angle entry's layout (bands of the sphere's angle, the
    shipped ones ending at the onset angle and 35 deg, or at fixed angles, contiguous from
    0 to 70 deg, each a 2-D ridge series and pieces from 0 to an end at or
    above 70 deg) and refuses it broken (a band's table, the bands' ranges, the former
    top-level layout), naming the file and the field; the one-angle layout still needs
    pieces ending exactly at 70 deg and a 1-D series."""
    from wetcontact.errors import InputError
    from wetcontact.export.closure_tables import TWO_ANGLES
    from wetcontact.export.closures import _capillary_part

    assert TWO_ANGLES == cc.WALL_TWO_ANGLES
    if cc.WALL_TWO_ANGLES not in source.table.parts:
        pytest.skip("the package data has no two-angle table")
    shipped = _entry_json(source, cc.WALL_TWO_ANGLES)
    part = _capillary_part(Path("t.json"), cc.WALL_TWO_ANGLES, shipped)
    assert part.two_angles and not part.pieces and part.split is None
    assert [(h.theta_sphere_lo, h.theta_sphere_hi) for h in part.bands] == [
        (0.0, None), (None, 35.0), (35.0, 70.0)] and part.onset is not None
    # the refusals below on the fixed-range layout (the shipped lowest and highest tables,
    # [0, 35] and [35, 70] deg, no onset series), which the reader accepts as well
    good = {"bands": [{**shipped["bands"][0], "theta_sphere_deg": [0.0, 35.0]},
                       shipped["bands"][-1]], "held_out": shipped["held_out"]}
    part = _capillary_part(Path("t.json"), cc.WALL_TWO_ANGLES, good)
    assert [(h.theta_sphere_lo, h.theta_sphere_hi) for h in part.bands] == [
        (0.0, 35.0), (35.0, 70.0)] and part.onset is None
    for h in part.bands:
        assert h.split.ndim == 2 and h.pieces[-1].theta_hi >= 70.0
        assert all(p.quadratic for p in h.pieces)  # the wall angle quadratic toward the ridge
    one = _entry_json(source, "sphere-sphere")

    def broken(entry, change):
        e = json.loads(json.dumps(entry))
        change(e)
        return e

    def band(i, change):  # a broken band of the two-angle entry
        return broken(good, lambda e: change(e["bands"][i]))

    first = good["bands"][0]
    cases = [
        (cc.WALL_TWO_ANGLES, band(1, lambda h: h["theta_split"].update(
            chebyshev=h["theta_split"]["chebyshev"][0])), "band 1 theta_split of shape"),
        (cc.WALL_TWO_ANGLES, band(0, lambda h: h["pieces"][-1].update(
            theta_deg=[None, 60.0])), "band 0 theta pieces .* an end at or above 70"),
        (cc.WALL_TWO_ANGLES, band(1, lambda h: h["pieces"][0].update(
            theta_deg=[5.0, None])), "band 1 theta pieces .* contiguous from 0"),
        (cc.WALL_TWO_ANGLES, band(0, lambda h: h["pieces"][0].update(
            rupture=h["pieces"][0]["rupture"][0])), "band 0 piece 0: .* rupture 3-D"),
        (cc.WALL_TWO_ANGLES, band(1, lambda h: h.update(theta_split=None)),
         "band 1 theta pieces .* only with a theta_split series"),
        (cc.WALL_TWO_ANGLES, band(0, lambda h: h.update(ridge_margin_deg=-0.3)),
         "band 0 ridge_margin_deg"),
        (cc.WALL_TWO_ANGLES, broken(good, lambda e: e.update(ridge_margin_deg=-0.3)),
         "ridge_margin_deg"),
        (cc.WALL_TWO_ANGLES, band(1, lambda h: h["pieces"][0].update(theta_map="cubic")),
         "band 1 piece 0: theta_map = 'cubic'"),
        # the bands' sphere-angle ranges: finite, increasing, contiguous over [0, 70]
        (cc.WALL_TWO_ANGLES, band(0, lambda h: h.update(theta_sphere_deg=[0.0, 30.0])),
         r"band 1: theta_sphere_deg = \[35.0, 70.0\] \(after 30 deg\)"),
        (cc.WALL_TWO_ANGLES, band(0, lambda h: h.update(theta_sphere_deg=[1.0, 35.0])),
         r"band 0: theta_sphere_deg = \[1.0, 35.0\]"),
        (cc.WALL_TWO_ANGLES, band(1, lambda h: h.update(theta_sphere_deg=[35.0, 60.0])),
         r"end at 60 deg; allowed: 'bands'"),
        (cc.WALL_TWO_ANGLES, band(1, lambda h: h.update(theta_sphere_deg=[35.0, 35.0])),
         r"band 1: theta_sphere_deg = \[35.0, 35.0\]"),
        (cc.WALL_TWO_ANGLES, band(1, lambda h: h.update(theta_sphere_deg=[35.0, "inf"])),
         "band 1: theta_sphere_deg"),
        (cc.WALL_TWO_ANGLES, band(1, lambda h: h.update(theta_sphere_deg=[35.0])),
         "band 1: theta_sphere_deg = \\[35.0\\]"),
        (cc.WALL_TWO_ANGLES, broken(good, lambda e: e.update(bands=[])),
         "field 'bands' = \\[\\]; allowed: 'bands', a list"),
        # the former layout: one table over the whole sphere range, no longer evaluated
        (cc.WALL_TWO_ANGLES, {**{k: v for k, v in first.items() if k != "theta_sphere_deg"},
                              "held_out": good["held_out"]},
         "top-level fields 'pieces'/'theta_split' .* no longer evaluates"),
        ("sphere-wall", broken(_entry_json(source, "sphere-wall"), lambda e: e["pieces"][0]
                               .update(theta_map="ridge-quadratic")), "ends at the split"),
        ("sphere-wall", broken(_entry_json(source, "sphere-wall"), lambda e: e.update(
            ridge_margin_deg=0.3)), "ridge_margin_deg = 0.3; allowed: 0 or absent"),
        ("sphere-sphere", broken(one, lambda e: e["pieces"][-1].update(
            theta_deg=[None, 90.0])), "contiguous from 0 to 70 deg"),
        ("sphere-sphere", broken(one, lambda e: e["theta_split"].update(
            chebyshev=[e["theta_split"]["chebyshev"]] * 2)), "1-D Chebyshev series in a"),
    ]
    for kind, entry, says in cases:
        with pytest.raises(InputError, match="t.json: .*" + says):
            _capillary_part(Path("t.json"), kind, entry)


# ---- json ---------------------------------------------------------------------------------


class _Validator:
    """The schema's validator (the schema itself checked first), given a document's
    :func:`skeleton`: the same verdict as the whole document (tested below, against
    jsonschema on the whole document), in 0.1 s instead of about 40 s for
    calibrated-capillary's 2 million coefficients."""

    def __init__(self) -> None:
        cls = jsonschema.validators.validator_for(schema())
        cls.check_schema(schema())
        self.whole = cls(schema())

    def validate(self, doc: dict) -> None:
        self.whole.validate(skeleton(doc))


def _validator() -> _Validator:
    return _Validator()


def _with_part_copied(doc: dict, i: int) -> dict:
    """``doc`` with its part ``i`` a deep copy, the rest shared: a document to break in one
    part without copying 48 MB of coefficients."""
    return {**doc, "parts": [json.loads(json.dumps(p)) if j == i else p
                             for j, p in enumerate(doc["parts"])]}


def test_json_shipped_matches_table_and_schema(tmp_path):
    from wetcontact.reduced_models.calibrated import viscous_table

    out = tmp_path / "viscous.json"
    assert main(["export", "json", "--closure", "calibrated-viscous", "--out", str(out)]) == 0
    doc = json.loads(out.read_text())
    _validator().validate(doc)
    table = viscous_table()
    parts = {p["name"]: p for p in doc["parts"]}
    wall = parts["immersed sphere-wall"]
    assert wall["coefficients"] == table["immersed"]["sphere-wall"]["chebyshev"]
    lo, hi = wall["domain"]["s_over_r"]
    assert (lo, hi) == pytest.approx((1e-5, 100.0), rel=1e-12, abs=0)
    assert parts["bridge sphere-sphere"]["coefficients"] == table["bridge"]["sphere-sphere"][
        "coefficients"]
    assert wall["held_out"]["relative_error"]["max"] < 1e-8
    assert doc["origin"] == "shipped" and "pushing" in doc["sign_convention"]


def test_json_calibrated_capillary_matches_table_and_schema(tmp_path, source):
    """``--closure calibrated-capillary``: every generated geometry's two tensors (a plane
    with two angles among them, with its 2-D ridge series), their shapes (in the layout),
    domain and held-out errors, exactly as the package data."""
    out = tmp_path / "capillary.json"
    assert main(["export", "json", "--closure", "calibrated-capillary", "--out", str(out)]) == 0
    doc = json.loads(out.read_text())
    _validator().validate(doc)
    assert doc["origin"] == "shipped" and doc["target"] == "capillary"
    assert "attraction < 0" in doc["sign_convention"]
    parts = iter(doc["parts"])
    assert len(doc["parts"]) == 2 * sum(len(p.all_pieces) for p in source.table.parts.values())
    tables = [(k, p, t, pc) for k, p in source.table.parts.items() for t in p.sections
              for pc in t.pieces]
    for kind, part, sec, piece in tables:
        for name, arr, held in (("rupture distance", piece.rupture_table,
                                 "rupture_distance"),
                                ("force", piece.force, "force")):
            p = next(parts)
            assert p["name"].startswith(f"{name} {kind}") and p["geometry"] == kind
            shape = tuple(int(n) for n in p["coefficient_layout"].split("shape (")[-1]
                          .split(")")[0].split(", "))
            assert shape == arr.shape
            coef = np.asarray(p["coefficients"])
            if None in (piece.theta_lo, piece.theta_hi):  # the split series first
                assert np.array_equal(coef[:sec.split.size].reshape(sec.split.shape),
                                      sec.split)
                coef = coef[sec.split.size:]
            assert np.array_equal(coef.reshape(shape), arr)
            assert p["held_out"]["relative_error"]["max"] == part.held_out[held]["max"]
            assert p["domain"]["v"] == [1e-4, 0.1]
            assert ("radius_ratio" in p["domain"]) == kind.startswith("sphere-sphere")
            two, pair = kind == cc.WALL_TWO_ANGLES, kind == cc.PAIR_TWO_ANGLES
            if pair:  # the small sphere's angle over its band, the large one's in the piece
                assert p["domain"]["theta_sphere_deg"] == [sec.theta_sphere_lo,
                                                           sec.theta_sphere_hi]
                assert p["domain"]["theta_large_sphere_deg"] == [
                    piece.theta_lo or 0.0, min(piece.theta_hi or 70.0, 70.0)]
            if two:  # the sphere's angle over its band, the wall's within the piece
                assert p["domain"]["theta_sphere_deg"] == [sec.theta_sphere_lo,
                                                           sec.theta_sphere_hi]
                lo_text = sphere_end_text(sec.theta_sphere_lo)
                assert f"sphere angle {lo_text} to " in p["name"]
                assert "first band whose upper" in p["form"] or name == "force"
                lo, hi = p["domain"]["theta_wall_deg"]
                assert lo == (piece.theta_lo or 0.0) and hi <= 70.0
                assert "cos theta_s + cos theta_w" in p["form"] or name != "force"
                assert "T_j(b1) T_k(b2)" in p["form"]
                assert "deg is evaluated in both" not in p["form"]  # no ridge margin
                assert ("b2 quadratic toward the ridge" in p["form"]) == piece.quadratic
                for stratum in ("near_ridge", "ridge_top"):
                    got = p["held_out"]["strata"][stratum]
                    assert got["relative_error"]["max"] == \
                        part.held_out_strata[stratum][held]["max"]
            assert ("theta_deg" in p["domain"]) == (not (two or pair))


def test_schema_rejects_a_two_angle_part_without_its_angles(source):
    """A part of a wall with two contact angles must name both angles' ranges."""
    if cc.WALL_TWO_ANGLES not in source.table.parts:
        pytest.skip("the package data has no two-angle table")
    doc = json.loads(json.dumps(shipped_document("calibrated-capillary")))
    _validator().validate(doc)
    i = next(i for i, p in enumerate(doc["parts"]) if p["geometry"] == cc.WALL_TWO_ANGLES)
    for key in ("theta_wall_deg", "theta_sphere_deg"):
        bad = _with_part_copied(doc, i)
        bad["parts"][i]["domain"].pop(key)
        with pytest.raises(jsonschema.ValidationError):
            _validator().validate(bad)
    bad = _with_part_copied(doc, i)
    bad["parts"][i]["held_out"]["strata"]["near_ridge"].pop("relative_error")
    with pytest.raises(jsonschema.ValidationError):
        _validator().validate(bad)


@pytest.mark.parametrize("family", ["willett", "lian-rupture", "finite-liquid-bridge-ss",
                                    "mikami-pw", "bagheri"])
def test_json_refit_round_trip(family, tmp_path):
    src = CALIBRATION_DIR / f"{family}.json"
    if not src.is_file():
        pytest.skip(f"{src} not in this checkout")
    out = tmp_path / "refit.json"
    info = write_json(out, coefficients=src)
    doc = json.loads(out.read_text())
    _validator().validate(doc)
    data = json.loads(src.read_text())
    (part,) = doc["parts"]
    assert part["coefficients"] == data["coefficients"]
    assert part["held_out"]["relative_error"]["max"] == data["held_out"]["after"]["max"]
    assert {k: tuple(v) for k, v in part["domain"].items()} == {
        k: tuple(v) for k, v in data["domain"].items()}
    assert doc["origin"] == "refitted" and info["closure"] == family
    # each coefficient named in the formula, in the coefficients' order (issue 58: was
    # bare numbers after "A, B, C in V* and theta" for Mikami)
    rows = part["labelled_coefficients"]
    assert [r["value"] for r in rows] == data["coefficients"]
    assert all(r["name"] and r["term"] for r in rows) and part["formula"]
    if family == "mikami-pw":
        assert [r["name"] for r in rows] == ["a0", "a1", "b0", "b1", "b2", "b3", "c0", "c1"]
        assert rows[3]["term"] == "theta^2 in B"


@pytest.mark.parametrize("mutate", [
    lambda d: d["parts"][0].pop("coefficients"),
    lambda d: d["parts"][0]["domain"].update(s_over_r=[1e-5]),
    lambda d: d["parts"][0]["coefficients"].__setitem__(0, "1.0"),
    lambda d: d.update(origin="guessed"),
    lambda d: d["provenance"].update(source_sha256="abc"),
    lambda d: d["parts"][0]["held_out"].pop("relative_error"),
])
def test_schema_rejects_broken_documents(mutate):
    doc = json.loads(json.dumps(shipped_document("calibrated-viscous")))
    _validator().validate(doc)
    mutate(doc)
    with pytest.raises(jsonschema.ValidationError):
        _validator().validate(doc)


_LONG = [float(x) for x in np.linspace(-1.0, 1.0, 5000)]


@pytest.mark.parametrize("mutate", [
    lambda p: None,
    lambda p: p.update(coefficients=list(_LONG)),
    lambda p: p.update(coefficients=[1, 2.5, -3]),
    lambda p: p.update(coefficients=[*_LONG, "1.0"]),  # a string last, after 5000 numbers
    lambda p: p.update(coefficients=[*_LONG[:10], True, *_LONG]),
    lambda p: p.update(coefficients=[None]),
    lambda p: p.update(coefficients=[]),
    lambda p: p.update(coefficients=[[1.0, 2.0]]),
    lambda p: p.update(coefficients=1.0),
    lambda p: p.update(coefficients=[np.float64(1.5), 2.0]),
    lambda p: p.update(coefficients=[float("nan")]),  # a number to the schema (the writer
    # refuses it: allow_nan=False)
    lambda p: p.pop("coefficients"),
    lambda p: p.update(published=[*_LONG, None]),
    lambda p: p.update(published=[]),
    lambda p: p.update(published=list(_LONG)),
    lambda p: p["domain"].update(s_over_r=[1e-5]),
], ids=["as-written", "long", "ints", "string-last", "bool", "null", "empty", "nested",
        "not-a-list", "numpy-float", "nan", "missing", "published-null", "published-empty",
        "published-long", "bad-domain"])
def test_skeleton_gives_the_whole_documents_verdict(mutate):
    """Validation of a document's :func:`skeleton` (its arrays of numbers cut to one
    number) accepts and refuses exactly what jsonschema does on the whole document; the
    document itself is left as it was."""
    whole = jsonschema.validators.validator_for(schema())(schema())
    doc = json.loads(json.dumps(shipped_document("calibrated-viscous")))
    mutate(doc["parts"][0])
    before = json.dumps(doc, default=float)
    verdicts = []
    for check in (lambda: whole.validate(doc), lambda: _validator().validate(doc)):
        try:
            check()
            verdicts.append(None)
        except jsonschema.ValidationError as exc:
            verdicts.append(list(exc.absolute_path))
    assert verdicts[0] == verdicts[1]  # the same verdict, the same offending element
    assert json.dumps(doc, default=float) == before


def test_skeleton_relies_only_on_what_the_schema_says_of_number_arrays():
    """:func:`skeleton` may cut an array of numbers to one number only while the schema
    asks of it no more than 'an array (of at least one) number': no maximum length, no
    other keyword, and ``finite`` is the plain JSON number."""
    part = schema()["$defs"]["part"]
    assert schema()["$defs"]["finite"] == {"type": "number"}
    for key in NUMBER_ARRAYS:
        spec = part["properties"][key]
        assert set(spec) <= {"description", "type", "minItems", "items"}, key
        assert spec["type"] == "array" and spec.get("minItems", 0) <= 1
        assert spec["items"] == {"$ref": "#/$defs/finite"}
    text = json.dumps(part["allOf"])
    assert not any(key in text for key in NUMBER_ARRAYS)  # no condition on them


def test_cli_errors_are_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"family": "willett", "coefficients": [1.0], "domain": {}}))
    cases = [
        (["export", "json", "--closure", "calibrated-nothing", "--out",
          str(tmp_path / "a")], "allowed: 'calibrated-viscous', 'calibrated-capillary'"),
        (["export", "json", "--coefficients", str(bad), "--out", str(tmp_path / "a")],
         "field 'coefficients' has 1 values"),
        (["export", "c", "--out", str(tmp_path / "no" / "x.h")], "does not exist"),
        (["export", "python", "--out", str(tmp_path), "--capillary",
          str(tmp_path / "missing.json")], "missing.json: no such calibration file"),
        # a trailing separator names a folder: a missing one is not written as a file
        (["export", "python", "--out", str(tmp_path / "pyfolder") + "/"],
         "names a folder that does not exist"),
        (["export", "json", "--closure", "calibrated-viscous", "--out",
          str(tmp_path / "j") + "/"], "names a folder that does not exist"),
    ]
    for argv, says in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and "Traceback" not in err, err
        assert says in err, err
    assert not (tmp_path / "pyfolder").exists() and not (tmp_path / "j").exists()


def test_cli_json_summary(tmp_path, capsys, source):
    assert main(["export", "c", "--out", str(tmp_path), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["functions"] == ["wc_viscous_force_immersed", "wc_viscous_force_bridge",
                                 "wc_capillary_force", "wc_rupture_distance",
                                 "wc_capillary_force_refit", "wc_rupture_distance_refit",
                                 "wc_transfer_fraction", "wc_dynamic_rupture_ratio"]
    assert Path(info["out"]).is_file() and info["wall_time_s"] >= 0
    assert info["bytes"] > 1000


# ---- a two-angle table whose bands end at the onset angle theta_on(V) -------------------

#: the synthetic table's onset series (deg, Chebyshev in a): theta_on = 23.5 + 6 a - 3 a^2,
#: from 14.5 deg (a = -1, v = 1e-4) to 26.5 deg (a = 1, v = 0.1)
ONSET_SERIES = [22.0, 6.0, -1.5]
ONSET_BANDS = [(0.0, None), (None, 35.0), (35.0, 70.0)]


def _onset_entry(shipped: dict) -> dict:
    """The shipped two-angle entry with its bands replaced by three, ``ONSET_BANDS``: [0,
    theta_on] and [theta_on, 35] deg both the shipped lowest band's tables (coefficients
    unchanged: the values are not physical, the package and the exports must only agree)
    and [35, 70] the shipped upper band; theta_on the series ``ONSET_SERIES`` (the shipped
    table's own bands are its lowest, highest and one between: the lowest and highest
    are taken)."""
    lower, upper = shipped["bands"][0], shipped["bands"][-1]
    return {**shipped, cc.ONSET_KEY: {"chebyshev": list(ONSET_SERIES)},
            "bands": [{**lower, "theta_sphere_deg": list(ONSET_BANDS[0])},
                       {**lower, "theta_sphere_deg": list(ONSET_BANDS[1])}, upper]}


@pytest.fixture(scope="module")
def onset(source):
    """``(entry, source)``: the synthetic table (:func:`_onset_entry`) as the package
    evaluates it (``entry=`` of force_star and ridge_deg) and ``source`` carrying it for
    the exports, read by their reader from the same entry."""
    from wetcontact.export.closures import _capillary_part

    table = cc.capillary_table()
    if table is None or cc.WALL_TWO_ANGLES not in table:
        pytest.skip("the package data has no two-angle table")
    entry = _onset_entry(table[cc.WALL_TWO_ANGLES])
    part = _capillary_part(Path("synthetic.json"), cc.WALL_TWO_ANGLES, entry)
    assert [(h.theta_sphere_lo, h.theta_sphere_hi) for h in part.bands] == ONSET_BANDS
    src = replace(source, table=replace(source.table, parts={
        **source.table.parts, cc.WALL_TWO_ANGLES: part}))
    return entry, src


def _held_as(target: np.ndarray) -> np.ndarray:
    """Sphere angles (deg) the package holds (``degrees(radians(x))``) as ``target``
    exactly: x = target or 1 or 2 ulps either side, the first that does (else target)."""
    out, found = target.copy(), np.zeros(target.shape, dtype=bool)
    for step in (0, 1, -1, 2, -2):
        x = target.copy()
        for _ in range(abs(step)):
            x = np.nextafter(x, np.inf if step > 0 else -np.inf)
        hit = ~found & (np.degrees(np.radians(x)) == target)
        out[hit], found[hit] = x[hit], True
    return out


def _onset_reference(entry, cap: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The package's rupture distance (m) and capillary force (N) at plane points with two
    angles (``capillary_force``'s arguments, all inside the domain) from the table
    ``entry``, by the model's formula (``CalibratedCapillary._force``: force_star at
    v = V/r1^3, the angles in radians, s = gap/r1, F = -2 pi sigma r1 f), all points in
    one call; the exports' precision, the accurate preset's: every train summed in double)."""
    r1 = cap["r1"]
    v, t1, t2 = cap["volume"] / r1**3, np.radians(cap["theta1_deg"]), np.radians(
        cap["theta2_deg"])
    _, sc = cc.force_star(cc.WALL_TWO_ANGLES, v, t1, np.zeros(v.size), entry=entry,
                          theta_wall=t2, precision="double")
    f, _ = cc.force_star(cc.WALL_TWO_ANGLES, v, t1, cap["gap"] / r1, entry=entry,
                         theta_wall=t2, precision="double")
    return {"rupture_distance": sc * r1,
            "capillary_force": -(2.0 * np.pi * cap["surface_tension"] * r1 * f)}


@pytest.fixture(scope="module")
def onset_points(onset):
    """``(cap, where, ref)``: planes with two angles inside the domain (capillary_force's
    arguments; v in [1e-4, 0.1], both angles in [0, 70] deg, gaps as :func:`_gaps`
    without overlaps, a third moved near rupture by :func:`near_rupture`): 400 with the
    sphere's angle uniform (the plane's uniform, or at odd indices within 1e-7 ... 3 deg
    of the table's ridge), then per boundary, the onset angle theta_on at the bridge's
    own v (``where["onset"]``) and 35 deg (``where["35"]``), 12 bridges each exactly at it
    (the angle the package holds: :func:`_held_as`), 1 and 2 ulps either side and
    1e-12 ... 0.1 deg either side; ``ref`` the package's values
    (:func:`_onset_reference`)."""
    entry, _ = onset
    rng = np.random.default_rng(41)
    n_uniform, per = 400, 12
    steps = [0, 1, -1, 2, -2]  # ulps
    offsets = [sign * d for d in (1e-12, 1e-9, 1e-6, 1e-3, 0.1) for sign in (1, -1)]
    n_edge = per * (len(steps) + len(offsets))
    n = n_uniform + 2 * n_edge
    r1 = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), n))
    volume = np.exp(rng.uniform(np.log(1e-4), np.log(0.1), n)) * r1**3
    v = np.clip(volume / r1**3, 1e-4, 0.1)  # as the package and the exports compute it
    volume = v * r1**3
    v = volume / r1**3
    on = cc.onset_deg(entry, cc.volume_coordinate(v))  # the package's, over this batch
    th1 = rng.uniform(0.0, 70.0, n)
    where = {"onset": np.zeros(n, dtype=bool), "35": np.zeros(n, dtype=bool)}
    for k, (label, edge) in enumerate((("onset", on), ("35", np.full(n, 35.0)))):
        sl = slice(n_uniform + k * n_edge, n_uniform + (k + 1) * n_edge)
        where[label][sl] = True
        e = edge[sl].reshape(-1, per)  # one row per offset
        rows = []
        for i, step in enumerate(steps):
            x = e[i].copy()
            for _ in range(abs(step)):
                x = np.nextafter(x, np.inf if step > 0 else -np.inf)
            rows.append(_held_as(x))
        rows += [e[len(steps) + i] + d for i, d in enumerate(offsets)]
        th1[sl] = np.concatenate(rows)
    th2 = rng.uniform(0.0, 70.0, n)
    dist = 10.0 ** rng.uniform(-7.0, np.log10(3.0), n) * rng.choice([-1.0, 1.0], n)
    near = np.abs(cc.ridge_deg(v, th1, entry) + dist)
    pick = (np.arange(n) % 2 == 1) & (np.arange(n) < n_uniform) & (near <= 70.0)
    th2 = np.where(pick, near, th2)
    assert np.all(np.abs(np.radians(th1) - np.radians(th2)) > 1e-6)  # two angles, each
    assert np.all((th1 >= 0) & (th1 <= 70) & (th2 >= 0) & (th2 <= 70))  # in the domain
    cap = {"r1": r1, "r2": np.full(n, np.inf), "volume": volume, "gap": np.abs(
        _gaps(rng, r1, th1, v)), "surface_tension": rng.uniform(0.02, 0.08, n),
        "theta1_deg": th1, "theta2_deg": th2}
    # near rupture: not the points near the ridge, where the two implementations' S_c
    # differ by up to RIDGE/sqrt(d) (not FOLD's ulps) and the fold's square root amplifies
    # that beyond the sum of the two terms (measured: 1.8e-10 at d = 2.5e-7 deg, 1 - S/S_c
    # = 1.3e-9, S_c 7.3e-14 apart), a case the comparison's tolerance does not model
    sc = _onset_reference(entry, cap)["rupture_distance"]
    near_rupture(cap, np.where(pick, np.nan, sc), seed=43)
    return cap, where, _onset_reference(entry, cap)


def _onset_tolerance(entry, cap: dict[str, np.ndarray], sc: np.ndarray
                     ) -> dict[str, np.ndarray]:
    """The comparison's tolerance at the points ``cap`` (as :func:`tol`): REL, plus
    RIDGE/sqrt(d) at d deg from the table's ridge, plus FOLD/sqrt(1 - S/S_c) for the force
    (``sc`` the package's rupture distance)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.abs(cap["theta2_deg"] - cc.ridge_deg(cap["volume"] / cap["r1"]**3,
                                                    cap["theta1_deg"], entry))
        ridge = RIDGE / np.sqrt(d)
        fold = FOLD / np.sqrt(1.0 - cap["gap"] / sc)
    ridge = np.where(np.isfinite(ridge), ridge, 0.0)
    return {"rupture_distance": REL + ridge,
            "capillary_force": REL + ridge + np.where(np.isfinite(fold), fold, 0.0)}


def test_onset_bands_package_rule(onset, onset_points, source):
    """The reference and the package's rule at the onset angle. On the shipped table the
    reference's formula (:func:`_onset_reference`) is the model's (package_evaluation,
    through a Scene) to REL. At the onset angle theta_on(V) (the synthetic table's bands
    [0, theta_on], [theta_on, 35]) a point belongs to the first band, an ulp above it to
    the second, as each band evaluated alone says; there the two bands' forces differ by
    far more than the comparison's tolerance (b1 = 1 in the first, -1 in the second), so a
    point put in the wrong band by an export fails the comparison below. Both sides of
    the onset occur within an ulp. The onset series summed term by term in the order of k
    (as the exports sum it) gives the package's value to the bit at every point, which is
    what lets the exports pick the package's band at the onset exactly."""
    entry, _ = onset
    cap, where, ref = onset_points
    sub = {k: x[:40] for k, x in cap.items()}
    shipped = _onset_reference(cc.capillary_table()[cc.WALL_TWO_ANGLES], sub)
    for name, want in shipped.items():
        model = package_evaluation_many(name, source, **{k: sub[k] for k in ARGS[name]})
        np.testing.assert_allclose(want, model, rtol=REL, atol=0.0)
    v = cap["volume"] / cap["r1"]**3
    a = cc.volume_coordinate(v)
    on = cc.onset_deg(entry, a)
    c = np.asarray(ONSET_SERIES)
    plain = (c[0] + c[1] * a) + c[2] * (2.0 * a * a - 1.0)  # the exports' order
    assert np.array_equal(on, plain), (
        "the package's onset (summed term by term, batch-independent) and the exports' "
        f"term-by-term sum differ at {np.sum(on != plain)} points: exactly at theta_on the "
        "package and the exports may then pick different bands")
    assert 14.5 <= on.min() and on.max() <= 26.5
    held = np.degrees(np.radians(cap["theta1_deg"]))
    ulp = np.abs(np.spacing(on))
    at, tiny = where["onset"] & (held == on), where["onset"] & (np.abs(held - on) <= 2 * ulp)
    assert np.sum(at) >= 6 and np.sum(tiny & (held < on)) >= 12 and np.sum(
        tiny & (held > on)) >= 12
    bands = entry["bands"]
    with np.errstate(all="ignore"):  # each band alone, extrapolated beyond its range
        first, second = (_half_alone(bands[k], cap, entry[cc.ONSET_KEY]) for k in (0, 1))
        want = np.where(held <= on, first, second)
        sel = where["onset"] & (ref["capillary_force"] != 0.0)
        jump = np.abs(first[at & sel] / second[at & sel] - 1.0)
    np.testing.assert_allclose(ref["capillary_force"][sel], want[sel], rtol=REL, atol=0.0)
    assert jump.size >= 4 and np.median(jump) > 1e-6, jump  # 1e6 x the tolerance


@pytest.mark.parametrize("language", ["python", "c"])
def test_onset_bands_exports_agree(onset, onset_points, tmp_path, language):
    """A table whose bands end at the onset angle (the synthetic one): both exports agree
    with the package to the comparison's tolerance at every point, at the onset angle and
    35 deg exactly, ulps and 1e-12 ... 0.1 deg either side (0 at the same points), and
    their texts name the bands' ends ``theta_on(V)``. In C also the contact API, bit for
    bit wc_capillary_force."""
    entry, src = onset
    cap, where, ref = onset_points
    pts = {"capillary_force": cap,
           "rupture_distance": {k: cap[k] for k in ARGS["rupture_distance"]}}
    got = _run_capillary(src, pts, tmp_path, language)
    tol = _onset_tolerance(entry, cap, ref["rupture_distance"])
    for name in SHIPPED_CAPILLARY:
        _compare(name, got[name], ref[name], tol[name])
        assert np.all(np.isfinite(ref[name]))
        for label in ("onset", "35"):
            assert np.sum(where[label] & (ref[name] != 0.0)) > 100, (name, label)
    assert np.sum(ref["capillary_force"] == 0.0) > 50
    out = tmp_path / ("wetcontact_closures.py" if language == "python" else
                      "wetcontact_closures.h")
    assert "[0, theta_on(V)] deg, [theta_on(V), 35] deg, [35, 70] deg" in out.read_text()
    if language == "c":
        at = _contact_run(tmp_path, cap, tmp_path)
        _compare("capillary_force (contact)", at[0], ref["capillary_force"],
                 tol["capillary_force"])


def test_onset_layout_is_validated(onset, source):
    """The reader takes a band's end null (the onset angle) with the entry's series
    ``theta_sphere_split`` ([.., null] then [null, ..] contiguous), and a series without a
    null end (the bands as before); it refuses a null end without the series, a series
    that is not a non-empty list of finite numbers, ranges not contiguous, empty or
    decreasing at some volume (the onset angle outside its neighbours' ends), naming the
    file, the field and its value."""
    from wetcontact.errors import InputError
    from wetcontact.export.closures import _capillary_part

    _, src = onset
    good = _entry_json(src, cc.WALL_TWO_ANGLES)
    part = _capillary_part(Path("t.json"), cc.WALL_TWO_ANGLES, good)
    assert [(h.theta_sphere_lo, h.theta_sphere_hi) for h in part.bands] == ONSET_BANDS
    assert part.onset.tolist() == ONSET_SERIES
    shipped = _entry_json(source, cc.WALL_TWO_ANGLES)
    fixed = [{**shipped["bands"][0], "theta_sphere_deg": [0.0, 35.0]}, shipped["bands"][-1]]
    plus = {**shipped, "bands": fixed, cc.ONSET_KEY: {"chebyshev": [20.0]}}
    part = _capillary_part(Path("t.json"), cc.WALL_TWO_ANGLES, plus)
    assert [(h.theta_sphere_lo, h.theta_sphere_hi) for h in part.bands] == [
        (0.0, 35.0), (35.0, 70.0)]

    def broken(change):
        e = json.loads(json.dumps(good))
        change(e)
        return e

    def series(value):
        return lambda e: e.update({cc.ONSET_KEY: value})

    def ranges(*rng):  # the bands' theta_sphere_deg (the first len(rng) bands, tables kept)
        def change(e):
            e["bands"] = [{**h, "theta_sphere_deg": list(r)} for h, r in zip(
                e["bands"] * 2, rng, strict=False)]
        return change

    key = cc.ONSET_KEY
    cases = [
        (lambda e: e.pop(key), r"band 0: theta_sphere_deg = \[0.0, None\], an end null \(the "
         r"onset angle\) in an entry without the field 'theta_sphere_split'; allowed: "),
        (series({"chebyshev": []}), r"field 'theta_sphere_split' = \{'chebyshev': \[\]\}; "
         r"allowed: \{'chebyshev': \[o_0, ..., o_n\]\}, a non-empty list of finite numbers"),
        (series({"chebyshev": [22.0, float("nan")]}), r"field 'theta_sphere_split' = "
         r"\{'chebyshev': \[22.0, nan\]\}; allowed: \{'chebyshev'"),
        (series({"chebyshev": ["22"]}), r"'theta_sphere_split' = \{'chebyshev': \['22'\]\}"),
        (series({"chebyshev": [True]}), r"'theta_sphere_split' = \{'chebyshev': \[True\]\}"),
        (series({"chebyshev": [[22.0, 6.0]]}), r"'theta_sphere_split' = .*non-empty list"),
        (series({"coefficients": [22.0]}), r"'theta_sphere_split' = \{'coefficients'"),
        (series(22.0), r"field 'theta_sphere_split' = 22.0; allowed"),
        (ranges((None, 35.0), (35.0, 70.0)),
         r"band 0: theta_sphere_deg = \[None, 35.0\] \(after 0 deg\)"),
        (ranges((0.0, None), (30.0, 35.0), (35.0, 70.0)),
         r"band 1: theta_sphere_deg = \[30.0, 35.0\] \(after theta_on\(V\) deg\)"),
        (ranges((0.0, 20.0), (None, 35.0), (35.0, 70.0)),
         r"band 1: theta_sphere_deg = \[None, 35.0\] \(after 20 deg\)"),
        (lambda e: (series({"chebyshev": [50.0]})(e), ranges((0.0, 35.0), (35.0, None))(e)),
         r"bands' theta_sphere_deg \[\[0.0, 35.0\], \[35.0, None\]\] end at "
         r"theta_on\(V\) deg; allowed: 'bands'"),
        (ranges((0.0, None), (None, None), (None, 70.0)),
         r"band 1: theta_sphere_deg = \[None, None\], empty or decreasing where the onset "
         r"angle is 14.5 to 26.5 deg"),
        (series({"chebyshev": [40.0]}), r"band 1: theta_sphere_deg = \[None, 35.0\], empty "
         r"or decreasing where the onset angle is 40 to 40 deg \(a in \[-1, 1\]\); allowed"),
        (series({"chebyshev": [5.0, 10.0]}), r"band 0: theta_sphere_deg = \[0.0, None\], "
         r"empty or decreasing where the onset angle is -5 to 15 deg"),
        (ranges((0.0, "null"), (None, 35.0), (35.0, 70.0)),
         r"band 0: theta_sphere_deg = \[0.0, 'null'\]; allowed: 'bands', a list of tables "
         r"each with 'theta_sphere_deg' \[lo, hi\] \(finite, or null for the onset angle"),
    ]
    for change, says in cases:
        with pytest.raises(InputError, match="t.json: sphere-wall-two-angles.*" + says):
            _capillary_part(Path("t.json"), cc.WALL_TWO_ANGLES, broken(change))


def test_onset_json_document(onset):
    """``export json`` of a table whose bands end at the onset angle: the two-angle parts'
    ``theta_sphere_deg`` are the bands' ranges with null for the onset angle, exactly the
    parts with a null end carry the series (``theta_sphere_split``), the document is valid;
    the schema refuses a null end without the series, a series not of numbers or empty,
    and null in another range."""
    from wetcontact.export.calibration_json import capillary_document

    _, src = onset
    doc = capillary_document(src.table)
    _validator().validate(doc)
    doc = json.loads(json.dumps(doc, allow_nan=False))  # null survives the file
    part = src.table.parts[cc.WALL_TWO_ANGLES]
    two = [p for p in doc["parts"] if p["geometry"] == cc.WALL_TWO_ANGLES]
    assert [p["domain"]["theta_sphere_deg"] for p in two] == [
        [h.theta_sphere_lo, h.theta_sphere_hi] for h in part.bands for _ in h.pieces
        for _ in range(2)]
    nulls = [i for i, p in enumerate(doc["parts"]) if None in p["domain"].get(
        "theta_sphere_deg", ()) and p["geometry"] == cc.WALL_TWO_ANGLES]
    assert len(nulls) == 2 * sum(len(h.pieces) for h in part.bands[:2])
    for i, p in enumerate(doc["parts"]):
        if p["geometry"] != cc.WALL_TWO_ANGLES:  # (the pair table's: test_pair_json_document)
            continue
        assert ("theta_sphere_split" in p) == (i in nulls)
        assert ("theta_on(V)" in p["name"]) == (i in nulls), p["name"]
        if i in nulls:
            assert p["theta_sphere_split"]["chebyshev"] == ONSET_SERIES
            assert "an end null is the onset angle" in p["form"] or "force" in p["name"]
    for change in (lambda q: q.pop("theta_sphere_split"),
                   lambda q: q["theta_sphere_split"].update(chebyshev=[]),
                   lambda q: q["theta_sphere_split"]["chebyshev"].__setitem__(0, "22"),
                   lambda q: q["domain"].update(theta_wall_deg=[0.0, None]),
                   lambda q: q["domain"].update(theta_sphere_deg=[0.0])):
        bad = _with_part_copied(doc, nulls[0])
        change(bad["parts"][nulls[0]])
        with pytest.raises(jsonschema.ValidationError):
            _validator().validate(bad)


@pytest.mark.parametrize("language", ["python", "c"])
def test_onset_comparison_sees_a_moved_onset(onset, onset_points, tmp_path, language):
    """The comparison above is sharp at the onset: with the exports' onset series moved by
    1e-9 deg (its leading coefficient) they disagree with the package there (the points
    within ulps above the onset change band, the others' b1 moves by about 1e-10), and
    agree at 35 deg and above, where no band's range is the onset angle."""
    entry, src = onset
    cap, where, ref = onset_points
    part = src.table.parts[cc.WALL_TWO_ANGLES]
    moved = replace(part, onset=part.onset + np.array([1e-9, 0.0, 0.0]))
    bad = replace(src, table=replace(src.table, parts={**src.table.parts,
                                                       cc.WALL_TWO_ANGLES: moved}))
    pts = {"capillary_force": cap,
           "rupture_distance": {k: cap[k] for k in ARGS["rupture_distance"]}}
    got = _run_capillary(bad, pts, tmp_path, language)
    tol = _onset_tolerance(entry, cap, ref["rupture_distance"])
    upper = cap["theta1_deg"] >= 35.0
    for name in SHIPPED_CAPILLARY:
        sel = where["onset"]
        with pytest.raises(AssertionError, match="relative difference|zeros differ"):
            _compare(name, got[name][sel], ref[name][sel], tol[name][sel])
        _compare(name, got[name][upper], ref[name][upper], tol[name][upper])


# ---- two spheres with two contact angles (a synthetic sphere-sphere-two-angles table) ----

#: noise added to every coefficient of the synthetic pair table (times 0.5 per unit of the
#: sum of its indices), so that each coefficient of every axis moves the values: the fitted
#: synthetic bridge alone is low-degree (most coefficients ~1e-17), and an export that
#: mixed up two axes could still agree on it
PAIR_NOISE = {"rupture": 0.02, "force_left": 0.02, "force_right": 0.02, "theta_split": 0.2,
              cc.ONSET_KEY: 0.3}
PAIR_FILE = Path("synthetic-pairs.json")
#: the axis orders of the synthetic pair table's tensor trains (rupture, force), piece by
#: piece, band after band: the gap axis c (4) first, inside and last, each order another
#: permutation, so that every transpose and both ends of the C header's gap series are
#: exercised (the generator would pick the cheapest order; here it need not be)
PAIR_TRAIN_ORDERS = [((3, 1, 0, 2), (4, 3, 2, 1, 0)), ((0, 1, 2, 3), (0, 1, 2, 3, 4)),
                     ((2, 0, 3, 1), (3, 2, 4, 1, 0)), ((1, 3, 2, 0), (1, 4, 0, 3, 2)),
                     ((0, 2, 1, 3), (2, 0, 1, 4, 3)), ((3, 2, 1, 0), (0, 3, 1, 2, 4))]


def _noisy(coef, scale: float, rng: np.random.Generator) -> list:
    """``coef`` plus seeded noise of ``scale`` times 0.5 per unit of the index sum."""
    arr = np.asarray(coef, dtype=float)
    decay = 0.5 ** np.indices(arr.shape).sum(axis=0)
    return (arr + scale * decay * rng.uniform(-1.0, 1.0, arr.shape)).tolist()


def _pair_table(cache_dir: Path) -> dict:
    """The synthetic pair table (:func:`conftest.synthetic_pair_table`, the generator's
    coarse stage on a polynomial bridge) with :data:`PAIR_NOISE` on every coefficient, its
    pieces' tensor trains built again from the noisy fit (as the generator builds them,
    :func:`~wetcontact.generate.calibrated_capillary.train_piece`, over the axis orders
    :data:`PAIR_TRAIN_ORDERS`; the trains are what the package and the exports evaluate)
    and a stand-in held-out table (the model's bound floor and the
    json document read one)."""
    from conftest import synthetic_pair_table

    from wetcontact.generate.calibrated_capillary import train_piece

    table = synthetic_pair_table(cache_dir)
    rng = np.random.default_rng(2611)
    onset = table[cc.ONSET_KEY]
    onset["chebyshev"] = _noisy(onset["chebyshev"], PAIR_NOISE[cc.ONSET_KEY], rng)
    for band in table["bands"]:
        band["theta_split"]["chebyshev"] = _noisy(band["theta_split"]["chebyshev"],
                                                  PAIR_NOISE["theta_split"], rng)
        for piece in band["pieces"]:
            for key in ("rupture", "force_left", "force_right"):
                piece[key] = _noisy(piece[key], PAIR_NOISE[key], rng)
    orders = iter(PAIR_TRAIN_ORDERS)
    for band in table["bands"]:
        band["pieces"] = [train_piece(p, dict(zip(("rupture_train", "force_train"),
                                                  next(orders), strict=True)))
                          for p in band["pieces"]]
    errors = {"max": 1e-4, "mean": 1e-5, "p95": 5e-5, "points": 100}
    table["held_out"] = {"force": errors, "rupture_distance": errors, "seed": 1,
                         "reference": "synthetic (the exports' test)"}
    return table


@pytest.fixture(scope="module")
def pair2(source, tmp_path_factory):
    """``(table, src)``: the synthetic pair table (:func:`_pair_table`) as the package data
    would hold it, and ``source`` carrying it for the exports, read by their reader."""
    from wetcontact.export.closure_tables import PAIR_TWO_ANGLES
    from wetcontact.export.closures import _capillary_part

    assert PAIR_TWO_ANGLES == cc.PAIR_TWO_ANGLES
    table = _pair_table(tmp_path_factory.mktemp("pair2"))
    part = _capillary_part(PAIR_FILE, cc.PAIR_TWO_ANGLES, table)
    assert [(h.theta_sphere_lo, h.theta_sphere_hi) for h in part.bands] == ONSET_BANDS
    assert part.onset.ndim == 2 and all(h.split.ndim == 3 for h in part.bands)
    assert [[p.upper_past_ridge for p in h.pieces] for h in part.bands] == [[False, True]] * 3
    src = replace(source, table=replace(source.table, parts={
        **source.table.parts, cc.PAIR_TWO_ANGLES: part}))
    return table, src


@contextmanager
def _with_pair_table(table: dict):
    """A context in which the model reads ``table`` as the package data's pair table."""
    full = {**cc.capillary_table(), cc.PAIR_TWO_ANGLES: cc.as_arrays({"e": table})["e"]}
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(cc.shipped, "capillary_table", lambda: full)
        yield


def _pair_design(entry: dict, seed: int = 47) -> tuple[dict[str, np.ndarray], dict]:
    """Two spheres with two angles (``capillary_force``'s arguments), ``where`` the labels
    of its strata: 600 uniform (radius ratio 1-10 log-uniform, sphere 2 the smaller at
    half of them, the small sphere's angle and the large one's 0-70 deg, at odd indices
    the large one's within 1e-7 ... 3 deg of the table's ridge, both sides), 40 equal
    spheres (ratio exactly 1: theta1 is sphere 1's), then per band boundary (the onset
    angle at the bridge's own (w, a), and 35 deg) 12 bridges at each of 1e-9 ... 0.1 deg
    either side and exactly at it and 1-2 ulps either side (as the package holds the
    angle: radians and back; the onset is a 2-D series that the package and both exports
    add term by term in one order, so that the python module puts such a point in the
    package's band; C's libm cbrt differs from numpy's by an ulp at about half of all
    ratios, 987 of 2000 measured, so C may take the other band within an ulp or two of the
    onset: ``onset_ulps``, which the C comparison leaves out),
    and 60 outside the domain (ratio 10-12, an angle 70-75 deg, v beyond [1e-4, 0.1]);
    gaps as :func:`_gaps` without overlaps."""
    rng = np.random.default_rng(seed)
    n_uniform, n_equal, per, n_out = 600, 40, 12, 60
    offsets = [sign * d for d in (1e-9, 1e-6, 1e-3, 0.1) for sign in (1, -1)]
    n_onset, n_35 = per * (len(offsets) + 5), per * (len(offsets) + 5)
    n = n_uniform + n_equal + n_onset + n_35 + n_out
    ratio = np.exp(rng.uniform(0.0, np.log(10.0), n))
    ratio[n_uniform:n_uniform + n_equal] = 1.0
    v = np.exp(rng.uniform(np.log(1e-4), np.log(0.1), n))
    small, large = rng.uniform(0.0, 70.0, n), rng.uniform(0.0, 70.0, n)
    lead = [cc.ratio_coordinate(ratio), cc.volume_coordinate(v)]
    on = cc.onset_deg(entry, lead)
    where = {k: np.zeros(n, dtype=bool)
             for k in ("onset", "onset_ulps", "35", "ridge", "outside")}
    lo = n_uniform + n_equal
    where["onset"][lo:lo + n_onset] = True
    at = on[lo:lo + n_onset]
    ulps = [at, *(np.nextafter(at, x) for x in (np.inf, -np.inf)),
            np.nextafter(np.nextafter(at, np.inf), np.inf),
            np.nextafter(np.nextafter(at, -np.inf), -np.inf)]
    k = np.arange(n_onset) // per  # each offset (the ulp steps first) for `per` bridges
    where["onset_ulps"][lo:lo + n_onset] = k < 5
    small[lo:lo + n_onset] = np.where(
        k < 5, _held_as(np.choose(np.minimum(k, 4), ulps)),
        at + np.array([0.0] * 5 + offsets)[k])
    lo += n_onset
    where["35"][lo:lo + n_35] = True
    edge = [35.0, *(np.nextafter(35.0, x) for x in (np.inf, -np.inf)),
            np.nextafter(np.nextafter(35.0, np.inf), np.inf),
            np.nextafter(np.nextafter(35.0, -np.inf), -np.inf)]
    small[lo:lo + n_35] = _held_as(np.repeat(np.array(edge + [35.0 + d for d in offsets]),
                                             per))
    ridge = cc.ridge_deg(v, small, entry, ratio)
    dist = 10.0 ** rng.uniform(-7.0, np.log10(3.0), n) * rng.choice([-1.0, 1.0], n)
    near = (np.arange(n) % 2 == 1) & (np.arange(n) < n_uniform) & (ridge + dist <= 70.0)
    large = np.where(near, np.abs(ridge + dist), large)
    where["ridge"] = near
    out = slice(n - n_out, n)
    where["outside"][out] = True
    k = np.arange(n_out) % 3
    ratio[out] = np.where(k == 0, rng.uniform(10.05, 12.0, n_out), ratio[out])
    large[out] = np.where(k == 1, rng.uniform(70.01, 75.0, n_out), large[out])
    v[out] = np.where(k == 2, rng.choice([5e-5, 0.15], n_out), v[out])
    rs = np.exp(rng.uniform(np.log(1e-5), np.log(1e-2), n))
    swap = rng.uniform(size=n) < 0.5  # sphere 2 the smaller: its angle is theta1
    swap[n_uniform:n_uniform + n_equal] = np.arange(n_equal) % 2 == 1  # r2 == r1
    r1, r2 = np.where(swap, ratio * rs, rs), np.where(swap, rs, ratio * rs)
    th1, th2 = np.where(swap, large, small), np.where(swap, small, large)
    equal = r1 == r2  # theta1 is sphere 1's angle, whichever is smaller
    small, large = np.where(equal, th1, small), np.where(equal, th2, large)
    assert np.all(np.abs(np.radians(th1) - np.radians(th2)) > 1e-6)  # two angles
    cap = {"r1": r1, "r2": r2, "volume": v * rs**3, "gap": np.abs(_gaps(rng, rs, small, v)),
           "surface_tension": rng.uniform(0.02, 0.08, n), "theta1_deg": th1,
           "theta2_deg": th2}
    return cap, {**where, "small": small, "large": large, "v": v, "ratio": ratio}


def _pair_reference(src, cap: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The package's rupture distance and force at ``cap`` through ``calibrated-capillary``
    on Scenes (:func:`package_evaluation_many`: its checks, its angle rule, NaN where it
    refuses)."""
    return {name: package_evaluation_many(name, src, **{k: cap[k] for k in ARGS[name]})
            for name in SHIPPED_CAPILLARY}


@pytest.fixture(scope="module")
def pair2_points(pair2):
    """``(cap, where, ref, tol)``: :func:`_pair_design`, a third of its bridges moved near
    rupture (not those near the ridge, as :func:`onset_points`), the package's values
    through the model (:func:`_pair_reference`) and the comparison's tolerance: REL, plus
    RIDGE/sqrt(d) at d deg from the ridge, plus FOLD/sqrt(1 - S/S_c) for the force, the
    terms and reasons of the shipped comparison (:func:`tol`): the 3-D ridge series is
    summed in another order by each implementation (measured below)."""
    table, src = pair2
    entry = cc.as_arrays({"e": table})["e"]
    cap, where = _pair_design(entry)
    with _with_pair_table(table):
        sc = _pair_reference(src, cap)["rupture_distance"]
        near_rupture(cap, np.where(where["ridge"], np.nan, sc), seed=48)
        ref = _pair_reference(src, cap)
    with np.errstate(invalid="ignore", divide="ignore"):
        ridge = cc.ridge_deg(where["v"], where["small"], entry, where["ratio"])
        rid = RIDGE / np.sqrt(np.abs(where["large"] - ridge))
        fold = FOLD / np.sqrt(1.0 - cap["gap"] / ref["rupture_distance"])
    rid = np.where(np.isfinite(rid), rid, 0.0)
    tol = {"rupture_distance": REL + rid,
           "capillary_force": REL + rid + np.where(np.isfinite(fold), fold, 0.0)}
    return cap, where, ref, tol


def _pair_pieces(entry: dict, where: dict) -> np.ndarray:
    """Per point of :func:`_pair_design`: 2 band + piece (band 0-2, piece 0 below the
    ridge, 1 above), as the package assigns them; -1 outside the domain."""
    lead = [cc.ratio_coordinate(where["ratio"]), cc.volume_coordinate(where["v"])]
    with np.errstate(invalid="ignore"):
        band = cc.band_index(entry, np.degrees(np.radians(where["small"])), lead)
        above = where["large"] > cc.ridge_deg(where["v"], where["small"], entry,
                                              where["ratio"])
    return np.where(where["outside"], -1, 2 * band + above)


@pytest.mark.parametrize("language", ["python", "c"])
def test_pair_two_angles_exports_agree(pair2, pair2_points, tmp_path, language):
    """Two spheres with two angles (the synthetic pair table): both exports agree with the
    package's ``calibrated-capillary`` to the comparison's tolerance at every point, in
    every band and both pieces (each at least 40 computed points), within 1e-9 ... 0.1 deg
    of the onset angle and at 35 deg exactly and ulps around it, near the ridge and near
    rupture, with theta1 the smaller sphere's angle whichever argument it is (sphere 2 the
    smaller at half the points; sphere 1's at equal radii); NaN outside the domain and 0
    past rupture at the same points. In C also the contact API, bit for bit
    wc_capillary_force."""
    table, src = pair2
    cap, where, ref, tol = pair2_points
    entry = cc.as_arrays({"e": table})["e"]
    pts = {"capillary_force": cap,
           "rupture_distance": {k: cap[k] for k in ARGS["rupture_distance"]}}
    got = _run_capillary(src, pts, tmp_path, language)
    which = _pair_pieces(entry, where)
    keep = ~where["onset_ulps"] if language == "c" else np.ones(len(cap["r1"]), dtype=bool)
    for name in SHIPPED_CAPILLARY:
        _compare(name, got[name][keep], ref[name][keep], tol[name][keep])
        computed = np.isfinite(ref[name]) & (ref[name] != 0.0)
        assert np.all(np.isnan(ref[name][where["outside"]])), name
        assert np.all(np.isfinite(ref[name][~where["outside"]])), name
        for k in range(6):
            assert np.sum(computed & (which == k)) >= 40, (name, k)
        for label in ("onset", "35", "ridge"):
            assert np.sum(computed & where[label]) > 60, (name, label)
        swapped = cap["r2"] < cap["r1"]
        assert np.sum(computed & swapped) > 200 and np.sum(computed & ~swapped) > 200
    assert np.sum(ref["capillary_force"] == 0.0) > 50
    out = tmp_path / ("wetcontact_closures.py" if language == "python" else
                      "wetcontact_closures.h")
    assert "[0, theta_on(V)] deg, [theta_on(V), 35] deg, [35, 70] deg" in out.read_text()
    if language == "c":
        at = _contact_run(tmp_path, cap, tmp_path)
        _compare("capillary_force (contact)", at[0][keep], ref["capillary_force"][keep],
                 tol["capillary_force"][keep])


def _pair_changed(src, change):
    """``src`` with each piece of its pair table replaced by ``change(band, i, piece)``."""
    part = src.table.parts[cc.PAIR_TWO_ANGLES]
    part = replace(part, bands=tuple(replace(h, pieces=tuple(
        change(k, i, p) for i, p in enumerate(h.pieces))) for k, h in enumerate(part.bands)))
    return replace(src, table=replace(src.table, parts={**src.table.parts,
                                                        cc.PAIR_TWO_ANGLES: part}))


PAIR_BREAKS = {
    # the piece above the ridge ending at its fixed 70.5 deg instead of 70.5 + theta2* -
    # theta1: its b2 moves at every point above the ridge (the pieces 1, 3, 5)
    "fixed upper end": ((1, 3, 5), lambda k, i, p: replace(p, upper_past_ridge=False)),
    # one coefficient of band 1's upper piece moved by 1e-9 (1000 x the tolerance)
    "band 1 upper rupture": ((3,), lambda k, i, p: _bumped(p, "rupture")
                             if (k, i) == (1, 1) else p),
    "band 2 lower force": ((4,), lambda k, i, p: _bumped(p, "force")
                           if (k, i) == (2, 0) else p),
}


@pytest.mark.parametrize("language", ["python", "c"])
@pytest.mark.parametrize("case", sorted(PAIR_BREAKS))
def test_pair_comparison_is_sharp(pair2, pair2_points, tmp_path, language, case):
    """The comparison above sees a broken pair export: the upper pieces' moving end fixed
    at its number, or one coefficient of one piece moved by 1e-9, fails it on the points of
    the pieces concerned (a force coefficient: the force only) and leaves the other points
    within tolerance."""
    table, src = pair2
    cap, where, ref, tol = pair2_points
    entry = cc.as_arrays({"e": table})["e"]
    pieces, change = PAIR_BREAKS[case]
    pts = {"capillary_force": cap,
           "rupture_distance": {k: cap[k] for k in ARGS["rupture_distance"]}}
    got = _run_capillary(_pair_changed(src, change), pts, tmp_path, language)
    keep = ~where["onset_ulps"] if language == "c" else np.ones(len(cap["r1"]), dtype=bool)
    hit = np.isin(_pair_pieces(entry, where), pieces) & keep
    for name in SHIPPED_CAPILLARY:
        if name == "rupture_distance" and "force" in case:
            _compare(name, got[name][keep], ref[name][keep], tol[name][keep])
            continue
        with pytest.raises(AssertionError, match="relative difference|zeros differ"):
            _compare(name, got[name][hit], ref[name][hit], tol[name][hit])
        rest = ~hit & keep  # C leaves out the points an ulp or two from the onset
        _compare(name, got[name][rest], ref[name][rest], tol[name][rest])


@pytest.mark.parametrize("language", ["python", "c"])
def test_a_pair_table_changes_no_other_value(pair2, pair2_points, points, tmp_path,
                                             language):
    """With the pair table added, the exports return the values without it bit for bit at
    every point of the shipped comparison (planes, sphere pairs with one angle, planes with
    two) and at the pair points outside the domain; without it NaN at every pair point
    (the package refuses two angles between spheres without their table). The shipped
    comparison's sphere pairs with two angles are pair points too: computed with the
    table, NaN without."""
    _, src = pair2
    cap, where, _, _ = pair2_points
    shipped = points[0]
    got = {}
    for label, s in (("with", src), ("without", _without(src, cc.PAIR_TWO_ANGLES))):
        d = tmp_path / label
        d.mkdir()
        pts = {name: {k: np.concatenate([shipped[name][k], cap[k]]) for k in ARGS[name]}
               for name in SHIPPED_CAPILLARY}
        got[label] = _run_capillary(s, pts, d, language)
    n = shipped["capillary_force"]["r1"].size
    for name in SHIPPED_CAPILLARY:
        with_, without = got["with"][name], got["without"][name]
        a = shipped[name]
        with np.errstate(invalid="ignore"):
            two = ~(np.abs(np.radians(a["theta1_deg"]) - np.radians(a["theta2_deg"]))
                    <= cc.ANGLE_TOL)
        pair = np.concatenate([~np.isposinf(a["r2"]) & two, np.ones(cap["r1"].size, bool)])
        assert np.array_equal(with_[~pair], without[~pair], equal_nan=True), name
        assert np.all(np.isnan(without[pair]))
        assert np.sum(np.isfinite(with_[n:])) > 600, name
        assert np.sum(np.isfinite(with_[:n][pair[:n]])) > 20, name


def _without(src, kind: str):
    parts = {k: v for k, v in src.table.parts.items() if k != kind}
    return replace(src, table=replace(src.table, parts=parts))


def test_pair_layout_is_validated(pair2):
    """The reader refuses a broken pair table, naming the file, the field and its value:
    an onset series not 2-D over (w, a), a ridge series not 3-D, a rupture table not 4-D,
    ``upper_past_ridge`` on a piece other than the last or not [null, number], a moving
    upper end that falls to 70 deg or below (checked on a grid of (w, a, b1)), and the
    bands' ranges as on a wall."""
    from wetcontact.errors import InputError
    from wetcontact.export.closures import _capillary_part

    table, _ = pair2
    _capillary_part(PAIR_FILE, cc.PAIR_TWO_ANGLES, table)

    def broken(change):
        e = json.loads(json.dumps(table))
        change(e)
        return e

    key = cc.ONSET_KEY
    cases = [
        (lambda e: e[key].update(chebyshev=e[key]["chebyshev"][0]),
         r"field 'theta_sphere_split' = .*allowed: \{'chebyshev': \[\[o_00, ..., o_0n\], "
         r"...\]\}, a non-empty rectangular list of lists of finite numbers"),
        (lambda e: e[key]["chebyshev"][1].pop(),
         r"field 'theta_sphere_split' = .*rectangular"),
        (lambda e: e["bands"][1]["theta_split"].update(
            chebyshev=e["bands"][1]["theta_split"]["chebyshev"][0]),
         r"band 1 theta_split of shape \(5, 5\); allowed: a finite 3-D Chebyshev series in "
         r"\(w, a, b1\)"),
        (lambda e: e["bands"][0]["pieces"][0].update(
            rupture=e["bands"][0]["pieces"][0]["rupture"][0]),
         r"band 0 piece 0: tables of shapes \(5, 5, 5\) \(rupture\).* rupture 4-D"),
        (lambda e: e["bands"][2]["pieces"][0].update(upper_past_ridge=True),
         r"band 2 piece 0: upper_past_ridge = True \(theta_deg \[0.0, None\]\); allowed: "
         r"absent or false, or true on a sphere pair's last piece \[null, number\]"),
        (lambda e: e["bands"][2]["pieces"][1].update(upper_past_ridge="yes"),
         r"band 2 piece 1: upper_past_ridge = 'yes'"),
        (lambda e: e["bands"][1]["pieces"][1].update(theta_deg=[None, 62.0]),
         r"band 1 theta pieces \[\(0.0, None\), \(None, 62.0\)\]; allowed: contiguous from 0 "
         r"to an end at or above 70 deg"),
        (lambda e: e["bands"][1]["theta_split"]["chebyshev"][0][0].__setitem__(
            0, e["bands"][1]["theta_split"]["chebyshev"][0][0][0] - 10.0),  # ridge - 10 deg
         r"band 1 piece 1: upper_past_ridge end 70.5 \+ theta2\* - theta1 = .* deg at \(w, "
         r"a, b1\) = .*; allowed: above 70 deg and above the ridge everywhere"),
        (lambda e: e["bands"][2].update(theta_sphere_deg=[36.0, 70.0]),
         r"band 2: theta_sphere_deg = \[36.0, 70.0\] \(after 35 deg\)"),
    ]
    for change, says in cases:
        with pytest.raises(InputError, match="synthetic-pairs.json: sphere-sphere-two-angles"
                           ".*" + says):
            _capillary_part(PAIR_FILE, cc.PAIR_TWO_ANGLES, broken(change))
    # a wall's upper_past_ridge: only pairs move their upper end
    wall = json.loads(json.dumps(_onset_entry_from(table)))
    with pytest.raises(InputError, match="upper_past_ridge = True"):
        _capillary_part(PAIR_FILE, cc.WALL_TWO_ANGLES, wall)


def _train_pieces(pair2) -> list[tuple[object, dict]]:
    """Every piece with tensor trains, read by the exports' reader, beside the package's
    own arrays of it (:func:`~wetcontact.reduced_models.calibrated_capillary.as_arrays`):
    the synthetic pair table's, and the shipped table's where its package data has them."""
    from wetcontact.export.closures import _capillary_part

    table, _ = pair2
    entries = [(table, PAIR_FILE)]
    shipped = cc.capillary_table() or {}
    if cc.PAIR_TWO_ANGLES in shipped:
        entries.append((shipped[cc.PAIR_TWO_ANGLES], Path(cc.CAPILLARY_FILE)))
    out = []
    for e, path in entries:
        part = _capillary_part(path, cc.PAIR_TWO_ANGLES, e)
        raw = cc.as_arrays({"e": e})["e"]
        out += [(p, q) for h, g in zip(part.bands, raw["bands"], strict=True)
                for p, q in zip(h.pieces, g["pieces"], strict=True)
                if p.force_train is not None]
    return out


def test_train_dense_tensor_is_the_package_sum(pair2):
    """A piece's dense tables from its tensor trains (``rupture_table``, ``force``: the
    cores contracted, then transposed from the train's axis order back to the table's, what
    the json export writes) sum, at 200 random points of [-1, 1]^d, to the package's own
    train sum (:func:`~wetcontact.reduced_models.calibrated_capillary.train_sum`) within
    1e-12 of exp(sum) (the rupture distance and force are exp of these sums, so the
    difference of the sums is their relative difference; measured up to 5e-14, the dense
    sum adding its 10^5 terms in another order). The force's sum differs from that of the
    fit the train was built from (the low-rank force) by far more where the truncation
    dropped anything (measured up to 1.7e-5), so a table taken from the fit would fail."""
    pieces = _train_pieces(pair2)
    assert len(pieces) >= 6
    rng = np.random.default_rng(53)
    fit_gap = []
    for piece, raw in pieces:
        for dense, train, fit in (
                (piece.rupture_table, raw["rupture_train"], piece.rupture),
                (piece.force, raw["force_train"],
                 np.tensordot(piece.force_left, piece.force_right, 1))):
            assert dense.shape == fit.shape
            x = [rng.uniform(-1.0, 1.0, 200) for _ in dense.shape]
            want = cc.train_sum(train, [cc._cheb_rows(t, n) for t, n in zip(x, dense.shape,
                                                                          strict=True)])
            np.testing.assert_allclose(np.exp(cc.chebyshev_tensor(dense, x)), np.exp(want),
                                       rtol=1e-12, atol=0.0)
            if dense.ndim == 5:  # the force: its train truncated at 1e-5
                fit_gap.append(np.max(np.abs(cc.chebyshev_tensor(fit, x) - want)))
    assert max(fit_gap) > 1e-7


def test_train_layout_is_validated(pair2):
    """The reader refuses a malformed tensor train, naming the file, the piece, the field,
    its value and the allowed layout: a core of the wrong shape (ranks not chained, or the
    wrong axis size), too few cores, an order that is not a permutation of the table's
    axes, stated ranks that are not the cores', a non-finite core, a train that is not a
    dict."""
    from wetcontact.errors import InputError
    from wetcontact.export.closures import _capillary_part

    table, _ = pair2
    where = r"synthetic-pairs.json: sphere-sphere-two-angles band 1 piece 0: field "

    def piece(e):
        return e["bands"][1]["pieces"][0]

    def core(name, k, change):
        def apply(e):
            train = piece(e)[name]
            train["cores"][k] = change(np.asarray(train["cores"][k])).tolist()
        return apply

    cases = [
        (core("force_train", 1, lambda g: g[:, :, :-1]),
         r"'force_train' cores of shapes \[.*\] \(order \[3, 2, 4, 1, 0\]\); want "
         r"\[.*\]; allowed: \{'order'.*"
         r"G_k a finite array of shape \(r_\(k-1\), n_\(o_k\), r_k\).*with table shape "
         r"\(5, 5, 5, 5, 19\)"),
        (core("rupture_train", 0, lambda g: g[:, :-1, :]),
         r"'rupture_train' cores of shapes .*with table shape \(5, 5, 5, 5\)"),
        (core("force_train", 2, lambda g: g.transpose(2, 1, 0)),
         r"'force_train' cores of shapes"),
        (lambda e: piece(e)["force_train"]["cores"].pop(),
         r"'force_train' has 4 cores of shapes .*; want 5, one per axis"),
        (lambda e: piece(e)["rupture_train"].update(order=[0, 1, 2, 2]),
         r"'rupture_train' order = \[0, 1, 2, 2\] \(the table has 4 axes\)"),
        (lambda e: piece(e)["force_train"].update(ranks=[1, 2, 3, 4]),
         r"'force_train' ranks = \[1, 2, 3, 4\], the cores' \[5, "),
        (core("force_train", 0, lambda g: np.where(g == g.flat[0], np.inf, g)),
         r"'force_train' cores not finite"),
        (lambda e: piece(e).update(rupture_train=[1.0, 2.0]),
         r"'rupture_train' = 'list' \(not a dict with 'order' and 'cores'\)"),
    ]
    for change, says in cases:
        e = json.loads(json.dumps(table))
        change(e)
        with pytest.raises(InputError, match=where + says):
            _capillary_part(PAIR_FILE, cc.PAIR_TWO_ANGLES, e)


def _onset_entry_from(table: dict) -> dict:
    """The shipped wall two-angle entry with its last piece flagged ``upper_past_ridge``."""
    shipped = cc.capillary_table()
    if shipped is None or cc.WALL_TWO_ANGLES not in shipped:
        pytest.skip("the package data has no two-angle wall table")
    e = json.loads(json.dumps(shipped[cc.WALL_TWO_ANGLES], default=lambda x: x.tolist()))
    e["bands"][0]["pieces"][-1][cc.UPPER_PAST_RIDGE] = True
    return e


def test_pair_json_document(pair2):
    """``export json`` of a table with the pair table: its parts (two per piece) carry
    axes (w, a, b1, b2), the radius ratio, the small sphere's band and the large sphere's
    range, the 3-D ridge series first where a piece ends at it, the 2-D onset series where
    a band ends at the onset, the moving upper end in name and form; the document is
    valid, and the schema refuses such a part without its angle ranges or ratio."""
    from wetcontact.export.calibration_json import capillary_document

    _, src = pair2
    doc = json.loads(json.dumps(capillary_document(src.table), allow_nan=False))
    _validator().validate(doc)
    part = src.table.parts[cc.PAIR_TWO_ANGLES]
    pairs = [p for p in doc["parts"] if p["geometry"] == cc.PAIR_TWO_ANGLES]
    assert len(pairs) == 2 * len(part.all_pieces)
    it = iter(pairs)
    for band in part.bands:
        for piece in band.pieces:
            for arr in (piece.rupture_table, piece.force):
                p = next(it)
                assert f"shape ({', '.join(map(str, arr.shape))}), axes (w, a, b1, b2" in \
                    p["coefficient_layout"]
                coef = np.asarray(p["coefficients"])
                if None in (piece.theta_lo, piece.theta_hi):
                    assert np.array_equal(coef[:band.split.size].reshape(band.split.shape),
                                          band.split)
                    coef = coef[band.split.size:]
                assert np.array_equal(coef.reshape(arr.shape), arr)
                dom = p["domain"]
                assert dom["radius_ratio"] == [1.0, 10.0] and dom["v"] == [1e-4, 0.1]
                assert dom["theta_sphere_deg"] == [band.theta_sphere_lo, band.theta_sphere_hi]
                assert dom["theta_large_sphere_deg"] == [piece.theta_lo or 0.0, min(
                    piece.theta_hi or 70.0, 70.0)]
                assert ("theta_sphere_split" in p) == (None in dom["theta_sphere_deg"])
                if "theta_sphere_split" in p:
                    assert p["theta_sphere_split"]["chebyshev"] == part.onset.tolist()
                assert ("+ ridge - theta_1" in p["name"]) == piece.upper_past_ridge
                assert "rho (cos theta_1 + cos theta_2)" in p["form"] or "rupture" in p["name"]
    doc["parts"] = pairs  # the refusals below on the pair's parts alone
    _validator().validate(doc)
    i = next(i for i, p in enumerate(doc["parts"]) if "theta_sphere_split" in p)
    for key in ("theta_large_sphere_deg", "theta_sphere_deg", "radius_ratio"):
        bad = _with_part_copied(doc, i)
        bad["parts"][i]["domain"].pop(key)
        with pytest.raises(jsonschema.ValidationError):
            _validator().validate(bad)
    bad = _with_part_copied(doc, i)
    bad["parts"][i]["theta_sphere_split"]["chebyshev"][0][0] = "22"
    with pytest.raises(jsonschema.ValidationError):
        _validator().validate(bad)
