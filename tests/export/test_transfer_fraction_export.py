"""``wc_transfer_fraction`` (C header), ``transfer_fraction`` (numpy module) and the JSON
entry against the package's ``calibrated_transfer_fraction``.

Tolerance 1e-12 absolute (issue 56): the exports evaluate the same node values with the
same formulas; only the order of the sums (and libm's cos, cbrt) differ, at 1e-16.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from wetcontact.export.transfer_fraction import FUNCTION, c_text, json_entry, python_text
from wetcontact.reduced_models.transfer_fraction import calibrated_transfer_fraction

sys.path.insert(0, str(Path(__file__).resolve().parent))
from exported import run_c_snippet  # noqa: E402

TOL = 1e-12


def _points(n: int = 400) -> tuple[np.ndarray, ...]:
    """Seeded points over the domain (a quarter on a wall, either body first, a few equal
    spheres with equal angles), and a few outside it (NaN in the exports)."""
    rng = np.random.default_rng(12)
    r1 = np.full(n, 1e-3)
    r2 = 1e-3 * np.exp(rng.uniform(-math.log(10.0), math.log(10.0), n))
    r2[: n // 4] = np.inf
    r2[n // 4: n // 4 + 10] = 1e-3
    small = np.minimum(r1, r2)
    v = small**3 * np.exp(rng.uniform(math.log(1e-4), math.log(0.1), n))
    t1, t2 = rng.uniform(0, 70, n), rng.uniform(0, 70, n)
    t2[n // 4: n // 4 + 5] = t1[n // 4: n // 4 + 5]
    return r1, r2, v, t1, t2


def _package(r1, r2, v, t1, t2) -> np.ndarray:
    return np.array([calibrated_transfer_fraction(a, None if math.isinf(b) else b, c, d, e)
                     for a, b, c, d, e in zip(r1, r2, v, t1, t2, strict=True)])


BAD = [(1e-3, 2e-2, 1e-12, 30.0, 30.0), (1e-3, np.inf, 1e-7, 30.0, 30.0),
       (1e-3, np.inf, 1e-11, 71.0, 30.0), (-1e-3, np.inf, 1e-11, 30.0, 30.0),
       (np.inf, np.inf, 1e-11, 30.0, 30.0), (1e-3, np.inf, math.nan, 30.0, 30.0)]


def test_python_module_matches_package(tmp_path):
    ns: dict = {"np": np, "__all__": []}
    exec(compile(python_text(), "transfer_fraction_export", "exec"), ns)
    pts = _points()
    got = ns["transfer_fraction"](*pts)
    ref = _package(*pts)
    assert np.array_equal(np.isnan(got), np.isnan(ref))
    ok = np.isfinite(ref)
    assert np.max(np.abs(got[ok] - ref[ok])) <= TOL
    for bad in BAD:
        assert math.isnan(ns["transfer_fraction"](*bad))


def test_c_function_matches_package(tmp_path):
    pts = _points()
    rows = [" ".join(repr(float(x)) for x in row) for row in zip(*pts, strict=True)]
    rows += [" ".join(repr(float(x)) for x in b) for b in BAD]
    src = ("#include <math.h>\n#include <stdio.h>\n#define WC_PI 3.141592653589793\n"
           + c_text() + "\nint main(void)\n{\n    double a[5];\n"
           "    while (scanf(\"%lf %lf %lf %lf %lf\", a, a + 1, a + 2, a + 3, a + 4) == 5)\n"
           f"        printf(\"%.17g\\n\", {FUNCTION}(a[0], a[1], a[2], a[3], a[4]));\n"
           "    return 0;\n}\n")
    got = run_c_snippet(tmp_path, src, rows)
    n = len(pts[0])
    ref = _package(*pts)
    assert np.array_equal(np.isnan(got[:n]), np.isnan(ref))
    ok = np.isfinite(ref)
    assert np.max(np.abs(got[:n][ok] - ref[ok])) <= TOL
    assert np.all(np.isnan(got[n:]))


def test_json_entry_carries_tables_and_domain():
    e = json_entry()
    assert e["function"] == FUNCTION
    assert e["domain"]["radius_ratio"] == [1.0, 10.0]
    assert np.asarray(e["lower"]).ndim == 4 and e["band_deg"] > 0
    assert set(e["held_out"]) >= {"max", "mean", "p95", "points", "in_band"}
