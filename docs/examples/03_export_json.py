"""Export a calibrated closure to JSON and evaluate it without wetcontact.

``wetcontact export json`` writes a closure's form, coefficients, domain and held-out
errors as one document, validated against the schema the package ships. This exports the
shipped ``calibrated-viscous`` closure to ``calibrated_viscous.json`` and evaluates its
immersed sphere-wall part with numpy alone, from the document's own form, as a DEM code in
any language would; then checks it against Brenner's exact series.
"""

import json
import subprocess
import sys
import textwrap

import numpy as np
from numpy.polynomial import chebyshev

# 1. export: the command line, as a user would run it (`wetcontact export json ...`)
subprocess.run([sys.executable, "-m", "wetcontact", "export", "json",
                "--closure", "calibrated-viscous", "--out", "calibrated_viscous.json"],
               check=True)
doc = json.load(open("calibrated_viscous.json"))
part = next(p for p in doc["parts"] if p["name"] == "immersed sphere-wall")
print(textwrap.fill("sign convention: " + doc["sign_convention"], 88))
print(textwrap.fill("form: " + part["form"], 88, subsequent_indent="    "))


# 2. evaluate it from the document alone: F = 6 pi eta R v lambda(s), s = S/R
def viscous_force_wall(gap, radius, viscosity, approach_speed):
    s = np.asarray(gap) / radius
    lo, hi = np.log(part["domain"]["s_over_r"])
    t = (2 * np.log(s) - lo - hi) / (hi - lo)
    lam = chebyshev.chebval(t, part["coefficients"]) * (1 + s) / s
    inside = (s >= part["domain"]["s_over_r"][0]) & (s <= part["domain"]["s_over_r"][1])
    return np.where(inside, 6 * np.pi * viscosity * radius * approach_speed * lam, np.nan)


# 3. against the exact series (the package's `brenner` model)
from wetcontact import get_model, scene_from_dict  # noqa: E402  (only for the check)

R, ETA, V = 1e-3, 1.2, 1e-3
gaps = np.geomspace(1e-5, 100, 200) * R
scene = scene_from_dict({
    "name": "json-check", "geometry": {"kind": "sphere-wall", "radius": R},
    "liquid": {"viscosity": ETA, "surface_tension": 0.063, "density": 1260.0},
    "amount": {"immersed": True}, "motion": {"velocity": V, "gaps": gaps.tolist()}})
exact = get_model("brenner").force(scene).force_viscous
error = np.abs(viscous_force_wall(gaps, R, ETA, V) / exact - 1)
print(f"numpy from the JSON vs the exact series, S/R in [1e-5, 100]: max relative error "
      f"{error.max():.1e}\n(the document's held-out maximum: "
      f"{part['held_out']['relative_error']['max']:.1e})")
print("outside the domain the function returns NaN:",
      viscous_force_wall(200 * R, R, ETA, V))
