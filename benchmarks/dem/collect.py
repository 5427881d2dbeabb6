"""Gather raw/*.json (the runs of yade_impact.py and liggghts_impact.py) into results.json.

Run: ``python3 benchmarks/dem/collect.py`` after the runs listed in README.md ("Rerun").
The force laws are written in words here, next to the numbers they produced; README.md has
the same formulas with the source lines.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

HERE = Path(__file__).resolve().parent
RAW = HERE / "raw"

YADE_LAWS = {
    "solid_contact": (
        "linear spring-dashpot, only while the spheres overlap (penetrationDepth d >= 0): "
        "F = max(0, kn d + cn d_dot) (no attraction; ViscoelasticPM.cpp 132-139). From (tc, en): "
        "kn = (pi^2 + ln(en)^2) mR / tc^2, cn = -2 ln(en) mR / tc with mR = m1 m2/(m1 + m2) "
        "of the two bodies' own masses (ViscoelasticPM.cpp 190-199, 224-225, 297-300); a fixed "
        "sphere keeps its mass there, so a sphere on a fixed equal sphere gets mR = m/2 while "
        "it moves with m: its dry restitution is not en"),
    "capillary": (
        "Willett_numeric: F = 2 pi R gamma exp(f1 - f2 exp(f3 ln S + f4 ln^2 S)), "
        "S = (s/2)/sqrt(Vb/R), f1..f4 cubic/quadratic in ln(Vb/R^3) and theta (Willett 2000 "
        "appendix), R = 2 R1 R2/(R1 + R2) (= R for equal spheres); attractive; "
        "ViscoelasticCapillarPM.cpp 230-269 and 123. Willett_analytic: F = 2 pi R gamma "
        "cos(theta)/(1 + 2.1 S + 10 S^2) (lines 271-293)"),
    "bridge_damping": (
        "F = dcap * (separation speed), same direction as the capillary force while separating "
        "(ViscoelasticCapillarPM.cpp 147-167); acts only while the bridge exists"),
    "when": (
        "bridge created at the first contact (d >= 0, line 114); capillary + dcap act only while "
        "the surfaces are apart (s = -d > 0) AND the bridge exists (lines 136-173); during "
        "contact only the spring-dashpot acts (lines 193-213), so the capillary force is zero "
        "in contact and jumps to its full value at s = 0+; nothing acts on approach"),
    "rupture": (
        "s >= sCrit = (1 + theta/2) (V*^(1/3) + 0.1 V*^(2/3)) R, V* = Vb/R^3, "
        "R = 2 R1 R2/(R1 + R2), theta in radians (ViscoelasticCapillarPM.cpp 217-224, 137); "
        "the interaction is then erased (Law2 returns false)"),
}

LIGGGHTS_LAWS = {
    "solid_contact": (
        "Hertz with damping, only while the spheres overlap (d > 0): "
        "F = kn d + gamma_n d_dot, kn = (4/3) Y* sqrt(R* d), gamma_n = 2 sqrt(5/6) |beta| "
        "sqrt(Sn m*), Sn = 2 Y* sqrt(R* d), beta = ln(e)/sqrt(ln(e)^2 + pi^2), "
        "Y* = 1/((1 - nu1^2)/E1 + (1 - nu2^2)/E2), R* = R1 R2/(R1 + R2), m* = m1 m2/(m1 + m2) or "
        "the mobile mass when the other is frozen (normal_model_hertz.h, global_properties.cpp, "
        "pair_gran_base.h 383-387); not clipped: limitForce is off by default, so the damping "
        "makes the force tensile at the end of the contact"),
    "capillary": (
        "Soulie et al. 2006: F = -pi gamma sqrt(Ri Rj) (exp(A s/R2 + B) + C), attractive, "
        "R2 = larger radius, V* = Vb/R2^3, A = -1.1 V*^-0.53, B = (-0.148 ln V* - 0.96) "
        "theta_eff^2 - 0.0082 ln V* + 0.48, C = 0.0018 ln V* + 0.078; in contact with s = 0 "
        "(cohesion_model_easo_capillary_viscous.h 212-221 in contact, 338-348 apart)"),
    "viscous": (
        "F = 6 pi eta R* v_n / max(Smin, s/R*) (Reynolds 6 pi eta R*^2 v/s, capped at "
        "s = Smin R*), opposing the relative normal motion; in contact F = 6 pi eta R* v_n/Smin "
        "(cohesion .h 225-226 in contact, 397-398 apart); tangential part ignored here"),
    "bridge_volume": (
        "Vb = sum over i of 0.5 (4/3 pi Ri^3 c_i) (1 - sqrt(1 - Rj^2/(Ri + Rj)^2)), c_i = "
        "surfaceLiquidContent used as a volume FRACTION (the doc says % of the solid volume); "
        "equal spheres: Vb = (4/3 pi R^3) c (1 - sqrt(3)/2) (cohesion .h 200-204)"),
    "when": (
        "bridge created at the first contact (history flag set in surfacesIntersect, line 198); "
        "capillary + viscous act in contact (with s = 0) and apart while the bridge exists; "
        "nothing acts on approach (the flag is 0 before the first contact)"),
    "rupture": (
        "s >= (1 + theta_eff/2) Vb^(1/3) (Lian 1993), or s > (maxSeparationDistanceRatio - 1) "
        "(Ri + Rj) (cohesion .h 310-322); theta_eff = 0.5 theta_i theta_j in radians in 3.8.0 "
        "(the intended mean 0.5 (theta_i + theta_j) came after 3.8.0)"),
}


LUB_LAWS = {
    "lubrication": (
        "F = (3/2) nu_n u_dot/u, nu_n = pi eta a^2, a = (R1 + R2)/2, on the FILM gap u, which is "
        "not the geometric gap u_n: a surface spring kn = 2 E1 R1 E2 R2/(E1 R1 + E2 R2) (= E R) "
        "in series, (3/2) nu_n u_dot/u = kn (u_n - u), force on the spheres kn (u - u_n) "
        "(Lubrication.cpp 16-75, 302-414, 498-571)"),
    "solid_contact": (
        "below u = 2 eps a the asperity spring keps kn joins: (3/2) nu_n u_dot/u = kn (u_n - u) "
        "+ keps kn (2 eps a - u); still force kn (u - u_n); elastic, no other dissipation "
        "(lines 353-359, 410-413)"),
    "when": "from the first interaction on (detection factor 1.5: from the start gap), no rupture",
}


def _load(name: str) -> dict | None:
    f = RAW / f"{name}.json"
    return json.loads(f.read_text()) if f.exists() else None


def _runs(doc: dict) -> list[dict]:
    out = []
    for r in doc["runs"]:
        h = r.get("half_dt") or {}
        row = {"v0_m_s": r["v0"], "outcome": r.get("outcome"), "e": r.get("e"),
               "e_half_dt": h.get("e"), "e_change_half_dt": r.get("e_change_half_dt"),
               "contact_duration_s": r.get("contact_duration_s"),
               "contact_duration_half_dt_s": h.get("contact_duration_s"),
               "max_overlap_m": r.get("max_overlap_m"), "wall_s": r.get("wall_s"),
               "wall_half_dt_s": h.get("wall_s")}
        for k in ("rupture_gap_m", "rupture_between_gaps_m", "min_film_gap_m",
                  "speed_at_contact", "force_at_contact_end_N", "steps", "steps_recorded"):
            if k in r:
                row[k] = r[k]
        out.append(row)
    return out


def yade_case(name: str, doc: dict, primary: bool) -> dict:
    p = doc["params"]
    m = doc["mass_kg"]
    ph = next((r["phys"] for r in doc["runs"] if r.get("phys")), {})
    case = {"name": name, "code": "yade", "version": "2023.02a (Debian yade 2023.02a-1)",
            "law": "yade-" + doc["law"], "partner": doc["partner"], "primary": primary,
            "params": {k: p[k] for k in ("R", "rho", "tc", "en", "et", "Vb", "gamma", "theta",
                                         "dcap", "captype", "capillar", "gap")},
            "params_units": {"R": "m", "rho": "kg/m3", "tc": "s", "Vb": "m3", "gamma": "N/m",
                             "theta": "deg", "dcap": "N s/m", "gap": "m (start gap)"},
            "derived": {"mass_kg": m, "reduced_mass_used_for_kn_cn_kg": 0.5 * m,
                        "moving_mass_kg": m if doc["partner"] == "fixed" else 0.5 * m,
                        "kn_N_per_m": ph.get("kn"), "cn_N_s_per_m": ph.get("cn"),
                        "sCrit_m": ph.get("sCrit"), "willett_radius_m": p["R"]},
            "force_laws": YADE_LAWS,
            "timestep_s": doc["dt"], "timestep_check_s": doc["dt"] / 2,
            "runs": _runs(doc)}
    return case


def yade_lub_case(name: str, doc: dict) -> dict:
    p = doc["params"]
    ph = next((r["phys"] for r in doc["runs"] if r.get("phys")), {})
    return {"name": name, "code": "yade", "version": "2023.02a (Debian yade 2023.02a-1)",
            "law": "yade-lubrication", "partner": doc["partner"], "primary": False,
            "params": {k: p[k] for k in ("R", "rho", "young", "poisson", "eta", "eps", "keps",
                                         "resolution", "lub_theta", "gap", "detect")},
            "derived": {"mass_kg": doc["mass_kg"], **ph},
            "force_laws": LUB_LAWS,
            "timestep_s": doc["dt"], "timestep_check_s": doc["dt"] / 2,
            "runs": _runs(doc)}


def liggghts_case(name: str, doc: dict, primary: bool) -> dict:
    p = doc["params"]
    return {"name": name, "code": "liggghts", "version": doc.get("version", "3.8.0"),
            "law": "liggghts-easo", "partner": doc["partner"], "primary": primary,
            "params": p,
            "params_units": {"R": "m", "rho": "kg/m3", "E": "Pa", "nu": "-", "en": "-",
                             "gamma": "N/m", "eta": "Pa s", "theta": "deg",
                             "smin": "minSeparationDistanceRatio (-)",
                             "smax": "maxSeparationDistanceRatio (-)",
                             "content": "surfaceLiquidContentInitial (fraction)",
                             "gap": "m (start gap)"},
            "derived": doc["derived"], "force_laws": LIGGGHTS_LAWS,
            "timestep_s": doc["dt"], "timestep_check_s": doc["dt"] / 2,
            "runs": _runs(doc)}


def main() -> None:
    cases = []
    for name, prim in (("yade_viscelcap_fixed", True), ("yade_viscelcap_pair", False),
                       ("yade_willett_analytic_fixed", False), ("yade_theta30_fixed", False),
                       ("yade_dry_fixed", False), ("yade_dry_pair", False)):
        d = _load(name)
        if d:
            cases.append(yade_case(name, d, prim))
    d = _load("yade_lubrication_fixed")
    if d:
        cases.append(yade_lub_case("yade_lubrication_fixed", d))
    for name, prim in (("liggghts_easo_fixed", True), ("liggghts_easo_pair", False),
                       ("liggghts_theta30_fixed", False), ("liggghts_dry_fixed", False),
                       ("liggghts_dry_pair", False)):
        d = _load(name)
        if d:
            cases.append(liggghts_case(name, d, prim))
    worst = max((r["e_change_half_dt"] for c in cases for r in c["runs"]
                 if r.get("e_change_half_dt") is not None), default=math.nan)
    doc = {
        "what": ("one head-on wet impact of a sphere (R = 1 mm, rho = 2500 kg/m3) on an equal "
                 "sphere, in Yade and LIGGGHTS with their own wet-contact laws; e = rebound "
                 "speed / approach speed, both relative normal speeds, the rebound one when the "
                 "gap is back at the start gap (beyond the rupture distance: free flight)"),
        "install": {"command": "apt-get update && apt-get install -y --no-install-recommends "
                               "yade liggghts",
                    "apt_get_update_s": 1.3, "install_s": 109.0, "packages_set_up": 180,
                    "versions": {"yade": "2023.02a-1", "liggghts": "3.8.0+repack1-9+b2"}},
        "largest_e_change_at_half_dt": worst,
        "cases": cases,
    }
    (HERE / "results.json").write_text(json.dumps(doc, indent=1) + "\n")
    print(f"results.json: {len(cases)} cases, largest |e(dt) - e(dt/2)| = {worst:.1e}")


if __name__ == "__main__":
    main()
