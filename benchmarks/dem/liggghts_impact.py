"""Driver for liggghts_impact.in: one wet head-on impact per speed, measured in LIGGGHTS.

Run:  ``python3 benchmarks/dem/liggghts_impact.py [--speeds 0.1,0.2,0.5,1.0] [--dt 2.5e-8]
[--converge] [--partner fixed|pair] [--dry] [--theta DEG] [--out FILE]``  (standard library
only; needs the ``liggghts`` executable of the Debian package). Prints one JSON document.

Each run calls ``liggghts -in liggghts_impact.in -var ...`` in a temporary folder; the input
prints one line per step from 2 um before contact on (step, time, gap, approach speed, the
x-force on the mover). Measured: e = (relative speed when the gap is back at the start gap)
/ v0 (after the bridge ruptured: free flight); the contact duration (gap < 0, crossings
interpolated linearly); the gap at which the force on the mover vanished after the contact
(the bridge rupture); the largest overlap. ``--converge`` reruns every speed at dt/2.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
INPUT = HERE / "liggghts_impact.in"

#: defaults of liggghts_impact.in (SI); the driver passes the ones it changes with -var
PARAMS = dict(R=1e-3, rho=2500.0, E=5e9, nu=0.3, en=0.9, gamma=0.072, eta=1e-3, theta=0.0,
              smin=0.01, smax=1.2, content=0.01781923, gap=3e-4)


def _crossing(t: list[float], g: list[float], k: int, level: float = 0.0) -> float:
    t0, t1, g0, g1 = t[k - 1], t[k], g[k - 1], g[k]
    return t0 + (level - g0) * (t1 - t0) / (g1 - g0)


def analyse(path: Path, v0: float, g_start: float) -> dict:
    t, g, v, f = [], [], [], []
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        _, ti, gi, vi, fi = line.split()
        t.append(float(ti))
        g.append(float(gi))
        v.append(float(vi))
        f.append(float(fi))
    n = len(g)
    out: dict = {"steps_recorded": n}
    ks = next((k for k in range(1, n) if g[k] < 0.0 <= g[k - 1]), None)
    if ks is None:
        out.update(outcome="no-contact", e=None)
        return out
    out["t_contact_start_s"] = _crossing(t, g, ks)
    out["max_overlap_m"] = -min(g)
    ke = next((k for k in range(ks + 1, n) if g[k] >= 0.0 > g[k - 1]), None)
    if ke is None:
        out.update(outcome="stuck", e=0.0)
        return out
    out["t_contact_end_s"] = _crossing(t, g, ke)
    out["contact_duration_s"] = out["t_contact_end_s"] - out["t_contact_start_s"]
    out["force_at_contact_end_N"] = f[ke]
    kr = next((k for k in range(ke, n) if f[k] == 0.0), None)
    if kr is not None:
        out["rupture_gap_m"] = [g[kr - 1], g[kr]]   # force on at g[kr-1], zero at g[kr]
    kg = next((k for k in range(ke, n) if g[k] >= g_start), None)
    if kg is None:
        out.update(outcome="captured", e=0.0, final_gap_m=g[-1], final_speed=v[-1])
        return out
    v_reb = -v[kg]
    out.update(outcome="rebound", e=v_reb / v0, v_rebound=v_reb, speed_at_contact=v[ks],
               t_back_at_start_gap_s=_crossing(t, g, kg, g_start))
    return out


def run_one(v0: float, dt: float, fixed: bool, over: dict) -> dict:
    with tempfile.TemporaryDirectory(prefix="liggghts_impact_") as tmp:
        out = Path(tmp) / "rec.txt"
        cmd = ["liggghts", "-in", str(INPUT), "-log", "none", "-var", "v0", repr(v0),
               "-var", "dt", repr(dt), "-var", "fixed", "1" if fixed else "0",
               "-var", "out", str(out)]
        for k, val in over.items():
            cmd += ["-var", k, repr(val)]
        w0 = time.time()
        proc = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True, timeout=600)
        wall = time.time() - w0
        if proc.returncode != 0 or not out.exists():
            raise RuntimeError(f"liggghts failed ({proc.returncode}):\n{proc.stdout[-3000:]}"
                               f"\n{proc.stderr[-2000:]}")
        g_start = over.get("gap", PARAMS["gap"])
        res = analyse(out, v0, g_start)
    res.update(v0=v0, dt=dt, wall_s=wall)
    return res


def derived(p: dict, fixed: bool) -> dict:
    """The coefficients LIGGGHTS derives from the inputs (see README.md for the source lines)."""
    R, m = p["R"], 4.0 / 3.0 * math.pi * p["R"] ** 3 * p["rho"]
    y_eff = 1.0 / (2.0 * (1.0 - p["nu"] ** 2) / p["E"])
    beta = math.log(p["en"]) / math.sqrt(math.log(p["en"]) ** 2 + math.pi ** 2)
    r_eff = R * R / (2.0 * R)
    m_eff = m if fixed else 0.5 * m
    v_p = 4.0 / 3.0 * math.pi * R ** 3
    vol_bond = 2.0 * 0.5 * v_p * p["content"] * (1.0 - math.sqrt(1.0 - R * R / (2 * R) ** 2))
    th = math.radians(p["theta"])
    th_eff = 0.5 * th * th                        # 3.8.0: 0.5 * theta_i * theta_j (rad^2)
    vs = vol_bond / R ** 3                        # R2 = the larger radius = R
    if vs <= 0.0:
        return {"mass_kg": m, "m_eff_kg": m_eff, "Y_eff_Pa": y_eff, "beta": beta,
                "R_eff_m": r_eff, "bridge_volume_m3": 0.0}
    A = -1.1 * vs ** -0.53
    B = (-0.148 * math.log(vs) - 0.96) * th_eff ** 2 - 0.0082 * math.log(vs) + 0.48
    C = 0.0018 * math.log(vs) + 0.078
    return {"mass_kg": m, "m_eff_kg": m_eff, "Y_eff_Pa": y_eff, "beta": beta,
            "R_eff_m": r_eff, "bridge_volume_m3": vol_bond, "theta_eff_rad": th_eff,
            "rupture_distance_m": (1.0 + 0.5 * th_eff) * vol_bond ** (1.0 / 3.0),
            "bridge_cutoff_m": (p["smax"] - 1.0) * 2.0 * R,
            "soulie_A": A, "soulie_B": B, "soulie_C": C,
            "capillary_force_at_contact_N": math.pi * p["gamma"] * R * (math.exp(B) + C),
            "viscous_coefficient_in_contact_Ns_per_m": 6 * math.pi * p["eta"] * r_eff / p["smin"],
            "h_min_m": p["smin"] * r_eff}


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", default="0.1,0.2,0.5,1.0")
    ap.add_argument("--dt", type=float, default=5e-8)
    ap.add_argument("--converge", action="store_true")
    ap.add_argument("--partner", choices=("fixed", "pair"), default="fixed")
    ap.add_argument("--dry", action="store_true", help="surfaceLiquidContentInitial = 0")
    ap.add_argument("--theta", type=float, default=None, help="contactAngle (degrees)")
    ap.add_argument("--var", action="append", default=[], metavar="NAME=VALUE",
                    help="any other variable of liggghts_impact.in")
    ap.add_argument("--out", default=None)
    a = ap.parse_args(argv)
    over: dict = {}
    if a.dry:
        over["content"] = 0.0
    if a.theta is not None:
        over["theta"] = a.theta
    for kv in a.var:
        k, val = kv.split("=", 1)
        over[k] = float(val)
    p = dict(PARAMS, **over)
    fixed = a.partner == "fixed"
    runs = []
    for v0 in (float(s) for s in a.speeds.split(",")):
        r = run_one(v0, a.dt, fixed, over)
        if a.converge:
            r2 = run_one(v0, 0.5 * a.dt, fixed, over)
            r["half_dt"] = {k: r2.get(k) for k in ("e", "contact_duration_s", "outcome",
                                                   "rupture_gap_m", "wall_s")}
            if r.get("e") is not None and r2.get("e") is not None:
                r["e_change_half_dt"] = abs(r["e"] - r2["e"])
        runs.append(r)
    with tempfile.TemporaryDirectory() as tmp:     # -h writes log.liggghts into the cwd
        ver = subprocess.run(["liggghts", "-log", "none", "-h"], capture_output=True, text=True,
                             cwd=tmp).stdout
    ver = next((ln.strip() for ln in ver.splitlines() if "LIGGGHTS" in ln and "Version" in ln),
               "LIGGGHTS 3.8.0")
    doc = {"code": "liggghts", "version": ver, "partner": a.partner, "params": p,
           "derived": derived(p, fixed), "dt": a.dt, "runs": runs}
    if a.out:
        Path(a.out).write_text(json.dumps(doc, indent=1) + "\n")
    print(json.dumps(doc))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
