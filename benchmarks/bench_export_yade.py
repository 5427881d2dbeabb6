"""Benchmark of ``wetcontact export yade``: Yade's ten capillary files, timed and checked.

Measures, in one run on this machine (2 cores shared with other jobs: the load average is
recorded before and after, and CPU time beside wall time):
- the full ten-file set at Yade's usual density (350 suctions x 80 distances per file,
  theta = 0) with 2 worker processes: wall time, CPU time, rows, Newton solves;
- Yade's own generator (``solveLaplace_uc.py`` from the Debian package's
  ``examples/capillaryLaplaceYoung``, its usual settings: Euler step 2e-6, filling-angle step
  0.3 deg) on one suction value (u* = 10, r = 1), run inside ``yade -n -x`` with a
  two-line shim for its Python-2 ``past.builtins.execfile`` import; its full-set time is
  that times 350 x 10 (its cost per suction varies with u*: an estimate);
- rows of the full set against independent solves (the volume-controlled solver at the
  row's V* and D*, 128 elements): a random sample of 40 rows per file;
- Yade reading the files: two spheres per configuration (r = 1 and 2, off-grid distances
  and suctions), one step, Yade's ``fCap`` and ``vMeniscus`` against ``meniscus`` at that
  volume and gap (force) and at that suction and gap (volume).

Writes ``benchmarks/results/export_yade.json`` and ``export_yade.png``. Run:
``PYTHONPATH=src .venv/bin/python benchmarks/bench_export_yade.py`` (about 5-20 min,
depending on the machine's load).
"""

from __future__ import annotations

import json
import math
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import RESULTS, write_json  # noqa: E402

from wetcontact.export.yade import export_yade, read_table, yade_probe  # noqa: E402
from wetcontact.solver.meniscus import Bridge, solve_suction, solve_volume  # noqa: E402

GENERATOR = Path("/usr/share/doc/yade/examples/capillaryLaplaceYoung")
SIGMA, R1 = 0.072, 1e-3


def _cpu_children() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def full_set(out: Path) -> dict:
    load0 = os.getloadavg()
    c0, t0 = _cpu_children() + time.process_time(), time.perf_counter()
    res = export_yade(0.0, out, n_suctions=350, n_distances=80, workers=2)
    wall = time.perf_counter() - t0
    cpu = _cpu_children() + time.process_time() - c0
    return {"wall_time_s": wall, "cpu_time_s": cpu, "load_before": load0,
            "load_after": os.getloadavg(), "files": res["files"], "suffix": res["suffix"],
            "rows": sum(t["rows"] for t in res["tables"]),
            "solves": sum(t["solves"] for t in res["tables"]),
            "tables": res["tables"]}


def yade_generator(u_star: float = 10.0, ratio: float = 1.0) -> dict | None:
    if shutil.which("yade") is None or not (GENERATOR / "solveLaplace_uc.py").exists():
        print("yade or its generator is not installed: generator timing skipped")
        return None
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for f in ("solveLaplace_uc.py", "solveLiqBridge.py"):
            shutil.copy(GENERATOR / f, tmp / f)
        (tmp / "past").mkdir()
        (tmp / "past" / "__init__.py").write_text("")
        (tmp / "past" / "builtins.py").write_text(
            "def execfile(path, glob=None):\n"
            "    exec(compile(open(path).read(), path, 'exec'), glob)\n")
        (tmp / "gen.py").write_text(
            "import sys, time, json\nsys.path.insert(0, '.')\nimport numpy\n"
            "from math import *\nfrom past.builtins import execfile\n"
            "execfile('solveLaplace_uc.py', globals())\n"
            "t0 = time.perf_counter(); c0 = time.process_time()\n"
            f"data = solveLaplace_uc(0.0, {ratio}, {u_star}, numpy.arange(0, 90.0001, 0.3),"
            " 2e-6, 0)\n"
            "json.dump({'wall_s': time.perf_counter() - t0, 'cpu_s': time.process_time() - c0,"
            " 'rows': data.tolist()}, open('gen_out.json', 'w'))\n")
        load0 = os.getloadavg()
        subprocess.run(["yade", "-n", "-x", "gen.py"], cwd=tmp, capture_output=True,
                       timeout=1800, stdin=subprocess.DEVNULL, check=True)
        out = json.loads((tmp / "gen_out.json").read_text())
    rows = np.array(out["rows"])
    # its rows against meniscus at their V* and D* (unit R2 = 1): the generator's accuracy
    br = Bridge(radius=1.0 / ratio, radius2=1.0, surface_tension=1.0)
    errs = []
    for D, _, V, F, *_ in rows[rows[:, 0] > 0][::4]:
        sol = solve_volume(br, float(D), float(V))
        errs.append(abs(F - sol.force_contact1 / (2 * math.pi)) / abs(F))
    return {"u_star": u_star, "ratio": ratio, "wall_time_s": out["wall_s"],
            "cpu_time_s": out["cpu_s"], "rows": int(rows.shape[0]), "load_before": load0,
            "full_set_estimate_s": out["wall_s"] * 350 * 10,
            "full_set_estimate_cpu_s": out["cpu_s"] * 350 * 10,
            "force_error_vs_meniscus_max": float(max(errs)) if errs else None}


