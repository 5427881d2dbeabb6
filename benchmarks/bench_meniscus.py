"""Benchmark of the FE Young-Laplace bridge (model ``meniscus``), with Surface Evolver as peer.

Measures, on this machine (2 cores shared with other jobs: timings are noisy):
- wall time of one volume-controlled configuration at each resolution preset, and the
  force error against a converged reference (n_elements = 512, error ~1e-14);
- wall time of a 100-point force-separation curve to rupture (continuation + fold);
- Surface Evolver (``evolver``, Debian package evolver-nox) on two sphere-wall cases at three
  refinements: force from the body pressure and the contact line on the sphere
  (F = 2 pi R sigma sin(phi) sin(phi + theta) - pi R^2 sin^2(phi) dp, PHYSICS.md section 2)
  and from the energy difference -dE/dS (central, step 2 % of S), with wall time.
  Skipped with a message when ``evolver`` is not on PATH.

Writes ``benchmarks/results/meniscus.json`` and ``meniscus.png``. Run:
``/work/venv/bin/python benchmarks/bench_meniscus.py``.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import RESULTS, main_or_chart, median_time, write_json  # noqa: E402

from wetcontact.solver.meniscus import (  # noqa: E402
    Bridge,
    force_separation_curve,
    solve_volume,
)

DEG = math.pi / 180.0
CASES = [  # sphere-wall, R = 1, sigma = 1: (V*, S*, theta_sphere, theta_wall) in degrees
    (1e-2, 0.05, 0.0, 0.0),
    (1e-2, 0.10, 30.0, 30.0),
]


# ---- Surface Evolver ------------------------------------------------------------------


def evolver_datafile(R: float, S: float, V: float, th_s: float, th_w: float, r0: float,
                     commands: str) -> str:
    """A sphere-wall bridge for Surface Evolver: a 6-sided tube between the wall z = 0
    (constraint 1) and the sphere centred at z = S + R (constraint 2). Wetted areas enter
    as contact-line integrals (-cos(theta) A), the sphere cap's volume as a content
    integral; both written in z only so that they are exact on chords at constant z."""
    zc = "(GAP+RAD)"
    h = f"({zc}-z)"
    rho2 = f"(RAD^2-{h}^2)"
    g_area = f"RAD*(RAD-{h})/{rho2}"
    g_vol = f"({zc}/2 + ({h}^3 - RAD^3)/(3*{rho2}))"
    n = 6
    R, S, V, r0 = float(R), float(S), float(V), float(r0)
    zt = S + R - math.sqrt(R * R - r0 * r0)
    lines = [
        f"PARAMETER RAD = {R!r}", f"PARAMETER GAP = {S!r}",
        f"PARAMETER CTS = {math.cos(th_s)!r}", f"PARAMETER CTW = {math.cos(th_w)!r}", "",
        "constraint 1", "formula: z = 0", "energy:", "e1: CTW*y", "e2: 0", "e3: 0", "",
        "constraint 2", f"formula: x^2 + y^2 + (z - {zc})^2 = RAD^2", "energy:",
        f"e1: CTS*y*{g_area}", f"e2: -CTS*x*{g_area}", "e3: 0", "content:",
        f"c1: y*{g_vol}", f"c2: -x*{g_vol}", "c3: 0", "", "vertices",
    ]
    for k, z, con in ((0, 0.0, 1), (n, zt, 2)):
        for i in range(n):
            a = 2 * math.pi * i / n
            lines.append(f"{k + i + 1} {r0 * math.cos(a)!r} {r0 * math.sin(a)!r} {z!r} "
                         f"constraint {con}")
    lines += ["", "edges"]
    lines += [f"{i + 1} {i + 1} {(i + 1) % n + 1} constraint 1" for i in range(n)]
    lines += [f"{n + i + 1} {n + i + 1} {n + (i + 1) % n + 1} constraint 2" for i in range(n)]
    lines += [f"{2 * n + i + 1} {i + 1} {n + i + 1}" for i in range(n)]
    lines += ["", "faces"]
    lines += [f"{i + 1} {i + 1} {2 * n + (i + 1) % n + 1} {-(n + i + 1)} {-(2 * n + i + 1)}"
              for i in range(n)]
    lines += ["", "bodies", "1 " + " ".join(str(i + 1) for i in range(n)) + f" volume {V!r}",
              "", "read", commands]
    return "\n".join(lines)


def run_evolver(R, S, V, th_s, th_w, r0, levels: int, workdir: Path):
    """One Evolver run: returns (energy, pressure, contact radius on the sphere, seconds)."""
    cmds = ["g 50"]
    for _ in range(levels):
        cmds += ["r", "g 200", "u", "V", "g 200", "hessian", "hessian", "hessian"]
    cmds += ['printf "E %.15g\\n", total_energy', 'printf "P %.15g\\n", body[1].pressure',
             'foreach vertex vv where on_constraint 2 do printf "C %.15g\\n", '
             "sqrt(vv.x^2+vv.y^2)", "quit"]
    path = workdir / f"bridge_{levels}_{S:.6f}.fe"
    path.write_text(evolver_datafile(R, S, V, th_s, th_w, r0, "\n".join(cmds)))
    t0 = time.perf_counter()
    out = subprocess.run(["evolver", "-x", str(path)], capture_output=True, text=True,
                         timeout=600, check=False).stdout
    wall = time.perf_counter() - t0
    E = P = None
    rc = []
    for line in out.splitlines():
        if line.startswith("E "):
            E = float(line.split()[1])
        elif line.startswith("P "):
            P = float(line.split()[1])
        elif line.startswith("C "):
            rc.append(float(line.split()[1]))
    if E is None or P is None or not rc:
        raise RuntimeError("Surface Evolver produced no result:\n" + out[-2000:])
    return E, P, sum(rc) / len(rc), wall


def evolver_study(ref_forces: list[float]) -> list[dict] | str:
    if shutil.which("evolver") is None:
        return "skipped: 'evolver' not on PATH (apt-get install evolver-nox)"
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for (V, S, ts, tw), fref in zip(CASES, ref_forces, strict=True):
            sol = solve_volume(Bridge(1.0, None, ts * DEG, tw * DEG, 1.0), S, V)
            r0 = sol.wetted_radius  # start the tube near the answer (helps Evolver only)
            for levels in (1, 2, 3):
                E, P, rc, wall = run_evolver(1.0, S, V, ts * DEG, tw * DEG, r0, levels,
                                             Path(tmp))
                phi = math.asin(rc)
                f_line = (2 * math.pi * math.sin(phi) * math.sin(phi + ts * DEG)
                          - math.pi * math.sin(phi) ** 2 * P)
                dS = 0.02 * S
                Ep, _, _, wp = run_evolver(1.0, S + dS, V, ts * DEG, tw * DEG, r0, levels,
                                           Path(tmp))
                Em, _, _, wm = run_evolver(1.0, S - dS, V, ts * DEG, tw * DEG, r0, levels,
                                           Path(tmp))
                f_energy = (Ep - Em) / (2 * dS)
                rows.append({
                    "case": {"V*": V, "S*": S, "theta_sphere_deg": ts, "theta_wall_deg": tw},
                    "refinements": levels, "force_contact_line": f_line,
                    "force_energy": f_energy, "error_contact_line": abs(f_line / fref - 1),
                    "error_energy": abs(f_energy / fref - 1), "wall_time_s": wall,
                    "wall_time_energy_s": wall + wp + wm,
                })
                print(f"  evolver case V*={V} S*={S} th={ts}/{tw} level {levels}: "
                      f"F_line={f_line:.6f} (err {rows[-1]['error_contact_line']:.2e}), "
                      f"F_energy={f_energy:.6f} (err {rows[-1]['error_energy']:.2e}), "
                      f"{wall:.2f} s")
    return rows


# ---- our solver -------------------------------------------------------------------------


def main() -> None:
    fe_rows = []
    refs = []
    for V, S, ts, tw in CASES:
        br = Bridge(1.0, None, ts * DEG, tw * DEG, 1.0)
        fref = -solve_volume(br, S, V, n_elements=512).force
        refs.append(fref)
        for n in (32, 64, 128, 256):
            t, sol = median_time(lambda br=br, S=S, V=V, n=n: solve_volume(br, S, V,
                                                                          n_elements=n),
                                 repeats=7)
            fe_rows.append({"case": {"V*": V, "S*": S, "theta_sphere_deg": ts,
                                     "theta_wall_deg": tw},
                            "n_elements": n, "force": -sol.force,
                            "error": abs(-sol.force / fref - 1), "wall_time_s": t,
                            "force_spread": sol.force_spread})
            print(f"  FE V*={V} S*={S} th={ts}/{tw} N={n}: F={-sol.force:.12f} "
                  f"err={fe_rows[-1]['error']:.1e} spread={sol.force_spread:.1e} "
                  f"{t * 1e3:.1f} ms")
    curve_rows = []
    for V, th in ((1e-2, 0.0), (1e-3, 30.0), (0.1, 50.0)):
        br = Bridge(1.0, None, th * DEG, th * DEG, 1.0)
        t, curve = median_time(lambda br=br, V=V: force_separation_curve(br, V, n_points=100),
                               repeats=3)
        curve_rows.append({"V*": V, "theta_deg": th, "points": len(curve.solutions),
                           "rupture_distance": curve.rupture_distance, "wall_time_s": t})
        print(f"  curve V*={V} th={th}: 100 points to S_c={curve.rupture_distance:.6f} "
              f"in {t:.3f} s")
    ev = evolver_study(refs)
    if isinstance(ev, str):
        print("  Surface Evolver", ev)
    data = {"note": "2 shared cores, timings noisy; R = sigma = 1, sphere-wall",
            "fe_single": fe_rows, "fe_curve_100": curve_rows, "surface_evolver": ev,
            "reference_forces": refs}
    path = write_json("meniscus", data)
    print("wrote", path)
    _plot(fe_rows, ev if isinstance(ev, list) else [])


def _plot(fe_rows, ev_rows) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.2))
    for k, (_V, S, ts, _tw) in enumerate(CASES):
        sel = [r for r in fe_rows if r["case"]["S*"] == S]
        ax.loglog([r["wall_time_s"] for r in sel], [max(r["error"], 1e-16) for r in sel],
                  ("o-", "s--", "^-.", "D:")[k % 4], color=f"C{k}",
                  label=f"FE P2, th={ts:.0f} deg (labels: elements)")
        for r in sel:
            ax.annotate(f"{r['n_elements']}", (r["wall_time_s"], max(r["error"], 1e-16)),
                        fontsize=6, textcoords="offset points", xytext=(4, 2))
        sel = [r for r in ev_rows if r["case"]["S*"] == S]
        if sel:
            ax.loglog([r["wall_time_s"] for r in sel], [r["error_contact_line"] for r in sel],
                      "s--", color=f"C{k}", label=f"Evolver (contact line), th={ts:.0f}")
            ax.loglog([r["wall_time_energy_s"] for r in sel], [r["error_energy"] for r in sel],
                      "^:", color=f"C{k}", label=f"Evolver (-dE/dS), th={ts:.0f}")
    ax.set_xlabel("wall time per configuration (s)")
    ax.set_ylabel("relative force error")
    ax.set_title("Sphere-wall bridge, V* = 0.01: work-precision")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    RESULTS.mkdir(parents=True, exist_ok=True)
    fig.savefig(RESULTS / "meniscus.png", dpi=120)


if __name__ == "__main__":
    main_or_chart("meniscus", main, lambda d: _plot(
        d["fe_single"], d["surface_evolver"] if isinstance(d["surface_evolver"], list) else []))
