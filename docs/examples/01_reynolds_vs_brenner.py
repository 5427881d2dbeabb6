"""Reynolds' closure against Brenner's exact series: an immersed sphere approaching a wall.

Every DEM code reduces the viscous force to Reynolds' ``F = 6 pi eta R^2 v / S``. Brenner's
(1961) series is the exact Stokes force of the same sphere. This solves both (and two
published corrections) on the same gaps and draws the forces and each closure's error
against the exact series into ``reynolds_vs_brenner.png``.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from wetcontact import get_model, scene_from_dict

R, ETA, V = 1.0e-3, 1.2, 1.0e-3  # a 2 mm sphere in glycerol at 1 mm/s
scene = scene_from_dict({
    "name": "immersed-sphere-wall",
    "geometry": {"kind": "sphere-wall", "radius": R},
    "liquid": {"viscosity": ETA, "surface_tension": 0.063, "density": 1260.0},
    "amount": {"immersed": True},
    "motion": {"velocity": V,
               "gaps": {"start": 10 * R, "stop": 1e-5 * R, "points": 61, "spacing": "log"}},
})
exact = get_model("brenner").force(scene)
s = exact.gap / R

closures = {  # model: colour, line style, marker, the gaps it accepts
    "reynolds": ("tab:red", "--", "o", s > 0),
    "cox-brenner": ("tab:green", ":", "s", s <= 1.0),  # an inner expansion: refuses S/R > 1
    "schaeffer": ("tab:purple", "-.", "^", s > 0),
}

fig, (ax_f, ax_e) = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
ax_f.loglog(s, exact.force_viscous, color="black", lw=2.5, label="brenner (exact)")
print("model        max |F/F_exact - 1|   at S/R = 1e-3")
for name, (colour, style, marker, where) in closures.items():
    curve = get_model(name).force(scene, gaps=exact.gap[where])
    err = np.abs(curve.force_viscous / exact.force_viscous[where] - 1)
    ax_f.loglog(s[where], curve.force_viscous, color=colour, ls=style, lw=1.5, label=name)
    ax_e.loglog(s[where], err, color=colour, ls=style, marker=marker, markevery=6, ms=5,
                label=name)
    at_1e3 = err[np.argmin(np.abs(np.log10(s[where]) + 3))]
    print(f"{name:12s} {err.max():10.2e}   {at_1e3:16.2e}")

ax_f.set(xlabel="gap S/R", ylabel="viscous force F (N)", title="force (positive: resists approach)")
ax_e.set(xlabel="gap S/R", ylabel="|F / F_brenner - 1|", title="error against the exact series")
ax_e.axhline(1e-3, color="grey", lw=0.8)
ax_e.annotate("0.1 %", (1.5e-5, 1.2e-3), color="grey", fontsize=8)
for ax in (ax_f, ax_e):
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8)
fig.suptitle(f"Immersed sphere approaching a wall: R = {R * 1e3:g} mm, "
             f"eta = {ETA:g} Pa s, v = {V * 1e3:g} mm/s")
fig.savefig("reynolds_vs_brenner.png", dpi=110)
print("wrote reynolds_vs_brenner.png")