def sample_rows(files: list[str], per_file: int = 40, seed: int = 1) -> dict:
    """Force (relative), suction (absolute, units sigma/R2) and filling angles (deg) of
    sampled rows against solve_volume at the row's V* and D*."""
    rng = np.random.default_rng(seed)
    ef = eu = ed = 0.0
    n = 0
    for f in files:
        ratio, blocks = read_table(Path(f))
        rows = np.vstack(blocks)
        rows = rows[rows[:, 1] > 0]
        br = Bridge(radius=1.0 / ratio, radius2=1.0, surface_tension=1.0)
        for D, u, V, F, d1, d2, *_ in rows[rng.choice(rows.shape[0], per_file, replace=False)]:
            sol = solve_volume(br, float(D), float(V))
            ef = max(ef, abs(F - sol.force_contact1 / (2 * math.pi)) / F)
            eu = max(eu, abs(u + sol.laplace_pressure))
            ed = max(ed, abs(d1 - math.degrees(sol.filling_angle1)),
                     abs(d2 - math.degrees(sol.filling_angle2)))
            n += 1
    return {"rows_checked": n, "max_force_rel_error": ef, "max_suction_abs_error": eu,
            "max_filling_angle_error_deg": ed}


def yade_table(files: list[str], suffix: str, work: Path) -> list[dict]:
    pairs = [(R1, r * R1, Ds * r * R1) for r in (1.0, 2.0) for Ds in (0.0131, 0.0517, 0.1033)]
    u_star = [0.0371, 0.533, 4.71, 27.3]   # for R2 = 2 mm; off the geometric grid
    suctions = [u * SIGMA / (2 * R1) for u in u_star]
    out = yade_probe(files, suffix, pairs, suctions, SIGMA, work)
    table = []
    for o in out:
        if o["vMeniscus"] == 0:
            table.append({**o, "bridge": False})
            continue
        b = Bridge(radius=o["R1"], radius2=o["R2"], surface_tension=SIGMA)
        f_ref = solve_volume(b, o["gap"], o["vMeniscus"]).force_contact1
        v_ref = solve_suction(b, o["gap"], -o["suction"], volume_guess=o["vMeniscus"]).volume
        table.append({"suction_pa": o["suction"], "u_star": o["suction"] * o["R2"] / SIGMA,
                      "ratio": o["R2"] / o["R1"], "gap_m": o["gap"],
                      "d_star": o["gap"] / o["R2"], "yade_force_n": o["fCap"],
                      "reference_force_n": f_ref, "force_error": o["fCap"] / f_ref - 1,
                      "yade_volume_m3": o["vMeniscus"], "reference_volume_m3": v_ref,
                      "volume_error": o["vMeniscus"] / v_ref - 1, "bridge": True})
    return table


def chart(data: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    rows = [r for r in data["yade_comparison"] if r["bridge"]]
    for ratio, mk in ((1.0, "o"), (2.0, "s")):
        sel = [r for r in rows if abs(r["ratio"] - ratio) < 1e-9]
        a.scatter([r["u_star"] for r in sel], [abs(r["force_error"]) for r in sel], marker=mk,
                  label=f"force, r = {ratio:g}")
        a.scatter([r["u_star"] for r in sel], [abs(r["volume_error"]) for r in sel],
                  marker=mk, facecolors="none", edgecolors="k", label=f"volume, r = {ratio:g}")
    a.axhline(5e-3, color="r", lw=0.8, label="0.5 %")
    a.set(xscale="log", yscale="log", xlabel="u* = u R2 / sigma",
          ylabel="|Yade / meniscus - 1|", title="Yade reading the exported files (theta = 0)")
    a.legend(fontsize=7)
    gen = data.get("yade_generator")
    names = ["wetcontact, 10 files\n(2 processes)"]
    vals = [data["full_set"]["wall_time_s"]]
    if gen:
        names.append("Yade's generator\n(estimate: 1 suction x 3500)")
        vals.append(gen["full_set_estimate_s"])
    b.bar(names, vals, color=["tab:blue", "tab:gray"][:len(vals)])
    b.set(yscale="log", ylabel="wall time (s)", title="Full set, 350 suctions x 80 distances")
    fig.tight_layout()
    fig.savefig(RESULTS / "export_yade.png", dpi=120)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        fs = full_set(tmp / "caps")
        print(f"full set: {fs['wall_time_s']:.1f} s wall, {fs['cpu_time_s']:.1f} s CPU, "
              f"{fs['rows']} rows, load {fs['load_before']} -> {fs['load_after']}")
        samples = sample_rows(fs["files"])
        print(f"sampled rows: {samples}")
        comparison = yade_table(fs["files"], fs["suffix"], tmp / "probe") \
            if shutil.which("yade") else []
        fs = {k: v for k, v in fs.items() if k != "files"}
    gen = yade_generator()
    print(f"yade generator: {gen}")
    data = {"full_set": fs, "independent_rows": samples, "yade_comparison": comparison,
            "yade_generator": gen,
            "conclusion": "see README 'Export to Yade'"}
    write_json("export_yade", data)
    chart(data)
    for r in comparison:
        if r["bridge"]:
            print(f"u*={r['u_star']:.4g} D*={r['d_star']:.4g} r={r['ratio']:g} "
                  f"F_yade={r['yade_force_n']:.6e} F_ref={r['reference_force_n']:.6e} "
                  f"err={r['force_error']:+.2e} V_err={r['volume_error']:+.2e}")


if __name__ == "__main__":
    main()
