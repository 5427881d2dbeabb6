"""Shared test fixtures: scenes built in memory from case-file style dicts."""

from __future__ import annotations

import copy
import math
import os
import sys
from pathlib import Path
from typing import Any

# The suite runs on two pytest-xdist workers (pyproject addopts): one BLAS thread each, so
# that two workers on two cores do not contend with four BLAS threads (small products ran
# 10-20x slower so). Only before numpy is loaded; a worker's subprocesses inherit it.
if os.environ.get("PYTEST_XDIST_WORKER") and "numpy" not in sys.modules:
    for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from wetcontact.models import load_all  # noqa: E402
from wetcontact.scene import Scene, scene_from_dict  # noqa: E402

load_all()  # fill the registry: closures and every solver present

BASE_CASE: dict[str, Any] = {
    "name": "test-scene",
    "geometry": {"kind": "sphere-wall", "radius": 1.0e-3},
    "liquid": {"viscosity": 1.0e-3, "surface_tension": 0.072, "density": 998.0,
               "contact_angle": 0.0},
    "amount": {"immersed": True},
    "motion": {"velocity": 0.1, "gaps": [1e-5, 1e-4]},
}


IMMERSED_TOML = """name = "imm"
[geometry]
kind = "sphere-wall"
radius = 1.0e-3
[liquid]
viscosity = 1.0e-3
surface_tension = 0.072
density = 998.0
[amount]
immersed = true
[motion]
velocity = 0.1
gaps = {gaps}
"""
"""An immersed sphere-wall case file; ``IMMERSED_TOML.format(gaps="[1e-4]")``."""


def make_scene(**tables: dict[str, Any]) -> Scene:
    """Scene from :data:`BASE_CASE` with whole tables replaced, e.g.
    ``make_scene(amount={"film_thickness": 1e-4}, geometry={...})``."""
    data = copy.deepcopy(BASE_CASE)
    for key, val in tables.items():
        data[key] = val
    return scene_from_dict(data)


@pytest.fixture
def scene_factory():
    """The :func:`make_scene` builder as a fixture."""
    return make_scene


# ---- a synthetic two-angle sphere-pair table (calibrate_pairs2 on polynomial bridges) ---


def _pair_w_a(ratio: float, v: float) -> tuple[float, float]:
    from wetcontact.reduced_models import calibrated_capillary as cc

    return (float(cc.ratio_coordinate(np.array(ratio))),
            float(cc.volume_coordinate(np.array(v))))


def synthetic_onset(ratio: float, v: float) -> float:
    """The synthetic bridge's onset angle (deg): bilinear in (w, a)."""
    w, a = _pair_w_a(ratio, v)
    return 25.0 + 2.0 * w - 1.5 * a + 0.5 * w * a


def synthetic_ridge(ratio: float, v: float, t1: float) -> float:
    """The synthetic bridge's ridge theta2* (deg): 6 deg above theta1, linear in w and a."""
    w, a = _pair_w_a(ratio, v)
    return t1 + 6.0 + w + a


def synthetic_rupture(ratio: float, v: float, t1: float, t2: float) -> float:
    """The synthetic bridge's S_c/R_s: log S_c linear in both angles and a."""
    return v ** (1.0 / 3.0) * math.exp(0.1 + 0.01 * t1 + 0.005 * t2
                                       + 0.05 * _pair_w_a(ratio, v)[1])


def synthetic_q(ratio: float, t2: float, c: np.ndarray) -> np.ndarray:
    """The synthetic bridge's force factor q at gap coordinates c."""
    return np.exp(0.2 * c + 0.001 * t2 + 0.01 * _pair_w_a(ratio, 1e-3)[0])


def synthetic_pair_table(cache_dir: Path) -> dict[str, Any]:
    """The coarse stage of :func:`wetcontact.generate.calibrated_capillary_pairs.fit_pair_table`
    on a synthetic bridge whose onset, ridge, rupture distance and force are polynomials of low
    degree in the table's coordinates (the onset in (w, a), the ridge linear in theta1, log
    S_c linear in both angles, log q linear in theta2 and c): the coarse nodes interpolate
    them exactly. The solver and searches are patched only while it runs (a few seconds)."""
    from wetcontact.generate import calibrated_capillary as gen
    from wetcontact.generate import calibrated_capillary_pairs as p2

    def fake_branch(kind, ratio, v, theta, c_nodes, theta2=None):
        t1, t2 = math.degrees(theta), math.degrees(theta2)
        return synthetic_rupture(ratio, v, t1, t2), synthetic_q(ratio, t2, np.asarray(c_nodes))

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(gen, "solve_branch", fake_branch)
        mp.setattr(p2, "pair_onset", lambda r, v, lo, hi, tol, ridge_tol: synthetic_onset(r, v))
        mp.setattr(p2, "split_at", lambda vs: np.array([synthetic_onset(1.0, v) for v in vs]))
        mp.setattr(p2, "pair_ridge",
                   lambda r, v, t1, bracket, tol: (synthetic_ridge(r, v, t1), tol))
        return p2.fit_pair_table("coarse", workers=1, cache_dir=cache_dir)
