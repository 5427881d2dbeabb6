"""``wetcontact export json|python|c``: the schema, and the exported code against the
package's own evaluation (through its models) at thousands of points.

Reference: :func:`wetcontact.export.closures.package_evaluation`, which goes through
``get_model("calibrated-viscous")`` and the refitted closures of
:func:`wetcontact.calibrate.load_coefficients` (NaN where they refuse). The exported code
repeats the arithmetic in another language, so agreement to 1e-12 relative (a few ulps of
libm's exp/log/acos compounded through the forms) shows it computes the same closures, with
the same domain (NaN at the same points) and the same rupture (0 at the same points).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from wetcontact.cli import main
from wetcontact.export.c_header import write_header
from wetcontact.export.calibration_json import schema, shipped_document, write_json
from wetcontact.export.closures import (
    REFIT_DIR,
    REFIT_FILES,
    capillary_source,
    package_evaluation_many,
)
from wetcontact.export.python_module import write_module

jsonschema = pytest.importorskip("jsonschema")

#: the calibration outputs of a source checkout (``wetcontact calibrate``)
CALIBRATION_DIR = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "calibration"

REL = 1e-12  # a few ulps of libm through exp(f1 - f2 exp(...)); not loosened
N = 1500  # points per function (6000 in all)

ARGS = {
    "viscous_force_immersed": ("r1", "r2", "viscosity", "approach_speed", "gap"),
    "viscous_force_bridge": ("r1", "r2", "viscosity", "volume", "approach_speed", "gap"),
    "rupture_distance": ("r1", "r2", "volume", "theta1_deg", "theta2_deg"),
    "capillary_force": ("r1", "r2", "volume", "gap", "surface_tension", "theta1_deg",
                        "theta2_deg"),
}


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
    return {"viscous_force_immersed": vis, "viscous_force_bridge": bridge,
            "rupture_distance": rup, "capillary_force": cap}


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
    ref = {f: package_evaluation_many(f, source, **a) for f, a in pts.items()}
    return pts, ref


def _compare(name: str, got: np.ndarray, want: np.ndarray) -> None:
    nan_w, nan_g = np.isnan(want), np.isnan(got)
    assert np.array_equal(nan_g, nan_w), (
        f"{name}: NaN at {int(np.sum(nan_g & ~nan_w))} points the package computes, "
        f"missing at {int(np.sum(nan_w & ~nan_g))} points it refuses")
    zero = want == 0.0
    assert np.array_equal(got == 0.0, zero), f"{name}: zeros differ"
    ok = ~nan_w & ~zero
    rel = np.abs(got[ok] / want[ok] - 1.0)
    assert rel.max() <= REL, f"{name}: max relative difference {rel.max():.3g}"


def test_design_covers_domain_refusals_and_rupture(points):
    """The comparison below is only worth something if every case occurs often."""
    _, ref = points
    for name, y in ref.items():
        assert np.sum(np.isfinite(y) & (y != 0)) > N // 3, name
        assert np.sum(np.isnan(y)) > 50, name
    assert np.sum(ref["capillary_force"] == 0.0) > 100
    assert np.all(ref["capillary_force"][np.isfinite(ref["capillary_force"])] <= 0.0)
    for name in ("viscous_force_immersed", "viscous_force_bridge"):
        vis = ref[name]
        speed = points[0][name]["approach_speed"]
        assert np.all(np.sign(vis[np.isfinite(vis)]) == np.sign(speed[np.isfinite(vis)]))


def test_python_module_numpy_only(points, source, tmp_path):
    pts, ref = points
    module = write_module(tmp_path, source)["out"]
    for name, args in pts.items():
        np.save(tmp_path / f"{name}_in.npy", np.stack([args[k] for k in ARGS[name]]))
    code = textwrap.dedent(f"""
        import sys
        sys.modules["wetcontact"] = None  # importing the package now fails
        sys.path.insert(0, {str(tmp_path)!r})
        import numpy as np
        import wetcontact_closures as wc
        for name in {list(ARGS)!r}:
            x = np.load({str(tmp_path)!r} + f"/{{name}}_in.npy")
            np.save({str(tmp_path)!r} + f"/{{name}}_out.npy", getattr(wc, name)(*x))
        assert not [m for m in sys.modules if m.startswith("wetcontact.")]
        assert not [m for m in sys.modules if m.split(".")[0] in ("scipy", "skfem", "h5py")]
        print(wc.capillary_force(1e-3, 1e-3, 1e-11, 2e-5, 0.07, 20.0, 30.0))
    """)
    run = subprocess.run([sys.executable, "-I", "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert Path(module).name == "wetcontact_closures.py"
    assert float(run.stdout) < 0.0  # scalars in, a scalar out
    for name in ARGS:
        _compare(name, np.load(tmp_path / f"{name}_out.npy"), ref[name])


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
    nargs = f == 1 ? 6 : f == 3 ? 7 : 5;
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
            y[i] = wc_rupture_distance(x[i], x[n + i], x[2 * n + i], x[3 * n + i],
                                       x[4 * n + i]);
        else
            y[i] = wc_capillary_force(x[i], x[n + i], x[2 * n + i], x[3 * n + i],
                                      x[4 * n + i], x[5 * n + i], x[6 * n + i]);
    }
    out = fopen(argv[4], "wb");
    if (!out || fwrite(y, sizeof(double), (size_t)n, out) != (size_t)n) return 4;
    fclose(out);
    free(x);
    free(y);
    return 0;
}
"""


