"""Table: the dynamic rupture distance against Pitois' law and the refitted closure.

Reference: ``stokes-dynamic`` stretching runs (:mod:`wetcontact.solver.stokes_dynamic.rupture`:
a bridge from the static meniscus at 0.2 S_c separated at constant speed to its pinch),
sphere-wall, equal and unequal spheres, over the capillary number Ca = eta v / sigma, V*
(V/R^3 on a wall, V/R*^3 between spheres, R* = 2 R R2/(R + R2)), the radius ratio and the
contact angle, from the generation record of the closure
(``reduced_models/data/dynamic_rupture.json``, ``python -m wetcontact.generate
dynamic-rupture``; the runs take about 40 min on 2 cores, so the report does not repeat
them). Beside each run: Pitois, Moucheront & Chateau's (2001) ``S_c (1 + Ca^1/2)``, the
refit of that form ``1 + a Ca^b`` and the extended closure
(:func:`~wetcontact.reduced_models.dynamic_rupture.dynamic_rupture_ratio`), each evaluated
now; the relative error of the rupture distance. Runs that did not reach the pinch are listed
with their reason (the method's failure region).

The stability map (``dynamic_stability.csv`` / ``.png``): every run of the record, the runs
at the edges of the validity (V/R^3 = 0.1, 60 deg, Ca = 0.3 at the largest volume, a
radius ratio of 10) included,
with whether it reached the pinch, the reason when not, its volume error and the neck's
fitted rate, over (Ca, V*) per geometry, and the region the solver refuses (Ca > 0.3).
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np

from wetcontact.reduced_models import dynamic_rupture as dr
from wetcontact.sweep import Point, SweepResult
from wetcontact.tables import StudyContext


def points(ctx: StudyContext) -> list[Point]:
    """Nothing to sweep: the references are the generation record's."""
    return []


GEOMETRIES = (("wall", "sphere on a wall"), ("pair", "two equal spheres"),
              ("unequal", "two unequal spheres"))
"""The report's geometries (:func:`geometry`) and their titles."""


def geometry(case: dict[str, Any]) -> str:
    """``"wall"``, ``"pair"`` (equal spheres) or ``"unequal"`` of a run's case."""
    if case["kind"] == "wall":
        return "wall"
    return "pair" if case.get("radius_ratio", 1.0) == 1.0 else "unequal"


def coordinates(case: dict[str, Any]) -> tuple[float, float]:
    """The closure's ``(V*, rho)`` of a run's case (module docstring)."""
    if case["kind"] == "wall":
        return case["volume"], 1.0
    v, q = dr.pair_coordinates(case["volume"], case.get("radius_ratio", 1.0))
    return float(v), float(q)


def rows_of(data: dict[str, Any]) -> list[dict[str, Any]]:
    """One row per run that reached the pinch: the reference, Pitois, the two fits."""
    rows = []
    for run in data["runs"]:
        if "result" not in run or run.get("edge"):
            continue
        c, r = run["case"], run["result"]
        wall = c["kind"] == "wall"
        v, rho = coordinates(c)
        args = (wall, c["capillary_number"], v, c["theta_deg"], rho)
        pit = 1.0 + float(np.sqrt(c["capillary_number"]))
        ab = float(dr.ratio_form(data["coefficients_ab"], *args))
        full = float(dr.ratio_form(data["coefficients"], *args))
        ref = r["ratio"]
        rows.append({"kind": geometry(c), "Ca": c["capillary_number"], "V*": v,
                     "radius_ratio": c.get("radius_ratio", 1.0), "rho": rho,
                     "theta_deg": c["theta_deg"], "held_out": run["held_out"],
                     "S_c_static": r["static_gap"], "S_c_dynamic": r["gap"],
                     "ratio_ref": ref, "ratio_pitois": pit,
                     "err_pitois": abs(pit / ref - 1.0), "ratio_refit_ab": ab,
                     "err_refit_ab": abs(ab / ref - 1.0), "ratio_closure": full,
                     "err_closure": abs(full / ref - 1.0), "neck_slope": r["slope"],
                     "volume_error": r["volume_error"], "wall_time_s": r["wall_time"]})
    return rows


def _reason(error: str) -> str:
    """The solver's reason of a failed run, without the case it repeats."""
    _, _, tail = error.partition("stopped before the pinch (")
    return tail.rstrip(")") if tail else error[-120:]


