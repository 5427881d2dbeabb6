"""Capillary closures of a pendular bridge against the calibrated reference.

A water bridge between two equal 100 um spheres, the DEM-typical pendular contact. The
published closures DEM codes use (Willett, Mikami, Rabinovich, Lambert, the toroidal
approximation, Bagheri) are compared with ``calibrated-capillary``, which interpolates the
finite-element Young-Laplace solver ``meniscus`` to about 1e-4, through the toolkit's one
error metric (``wetcontact.compare.compare``). Writes ``capillary_closures.png`` and the
error table ``capillary_closures.csv``.
"""

import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from wetcontact import get_model, scene_from_dict
from wetcontact.compare import compare

R, V_STAR, THETA = 50e-6, 0.01, 20.0
base = {
    "name": "water-bridge-100um",
    "geometry": {"kind": "sphere-sphere", "radius": R, "radius2": R},
    "liquid": {"viscosity": 1e-3, "surface_tension": 0.072, "density": 998.0,
               "contact_angle": THETA},
    "amount": {"bridge_volume": V_STAR * R**3},
    "motion": {"velocity": 0.01, "gaps": [1e-3 * R]},
}
# the reference's rupture distance S_c sets the gaps: from near contact to past rupture
s_c = get_model("calibrated-capillary").force(scene_from_dict(base)).extras["rupture_distance"][0]
gaps = np.linspace(0.002, 1.15, 116) * s_c
scene = scene_from_dict({**base, "motion": {"velocity": 0.01, "gaps": gaps.tolist()}})
reference = get_model("calibrated-capillary").force(scene)

styles = {  # model: colour, line style, marker
    "willett": ("tab:blue", "--", "o"),
    "willett-simple": ("tab:orange", "-.", "s"),
    "mikami": ("tab:green", ":", "^"),
    "rabinovich": ("tab:red", (0, (5, 1, 1, 1, 1, 1)), "v"),
    "lambert": ("tab:purple", (0, (3, 1)), "D"),
    "toroidal": ("tab:brown", (0, (1, 1)), "P"),
    "bagheri": ("tab:pink", (0, (8, 2)), "X"),
}
x = gaps / s_c
fig, (ax_f, ax_e) = plt.subplots(1, 2, figsize=(12.5, 4.6), constrained_layout=True)
ax_f.plot(x, reference.force_capillary * 1e6, color="black", lw=2.5,
          label="calibrated-capillary\n(reference)")
rows = []
for k, (name, (colour, style, marker)) in enumerate(styles.items()):
    curve = get_model(name).force(scene)
    c = compare(curve, reference, "capillary")
    rows.append({"model": name, "max_rel_error": c.max_rel_error,
                 "mean_rel_error": c.mean_rel_error, "p95_rel_error": c.p95_rel_error,
                 "spurious_gaps": c.spurious})
    ax_f.plot(x, curve.force_capillary * 1e6, color=colour, ls=style, lw=1.4, marker=marker,
              markevery=(2 * k, 15), ms=4, label=name)
    ax_e.plot(c.gap / s_c, 100 * c.signed_error, color=colour, ls=style, lw=1.4,
              marker=marker, markevery=(2 * k, 15), ms=4, label=name)

ax_f.axhline(0, color="grey", lw=0.8)
ax_f.axvline(1, color="grey", lw=0.8)
ax_f.annotate("reference S_c", (1.015, 0.45), xycoords=("data", "axes fraction"), fontsize=8,
              color="grey", rotation=90)
ax_f.set(xlabel="gap S / S_c (S_c: the reference's rupture distance)",
         ylabel="capillary force F (uN), negative = attraction", title="force")
ax_e.axhline(0, color="grey", lw=0.8)
ax_e.set_yscale("symlog", linthresh=1.0)  # linear within +-1 %, logarithmic beyond
ax_e.axhspan(-1, 1, color="grey", alpha=0.12, lw=0)
ax_e.set(xlabel="gap S / S_c", ylabel="F / F_reference - 1 (%), symlog (shaded: +-1 %)",
         title="signed error where the reference bridge exists")
for ax in (ax_f, ax_e):
    ax.grid(True, alpha=0.3)
fig.legend(*ax_f.get_legend_handles_labels(), loc="outside right center", fontsize=8)
fig.suptitle(f"Water bridge between two spheres: R = {R * 1e6:g} um, V/R^3 = {V_STAR:g}, "
             f"contact angle {THETA:g} deg")
fig.savefig("capillary_closures.png", dpi=110)

with open("capillary_closures.csv", "w", newline="") as f:
    writer = csv.DictWriter(f, fieldnames=list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)
print(f"rupture distance of the reference: S_c = {s_c:.4e} m")
print("model            max rel. error   mean     p95   spurious gaps")
for r in rows:
    print(f"{r['model']:16s} {r['max_rel_error']:10.3f} {r['mean_rel_error']:8.3f} "
          f"{r['p95_rel_error']:7.3f} {r['spurious_gaps']:8d}")
print("wrote capillary_closures.png and capillary_closures.csv")
