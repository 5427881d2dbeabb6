"""Error table: the capillary closures and rupture correlations against the FE meniscus.

For a sphere on a wall and two equal spheres (R = 1 mm, sigma = 0.072 N/m, the same contact
angle on both solids), over V* = V/R^3 in [1e-4, 0.1], theta in [0, 50] deg and gaps from
contact (S = 1e-6 R) to 0.95 of the FE rupture distance, every registered capillary closure
(toroidal, Mikami, Willett, Willett simple, Rabinovich, Lambert, Bagheri, and the shipped
``calibrated-capillary``) is swept as a
point of the report's study and compared with the finite-element Young-Laplace bridge
(model ``meniscus``, force error ~1e-9) by :func:`wetcontact.compare.compare`: relative
error ``|F_closure - F_FE|/|F_FE|``. The gaps are a derived axis: stage 1
(:func:`points`) sweeps the FE bridge at contact for its rupture distance S_c, stage 2
(:func:`derived_points`) the gaps S/S_c. A closure that refuses a scene (its ``check``
raises ValidityError, or it fails) is counted as "n/a", not as an error. The rupture
correlations (Lian 1993, Willett 2000, Mikami pp/pw, ``calibrated-capillary``) are compared
with the FE turning point.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from wetcontact.compare import Comparison, compare, pooled
from wetcontact.errors import SolverError
from wetcontact.models import get_model
from wetcontact.scene import Scene, scene_from_dict
from wetcontact.sweep import Point, SweepResult
from wetcontact.tables import StudyContext

R, SIGMA = 1.0e-3, 0.072
CLOSURES = ("toroidal", "mikami", "willett", "willett-simple", "rabinovich", "lambert",
            "bagheri", "calibrated-capillary")
RUPTURE = ("lian", "willett", "mikami-pp", "mikami-pw", "calibrated-capillary")
KINDS = ("sphere-wall", "sphere-sphere")
CONTACT = 1e-6 * R  # the gap "at contact"


def _scene(kind: str, vstar: float, theta_deg: float, gaps: list[float]) -> Scene:
    geom = {"kind": kind, "radius": R}
    if kind == "sphere-sphere":
        geom["radius2"] = R
    return scene_from_dict({
        "name": f"{kind}-V{vstar:g}-th{theta_deg:g}",
        "geometry": geom,
        "liquid": {"viscosity": 1e-3, "surface_tension": SIGMA, "density": 1000.0,
                   "contact_angle": theta_deg},
        "amount": {"bridge_volume": vstar * R**3},
        "motion": {"velocity": 0.0, "gaps": gaps},
    })


def _rupture_correlations(kind: str, V: float, th: float) -> dict[str, float]:
    from wetcontact.reduced_models import rupture as rp

    out = {"lian": float(rp.lian_rupture_distance(V, th)),
           "willett": float(rp.willett_rupture_distance(V, R, th))}
    if kind == "sphere-sphere":
        out["mikami-pp"] = float(rp.mikami_rupture_distance_pp(V, R, th))
    else:
        out["mikami-pw"] = float(rp.mikami_rupture_distance_pw(V, R, th))
    model = get_model("calibrated-capillary")
    scene = _scene(kind, V / R**3, math.degrees(th), [CONTACT])
    if model.applicable(scene) is None:
        out["calibrated-capillary"] = float(model.rupture_distance(scene))
    return out


def _grid(quick: bool) -> tuple[list[tuple[str, float, float]], tuple[float, ...]]:
    """The (geometry, V*, theta) series and the gap fractions S/S_c of each."""
    vstars = (1e-4, 1e-2, 0.1) if quick else (1e-4, 1e-3, 1e-2, 0.1)
    thetas = (0.0, 50.0) if quick else (0.0, 25.0, 50.0)
    fracs = (0.0, 0.4, 0.8, 0.95) if quick else (0.0, 0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 0.95)
    return [(k, v, t) for k in KINDS for v in vstars for t in thetas], fracs


def _rupture_point(kind: str, vs: float, th: float) -> Point:
    """The FE bridge at contact: its ``rupture_distance`` extra is the FE turning point."""
    return Point(_scene(kind, vs, th, [CONTACT]), "meniscus", "fast")


def points(ctx: StudyContext) -> list[Point]:
    """Stage 1: the FE rupture distance of every (geometry, V*, theta)."""
    return [_rupture_point(*series) for series in _grid(ctx.quick)[0]]


def _rupture(result: SweepResult, kind: str, vs: float, th: float) -> float | None:
    curve = result.curve(_rupture_point(kind, vs, th))
    return None if curve is None else float(curve.extras["rupture_distance"][0])


def _series_points(result: SweepResult, ctx: StudyContext):
    """Per series: (kind, V*, theta, S_c, gaps, FE point, {closure: point})."""
    series, fracs = _grid(ctx.quick)
    for kind, vs, th in series:
        sc_rup = _rupture(result, kind, vs, th)
        if sc_rup is None:
            continue
        gaps = [max(f * sc_rup, CONTACT) for f in fracs]
        scene = _scene(kind, vs, th, gaps)
        closures = {c: Point(scene, c) for c in CLOSURES
                    if get_model(c).applicable(scene) is None}
        yield kind, vs, th, sc_rup, gaps, Point(scene, "meniscus", "fast"), closures


def derived_points(ctx: StudyContext, result: SweepResult) -> list[Point]:
    """Stage 2: gaps from contact to 0.95 S_c (FE), the FE bridge and every closure there."""
    return [p for *_, fe, cl in _series_points(result, ctx) for p in (fe, *cl.values())]


def compute(result: SweepResult, ctx: StudyContext
            ) -> tuple[list[dict], list[dict], dict[tuple[str, str], list[Comparison]]]:
    """Rows of (closure, kind, V*, theta, S/S_c, S (m), F_FE and F_closure (N), rel. error),
    rupture rows (S_c in m), and the comparison records per (closure, kind)."""
    fracs = _grid(ctx.quick)[1]
    rows, rup_rows = [], []
    recs: dict[tuple[str, str], list[Comparison]] = {}
    for kind, vs, th, sc_rup, gaps, fe_pt, cl in _series_points(result, ctx):
        V = vs * R**3
        for name, val in _rupture_correlations(kind, V, math.radians(th)).items():
            rup_rows.append({"correlation": name, "kind": kind, "V*": vs,
                             "theta_deg": th, "S_c_FE_m": sc_rup, "S_c_m": val,
                             "rel_error": abs(val / sc_rup - 1)})
        fe = result.curve(fe_pt)
        if fe is None:
            continue
        for name in CLOSURES:
            curve = result.curve(cl[name]) if name in cl else None
            rec = None if curve is None else compare(curve, fe, "capillary")
            if rec is not None:
                recs.setdefault((name, kind), []).append(rec)
            for i, (f, s) in enumerate(zip(fracs, gaps, strict=True)):
                rows.append({"closure": name, "kind": kind, "V*": vs, "theta_deg": th,
                             "S/S_c": f, "S_m": s, "F_FE_N": float(fe.force_capillary[i]),
                             "F_closure_N": None if curve is None
                             else float(curve.force_capillary[i]),
                             "rel_error": None if rec is None else rec.rel_at(s)})
    return rows, rup_rows, recs


def reach(rows: list[dict], tol: float) -> float:
    """Largest S/S_c up to which every point of one (closure, geometry, V*, theta) series is
    within ``tol`` (the series starts at contact); -1 if it fails already at contact."""
    ok = -1.0
    for r in sorted(rows, key=lambda r: r["S/S_c"]):
        if r["rel_error"] is None or r["rel_error"] > tol:
            break
        ok = r["S/S_c"]
    return ok


def regions(rows: list[dict]) -> list[dict]:
    """Per (closure, geometry, V*, theta): the S/S_c reach within 1 % and within 5 %."""
    keys = sorted({(r["closure"], r["kind"], r["V*"], r["theta_deg"]) for r in rows
                   if r["rel_error"] is not None})
    out = []
    for name, kind, vs, th in keys:
        sel = [r for r in rows if (r["closure"], r["kind"], r["V*"], r["theta_deg"])
               == (name, kind, vs, th)]
        out.append({"closure": name, "kind": kind, "V*": vs, "theta_deg": th,
                    "reach_1pct": reach(sel, 0.01), "reach_5pct": reach(sel, 0.05)})
    return out


def _region_cell(reg: list[dict], col: str) -> str:
    """'k/n (V*, theta) at contact; S/S_c reach median m, best at V*=..., theta=...'."""
    reaches = np.array([r[col] for r in reg])
    n_ok = int(np.sum(reaches >= 0))
    if n_ok == 0:
        return f"0/{len(reg)} at contact"
    best = max(reg, key=lambda r: r[col])
    return (f"{n_ok}/{len(reg)} at contact; their reach median "
            f"{np.median(reaches[reaches >= 0]):g}, max {best[col]:g} (V* {best['V*']:g}, "
            f"{best['theta_deg']:g} deg)")


def section(out: Path, result: SweepResult, ctx: StudyContext) -> str:
    """Write ``capillary_closures.csv``, ``capillary_rupture.csv`` (+ PNG); return Markdown."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows, rup, recs = compute(result, ctx)
    if not rows or not rup:
        raise SolverError("report section 'capillary closures': no stored meniscus curve "
                          "for its points (every one refused or failed; see the sweep "
                          "summary)")
    with open(out / "capillary_closures.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    reg = regions(rows)
    for name, table in (("capillary_rupture.csv", rup), ("capillary_regions.csv", reg)):
        with open(out / name, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(table[0]))
            w.writeheader()
            w.writerows(table)
    lines = ["## Capillary closures against the FE Young-Laplace bridge", "",
             "Relative force error |F/F_FE - 1| over V* in [1e-4, 0.1], theta in [0, 50] deg "
             "(both solids), S from contact to 0.95 S_c (FE rupture distance); "
             "R = 1 mm, sigma = 0.072 N/m. n/a = the closure refuses the scene. "
             "Region columns: of the (V*, theta) pairs, how many are within the tolerance at "
             "contact, and the reach: the S/S_c up to which the closure stays within it "
             "(per pair in `capillary_regions.csv`, map in `capillary_regions.png`). "
             "Every point: `capillary_closures.csv`; the maximum over (V*, theta) against "
             "S/S_c: `capillary_closures.png`.", "",
             "| closure | geometry | points | n/a | max | mean | 95th pct | within 1 % | "
             "within 5 % |", "|---|---|---|---|---|---|---|---|---|"]
    best = None
    for name in CLOSURES:
        for kind in ("sphere-wall", "sphere-sphere"):
            sel = [r for r in rows if r["closure"] == name and r["kind"] == kind]
            st = pooled(recs.get((name, kind), []))
            na = len(sel) - st["points"]
            if not st["points"]:
                lines.append(f"| {name} | {kind} | 0 | {na} | - | - | - | - | - |")
                continue
            p95 = st["p95_rel_error"]
            rk = [r for r in reg if r["closure"] == name and r["kind"] == kind]
            lines.append(f"| {name} | {kind} | {st['points']} | {na} | "
                         f"{st['max_rel_error']:.3g} | {st['mean_rel_error']:.3g} | "
                         f"{p95:.3g} | {_region_cell(rk, 'reach_1pct')} | "
                         f"{_region_cell(rk, 'reach_5pct')} |")
            if kind == "sphere-sphere" and (best is None or p95 < best[1]):
                best = (name, p95)
    lines += ["", "Rupture distance correlations against the FE turning point "
              "(every point: `capillary_rupture.csv`):", "",
              "| correlation | geometry | max | mean |", "|---|---|---|---|"]
    for name in RUPTURE:
        for kind in ("sphere-wall", "sphere-sphere"):
            e = np.array([r["rel_error"] for r in rup if r["correlation"] == name
                          and r["kind"] == kind])
            if e.size:
                lines.append(f"| {name} | {kind} | {e.max():.3g} | {e.mean():.3g} |")
    _plot(out, rows)
    _plot_regions(out, reg)
    if best is not None:
        lines += ["", f"Conclusion: for two equal spheres the most accurate closure over this "
                  f"range is **{best[0]}** (95th-percentile error {100 * best[1]:.2g} %); "
                  "the published closures degrade towards rupture."]
    return "\n".join(lines) + "\n"


def _plot(out: Path, rows: list[dict]) -> None:
    from wetcontact.plotting import save

    save(closures_figure(rows), out / "capillary_closures.png")


def closures_figure(rows: list[dict]):
    """Max relative error over (V*, theta) against S/S_c, one colour and marker per closure."""
    from wetcontact.plotting import pyplot, styles

    plt = pyplot()
    st = styles(CLOSURES)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True, layout="constrained")
    for ax, kind in zip(axes, KINDS, strict=True):
        for name in CLOSURES:
            sel = [r for r in rows if r["closure"] == name and r["kind"] == kind
                   and r["rel_error"] is not None]
            if sel:
                fr = sorted({r["S/S_c"] for r in sel})
                mx = [np.max([r["rel_error"] for r in sel if r["S/S_c"] == f]) for f in fr]
                ax.semilogy(fr, np.maximum(mx, 1e-6), ms=5, label=name, **st[name])
        ax.set_title(f"{kind}, R = {R * 1e3:g} mm, sigma = {SIGMA:g} N/m", fontsize=9)
        ax.set_xlabel("S / S_c (FE)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max relative force error over V*, theta")
    axes[1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0),
                   borderaxespad=0.0)  # beside the panels: inside, it hid willett's points
    return fig


