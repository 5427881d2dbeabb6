"""Re-integrate each code's normal force law, as README.md writes it, and compare e.

This is not the toolkit: a plain ODE (scipy DOP853, rtol 1e-11, events at contact start
and end and at the rupture distance) for the gap s of the two surfaces with the laws read
in the codes' sources. If the written formulas are complete, its e agrees with the e the
codes measured (raw/*.json) to about the codes' own timestep error (1e-4 or better).

Run: ``.venv/bin/python benchmarks/dem/check_formulas.py [--write]`` (``--write`` stores the
comparison into results.json under each run as ``e_formula_ode``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from scipy.integrate import solve_ivp

HERE = Path(__file__).resolve().parent


# ---------------------------------------------------------------- Yade ViscElCap
def yade_force(p: dict, partner: str):
    """Yade: F(s, w) pushing the surfaces apart (s = gap, w = ds/dt), per phase."""
    R, m = p["R"], 4.0 / 3.0 * math.pi * p["R"] ** 3 * p["rho"]
    # Ip2: massR = m1 m2/(m1 + m2) with the fixed body's own mass (ViscoelasticPM.cpp 190-199)
    mass_r = 0.5 * m
    ln_en = math.log(p["en"])
    kn = (math.pi ** 2 + ln_en ** 2) * mass_r / p["tc"] ** 2      # lines 224, 297 (harmonic)
    cn = -2.0 * ln_en * mass_r / p["tc"]                           # lines 225, 299
    m_motion = m if partner == "fixed" else 0.5 * m
    Rw = 2.0 * R * R / (R + R)                                     # phys.R (Capillar .cpp 123)
    th = math.radians(p["theta"])
    vs = p["Vb"] / Rw ** 3
    s_crit = (1 + 0.5 * th) * (vs ** (1 / 3) + 0.1 * vs ** (2 / 3)) * Rw
    L = math.log(vs)
    t1, t2 = th, th * th
    f1 = ((-0.44507 + 0.050832 * t1 - 1.1466 * t2) + (-0.1119 - 0.000411 * t1 - 0.1490 * t2) * L
          + (-0.012101 - 0.0036456 * t1 - 0.01255 * t2) * L * L
          + (-0.0005 - 0.0003505 * t1 - 0.00029076 * t2) * L ** 3)
    f2 = ((1.9222 - 0.57473 * t1 - 1.2918 * t2) + (-0.0668 - 0.1201 * t1 - 0.22574 * t2) * L
          + (-0.0013375 - 0.0068988 * t1 - 0.01137 * t2) * L * L)
    f3 = ((1.268 - 0.01396 * t1 - 0.23566 * t2) + (0.198 + 0.092 * t1 - 0.06418 * t2) * L
          + (0.02232 + 0.02238 * t1 - 0.009853 * t2) * L * L
          + (0.0008585 + 0.001318 * t1 - 0.00053 * t2) * L ** 3)
    f4 = ((-0.010703 + 0.073776 * t1 - 0.34742 * t2) + (0.03345 + 0.04543 * t1 - 0.09056 * t2) * L
          + (0.0018574 + 0.004456 * t1 - 0.006257 * t2) * L * L)

    def f_cap(s: float) -> float:
        if not p.get("capillar", True):
            return 0.0
        if p["captype"] == "Willett_analytic":
            sp = (s / 2.0) / math.sqrt(p["Vb"] / Rw)
            return math.cos(th) / (1 + 2.1 * sp + 10.0 * sp * sp) * 2 * math.pi * Rw * p["gamma"]
        sp = (s / 2.0) / math.sqrt(p["Vb"] / Rw)
        ls = math.log(sp)
        return math.exp(f1 - f2 * math.exp(f3 * ls + f4 * ls * ls)) * 2 * math.pi * Rw * p["gamma"]

    def contact(s: float, w: float) -> float:
        return max(0.0, kn * (-s) + cn * (-w))                     # ViscoelasticPM.cpp 132-139

    def bridge(s: float, w: float) -> float:
        if not p.get("capillar", True):
            return 0.0
        return -(f_cap(s) + p["dcap"] * w)                        # Capillar .cpp 144-167

    return dict(m=m_motion, contact=contact, bridge=bridge,
                rupture=s_crit if p.get("capillar", True) else 0.0,
                coeffs=dict(kn=kn, cn=cn, sCrit=s_crit, m_motion=m_motion))


# ---------------------------------------------------------------- LIGGGHTS easo
def liggghts_force(p: dict, partner: str):
    R, m = p["R"], 4.0 / 3.0 * math.pi * p["R"] ** 3 * p["rho"]
    m_eff = m if partner == "fixed" else 0.5 * m                  # pair_gran_base.h 383-387
    y_eff = 1.0 / (2.0 * (1.0 - p["nu"] ** 2) / p["E"])          # global_properties.cpp 432
    lne = math.log(p["en"])
    beta = lne / math.sqrt(lne * lne + math.pi ** 2)              # global_properties.cpp 539
    r_eff = 0.5 * R
    s56 = math.sqrt(5.0 / 6.0)
    vp = 4.0 / 3.0 * math.pi * R ** 3
    vb = vp * p["content"] * (1.0 - math.sqrt(1.0 - 0.25))      # cohesion .h 200-204
    wet = vb * 1000.0 >= 1e-14
    th = math.radians(p["theta"])
    th_eff = 0.5 * th * th                                        # 3.8.0: 0.5*theta_i*theta_j
    d_max = (1.0 + 0.5 * th_eff) * vb ** (1.0 / 3.0)              # cohesion .h 310
    d_cut = (p["smax"] - 1.0) * 2.0 * R                          # cohesion .h 315-320
    if wet:
        vs = vb / R ** 3
        A = -1.1 * vs ** -0.53
        B = (-0.148 * math.log(vs) - 0.96) * th_eff ** 2 - 0.0082 * math.log(vs) + 0.48
        C = 0.0018 * math.log(vs) + 0.078
    eta, gam, smin = p["eta"], p["gamma"], p["smin"]

    def contact(s: float, w: float) -> float:
        d, dd = max(-s, 0.0), -w                                  # overlap, its rate
        sq = math.sqrt(r_eff * d)
        kn = 4.0 / 3.0 * y_eff * sq                               # normal_model_hertz.h
        gn = -2.0 * s56 * beta * math.sqrt(2.0 * y_eff * sq * m_eff)
        f = kn * d + gn * dd                                      # no limitForce: may be < 0
        if wet:
            f += -math.pi * gam * R * (math.exp(B) + C)           # cohesion .h 216-221 (dist=0)
            f += 6.0 * math.pi * eta * r_eff * dd / smin          # cohesion .h 225-226
        return f

    def bridge(s: float, w: float) -> float:
        if not wet:
            return 0.0
        fc = -math.pi * gam * R * (math.exp(A * s / R + B) + C)  # cohesion .h 342-348
        fv = -6.0 * math.pi * eta * r_eff * w / max(smin, s / r_eff)   # .h 397-398
        return fc + fv

    return dict(m=m_eff, contact=contact, bridge=bridge,
                rupture=min(d_max, d_cut) if wet else 0.0,
                coeffs=dict(Y_eff=y_eff, beta=beta, bridge_volume=vb, rupture=d_max))


# ---------------------------------------------------------------- Yade implicit lubrication
def yade_lubrication_e(p: dict, v0: float) -> tuple[float, float]:
    """Law2_ScGeom_ImplicitLubricationPhys, resolution 0 (Lubrication.cpp 302-414): the film
    gap u follows (3/2) nu_n u'/u = kn (u_n - u) + keps kn (2 eps a - u)[u < 2 eps a], the
    force pushing the spheres apart is kn (u - u_n); nu_n = pi eta a^2, a = (R1 + R2)/2,
    kn = 2 E1 R1 E2 R2/(E1 R1 + E2 R2) (Cundall-stack, lines 53-67). Starts at the start gap
    with u = u_n; e when u_n is back at the start gap. Returns (e, time with u < 2 eps a)."""
    R, m = p["R"], 4.0 / 3.0 * math.pi * p["R"] ** 3 * p["rho"]
    a = R
    kn = 2.0 * p["young"] * R * p["young"] * R / (2.0 * p["young"] * R)
    keps = p["keps"] * kn
    nu = 1.5 * math.pi * p["eta"] * a * a
    u_c = 2.0 * p["eps"] * a
    g0 = p["gap"]

    def rhs(_t, y):
        un, w, u = y
        u = max(u, 1e-15)
        drive = kn * (un - u) + (keps * (u_c - u) if u < u_c else 0.0)
        du = u * drive / nu
        f_rep = kn * (u - un)
        return [w, f_rep / m, du]

    def back(_t, y):
        return y[0] - g0
    back.terminal, back.direction = True, 1

    def c_in(_t, y):
        return y[2] - u_c
    c_in.direction = 0
    sol = solve_ivp(rhs, (0.0, 50.0 * g0 / v0), [g0, -v0, g0], method="Radau", rtol=1e-10,
                    atol=[1e-15, 1e-12, 1e-15], events=[back, c_in], max_step=g0 / v0 / 200)
    t_c = sol.t_events[1]
    dur = float(t_c[1] - t_c[0]) if len(t_c) >= 2 else math.nan
    if not sol.t_events[0].size:
        return 0.0, dur
    return float(sol.y_events[0][0][1]) / v0, dur


def restitution(law: dict, v0: float) -> tuple[float, float]:
    """(e, contact duration) of the ODE; starts at s = 0 (nothing acts before contact)."""
    m = law["m"]
    s, w = 0.0, -v0
    t_contact = None
    for _ in range(200):
        # contact phase: from s = 0 going in, until s = 0 going out
        def rhs_c(_t, y):
            return [y[1], law["contact"](y[0], y[1]) / m]

        def out(_t, y):
            return y[0]
        out.terminal, out.direction = True, 1
        sol = solve_ivp(rhs_c, (0, 1.0), [s - 1e-30, w], method="DOP853", rtol=1e-11,
                        atol=1e-16, events=out, max_step=1e-6)
        if not sol.t_events[0].size:
            return 0.0, t_contact if t_contact is not None else math.inf
        if t_contact is None:
            t_contact = sol.t_events[0][0]        # the first contact's duration
        s, w = 0.0, sol.y_events[0][0][1]
        if law["rupture"] <= 0.0:
            return w / v0, t_contact

        # bridge phase: until rupture (going out) or re-contact (coming back)
        def rhs_b(_t, y):
            return [y[1], law["bridge"](max(y[0], 1e-300), y[1]) / m]

        def rup(_t, y):
            return y[0] - law["rupture"]
        rup.terminal, rup.direction = True, 1

        def back(_t, y):
            return y[0]
        back.terminal, back.direction = True, -1
        sol = solve_ivp(rhs_b, (0, 10.0), [1e-30, w], method="DOP853", rtol=1e-11, atol=1e-18,
                        events=[rup, back], max_step=1e-5)
        if sol.t_events[0].size:
            return sol.y_events[0][0][1] / v0, t_contact
        if not sol.t_events[1].size:
            return 0.0, t_contact
        s, w = 0.0, sol.y_events[1][0][1]
    return 0.0, t_contact


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--write", action="store_true")
    a = ap.parse_args(argv)
    res_path = HERE / "results.json"
    doc = json.loads(res_path.read_text())
    worst = 0.0
    for case in doc["cases"]:
        p, partner = case["params"], case["partner"]
        if case["law"] == "yade-viscelcap":
            law = yade_force(p, partner)
        elif case["law"] == "liggghts-easo":
            law = liggghts_force(p, partner)
        elif case["law"] == "yade-lubrication" and partner == "fixed":
            law = None
        else:
            continue
        for r in case["runs"]:
            if law is None:
                e_ode, tc_ode = yade_lubrication_e(p, r["v0_m_s"])
            else:
                e_ode, tc_ode = restitution(law, r["v0_m_s"])
            e_code = r["e"]
            diff = abs(e_ode - e_code)
            worst = max(worst, diff)
            print(f"{case['name']:32s} v0={r['v0_m_s']:5.2f}  e_code={e_code:.6f}  "
                  f"e_ode={e_ode:.6f}  |diff|={diff:.1e}  tc_code={r.get('contact_duration_s')}"
                  f"  tc_ode={tc_ode:.6e}")
            if a.write:
                r["e_formula_ode"] = e_ode
                r["contact_duration_formula_ode_s"] = tc_ode
    print(f"largest |e_code - e_ode| = {worst:.2e}")
    if a.write:
        res_path.write_text(json.dumps(doc, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
