"""``wc_dynamic_rupture_ratio`` (C header), ``dynamic_rupture_ratio`` (numpy module) and the
JSON entry against the package's ``dynamic_rupture_ratio``, within 1e-12 relative."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.errors import InputError
from wetcontact.export.dynamic_rupture import FUNCTION, c_text, json_entry, python_text
from wetcontact.reduced_models import dynamic_rupture as dr

sys.path.insert(0, str(Path(__file__).resolve().parent))
from exported import run_c_snippet  # noqa: E402

TOL = 1e-12


OUTSIDE = 7
"""Points of :func:`_points` outside the domain."""


def _points(n: int = 200) -> list[tuple[int, float, float, float, float]]:
    """Seeded points (pair, Ca, V/R^3, theta, R2/R): pairs of any radius ratio with rho in
    the domain (either sphere the larger, V/R*^3 in the domain), and :data:`OUTSIDE` points
    outside (NaN in the exports)."""
    dom = dr.load()["domain"]
    rng = np.random.default_rng(57)
    (c0, c1), (v0, v1), (q0, _) = dom["capillary_number"], dom["volume"], dom["rho"]
    pts = []
    for _ in range(n):
        pair = int(rng.integers(2))
        t0, t1 = dom["theta_deg"]["pair" if pair else "wall"]
        q = float(np.exp(rng.uniform(math.log(q0), -math.log(q0)))) if pair else 1.0
        vs = float(np.exp(rng.uniform(math.log(v0), math.log(v1))))
        pts.append((pair, float(np.exp(rng.uniform(math.log(c0), math.log(c1)))),
                    vs * float(dr.effective_radius(q)) ** 3 if pair else vs,
                    float(rng.uniform(t0, t1)), q))
    tp = dom["theta_deg"]["pair"][1]
    return pts + [(0, c0 / 2, 1e-3, 20.0, 1.0), (1, c1 * 2, 1e-3, 20.0, 1.0),
                  (0, 1e-2, v1 * 2, 20.0, 1.0), (1, 1e-2, 1e-3, tp + 1.0, 1.0),
                  (1, 1e-2, 1e-3, 20.0, 0.5 * q0), (1, 1e-2, 1e-3, 20.0, 2.0 / q0),
                  (0, 1e-2, 1e-3, 20.0, 2.0)]


def _package(pts) -> np.ndarray:
    """The package's closure at each point; NaN where it refuses the input."""
    out = []
    for pair, ca, v, th, q in pts:
        try:
            out.append(dr.dynamic_rupture_ratio("pair" if pair else "wall", ca, v, th, q))
        except InputError:
            out.append(math.nan)
    return np.array(out)


def test_python_module_matches_package():
    ns: dict[str, Any] = {"np": np, "__all__": [], "Any": Any}
    exec(compile(python_text(), "dynamic_rupture_export", "exec"), ns)
    pts = _points()
    got = np.array([ns["dynamic_rupture_ratio"]("pair" if p else "wall", c, v, t, q)
                    for p, c, v, t, q in pts])
    ref = _package(pts)
    assert np.array_equal(np.isnan(got), np.isnan(ref)) and np.isnan(ref).sum() == OUTSIDE
    ok = np.isfinite(ref)
    assert np.max(np.abs(got[ok] / ref[ok] - 1)) <= TOL


def test_c_function_matches_package(tmp_path):
    pts = _points()
    src = ("#include <math.h>\n#include <stdio.h>\n#define WC_PI 3.141592653589793\n"
           + c_text() + "\nint main(void)\n{\n    int k;\n    double a[4];\n"
           "    while (scanf(\"%d %lf %lf %lf %lf\", &k, a, a + 1, a + 2, a + 3) == 5)\n"
           f"        printf(\"%.17g\\n\", {FUNCTION}(k, a[0], a[1], a[2], a[3]));\n"
           "    return 0;\n}\n")
    got = run_c_snippet(tmp_path, src, [f"{p} {c!r} {v!r} {t!r} {q!r}"
                                         for p, c, v, t, q in pts])
    ref = _package(pts)
    assert np.array_equal(np.isnan(got), np.isnan(ref))
    ok = np.isfinite(ref)
    assert np.max(np.abs(got[ok] / ref[ok] - 1)) <= TOL


def test_json_entry_carries_the_form_and_domain():
    e = json_entry()
    assert e["function"] == FUNCTION
    assert set(e["coefficients"]) == {"wall", "pair"}
    assert all(set(c) == set(dr.NAMES) for c in e["coefficients"].values())
    assert set(e["held_out"]) >= {"max", "mean", "points", "pitois_max"}