def _plot_regions(out: Path, reg: list[dict]) -> None:
    from wetcontact.plotting import save

    save(regions_figure(reg), out / "capillary_regions.png")


def regions_figure(reg: list[dict]):
    """Heat maps of the S/S_c reach within 5 %: closures down, (V*, theta) across."""
    import matplotlib

    from wetcontact.plotting import pyplot

    plt = pyplot()
    pairs = sorted({(r["V*"], r["theta_deg"]) for r in reg})
    fig, axes = plt.subplots(2, 1, figsize=(max(7.0, 0.55 * len(pairs) + 3), 7.5),
                             sharex=True, layout="constrained")
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.8")
    im = None
    for ax, kind in zip(axes, KINDS, strict=True):
        grid = np.full((len(CLOSURES), len(pairs)), np.nan)
        for r in reg:
            if r["kind"] == kind:
                grid[CLOSURES.index(r["closure"]), pairs.index((r["V*"], r["theta_deg"]))] = (
                    r["reach_5pct"])
        im = ax.imshow(np.ma.masked_where(~(grid >= 0), grid), vmin=0.0, vmax=1.0,
                       cmap=cmap, aspect="auto")
        ax.set_yticks(range(len(CLOSURES)), CLOSURES, fontsize=8)
        ax.set_title(f"{kind}: S/S_c reach within 5 % (grey: fails at contact)", fontsize=9)
    axes[-1].set_xticks(range(len(pairs)), [f"{v:g}\n{th:g}°" for v, th in pairs],
                        fontsize=7)
    axes[-1].set_xlabel("V* = V/R^3 (top) and contact angle (bottom)")
    fig.colorbar(im, ax=axes, shrink=0.8, label="largest S/S_c within 5 %")
    return fig
