"""Export times per format (json, python, c) and the cost of evaluating what was exported.

Writes ``benchmarks/results/export.json`` and ``export.png``. Run:
``python benchmarks/bench_export.py``. Medians of a few runs on a shared 2-core machine:
read them as orders of magnitude.

- writer: the export function in-process (read the tables, build, validate, write);
- command: ``wetcontact export ...`` end to end in a subprocess (interpreter start-up and
  imports included: what a user waits for);
- evaluation: seconds per point of the exported numpy module (1e5 points, vectorised, one
  BLAS thread) and of the C header (1e6 calls in a loop, 1e5 for calibrated-capillary,
  ``cc -O2``, CPU time by ``clock()``; ``wc_capillary_force_at``: 1e6 gaps of one contact
  set up once by ``wc_capillary_contact_init``; two spheres with two contact angles, 20 and
  30 deg, the volume varying over 50 values; and two spheres with every input varying over
  the domain, at contact, with one angle and with two: what a call costs when a contact law
  calls ``wc_capillary_force`` for bridges all different, instead of setting each up once),
  and the compile time of a program including the header.
"""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

# one BLAS thread (before numpy loads): the numpy module's small matrix products on two
# threads contended by other jobs ran several times slower and varied from run to run
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, main_or_chart, median_time, write_json  # noqa: E402

from wetcontact.export.c_header import write_header  # noqa: E402
from wetcontact.export.calibration_json import write_json as export_json  # noqa: E402
from wetcontact.export.closures import REFIT_DIR, REFIT_FILES, capillary_source  # noqa: E402
from wetcontact.export.python_module import write_module  # noqa: E402

C_BENCH = r"""
#include <math.h>
#include <stdio.h>
#include <time.h>
#include "wetcontact_closures.h"

#define TIME(k, n, call) do { c0 = clock(); for (i = 0; i < (n); ++i) acc += (call); \
    t[k] = (double)(clock() - c0) / CLOCKS_PER_SEC / (n); } while (0)

int main(void)
{
    const int n = 1000000, m = 100000;
    double acc = 0.0, t[14];
    struct wc_capillary_contact plane, spheres;
    clock_t c0;
    int i, k;
    TIME(0, n, wc_viscous_force_immersed(1e-3, INFINITY, 1e-3, 0.1, 1e-7 * (1 + i % 1000)));
    TIME(1, n, wc_viscous_force_bridge(1e-3, 2e-3, 1e-3, 1e-11, 0.1, 1e-7 * (1 + i % 100)));
    TIME(2, m, wc_rupture_distance(1e-3, INFINITY, 1e-11 * (1 + i % 50), 20.0, 20.0));
    TIME(3, m, wc_capillary_force(1e-3, INFINITY, 1e-11, 1e-7 * (1 + i % 1000), 0.072, 20.0,
                                  20.0));
    TIME(4, m, wc_rupture_distance(1e-3, 2e-3, 1e-11 * (1 + i % 50), 20.0, 20.0));
    TIME(5, m, wc_capillary_force(1e-3, 2e-3, 1e-11, 1e-7 * (1 + i % 1000), 0.072, 20.0, 20.0));
    TIME(6, n, wc_rupture_distance_refit(1e-3, 1e-3, 1e-11 * (1 + i % 50), 10.0, 30.0));
    TIME(7, n, wc_capillary_force_refit(1e-3, 1e-3, 1e-11, 1e-7 * (1 + i % 1000), 0.072, 10.0,
                                        30.0));
    /* one contact set up once, then the force at a changing gap */
    wc_capillary_contact_init(&plane, 1e-3, INFINITY, 1e-11, 0.072, 20.0, 20.0);
    wc_capillary_contact_init(&spheres, 1e-3, 2e-3, 1e-11, 0.072, 20.0, 20.0);
    TIME(8, n, wc_capillary_force_at(&plane, 1e-7 * (1 + i % 1000)));
    TIME(9, n, wc_capillary_force_at(&spheres, 1e-7 * (1 + i % 1000)));
    /* two spheres with two contact angles (the table evaluated by its tensor trains) */
    TIME(10, m, wc_rupture_distance(1e-3, 2e-3, 1e-11 * (1 + i % 50), 20.0, 30.0));
    TIME(11, m, wc_capillary_force(1e-3, 2e-3, 1e-11 * (1 + i % 50), 1e-7 * (1 + i % 1000),
                                   0.072, 20.0, 30.0));
    /* every input varying (quasi-random sequences): radius ratio 1-10, V/R_s^3 1e-4 to
       0.1, each angle 0-70 deg, at contact (gap 0: the whole evaluation, no early 0 past
       rupture); the first loop gives both spheres one angle, the second two */
#define FRAC(x) ((x) - floor(x))
#define RATIO(i) exp(2.302585092994046 * FRAC((i) * 0.6180339887498949))
#define VOL(i) (1e-13 * exp(6.907755278982137 * FRAC((i) * 0.4142135623730951)))
#define ANGLE(i, c) (70.0 * FRAC((i) * (c)))
    TIME(12, m, wc_capillary_force(1e-3, 1e-3 * RATIO(i), VOL(i), 0.0, 0.072,
                                   ANGLE(i, 0.7320508075688772), ANGLE(i, 0.7320508075688772)));
    TIME(13, m, wc_capillary_force(1e-3, 1e-3 * RATIO(i), VOL(i), 0.0, 0.072,
                                   ANGLE(i, 0.7320508075688772), ANGLE(i, 0.2360679774997897)));
    for (k = 0; k < 14; ++k)
        printf("%.6g ", t[k]);
    printf("%.17g\n", acc);
    return 0;
}
"""
C_NAMES = ("viscous_force_immersed", "viscous_force_bridge", "rupture_distance (plane)",
           "capillary_force (plane)", "rupture_distance (spheres, r = 2)",
           "capillary_force (spheres, r = 2)", "rupture_distance_refit", "capillary_force_refit",
           "capillary_force_at (plane, contact set up once)",
           "capillary_force_at (spheres, r = 2, contact set up once)",
           "rupture_distance (spheres, r = 2, 20 and 30 deg)",
           "capillary_force (spheres, r = 2, 20 and 30 deg)",
           "capillary_force (spheres, every input varying, one angle)",
           "capillary_force (spheres, every input varying, two angles)")