def _stats(rows: list[dict[str, Any]], col: str) -> str:
    e = np.array([r[col] for r in rows])
    return f"{e.max():.3g} / {e.mean():.3g}" if e.size else "-"


def section(out: Path, result: SweepResult, ctx: StudyContext) -> str:
    """Write ``dynamic_rupture.csv`` and ``dynamic_rupture.png``; return the Markdown."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    data = dr.load()
    rows = rows_of(data)
    with open(out / "dynamic_rupture.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    from wetcontact.plotting import save

    save(figure(rows, data), out / "dynamic_rupture.png")
    stab = stability_rows(data)
    with open(out / "dynamic_stability.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(stab[0]))
        w.writeheader()
        w.writerows(stab)
    save(stability_figure(stab), out / "dynamic_stability.png")
    failed = [run for run in data["runs"] if "error" in run and not run.get("edge")]
    dom = data["domain"]
    ab = data["coefficients_ab"]
    lines = ["## Dynamic rupture: Pitois' (1 + Ca^1/2) against free-surface Stokes flow", "",
             "Rupture distance S_c(Ca) of a bridge stretched at constant relative speed v "
             "(Ca = eta v / sigma) from the static meniscus at "
             f"{data['start_over_static']:g} S_c to its pinch (`stokes-dynamic`, default "
             "preset; S_c the static fold of `meniscus`). Sphere-wall, equal and unequal "
             f"spheres (rho = R_small/R_large {dom['rho'][0]:g}-1), Ca "
             f"{dom['capillary_number'][0]:g}-{dom['capillary_number'][1]:g}, V* (V/R^3 on a "
             "wall, V/R*^3 between spheres, R* = 2 R R2/(R + R2)) "
             f"{dom['volume'][0]:g}-{dom['volume'][1]:g}, contact angle (static, both "
             f"solids) {dom['theta_deg']['wall'][0]:g}-{dom['theta_deg']['wall'][1]:g} deg on "
             f"a wall, {dom['theta_deg']['pair'][0]:g}-{dom['theta_deg']['pair'][1]:g} deg "
             "between spheres (above, the static bridge between equal spheres breaks its "
             "symmetry before its fold), "
             "slip 1e-3 R. References from the closure's generation record; the laws "
             "evaluated now. Relative error of S_c(Ca), max / mean; every run: "
             "`dynamic_rupture.csv`, S_c(Ca)/S_c against Ca: `dynamic_rupture.png`.", "",
             "| law | grid runs | held-out runs |", "|---|---|---|"]
    grid = [r for r in rows if not r["held_out"]]
    held = [r for r in rows if r["held_out"]]
    labels = (("Pitois 2001, 1 + Ca^1/2", "err_pitois"),
              ("refit 1 + a Ca^b (per geometry: wall a = "
               f"{ab['wall']['a']:.3g}, b = {ab['wall']['b']:.3g}; pair a = "
               f"{ab['pair']['a']:.3g}, b = {ab['pair']['b']:.3g})", "err_refit_ab"),
              ("closure 1 + a Ca^(b + c ln Ca) (V*/1e-3)^d e^(e theta) rho^g", "err_closure"))
    for label, col in labels:
        lines.append(f"| {label} | {_stats(grid, col)} | {_stats(held, col)} |")
    lines += ["", f"{len(rows)} runs reached the pinch; {len(failed)} did not (the method's "
              "failure region)" + (": " + "; ".join(
                  f"{geometry(f['case'])} Ca {f['case']['capillary_number']:g} V* "
                  f"{coordinates(f['case'])[0]:.3g} theta {f['case']['theta_deg']:g} deg "
                  f"({_reason(f['error'])})" for f in failed) if failed else "") + "."]
    e_p = max(r["err_pitois"] for r in held) if held else float("nan")
    e_c = max(r["err_closure"] for r in held) if held else float("nan")
    e_ab = max(r["err_refit_ab"] for r in held) if held else float("nan")
    under = sum(r["ratio_pitois"] < r["ratio_ref"] for r in rows)
    lines += ["", f"Conclusion: Pitois' factor underestimates the rupture distance in {under} "
              f"of {len(rows)} runs, by up to {100 * e_p:.1f} % on the held-out runs; "
              f"refitting its form 1 + a Ca^b leaves {100 * e_ab:.1f} %, the closure "
              f"{100 * e_c:.1f} %."]
    uneq = [r for r in held if r["kind"] == "unequal"]
    if uneq:
        lines += ["", "Unequal spheres (held-out, rho "
                  f"{min(r['rho'] for r in uneq):.2f}-{max(r['rho'] for r in uneq):.2f}): "
                  f"closure {_stats(uneq, 'err_closure')}, Pitois "
                  f"{_stats(uneq, 'err_pitois')} (max / mean)."]
    lines += ["", stability_text(stab)]
    return "\n".join(lines) + "\n"


def stability_rows(data: dict[str, Any]) -> list[dict[str, Any]]:
    """One row per run of the record: the case, ``pinch`` (1/0), the reason when not, the
    volume error, the neck's rate and the wall time."""
    out = []
    for run in data["runs"]:
        c, r = run["case"], run.get("result", {})
        out.append({"kind": geometry(c), "Ca": c["capillary_number"],
                    "V*": coordinates(c)[0], "radius_ratio": c.get("radius_ratio", 1.0),
                    "theta_deg": c["theta_deg"],
                    "set": "edge" if run.get("edge") else ("held-out" if run["held_out"]
                                                           else "grid"),
                    "pinch": int("result" in run),
                    "reason": "" if "result" in run else _reason(run["error"]),
                    "ratio_ref": r.get("ratio", float("nan")),
                    "volume_error": r.get("volume_error", float("nan")),
                    "neck_slope": r.get("slope", float("nan")),
                    "wall_time_s": r.get("wall_time", float("nan"))})
    return out