@pytest.fixture(scope="module")
def c_program(source, tmp_path_factory):
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler (cc) on this machine")
    d = tmp_path_factory.mktemp("c")
    header = write_header(d, source)["out"]
    assert Path(header).name == "wetcontact_closures.h"
    (d / "driver.c").write_text(C_DRIVER)
    exe = d / "driver"
    run = subprocess.run([cc, "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2",
                          "-o", str(exe), str(d / "driver.c"), "-lm"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    return exe


def test_c_header_matches_package(points, c_program, tmp_path):
    pts, ref = points
    for idx, name in enumerate(ARGS):
        x = np.ascontiguousarray(np.stack([pts[name][k] for k in ARGS[name]]), dtype="<f8")
        x.tofile(tmp_path / "in.bin")
        run = subprocess.run([str(c_program), str(idx), str(N), str(tmp_path / "in.bin"),
                              str(tmp_path / "out.bin")], capture_output=True, timeout=60)
        assert run.returncode == 0, run.stderr
        _compare(name, np.fromfile(tmp_path / "out.bin", dtype="<f8"), ref[name])


def test_c_header_says_capillary_is_a_refit(source, tmp_path):
    text = Path(write_header(tmp_path, source)["out"]).read_text()
    assert "NOT A SHIPPED CALIBRATED CLOSURE" in text
    assert f"{100 * source.force.held_out_max:.1f} %" in text
    assert "CAPILLARY: replace from here" in text
    assert "#include <math.h>" in text and text.count("#include") == 1


# ---- json ---------------------------------------------------------------------------------


def _validator():
    cls = jsonschema.validators.validator_for(schema())
    cls.check_schema(schema())
    return cls(schema())


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
    assert (lo, hi) == pytest.approx((1e-5, 100.0), rel=1e-12)
    assert parts["bridge sphere-sphere"]["coefficients"] == table["bridge"]["sphere-sphere"][
        "coefficients"]
    assert wall["held_out"]["relative_error"]["max"] < 1e-8
    assert doc["origin"] == "shipped" and "pushing" in doc["sign_convention"]


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


def test_cli_errors_are_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"family": "willett", "coefficients": [1.0], "domain": {}}))
    cases = [
        (["export", "json", "--closure", "calibrated-capillary", "--out",
          str(tmp_path / "a")], "calibrated-capillary does not exist"),
        (["export", "json", "--coefficients", str(bad), "--out", str(tmp_path / "a")],
         "coefficients has 1 values"),
        (["export", "c", "--out", str(tmp_path / "no" / "x.h")], "does not exist"),
        (["export", "python", "--out", str(tmp_path), "--capillary",
          str(tmp_path / "missing.json")], "missing.json: no such calibration file"),
    ]
    for argv, says in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and "Traceback" not in err, err
        assert says in err, err


def test_cli_json_summary(tmp_path, capsys, source):
    assert main(["export", "c", "--out", str(tmp_path), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["functions"] == ["wc_viscous_force_immersed", "wc_viscous_force_bridge",
                                 "wc_capillary_force", "wc_rupture_distance"]
    assert Path(info["out"]).is_file() and info["wall_time_s"] >= 0
    assert info["bytes"] > 1000