N_PY = 100_000


def main() -> None:
    source = capillary_source()
    tmp = Path(tempfile.mkdtemp(prefix="bench_export_"))
    writers = {
        "json (calibrated-viscous)": lambda: export_json(tmp / "cv.json",
                                                         closure="calibrated-viscous"),
        "json (calibrated-capillary)": lambda: export_json(tmp / "cc.json",
                                                           closure="calibrated-capillary"),
        "json (willett refit)": lambda: export_json(
            tmp / "w.json", coefficients=REFIT_DIR / REFIT_FILES["willett"]),
        "python": lambda: write_module(tmp, capillary_source()),
        "c": lambda: write_header(tmp, capillary_source()),
    }
    writer_s = {name: median_time(fn, repeats=7, warmup=1)[0] for name, fn in writers.items()}
    exe = shutil.which("wetcontact") or str(Path(sys.executable).with_name("wetcontact"))
    commands = {
        "json (calibrated-viscous)": ["json", "--closure", "calibrated-viscous", "--out",
                                      str(tmp / "cv.json")],
        "json (calibrated-capillary)": ["json", "--closure", "calibrated-capillary", "--out",
                                        str(tmp / "cc.json")],
        "python": ["python", "--out", str(tmp)],
        "c": ["c", "--out", str(tmp)],
    }
    command_s = {name: median_time(lambda a=args: subprocess.run(
        [exe, "export", *a], check=True, capture_output=True), repeats=3, warmup=1)[0]
        for name, args in commands.items()}

    spec = importlib.util.spec_from_file_location("wc_bench", tmp / "wetcontact_closures.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    rng = np.random.default_rng(3)
    gap = 1e-3 * np.exp(rng.uniform(np.log(1e-5), np.log(100), N_PY))
    vol = np.full(N_PY, 1e-11)
    sc = mod.rupture_distance(1e-3, 1e-3, vol, 10.0, 30.0)
    cgap = sc * rng.uniform(0.02, 1.0, N_PY)
    def per_point(fn):
        return median_time(fn, repeats=5)[0] / N_PY

    py_eval = {
        "viscous_force_immersed": per_point(lambda: mod.viscous_force_immersed(
            1e-3, np.inf, 1e-3, 0.1, gap)),
        "viscous_force_bridge": per_point(lambda: mod.viscous_force_bridge(
            1e-3, 2e-3, 1e-3, vol, 0.1, gap * 1e-2)),
    }
    for label, r2, t2 in (("plane", np.inf, 20.0), ("spheres, r = 2", 2e-3, 20.0),
                          ("spheres, r = 2, 20 and 30 deg", 2e-3, 30.0)):
        sc = mod.rupture_distance(1e-3, r2, vol, 20.0, t2)
        cgap = sc * rng.uniform(0.0, 1.0, N_PY)
        py_eval[f"rupture_distance ({label})"] = per_point(
            lambda r2=r2, t2=t2: mod.rupture_distance(1e-3, r2, vol, 20.0, t2))
        py_eval[f"capillary_force ({label})"] = per_point(
            lambda r2=r2, t2=t2, cgap=cgap: mod.capillary_force(1e-3, r2, vol, cgap, 0.072,
                                                                20.0, t2))
    i = np.arange(N_PY, dtype=float)  # the C loop's quasi-random inputs, every one varying
    ratio = np.exp(np.log(10.0) * np.modf(i * 0.6180339887498949)[0])
    vary = 1e-13 * np.exp(np.log(1000.0) * np.modf(i * 0.4142135623730951)[0])
    t1 = 70.0 * np.modf(i * 0.7320508075688772)[0]
    for label, t2 in (("one angle", t1), ("two angles", 70.0 * np.modf(
            i * 0.2360679774997897)[0])):
        py_eval[f"capillary_force (spheres, every input varying, {label})"] = per_point(
            lambda t2=t2: mod.capillary_force(1e-3, 1e-3 * ratio, vary, 0.0, 0.072, t1, t2))
    sc = mod.rupture_distance_refit(1e-3, 1e-3, vol, 10.0, 30.0)
    cgap = sc * rng.uniform(0.02, 1.0, N_PY)
    py_eval["rupture_distance_refit"] = per_point(lambda: mod.rupture_distance_refit(
        1e-3, 1e-3, vol, 10.0, 30.0))
    py_eval["capillary_force_refit"] = per_point(lambda: mod.capillary_force_refit(
        1e-3, 1e-3, vol, cgap, 0.072, 10.0, 30.0))
    c_eval, compile_s = None, None
    cc = shutil.which("cc")
    if cc:
        (tmp / "bench.c").write_text(C_BENCH)
        build = [cc, "-std=c99", "-Wall", "-Werror", "-O2", "-o", str(tmp / "bench"),
                 str(tmp / "bench.c"), "-lm"]
        compile_s = median_time(lambda: subprocess.run(build, check=True), repeats=3)[0]
        runs = [subprocess.run([str(tmp / "bench")], check=True, capture_output=True,
                               text=True).stdout.split() for _ in range(3)]
        c_eval = {name: float(np.median([float(r[i]) for r in runs])) for i, name in
                  enumerate(C_NAMES)}
    shutil.rmtree(tmp, ignore_errors=True)
    out = {"writer_median_s": writer_s, "command_median_s": command_s,
           "python_module_s_per_point": py_eval, "python_points": N_PY,
           "c_header_s_per_call": c_eval,
           "c_calls": {"calibrated-capillary": 100_000, "other": 1_000_000,
                       "capillary_force_at": 1_000_000},
           "c_compile_median_s": compile_s,
           "capillary": source.label}
    write_json("export", out)
    chart(writer_s, command_s, py_eval, c_eval)
    print(json.dumps(out, indent=1))


def chart(writer_s: dict[str, float], command_s: dict[str, float],
          py_eval: dict[str, float], c_eval: dict[str, float] | None) -> None:
    """Left: export time per format; right: the cost of evaluating what was exported (numpy
    module per point, C header per call)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(13.0, 5.2),
                                 gridspec_kw={"width_ratios": [1.0, 1.25]})
    names = list(writer_s)
    y = np.arange(len(names))
    ax.barh(y - 0.2, [writer_s[n] * 1e3 for n in names], 0.4, color="tab:blue",
            label="writer (in-process)")
    ax.barh(y + 0.2, [command_s.get(n, np.nan) * 1e3 for n in names], 0.4,
            color="tab:orange", hatch="//", label="wetcontact export (subprocess)")
    ax.set_yticks(y, names, fontsize=8)
    ax.set_xscale("log")
    for k, n in enumerate(names):  # a missing bar says why
        if n not in command_s:
            ax.annotate("no subprocess run timed", (writer_s[n] * 1e3, k + 0.2), fontsize=7,
                        textcoords="offset points", xytext=(4, 0), va="center")
    ax.set_xlabel("ms (median)")
    ax.set_title("export time per format", fontsize=10)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=1)
    funcs = list((c_eval or {}) | py_eval)
    y = np.arange(len(funcs))
    bx.barh(y - 0.2, [py_eval.get(n, np.nan) * 1e6 for n in funcs], 0.4, color="tab:green",
            label="numpy module, per point (1e5 vectorised)")
    if c_eval:
        bx.barh(y + 0.2, [c_eval.get(n, np.nan) * 1e6 for n in funcs], 0.4,
                color="tab:purple", hatch="..", label="C header, per call (cc -O2)")
    for k, n in enumerate(funcs):
        if n not in py_eval:
            bx.annotate("C only (per-contact API)", (c_eval[n] * 1e6 if c_eval and n in c_eval
                                                     else 1e-2, k - 0.2), fontsize=7,
                        textcoords="offset points", xytext=(4, 0), va="center")
    bx.set_yticks(y, funcs, fontsize=8)
    bx.set_xscale("log")
    bx.set_xlabel("us (median)")
    bx.set_title("evaluating the exports (capillary: V = 1e-11 m^3, r1 = 1 mm,\ntheta = 20 "
                 "deg, two angles 20 and 30 deg; every input varying:\nr2/r1 1-10, V/r1^3 "
                 "1e-4 to 0.1, angles 0-70 deg, at contact)", fontsize=9)
    bx.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=1)
    fig.suptitle("wetcontact exports on a shared 2-core machine (medians; other jobs may run)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(RESULTS / "export.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main_or_chart("export", main, lambda d: chart(
        d["writer_median_s"], d["command_median_s"], d["python_module_s_per_point"],
        d["c_header_s_per_call"]))