def stability_text(stab: list[dict[str, Any]]) -> str:
    """The stability map's paragraph: where the runs fail and what they reach elsewhere."""
    ok = [r for r in stab if r["pinch"]]
    bad = [r for r in stab if not r["pinch"]]
    edge = [r for r in stab if r["set"] == "edge"]
    fails = "; ".join(f"{r['kind']} Ca {r['Ca']:g} V* {r['V*']:g} {r['theta_deg']:g} deg: "
                      f"{r['reason']}" for r in bad) or "none"
    return (f"**Stability map** (`dynamic_stability.png`, `dynamic_stability.csv`): of "
            f"{len(stab)} runs ({len(edge)} at the edges of the validity: V* = 0.1, 60 deg "
            f"on a wall, Ca = 0.3 at the largest volume, a radius ratio of 10), {len(ok)} "
            "reached the pinch, with "
            f"volume kept within {max(r['volume_error'] for r in ok):.1e} and the neck's "
            f"fitted rate {min(r['neck_slope'] for r in ok):.3f}-"
            f"{max(r['neck_slope'] for r in ok):.3f} sigma/eta over its last decade "
            "(Papageorgiou's asymptote 0.0709). Failures (the run stops and says why, no "
            f"value): {fails}. Refused: Ca > 0.3 (at Ca = 1 the thread's mesh degenerates "
            "after 52 remeshings at 2.6 S_c), V* outside 1e-4-0.1, angles outside 1-60 deg, "
            "spheres above 30 deg (between equal ones the static bridge breaks its symmetry "
            "first), radius ratios outside 0.1-10.")


