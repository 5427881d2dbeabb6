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

``--part rows [--contact-angle DEG] [--files DIR]``: EVERY row of a full set (generated
as above, or read from DIR) against the exact bridge at the row's (D*, u*) from the ODE
shooting of tests/export/yade_rows.py (independent of the finite-element meniscus solver),
2 processes, a progress line every 10 s; per quantity the largest relative error, where it
sits (file, line, D*, u*) and the number of rows above 1e-6. Merged into
``benchmarks/results/export_yade_rows.json`` under ``theta<DEG>``, chart
``export_yade_rows.png`` (about 10 min: 4-6 to generate, 4-5 to check).
"""

from __future__ import annotations

import argparse
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

from wetcontact.export.yade import (  # noqa: E402
    RATIOS,
    default_suffix,
    export_yade,
    file_name,
    read_table,
    yade_probe,
)
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


# ---------------------------------------------------------------------------------------
# --part rows: every row of a full set against the independent shooting solution
# ---------------------------------------------------------------------------------------

LIMIT = 1e-6          # the acceptance: every row within 1e-6 of an independent solve
CHUNK = 1500          # rows per task (vectorised shooting: a few seconds each)


def _row_lines(blocks: list[np.ndarray]) -> np.ndarray:
    """1-based line number in the file of each data row (2 header lines, 1 per block)."""
    lines, line = [], 3
    for b in blocks:
        lines.extend(range(line + 1, line + 1 + b.shape[0]))
        line += b.shape[0] + 1
    return np.array(lines)


def _check_chunk(args: tuple) -> dict:
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "export"))
    from yade_rows import check_rows

    name, ratio, theta, lines, rows = args
    res = check_rows(ratio, theta, rows)
    return {"file": name, "ratio": ratio, "lines": lines, "rows": rows, **res}


def check_set(files: list[str], theta: float, workers: int = 2) -> dict:
    """Every row of the files against the exact bridge at its (D*, u*); the summary."""
    from concurrent.futures import ProcessPoolExecutor

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "export"))
    from yade_rows import QUANTITIES, U_FLOOR

    tasks = []
    for f in files:
        ratio, blocks = read_table(Path(f))
        rows, lines = np.vstack(blocks), _row_lines(blocks)
        for k in range(0, rows.shape[0], CHUNK):
            tasks.append((Path(f).name, ratio, theta, lines[k:k + CHUNK], rows[k:k + CHUNK]))
    total = sum(t[4].shape[0] for t in tasks)
    worst = {q: {"rel_error": -1.0} for q in QUANTITIES}
    over = dict.fromkeys(QUANTITIES, 0)
    over_any, n_done, not_conv = 0, 0, []
    diag = {"max_self_check": 0.0, "max_step_check": 0.0, "max_abs_d_residual": 0.0}
    flagged, per_file = [], {}
    load0, t0, t_print = os.getloadavg(), time.perf_counter(), time.perf_counter()
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for r in pool.map(_check_chunk, tasks):
            conv = r["converged"]
            for q in QUANTITIES:               # worst among the converged; the others apart
                over[q] += int(np.sum((r["err"][q] > LIMIT) | ~conv))
                e = np.where(conv, r["err"][q], 0.0)
                i = int(np.argmax(e))
                if e[i] > worst[q]["rel_error"]:
                    worst[q] = {"rel_error": float(e[i]), "file": r["file"],
                                "line": int(r["lines"][i]), "D*": float(r["rows"][i, 0]),
                                "u*": float(r["rows"][i, 1])}
            pf = per_file.setdefault(r["file"], {"rows": 0, **dict.fromkeys(QUANTITIES, 0.0)})
            pf["rows"] += int(r["rows"].shape[0])
            for q in QUANTITIES:
                pf[q] = max(pf[q], float(np.max(np.where(conv, r["err"][q], 0.0))))
            e_all = np.max(np.stack([r["err"][q] for q in QUANTITIES if q != "u*"]), axis=0)
            bad = (e_all > LIMIT) | ~conv
            over_any += int(np.sum(bad))
            for i in np.flatnonzero(bad):
                flagged.append({"file": r["file"], "line": int(r["lines"][i]),
                                "D*": float(r["rows"][i, 0]), "u*": float(r["rows"][i, 1]),
                                "converged": bool(conv[i]), "max_rel_error": float(e_all[i]),
                                "dD_ddelta1": float(r["dD_ddelta1"][i]),
                                "d_residual": float(r["d_residual"][i])})
            not_conv += [(r["file"], int(r["lines"][i])) for i in np.flatnonzero(~conv)]
            ok = conv
            diag["max_self_check"] = max(diag["max_self_check"],
                                         float(np.max(r["self_check"][ok], initial=0.0)))
            diag["max_step_check"] = max(diag["max_step_check"],
                                         float(np.max(r["step_check"][ok], initial=0.0)))
            diag["max_abs_d_residual"] = max(diag["max_abs_d_residual"],
                                             float(np.max(np.abs(r["d_residual"]))))
            n_done += r["rows"].shape[0]
            if time.perf_counter() - t_print >= 10.0 or n_done == total:
                t_print = time.perf_counter()
                print(f"  rows {n_done}/{total}  {t_print - t0:.0f} s  not converged "
                      f"{len(not_conv)}  max rel. error "
                      + ", ".join(f"{q} {worst[q]['rel_error']:.1e}" for q in QUANTITIES),
                      flush=True)
    flagged.sort(key=lambda x: -x["max_rel_error"] if x["converged"] else -math.inf)
    return {"rows_checked": total, "limit": LIMIT, "wall_time_s": time.perf_counter() - t0,
            "load_before": load0, "load_after": os.getloadavg(), "workers": workers,
            "worst": worst, "rows_over_limit": over, "max_rel_error_per_file": per_file,
            "rows_over_limit_any_but_suction": over_any,
            "not_converged": not_conv, "diagnostics": diag,
            "flagged_rows_worst_50": flagged[:50],
            "suction_floor": U_FLOOR,
            "method": "exact bridge at the row's (D*, u*) by ODE shooting in the tangent "
                      "angle (8th-order Runge-Kutta, 200 steps, checked against 400); "
                      "suction: u(D*, V*) by linearisation at the row's volume, relative to "
                      "max(u*, suction_floor)"}


def chart_rows(data: dict) -> None:
    """Largest relative error per file and quantity, each angle checked (log scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = sorted(k for k in data if k.startswith("theta"))
    fig, axes = plt.subplots(1, len(keys), figsize=(5.5 * len(keys), 4.2), squeeze=False)
    markers = "osD^v<>"
    for ax, key in zip(axes[0], keys, strict=True):
        per = data[key]["max_rel_error_per_file"]
        ratios = [float(f.split("=")[1].split(")")[0]) for f in per]
        for k, q in enumerate(data[key]["worst"]):
            ax.plot(ratios, [per[f][q] for f in per], marker=markers[k % len(markers)],
                    ls=("-", "--", ":")[k % 3],
                    label="u*, read back from V*" if q == "u*" else q)
        ax.axhline(LIMIT, color="r", lw=1.0, label="1e-6 (acceptance)")
        low = min(v for f in per.values() for q, v in f.items() if q != "rows" and v > 0)
        ax.set_ylim(low / 3, 5 * LIMIT)
        ax.set(xscale="log", yscale="log", xlabel="radius ratio r = R2/R1",
               ylabel="largest relative error in the file",
               title=f"Yade files, {key.replace('theta', 'theta = ')} deg: every row "
                     f"({data[key]['rows_checked']}) vs shooting")
        ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(RESULTS / "export_yade_rows.png", dpi=120)


def rows_part(theta_deg: float, files_dir: Path | None) -> None:
    path = RESULTS / "export_yade_rows.json"
    data = json.loads(path.read_text()) if path.exists() else {}
    with tempfile.TemporaryDirectory() as tmp:
        gen = None
        if files_dir is None:
            files_dir = Path(tmp) / "caps"
            load0, t0 = os.getloadavg(), time.perf_counter()
            c0 = _cpu_children() + time.process_time()
            res = export_yade(theta_deg, files_dir, n_suctions=350, n_distances=80, workers=2)
            gen = {"wall_time_s": time.perf_counter() - t0,
                   "cpu_time_s": _cpu_children() + time.process_time() - c0,
                   "load_before": load0, "load_after": os.getloadavg(),
                   "n_elements": res["n_elements"],
                   "rows": sum(t["rows"] for t in res["tables"]),
                   "rows_polished": sum(t["polished"] for t in res["tables"])}
            print(f"generated: {gen}", flush=True)
        files = [str(Path(files_dir) / file_name(r, default_suffix(theta_deg)))
                 for r in RATIOS]
        summary = check_set(files, math.radians(theta_deg))
    summary["generation"] = gen
    print(json.dumps({k: summary[k] for k in ("rows_checked", "wall_time_s", "worst",
                                              "rows_over_limit", "diagnostics")}, indent=1))
    data[f"theta{theta_deg:g}"] = summary
    write_json("export_yade_rows", {k: v for k, v in data.items() if k != "cpu_count"})
    chart_rows(data)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", choices=("all", "rows"), default="all")
    ap.add_argument("--contact-angle", type=float, default=0.0)
    ap.add_argument("--files", type=Path, default=None,
                    help="check an existing set (DIR) instead of generating one")
    a = ap.parse_args()
    if a.part == "rows":
        rows_part(a.contact_angle, a.files)
        return
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