def stability_figure(stab: list[dict[str, Any]]):
    """Runs over (Ca, V*) per geometry: reached the pinch or not, by angle."""
    from wetcontact.plotting import pyplot, styles

    plt = pyplot()
    ths = sorted({r["theta_deg"] for r in stab if r["set"] != "held-out"})
    names = [f"pinch reached, theta {t:g} deg" for t in ths] + [
        "held-out run, pinch reached", "stopped before the pinch (reason: the CSV)"]
    st = styles(names)
    fig, axes = plt.subplots(1, 3, figsize=(14, 5.0), sharey=True, layout="constrained")
    for ax, (kind, title) in zip(axes, GEOMETRIES, strict=True):
        for k, (t, name) in enumerate(zip(ths, names, strict=False)):
            sel = [r for r in stab if r["kind"] == kind and r["theta_deg"] == t
                   and r["pinch"] and r["set"] != "held-out"]
            if sel:  # the angles side by side around each Ca
                ax.plot([r["Ca"] * 1.25 ** (k - len(ths) / 2) for r in sel],
                        [r["V*"] for r in sel], ms=7, mfc="none", label=name,
                        **{**st[name], "linestyle": "none"})
        sel = [r for r in stab if r["kind"] == kind and r["set"] == "held-out" and r["pinch"]]
        ax.plot([r["Ca"] for r in sel], [r["V*"] for r in sel], ms=5, label=names[-2],
                **{**st[names[-2]], "linestyle": "none"})
        sel = [r for r in stab if r["kind"] == kind and not r["pinch"]]
        ax.plot([r["Ca"] * 1.25 ** (ths.index(r["theta_deg"]) - len(ths) / 2)
                 if r["theta_deg"] in ths else r["Ca"] for r in sel],
                [r["V*"] for r in sel], ms=11, mew=2.5, marker="x", color="red",
                linestyle="none", label=names[-1])
        ax.axvspan(0.3, 3.0, color="0.85", zorder=0, label="refused: Ca > 0.3")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(3e-5, 3.0)
        ax.set_ylim(5e-5, 0.2)
        ratios = sorted({r["radius_ratio"] for r in stab if r["kind"] == kind
                         and r["set"] == "grid"})
        ax.set_title(title + (" (R2/R " + " and ".join(f"{q:g}" for q in ratios)
                              + " at each grid point)" if kind == "unequal" else ""),
                     fontsize=9)
        ax.set_xlabel("Ca = eta v / sigma (the angles side by side at each Ca)")
        ax.grid(True, alpha=0.3)
    handles: dict[str, Any] = {}
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(lab, h)
    fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncols=4,
               fontsize=8)
    axes[0].set_ylabel("V* (V/R^3; V/R*^3 between spheres)")
    fig.suptitle("stokes-dynamic stability map: bridges stretched from 0.2 S_c to the pinch, "
                 "which runs reach it (default preset)", fontsize=10)
    return fig


def figure(rows: list[dict[str, Any]], data: dict[str, Any]):
    """S_c(Ca)/S_c against Ca, one panel per geometry: the runs by angle, Pitois and the
    closure at each angle (V* = 1e-3) as lines."""
    from wetcontact.plotting import pyplot, styles

    plt = pyplot()
    ths = sorted({r["theta_deg"] for r in rows if not r["held_out"]})
    names = [f"stokes-dynamic, theta {t:g} deg" for t in ths] + [
        f"closure, theta {t:g} deg, V* 1e-3" for t in ths] + ["Pitois 2001, 1 + Ca^1/2",
                                                               "held-out runs"]
    st = styles(names)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), sharey=True, layout="constrained")
    ca = np.geomspace(*data["domain"]["capillary_number"], 100)
    for ax, (kind, title) in zip(axes, GEOMETRIES, strict=True):
        rho = min((r["rho"] for r in rows if r["kind"] == kind), default=1.0)
        for t, name, cname in zip(ths, names[:len(ths)], names[len(ths):2 * len(ths)],
                                  strict=True):
            sel = [r for r in rows if r["kind"] == kind and r["theta_deg"] == t
                   and not r["held_out"]]
            if not sel:
                continue
            ax.plot([r["Ca"] for r in sel], [r["ratio_ref"] for r in sel], mfc="none",
                    ms=6, label=name, **{**st[name], "linestyle": "none"})
            ax.plot(ca, dr.ratio_form(data["coefficients"], kind == "wall", ca, 1e-3, t, rho),
                    lw=1.4, label=cname + (f", rho {rho:g}" if rho < 1 else ""),
                    **{**st[cname], "marker": None})
        ax.plot(ca, 1 + np.sqrt(ca), lw=2.0, label=names[-2],
                **{**st[names[-2]], "marker": None})
        sel = [r for r in rows if r["kind"] == kind and r["held_out"]]
        ax.plot([r["Ca"] for r in sel], [r["ratio_ref"] for r in sel], ms=7, label=names[-1],
                **{**st[names[-1]], "linestyle": "none"})
        ax.set_xscale("log")
        rhos = sorted({r["rho"] for r in rows if r["kind"] == kind and not r["held_out"]})
        ax.set_title(f"{title}: V* 1e-4 to 1e-2 (points)"
                     + (", rho " + ", ".join(f"{q:g}" for q in rhos) if kind == "unequal"
                        else ""), fontsize=9)
        ax.set_xlabel("Ca = eta v / sigma")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("S_c(Ca) / S_c (static fold)")
    for ax in axes:
        ax.legend(fontsize=7, loc="upper left")
    fig.suptitle("Dynamic rupture distance: bridge stretched at constant speed from 0.2 S_c "
                 "to its pinch (stokes-dynamic) against Pitois 2001 and the refit", fontsize=10)
    return fig
